/* test_body_grid.c: many bodies (Section 6) through the uniform partition of
 * body occupancy (sim/body_grid.c):
 * - every body's world box holds all points where its phi < 0, in motion;
 * - B.4 with the partition is bit for bit the loop over all bodies per
 *   point, also where bodies overlap and a point pushed out of one lands in
 *   the next (checked against the same bodies made unbounded);
 * - bodies away from the cloth cost no queries: 48 of them add none;
 * - cs_sim_body_penetration reports the deepest free vertex. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sim/body_grid.h"
#include "sim/sim.h"

static double urand(double lo, double hi) { return lo + (hi - lo) * rand() / (double)RAND_MAX; }

static cs_body_def body(cs_body_shape shape, double x, double y, double z)
{
    cs_body_def b = cs_default_body_def();
    b.shape = shape;
    b.motion.position[0] = x;
    b.motion.position[1] = y;
    b.motion.position[2] = z;
    b.friction = 0.4;
    return b;
}

static void test_bounds_hold_the_inside(void **state)
{
    (void)state;
    srand(3);
    cs_body_def bodies[4];
    bodies[0] = body(CS_BODY_SPHERE, 0.3, 0.2, -0.1);
    bodies[0].radius = 0.4;
    bodies[1] = body(CS_BODY_BOX, -0.2, 0.1, 0.3);
    bodies[1].half_extents[0] = 0.5, bodies[1].half_extents[1] = 0.1,
    bodies[1].half_extents[2] = 0.2;
    double deg[3] = {20, 35, -50};
    cs_quat_from_euler_degrees(deg, bodies[1].motion.rotation);
    bodies[2] = body(CS_BODY_CYLINDER, 0.1, -0.2, 0.2);
    bodies[2].radius = 0.15, bodies[2].half_height = 0.45;
    bodies[2].motion.kind = CS_MOTION_CONSTANT;
    bodies[2].motion.velocity[0] = 0.5;
    bodies[2].motion.angular_velocity[2] = 3;
    bodies[3] = bodies[1];
    bodies[3].motion.kind = CS_MOTION_CONSTANT;
    bodies[3].motion.angular_velocity[0] = -2;
    bodies[3].motion.angular_velocity[1] = 1;
    for (int b = 0; b < 4; b++)
        for (int k = 0; k < 3; k++) {
            double t = 0.37 * k, lo[3], hi[3];
            assert_true(cs_body_def_bounds(&bodies[b], t, lo, hi));
            int inside = 0;
            for (int i = 0; i < 20000; i++) {
                double p[3], g[3];
                for (int d = 0; d < 3; d++)
                    p[d] = urand(lo[d] - 0.3, hi[d] + 0.3);
                if (!(cs_body_def_phi(&bodies[b], t, p, g) < 0))
                    continue;
                inside++;
                for (int d = 0; d < 3; d++)
                    assert_true(p[d] >= lo[d] && p[d] <= hi[d]);
            }
            assert_true(inside > 100);
        }
    /* unbounded: a plane, and a distance function without a box */
    cs_body_def plane = body(CS_BODY_PLANE, 0, 0, 0);
    double lo[3], hi[3];
    assert_false(cs_body_def_bounds(&plane, 0, lo, hi));
}

/* ------------------------------------------------ exact same physics */

/* The body's own shape at rest, as a distance function: cs_body_def_phi
 * with an identity pose computes exactly what the shape does. */
static double shape_phi(const void *data, const double p[3], double g[3])
{
    cs_body_def inner = *(const cs_body_def *)data;
    inner.motion = cs_motion_static();
    inner.phi_fn = NULL;
    return cs_body_def_phi(&inner, 0, p, g);
}

typedef struct counted {
    const cs_body_def *shape;
    long *calls;
} counted;

static double counted_phi(const void *data, const double p[3], double g[3])
{
    const counted *c = data;
    (*c->calls)++;
    return shape_phi(c->shape, p, g);
}

/* Overlapping spheres, boxes and a cylinder, two of them moving, over a
 * ground plane: a sheet falls through the lot. */
static int make_bodies(cs_body_def *b)
{
    int n = 0;
    b[n] = body(CS_BODY_SPHERE, 0, 0.35, 0), b[n++].radius = 0.3;
    b[n] = body(CS_BODY_SPHERE, 0.25, 0.3, 0.1), b[n++].radius = 0.25;
    b[n] = body(CS_BODY_BOX, -0.3, 0.2, -0.2);
    b[n].half_extents[0] = 0.3, b[n].half_extents[1] = 0.2, b[n].half_extents[2] = 0.15;
    double deg[3] = {0, 30, 10};
    cs_quat_from_euler_degrees(deg, b[n++].motion.rotation);
    b[n] = body(CS_BODY_CYLINDER, 0.1, 0.3, -0.3);
    b[n].radius = 0.12, b[n].half_height = 0.3;
    b[n].motion.kind = CS_MOTION_CONSTANT;
    b[n].motion.velocity[0] = 0.2;
    b[n++].motion.angular_velocity[1] = 2;
    b[n] = body(CS_BODY_SPHERE, -0.1, 0.5, 0.35), b[n].radius = 0.15;
    b[n].motion.kind = CS_MOTION_CONSTANT;
    b[n++].motion.velocity[1] = 0.3;
    b[n++] = body(CS_BODY_PLANE, 0, 0, 0);
    return n;
}

static cs_sim *drop_sheet(const cs_body_def *bodies, int nbodies, cs_trimesh **mesh,
                          cs_friction_method method)
{
    double size[2] = {1.2, 1.2}, rot[4] = {1, 0, 0, 0}, centre[3] = {0, 0.9, 0};
    int res[2] = {16, 16};
    *mesh = cs_trimesh_create_grid(size, res, rot, centre);
    static cs_cloth_def cloth;
    cloth = (cs_cloth_def){.name = "sheet", .mesh = *mesh, .material = cs_default_cloth_material()};
    cloth.material.density = 0.15;
    cs_sim_def def = cs_default_sim_def();
    def.cloths = &cloth;
    def.ncloths = 1;
    def.bodies = bodies;
    def.nbodies = nbodies;
    def.friction_method = method;
    def.step_limit = CS_STEP_UNDAMPED; /* the contact counts below are per step */
    char err[256];
    cs_sim *sim = cs_sim_create(&def, err, sizeof err);
    assert_non_null(sim);
    return sim;
}

static void test_same_physics_as_every_body_per_point(void **state)
{
    (void)state;
    for (int m = 0; m < 2; m++) {
        cs_friction_method method = m ? CS_FRICTION_PROJECTION : CS_FRICTION_IMPROVED;
        cs_body_def shapes[8], plain[8];
        int n = make_bodies(shapes);
        for (int b = 0; b < n; b++) { /* the same shape, unbounded: every point asked */
            plain[b] = shapes[b];
            if (shapes[b].shape != CS_BODY_PLANE) {
                plain[b].phi_fn = shape_phi;
                plain[b].phi_data = &shapes[b];
            }
        }
        cs_trimesh *m1, *m2;
        cs_sim *a = drop_sheet(shapes, n, &m1, method), *b = drop_sheet(plain, n, &m2, method);
        long contacts = 0;
        for (int f = 0; f < 8; f++) {
            cs_frame_stats sa, sb;
            assert_int_equal(cs_sim_advance_frame(a, &sa), CS_OK);
            assert_int_equal(cs_sim_advance_frame(b, &sb), CS_OK);
            assert_int_equal(sa.body_contacts, sb.body_contacts);
            contacts += sa.body_contacts;
        }
        int np = cs_sim_particle_count(a);
        assert_memory_equal(cs_sim_positions(a), cs_sim_positions(b), 3 * sizeof(double) * np);
        assert_memory_equal(cs_sim_velocities(a), cs_sim_velocities(b), 3 * sizeof(double) * np);
        assert_true(contacts > 1000); /* it did meet the bodies */
        cs_sim_destroy(a);
        cs_sim_destroy(b);
        cs_trimesh_destroy(m1);
        cs_trimesh_destroy(m2);
    }
}

/* ------------------------------------------------------ many bodies */

static void test_far_bodies_cost_no_queries(void **state)
{
    (void)state;
    cs_body_def shape = body(CS_BODY_SPHERE, 0, 0, 0);
    shape.radius = 0.3;
    long calls_one = 0, calls_many = 0;
    counted c_one = {&shape, &calls_one}, c_many = {&shape, &calls_many};

    /* a distance function with its box: the sphere under the cloth */
    cs_body_def near = body(CS_BODY_MESH, 0, 0.35, 0);
    near.phi_fn = counted_phi;
    near.phi_bounded = true;
    for (int k = 0; k < 3; k++)
        near.phi_min[k] = -0.3, near.phi_max[k] = 0.3;

    cs_body_def one[1] = {near};
    one[0].phi_data = &c_one;
    cs_body_def many[49];
    for (int i = 0; i < 49; i++) {
        many[i] = near;
        many[i].phi_data = &c_many;
        if (i > 0) { /* 48 more on a ring 5 m out */
            many[i].motion.position[0] = 5 * cos(2 * M_PI * i / 48);
            many[i].motion.position[2] = 5 * sin(2 * M_PI * i / 48);
        }
    }
    cs_trimesh *m1, *m2;
    cs_sim *a = drop_sheet(one, 1, &m1, CS_FRICTION_IMPROVED);
    cs_sim *b = drop_sheet(many, 49, &m2, CS_FRICTION_IMPROVED);
    for (int f = 0; f < 8; f++) {
        assert_int_equal(cs_sim_advance_frame(a, NULL), CS_OK);
        assert_int_equal(cs_sim_advance_frame(b, NULL), CS_OK);
    }
    /* the queries are those of the near sphere only, and far fewer than
     * every point against every body would take */
    long steps = 8L * (long)lround(1.0 / 24 / cs_sim_dt(a));
    assert_int_equal(calls_many, calls_one);
    assert_true(calls_one > 0);
    assert_true(calls_many < steps * cs_sim_particle_count(b) * 49 / 20);
    int np = cs_sim_particle_count(a);
    assert_memory_equal(cs_sim_positions(a), cs_sim_positions(b), 3 * sizeof(double) * np);
    cs_sim_destroy(a);
    cs_sim_destroy(b);
    cs_trimesh_destroy(m1);
    cs_trimesh_destroy(m2);
}

static void test_penetration(void **state)
{
    (void)state;
    cs_body_def ball = body(CS_BODY_SPHERE, 0, 0, 0);
    ball.radius = 1;
    cs_trimesh *pts = cs_trimesh_create(3, 0);
    double x[9] = {0, 0.9, 0, /* 0.1 deep */ 0, 0.5, 0, /* 0.5 deep, pinned */ 3, 0, 0};
    memcpy(pts->x, x, sizeof x);
    int pinned = 1;
    cs_vertex_script pin = {.nvertices = 1, .vertices = &pinned, .motion = cs_motion_static()};
    cs_cloth_def cloth = {.name = "p", .mesh = pts, .material = cs_default_cloth_material(),
                          .nscripts = 1, .scripts = &pin};
    cs_sim_def def = cs_default_sim_def();
    def.cloths = &cloth;
    def.ncloths = 1;
    def.bodies = &ball;
    def.nbodies = 1;
    char err[256];
    cs_sim *sim = cs_sim_create(&def, err, sizeof err);
    assert_non_null(sim);
    assert_true(fabs(cs_sim_body_penetration(sim) - 0.1) < 1e-12);
    cs_sim_step(sim, 1e-3); /* pushed out */
    assert_true(cs_sim_body_penetration(sim) < 1e-9);
    cs_sim_destroy(sim);
    def.bodies_enabled = false;
    sim = cs_sim_create(&def, err, sizeof err);
    assert_true(cs_sim_body_penetration(sim) == 0);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(pts);
}

/* The surface between vertices counts: one large triangle over a unit ball
 * with every vertex 2 m from the centre and its centroid 5 cm inside. */
static void test_penetration_between_vertices(void **state)
{
    (void)state;
    cs_body_def ball = body(CS_BODY_SPHERE, 0, 0, 0);
    ball.radius = 1;
    cs_trimesh *tri = cs_trimesh_create(3, 1);
    double x[9] = {-2, 0.95, -1.1547, 2, 0.95, -1.1547, 0, 0.95, 2.3094};
    memcpy(tri->x, x, sizeof x);
    tri->tri[0] = 0, tri->tri[1] = 1, tri->tri[2] = 2;
    cs_cloth_def cloth = {.name = "t", .mesh = tri, .material = cs_default_cloth_material()};
    cs_sim_def def = cs_default_sim_def();
    def.cloths = &cloth;
    def.ncloths = 1;
    def.bodies = &ball;
    def.nbodies = 1;
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    assert_true(fabs(cs_sim_body_penetration(sim) - 0.05) < 1e-4);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(tri);
}

/* bodies[].collision_offset: a particle dropped on the ground comes to rest
 * the offset above it, and the penetration report still measures against
 * the true surface (0: nothing is inside). */
static void test_collision_offset(void **state)
{
    (void)state;
    cs_body_def ground = body(CS_BODY_PLANE, 0, 0, 0);
    ground.offset = 0.02;
    cs_trimesh *pt = cs_trimesh_create(1, 0);
    pt->x[1] = 0.1;
    cs_cloth_def cloth = {.name = "p", .mesh = pt, .material = cs_default_cloth_material()};
    cs_sim_def def = cs_default_sim_def();
    def.cloths = &cloth;
    def.ncloths = 1;
    def.bodies = &ground;
    def.nbodies = 1;
    def.fps = 24;
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    cs_frame_stats st;
    for (int f = 0; f < 12; f++) /* 0.5 s: it lands after 0.13 s */
        assert_int_equal(cs_sim_advance_frame(sim, &st), CS_OK);
    double y = cs_sim_positions(sim)[1];
    assert_true(fabs(y - 0.02) < 1e-3);
    assert_true(cs_sim_body_penetration(sim) == 0);
    cs_sim_destroy(sim);
    ground.offset = 0;
    sim = cs_sim_create(&def, NULL, 0);
    for (int f = 0; f < 12; f++)
        assert_int_equal(cs_sim_advance_frame(sim, &st), CS_OK);
    assert_true(fabs(cs_sim_positions(sim)[1]) < 1e-3);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(pt);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bounds_hold_the_inside),
        cmocka_unit_test(test_same_physics_as_every_body_per_point),
        cmocka_unit_test(test_far_bodies_cost_no_queries),
        cmocka_unit_test(test_penetration),
        cmocka_unit_test(test_penetration_between_vertices),
        cmocka_unit_test(test_collision_offset),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
