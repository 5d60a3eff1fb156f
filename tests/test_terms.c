/* Every term of the model checked on its own: each test
 * isolates one physical term in a scene small enough to have an analytic
 * answer, or a reference computed here independently of sim/ (a Newton
 * solve of the static equilibrium from the spring law, the closed form of
 * a damped oscillator, the linear system of the solves rebuilt from
 * Section 3), sized so that a 10% change in its term breaks it. Every
 * time step is set explicitly and checked to be the one taken; nothing
 * depends on the automatic step. The self-collision terms (Eq. 1,
 * cloth-cloth friction, the edge/edge history rule) are in
 * test_terms_selfcol.c, the wind's in test_terms_wind.c; body friction on
 * the incline is test_incline.c's.
 *
 * Mutations of sim/ applied in a scratch copy of the tree (each reverted),
 * the tests that failed and by how much (t: test_terms, w: test_terms_wind,
 * s: test_terms_selfcol, i: test_incline):
 *
 *  (a) bending springs built with E_e      t bend_stiffness_folded_hinge: fold 85% short
 *      instead of E_b                      t bend_damping_ratio: decay -811 /s, analytic -255
 *                                          t cg_tolerance_is_met: residual 35x the tolerance
 *  (b) phi0 += dt (v_B . N) left out       t moving_plane_contact_time: 0.5 mm (half a
 *      (Section 6, moving body)              step's travel) ahead of the plane at contact
 *  (c) Eq. 1 impulse halved                s repulsion_eq1_spring_branch: rose 0.51 of exact
 *                                          s repulsion_eq1_capped_branch: rose 0.54 of exact
 *                                          s cloth_friction_impulse, edge_edge_history_repels
 *  (d) cloth-cloth friction off            s cloth_friction_impulse: v 1.0, exact 0.7
 *                                          s cloth_friction_sliding: 1.0, exact 0.98824
 *  (e) history rule s0.s < eps -> > eps    s edge_edge_history_repels: the edge moved -4x
 *                                            the exact rise (pulled through, not pushed)
 *  (f) CG stops at 10x cg_tolerance        t cg_tolerance_is_met: residual 9.4x the tolerance
 *
 *  10% changes (x1.1):
 *  gravity                  t gravity_free_fall (exact to 1e-12), hanging triangle 9%, folded
 *                             hinge 9.5%, impact friction; s cloth_friction_sliding
 *  node mass                t hanging 9%, both damping rates -4.7%, hinge 9.5%, CG 2.6x;
 *                           s Eq. 1 rise 0.91, edge/edge 0.91
 *  E_e (edge stiffness)     t hanging triangle 8.4% of the drop, edge damping rate +4.9%, CG 2.5x
 *  xi_e (edge damping)      t edge_damping_ratio: rate -9.1%; CG 4.8x
 *  E_b (bending stiffness)  t folded hinge 8.3% of the fold, bend damping rate +4.9%, CG 9x
 *  xi_b (bending damping)   t bend_damping_ratio: rate -9.2%; CG 2.1x
 *  wind drag (area), wind   w wind_velocity_drag: v 0.534 and 0.544, exact 0.4945
 *    velocity
 *  wind ground_boost       w wind_ground_boost: y 0.215170 at t = 0.05, exact 0.212984
 *  wind gust (amplitude)    w wind_gust_drives_sheet: V -0.0072911 at t = 0.014, exact -0.0066307
 *  gust phase rate          w wind_gust_drives_sheet: V 0.0017346 at t = 0.006, exact 0.0022202
 *  body friction mu         t impact_friction_thrown_particle: vx 1.6766, exact 1.706;
 *                           i every case (the paper's: 474x the position tolerance)
 *  repulsion k              s Eq. 1 spring branch 1.094 of the rise, edge/edge 1.1
 *  Eq. 1 cap 0.1            s Eq. 1 capped branch 1.083 of the rise
 *  thickness h (in Eq. 2)   s Eq. 1 both branches 1.167, edge/edge 1.25, sliding
 *  cloth friction mu        s friction impulse 0.67, exact 0.7; sliding
 *  inelastic repulsion off  s friction impulse v (1, -1, 0), exact (0.7, 0, 0); sliding
 *  cg_tolerance             t cg_tolerance_is_met: residual 1.02x the tolerance
 *  Not covered by a 10% change: edge_flip_epsilon (only the rule's direction:
 *  its threshold matters only for pairs that turned between steps A and B).
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

/* ------------------------------------------------------------ helpers */

/* Force of the spring law F = E (l / L0 - 1) u_hat on a point at x from an
 * anchor at y, and its Jacobian dF/dx added into f and J. */
static void spring_add(const double x[3], const double y[3], double L0, double E, double f[3],
                       double J[9])
{
    double u[3] = {y[0] - x[0], y[1] - x[1], y[2] - x[2]};
    double l = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    double mag = E * (l / L0 - 1);
    for (int r = 0; r < 3; r++) {
        f[r] += mag * u[r] / l;
        for (int c = 0; c < 3; c++) {
            double uu = u[r] * u[c] / (l * l);
            /* d/dx of mag u_hat: -(E / L0) [uu + (1 - L0 / l)(I - uu)] */
            J[3 * r + c] -= E / L0 * (uu + (1 - L0 / l) * ((r == c) - uu));
        }
    }
}

static void solve3(const double A[9], const double b[3], double x[3])
{
    double det = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) +
                 A[2] * (A[3] * A[7] - A[4] * A[6]);
    for (int k = 0; k < 3; k++) {
        double M[9];
        memcpy(M, A, sizeof M);
        for (int r = 0; r < 3; r++)
            M[3 * r + k] = b[r];
        x[k] = (M[0] * (M[4] * M[8] - M[5] * M[7]) - M[1] * (M[3] * M[8] - M[5] * M[6]) +
                M[2] * (M[3] * M[7] - M[4] * M[6])) /
               det;
    }
}

/* The static equilibrium of one free particle of weight m g held by n
 * springs to fixed anchors, by Newton's method from x (the reference the
 * settled simulation must reach; it shares nothing with sim/ but the
 * spring law of Section 3). */
static void static_equilibrium(int n, const double *anchors, const double *L0, const double *E,
                               double m, const double g[3], double x[3])
{
    for (int it = 0; it < 100; it++) {
        double f[3] = {m * g[0], m * g[1], m * g[2]}, J[9] = {0}, dx[3];
        for (int s = 0; s < n; s++)
            spring_add(x, anchors + 3 * s, L0[s], E[s], f, J);
        double mf[3] = {-f[0], -f[1], -f[2]}, scale = 0;
        for (int k = 0; k < 9; k++)
            scale = fmax(scale, fabs(J[k]));
        for (int k = 0; k < 3; k++) /* a direction no spring resists: no step along it */
            J[4 * k] -= 1e-9 * scale;
        solve3(J, mf, dx);
        double step = 0;
        for (int d = 0; d < 3; d++) {
            x[d] += dx[d];
            step = fmax(step, fabs(dx[d]));
        }
        if (step < 1e-15)
            break;
    }
}

static double dist3(const double *a, const double *b)
{
    double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

/* Overdamping fraction xi to the damping parameter d of a spring (the
 * convention of sim/springs.h): xi times the critical 2 sqrt(E m_red / L0). */
static double spring_damping(double xi, double E, double mi, double mj, double L0)
{
    return xi * 2 * sqrt(E * (mi * mj / (mi + mj)) / L0);
}

/* m u'' + c u' + k u = 0, u(0) = 0, u'(0) = V (overdamped). */
static double oscillator(double m, double c, double k, double V, double t, double *slow)
{
    double disc = sqrt(c * c - 4 * m * k);
    double s1 = (-c + disc) / (2 * m), s2 = (-c - disc) / (2 * m);
    if (slow)
        *slow = s1;
    return V * (exp(s1 * t) - exp(s2 * t)) / (s1 - s2);
}

/* --------------------------------------------------------------- gravity */

/* The Newmark variant integrates a constant acceleration exactly:
 * x = x0 + v0 t + g t^2 / 2 and v = v0 + g t at every step end. */
/* A scripted vertex let go (cs_vertex_script.release_time): held on its
 * script's straight line until the release, then a projectile leaving with
 * the script's velocity. Exact, like the free fall below; released a step
 * late or early, or without the script's velocity, it is millimetres off. */
static void test_script_release(void **state)
{
    (void)state;
    double x0[3] = {0, 1, 0}, u[3] = {0.5, 0.2, 0}, g[3] = {0, -9.8, 0};
    const double release = 0.25; /* frame 10 at 40 fps: a step boundary */
    cs_trimesh *mesh = mesh_of(1, x0, 0, NULL);
    int vertex = 0;
    cs_vertex_script script = {1, &vertex, cs_motion_static(), release};
    script.motion.kind = CS_MOTION_CONSTANT;
    memcpy(script.motion.position, x0, sizeof x0);
    memcpy(script.motion.velocity, u, sizeof u);
    cs_cloth_def cloth = {.name = "p", .mesh = mesh, .material = cs_default_cloth_material(),
                          .nscripts = 1, .scripts = &script};
    cs_sim_def def = bare_def(&cloth, 1e-3, 40);
    memcpy(def.gravity, g, sizeof g);
    cs_sim *sim = create(&def);
    for (int f = 1; f <= 20; f++) {
        advance(sim);
        double t = cs_sim_time(sim), s = t > release ? t - release : 0;
        const double *x = cs_sim_positions(sim), *v = cs_sim_velocities(sim);
        for (int d = 0; d < 3; d++) {
            double xe = x0[d] + u[d] * t + 0.5 * g[d] * s * s, ve = u[d] + g[d] * s;
            if (!(fabs(x[d] - xe) < 1e-12 && fabs(v[d] - ve) < 1e-12))
                fail_msg("t=%g axis %d: x %.15g (exact %.15g), v %.15g (exact %.15g)", t, d,
                         x[d], xe, v[d], ve);
        }
    }
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

static void test_gravity_free_fall(void **state)
{
    (void)state;
    double x0[3] = {0.1, 2, -0.3};
    cs_trimesh *mesh = mesh_of(1, x0, 0, NULL);
    cs_cloth_def cloth = {.name = "p", .mesh = mesh, .material = cs_default_cloth_material(),
                          .velocity = {1, 2, 0.5}};
    cs_sim_def def = bare_def(&cloth, 1e-3, 50);
    double g[3] = {0.3, -9.8, 0.1};
    memcpy(def.gravity, g, sizeof g);
    cs_sim *sim = create(&def);
    for (int f = 1; f <= 25; f++) {
        advance(sim);
        double t = cs_sim_time(sim);
        const double *x = cs_sim_positions(sim), *v = cs_sim_velocities(sim);
        for (int d = 0; d < 3; d++) {
            double xe = x0[d] + cloth.velocity[d] * t + 0.5 * g[d] * t * t;
            double ve = cloth.velocity[d] + g[d] * t;
            if (!(fabs(x[d] - xe) < 1e-12 && fabs(v[d] - ve) < 1e-12))
                fail_msg("t=%g axis %d: x %.15g (exact %.15g), v %.15g (exact %.15g)", t, d,
                         x[d], xe, v[d], ve);
        }
    }
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* ------------------------------------------------------- edge springs */

/* Stretch stiffness: a triangle hung by its top edge (both ends pinned),
 * its lowest vertex carrying m g. No bending spring exists in one
 * triangle, so the two slanted edge springs alone hold the weight; the
 * settled position must be the spring law's equilibrium: it drops 1.5 cm,
 * the springs 8% stretched. */
static void test_edge_stiffness_hanging_triangle(void **state)
{
    (void)state;
    const double L = 0.1, H = 0.1;
    double x[9] = {-L, 0, 0, L, 0, 0, 0, -H, 0};
    int tri[3] = {0, 1, 2}, pins[2] = {0, 1};
    cs_trimesh *mesh = mesh_of(3, x, 1, tri);
    cs_vertex_script pin = {2, pins, cs_motion_static(), 0};
    cs_cloth_def cloth = {.name = "t", .mesh = mesh, .material = cs_default_cloth_material(),
                          .nscripts = 1, .scripts = &pin};
    cloth.material.node_mass = 0.05;
    cloth.material.edge_overdamping = 1; /* settles in well under a second */
    cs_sim_def def = bare_def(&cloth, 1e-3, 10);
    def.gravity[1] = -9.8;
    cs_sim *sim = create(&def);
    for (int f = 0; f < 30; f++)
        advance(sim);
    double L0 = sqrt(L * L + H * H);
    double anchors[6] = {-L, 0, 0, L, 0, 0}, rest[2] = {L0, L0};
    double E[2] = {cloth.material.edge_stiffness, cloth.material.edge_stiffness};
    double ref[3] = {0, -H, 0};
    static_equilibrium(2, anchors, rest, E, 0.05, def.gravity, ref);
    const double *p = cs_sim_positions(sim) + 6;
    double drop = -H - ref[1], err = dist3(p, ref);
    print_message("hanging triangle: drop %.6f m, simulated off by %.3g of it\n", drop,
                  err / drop);
    assert_true(drop > 0.01); /* a real stretch */
    if (!(err < 1e-4 * drop))
        fail_msg("hanging vertex at (%.9f, %.9f, %.9f), equilibrium (%.9f, %.9f, %.9f): "
                 "off by %.3g of the %.4f m drop",
                 p[0], p[1], p[2], ref[0], ref[1], ref[2], err / drop, drop);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* Edge damping: the same triangle without gravity, its free vertex kicked
 * down at V. By symmetry it moves along y only, a linear oscillator with
 * k = 2 (E / L0) (H / L0)^2 and c = 2 d (H / L0)^2, d from xi_e (Table 1's
 * 15: heavily overdamped), so after the fast transient it creeps back at
 * the slow root s1 = (-c + sqrt(c^2 - 4 m k)) / 2m. */
static void test_edge_damping_ratio(void **state)
{
    (void)state;
    const double L = 0.1, H = 0.1, V = 0.01, m = 1e-6;
    double x[9] = {-L, 0, 0, L, 0, 0, 0, -H, 0};
    int tri[3] = {0, 1, 2}, pins[2] = {0, 1};
    cs_trimesh *mesh = mesh_of(3, x, 1, tri);
    cs_vertex_script pin = {2, pins, cs_motion_static(), 0};
    cs_cloth_def cloth = {.name = "t", .mesh = mesh, .material = cs_default_cloth_material(),
                          .nscripts = 1, .scripts = &pin, .velocity = {0, -V, 0}};
    const cs_cloth_material *mat = &cloth.material;
    cs_sim_def def = bare_def(&cloth, 1e-6, 2000);
    cs_sim *sim = create(&def);
    double L0 = sqrt(L * L + H * H), cos2 = (H / L0) * (H / L0);
    double k = 2 * mat->edge_stiffness / L0 * cos2;
    double c = 2 * spring_damping(mat->edge_overdamping, mat->edge_stiffness, m, m, L0) * cos2;
    double s1;
    oscillator(m, c, k, -V, 0, &s1);
    double t1 = 0, u1 = 0, worst = 0;
    for (int f = 1; f <= 20; f++) {
        advance(sim);
        double t = cs_sim_time(sim), u = cs_sim_positions(sim)[7] + H;
        double exact = oscillator(m, c, k, -V, t, NULL);
        worst = fmax(worst, fabs(u / exact - 1));
        if (f == 2)
            t1 = t, u1 = u;
        if (f == 20) {
            double rate = log(u / u1) / (t - t1);
            print_message("edge damping: decay rate %.6g /s, analytic %.6g /s\n", rate, s1);
            if (!(fabs(rate / s1 - 1) < 0.01))
                fail_msg("slow decay rate %.6g /s, analytic %.6g /s (xi_e %g)", rate, s1,
                         mat->edge_overdamping);
        }
    }
    print_message("  displacement off the damped oscillator by %.3g at most\n", worst);
    if (!(worst < 0.01))
        fail_msg("displacement off the damped oscillator by %.3g (relative)", worst);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* ---------------------------------------------------- bending springs */

/* Bending stiffness: a hinge of two triangles on the pinned edge a-b,
 * one wing (c) pinned flat, the other (d) folded up by 90 degrees and
 * loaded across its plane. Rotating about the hinge leaves d's edge
 * springs unstretched to first order, so the bending spring c-d carries
 * the load; the settled d must be the equilibrium of its three springs
 * (Newton, above), a 7% fold. Building the bending springs with the edge
 * stiffness (E_e = 10 E_b) would fold it 10 times less. */
static void test_bend_stiffness_folded_hinge(void **state)
{
    (void)state;
    const double L = 0.05, W = 0.05, m = 1e-3;
    double x[12] = {-L, 0, 0, L, 0, 0, 0, 0, -W, 0, W, 0};
    int tri[6] = {0, 1, 2, 1, 0, 3}, pins[3] = {0, 1, 2};
    cs_trimesh *mesh = mesh_of(4, x, 2, tri);
    cs_vertex_script pin = {3, pins, cs_motion_static(), 0};
    cs_cloth_def cloth = {.name = "hinge", .mesh = mesh, .material = cs_default_cloth_material(),
                          .nscripts = 1, .scripts = &pin};
    cloth.material.node_mass = m;
    cloth.material.edge_overdamping = 1; /* settle quickly: statics only */
    cloth.material.bend_overdamping = 1;
    cs_sim_def def = bare_def(&cloth, 1e-3, 10);
    def.gravity[2] = -9.8; /* across wing d, closing the fold */
    cs_sim *sim = create(&def);
    assert_int_equal(cs_sim_spring_count(sim), 6); /* five edges, one bending spring */
    for (int f = 0; f < 30; f++)
        advance(sim);
    const cs_cloth_material *mat = &cloth.material;
    double anchors[9] = {-L, 0, 0, L, 0, 0, 0, 0, -W};
    double rest[3] = {sqrt(L * L + W * W), sqrt(L * L + W * W), W * sqrt(2.0)};
    double E[3] = {mat->edge_stiffness, mat->edge_stiffness, mat->bend_stiffness};
    double ref[3] = {0, W, 0};
    static_equilibrium(3, anchors, rest, E, m, def.gravity, ref);
    const double *p = cs_sim_positions(sim) + 9;
    double fold = dist3(ref, x + 9), err = dist3(p, ref);
    /* the linear estimate: only the bending spring resists, k = E_b / L_b sin^2 45 */
    double k_lin = mat->bend_stiffness / rest[2] * 0.5;
    print_message("folded hinge: fold %.6f m (linear estimate %.6f), simulated off by %.3g "
                  "of it\n", fold, m * 9.8 / k_lin, err / fold);
    assert_true(fabs(fold / (m * 9.8 / k_lin) - 1) < 0.1);
    if (!(err < 1e-3 * fold))
        fail_msg("folded vertex at (%.7f, %.7f, %.7f), equilibrium (%.7f, %.7f, %.7f): off by "
                 "%.3g of the %.5f m fold",
                 p[0], p[1], p[2], ref[0], ref[1], ref[2], err / fold, fold);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* Bending damping: a hinge folded shut, wing d lying flat in y = 0 and
 * the pinned wing c a distance G straight below d. d's edge springs lie in
 * y = 0, so along y d feels the bending spring alone: a linear oscillator
 * with k = E_b / G and c = d_b from xi_b (8: overdamped), kicked at V. */
static void test_bend_damping_ratio(void **state)
{
    (void)state;
    const double L = 0.1, W = 0.1, G = 0.05, V = 0.01, m = 1e-6;
    double x[12] = {-L, 0, 0, L, 0, 0, 0, -G, W, 0, 0, W};
    int tri[6] = {0, 1, 2, 1, 0, 3}, pins[3] = {0, 1, 2};
    cs_trimesh *mesh = mesh_of(4, x, 2, tri);
    cs_vertex_script pin = {3, pins, cs_motion_static(), 0};
    cs_cloth_def cloth = {.name = "hinge", .mesh = mesh, .material = cs_default_cloth_material(),
                          .nscripts = 1, .scripts = &pin, .velocity = {0, -V, 0}};
    const cs_cloth_material *mat = &cloth.material;
    cs_sim_def def = bare_def(&cloth, 1e-6, 2000);
    cs_sim *sim = create(&def);
    double k = mat->bend_stiffness / G;
    double c = spring_damping(mat->bend_overdamping, mat->bend_stiffness, m, m, G);
    double s1;
    oscillator(m, c, k, -V, 0, &s1);
    double t1 = 0, u1 = 0, worst = 0;
    for (int f = 1; f <= 20; f++) {
        advance(sim);
        double t = cs_sim_time(sim), u = cs_sim_positions(sim)[10];
        double exact = oscillator(m, c, k, -V, t, NULL);
        worst = fmax(worst, fabs(u / exact - 1));
        if (f == 2)
            t1 = t, u1 = u;
        if (f == 20) {
            double rate = log(u / u1) / (t - t1);
            print_message("bend damping: decay rate %.6g /s, analytic %.6g /s\n", rate, s1);
            if (!(fabs(rate / s1 - 1) < 0.01))
                fail_msg("slow decay rate %.6g /s, analytic %.6g /s (E_b %g, xi_b %g)", rate,
                         s1, mat->bend_stiffness, mat->bend_overdamping);
        }
    }
    print_message("  displacement off the damped oscillator by %.3g at most\n", worst);
    if (!(worst < 0.01))
        fail_msg("displacement off the damped oscillator by %.3g (relative)", worst);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* --------------------------------------------------------------- bodies */

/* Section 6's crossing point with a moving body: a particle at rest, a
 * frictionless plane coming at it with velocity u. Contact happens at
 * t_c = D / (u . n), halfway through a step; from then on the particle
 * rides on the plane at (u . n) n. The step of contact must put it on the
 * plane exactly: the plane's motion over the step is part of phi at time
 * n (phi0 += dt v_B . N); leaving it out puts the particle ahead of the
 * plane by the part of the step before contact (half a step's travel). */
static void check_moving_plane(const double n[3], const double u[3])
{
    const double dt = 1e-3, un = u[0] * n[0] + u[1] * n[1] + u[2] * n[2];
    const double D = 10.5 * dt * un; /* contact halfway through step 11 */
    double c0[3] = {0.2, -0.1, 0.3}, p0[3];
    /* the particle: D along n from the plane's origin, and off to the side */
    double side[3] = {n[1], -n[0], 0}; /* in the plane when n[2] = 0 */
    for (int d = 0; d < 3; d++)
        p0[d] = c0[d] + D * n[d] + 0.05 * side[d] + 0.02 * (d == 2);
    cs_trimesh *mesh = mesh_of(1, p0, 0, NULL);
    cs_cloth_def cloth = {.name = "p", .mesh = mesh, .material = cs_default_cloth_material()};
    cs_body_def plane = cs_default_body_def();
    plane.friction = 0;
    plane.motion.kind = CS_MOTION_CONSTANT;
    memcpy(plane.motion.position, c0, sizeof c0);
    cs_quat_from_y_to(n, plane.motion.rotation);
    memcpy(plane.motion.velocity, u, 3 * sizeof *u);
    cs_sim_def def = bare_def(&cloth, dt, 1 / dt);
    def.nbodies = 1;
    def.bodies = &plane;
    cs_sim *sim = create(&def);
    double tc = D / un;
    for (int f = 1; f <= 30; f++) {
        advance(sim);
        double t = cs_sim_time(sim), s = t > tc ? t - tc : 0;
        const double *x = cs_sim_positions(sim), *v = cs_sim_velocities(sim);
        for (int d = 0; d < 3; d++) {
            double xe = p0[d] + un * s * n[d], ve = t > tc ? un * n[d] : 0;
            if (!(fabs(x[d] - xe) < 1e-12 && fabs(v[d] - ve) < 1e-12))
                fail_msg("n=(%g,%g,%g) u=(%g,%g,%g) t=%.4f (contact %.4f) axis %d: x %.9f, "
                         "exact %.9f (off %.3g of a step's travel); v %.9f, exact %.9f",
                         n[0], n[1], n[2], u[0], u[1], u[2], t, tc, d, x[d], xe,
                         fabs(x[d] - xe) / (dt * un), v[d], ve);
        }
    }
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

static void test_moving_plane_contact_time(void **state)
{
    (void)state;
    double up[3] = {0, 1, 0}, u_up[3] = {0, 1, 0};
    check_moving_plane(up, u_up); /* along its normal */
    double s = sin(M_PI / 6), c = cos(M_PI / 6);
    double tilted[3] = {s, c, 0}, u_side[3] = {2, 0.5, 0.3};
    check_moving_plane(tilted, u_side); /* obliquely, sliding along itself too */
}

/* Cloth-object friction at an impact: a particle thrown horizontally at
 * vx0 onto a static plane with friction mu. The inward normal velocity it
 * carries into the step of contact, plus the weight over what remains of
 * that step, is removed by Gamma with the friction it implies; then it
 * slides at mu g. In all, vx(t) = vx0 - mu g t after contact, exactly as
 * the continuous impact and slide give (up to when it stops). */
static void test_impact_friction_thrown_particle(void **state)
{
    (void)state;
    const double g = 9.8, dt = 1e-3, mu = 0.5, vx0 = 2;
    const double tc = 50.5 * dt, y0 = 0.5 * g * tc * tc;
    double p0[3] = {0, y0, 0};
    cs_trimesh *mesh = mesh_of(1, p0, 0, NULL);
    cs_cloth_def cloth = {.name = "p", .mesh = mesh, .material = cs_default_cloth_material(),
                          .velocity = {vx0, 0, 0}};
    cs_body_def ground = cs_default_body_def();
    ground.friction = mu;
    cs_sim_def def = bare_def(&cloth, dt, 100);
    def.gravity[1] = -g;
    def.nbodies = 1;
    def.bodies = &ground;
    cs_sim *sim = create(&def);
    for (int f = 1; f <= 30; f++) {
        advance(sim);
        double t = cs_sim_time(sim);
        const double *x = cs_sim_positions(sim), *v = cs_sim_velocities(sim);
        double vx = t < tc ? vx0 : vx0 - mu * g * t;
        double vy = t < tc ? -g * t : 0, y = t < tc ? y0 - 0.5 * g * t * t : 0;
        if (!(fabs(v[0] - vx) < 1e-9 && fabs(v[1] - vy) < 1e-9 && fabs(x[1] - y) < 1e-12))
            fail_msg("t=%.3f (contact %.4f): v (%.9f, %.9f), exact (%.9f, %.9f); y %.3g, "
                     "exact %.3g",
                     t, tc, v[0], v[1], vx, vy, x[1], y);
    }
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}


/* ------------------------------------------------------------ the solver */

/* The springs of a mesh rebuilt here from Section 3 (an edge spring per
 * edge, a bending spring across each edge two triangles share), with
 * their damping from the overdamping fractions. */
typedef struct ref_spring {
    int i, j;
    double L0, E, d;
} ref_spring;

typedef struct edge_key {
    int a, b, opposite;
} edge_key;

static int edge_key_cmp(const void *p, const void *q)
{
    const edge_key *x = p, *y = q;
    if (x->a != y->a)
        return x->a < y->a ? -1 : 1;
    return (x->b > y->b) - (x->b < y->b);
}

static int ref_springs(const cs_trimesh *m, const cs_cloth_material *mat, double mass,
                       ref_spring **out)
{
    edge_key *e = malloc(sizeof *e * 3 * (size_t)m->nt);
    ref_spring *s = malloc(sizeof *s * 6 * (size_t)m->nt);
    assert_non_null(e);
    assert_non_null(s);
    for (int t = 0; t < m->nt; t++)
        for (int k = 0; k < 3; k++) {
            int a = m->tri[3 * t + k], b = m->tri[3 * t + (k + 1) % 3];
            e[3 * t + k] = (edge_key){a < b ? a : b, a < b ? b : a, m->tri[3 * t + (k + 2) % 3]};
        }
    qsort(e, 3 * (size_t)m->nt, sizeof *e, edge_key_cmp);
    int n = 0;
    for (int k = 0; k < 3 * m->nt;) {
        int j = k;
        while (j < 3 * m->nt && e[j].a == e[k].a && e[j].b == e[k].b)
            j++;
        int ends[2][2] = {{e[k].a, e[k].b}, {e[k].opposite, j > k + 1 ? e[k + 1].opposite : -1}};
        for (int kind = 0; kind < 2; kind++) {
            if (ends[kind][1] < 0)
                continue;
            double E = kind ? mat->bend_stiffness : mat->edge_stiffness;
            double xi = kind ? mat->bend_overdamping : mat->edge_overdamping;
            ref_spring *r = s + n++;
            r->i = ends[kind][0];
            r->j = ends[kind][1];
            r->L0 = dist3(m->x + 3 * r->i, m->x + 3 * r->j);
            r->E = E;
            r->d = spring_damping(xi, E, mass, mass, r->L0);
        }
        k = j;
    }
    free(e);
    *out = s;
    return n;
}

/* The largest velocity residual |r_i| / m over free particles of
 * (M - h D(x)) v = M v_start + h (f_elastic(x) + M g), with fixed
 * particles at velocity 0: what cg_tolerance bounds (sim.h). */
static double solve_residual(int np, const unsigned char *is_free, int ns, const ref_spring *s,
                             double m, const double g[3], double h, const double *x,
                             const double *v, const double *v_start)
{
    double *r = calloc(3 * (size_t)np, sizeof *r);
    assert_non_null(r);
    for (int i = 0; i < np; i++)
        for (int d = 0; d < 3; d++)
            r[3 * i + d] = m * v_start[3 * i + d] + h * m * g[d] - m * v[3 * i + d];
    for (int k = 0; k < ns; k++) {
        int i = s[k].i, j = s[k].j;
        double u[3], rel[3];
        for (int d = 0; d < 3; d++) {
            u[d] = x[3 * j + d] - x[3 * i + d];
            rel[d] = (is_free[j] ? v[3 * j + d] : 0) - (is_free[i] ? v[3 * i + d] : 0);
        }
        double l = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        double along = (rel[0] * u[0] + rel[1] * u[1] + rel[2] * u[2]) / l;
        double mag = s[k].E * (l / s[k].L0 - 1) + s[k].d * along; /* on i, along u / l */
        for (int d = 0; d < 3; d++) {
            r[3 * i + d] += h * mag * u[d] / l;
            r[3 * j + d] -= h * mag * u[d] / l;
        }
    }
    double worst = 0;
    for (int i = 0; i < np; i++)
        if (is_free[i])
            worst = fmax(worst, sqrt(r[3 * i] * r[3 * i] + r[3 * i + 1] * r[3 * i + 1] +
                                     r[3 * i + 2] * r[3 * i + 2]) / m);
    free(r);
    return worst;
}

/* The CG tolerance is a promise about the solution (sim.h): the velocity
 * residual of each backward Euler solve is at most cg_tolerance. A sheet
 * pinned along one edge and thrown across its plane (the damping
 * couples every particle: many iterations), one step at a time: B.1's
 * v~^(n+1/2) is (x^(n+1) - x^n) / dt, B.5's v^(n+1/2) is
 * (v^n + v^(n+1)) / 2, and each must satisfy its system, rebuilt here,
 * to the tolerance asked for, at every tolerance. */
static void test_cg_tolerance_is_met(void **state)
{
    (void)state;
    double size[2] = {0.1, 0.1}, q[4] = {1, 0, 0, 0}, center[3] = {0, 0, 0};
    int res[2] = {6, 6};
    cs_trimesh *mesh = cs_trimesh_create_grid(size, res, q, center);
    int np = mesh->nv, pins[7];
    unsigned char *is_free = malloc((size_t)np);
    for (int i = 0; i < np; i++)
        is_free[i] = i > res[0];
    for (int i = 0; i <= res[0]; i++)
        pins[i] = i;
    cs_vertex_script pin = {res[0] + 1, pins, cs_motion_static(), 0};
    cs_cloth_def cloth = {.name = "sheet", .mesh = mesh, .material = cs_default_cloth_material(),
                          .nscripts = 1, .scripts = &pin, .velocity = {0.1, 0.5, 0}};
    const double m = cloth.material.node_mass, dt = 2e-5, h = dt / 2;
    ref_spring *springs;
    int ns = ref_springs(mesh, &cloth.material, m, &springs);
    double tolerances[] = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 3e-8};
    size_t bytes = sizeof(double) * 3 * (size_t)np;
    double *xn = malloc(bytes), *vn = malloc(bytes), *vh = malloc(bytes), *xm = malloc(bytes),
           *vp = malloc(bytes);
    for (size_t k = 0; k < sizeof tolerances / sizeof *tolerances; k++) {
        double tol = tolerances[k];
        cs_sim_def def = bare_def(&cloth, dt, 1 / (100 * dt));
        def.gravity[1] = -9.8;
        def.cg_tolerance = tol;
        cs_sim *sim = create(&def);
        double worst = 0;
        for (int step = 0; step < 4; step++) {
            memcpy(xn, cs_sim_positions(sim), bytes);
            memcpy(vn, cs_sim_velocities(sim), bytes);
            assert_int_equal(cs_sim_step(sim, dt), CS_OK);
            const double *x1 = cs_sim_positions(sim), *v1 = cs_sim_velocities(sim);
            for (int c = 0; c < 3 * np; c++) {
                vh[c] = (x1[c] - xn[c]) / dt;
                xm[c] = 0.5 * (xn[c] + x1[c]);
                vp[c] = 0.5 * (vn[c] + v1[c]);
            }
            double r1 = solve_residual(np, is_free, ns, springs, m, def.gravity, h, xn, vh, vn);
            double r5 = solve_residual(np, is_free, ns, springs, m, def.gravity, h, xm, vp, vn);
            worst = fmax(worst, fmax(r1, r5) / tol);
            /* round-off of the reconstruction: far below the tolerances */
            if (!(r1 <= tol * (1 + 1e-6) + 1e-10 && r5 <= tol * (1 + 1e-6) + 1e-10))
                fail_msg("cg_tolerance %g, step %d: velocity residual %.4g (B.1), %.4g (B.5): "
                         "%.3g times the tolerance",
                         tol, step + 1, r1, r5, fmax(r1, r5) / tol);
        }
        print_message("cg_tolerance %g: largest velocity residual %.3g of it\n", tol, worst);
        cs_sim_destroy(sim);
    }
    free(xn), free(vn), free(vh), free(xm), free(vp);
    free(springs);
    free(is_free);
    cs_trimesh_destroy(mesh);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gravity_free_fall),
        cmocka_unit_test(test_edge_stiffness_hanging_triangle),
        cmocka_unit_test(test_edge_damping_ratio),
        cmocka_unit_test(test_bend_stiffness_folded_hinge),
        cmocka_unit_test(test_bend_damping_ratio),
        cmocka_unit_test(test_moving_plane_contact_time),
        cmocka_unit_test(test_impact_friction_thrown_particle),
        cmocka_unit_test(test_cg_tolerance_is_met),
        cmocka_unit_test(test_script_release),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
