/* test_scene.c: the YAML scene loader (import/scene_*.c, from the table of
 * keys import/scene_keys.def): values and defaults of a converted scene,
 * selections, files, the shipped scenes and the example in
 * docs/scene-reference.md. Its error messages and --set overrides:
 * test_scene_errors.c. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <glob.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "import/import.h"
#include "sim/internal.h"
#include "tests/scene_load.h"

#define EPS 1e-12
#define H 0.70710678118654752440   /* sqrt(1/2) */

/* ------------------------------------------------------------- helpers */

static void assert_quat(const double *q, double w, double x, double y, double z)
{
    assert_true(fabs(q[0] - w) < 1e-9);
    assert_true(fabs(q[1] - x) < 1e-9);
    assert_true(fabs(q[2] - y) < 1e-9);
    assert_true(fabs(q[3] - z) < 1e-9);
}

/* v rotated by the unit quaternion q, computed independently of the loader
 * (through the rotation matrix). */
static void rotate(const double q[4], const double v[3], double out[3])
{
    double w = q[0], x = q[1], y = q[2], z = q[3];
    double R[9] = {
        1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
        2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
        2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y),
    };
    for (int i = 0; i < 3; i++)
        out[i] = R[3 * i] * v[0] + R[3 * i + 1] * v[1] + R[3 * i + 2] * v[2];
}

/* ------------------------------------------------- a scene with everything */

static const char *full_scene =
    "name: full\n"
    "description: every feature at once\n"
    "time:\n"
    "  fps: 30\n"
    "  frames: 12\n"
    "  dt: 0.002\n"
    "  dt_safety: 0.25\n"
    "  collision_steps: 8\n"
    "  cg_tolerance: 1e-4\n"
    "  cg_max_iterations: 50\n"
    "gravity: [0, 0, -9.81]\n"
    "effects:\n"
    "  bodies: true\n"
    "  wind: true\n"
    "  self_collision: true\n"
    "  friction: projection\n"
    "wind:\n"
    "  velocity: [1, 0, 0]\n"
    "  drag: 0.5\n"
    "  gust: 0.3\n"
    "  gust_length: 0.4\n"
    "  gust_period: 0.7\n"
    "output:\n"
    "  format: glb\n"
    "camera:\n"
    "  position: [0, 1, 5]\n"
    "  target: [0, 0.5, 0]\n"
    "  up: [0, 0, 1]\n"
    "  fov: 35\n"
    "  motion: {keys: [{time: 0}, {time: 2, translate: [1, 0, 0], rotate: [0, 90, 0]}]}\n"
    "cloths:\n"
    "  - name: sheet\n"
    "    color: [0.1, 0.2, 0.3]\n"
    "    grid:\n"
    "      size: [1, 1]\n"
    "      resolution: [4, 4]\n"
    "      center: [0, 1, 0]\n"
    "      rotation: [0, 0, 0]\n"
    "    material:\n"
    "      edge_stiffness: 5\n"
    "      node_mass: 2e-6\n"
    "    velocity: [0, -1, 0]\n"
    "    pins:\n"
    "      - box: {min: [-0.6, 0.5, -0.6], max: [-0.2, 1.5, 0.6]}\n"
    "      - grid_points: [[4, 4]]\n"
    "    scripts:\n"
    "      - select: {vertices: [12]}\n"
    "        motion:\n"
    "          keys:\n"
    "            - {time: 0}\n"
    "            - {time: 1, translate: [0, 0.5, 0], rotate: [0, 0, 90]}\n"
    "      - select: {grid_points: [[4, 0]]}\n"
    "        pivot: [0, 0, 0]\n"
    "        motion: {angular_velocity: [0, 1, 0]}\n"
    "  - name: patch\n"
    "    mesh:\n"
    "      vertices: [[0, 0, 0], [1, 0, 0], [0, 0, 1]]\n"
    "      triangles: [[0, 1, 2]]\n"
    "      rotation: [0, 0, 90]\n"
    "      translate: [1, 0, 0]\n"
    "    material: {density: 0.2}\n"
    "bodies:\n"
    "  - name: ball\n"
    "    shape: sphere\n"
    "    position: [1, 2, 3]\n"
    "    rotation: [90, 0, 0]\n"
    "    radius: 0.5\n"
    "    friction: 0.9\n"
    "    color: [1, 0, 0]\n"
    "    motion:\n"
    "      keys:\n"
    "        - {time: 0}\n"
    "        - {time: 1, translate: [1, 0, 0], rotate: [0, 90, 0]}\n"
    "  - name: wall\n"
    "    shape: plane\n"
    "    normal: [1, 0, 0]\n"
    "  - shape: box\n"
    "    size: [2, 4, 6]\n"
    "    motion: {velocity: [0, 1, 0]}\n"
    "  - shape: cylinder\n"
    "    radius: 0.25\n"
    "    height: 3\n"
    "    rotation: [90, 0, 90]\n";

static void test_full_scene_values(void **state)
{
    (void)state;
    cs_scene *s = load_ok(full_scene, 0, NULL);
    const cs_sim_def *d = &s->def;

    assert_string_equal(s->name, "full");
    assert_string_equal(s->path, "scenes/a.yaml");
    assert_int_equal(s->frames, 12);
    assert_string_equal(s->output_format, "glb");
    assert_true(s->camera.given);
    assert_vec(s->camera.position, 0, 1, 5);
    assert_vec(s->camera.target, 0, 0.5, 0);
    assert_vec(s->camera.up, 0, 0, 1);
    assert_true(fabs(s->camera.fov_degrees - 35) < EPS);
    /* the camera's motion: its frame starts at the target, unrotated */
    assert_int_equal(s->camera.motion.kind, CS_MOTION_KEYFRAMES);
    assert_int_equal(s->camera.motion.nkeys, 2);
    assert_vec(s->camera.motion.position, 0, 0.5, 0);
    assert_vec(s->camera.motion.keys[1].position, 1, 0.5, 0);
    assert_true(fabs(s->camera.motion.keys[1].rotation[0] - sqrt(0.5)) < EPS &&
                fabs(s->camera.motion.keys[1].rotation[2] - sqrt(0.5)) < EPS);
    assert_true(fabs(d->wind.gust - 0.3) < EPS && fabs(d->wind.gust_length - 0.4) < EPS &&
                fabs(d->wind.gust_period - 0.7) < EPS);

    assert_true(fabs(d->fps - 30) < EPS);
    assert_true(fabs(d->dt - 0.002) < EPS);
    assert_true(fabs(d->dt_safety - 0.25) < EPS);
    assert_int_equal(d->collision_steps, 8);
    assert_true(fabs(d->cg_tolerance - 1e-4) < EPS);
    assert_int_equal(d->cg_max_iterations, 50);
    assert_vec(d->gravity, 0, 0, -9.81);
    assert_true(d->bodies_enabled);
    assert_true(d->wind_enabled);
    assert_true(d->self_collision);
    assert_int_equal(d->friction_method, CS_FRICTION_PROJECTION);
    assert_vec(d->wind.velocity, 1, 0, 0);
    assert_true(fabs(d->wind.drag - 0.5) < EPS);

    /* cloth 0: a 4 x 4 grid at height 1 */
    assert_int_equal(d->ncloths, 2);
    const cs_cloth_def *c = &d->cloths[0];
    assert_string_equal(c->name, "sheet");
    assert_vec(s->cloth_colors, 0.1, 0.2, 0.3);
    assert_int_equal(c->mesh->nv, 25);
    assert_int_equal(c->mesh->nt, 32);
    assert_vec(c->mesh->x + 3 * 12, 0, 1, 0);
    cs_cloth_material m0 = cs_default_cloth_material();
    assert_true(fabs(c->material.edge_stiffness - 5) < EPS);
    assert_true(fabs(c->material.node_mass - 2e-6) < EPS);
    assert_true(c->material.edge_overdamping == m0.edge_overdamping);
    assert_true(c->material.bend_stiffness == m0.bend_stiffness);
    assert_true(c->material.bend_overdamping == m0.bend_overdamping);
    assert_true(c->material.density == m0.density);
    assert_vec(c->velocity, 0, -1, 0);

    /* pins merged into one static script: the box takes the columns
     * i = 0, 1 (x = -0.5, -0.25) of every row, grid point (4, 4) is 24 */
    assert_int_equal(c->nscripts, 3);
    const cs_vertex_script *pin = &c->scripts[0];
    static const int pinned[] = {0, 1, 5, 6, 10, 11, 15, 16, 20, 21, 24};
    assert_int_equal(pin->nvertices, 11);
    for (int i = 0; i < 11; i++)
        assert_int_equal(pin->vertices[i], pinned[i]);
    assert_int_equal(pin->motion.kind, CS_MOTION_STATIC);
    assert_quat(pin->motion.rotation, 1, 0, 0, 0);

    /* script 0: keys relative to the pivot, which defaults to the centroid
     * of the selection (vertex 12 at (0, 1, 0)) */
    const cs_vertex_script *sc = &c->scripts[1];
    assert_int_equal(sc->nvertices, 1);
    assert_int_equal(sc->vertices[0], 12);
    assert_int_equal(sc->motion.kind, CS_MOTION_KEYFRAMES);
    assert_vec(sc->motion.position, 0, 1, 0);
    assert_quat(sc->motion.rotation, 1, 0, 0, 0);
    assert_int_equal(sc->motion.nkeys, 2);
    assert_true(sc->motion.keys[0].time == 0);
    assert_vec(sc->motion.keys[0].position, 0, 1, 0);
    assert_quat(sc->motion.keys[0].rotation, 1, 0, 0, 0);
    assert_true(sc->motion.keys[1].time == 1);
    assert_vec(sc->motion.keys[1].position, 0, 1.5, 0);
    assert_quat(sc->motion.keys[1].rotation, H, 0, 0, H);

    /* script 1: grid point (4, 0) is vertex 4, constant spin about a pivot */
    sc = &c->scripts[2];
    assert_int_equal(sc->nvertices, 1);
    assert_int_equal(sc->vertices[0], 4);
    assert_int_equal(sc->motion.kind, CS_MOTION_CONSTANT);
    assert_vec(sc->motion.position, 0, 0, 0);
    assert_vec(sc->motion.velocity, 0, 0, 0);
    assert_vec(sc->motion.angular_velocity, 0, 1, 0);

    /* cloth 1: inline mesh turned 90 degrees about z, then moved */
    c = &d->cloths[1];
    assert_string_equal(c->name, "patch");
    assert_vec(s->cloth_colors + 3, 0.8, 0.3, 0.2);
    assert_int_equal(c->mesh->nv, 3);
    assert_int_equal(c->mesh->nt, 1);
    assert_vec(c->mesh->x, 1, 0, 0);
    assert_vec(c->mesh->x + 3, 1, 1, 0);
    assert_vec(c->mesh->x + 6, 1, 0, 1);
    assert_int_equal(c->mesh->tri[2], 2);
    assert_true(fabs(c->material.density - 0.2) < EPS);
    assert_int_equal(c->nscripts, 0);

    /* bodies */
    assert_int_equal(d->nbodies, 4);
    const cs_body_def *b = &d->bodies[0];
    assert_string_equal(b->name, "ball");
    assert_int_equal(b->shape, CS_BODY_SPHERE);
    assert_true(fabs(b->radius - 0.5) < EPS);
    assert_true(fabs(b->friction - 0.9) < EPS);
    assert_vec(s->body_colors, 1, 0, 0);
    assert_int_equal(b->motion.kind, CS_MOTION_KEYFRAMES);
    assert_vec(b->motion.position, 1, 2, 3);
    assert_quat(b->motion.rotation, H, H, 0, 0);   /* 90 degrees about x */
    assert_int_equal(b->motion.nkeys, 2);
    assert_vec(b->motion.keys[0].position, 1, 2, 3);
    assert_quat(b->motion.keys[0].rotation, H, H, 0, 0);
    /* key 1: translate relative to the position, rotate applied after the
     * initial rotation: Ry(90) Rx(90) takes +y to +x */
    assert_vec(b->motion.keys[1].position, 2, 2, 3);
    assert_quat(b->motion.keys[1].rotation, 0.5, 0.5, 0.5, -0.5);
    double out[3];
    static const double y_axis[3] = {0, 1, 0};
    rotate(b->motion.keys[1].rotation, y_axis, out);
    assert_vec(out, 1, 0, 0);

    b = &d->bodies[1];   /* plane by its normal: +y onto +x */
    assert_string_equal(b->name, "wall");
    assert_int_equal(b->shape, CS_BODY_PLANE);
    assert_int_equal(b->motion.kind, CS_MOTION_STATIC);
    rotate(b->motion.rotation, y_axis, out);
    assert_vec(out, 1, 0, 0);
    assert_true(fabs(b->friction - cs_default_body_def().friction) < EPS);
    assert_vec(s->body_colors + 3, 0.7, 0.7, 0.7);

    b = &d->bodies[2];
    assert_string_equal(b->name, "body2");
    assert_int_equal(b->shape, CS_BODY_BOX);
    assert_vec(b->half_extents, 1, 2, 3);
    assert_int_equal(b->motion.kind, CS_MOTION_CONSTANT);
    assert_vec(b->motion.velocity, 0, 1, 0);
    assert_vec(b->motion.angular_velocity, 0, 0, 0);

    /* Euler order: R = Rz(90) Rx(90) takes +y to +z (Rx Rz would give -x) */
    b = &d->bodies[3];
    assert_int_equal(b->shape, CS_BODY_CYLINDER);
    assert_true(fabs(b->radius - 0.25) < EPS);
    assert_true(fabs(b->half_height - 1.5) < EPS);
    rotate(b->motion.rotation, y_axis, out);
    assert_vec(out, 0, 0, 1);
    assert_quat(b->motion.rotation, 0.5, 0.5, 0.5, 0.5);

    cs_scene_destroy(s);
}

static void test_defaults(void **state)
{
    (void)state;
    char err[256];
    cs_scene *s = NULL;
    assert_int_equal(cs_scene_load_string("cloths: [{grid: {}}]\n", NULL, 0, NULL, &s, err,
                                          sizeof err),
                     CS_OK);
    cs_sim_def def = cs_default_sim_def();
    assert_string_equal(s->name, "scene");
    assert_string_equal(s->path, "<string>");
    assert_int_equal(s->frames, 48);
    assert_string_equal(s->output_format, "ply");
    assert_false(s->camera.given);
    assert_vec(s->camera.up, 0, 1, 0);
    assert_true(s->camera.fov_degrees == 40);
    assert_true(s->def.fps == def.fps && def.fps == 24);
    assert_true(s->def.dt == 0);
    assert_true(s->def.dt_safety == def.dt_safety);
    assert_int_equal(s->def.collision_steps, def.collision_steps);
    assert_true(s->def.cg_tolerance == def.cg_tolerance);
    assert_int_equal(s->def.cg_max_iterations, def.cg_max_iterations);
    assert_vec(s->def.gravity, 0, -9.8, 0);
    assert_true(s->def.bodies_enabled);
    assert_false(s->def.wind_enabled);
    assert_false(s->def.self_collision);
    assert_int_equal(s->def.friction_method, CS_FRICTION_IMPROVED);
    assert_int_equal(s->def.nbodies, 0);
    assert_null(s->body_colors);
    assert_int_equal(s->def.ncloths, 1);
    const cs_cloth_def *c = &s->def.cloths[0];
    assert_string_equal(c->name, "cloth0");
    assert_int_equal(c->mesh->nv, 21 * 21);     /* 20 x 20 quads */
    assert_vec(c->mesh->x, -0.5, 0, -0.5);       /* 1 x 1 m at the origin */
    assert_vec(c->mesh->x + 3 * (21 * 21 - 1), 0.5, 0, 0.5);
    assert_vec(s->cloth_colors, 0.8, 0.3, 0.2);
    assert_vec(c->velocity, 0, 0, 0);
    assert_int_equal(c->nscripts, 0);
    assert_true(c->material.node_mass == cs_default_cloth_material().node_mass);
    cs_scene_destroy(s);

    /* origin names the scene by its stem; "auto" is dt = 0 */
    s = load_ok("cloths: [{grid: {}}]\ntime: {dt: auto}\n", 0, NULL);
    assert_string_equal(s->name, "a");
    assert_true(s->def.dt == 0);
    cs_scene_destroy(s);

    cs_scene_destroy(NULL);
}

/* An explicit 0 or false is not the same as leaving the key out. */
static void test_explicit_zero_is_not_absent(void **state)
{
    (void)state;
    cs_scene *s = load_ok("cloths: [{grid: {}}]\n"
                          "time: {frames: 0}\n"
                          "effects: {bodies: false, wind: true}\n"
                          "wind: {velocity: [1, 0, 0], drag: 0}\n"
                          "bodies: [{shape: plane, friction: 0}]\n",
                          0, NULL);
    assert_int_equal(s->frames, 0);
    assert_false(s->def.bodies_enabled);
    assert_false(s->def.wind_enabled);   /* drag 0: nothing to do */
    assert_true(s->def.bodies[0].friction == 0);
    cs_scene_destroy(s);

    s = load_ok("cloths: [{grid: {}}]\neffects: {wind: false}\nwind: {drag: 2}\n", 0, NULL);
    assert_false(s->def.wind_enabled);
    assert_true(s->def.wind.drag == 2);
    cs_scene_destroy(s);
    s = load_ok("cloths: [{grid: {}}]\nwind: {drag: 2}\n", 0, NULL);
    assert_true(s->def.wind_enabled);
    cs_scene_destroy(s);
}

static void test_selections(void **state)
{
    (void)state;
    /* A 2 x 2 grid (vertices 0..8): the box picks the middle row, the
     * lists pick their vertices once each. */
    cs_scene *s = load_ok("cloths:\n"
                          "  - grid: {resolution: [2, 2]}\n"
                          "    pins:\n"
                          "      - box: {min: [-1, -1, -0.1], max: [1, 1, 0.1]}\n"
                          "      - vertices: [0, 0, 2]\n"
                          "    scripts:\n"
                          "      - select: {grid_points: [[0, 2], [2, 2]]}\n"
                          "        motion: {velocity: [0, 1, 0]}\n",
                          0, NULL);
    const cs_cloth_def *c = &s->def.cloths[0];
    assert_int_equal(c->nscripts, 2);
    static const int pinned[] = {0, 2, 3, 4, 5};
    assert_int_equal(c->scripts[0].nvertices, 5);
    for (int i = 0; i < 5; i++)
        assert_int_equal(c->scripts[0].vertices[i], pinned[i]);
    assert_int_equal(c->scripts[1].nvertices, 2);
    assert_int_equal(c->scripts[1].vertices[0], 6);
    assert_int_equal(c->scripts[1].vertices[1], 8);
    assert_vec(c->scripts[1].motion.position, 0, 0, 0.5);   /* centroid */
    assert_int_equal(c->scripts[1].motion.kind, CS_MOTION_CONSTANT);
    cs_scene_destroy(s);

    /* box bounds are inclusive: a flat box on the sheet's plane, its edges
     * through vertices (grid coordinates are exact here) */
    s = load_ok("cloths:\n"
                "  - grid: {resolution: [2, 2]}\n"
                "    pins: [{box: {min: [-0.5, 0, -0.5], max: [0, 0, 0.5]}}]\n",
                0, NULL);
    c = &s->def.cloths[0];
    static const int boxed[] = {0, 1, 3, 4, 6, 7};
    assert_int_equal(c->scripts[0].nvertices, 6);
    for (int i = 0; i < 6; i++)
        assert_int_equal(c->scripts[0].vertices[i], boxed[i]);
    cs_scene_destroy(s);
}

/* The smallest scene, two lines. */
static const char *grid2 = "cloths:\n  - grid: {resolution: [2, 2]}\n";

/* --------------------------------------------------------------- files */

static void test_files(void **state)
{
    (void)state;
    char dir[] = "/tmp/cs_test_scene_XXXXXX", path[256], err[512];
    cs_scene *s = NULL;
    assert_non_null(mkdtemp(dir));

    snprintf(path, sizeof path, "%s/missing.yaml", dir);
    assert_int_equal(cs_scene_load(path, 0, NULL, &s, err, sizeof err), CS_ERR_BAD_INPUT);
    assert_null(s);
    char want[512];
    snprintf(want, sizeof want, "%s: cannot read: No such file or directory", path);
    assert_string_equal(err, want);

    /* a directory opens but does not read */
    assert_int_equal(cs_scene_load(dir, 0, NULL, &s, err, sizeof err), CS_ERR_BAD_INPUT);
    snprintf(want, sizeof want, "%s: cannot read: Is a directory", dir);
    assert_string_equal(err, want);

    snprintf(path, sizeof path, "%s/my_scene.yaml", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("cloths:\n  - grid: {resolution: [2, 2]}\n", f);
    fclose(f);
    assert_int_equal(cs_scene_load(path, 0, NULL, &s, err, sizeof err), CS_OK);
    assert_string_equal(s->name, "my_scene");   /* the file's stem */
    assert_string_equal(s->path, path);
    cs_scene_destroy(s);

    f = fopen(path, "w");
    assert_non_null(f);
    fputs("cloths:\n  - grid: {resolution: [2, 2]}\nbodies:\n  - shape: sphere\n    radius: 0\n",
          f);
    fclose(f);
    assert_int_equal(cs_scene_load(path, 0, NULL, &s, err, sizeof err), CS_ERR_BAD_INPUT);
    snprintf(want, sizeof want, "%s:5: bodies[0].radius: must be > 0 (got 0)", path);
    assert_string_equal(err, want);

    unlink(path);
    rmdir(dir);
}

/* Every shipped scene loads. */
static void test_shipped_scenes(void **state)
{
    (void)state;
    glob_t g;
    char err[512];
    if (glob(CS_SOURCE_DIR "/scenes/*.yaml", 0, NULL, &g) != 0) {
        skip();
        return;
    }
    for (size_t i = 0; i < g.gl_pathc; i++) {
        cs_scene *s = NULL;
        int rc = cs_scene_load(g.gl_pathv[i], 0, NULL, &s, err, sizeof err);
        if (rc != CS_OK)
            print_error("%s\n", err);
        assert_int_equal(rc, CS_OK);
        cs_scene_destroy(s);
    }
    globfree(&g);
}

/* The complete example of docs/scene-reference.md loads (the first yaml
 * block after the "## Complete example" heading), and the simulation
 * accepts what it becomes. */
static void test_reference_example(void **state)
{
    (void)state;
    FILE *f = fopen(CS_SOURCE_DIR "/docs/scene-reference.md", "r");
    assert_non_null(f);
    char line[1024], text[16384] = "";
    size_t used = 0;
    int phase = 0;   /* 0: before the heading, 1: before the fence, 2: in it */
    while (phase < 3 && fgets(line, sizeof line, f)) {
        if (phase == 0 && !strncmp(line, "## Complete example", 19))
            phase = 1;
        else if (phase == 1 && !strncmp(line, "```yaml", 7))
            phase = 2;
        else if (phase == 2 && !strncmp(line, "```", 3))
            phase = 3;
        else if (phase == 2 && used + strlen(line) < sizeof text)
            used += (size_t)sprintf(text + used, "%s", line);
    }
    fclose(f);
    assert_int_equal(phase, 3);
    cs_scene *s = load_ok(text, 0, NULL);
    assert_true(s->def.ncloths >= 1);
    char err[256] = "";
    cs_sim *sim = cs_sim_create(&s->def, err, sizeof err);
    if (!sim)
        print_error("cs_sim_create: %s\n", err);
    assert_non_null(sim);
    cs_sim_destroy(sim);
    cs_scene_destroy(s);
}

/* ---------------------------------------------------- friction schedules */

/* bodies[].friction_keys: the keys as loaded, and no friction key beside. */
static void test_friction_keys_loaded(void **state)
{
    (void)state;
    char text[512];
    snprintf(text, sizeof text, "%s%s", grid2,
             "bodies:\n"
             "  - shape: plane\n"
             "    friction_keys:\n"
             "      - {time: 0, friction: 0.8}\n"
             "      - {time: 1.5, friction: 0.05}\n"
             "  - shape: sphere\n"
             "    radius: 1\n"
             "    friction: 0.4\n");
    cs_scene *s = load_ok(text, 0, NULL);
    const cs_body_def *b = s->def.bodies;
    assert_int_equal(b[0].nfriction_keys, 2);
    assert_true(b[0].friction_keys[0].time == 0 && b[0].friction_keys[0].friction == 0.8);
    assert_true(b[0].friction_keys[1].time == 1.5 && b[0].friction_keys[1].friction == 0.05);
    assert_true(fabs(cs_body_def_friction(&b[0], 0.75) - 0.425) < EPS);
    assert_int_equal(b[1].nfriction_keys, 0);
    assert_true(cs_body_def_friction(&b[1], 3) == 0.4);
    cs_scene_destroy(s);
    /* an override replaces the schedule like any list */
    const char *ov[] = {"bodies.0.friction_keys=[{time: 2, friction: 0}]"};
    s = load_ok(text, 1, ov);
    assert_int_equal(s->def.bodies[0].nfriction_keys, 1);
    assert_true(cs_body_def_friction(&s->def.bodies[0], 0) == 0);
    cs_scene_destroy(s);
}
/* --skip PATTERN: all cases but those PATTERN matches (cmocka's * and ?
 * wildcards); a build without assimp or OpenVDB skips test_shipped_scenes,
 * some of whose scenes have mesh cloths and bodies (tests/CMakeLists.txt). */
int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "--skip") == 0) {
        cmocka_set_skip_filter(argv[2]);
    } else if (argc != 1) {
        fprintf(stderr, "usage: %s [--skip PATTERN]\n", argv[0]);
        return 2;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_full_scene_values),
        cmocka_unit_test(test_defaults),
        cmocka_unit_test(test_explicit_zero_is_not_absent),
        cmocka_unit_test(test_selections),
        cmocka_unit_test(test_files),
        cmocka_unit_test(test_shipped_scenes),
        cmocka_unit_test(test_reference_example),
        cmocka_unit_test(test_friction_keys_loaded),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
