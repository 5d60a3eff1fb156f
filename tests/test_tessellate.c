/* Tests of cs_body_def_tessellate (sim/tessellate.c): vertices on the
 * analytic surface, outward winding, enclosed volume close to the shape's,
 * the body's pose at time t applied, and refusals. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "sim/sim.h"

/* Signed volume by the divergence theorem: positive for outward winding. */
static double volume(const cs_trimesh *m)
{
    double v = 0;
    for (int t = 0; t < m->nt; t++) {
        const double *a = m->x + 3 * m->tri[3 * t], *b = m->x + 3 * m->tri[3 * t + 1],
                     *c = m->x + 3 * m->tri[3 * t + 2];
        v += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
              a[2] * (b[0] * c[1] - b[1] * c[0])) /
             6.0;
    }
    return v;
}

/* Every triangle's normal points away from the centre (convex shapes). */
static void assert_outward(const cs_trimesh *m, const double centre[3])
{
    for (int t = 0; t < m->nt; t++) {
        const double *a = m->x + 3 * m->tri[3 * t], *b = m->x + 3 * m->tri[3 * t + 1],
                     *c = m->x + 3 * m->tri[3 * t + 2];
        double e1[3], e2[3], n[3], g[3];
        for (int i = 0; i < 3; i++) {
            e1[i] = b[i] - a[i];
            e2[i] = c[i] - a[i];
            g[i] = (a[i] + b[i] + c[i]) / 3 - centre[i];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        assert_true(n[0] * g[0] + n[1] * g[1] + n[2] * g[2] > 0);
    }
}

static void assert_on_surface(const cs_body_def *b, double t, const cs_trimesh *m, double tol)
{
    for (int v = 0; v < m->nv; v++) {
        double g[3];
        double phi = cs_body_def_phi(b, t, m->x + 3 * v, g);
        if (fabs(phi) > tol)
            fail_msg("vertex %d is %g from the surface", v, phi);
    }
}

static void test_sphere(void **state)
{
    (void)state;
    cs_body_def b = cs_default_body_def();
    b.shape = CS_BODY_SPHERE;
    b.radius = 0.7;
    b.motion.kind = CS_MOTION_CONSTANT;
    b.motion.position[0] = 1;
    b.motion.velocity[1] = 2;
    cs_trimesh *m = cs_body_def_tessellate(&b, 0.5, 0, 48);
    assert_non_null(m);
    assert_int_equal(m->nv, 2 + 23 * 48);   /* shared vertices: smooth */
    assert_int_equal(m->nt, 2 * 48 * 23);
    assert_on_surface(&b, 0.5, m, 1e-12);
    double centre[3] = {1, 1, 0};
    assert_outward(m, centre);
    double exact = 4.0 / 3.0 * M_PI * 0.7 * 0.7 * 0.7, v = volume(m);
    assert_true(v < exact && v > 0.98 * exact);
    for (int i = 0; i < 3 * m->nv; i++)
        assert_true(isfinite(m->x[i]));
    cs_trimesh_destroy(m);
}

static void test_box_and_cylinder(void **state)
{
    (void)state;
    cs_body_def b = cs_default_body_def();
    b.shape = CS_BODY_BOX;
    b.half_extents[0] = 0.3;
    b.half_extents[1] = 0.2;
    b.half_extents[2] = 0.1;
    /* Keyframed: a quarter turn about y and a shift over one second. */
    cs_keyframe keys[2] = {{0, {0, 0, 0}, {1, 0, 0, 0}},
                           {1, {0.5, 1, 0}, {cos(M_PI / 4), 0, sin(M_PI / 4), 0}}};
    b.motion.kind = CS_MOTION_KEYFRAMES;
    b.motion.nkeys = 2;
    b.motion.keys = keys;
    cs_trimesh *m = cs_body_def_tessellate(&b, 1.0, 0, 0);
    assert_non_null(m);
    assert_int_equal(m->nv, 24);   /* four per face: edges stay sharp */
    assert_int_equal(m->nt, 12);
    assert_on_surface(&b, 1.0, m, 1e-12);
    double c[3] = {0.5, 1, 0};
    assert_outward(m, c);
    assert_true(fabs(volume(m) - 8 * 0.3 * 0.2 * 0.1) < 1e-12);
    cs_trimesh_destroy(m);

    b = cs_default_body_def();
    b.shape = CS_BODY_CYLINDER;
    b.radius = 0.2;
    b.half_height = 0.5;
    double deg[3] = {90, 0, 0};
    cs_quat_from_euler_degrees(deg, b.motion.rotation);
    m = cs_body_def_tessellate(&b, 0, 0, 32);
    assert_non_null(m);
    assert_int_equal(m->nt, 4 * 32);
    assert_on_surface(&b, 0, m, 1e-12);
    double o[3] = {0, 0, 0};
    assert_outward(m, o);
    double exact = M_PI * 0.2 * 0.2 * 1.0, v = volume(m);
    assert_true(v < exact && v > 0.98 * exact);
    cs_trimesh_destroy(m);
}

static void test_plane_and_refusals(void **state)
{
    (void)state;
    cs_body_def b = cs_default_body_def();   /* a plane */
    double n[3] = {0, 0, 1};
    cs_quat_from_y_to(n, b.motion.rotation);
    b.motion.position[2] = -2;
    cs_trimesh *m = cs_body_def_tessellate(&b, 0, 5, 0);
    assert_non_null(m);
    assert_int_equal(m->nv, 4);
    assert_int_equal(m->nt, 2);
    for (int v = 0; v < 4; v++) {
        assert_true(fabs(m->x[3 * v + 2] + 2) < 1e-12);   /* in the plane z = -2 */
        assert_true(fabs(fabs(m->x[3 * v]) - 5) < 1e-12);
    }
    /* Wound so the normal is the plane's. */
    const double *a = m->x + 3 * m->tri[0], *p = m->x + 3 * m->tri[1], *q = m->x + 3 * m->tri[2];
    double e1[2] = {p[0] - a[0], p[1] - a[1]}, e2[2] = {q[0] - a[0], q[1] - a[1]};
    assert_true(e1[0] * e2[1] - e1[1] * e2[0] > 0);
    cs_trimesh_destroy(m);

    assert_null(cs_body_def_tessellate(&b, 0, 0, 0));      /* a plane needs an extent */
    assert_null(cs_body_def_tessellate(NULL, 0, 1, 8));
    b = cs_default_body_def();
    b.shape = CS_BODY_SPHERE;
    b.radius = -1;
    assert_null(cs_body_def_tessellate(&b, 0, 0, 8));
    b.radius = 1;
    m = cs_body_def_tessellate(&b, 0, 0, 1);   /* detail clamped to 3 */
    assert_non_null(m);
    assert_int_equal(m->nv, 2 + 1 * 3);
    cs_trimesh_destroy(m);
}

static double phi_fn(const void *data, const double p[3], double g[3])
{
    (void)data;
    g[0] = 0;
    g[1] = 1;
    g[2] = 0;
    return p[1];
}

static void test_distance_function_body(void **state)
{
    (void)state;
    cs_body_def b = cs_default_body_def();
    b.phi_fn = phi_fn;
    assert_null(cs_body_def_tessellate(&b, 0, 1, 8));   /* nothing analytic to draw */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_box_and_cylinder),
        cmocka_unit_test(test_plane_and_refusals),
        cmocka_unit_test(test_distance_function_body),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
