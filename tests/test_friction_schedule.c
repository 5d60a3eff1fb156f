/* test_friction_schedule.c: a body's friction that changes over time
 * (bodies[].friction_keys).
 *
 * - cs_body_def_friction: piecewise linear between keys, constant outside,
 *   the constant `friction` without keys.
 * - The incline of tests/test_incline.c (theta = 36 degrees, tan theta =
 *   0.7265) with mu = 0.9 > tan theta held until t1 = 0.3 s, then a ramp
 *   to mu = 0.2 at t2 = 0.4 s. mu(t) crosses tan theta at t* = t1 + (0.9 -
 *   tan theta) / k, k = (0.9 - 0.2) / (t2 - t1) the ramp's slope. Before t*
 *   the body is held (static friction); on the ramp it accelerates at
 *   a(t) = g cos theta k (t - t*), so v(t2) = g cos theta k (t2 - t*)^2 / 2
 *   and s(t2) = g cos theta k (t2 - t*)^3 / 6; after t2 at the constant
 *   a1 = g (sin theta - 0.2 cos theta). The distance travelled is checked
 *   at every frame against that with test_incline's tolerance (1e-3 of the
 *   distance, or 1e-4 m where that is smaller), for a particle and for the
 *   damped tetrahedron, loaded from scene text through the loader.
 * - A run stopped on the ramp and resumed from its state arrays (as
 *   `clothsim run --resume` does) ends with the same bits: the schedule is
 *   part of the definition, evaluated from the time alone.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "import/import.h"
#include "sim/internal.h"

#define G 9.8
#define THETA_DEG 36.0
#define MU0 0.9
#define MU1 0.2
#define T1 0.3
#define T2 0.4

/* ------------------------------------------------- the schedule itself */

static void test_schedule_values(void **state)
{
    (void)state;
    cs_body_def b = cs_default_body_def();
    b.friction = 0.45;
    assert_int_equal(b.nfriction_keys, 0);
    assert_true(cs_body_def_friction(&b, -1) == 0.45);
    assert_true(cs_body_def_friction(&b, 7) == 0.45);

    b.nfriction_keys = 3;
    b.friction_keys[0] = (cs_friction_key){0.5, 0.8};
    b.friction_keys[1] = (cs_friction_key){1.5, 0.05};
    b.friction_keys[2] = (cs_friction_key){2.0, 0.25};
    double want[][2] = {{-3, 0.8},   {0, 0.8},   {0.5, 0.8},   {1.0, 0.425}, {1.5, 0.05},
                        {1.75, 0.15}, {2.0, 0.25}, {9.0, 0.25}, {1.25, 0.2375}};
    for (size_t k = 0; k < sizeof want / sizeof want[0]; k++) {
        double got = cs_body_def_friction(&b, want[k][0]);
        if (fabs(got - want[k][1]) > 1e-15)
            fail_msg("mu(%g) = %.17g, want %g", want[k][0], got, want[k][1]);
    }
    /* `friction` is unused once there are keys */
    b.friction = 123;
    assert_true(fabs(cs_body_def_friction(&b, 1.0) - 0.425) < 1e-15);
    /* one key: constant */
    b.nfriction_keys = 1;
    assert_true(cs_body_def_friction(&b, -1) == 0.8 && cs_body_def_friction(&b, 5) == 0.8);
}

/* --------------------------------------------------------- the incline */

/* The scenes of scenes/validation/particle_accelerating.yaml and
 * tetrahedron_accelerating.yaml with the schedule instead of friction: the
 * 36 degree incline whose friction ramps from 0.9 down to 0.2. */
#define RAMPED_INCLINE                                                                       \
    "bodies:\n"                                                                              \
    "  - shape: plane\n"                                                                     \
    "    rotation: [0, 0, 36]\n"                                                             \
    "    friction_keys:\n"                                                                   \
    "      - {time: 0, friction: 0.9}\n"                                                     \
    "      - {time: 0.3, friction: 0.9}\n"                                                   \
    "      - {time: 0.4, friction: 0.2}\n"

static const char *particle_scene =
    "time: {fps: 100, frames: 100, dt: 0.001}\n"
    "gravity: [0, -9.8, 0]\n"
    "cloths:\n"
    "  - mesh: {vertices: [[0, 0, 0]]}\n" RAMPED_INCLINE;

static const char *tetrahedron_scene =
    "time: {fps: 100, frames: 100, cg_tolerance: 1e-9}\n"
    "gravity: [0, -9.8, 0]\n"
    "cloths:\n"
    "  - mesh:\n"
    "      vertices: [[0, 0, 0.1], [0.08660254037844387, 0, -0.05],\n"
    "                 [-0.08660254037844387, 0, -0.05], [0, 0.1414213562373095, 0]]\n"
    "      triangles: [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]\n"
    "      rotation: [0, 0, 36]\n"
    "    material: {edge_stiffness: 100, edge_overdamping: 1, bend_stiffness: 100,\n"
    "               bend_overdamping: 1, node_mass: 0.001}\n" RAMPED_INCLINE;

/* Distance down the slope at time t from rest at t = 0. */
static double analytic_distance(double t)
{
    double th = THETA_DEG * M_PI / 180, c = cos(th);
    double k = (MU0 - MU1) / (T2 - T1);
    double ts = T1 + (MU0 - tan(th)) / k; /* mu(ts) = tan theta */
    if (t <= ts)
        return 0;
    if (t <= T2)
        return G * c * k * pow(t - ts, 3) / 6;
    double v2 = G * c * k * pow(T2 - ts, 2) / 2, s2 = G * c * k * pow(T2 - ts, 3) / 6;
    double a1 = G * (sin(th) - MU1 * c);
    return s2 + v2 * (t - T2) + 0.5 * a1 * (t - T2) * (t - T2);
}

static cs_scene *load(const char *text)
{
    char err[512] = "";
    cs_scene *s = NULL;
    /* the analytic tolerance holds at the undamped step (docs/accuracy.md) */
    const char *undamped[] = {"time.step_limit=undamped"};
    if (cs_scene_load_string(text, "friction.yaml", 1, undamped, &s, err, sizeof err) !=
        CS_OK)
        fail_msg("%s", err);
    return s;
}

static cs_sim *create(const cs_scene *s)
{
    char err[512] = "";
    cs_sim *sim = cs_sim_create(&s->def, err, sizeof err);
    if (!sim)
        fail_msg("cs_sim_create: %s", err);
    return sim;
}

/* Centre of mass down the slope, relative to com0. */
static double slope_distance(const cs_sim *sim, const double com0[3])
{
    double th = THETA_DEG * M_PI / 180, down[3] = {-cos(th), -sin(th), 0};
    int n = cs_sim_particle_count(sim);
    const double *m = cs_sim_masses(sim), *x = cs_sim_positions(sim);
    double total = 0, s = 0;
    for (int i = 0; i < n; i++) {
        total += m[i];
        for (int d = 0; d < 3; d++)
            s += m[i] * (x[3 * i + d] - com0[d]) * down[d];
    }
    return s / total;
}

static void centre_of_mass(const cs_sim *sim, double com[3])
{
    int n = cs_sim_particle_count(sim);
    const double *m = cs_sim_masses(sim), *x = cs_sim_positions(sim);
    double total = 0;
    com[0] = com[1] = com[2] = 0;
    for (int i = 0; i < n; i++) {
        total += m[i];
        for (int d = 0; d < 3; d++)
            com[d] += m[i] * x[3 * i + d];
    }
    for (int d = 0; d < 3; d++)
        com[d] /= total;
}

/* held: the largest distance allowed while static friction holds. */
static void expect_held_then_analytic(const char *what, const char *text, double held)
{
    cs_scene *s = load(text);
    assert_int_equal(s->def.nbodies, 1);
    assert_int_equal(s->def.bodies[0].nfriction_keys, 3);
    cs_sim *sim = create(s);
    double com0[3], worst = 0, moved_while_held = 0, end = 0, exact = 0;
    centre_of_mass(sim, com0);
    double ts = T1 + (MU0 - tan(THETA_DEG * M_PI / 180)) / ((MU0 - MU1) / (T2 - T1));
    for (int f = 1; f <= s->frames; f++) {
        cs_frame_stats st;
        if (cs_sim_advance_frame(sim, &st) != CS_OK)
            fail_msg("%s: unstable at frame %d", what, f);
        double t = cs_sim_time(sim), d = slope_distance(sim, com0);
        exact = analytic_distance(t);
        end = d;
        if (t <= ts)
            moved_while_held = fmax(moved_while_held, fabs(d));
        worst = fmax(worst, fabs(d - exact) / fmax(1e-3 * fabs(exact), 1e-4));
    }
    double t = cs_sim_time(sim);
    cs_sim_destroy(sim);
    cs_scene_destroy(s);
    print_message("%s: held to %.2g m before t* = %.4f s; at t = %.2f s %.6f m, analytic %.6f m "
                  "(worst error %.3g of the tolerance)\n",
                  what, moved_while_held, ts, t, end, exact, worst);
    if (!(moved_while_held <= held))
        fail_msg("%s: moved %.3g m while mu > tan theta (allowed %.3g)", what, moved_while_held,
                 held);
    if (!(worst <= 1))
        fail_msg("%s: %.3g of the tolerance off the analytic distance (%.6f m against %.6f m "
                 "at the end)",
                 what, worst, end, exact);
    /* neither constant coefficient explains it: the schedule acted */
    double th = THETA_DEG * M_PI / 180;
    double slid_all_along = 0.5 * G * (sin(th) - MU1 * cos(th)) * t * t;
    assert_true(end > 0.3 && fabs(end - slid_all_along) > 0.1);
}

static void test_particle_held_then_slides(void **state)
{
    (void)state;
    /* a particle in steady contact is exact to round-off on the incline */
    expect_held_then_analytic("particle", particle_scene, 1e-12);
}

static void test_tetrahedron_held_then_slides(void **state)
{
    (void)state;
    /* the elastic tetrahedron settles a little as it is set down */
    expect_held_then_analytic("tetrahedron", tetrahedron_scene, 1e-4);
}

/* ------------------------------------------------------------ resuming */

static void test_resume_on_the_ramp(void **state)
{
    (void)state;
    cs_scene *s = load(tetrahedron_scene);
    cs_frame_stats st;
    int frames = 60, stop = 35; /* t = 0.35 s: on the ramp, sliding */

    cs_sim *straight = create(s);
    for (int f = 0; f < frames; f++)
        assert_int_equal(cs_sim_advance_frame(straight, &st), CS_OK);

    cs_sim *first = create(s);
    for (int f = 0; f < stop; f++)
        assert_int_equal(cs_sim_advance_frame(first, &st), CS_OK);
    cs_state_array a[CS_STATE_MAX_ARRAYS], b[CS_STATE_MAX_ARRAYS];
    int na = cs_sim_state_arrays(first, a);
    double *saved[CS_STATE_MAX_ARRAYS];
    for (int k = 0; k < na; k++) {
        saved[k] = malloc(sizeof(double) * a[k].count);
        assert_non_null(saved[k]);
        memcpy(saved[k], a[k].data, sizeof(double) * a[k].count);
    }
    cs_sim_destroy(first);

    cs_sim *resumed = create(s);
    assert_int_equal(cs_sim_state_arrays(resumed, b), na);
    for (int k = 0; k < na; k++) {
        assert_string_equal(a[k].name, b[k].name);
        assert_int_equal(a[k].count, b[k].count);
        memcpy(b[k].data, saved[k], sizeof(double) * b[k].count);
        free(saved[k]);
    }
    for (int f = stop; f < frames; f++)
        assert_int_equal(cs_sim_advance_frame(resumed, &st), CS_OK);

    int n = cs_sim_particle_count(straight);
    assert_true(cs_sim_time(straight) == cs_sim_time(resumed));
    assert_memory_equal(cs_sim_positions(straight), cs_sim_positions(resumed),
                        3 * sizeof(double) * (size_t)n);
    assert_memory_equal(cs_sim_velocities(straight), cs_sim_velocities(resumed),
                        3 * sizeof(double) * (size_t)n);
    cs_sim_destroy(straight);
    cs_sim_destroy(resumed);
    cs_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_schedule_values),
        cmocka_unit_test(test_particle_held_then_slides),
        cmocka_unit_test(test_tetrahedron_held_then_slides),
        cmocka_unit_test(test_resume_on_the_ramp),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
