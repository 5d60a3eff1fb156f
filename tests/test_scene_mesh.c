/* test_scene_mesh.c: the scene keys of mesh files: cloths and bodies from mesh
 * files (file, node, units, scale, rotation, translate), mesh bodies as
 * level sets (voxel_size, band, interior, close_holes), the cache
 * (levelset.cache), and one exact message per kind of error, each one line
 * "FILE:LINE: KEY: what was expected (got X)". */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "import/import.h"
#include "tests/scene_load.h"

#ifndef CS_ASSETS_DIR
#error "CS_ASSETS_DIR must name the repository's assets/ folder (tests/CMakeLists.txt defines it)"
#endif
#define ASSET(name) CS_ASSETS_DIR "/" name

static char tmpdir[256];

static int setup(void **state)
{
    (void)state;
    snprintf(tmpdir, sizeof tmpdir, "/tmp/cs_test_scene_mesh_XXXXXX");
    if (!mkdtemp(tmpdir))
        return -1;
    if (access(ASSET("ico4.obj"), R_OK) != 0) {
        print_error("missing test assets in %s: the repository's assets/ folder is "
                    "incomplete\n",
                    CS_ASSETS_DIR);
        return -1;
    }
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    return system(cmd) == 0 ? 0 : -1;
}

/* The error starts with want (for messages that go on with a path or a
 * number that depends on the machine). */
static void expect_error_prefix(const char *text, const char *want)
{
    char err[1024] = "";
    cs_scene *s = NULL;
    assert_int_equal(cs_scene_load_string(text, "scenes/a.yaml", 0, NULL, &s, err, sizeof err),
                     CS_ERR_BAD_INPUT);
    if (strncmp(err, want, strlen(want)) != 0)
        print_error("got:  %s\nwant: %s...\n", err, want);
    assert_int_equal(strncmp(err, want, strlen(want)), 0);
    assert_null(strchr(err, '\n'));
}

static bool has_note(const cs_scene *s, const char *text)
{
    for (int i = 0; i < s->nnotes; i++)
        if (strstr(s->notes[i], text))
            return true;
    return false;
}

#define GRID "cloths:\n  - grid: {resolution: [4, 4]}\n"

/* -------------------------------------------------------------- cloths */

static void test_cloth_from_file(void **state)
{
    (void)state;
    cs_scene *s = load_ok("cloths:\n"
                          "  - name: curtain\n"
                          "    mesh:\n"
                          "      file: " ASSET("curtain_open.gltf") "\n"
                          "      scale: [0.5, 1, 0.5]\n"
                          "      rotation: [0, 90, 0]\n"
                          "      translate: [0, 1, 0]\n"
                          "    material: {density: 0.2}\n",
                          0, NULL);
    const cs_trimesh *m = s->def.cloths[0].mesh;
    assert_int_equal(m->nt, 9216);
    assert_int_equal(m->nv, 4930);
    /* y (0.135 .. 2.964) is kept and lifted by 1; the 3.2 m width along x
     * is halved and turned onto z */
    double lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
    for (int i = 0; i < m->nv; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], m->x[3 * i + k]);
            hi[k] = fmax(hi[k], m->x[3 * i + k]);
        }
    assert_true(fabs(lo[1] - 1.135) < 2e-3 && fabs(hi[1] - 3.964) < 2e-3);
    assert_true(fabs(hi[2] - lo[2] - 1.604) < 2e-3);
    assert_true(has_note(s, "cloths[0] 'curtain': curtain_open.gltf"));
    assert_true(has_note(s, "9216 triangles"));
    /* it simulates */
    char err[256];
    cs_sim *sim = cs_sim_create(&s->def, err, sizeof err);
    assert_non_null(sim);
    cs_sim_destroy(sim);
    cs_scene_destroy(s);
}

/* A path is relative to the scene file's folder. */
static void test_relative_path(void **state)
{
    (void)state;
    char dir[300], path[400], err[1024];
    snprintf(dir, sizeof dir, "%s/scenes", tmpdir);
    mkdir(dir, 0777);
    snprintf(path, sizeof path, "%s/square.obj", tmpdir);
    FILE *f = fopen(path, "w");
    fputs("v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 3 4\n", f); /* a quad */
    fclose(f);
    snprintf(path, sizeof path, "%s/scene.yaml", dir);
    f = fopen(path, "w");
    fputs("cloths:\n  - mesh: {file: ../square.obj, units: cm}\n", f);
    fclose(f);
    cs_scene *s = NULL;
    assert_int_equal(cs_scene_load(path, 0, NULL, &s, err, sizeof err), CS_OK);
    assert_int_equal(s->def.cloths[0].mesh->nt, 2);   /* triangulated */
    assert_true(fabs(s->def.cloths[0].mesh->x[3] - 0.01) < 1e-12 ||
                fabs(s->def.cloths[0].mesh->x[6] - 0.01) < 1e-12);
    cs_scene_destroy(s);
}

/* -------------------------------------------------------------- bodies */

/* A scene with one mesh body, the unit sphere of ico4.obj centred at
 * (0, 1, 0), with the body keys in keys (indented lines). */
static void ball_scene(char *text, size_t size, const char *keys)
{
    snprintf(text, size,
             GRID "bodies:\n"
                  "  - name: ball\n"
                  "    shape: mesh\n"
                  "    mesh:\n"
                  "      file: %s\n"
                  "      translate: [-0.240, -0.180, -0.898]\n"
                  "    position: [0, 1, 0]\n"
                  "%s"
                  "levelset: {cache: %s/cache}\n",
             ASSET("ico4.obj"), keys, tmpdir);
}

static void test_mesh_body(void **state)
{
    (void)state;
    char text[2048];
    ball_scene(text, sizeof text, "    voxel_size: 0.1\n    band: 2\n    friction: 0.6\n");
    cs_scene *s = load_ok(text, 0, NULL);
    const cs_body_def *b = &s->def.bodies[0];
    const cs_scene_mesh_body *mb = &s->mesh_bodies[0];
    assert_int_equal(b->shape, CS_BODY_MESH);
    assert_non_null(b->phi_fn);
    assert_ptr_equal(b->phi_data, mb->levelset);
    assert_true(b->phi_bounded);
    assert_true(fabs(b->friction - 0.6) < 1e-12);
    assert_true(fabs(mb->voxel_size - 0.1) < 1e-12 && fabs(mb->band - 2) < 1e-12);
    assert_true(mb->fill_interior); /* auto: a small interior */
    assert_int_equal(mb->mesh->nt, 1280);
    assert_false(mb->from_cache);
    assert_non_null(mb->cache_path);
    struct stat st;
    assert_int_equal(stat(mb->cache_path, &st), 0);
    /* phi in the world: the sphere of radius 1 sits at (0, 1, 0) */
    double g[3], top[3] = {0, 2.05, 0}, centre[3] = {0, 1, 0};
    assert_true(fabs(cs_body_def_phi(b, 0, top, g) - 0.05) < 0.02);
    assert_true(g[1] > 0.99);
    assert_true(cs_body_def_phi(b, 0, centre, g) < -0.9);
    assert_true(has_note(s, "bodies[0] 'ball': ico4.obj"));
    assert_true(has_note(s, "cached as"));
    char path[1024];
    snprintf(path, sizeof path, "%s", mb->cache_path);
    cs_scene_destroy(s);

    /* again: the grid comes from the cache */
    s = load_ok(text, 0, NULL);
    assert_true(s->mesh_bodies[0].from_cache);
    assert_string_equal(s->mesh_bodies[0].cache_path, path);
    assert_true(has_note(s, "read from the cache"));
    cs_scene_destroy(s);

    /* an inline mesh body: a tetrahedron, default voxel; no cache */
    s = load_ok(GRID "bodies:\n"
                     "  - shape: mesh\n"
                     "    mesh:\n"
                     "      vertices: [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]\n"
                     "      triangles: [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]\n"
                     "levelset: {cache: none}\n",
                0, NULL);
    assert_non_null(s->def.bodies[0].phi_fn);
    assert_null(s->mesh_bodies[0].cache_path);
    double inside[3] = {0.1, 0.1, 0.1};
    assert_true(cs_body_def_phi(&s->def.bodies[0], 0, inside, g) < 0);
    cs_scene_destroy(s);
}

/* A collision offset wider than the narrow band: the grid reaches band
 * voxels past the offset surface, so collisions (phi - offset) read true
 * distances there. With the band alone (2 voxels of 0.05 m) phi read 0.1
 * beyond 0.1 m, and a point 0.25 m out was 0.05 m inside the 0.3 m offset
 * surface: B.4 moved such particles onto it in one step (the wardrobe at
 * 100,352 triangles: an 18 mm jump, then a runaway). */
static void test_offset_beyond_band(void **state)
{
    (void)state;
    char text[2048];
    ball_scene(text, sizeof text, "    voxel_size: 0.05\n    band: 2\n    collision_offset: 0.3\n");
    cs_scene *s = load_ok(text, 0, NULL);
    const cs_body_def *b = &s->def.bodies[0];
    const cs_scene_mesh_body *mb = &s->mesh_bodies[0];
    assert_true(fabs(mb->band - 2) < 1e-12);
    assert_true(fabs(mb->grid_band - 8) < 1e-12); /* 2 + 0.3 / 0.05 */
    assert_true(has_note(s, "(band 8"));
    /* the unit sphere at (0, 1, 0): points 0.25 m and 0.4 m out read their
     * distance (within a voxel's chord error), inside and outside the
     * offset surface respectively */
    double g[3], p1[3] = {0, 2.25, 0}, p2[3] = {0.4 + 1, 1, 0};
    double phi1 = cs_body_def_phi(b, 0, p1, g), phi2 = cs_body_def_phi(b, 0, p2, g);
    assert_true(fabs(phi1 - 0.25) < 0.02);
    assert_true(phi1 - b->offset < 0);
    assert_true(fabs(phi2 - 0.4) < 0.02);
    assert_true(phi2 - b->offset > 0);
    assert_true(g[0] > 0.99);
    cs_scene_destroy(s);
}

static void test_open_body_warns(void **state)
{
    (void)state;
    cs_scene *s = load_ok(GRID "bodies:\n"
                               "  - shape: mesh\n"
                               "    mesh: {file: " ASSET("sphereWithHole.stl") "}\n"
                               "    voxel_size: 0.1\n"
                               "levelset: {cache: none}\n",
                          0, NULL);
    assert_true(has_note(s, "warning: bodies[0] 'body0': the mesh is not closed"));
    assert_true(s->mesh_bodies[0].holes_closed >= 1);
    /* closed for the sign: the centre of the sphere (r 1.5) is inside */
    double c[3] = {1.5, 1.5, 1.5}, g[3];
    assert_true(cs_body_def_phi(&s->def.bodies[0], 0, c, g) < -1);
    cs_scene_destroy(s);

    s = load_ok(GRID "bodies:\n"
                     "  - shape: mesh\n"
                     "    mesh: {file: " ASSET("sphereWithHole.stl") "}\n"
                     "    voxel_size: 0.1\n"
                     "    close_holes: false\n"
                     "    interior: band\n"
                     "levelset: {cache: none}\n",
                0, NULL);
    assert_true(has_note(s, "close_holes is false"));
    assert_false(s->mesh_bodies[0].fill_interior);
    assert_int_equal(s->mesh_bodies[0].holes_closed, 0);
    cs_scene_destroy(s);
}

/* The default voxel follows the cloth: half its median edge. */
static void test_default_voxel(void **state)
{
    (void)state;
    cs_scene *s = load_ok("cloths:\n  - grid: {size: [2, 2], resolution: [25, 25]}\n"
                          "bodies:\n"
                          "  - shape: mesh\n"
                          "    mesh: {file: " ASSET("ico4.obj") "}\n"
                          "levelset: {cache: none}\n",
                          0, NULL);
    /* edges of 0.08 m (and diagonals of 0.113): median 0.08, half is 0.04 */
    assert_true(fabs(s->mesh_bodies[0].voxel_size - 0.04) < 1e-12);
    cs_scene_destroy(s);
}

static void test_override_scale(void **state)
{
    (void)state;
    const char *text = GRID "bodies:\n"
                            "  - shape: mesh\n"
                            "    mesh: {file: " ASSET("ico4.obj") ", scale: 1}\n"
                            "    voxel_size: 0.2\n"
                            "levelset: {cache: none}\n";
    const char *ov[] = {"bodies.0.mesh.scale=0.5"};
    cs_scene *s = load_ok(text, 1, ov);
    assert_true(fabs(s->mesh_bodies[0].report.max[1] - s->mesh_bodies[0].report.min[1] - 1) <
                1e-3);
    cs_scene_destroy(s);
    const char *bad[] = {"bodies.0.mesh.scale=[1, 0, 1]"};
    expect_error(text, 1, bad,
                 "--set bodies.0.mesh.scale=[1, 0, 1]: bodies[0].mesh.scale[1]: must be > 0 "
                 "(got 0)");
}

/* -------------------------------------------------------------- errors */

static void test_errors(void **state)
{
    (void)state;
    expect_error(GRID "bodies:\n  - shape: mesh\n", 0, NULL,
                 "scenes/a.yaml:4: bodies[0].mesh: is required for a mesh");
    expect_error(GRID "bodies:\n  - shape: sphere\n    radius: 1\n    mesh: {file: x.obj}\n", 0,
                 NULL, "scenes/a.yaml:6: bodies[0].mesh: is not used by a sphere (remove it)");
    expect_error(GRID "bodies:\n  - {shape: sphere, radius: 1, voxel_size: 0.1}\n", 0, NULL,
                 "scenes/a.yaml:4: bodies[0].voxel_size: is not used by a sphere (remove it)");
    expect_error(GRID "bodies:\n  - shape: mesh\n    radius: 1\n    mesh: {file: x.obj}\n", 0,
                 NULL, "scenes/a.yaml:5: bodies[0].radius: is not used by a mesh (remove it)");
    expect_error(GRID "bodies:\n  - shape: mesh\n    mesh: {file: missing.obj}\n", 0, NULL,
                 "scenes/a.yaml:5: bodies[0].mesh.file: cannot read scenes/missing.obj: No such "
                 "file or directory");
    expect_error("cloths:\n  - mesh: {file: x.obj, vertices: [[0, 0, 0]]}\n", 0, NULL,
                 "scenes/a.yaml:2: cloths[0].mesh: expected exactly one of file or vertices "
                 "(got both)");
    expect_error("cloths:\n  - mesh: {scale: 2}\n", 0, NULL,
                 "scenes/a.yaml:2: cloths[0].mesh: expected exactly one of file or vertices "
                 "(got neither)");
    expect_error("cloths:\n  - mesh: {vertices: [[0, 0, 0]], node: a}\n", 0, NULL,
                 "scenes/a.yaml:2: cloths[0].mesh.node: is only used with file (remove it)");
    expect_error("cloths:\n  - mesh:\n      file: x.obj\n      triangles: [[0, 1, 2]]\n", 0, NULL,
                 "scenes/a.yaml:4: cloths[0].mesh.triangles: is only used with vertices (remove "
                 "it or the file)");
    expect_error("cloths:\n  - mesh: {file: x.obj, units: furlong}\n", 0, NULL,
                 "scenes/a.yaml:2: cloths[0].mesh.units: expected one of auto, m, cm, mm, km, in, "
                 "ft (got furlong)");
    expect_error("cloths:\n  - mesh: {vertices: [[0, 0, 0]], scale: 0}\n", 0, NULL,
                 "scenes/a.yaml:2: cloths[0].mesh.scale: must be > 0 (got 0)");
    expect_error("cloths:\n  - mesh: {vertices: [[0, 0, 0]], scale: big}\n", 0, NULL,
                 "scenes/a.yaml:2: cloths[0].mesh.scale: expected a number > 0 or a list of 3 "
                 "numbers > 0 (got big)");
    expect_error("cloths:\n  - mesh: {vertices: [[0, 0, 0]], scale: [1, 2]}\n", 0, NULL,
                 "scenes/a.yaml:2: cloths[0].mesh.scale: expected a number > 0 or a list of 3 "
                 "numbers > 0 (got a list of 2)");
    expect_error("cloths:\n  - mesh:\n      vertices: [[0, 0, 0]]\n      scale: [1, x, 1]\n", 0,
                 NULL, "scenes/a.yaml:4: cloths[0].mesh.scale[1]: expected a number > 0 (got x)");
    expect_error(GRID "bodies:\n  - shape: mesh\n    mesh: {file: " ASSET("ico4.obj")
                      ", node: lid}\n",
                 0, NULL,
                 "scenes/a.yaml:5: bodies[0].mesh.node: " ASSET("ico4.obj") " has no node or "
                 "mesh named 'lid' with triangles (it has: ico4.obj, Icosphere_Icosphere.001, "
                 "Icosphere_Icosphere.001)");
    const char *ico = GRID "bodies:\n  - shape: mesh\n    mesh: {file: " ASSET("ico4.obj") "}\n";
    char text[1024];
    snprintf(text, sizeof text, "%s    voxel_size: 0\n", ico);
    expect_error(text, 0, NULL, "scenes/a.yaml:6: bodies[0].voxel_size: must be > 0 (got 0)");
    snprintf(text, sizeof text, "%s    voxel_size: 1\n", ico);
    expect_error(text, 0, NULL,
                 "scenes/a.yaml:6: bodies[0].voxel_size: must be at most a quarter of the mesh's "
                 "largest extent, 2 m, or the grid could not tell its shape (got 1)");
    snprintf(text, sizeof text, "%s    voxel_size: 1e-5\n", ico);
    expect_error_prefix(text, "scenes/a.yaml:6: bodies[0].voxel_size: would need about ");
    snprintf(text, sizeof text, "%s    band: 0.5\n", ico);
    expect_error(text, 0, NULL, "scenes/a.yaml:6: bodies[0].band: must be in [1, 1000] (got 0.5)");
    snprintf(text, sizeof text, "%s    interior: hollow\n", ico);
    expect_error(text, 0, NULL,
                 "scenes/a.yaml:6: bodies[0].interior: expected one of auto, fill, band (got "
                 "hollow)");
    expect_error(GRID "levelset: {cache: ''}\n", 0, NULL,
                 "scenes/a.yaml:3: levelset.cache: must not be empty (none turns the cache off)");

    /* bad files: corrupt, without triangles, NaN */
    char path[400];
    snprintf(path, sizeof path, "%s/nan.obj", tmpdir);
    FILE *f = fopen(path, "w");
    fputs("v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n", f);
    fclose(f);
    snprintf(text, sizeof text, "cloths:\n  - mesh: {file: %s}\n", path);
    char want[1024];
    snprintf(want, sizeof want,
             "scenes/a.yaml:2: cloths[0].mesh.file: %s: vertex 1 has a non-finite coordinate "
             "(NaN or infinity)",
             path);
    expect_error(text, 0, NULL, want);
    snprintf(path, sizeof path, "%s/points.obj", tmpdir);
    f = fopen(path, "w");
    fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\np 1\np 2\n", f);
    fclose(f);
    snprintf(text, sizeof text, GRID "bodies:\n  - shape: mesh\n    mesh: {file: %s}\n", path);
    snprintf(want, sizeof want, "scenes/a.yaml:5: bodies[0].mesh.file: %s holds no triangles",
             path);
    expect_error_prefix(text, want);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cloth_from_file),
        cmocka_unit_test(test_relative_path),
        cmocka_unit_test(test_mesh_body),
        cmocka_unit_test(test_offset_beyond_band),
        cmocka_unit_test(test_open_body_warns),
        cmocka_unit_test(test_default_voxel),
        cmocka_unit_test(test_override_scale),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
