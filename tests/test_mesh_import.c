/* test_mesh_import.c: mesh files through assimp (import/mesh_import.c):
 * every format of the issue on the real meshes of the repository's assets/
 * folder, checked against the counts of its MANIFEST.md; node selection
 * and merging, units and placement; repairs and topology; hole closing; and
 * bad input, which must be a clear message, never a crash, a hang or an
 * empty mesh (tests/data/bad_meshes/).
 *
 * The meshes come from the repository's assets/ folder (CS_ASSETS_DIR);
 * without them the tests fail, they do not skip. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "import/import.h"
#include "tests/tmpdir.h"

#ifndef CS_ASSETS_DIR
#error "CS_ASSETS_DIR must name the repository's assets/ folder (tests/CMakeLists.txt defines it)"
#endif

static void asset(char *out, size_t len, const char *name)
{
    snprintf(out, len, "%s/%s", CS_ASSETS_DIR, name);
    if (access(out, R_OK) != 0) {
        print_error("missing test asset %s: the repository's assets/ folder is incomplete\n",
                    out);
        fail();
    }
}

static cs_trimesh *import_ok(const char *name, const cs_mesh_placement *pl, cs_mesh_report *r)
{
    char path[1024], err[512];
    asset(path, sizeof path, name);
    cs_trimesh *m = NULL;
    int rc = cs_mesh_import(path, pl, &m, r, err, sizeof err);
    if (rc != CS_OK)
        print_error("%s\n", err);
    assert_int_equal(rc, CS_OK);
    assert_non_null(m);
    assert_int_equal(m->nv, r->vertices);
    assert_int_equal(m->nt, r->triangles);
    return m;
}

static void assert_near(double got, double want, double tol)
{
    if (!(fabs(got - want) <= tol))
        print_error("got %.6g, want %.6g (+- %g)\n", got, want, tol);
    assert_true(fabs(got - want) <= tol);
}

/* Euler characteristic V - E + F of a mesh without boundary: 2 - 2 genus. */
static long edges_of(const cs_mesh_report *r)
{
    return (3L * r->triangles + r->boundary_edges) / 2;
}

/* ----------------------------------------------------------- formats */

static void test_obj(void **state)
{
    (void)state;
    cs_mesh_report r;
    cs_trimesh *m = import_ok("ico4.obj", NULL, &r);
    assert_int_equal(r.triangles, 1280);
    assert_int_equal(r.vertices, 642);
    assert_true(r.closed);
    assert_int_equal(r.parts, 1);
    assert_int_equal(r.vertices - edges_of(&r) + r.triangles, 2); /* a sphere */
    assert_near(0.5 * (r.min[0] + r.max[0]), 0.240, 1e-3);
    assert_near(0.5 * (r.min[2] + r.max[2]), 0.898, 1e-3);
    assert_near(r.max[1] - r.min[1], 2.0, 1e-3);
    assert_non_null(strstr(r.format, "Wavefront"));
    cs_trimesh_destroy(m);

    m = import_ok("stanford-bunny.obj", NULL, &r);
    assert_int_equal(r.triangles, 69451);
    assert_int_equal(r.vertices, 34834);        /* the referenced ones of 35,947 */
    assert_int_equal(r.boundary_edges, 223);
    assert_int_equal(r.boundary_loops, 5);
    assert_int_equal(r.nonmanifold_edges, 0);
    assert_int_equal(r.vertices - edges_of(&r) + r.triangles, -3);
    assert_false(r.closed);
    cs_trimesh_destroy(m);
}

static void test_ply_ascii_and_binary(void **state)
{
    (void)state;
    cs_mesh_report r, r2;
    cs_trimesh *m = import_ok("Wuson.ply", NULL, &r);   /* ascii, unwelded */
    assert_int_equal(r.triangles, 3732);
    assert_int_equal(r.vertices, 2117);
    assert_int_equal(r.welded_vertices, 11184 - 2117);
    assert_int_equal(r.parts, 51);
    assert_int_equal(r.boundary_edges, 412);
    assert_near(r.max[1] - r.min[1], 1.516, 2e-3);

    /* binary PLY (and glTF binary) written by clothsim read back the same */
    const char *formats[] = {"ply", "glb"};
    for (int f = 0; f < 2; f++) {
        char path[512], err[512];
        snprintf(path, sizeof path, "%s/wuson.%s", tmpdir, formats[f]);
        cs_mesh_format fmt;
        assert_true(cs_mesh_format_from_name(formats[f], &fmt));
        cs_mesh_view view = {"wuson", m->nv, m->x, m->nt, m->tri};
        assert_int_equal(cs_mesh_write(path, fmt, 1, &view, err, sizeof err), CS_OK);
        cs_trimesh *back = NULL;
        assert_int_equal(cs_mesh_import(path, NULL, &back, &r2, err, sizeof err), CS_OK);
        assert_int_equal(r2.triangles, r.triangles);
        assert_int_equal(r2.vertices, r.vertices);
        assert_int_equal(r2.boundary_edges, r.boundary_edges);
        for (int k = 0; k < 3; k++)
            assert_near(r2.min[k], r.min[k], 1e-5);
        cs_trimesh_destroy(back);
    }
    cs_trimesh_destroy(m);
}

static void test_stl_ascii_and_binary(void **state)
{
    (void)state;
    cs_mesh_report r;
    /* binary, though its 80-byte header starts with "solid" */
    cs_trimesh *m = import_ok("torus.STL", NULL, &r);
    assert_int_equal(r.triangles, 8700);
    assert_int_equal(r.vertices, 4350);         /* 26,100 corners joined */
    assert_int_equal(r.welded_vertices, 26100 - 4350);
    assert_true(r.closed);
    assert_int_equal(r.vertices - edges_of(&r) + r.triangles, 0); /* genus 1 */
    assert_near(r.max[0], 1.5, 1e-3);
    assert_near(r.max[2], 0.5, 1e-3);
    cs_trimesh_destroy(m);

    m = import_ok("sphereWithHole.stl", NULL, &r);  /* ascii */
    assert_int_equal(r.triangles, 285);
    assert_int_equal(r.vertices, 146);
    assert_int_equal(r.boundary_edges, 9);
    assert_false(r.closed);
    cs_trimesh_destroy(m);

    m = import_ok("Spider_binary.stl", NULL, &r);   /* the awkward one */
    assert_int_equal(r.degenerate_triangles, 56);
    assert_int_equal(r.triangles, 1368 - 56);
    assert_int_equal(r.parts, 18);
    assert_int_equal(r.boundary_edges, 72);
    assert_int_equal(r.inconsistent_edges, 10);
    cs_trimesh_destroy(m);
}

static void test_gltf(void **state)
{
    (void)state;
    cs_mesh_report r;
    cs_trimesh *m = import_ok("wooden_table_02_1k.gltf", NULL, &r);
    assert_int_equal(r.triangles, 196);
    assert_int_equal(r.vertices, 120);
    assert_int_equal(r.parts, 5);
    assert_int_equal(r.boundary_edges, 32);
    assert_near(r.max[1], 0.799, 2e-3);
    assert_non_null(strstr(r.units, "glTF"));
    cs_trimesh_destroy(m);

    /* five primitives merged, or one node of them */
    m = import_ok("painted_wooden_cabinet_1k.gltf", NULL, &r);
    assert_int_equal(r.triangles, 2227);
    assert_int_equal(r.vertices, 1192);
    assert_int_equal(r.instances, 5);
    cs_trimesh_destroy(m);
    cs_mesh_placement pl = cs_default_mesh_placement();
    pl.node = "painted_wooden_cabinet_door_01";
    m = import_ok("painted_wooden_cabinet_1k.gltf", &pl, &r);
    assert_int_equal(r.instances, 1);
    assert_int_equal(r.triangles, 80);
    cs_trimesh_destroy(m);

    m = import_ok("curtain_open.gltf", NULL, &r);   /* a sheet: a cloth */
    assert_int_equal(r.triangles, 9216);
    assert_int_equal(r.vertices, 4930);
    assert_int_equal(r.parts, 2);
    assert_int_equal(r.boundary_edges, 640);
    cs_trimesh_destroy(m);
}

static void test_fbx_units(void **state)
{
    (void)state;
    cs_mesh_report r;
    /* UnitScaleFactor 1: centimetres, node transforms applied */
    cs_trimesh *m = import_ok("spider.fbx", NULL, &r);
    assert_near(r.unit_scale, 0.01, 1e-12);
    assert_near(r.min[0], -92.655, 0.01);
    assert_near(r.max[2], 86.691, 0.01);
    assert_int_equal(r.instances, 19);
    assert_int_equal(r.vertices, 722);
    cs_trimesh_destroy(m);
    /* the scene's units win */
    cs_mesh_placement pl = cs_default_mesh_placement();
    pl.unit_scale = 0.001;
    m = import_ok("spider.fbx", &pl, &r);
    assert_near(r.min[0], -9.2655, 0.001);
    cs_trimesh_destroy(m);
}

static void test_collada_nodes(void **state)
{
    (void)state;
    cs_mesh_report r;
    cs_trimesh *m = import_ok("human.dae", NULL, &r);   /* body and eyes */
    assert_int_equal(r.triangles, 28796);
    assert_int_equal(r.vertices, 14444);
    assert_int_equal(r.parts, 5);
    assert_int_equal(r.boundary_edges, 80);
    assert_near(r.max[1] - r.min[1], 1.659, 2e-3);
    cs_trimesh_destroy(m);

    /* the body alone, by node name or by mesh name: closed, genus 0 */
    const char *names[] = {"human-baseObject", "human-baseMesh"};
    for (int i = 0; i < 2; i++) {
        cs_mesh_placement pl = cs_default_mesh_placement();
        pl.node = names[i];
        m = import_ok("human.dae", &pl, &r);
        assert_int_equal(r.vertices, 13380);
        assert_true(r.closed);
        assert_int_equal(r.vertices - edges_of(&r) + r.triangles, 2);
        cs_trimesh_destroy(m);
    }

    /* the catalog mesh-info prints */
    char path[1024], err[512];
    asset(path, sizeof path, "human.dae");
    cs_mesh_catalog *c = NULL;
    assert_int_equal(cs_mesh_catalog_read(path, &c, err, sizeof err), CS_OK);
    assert_int_equal(c->nmeshes, 2);
    assert_int_equal(c->nnodes, 3);
    assert_string_equal(c->nodes[1].name, "human-baseObject");
    assert_int_equal(c->nodes[1].depth, 1);
    assert_int_equal(c->meshes[c->nodes[1].meshes[0]].triangles, 26756);
    cs_mesh_catalog_destroy(c);
}

/* scale, then rotation, then translation, after the units */
static void test_placement(void **state)
{
    (void)state;
    cs_mesh_report r;
    cs_mesh_placement pl = cs_default_mesh_placement();
    pl.scale[0] = 2;
    pl.scale[1] = 3;
    pl.scale[2] = 4;
    double deg[3] = {0, 0, 90};   /* x -> y */
    cs_quat_from_euler_degrees(deg, pl.rotation);
    pl.translate[0] = 10;
    cs_trimesh *m = import_ok("torus.STL", &pl, &r);
    /* the torus spans x and y in [-1.5, 1.5] (to its facets' precision), z
     * in [-0.5, 0.5]: x scaled to [-3, 3] and turned onto y, y scaled to
     * [-4.5, 4.5] and turned onto -x, then moved by 10 along x */
    assert_near(r.min[1], -3, 0.01);
    assert_near(r.max[1], 3, 0.01);
    assert_near(r.min[0], 10 - 4.5, 0.01);
    assert_near(r.max[2], 2, 0.01);
    cs_trimesh_destroy(m);
}

/* ------------------------------------------------------------ repairs */

static void write_text(const char *name, const char *text, char *path, size_t len)
{
    snprintf(path, len, "%s/%s", tmpdir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static void test_repairs(void **state)
{
    (void)state;
    /* a square of two triangles, plus: the first again reversed, a
     * triangle with a repeated corner, a sliver of zero area, an unused
     * vertex, and a duplicate vertex position joined to its twin */
    char path[512], err[512];
    write_text("defects.obj",
               "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 5 5 5\nv 1 0 0\nv 2 0 0\n"
               "f 1 2 3\nf 1 3 4\nf 3 2 1\nf 1 6 3\nf 1 2 7\n",
               path, sizeof path);
    cs_trimesh *m = NULL;
    cs_mesh_report r;
    assert_int_equal(cs_mesh_import(path, NULL, &m, &r, err, sizeof err), CS_OK);
    assert_int_equal(r.triangles_read, 5);
    assert_int_equal(r.duplicate_triangles, 2);     /* "3 2 1" and "1 6 3" */
    assert_int_equal(r.degenerate_triangles, 1);    /* "1 2 7": collinear */
    assert_int_equal(r.triangles, 2);
    assert_int_equal(r.vertices, 4);
    assert_int_equal(r.boundary_edges, 4);
    assert_int_equal(r.boundary_loops, 1);
    cs_trimesh_destroy(m);

    /* three triangles on one edge: non-manifold, reported */
    write_text("fin.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\n"
                          "f 1 2 3\nf 2 1 4\nf 1 2 5\n",
               path, sizeof path);
    assert_int_equal(cs_mesh_import(path, NULL, &m, &r, err, sizeof err), CS_OK);
    assert_int_equal(r.nonmanifold_edges, 1);
    assert_false(r.closed);
    cs_trimesh_destroy(m);
}

static void test_close_holes(void **state)
{
    (void)state;
    cs_mesh_report r;
    cs_trimesh *m = import_ok("stanford-bunny.obj", NULL, &r);
    double volume = r.volume;
    assert_int_equal(cs_mesh_close_holes(&m), 5);
    cs_mesh_analyse(m, &r);
    assert_true(r.closed);
    assert_int_equal(r.inconsistent_edges, 0);      /* fans oriented like the rest */
    assert_int_equal(r.vertices - edges_of(&r) + r.triangles, 2);
    assert_near(r.volume, volume, 0.05 * volume);
    assert_int_equal(cs_mesh_close_holes(&m), 0);   /* nothing left to close */
    cs_trimesh_destroy(m);

    m = import_ok("wooden_table_02_1k.gltf", NULL, &r);
    assert_true(cs_mesh_close_holes(&m) > 0);
    cs_mesh_analyse(m, &r);
    assert_true(r.closed);
    cs_trimesh_destroy(m);
}

/* --------------------------------------------------------- bad input */

static void expect_bad(const char *path, const char *node, const char *want)
{
    char err[1024] = "";
    cs_trimesh *m = (cs_trimesh *)err;   /* must come back NULL */
    cs_mesh_report r;
    cs_mesh_placement pl = cs_default_mesh_placement();
    pl.node = node;
    assert_int_equal(cs_mesh_import(path, &pl, &m, &r, err, sizeof err), CS_ERR_BAD_INPUT);
    assert_null(m);
    assert_null(strchr(err, '\n'));
    if (!strstr(err, want))
        print_error("'%s' lacks '%s'\n", err, want);
    assert_non_null(strstr(err, want));
}

static void test_bad_input(void **state)
{
    (void)state;
    char path[512], ico[1024];
    snprintf(path, sizeof path, "%s/missing.obj", tmpdir);
    expect_bad(path, NULL, "No such file or directory");
    expect_bad(tmpdir, NULL, "Is a directory");
    write_text("empty.obj", "", path, sizeof path);
    expect_bad(path, NULL, "the file is empty");
    write_text("notes.xyz123", "hello\n", path, sizeof path);
    expect_bad(path, NULL, "No suitable reader");
    write_text("nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", path, sizeof path);
    expect_bad(path, NULL, "non-finite coordinate");
    write_text("nan.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                          "vertex 1 0 0\nvertex 0 inf 0\nendloop\nendfacet\nendsolid x\n",
               path, sizeof path);
    expect_bad(path, NULL, "non-finite coordinate");
    write_text("lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n", path, sizeof path);
    expect_bad(path, NULL, "holds no triangles");
    write_text("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", path, sizeof path);
    expect_bad(path, NULL, "no triangles of nonzero area");
    /* a binary STL cut short, and garbage under a known extension */
    char torus[1024];
    asset(torus, sizeof torus, "torus.STL");
    FILE *in = fopen(torus, "rb"), *out;
    char buf[300];
    assert_int_equal(fread(buf, 1, sizeof buf, in), sizeof buf);
    fclose(in);
    snprintf(path, sizeof path, "%s/cut.stl", tmpdir);
    out = fopen(path, "wb");
    fwrite(buf, 1, sizeof buf, out);
    fclose(out);
    expect_bad(path, NULL, path);
    write_text("junk.ply", "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n", path,
               sizeof path);
    expect_bad(path, NULL, "junk.ply");
    asset(ico, sizeof ico, "ico4.obj");
    expect_bad(ico, "no_such_node", "has no node or mesh named 'no_such_node'");
    expect_bad(ico, "no_such_node", "Icosphere");  /* and says what there is */
}

/* ------------------------------------------- files that must not crash */

#ifndef CS_SOURCE_DIR
#error "CS_SOURCE_DIR must name the repository (tests/CMakeLists.txt defines it)"
#endif

/* tests/data/bad_meshes/: each file a case that crashed, hung,
 * tried to allocate what its header claimed, or was silently misread. */
static void test_bad_files(void **state)
{
    (void)state;
    static const struct {
        const char *file, *want;
    } cases[] = {
        {"ply_list_count_255.ply", "PLY face 0 has a list of 255 entries, more than the 12 bytes"},
        {"ply_list_count_255_ascii.ply", "PLY face 0 has a list of '255' entries but 3 values"},
        {"ply_flipped_face_bytes.ply", "PLY face 0 refers to vertex 65280, but the file has 4"},
        {"ply_no_end_header.ply", "PLY header has no end_header line"},
        {"ply_1e20_vertices.ply", "count '100000000000000000000' is not a whole number"},
        {"ply_2e31_vertices.ply", "promises 2147483648 'vertex' elements"},
        {"ply_4e9_faces.ply", "promises 4000000000 'face' elements"},
        {"ply_4e9_list_entries.ply", "a list of 4000000000 entries, more than the 12 bytes"},
        {"ply_4e9_list_entries_ascii.ply", "a list of '4000000000' entries but 3 values"},
        {"ply_index_2e9.ply", "PLY face 0 refers to vertex 2000000000, but the file has 3"},
        {"ply_index_minus5.ply", "PLY face 0 refers to vertex -5, but the file has 3"},
        {"ply_tristrips.ply", "triangle strips (element 'tristrips') are not read"},
        {"ply_mostly_unused.ply", "its 1 triangle uses 3 of its 10 vertices"},
        {"obj_long_number.obj", "line 2: a number of more than 100 digits"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/tests/data/bad_meshes/%s", CS_SOURCE_DIR, cases[i].file);
        expect_bad(path, NULL, cases[i].want);
        expect_bad(path, NULL, cases[i].file);
    }
}

/* The large cases, made here: a face of 300,000 corners (minutes of
 * triangulation), a coordinate of a million digits, and a binary FBX whose
 * array length says 2^31 - 1. */
static void test_bad_large_files(void **state)
{
    (void)state;
    char path[512];
    snprintf(path, sizeof path, "%s/huge_face.obj", tmpdir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    for (int i = 0; i < 300000; i++)
        fprintf(f, "v %.6f %.6f 0\n", cos(i * 2e-5), sin(i * 2e-5));
    fputs("f", f);
    for (int i = 1; i <= 300000; i++)
        fprintf(f, " %d", i);
    fputs("\n", f);
    fclose(f);
    expect_bad(path, NULL, "face 0 of mesh 0 has 300000 corners; at most 10000 are read");

    snprintf(path, sizeof path, "%s/long_number.obj", tmpdir);
    f = fopen(path, "w");
    assert_non_null(f);
    fputs("v 0 0 0\nv 0.", f);
    for (int i = 0; i < 1000000; i++)
        fputc('3', f);
    fputs(" 1 0\nv 0 1 0\nf 1 2 3\n", f);
    fclose(f);
    expect_bad(path, NULL, "line 2: a number of more than 100 digits");

    char fbx[1024];
    asset(fbx, sizeof fbx, "spider.fbx");
    f = fopen(fbx, "rb");
    assert_non_null(f);
    static unsigned char data[200000];
    size_t n = fread(data, 1, sizeof data, f);
    fclose(f);
    assert_true(n > 43227);
    memcpy(data + 43223, "\xff\xff\xff\x7f", 4);   /* an array's element count */
    snprintf(path, sizeof path, "%s/lying.fbx", tmpdir);
    f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
    /* The 4 GB array meets the memory limit: AddressSanitizer's allocator
     * stops the child (an error naming the limit); glibc's malloc returns
     * NULL and assimp drops that object (fewer triangles). Never a crash. */
    setenv("CLOTHSIM_IMPORT_MEMORY", "512", 1);
    char err[1024] = "";
    cs_trimesh *m = NULL;
    cs_mesh_report r;
    int rc = cs_mesh_import(path, NULL, &m, &r, err, sizeof err);
    unsetenv("CLOTHSIM_IMPORT_MEMORY");
    if (rc == CS_OK) {
        assert_true(r.triangles_read < 1368);   /* spider.fbx: 1368 */
        cs_trimesh_destroy(m);
    } else {
        assert_int_equal(rc, CS_ERR_BAD_INPUT);
        assert_non_null(strstr(err, "more than 512 MB of memory"));
    }
}

/* Read right where assimp 5.2 misread: a binary PLY whose data begins with
 * a line feed; and an STL in millimetres gets a warning on units. */
static void test_misread_files(void **state)
{
    (void)state;
    char path[1024], err[512];
    snprintf(path, sizeof path, "%s/tests/data/bad_meshes/ply_data_starts_with_lf.ply",
             CS_SOURCE_DIR);
    cs_trimesh *m = cs_mesh_read(path, err, sizeof err);
    if (!m)
        fail_msg("%s", err);
    assert_int_equal(m->nv, 3);
    assert_int_equal(m->nt, 1);
    assert_near(m->x[3], 2.0, 0);
    assert_near(m->x[7], 1.0, 0);
    cs_trimesh_destroy(m);

    cs_mesh_report r;
    cs_mesh_placement pl = cs_default_mesh_placement();
    snprintf(path, sizeof path, "%s/tests/data/bad_meshes/stl_in_millimetres.stl", CS_SOURCE_DIR);
    assert_int_equal(cs_mesh_import(path, &pl, &m, &r, err, sizeof err), CS_OK);
    cs_trimesh_destroy(m);
    assert_non_null(strstr(r.size_warning, "150 m across"));
    assert_non_null(strstr(r.size_warning, "units: mm"));
    pl.unit_scale = 0.001;   /* units: mm */
    assert_int_equal(cs_mesh_import(path, &pl, &m, &r, err, sizeof err), CS_OK);
    cs_trimesh_destroy(m);
    assert_string_equal(r.size_warning, "");
    assert_near(r.max[0] - r.min[0], 0.15, 1e-9);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_obj),
        cmocka_unit_test(test_ply_ascii_and_binary),
        cmocka_unit_test(test_stl_ascii_and_binary),
        cmocka_unit_test(test_gltf),
        cmocka_unit_test(test_fbx_units),
        cmocka_unit_test(test_collada_nodes),
        cmocka_unit_test(test_placement),
        cmocka_unit_test(test_repairs),
        cmocka_unit_test(test_close_holes),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_bad_files),
        cmocka_unit_test(test_bad_large_files),
        cmocka_unit_test(test_misread_files),
    };
    return cmocka_run_group_tests(tests, tmpdir_make, tmpdir_remove);
}
