/* test_mesh_io.c: mesh files written through assimp read back the same. */
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
#include "tests/tmpdir.h"

/* Coordinates go through 32-bit floats (and OBJ through text). */
#define TOL 1e-5

static void path_in_dir(char *out, size_t len, const char *name)
{
    snprintf(out, len, "%s/%s", tmpdir, name);
}

static bool exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Two meshes apart in space so no vertex of one coincides with the other:
 * a 3 x 2 quad grid (12 vertices, 12 triangles) and a tetrahedron. */
typedef struct fixture {
    double grid_x[12 * 3];
    int grid_tri[12 * 3];
    double tet_x[4 * 3];
    int tet_tri[4 * 3];
    cs_mesh_view views[2];
} fixture;

static void make_fixture(fixture *f)
{
    int n = 0;
    for (int j = 0; j <= 2; j++)
        for (int i = 0; i <= 3; i++, n++) {
            f->grid_x[3 * n + 0] = 0.25 * i - 0.3;
            f->grid_x[3 * n + 1] = 0.5 + 0.01 * i * j;
            f->grid_x[3 * n + 2] = 0.3 * j + 1.0 / 3.0;
        }
    int t = 0;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 3; i++) {
            int a = j * 4 + i, b = a + 1, c = a + 4, d = c + 1;
            int tris[6] = {a, c, b, b, c, d};
            memcpy(&f->grid_tri[3 * t], tris, sizeof tris);
            t += 2;
        }
    const double tx[12] = {3, 0, 0, 4, 0, 0, 3, 1, 0, 3, 0, 1.5};
    const int tt[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    memcpy(f->tet_x, tx, sizeof tx);
    memcpy(f->tet_tri, tt, sizeof tt);
    f->views[0] = (cs_mesh_view){"sheet", 12, f->grid_x, 12, f->grid_tri};
    f->views[1] = (cs_mesh_view){"tetra", 4, f->tet_x, 4, f->tet_tri};
}

/* Position of corner k of triangle t over the concatenation of views. */
static const double *view_corner(const cs_mesh_view *views, int nviews, int t, int k)
{
    for (int m = 0; m < nviews; m++) {
        if (t < views[m].nt)
            return &views[m].x[3 * views[m].tri[3 * t + k]];
        t -= views[m].nt;
    }
    return NULL;
}

/* The file may number vertices differently (OBJ does), so compare what the
 * triangles are: every corner of every triangle, in order, by position. */
static void assert_same_mesh(const cs_trimesh *got, const cs_mesh_view *views, int nviews)
{
    int nv = 0, nt = 0;
    for (int m = 0; m < nviews; m++) {
        nv += views[m].nv;
        nt += views[m].nt;
    }
    assert_int_equal(got->nv, nv);
    assert_int_equal(got->nt, nt);
    for (int t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            int v = got->tri[3 * t + k];
            assert_true(v >= 0 && v < got->nv);
            const double *want = view_corner(views, nviews, t, k);
            for (int d = 0; d < 3; d++) {
                if (fabs(got->x[3 * v + d] - want[d]) > TOL)
                    fail_msg("triangle %d corner %d coord %d: read %.9g, wrote %.9g",
                             t, k, d, got->x[3 * v + d], want[d]);
            }
        }
}

static void test_format_names(void **state)
{
    (void)state;
    cs_mesh_format f;
    assert_true(cs_mesh_format_from_name("ply", &f));
    assert_int_equal(f, CS_MESH_PLY);
    assert_true(cs_mesh_format_from_name("obj", &f));
    assert_int_equal(f, CS_MESH_OBJ);
    assert_true(cs_mesh_format_from_name("glb", &f));
    assert_int_equal(f, CS_MESH_GLB);
    assert_true(cs_mesh_format_from_name("gltf", &f));
    assert_int_equal(f, CS_MESH_GLB);
    assert_false(cs_mesh_format_from_name("stl", &f));
    assert_false(cs_mesh_format_from_name("", &f));
    assert_false(cs_mesh_format_from_name(NULL, &f));
    assert_string_equal(cs_mesh_format_extension(CS_MESH_PLY), "ply");
    assert_string_equal(cs_mesh_format_extension(CS_MESH_OBJ), "obj");
    assert_string_equal(cs_mesh_format_extension(CS_MESH_GLB), "glb");
}

static void round_trip(cs_mesh_format format, int nviews)
{
    fixture f;
    make_fixture(&f);
    char name[64], path[512], tmp[520], err[512] = "";
    snprintf(name, sizeof name, "round_%d.%s", nviews, cs_mesh_format_extension(format));
    path_in_dir(path, sizeof path, name);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);

    int rc = cs_mesh_write(path, format, nviews, f.views, err, sizeof err);
    if (rc != CS_OK)
        fail_msg("write %s: %s", path, err);
    assert_true(exists(path));
    assert_false(exists(tmp));   /* written beside, then renamed */

    cs_trimesh *got = cs_mesh_read(path, err, sizeof err);
    if (!got)
        fail_msg("read %s: %s", path, err);
    assert_same_mesh(got, f.views, nviews);
    cs_trimesh_destroy(got);

    /* Writing again replaces the file and still leaves no .tmp behind. */
    f.grid_x[1] += 0.125;
    rc = cs_mesh_write(path, format, nviews, f.views, err, sizeof err);
    assert_int_equal(rc, CS_OK);
    assert_false(exists(tmp));
    got = cs_mesh_read(path, err, sizeof err);
    assert_non_null(got);
    assert_same_mesh(got, f.views, nviews);
    cs_trimesh_destroy(got);
}

static void test_ply(void **state)
{
    (void)state;
    round_trip(CS_MESH_PLY, 1);
    round_trip(CS_MESH_PLY, 2);
}

static void test_obj(void **state)
{
    (void)state;
    round_trip(CS_MESH_OBJ, 1);
    round_trip(CS_MESH_OBJ, 2);
}

static void test_glb(void **state)
{
    (void)state;
    round_trip(CS_MESH_GLB, 1);
    round_trip(CS_MESH_GLB, 2);
}

/* The simulation's vertex numbering survives in PLY and glb, so a renderer
 * can match vertices across frames. */
static void test_vertex_order_kept(void **state)
{
    (void)state;
    fixture f;
    make_fixture(&f);
    const cs_mesh_format formats[2] = {CS_MESH_PLY, CS_MESH_GLB};
    for (int i = 0; i < 2; i++) {
        char name[32], path[512], err[512] = "";
        snprintf(name, sizeof name, "order.%s", cs_mesh_format_extension(formats[i]));
        path_in_dir(path, sizeof path, name);
        assert_int_equal(cs_mesh_write(path, formats[i], 1, f.views, err, sizeof err), CS_OK);
        cs_trimesh *got = cs_mesh_read(path, err, sizeof err);
        assert_non_null(got);
        assert_int_equal(got->nv, 12);
        for (int v = 0; v < 12; v++)
            for (int d = 0; d < 3; d++)
                assert_true(fabs(got->x[3 * v + d] - f.grid_x[3 * v + d]) < TOL);
        for (int k = 0; k < 3 * 12; k++)
            assert_int_equal(got->tri[k], f.grid_tri[k]);
        cs_trimesh_destroy(got);
    }
}

/* Each view is an object of its own in OBJ and glb: read back by name,
 * whatever the order asked; a name the file lacks is refused. */
static void test_read_named(void **state)
{
    (void)state;
    fixture f;
    make_fixture(&f);
    const cs_mesh_format formats[2] = {CS_MESH_OBJ, CS_MESH_GLB};
    for (int i = 0; i < 2; i++) {
        char name[32], path[512], err[512] = "";
        snprintf(name, sizeof name, "named.%s", cs_mesh_format_extension(formats[i]));
        path_in_dir(path, sizeof path, name);
        assert_int_equal(cs_mesh_write(path, formats[i], 2, f.views, err, sizeof err),
                         CS_OK);
        const char *names[2] = {"tetra", "sheet"};
        cs_trimesh *got[2] = {NULL, NULL};
        if (cs_mesh_read_named(path, 2, names, got, err, sizeof err) != CS_OK)
            fail_msg("read %s by name: %s", path, err);
        assert_same_mesh(got[0], &f.views[1], 1);
        assert_same_mesh(got[1], &f.views[0], 1);
        cs_trimesh_destroy(got[0]);
        cs_trimesh_destroy(got[1]);
        const char *missing[2] = {"sheet", "nothing"};
        assert_int_equal(cs_mesh_read_named(path, 2, missing, got, err, sizeof err),
                         CS_ERR_BAD_INPUT);
        assert_null(got[0]);
        assert_non_null(strstr(err, "'nothing'"));
    }
}

static void test_write_bad_path(void **state)
{
    (void)state;
    fixture f;
    make_fixture(&f);
    char err[512] = "";
    const char *path = "/nonexistent-dir/cs/frame.ply";
    int rc = cs_mesh_write(path, CS_MESH_PLY, 1, f.views, err, sizeof err);
    assert_int_equal(rc, CS_ERR_BAD_INPUT);
    assert_non_null(strstr(err, path));
    assert_non_null(strstr(err, "No such file"));
}

static void test_write_bad_input(void **state)
{
    (void)state;
    fixture f;
    make_fixture(&f);
    char path[512], err[512] = "";
    path_in_dir(path, sizeof path, "bad.ply");

    assert_int_equal(cs_mesh_write(path, CS_MESH_PLY, 0, f.views, err, sizeof err),
                     CS_ERR_BAD_INPUT);
    assert_non_null(strstr(err, "no meshes"));

    f.grid_tri[5] = 12;   /* one past the last vertex */
    err[0] = '\0';
    assert_int_equal(cs_mesh_write(path, CS_MESH_PLY, 1, f.views, err, sizeof err),
                     CS_ERR_BAD_INPUT);
    assert_non_null(strstr(err, "sheet"));
    assert_false(exists(path));
}

/* A cloth without triangles is written as points and read back:
 * alone, a point-cloud PLY of vertices only; beside a triangle mesh, in
 * the same file. */
static void test_points(void **state)
{
    (void)state;
    fixture f;
    make_fixture(&f);
    const double px[6] = {0.5, 2.0, -1.0, 0.25, 2.5, -1.5};
    cs_mesh_view views[2] = {{"particles", 2, px, 0, NULL}, f.views[1]};
    const cs_mesh_format formats[3] = {CS_MESH_PLY, CS_MESH_OBJ, CS_MESH_GLB};
    for (int i = 0; i < 3; i++)
        for (int n = 1; n <= 2; n++) {
            char name[32], path[512], err[512] = "";
            snprintf(name, sizeof name, "points_%d.%s", n, cs_mesh_format_extension(formats[i]));
            path_in_dir(path, sizeof path, name);
            if (cs_mesh_write(path, formats[i], n, views, err, sizeof err) != CS_OK)
                fail_msg("write %s: %s", path, err);
            cs_trimesh *got = cs_mesh_read(path, err, sizeof err);
            if (!got)
                fail_msg("read %s: %s", path, err);
            assert_int_equal(got->nv, n == 1 ? 2 : 6);
            assert_int_equal(got->nt, n == 1 ? 0 : 4);
            for (int d = 0; d < 6 && n == 1; d++)
                assert_true(fabs(got->x[d] - px[d]) < TOL);
            cs_trimesh_destroy(got);
            if (formats[i] == CS_MESH_PLY && n == 1) {
                char head[512] = "";
                FILE *fp = fopen(path, "rb");
                assert_non_null(fp);
                size_t len = fread(head, 1, sizeof head - 1, fp);
                fclose(fp);
                head[len] = '\0';
                assert_non_null(strstr(head, "element vertex 2\n"));
                assert_null(strstr(head, "element face"));
            }
        }
}

static void write_text(const char *path, const char *text)
{
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    fputs(text, fp);
    fclose(fp);
}

static void test_read_errors(void **state)
{
    (void)state;
    char path[512], err[512] = "";

    path_in_dir(path, sizeof path, "missing.obj");
    assert_null(cs_mesh_read(path, err, sizeof err));
    assert_non_null(strstr(err, path));

    /* Points and a line only: nothing to collide with or simulate. */
    path_in_dir(path, sizeof path, "lines.obj");
    write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\n");
    err[0] = '\0';
    assert_null(cs_mesh_read(path, err, sizeof err));
    assert_non_null(strstr(err, "no triangles"));

    path_in_dir(path, sizeof path, "garbage.ply");
    write_text(path, "this is not a mesh\n");
    err[0] = '\0';
    assert_null(cs_mesh_read(path, err, sizeof err));
    assert_non_null(strstr(err, path));
}

static void test_read_non_finite(void **state)
{
    (void)state;
    char path[512], err[512] = "";
    path_in_dir(path, sizeof path, "inf.ply");
    write_text(path,
               "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
               "property float y\nproperty float z\nelement face 1\n"
               "property list uchar int vertex_indices\nend_header\n"
               "0 0 0\n1 0 0\n0 1e39 0\n3 0 1 2\n");
    cs_trimesh *m = cs_mesh_read(path, err, sizeof err);
    if (m) {
        cs_trimesh_destroy(m);
        fail_msg("a vertex at y = 1e39 (inf as a float) was accepted");
    }
    assert_non_null(strstr(err, "non-finite"));
}

/* Node transforms are applied when meshes are merged. */
static void test_read_applies_transforms(void **state)
{
    (void)state;
    char path[512], err[512] = "";
    path_in_dir(path, sizeof path, "moved.gltf");
    /* One triangle, instanced by two nodes: as is and moved by +2 in x. */
    write_text(path,
               "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,"
               "\"scenes\":[{\"nodes\":[0,1]}],"
               "\"nodes\":[{\"mesh\":0},{\"mesh\":0,\"translation\":[2,0,0]}],"
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
               "\"buffers\":[{\"byteLength\":44,\"uri\":\"data:application/octet-stream;base64,"
               "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=\"}],"
               "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},"
               "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}],"
               "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,"
               "\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]},"
               "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]}");
    cs_trimesh *m = cs_mesh_read(path, err, sizeof err);
    if (!m)
        fail_msg("%s", err);
    assert_int_equal(m->nv, 6);
    assert_int_equal(m->nt, 2);
    double minx = 1e9, maxx = -1e9;
    for (int v = 0; v < m->nv; v++) {
        minx = fmin(minx, m->x[3 * v]);
        maxx = fmax(maxx, m->x[3 * v]);
    }
    assert_true(fabs(minx - 0.0) < TOL);
    assert_true(fabs(maxx - 3.0) < TOL);
    cs_trimesh_destroy(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_format_names),
        cmocka_unit_test(test_ply),
        cmocka_unit_test(test_obj),
        cmocka_unit_test(test_glb),
        cmocka_unit_test(test_vertex_order_kept),
        cmocka_unit_test(test_read_named),
        cmocka_unit_test(test_write_bad_path),
        cmocka_unit_test(test_write_bad_input),
        cmocka_unit_test(test_points),
        cmocka_unit_test(test_read_errors),
        cmocka_unit_test(test_read_non_finite),
        cmocka_unit_test(test_read_applies_transforms),
    };
    return cmocka_run_group_tests(tests, tmpdir_make, tmpdir_remove);
}
