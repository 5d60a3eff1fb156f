/* Every term of the model checked on its own: the
 * self-collision terms of Section 5, each in a scene of one or two pairs
 * whose response has a closed form: Eq. 1's elastic repulsion in both of
 * its branches, the inelastic repulsion, cloth-cloth Coulomb friction as
 * an impulse and while sliding, and the edge/edge history rule. The
 * second cloth is pinned (its inverse mass is 0), so a pair's response
 * moves the free side alone and the expected motion is exact. Time steps
 * are set explicitly (Eq. 1 depends on dt). The other terms are in
 * test_terms.c, with the table of mutations these files catch.
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

#include "sim/sim.h"
#include "mesh_of.h"
#include "terms_sim.h"

/* A pinned horizontal triangle in y = 0, large enough that everything
 * above it here projects inside it, and a second cloth: a lone particle
 * (no triangles: the only pair is point/triangle) or a triangle. */
typedef struct pair_scene {
    cs_trimesh *floor, *top;
    int pins[3];
    cs_vertex_script pin;
    cs_cloth_def cloths[2];
    cs_sim_def def;
    cs_sim *sim;
    int floor_cloth, top_offset; /* which cloth is the floor; the top's first particle */
} pair_scene;


/* floor: 3 vertices (pinned); top: ntop vertices, ttop triangles, all free
 * with velocity v. Steps of dt, frames of steps_per_frame steps. The floor
 * is the first cloth (its particles come first) unless top_first. */
static void scene_create_ordered(pair_scene *s, const double *floor_x, int ntop,
                                 const double *top_x, int ttop, const int *top_tri,
                                 const double v[3], double dt, int steps_per_frame,
                                 double gravity, bool top_first)
{
    memset(s, 0, sizeof *s);
    s->floor_cloth = top_first ? 1 : 0;
    s->top_offset = top_first ? 0 : 3;
    int tri[3] = {0, 1, 2};
    s->floor = mesh_of(3, floor_x, 1, tri);
    s->top = mesh_of(ntop, top_x, ttop, top_tri);
    for (int k = 0; k < 3; k++)
        s->pins[k] = k;
    s->pin = (cs_vertex_script){3, s->pins, cs_motion_static(), 0};
    cs_cloth_def *floor_cloth = s->cloths + s->floor_cloth, *top = s->cloths + 1 - s->floor_cloth;
    *floor_cloth = (cs_cloth_def){.name = "floor", .mesh = s->floor,
                                  .material = cs_default_cloth_material(), .nscripts = 1,
                                  .scripts = &s->pin};
    *top = (cs_cloth_def){.name = "top", .mesh = s->top, .material = cs_default_cloth_material()};
    memcpy(top->velocity, v, 3 * sizeof *v);
    s->def = cs_default_sim_def();
    s->def.gravity[1] = gravity;
    s->def.ncloths = 2;
    s->def.cloths = s->cloths;
    s->def.self_collision = true;
    s->def.dt = dt;
    s->def.fps = 1.0 / (steps_per_frame * dt);
    s->def.cg_tolerance = 1e-13;
    s->sim = create(&s->def);
}

static void scene_create(pair_scene *s, const double *floor_x, int ntop, const double *top_x,
                         int ttop, const int *top_tri, const double v[3], double dt,
                         int steps_per_frame, double gravity)
{
    scene_create_ordered(s, floor_x, ntop, top_x, ttop, top_tri, v, dt, steps_per_frame,
                         gravity, false);
}

static double top_mass(const pair_scene *s)
{
    return s->cloths[1 - s->floor_cloth].material.node_mass;
}

static void scene_destroy(pair_scene *s)
{
    cs_sim_destroy(s->sim);
    cs_trimesh_destroy(s->floor);
    cs_trimesh_destroy(s->top);
}

static const double big_floor[9] = {-2, 0, -1, 0, 0, 2, 2, 0, -1};

/* The top cloth's particle k after a frame. */
static const double *top_x(const pair_scene *s, int k)
{
    return cs_sim_positions(s->sim) + 3 * (s->top_offset + k);
}

static const double *top_v(const pair_scene *s, int k)
{
    return cs_sim_velocities(s->sim) + 3 * (s->top_offset + k);
}

/* ----------------------------------------------------------- Eq. 1 */

/* Eq. 1 with the triangle pinned: the pair's mass is the particle's m, the
 * particle at distance y < h at rest feels I = min(dt k d, m 0.1 d / dt)
 * with d = h - y (Eq. 2). The impulse changes only the velocity that moves
 * the positions (B.2), so the particle stays at rest and each step moves
 * it by dt I / m: y_(n+1) = y_n + q (h - y_n), d_n = d_0 (1 - q)^n, with
 * q = k dt^2 / m in the spring branch and q = 0.1 in the capped one. */
static void check_eq1(double dt, int steps_per_frame, int frames, double q_expected,
                      const char *branch)
{
    const double y0 = 0.004;
    double p[3] = {0.1, y0, 0.2}, rest[3] = {0, 0, 0};
    pair_scene s;
    scene_create(&s, big_floor, 1, p, 0, NULL, rest, dt, steps_per_frame, 0);
    const cs_self_collision_def *self = &s.def.self;
    const double m = top_mass(&s), h = self->thickness;
    double q = fmin(self->stiffness * dt * dt / m, 0.1);
    assert_true(fabs(q / q_expected - 1) < 1e-12); /* the branch meant */
    for (int f = 1; f <= frames; f++) {
        cs_frame_stats st;
        assert_int_equal(cs_sim_advance_frame(s.sim, &st), CS_OK);
        int n = f * steps_per_frame;
        double y = h - (h - y0) * pow(1 - q, n);
        const double *x = top_x(&s, 0), *v = top_v(&s, 0);
        if (f == frames)
            print_message("Eq. 1 %s branch: y %.12f after %d steps, exact %.12f\n", branch,
                          x[1], n, y);
        if (!(fabs(x[1] - y) < 1e-12 && fabs(x[0] - p[0]) < 1e-15 && fabs(x[2] - p[2]) < 1e-15))
            fail_msg("Eq. 1, %s branch, step %d: particle at height %.12f, exact %.12f "
                     "(moved %.4g of the exact distance)",
                     branch, n, x[1], y, (x[1] - y0) / (y - y0));
        if (!(v[0] == 0 && v[1] == 0 && v[2] == 0))
            fail_msg("Eq. 1, %s branch: the elastic repulsion reached the velocity "
                     "(%.3g, %.3g, %.3g)", branch, v[0], v[1], v[2]);
        assert_true(st.repulsions >= steps_per_frame); /* B.2 every step */
        assert_int_equal(st.collisions, 0);
    }
    scene_destroy(&s);
}

static void test_repulsion_eq1_spring_branch(void **state)
{
    (void)state;
    /* k dt^2 / m = 30 * 4e-10 / 1e-6 = 0.012 < 0.1: I = dt k d */
    check_eq1(2e-5, 10, 5, 0.012, "spring");
}

static void test_repulsion_eq1_capped_branch(void **state)
{
    (void)state;
    /* k dt^2 / m = 30 >> 0.1: I = m 0.1 d / dt, a tenth of d per step */
    check_eq1(1e-3, 4, 3, 0.1, "capped");
}

/* ---------------------------------------------------------- friction */

/* A particle inside the repulsion thickness approaching the pinned
 * triangle at w while sliding at vt. B.2's inelastic impulse stops the
 * approach, then Eq. 1 pushes it out (positions); B.8's inelastic
 * impulse removes w from the final velocity, and Coulomb friction takes
 * mu w off the sliding speed, or all of it when that is less:
 * v = (max(vt - mu w, 0), 0, 0). Nothing presses it afterwards, so it
 * keeps that speed. */
static void check_friction_impulse(double vt, double w)
{
    const double dt = 2e-5, y0 = 0.004;
    double p[3] = {0.1, y0, 0.2}, v0[3] = {vt, -w, 0};
    pair_scene s;
    scene_create(&s, big_floor, 1, p, 0, NULL, v0, dt, 1, 0);
    const cs_self_collision_def *self = &s.def.self;
    const double m = top_mass(&s), h = self->thickness;
    advance(s.sim);
    double want = fmax(vt - self->friction * w, 0);
    double y1 = y0 + self->stiffness * dt * dt / m * (h - y0);
    const double *x = top_x(&s, 0), *v = top_v(&s, 0);
    print_message("cloth friction: vt %g, w %g: sliding speed %.12f after the impulse, exact "
                  "%.12f\n", vt, w, v[0], want);
    if (!(fabs(v[0] - want) < 1e-12 && fabs(v[1]) < 1e-12 && fabs(v[2]) < 1e-12))
        fail_msg("vt %g, w %g: velocity (%.12f, %.3g, %.3g) after the impulse, exact (%.12f, "
                 "0, 0)", vt, w, v[0], v[1], v[2], want);
    /* positions: the approach stopped before Eq. 1 (B.2), sliding at vt */
    if (!(fabs(x[1] - y1) < 1e-12 && fabs(x[0] - (p[0] + dt * vt)) < 1e-12))
        fail_msg("vt %g, w %g: position (%.12f, %.12f) after a step, exact (%.12f, %.12f)", vt,
                 w, x[0], x[1], p[0] + dt * vt, y1);
    for (int f = 0; f < 20; f++)
        advance(s.sim);
    assert_true(fabs(top_v(&s, 0)[0] - want) < 1e-12);
    scene_destroy(&s);
}

static void test_cloth_friction_impulse(void **state)
{
    (void)state;
    check_friction_impulse(1.0, 1.0);  /* slides on at 1 - 0.3 */
    check_friction_impulse(0.2, 1.0);  /* mu w > vt: stopped */
    check_friction_impulse(0.5, 0.25); /* 0.5 - 0.075 */
}

/* A particle resting on the pinned cloth under gravity, sliding at v0:
 * every step B.8 removes the dt g it gained towards the cloth and friction
 * takes mu g dt off its speed, so v(t) = v0 - mu g t, as for a block on a
 * level floor (the incline of test_incline.c, with a cloth for floor). */
static void test_cloth_friction_sliding(void **state)
{
    (void)state;
    const double dt = 2e-5, g = 9.8, v0 = 1.0;
    double p[3] = {-0.5, 0.005, 0.2}, vel[3] = {v0, 0, 0};
    pair_scene s;
    scene_create(&s, big_floor, 1, p, 0, NULL, vel, dt, 200, -g);
    const double mu = s.def.self.friction, h = s.def.self.thickness;
    for (int f = 1; f <= 10; f++) {
        advance(s.sim);
        double t = cs_sim_time(s.sim), want = v0 - mu * g * t;
        const double *x = top_x(&s, 0), *v = top_v(&s, 0);
        if (f == 10)
            print_message("cloth friction sliding: speed %.12f at t = %g, exact %.12f\n", v[0],
                          t, want);
        if (!(fabs(v[0] - want) < 1e-9 && x[1] > 0 && x[1] < h))
            fail_msg("t=%g: sliding at %.12f, exact %.12f (height %.6f)", t, v[0], want, x[1]);
    }
    scene_destroy(&s);
}

/* ----------------------------------------------------- edge/edge history */

/* Two edges crossing at right angles, a distance y0 < h apart: the pinned
 * triangle's top edge along x at y = 0 (the floor here stands upright in
 * z = 0), and the bottom edge of a free triangle along z at y = y0 (it
 * stands in x = 0). No point comes near a triangle, so the pair is edge/
 * edge only. Nothing has crossed, so s . s0 = 1 and the history rule
 * (flip s when s0 . s < epsilon) keeps s: Eq. 1 pushes the free edge up,
 * each end (weight 1/2 at the closest point) by dt (1/2) I / m with
 * I = dt k d. Inverting the rule would read the pair as crossed and pull
 * the edge down through the other. */
static void test_edge_edge_history_repels(void **state)
{
    (void)state;
    const double dt = 2e-5, y0 = 0.006, a = 0.1;
    double upright[9] = {-a, 0, 0, a, 0, 0, 0, -a, 0};
    double top[9] = {0, y0, -a, 0, y0, a, 0, y0 + a, 0};
    int tri[3] = {0, 1, 2};
    double rest[3] = {0, 0, 0};
    for (int k = 0; k < 2; k++) { /* the free cloth's particles last, then first */
        pair_scene s;
        scene_create_ordered(&s, upright, 3, top, 1, tri, rest, dt, 1, 0, k == 1);
        const cs_self_collision_def *self = &s.def.self;
        const double m = top_mass(&s), h = self->thickness;
        cs_frame_stats st;
        assert_int_equal(cs_sim_advance_frame(s.sim, &st), CS_OK);
        double rise = dt * dt * 0.5 * self->stiffness * (h - y0) / m;
        for (int e = 0; e < 2; e++) {
            const double *x = top_x(&s, e);
            if (!(fabs(x[1] - (y0 + rise)) < 1e-12 && fabs(x[0] - top[3 * e]) < 1e-15 &&
                  fabs(x[2] - top[3 * e + 2]) < 1e-15))
                fail_msg("edge end %d at height %.12f after a step, exact %.12f: moved %.4g "
                         "of the repulsion's rise",
                         e, x[1], y0 + rise, (x[1] - y0) / rise);
        }
        if (k == 0)
            print_message("edge/edge repulsion: rose %.6g m in a step, exact %.6g m\n",
                          top_x(&s, 0)[1] - y0, rise);
        assert_true(fabs(top_x(&s, 2)[1] - top[7]) < 1e-15); /* the apex felt nothing yet */
        assert_true(st.repulsions >= 1);
        assert_int_equal(st.collisions, 0);
        scene_destroy(&s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_repulsion_eq1_spring_branch),
        cmocka_unit_test(test_repulsion_eq1_capped_branch),
        cmocka_unit_test(test_cloth_friction_impulse),
        cmocka_unit_test(test_cloth_friction_sliding),
        cmocka_unit_test(test_edge_edge_history_repels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
