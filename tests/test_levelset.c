/* test_levelset.c: mesh bodies as OpenVDB level sets.
 *
 * - accuracy: phi of the grid against the exact signed distance to the
 *   triangle mesh, by brute force (closest point on every triangle; the
 *   sign from the generalised winding number), at points near the surface
 *   of the icosphere (ico4.obj) and of the Stanford bunny (holes closed);
 * - the gradient against the exact normal on the sphere;
 * - a particle dropped on the imported sphere rests at the analytic
 *   sphere's height within a voxel, and friction holds it or lets it slide
 *   as on the analytic sphere;
 * - the cache: a .vdb written, read back, reused by its content key, and
 *   replaced when the mesh or the voxel size change, and a file of the
 *   older naming (a SHA-256 key) in the cache ignored.
 *
 * The meshes come from the repository's assets/ folder (CS_ASSETS_DIR);
 * without them the tests fail, they do not skip.
 */
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

#ifndef CS_ASSETS_DIR
#error "CS_ASSETS_DIR must name the repository's assets/ folder (tests/CMakeLists.txt defines it)"
#endif

static void require_asset(const char *path)
{
    if (access(path, R_OK) != 0) {
        print_error("missing test asset %s: the repository's assets/ folder is incomplete\n",
                    path);
        fail();
    }
}

static cs_trimesh *load(const char *name, cs_mesh_report *rep)
{
    char path[1024], err[512];
    snprintf(path, sizeof path, "%s/%s", CS_ASSETS_DIR, name);
    require_asset(path);
    cs_trimesh *m = NULL;
    int rc = cs_mesh_import(path, NULL, &m, rep, err, sizeof err);
    if (rc != CS_OK)
        print_error("%s\n", err);
    assert_int_equal(rc, CS_OK);
    return m;
}

/* ------------------------------------------------------- exact distance */

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Closest point on triangle abc to p (Ericson, Real-Time Collision
 * Detection, 5.1.5); returns the squared distance. */
static double dist2_triangle(const double *p, const double *a, const double *b, const double *c)
{
    double ab[3], ac[3], ap[3], q[3];
    for (int k = 0; k < 3; k++) {
        ab[k] = b[k] - a[k];
        ac[k] = c[k] - a[k];
        ap[k] = p[k] - a[k];
    }
    double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        memcpy(q, a, sizeof q);
        goto done;
    }
    double bp[3] = {p[0] - b[0], p[1] - b[1], p[2] - b[2]};
    double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0 && d4 <= d3) {
        memcpy(q, b, sizeof q);
        goto done;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; k++)
            q[k] = a[k] + v * ab[k];
        goto done;
    }
    double cp[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
    double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0 && d5 <= d6) {
        memcpy(q, c, sizeof q);
        goto done;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double w = d2 / (d2 - d6);
        for (int k = 0; k < 3; k++)
            q[k] = a[k] + w * ac[k];
        goto done;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; k++)
            q[k] = b[k] + w * (c[k] - b[k]);
        goto done;
    }
    double denom = 1.0 / (va + vb + vc), v = vb * denom, w = vc * denom;
    for (int k = 0; k < 3; k++)
        q[k] = a[k] + ab[k] * v + ac[k] * w;
done:;
    double d[3] = {p[0] - q[0], p[1] - q[1], p[2] - q[2]};
    return dot3(d, d);
}

/* Solid angle of triangle abc seen from p (Van Oosterom and Strackee). */
static double solid_angle(const double *p, const double *a, const double *b, const double *c)
{
    double x[3], y[3], z[3];
    for (int k = 0; k < 3; k++) {
        x[k] = a[k] - p[k];
        y[k] = b[k] - p[k];
        z[k] = c[k] - p[k];
    }
    double lx = sqrt(dot3(x, x)), ly = sqrt(dot3(y, y)), lz = sqrt(dot3(z, z));
    double cr[3] = {y[1] * z[2] - y[2] * z[1], y[2] * z[0] - y[0] * z[2], y[0] * z[1] - y[1] * z[0]};
    double num = dot3(x, cr);
    double den = lx * ly * lz + dot3(x, y) * lz + dot3(y, z) * lx + dot3(z, x) * ly;
    return 2 * atan2(num, den);
}

/* Exact signed distance: negative inside (winding number above 1/2). */
static double exact_phi(const cs_trimesh *m, const double *p)
{
    double best = INFINITY, wind = 0;
    for (int t = 0; t < m->nt; t++) {
        const double *a = m->x + 3 * m->tri[3 * t], *b = m->x + 3 * m->tri[3 * t + 1],
                     *c = m->x + 3 * m->tri[3 * t + 2];
        double d2 = dist2_triangle(p, a, b, c);
        if (d2 < best)
            best = d2;
        wind += solid_angle(p, a, b, c);
    }
    wind /= 4 * M_PI;
    return fabs(wind) > 0.5 ? -sqrt(best) : sqrt(best);
}

/* Points near the surface: triangle centroids pushed along the normal by a
 * distance in [-reach, reach], one triangle in every `stride`. */
static int near_points(const cs_trimesh *m, int stride, double reach, double *out, int max)
{
    int n = 0;
    srand(11);
    for (int t = 0; t < m->nt && n < max; t += stride) {
        const double *a = m->x + 3 * m->tri[3 * t], *b = m->x + 3 * m->tri[3 * t + 1],
                     *c = m->x + 3 * m->tri[3 * t + 2];
        double u[3], v[3], nrm[3];
        for (int k = 0; k < 3; k++) {
            u[k] = b[k] - a[k];
            v[k] = c[k] - a[k];
        }
        nrm[0] = u[1] * v[2] - u[2] * v[1];
        nrm[1] = u[2] * v[0] - u[0] * v[2];
        nrm[2] = u[0] * v[1] - u[1] * v[0];
        double len = sqrt(dot3(nrm, nrm));
        if (!(len > 0))
            continue;
        double s = reach * (2.0 * rand() / RAND_MAX - 1.0);
        for (int k = 0; k < 3; k++)
            out[3 * n + k] = (a[k] + b[k] + c[k]) / 3 + s * nrm[k] / len;
        n++;
    }
    return n;
}

/* Largest and mean |phi_grid - phi_exact| over the points, in voxels; also
 * counts wrong signs away from the surface (beyond half a voxel). */
static double worst_error(const cs_trimesh *m, const cs_levelset *ls, double voxel,
                          const double *pts, int n, int *sign_errors, double *mean)
{
    double worst = 0, g[3];
    *sign_errors = 0;
    *mean = 0;
    for (int i = 0; i < n; i++) {
        double exact = exact_phi(m, pts + 3 * i);
        double got = cs_levelset_phi(ls, pts + 3 * i, g);
        double e = fabs(got - exact) / voxel;
        if (e > worst)
            worst = e;
        *mean += e / n;
        if (fabs(exact) > 0.5 * voxel && (exact < 0) != (got < 0))
            (*sign_errors)++;
    }
    return worst;
}

/* --------------------------------------------------------------- tests */

/* The icosphere: r = 1 about (0.240, 0.180, 0.898), 1280 triangles. At
 * voxel 0.05 every sampled phi is within 0.1 voxel of the exact distance
 * to the triangles, inside and outside. */
static void test_accuracy_sphere(void **state)
{
    (void)state;
    cs_mesh_report rep;
    cs_trimesh *m = load("ico4.obj", &rep);
    assert_true(rep.closed);
    const double voxel = 0.05;
    char err[256];
    cs_levelset *ls = cs_levelset_create(m, voxel, 3, true, err, sizeof err);
    assert_non_null(ls);
    double pts[3 * 1280];
    int n = near_points(m, 1, 2.5 * voxel, pts, 1280);
    int sign_errors;
    double mean, worst = worst_error(m, ls, voxel, pts, n, &sign_errors, &mean);
    print_message("ico4: %d points within 2.5 voxels: |phi - exact| worst %.3f, mean %.3f "
                  "voxel\n",
                  n, worst, mean);
    assert_true(worst < 0.1);
    assert_int_equal(sign_errors, 0);
    /* the filled interior: the centre reads the inscribed distance */
    /* the filled interior holds a distance all the way in; OpenVDB extends
     * it from the band by closest-triangle propagation, so deep inside it
     * is approximate: the centre (20 voxels deep) is within a voxel */
    double c[3] = {0.240, 0.180, 0.898}, g[3];
    assert_true(fabs(cs_levelset_phi(ls, c, g) - exact_phi(m, c)) < voxel);
    cs_levelset_destroy(ls);
    cs_trimesh_destroy(m);
}

/* The unit normal: grad phi against the direction from the centre, at
 * points within a voxel of the sphere. */
static void test_gradient_sphere(void **state)
{
    (void)state;
    cs_mesh_report rep;
    cs_trimesh *m = load("ico4.obj", &rep);
    char err[256];
    cs_levelset *ls = cs_levelset_create(m, 0.05, 3, true, err, sizeof err);
    assert_non_null(ls);
    const double c[3] = {0.240, 0.180, 0.898};
    double worst = 0;
    srand(5);
    for (int i = 0; i < 2000; i++) {
        double d[3], len = 0;
        for (int k = 0; k < 3; k++) {
            d[k] = 2.0 * rand() / RAND_MAX - 1;
            len += d[k] * d[k];
        }
        len = sqrt(len);
        double r = 1 + 0.05 * (2.0 * rand() / RAND_MAX - 1), p[3], g[3];
        for (int k = 0; k < 3; k++)
            p[k] = c[k] + r * d[k] / len;
        cs_levelset_phi(ls, p, g);
        double cosang = dot3(g, d) / len;
        assert_true(fabs(dot3(g, g) - 1) < 1e-9);
        if (1 - cosang > worst)
            worst = 1 - cosang;
    }
    double degrees = acos(1 - worst) * 180 / M_PI;
    print_message("ico4: worst normal error %.2f degrees\n", degrees);
    assert_true(degrees < 5);
    cs_levelset_destroy(ls);
    cs_trimesh_destroy(m);
}

/* The bunny (69k triangles, 5 holes in its base closed with fans) at a
 * voxel of 2 mm: within half a voxel of the exact distance, a tenth on
 * average. Its scanned surface has detail finer than the voxel (triangles
 * of about 1 mm), which trilinear interpolation cannot follow exactly. */
static void test_accuracy_bunny(void **state)
{
    (void)state;
    cs_mesh_report rep;
    cs_trimesh *m = load("stanford-bunny.obj", &rep);
    assert_false(rep.closed);
    assert_int_equal(rep.boundary_loops, 5);
    assert_int_equal(cs_mesh_close_holes(&m), 5);
    cs_mesh_analyse(m, &rep);
    assert_true(rep.closed);
    const double voxel = 0.002;
    char err[256];
    cs_levelset *ls = cs_levelset_create(m, voxel, 3, true, err, sizeof err);
    assert_non_null(ls);
    double pts[3 * 300];
    int n = near_points(m, m->nt / 300 + 1, 2.5 * voxel, pts, 300);
    int sign_errors;
    double mean, worst = worst_error(m, ls, voxel, pts, n, &sign_errors, &mean);
    print_message("bunny: %d points within 2.5 voxels: |phi - exact| worst %.3f, mean %.3f "
                  "voxel\n",
                  n, worst, mean);
    assert_true(worst < 0.5);
    assert_true(mean < 0.1);
    assert_int_equal(sign_errors, 0);
    cs_levelset_destroy(ls);
    cs_trimesh_destroy(m);
}

/* ---------------------------------------------------- particle on sphere */

/* A body at the icosphere's centre: analytic, or the grid of ico4.obj
 * moved so its centre is at the origin of its frame. */
typedef struct drop_result {
    double x[3];       /* final position */
    double rest;       /* distance from the centre at the end */
} drop_result;

static drop_result drop(const cs_body_def *body, const double start[3], double seconds)
{
    cs_trimesh *p = cs_trimesh_create(1, 0);
    memcpy(p->x, start, sizeof(double) * 3);
    cs_sim_def def = cs_default_sim_def();
    cs_cloth_def cloth = {.name = "particle", .mesh = p, .material = cs_default_cloth_material()};
    def.cloths = &cloth;
    def.ncloths = 1;
    def.bodies = body;
    def.nbodies = 1;
    def.fps = 100;
    def.dt = 1e-3;
    char err[256];
    cs_sim *sim = cs_sim_create(&def, err, sizeof err);
    assert_non_null(sim);
    int frames = (int)lround(seconds * def.fps);
    for (int f = 0; f < frames; f++)
        assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
    drop_result r;
    memcpy(r.x, cs_sim_positions(sim), sizeof r.x);
    r.rest = sqrt(dot3(r.x, r.x));
    cs_sim_destroy(sim);
    cs_trimesh_destroy(p);
    return r;
}

static void test_particle_on_imported_sphere(void **state)
{
    (void)state;
    cs_mesh_report rep;
    char path[1024], err[512];
    snprintf(path, sizeof path, "%s/ico4.obj", CS_ASSETS_DIR);
    require_asset(path);
    cs_mesh_placement pl = cs_default_mesh_placement();
    pl.translate[0] = -0.240; /* centre the sphere in its body frame */
    pl.translate[1] = -0.180;
    pl.translate[2] = -0.898;
    cs_trimesh *m = NULL;
    assert_int_equal(cs_mesh_import(path, &pl, &m, &rep, err, sizeof err), CS_OK);
    const double voxel = 0.04;
    cs_levelset *ls = cs_levelset_create(m, voxel, 3, true, err, sizeof err);
    assert_non_null(ls);

    cs_body_def analytic = cs_default_body_def();
    analytic.shape = CS_BODY_SPHERE;
    analytic.radius = 1;
    cs_body_def grid = analytic;
    grid.shape = CS_BODY_MESH;
    cs_levelset_attach(&grid, ls);

    /* dropped onto the top from 0.2 m: rests on it */
    const double top[3] = {0, 1.2, 0};
    drop_result a = drop(&analytic, top, 0.6), g = drop(&grid, top, 0.6);
    print_message("rest on top: analytic %.5f m, grid %.5f m from the centre (voxel %g)\n",
                  a.rest, g.rest, voxel);
    assert_true(fabs(a.rest - 1) < 1e-3);
    assert_true(fabs(g.rest - a.rest) < voxel);
    assert_true(fabs(g.x[0]) < voxel && fabs(g.x[2]) < voxel); /* it stayed on top */

    /* 20 degrees off the top: tan 20 = 0.36, so mu = 0.6 holds it and
     * mu = 0.1 lets it slide off; the grid sphere does the same */
    const double th = 20 * M_PI / 180;
    const double side[3] = {sin(th) * 1.001, cos(th) * 1.001, 0};
    for (int k = 0; k < 2; k++) {
        double mu = k == 0 ? 0.6 : 0.1;
        analytic.friction = grid.friction = mu;
        a = drop(&analytic, side, 0.4);
        g = drop(&grid, side, 0.4);
        double angle_a = atan2(a.x[0], a.x[1]) * 180 / M_PI;
        double angle_g = atan2(g.x[0], g.x[1]) * 180 / M_PI;
        print_message("mu %.1f: after 0.4 s at %.2f degrees (analytic) and %.2f (grid)\n", mu,
                      angle_a, angle_g);
        if (mu > 0.36) {
            assert_true(fabs(angle_a - 20) < 0.5);
            assert_true(fabs(angle_g - 20) < 0.5 + voxel * 180 / M_PI);
        } else {
            assert_true(angle_a > 30);
            assert_true(fabs(angle_g - angle_a) < 0.1 * angle_a);
        }
    }
    cs_levelset_destroy(ls);
    cs_trimesh_destroy(m);
}

/* A grid body in rigid motion answers like the analytic sphere moving the
 * same way: the grid is in the body's frame, the motion places it. */
static void test_moving_grid_body(void **state)
{
    (void)state;
    char path[1024], err[512];
    snprintf(path, sizeof path, "%s/ico4.obj", CS_ASSETS_DIR);
    require_asset(path);
    cs_mesh_placement pl = cs_default_mesh_placement();
    pl.translate[0] = -0.240;
    pl.translate[1] = -0.180;
    pl.translate[2] = -0.898;
    cs_trimesh *m = NULL;
    cs_mesh_report rep;
    assert_int_equal(cs_mesh_import(path, &pl, &m, &rep, err, sizeof err), CS_OK);
    const double voxel = 0.05;
    cs_levelset *ls = cs_levelset_create(m, voxel, 3, true, err, sizeof err);
    assert_non_null(ls);
    cs_keyframe keys[2] = {{0, {0, 0, 0}, {1, 0, 0, 0}}, {1, {2, 1, 0}, {0, 0, 0, 1}}};
    double deg[3] = {0, 0, 120};
    cs_quat_from_euler_degrees(deg, keys[1].rotation);
    cs_body_def analytic = cs_default_body_def();
    analytic.shape = CS_BODY_SPHERE;
    analytic.radius = 1;
    analytic.motion.kind = CS_MOTION_KEYFRAMES;
    analytic.motion.nkeys = 2;
    analytic.motion.keys = keys;
    cs_body_def grid = analytic;
    grid.shape = CS_BODY_MESH;
    grid.phi_fn = cs_levelset_phi;
    grid.phi_data = ls;
    srand(9);
    double worst = 0, worst_normal = 0;
    for (int i = 0; i < 500; i++) {
        double t = 0.5 + 0.4 * rand() / RAND_MAX, c[3], d[3], len = 0, x[3], ga[3], gg[3];
        cs_motion_pose(&analytic.motion, t, NULL, c, NULL, NULL);
        for (int k = 0; k < 3; k++) {
            d[k] = 2.0 * rand() / RAND_MAX - 1;
            len += d[k] * d[k];
        }
        len = sqrt(len);
        for (int k = 0; k < 3; k++)
            x[k] = c[k] + (1 + 0.1 * (2.0 * rand() / RAND_MAX - 1)) * d[k] / len;
        double pa = cs_body_def_phi(&analytic, t, x, ga), pg = cs_body_def_phi(&grid, t, x, gg);
        worst = fmax(worst, fabs(pa - pg));
        worst_normal = fmax(worst_normal, 1 - dot3(ga, gg));
    }
    /* the icosphere's flat facets lie a few millimetres inside the sphere */
    print_message("moving: |phi_grid - phi_sphere| <= %.4f, normals within %.2f degrees\n", worst,
                  acos(1 - worst_normal) * 180 / M_PI);
    assert_true(worst < 0.01 + 0.1 * voxel);
    assert_true(acos(1 - worst_normal) * 180 / M_PI < 5);
    cs_levelset_destroy(ls);
    cs_trimesh_destroy(m);
}

/* ------------------------------------------------------------- cache */

static char cache_dir[256];

static int make_cache_dir(void **state)
{
    (void)state;
    snprintf(cache_dir, sizeof cache_dir, "/tmp/cs_test_levelset_XXXXXX");
    return mkdtemp(cache_dir) ? 0 : -1;
}

static int remove_cache_dir(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", cache_dir);
    return system(cmd) == 0 ? 0 : -1;
}

static void test_cache(void **state)
{
    (void)state;
    cs_mesh_report rep;
    cs_trimesh *m = load("ico4.obj", &rep);
    char err[512], dir[300];
    snprintf(dir, sizeof dir, "%s/cache", cache_dir); /* made on first write */
    cs_levelset_request req = {.voxel_size = 0.1, .band = 3, .fill_interior = true,
                               .cache_dir = dir, .label = "ico4"};
    cs_levelset_result r1, r2, r3, r4;
    assert_int_equal(cs_levelset_build(m, &req, &r1, err, sizeof err), CS_OK);
    assert_false(r1.from_cache);
    assert_string_equal(r1.cache_note, "");
    assert_int_equal(strncmp(r1.cache_path, dir, strlen(dir)), 0);
    struct stat st;
    assert_int_equal(stat(r1.cache_path, &st), 0);
    /* the key: XXH3-128 in hex, its first 16 digits in the file's name */
    assert_int_equal(strlen(r1.key), 32);
    assert_int_equal(strspn(r1.key, "0123456789abcdef"), 32);
    char name[64];
    snprintf(name, sizeof name, "/ico4-%.16s.vdb", r1.key);
    assert_non_null(strstr(r1.cache_path, name));
    /* a grid under an older name (the SHA-256 key's) is simply not looked at */
    char old[400];
    snprintf(old, sizeof old, "%s/ico4-%.16s.vdb", dir, "9f86d081884c7d65");
    assert_int_equal(rename(r1.cache_path, old), 0);
    cs_levelset_result r0;
    assert_int_equal(cs_levelset_build(m, &req, &r0, err, sizeof err), CS_OK);
    assert_false(r0.from_cache);
    assert_string_equal(r0.cache_note, "");
    assert_string_equal(r0.cache_path, r1.cache_path);
    cs_levelset_destroy(r0.grid);
    unlink(old);

    /* the same input: read back, equal values */
    assert_int_equal(cs_levelset_build(m, &req, &r2, err, sizeof err), CS_OK);
    assert_true(r2.from_cache);
    assert_string_equal(r1.cache_path, r2.cache_path);
    for (int i = 0; i < 50; i++) {
        double p[3] = {0.24 + 0.03 * i - 0.7, 0.18 + 0.01 * i, 0.9}, g1[3], g2[3];
        assert_true(cs_levelset_phi(r1.grid, p, g1) == cs_levelset_phi(r2.grid, p, g2));
    }

    /* a file's time means nothing: touching it changes nothing, and a
     * different mesh (moved by 1 mm) or voxel size is another file */
    m->x[0] += 1e-3;
    assert_int_equal(cs_levelset_build(m, &req, &r3, err, sizeof err), CS_OK);
    assert_false(r3.from_cache);
    assert_string_not_equal(r3.cache_path, r1.cache_path);
    m->x[0] -= 1e-3;
    req.voxel_size = 0.11;
    assert_int_equal(cs_levelset_build(m, &req, &r4, err, sizeof err), CS_OK);
    assert_false(r4.from_cache);
    assert_string_not_equal(r4.cache_path, r1.cache_path);

    /* a file under the right name but made from other input is not used */
    cs_levelset_destroy(r2.grid);
    rename(r3.cache_path, r1.cache_path);
    req.voxel_size = 0.1;
    assert_int_equal(cs_levelset_build(m, &req, &r2, err, sizeof err), CS_OK);
    assert_false(r2.from_cache);
    assert_non_null(strstr(r2.cache_note, "other input"));

    /* the .vdb opens on its own, as other tools would open it */
    cs_levelset *back = cs_levelset_read(r1.cache_path, NULL, NULL, err, sizeof err);
    assert_non_null(back);
    cs_levelset_info info;
    cs_levelset_get_info(back, &info);
    assert_true(fabs(info.voxel_size - 0.1) < 1e-12);
    cs_levelset_destroy(back);
    /* an unwritable cache is a note, not a failure */
    req.cache_dir = "/proc/no/such/dir";
    cs_levelset_destroy(r2.grid);
    assert_int_equal(cs_levelset_build(m, &req, &r2, err, sizeof err), CS_OK);
    assert_non_null(r2.grid);
    assert_non_null(strstr(r2.cache_note, "not kept"));

    cs_levelset_destroy(r1.grid);
    cs_levelset_destroy(r2.grid);
    cs_levelset_destroy(r3.grid);
    cs_levelset_destroy(r4.grid);
    cs_trimesh_destroy(m);
}

static void test_cache_dir_choice(void **state)
{
    (void)state;
    char *d = cs_levelset_cache_dir("grids", "/scenes");
    assert_string_equal(d, "/scenes/grids");
    free(d);
    assert_null(cs_levelset_cache_dir("none", "/scenes"));
    setenv("CLOTHSIM_CACHE", "/tmp/x", 1);
    d = cs_levelset_cache_dir(NULL, "/scenes");
    assert_string_equal(d, "/tmp/x");
    free(d);
    setenv("CLOTHSIM_CACHE", "off", 1);
    assert_null(cs_levelset_cache_dir(NULL, "/scenes"));
    unsetenv("CLOTHSIM_CACHE");
    setenv("XDG_CACHE_HOME", "/xdg", 1);
    d = cs_levelset_cache_dir(NULL, "/scenes");
    assert_string_equal(d, "/xdg/clothsim");
    free(d);
}

static void test_voxel_checks(void **state)
{
    (void)state;
    cs_mesh_report rep;
    cs_trimesh *m = load("ico4.obj", &rep);
    char why[256];
    assert_true(cs_levelset_voxel_ok(&rep, 0.05, 3, true, why, sizeof why));
    assert_false(cs_levelset_voxel_ok(&rep, 0.6, 3, true, why, sizeof why));
    assert_non_null(strstr(why, "quarter"));
    assert_false(cs_levelset_voxel_ok(&rep, 1e-5, 3, false, why, sizeof why));
    assert_non_null(strstr(why, "would need about"));
    assert_non_null(strstr(why, "available"));
    /* the default follows the cloth's edge, within the mesh's limits */
    assert_true(fabs(cs_levelset_default_voxel(&rep, 0.04, 3, true) - 0.02) < 1e-12);
    assert_true(fabs(cs_levelset_default_voxel(&rep, 1.0, 3, true) - 2.0 / 32) < 1e-3);
    assert_true(fabs(cs_levelset_default_voxel(&rep, 0, 3, true) - 0.02) < 1e-12);
    cs_trimesh_destroy(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_accuracy_sphere),
        cmocka_unit_test(test_gradient_sphere),
        cmocka_unit_test(test_accuracy_bunny),
        cmocka_unit_test(test_particle_on_imported_sphere),
        cmocka_unit_test(test_moving_grid_body),
        cmocka_unit_test(test_cache),
        cmocka_unit_test(test_cache_dir_choice),
        cmocka_unit_test(test_voxel_checks),
    };
    return cmocka_run_group_tests(tests, make_cache_dir, remove_cache_dir);
}
