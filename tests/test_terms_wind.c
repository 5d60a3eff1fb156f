/* Every term of the model checked on its own: the wind
 * of Section 8 (velocity drag, the ground boost, the gust field, a sheet
 * driven by a gust), each against a closed form. The other terms are in
 * test_terms.c, with the table of mutations these files catch. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/internal.h"
#include "sim/sim.h"
#include "terms_sim.h"

/* ----------------------------------------------------------------- wind */

/* A level square sheet of `side` m and res x res quads centred at center,
 * density rho, in drag cd (no wind velocity yet): cloth->mesh is the
 * caller's to destroy, and cloth must outlive the definition. */
static cs_sim_def wind_sheet_def(double side, int res, const double center[3], double rho,
                                 double cd, double dt, double fps, cs_cloth_def *cloth)
{
    double size[2] = {side, side}, q[4] = {1, 0, 0, 0};
    int r[2] = {res, res};
    *cloth = (cs_cloth_def){.name = "sheet",
                            .mesh = cs_trimesh_create_grid(size, r, q, center),
                            .material = cs_default_cloth_material()};
    cloth->material.density = rho;
    cs_sim_def def = bare_def(cloth, dt, fps);
    def.wind_enabled = true;
    def.wind.drag = cd;
    return def;
}

/* Wind velocity (Section 8): a sheet at rest, no gravity, in a wind with
 * a normal part wn and a tangential part. The drag acts along the normal
 * only, on area A_i, and the mass is rho A_i, so every vertex follows
 * v_n = wn (1 - exp(-c t / rho)) and never moves sideways. (The drag
 * coefficient on a falling sheet is test_sim_core's.) */
static void test_wind_velocity_drag(void **state)
{
    (void)state;
    const double rho = 0.1, cd = 2.0, wn = 1.5;
    cs_cloth_def cloth;
    cs_sim_def def = wind_sheet_def(1, 4, (const double[3]){0, 0, 0}, rho, cd, 1e-3, 50, &cloth);
    def.wind.velocity[0] = 3;
    def.wind.velocity[1] = wn;
    def.wind.velocity[2] = -1;
    cs_sim *sim = create(&def);
    for (int f = 1; f <= 10; f++) {
        advance(sim);
        double t = cs_sim_time(sim), exact = wn * (1 - exp(-cd * t / rho));
        for (int i = 0; i < cs_sim_particle_count(sim); i++) {
            const double *v = cs_sim_velocities(sim) + 3 * i;
            if (!(fabs(v[1] - exact) < 1e-4 * wn && fabs(v[0]) < 1e-12 && fabs(v[2]) < 1e-12))
                fail_msg("t=%.3f vertex %d: v (%.3g, %.7f, %.3g), exact (0, %.7f, 0)", t, i,
                         v[0], v[1], v[2], exact);
        }
    }
    cs_sim_destroy(sim);
    cs_trimesh_destroy((cs_trimesh *)cloth.mesh);
}

/* The wind near the ground (Section 8, Fig. 9's "high wind speed near the
 * ground"): a level sheet under gravity in an updraft that is B at y = 0
 * and fades linearly to none at y = H. Per unit area
 *   rho y'' = -rho g + c (B (1 - y / H) - y'),
 * a damped oscillator about y* = H (1 - rho g / (c B)); from rest at y0 it
 * rises without overshoot (overdamped here), so the sheet stays inside
 * [0, H], where the profile is linear. Every vertex follows the closed
 * form; a 10% change in B moves y* by 3 cm. */
static void test_wind_ground_boost(void **state)
{
    (void)state;
    const double rho = 0.1, cd = 2.0, B = 1.5, H = 1.0, g = 9.8, y0 = 0.2;
    cs_cloth_def cloth;
    cs_sim_def def = wind_sheet_def(1, 4, (const double[3]){0, y0, 0}, rho, cd, 1e-4, 20, &cloth);
    def.gravity[1] = -g;
    def.wind.ground_boost[1] = B;
    def.wind.ground_height = H;
    cs_sim *sim = create(&def);
    /* y = y* + a1 e^(r1 t) + a2 e^(r2 t), y(0) = y0, y'(0) = 0 */
    double a = cd / rho, k = cd * B / (rho * H), ystar = H * (1 - rho * g / (cd * B));
    double disc = sqrt(a * a - 4 * k), r1 = (-a + disc) / 2, r2 = (-a - disc) / 2;
    double a1 = (y0 - ystar) / (1 - r1 / r2), a2 = -r1 * a1 / r2;
    double worst = 0;
    for (int f = 1; f <= 40; f++) {
        advance(sim);
        double t = cs_sim_time(sim);
        double exact = ystar + a1 * exp(r1 * t) + a2 * exp(r2 * t);
        for (int i = 0; i < cs_sim_particle_count(sim); i++) {
            const double *x = cs_sim_positions(sim) + 3 * i;
            double err = fabs(x[1] - exact);
            worst = err > worst ? err : worst;
            if (!(err < 1e-3 * (ystar - y0)))
                fail_msg("t=%.3f vertex %d: y %.6f, exact %.6f (y* %.4f)", t, i, x[1], exact,
                         ystar);
        }
    }
    /* 2 s in, the sheet has nearly reached y*: the test saw the rise */
    assert_true(fabs(cs_sim_positions(sim)[1] - ystar) < 0.1 * (ystar - y0));
    print_message("ground boost: worst |y - exact| %.3g m over 2 s (y* = %.4f m)\n", worst,
                  ystar);
    cs_sim_destroy(sim);
    cs_trimesh_destroy((cs_trimesh *)cloth.mesh);
}

/* The gust field (wind.gust, an ABC flow), checked from its definition:
 * divergence-free (central differences), each component's RMS over a
 * wavelength cube equal to `gust`, never faster than cs_wind_max_speed, and
 * changing with time at the rates docs/scene-reference.md gives (one phase
 * a period). */
static void test_wind_gust_field(void **state)
{
    (void)state;
    cs_wind_def w = cs_default_sim_def().wind;
    w.gust = 0.7;
    w.gust_length = 0.5;
    w.gust_period = 1.5;
    const int n = 16;
    const double h = 1e-5, L = w.gust_length;
    double sq[3] = {0, 0, 0}, fastest = 0, worst_div = 0;
    for (int a = 0; a < n; a++)
        for (int b = 0; b < n; b++)
            for (int c = 0; c < n; c++) {
                double p[3] = {L * a / n, 2 + L * b / n, L * c / n}, u[3], t = 0.3;
                cs_wind_at(&w, p, t, u);
                for (int d = 0; d < 3; d++)
                    sq[d] += u[d] * u[d] / (n * n * n);
                fastest = fmax(fastest, sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]));
                double div = 0;
                for (int d = 0; d < 3; d++) {
                    double pp[3] = {p[0], p[1], p[2]}, pm[3] = {p[0], p[1], p[2]}, up[3], um[3];
                    pp[d] += h;
                    pm[d] -= h;
                    cs_wind_at(&w, pp, t, up);
                    cs_wind_at(&w, pm, t, um);
                    div += (up[d] - um[d]) / (2 * h);
                }
                worst_div = fmax(worst_div, fabs(div));
            }
    for (int d = 0; d < 3; d++)
        if (!(fabs(sqrt(sq[d]) - w.gust) < 1e-9))
            fail_msg("component %d: RMS %.12f, expected %.12f", d, sqrt(sq[d]), w.gust);
    /* |div| against the size of one derivative, k A = 2 pi A / L */
    assert_true(worst_div < 1e-6 * 2 * M_PI * w.gust / L);
    assert_true(fastest <= cs_wind_max_speed(&w) && fastest > 0.5 * cs_wind_max_speed(&w));
    /* the phases' rates: at x = z = 0, u_y = A (sin(s) + cos(0.414 s)),
     * s = 2 pi t / period; at t = 0 it is A, a quarter period on sin is 1 */
    double o[3] = {0, 2, 0}, u0[3], u1[3];
    cs_wind_at(&w, o, 0.0, u0);
    cs_wind_at(&w, o, 0.25 * w.gust_period, u1);
    assert_true(fabs(u0[1] - w.gust) < 1e-12);
    assert_true(fabs(u1[1] - w.gust * (1 + cos(0.4142135623730951 * M_PI / 2))) < 1e-12);
    /* no gust: the old wind, exactly */
    w.gust = 0;
    cs_wind_at(&w, o, 0.7, u0);
    assert_true(u0[0] == 0 && u0[1] == 0 && u0[2] == 0);
}

/* V(t) of V' = a (sin(theta + omega t) - V), V(0) = 0: the steady response
 * plus the transient that starts it from rest. */
static double first_order_sin(double a, double omega, double theta, double t)
{
    double k = a / (a * a + omega * omega);
    return k * (a * sin(theta + omega * t) - omega * cos(theta + omega * t)) -
           exp(-a * t) * k * (a * sin(theta) - omega * cos(theta));
}

/* Gusts drive the cloth through the drag: a 1 cm level sheet, no gravity,
 * in fast gusts alone (period 0.05 s), for 0.02 s. The drag is along the normal (y) and the gusts' y
 * component at (x, z) is A (sin(k x + s) + cos(k z + r s)), s = 2 pi t / P,
 * so each vertex is pushed by two sinusoids of its own phase. The springs'
 * forces cancel in the sum, so the mass-weighted mean velocity follows
 * rho V' = c (U(t) - V), U the area-weighted mean of the pushes: two
 * first-order responses per vertex, in closed form. That holds while the
 * sheet stays level; but the gusts differ across it and turn it (that is
 * what makes leaves flutter), tilting the drag into the gusts' horizontal
 * part, an error growing as t^2: 1e-4 m/s at 0.02 s, a quarter of the
 * tolerance. A 10% change in the gusts' amplitude or phase rate breaks it
 * (header). */
static void test_wind_gust_drives_sheet(void **state)
{
    (void)state;
    const double rho = 0.1, cd = 1.0, A = 0.4, L = 0.5, P = 0.05, r = 0.4142135623730951;
    cs_cloth_def cloth;
    cs_sim_def def =
        wind_sheet_def(0.01, 2, (const double[3]){0.13, 0.5, -0.21}, rho, cd, 1e-4, 500, &cloth);
    const cs_trimesh *mesh = cloth.mesh;
    def.wind.gust = A;
    def.wind.gust_length = L;
    def.wind.gust_period = P;
    cs_sim *sim = create(&def);
    int nv = mesh->nv;
    double *area = calloc((size_t)nv, sizeof *area), total = 0;
    assert_non_null(area);
    for (int t = 0; t < mesh->nt; t++) {
        const int *v = mesh->tri + 3 * t;
        double e1[3], e2[3];
        for (int d = 0; d < 3; d++) {
            e1[d] = mesh->x[3 * v[1] + d] - mesh->x[3 * v[0] + d];
            e2[d] = mesh->x[3 * v[2] + d] - mesh->x[3 * v[0] + d];
        }
        double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
               cz = e1[0] * e2[1] - e1[1] * e2[0], a = 0.5 * sqrt(cx * cx + cy * cy + cz * cz);
        for (int k = 0; k < 3; k++)
            area[v[k]] += a / 3;
        total += a;
    }
    double a = cd / rho, k = 2 * M_PI / L, omega = 2 * M_PI / P, worst = 0;
    for (int f = 1; f <= 10; f++) {
        advance(sim);
        double t = cs_sim_time(sim), exact = 0, mean = 0;
        for (int i = 0; i < nv; i++) {
            const double *x0 = mesh->x + 3 * i;
            exact += area[i] / total * A *
                     (first_order_sin(a, omega, k * x0[0], t) +
                      first_order_sin(a, r * omega, k * x0[2] + M_PI / 2, t));
            mean += area[i] / total * cs_sim_velocities(sim)[3 * i + 1];
        }
        worst = fmax(worst, fabs(mean - exact));
        if (!(fabs(mean - exact) < 1e-3 * A))
            fail_msg("t=%.3f: mean v_y %.7f, exact %.7f", t, mean, exact);
    }
    print_message("gusts: worst |V - exact| %.3g m/s over 0.02 s (A = %.2f m/s)\n", worst, A);
    free(area);
    cs_sim_destroy(sim);
    cs_trimesh_destroy((cs_trimesh *)cloth.mesh);
}
int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wind_velocity_drag),
        cmocka_unit_test(test_wind_ground_boost),
        cmocka_unit_test(test_wind_gust_field),
        cmocka_unit_test(test_wind_gust_drives_sheet),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
