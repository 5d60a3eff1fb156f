/* Validation against the analytic solution (Figs. 7 and 8): a particle and
 * a damped tetrahedron on an incline plane, from the scene files in
 * scenes/validation/, at the paper's angle and coefficients and at others
 * set through the same --set overrides a user would type. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "incline_analytic.h"

static void expect_analytic(const char *file, double theta, double mu, double v0)
{
    incline_result r;
    char err[512];
    if (run_incline(file, theta, mu, v0, "improved", 0, NULL, &r, err, sizeof err))
        fail_msg("%s", err);
    if (r.worst_position > 1 || r.worst_velocity > 1)
        fail_msg("%s theta=%g mu=%g v0=%g: position error %.3g, velocity error %.3g of the "
                 "tolerance (displacement %.6f, analytic %.6f)",
                 file, theta, mu, v0, r.worst_position, r.worst_velocity, r.displacement, r.exact);
    double a = (sin(theta * M_PI / 180) - mu * cos(theta * M_PI / 180)) * G;
    double t_stop = a < 0 ? -v0 / a : INFINITY;
    if (v0 > 0 && t_stop < 0.98) { /* it must come to rest within a frame of the analytic time */
        if (!(r.stop_time > 0 && fabs(r.stop_time - t_stop) <= 0.0100001))
            fail_msg("%s theta=%g mu=%g v0=%g: stopped at %.4f s, analytic %.4f s", file, theta,
                     mu, v0, r.stop_time, t_stop);
    }
}

static void test_particle_paper_cases(void **state)
{
    (void)state;
    expect_analytic("particle_accelerating.yaml", 36, 0.6, 0);
    expect_analytic("particle_decelerating.yaml", 36, 0.9, 1);
}

static void test_tetrahedron_paper_cases(void **state)
{
    (void)state;
    expect_analytic("tetrahedron_accelerating.yaml", 36, 0.6, 0);
    expect_analytic("tetrahedron_decelerating.yaml", 36, 0.9, 1);
}

/* The previous method's position projection and projected solve lose the
 * friction, so it slides too fast in both cases (Fig. 7). */
static void test_previous_method_is_too_fast(void **state)
{
    (void)state;
    const char *files[] = {"particle_accelerating.yaml", "particle_decelerating.yaml",
                           "tetrahedron_accelerating.yaml", "tetrahedron_decelerating.yaml"};
    double mus[] = {0.6, 0.9, 0.6, 0.9}, v0s[] = {0, 1, 0, 1};
    for (int k = 0; k < 4; k++) {
        incline_result r;
        char err[512];
        if (run_incline(files[k], 36, mus[k], v0s[k], "projection", 0, NULL, &r, err, sizeof err))
            fail_msg("%s", err);
        if (!(r.displacement > 1.5 * r.exact + 0.05))
            fail_msg("%s: the previous method went %.4f m, analytic %.4f m: not too fast",
                     files[k], r.displacement, r.exact);
    }
}

static void test_other_angles_and_coefficients(void **state)
{
    (void)state;
    double thetas[] = {12, 27, 45, 60};
    double mus[] = {0.1, 0.45, 1.3};
    double v0s[] = {0, 2};
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 2; k++)
                expect_analytic("particle_accelerating.yaml", thetas[i], mus[j], v0s[k]);
    /* the tetrahedron: fewer combinations, each exercising CG */
    expect_analytic("tetrahedron_accelerating.yaml", 20, 0.2, 0.5);
    expect_analytic("tetrahedron_decelerating.yaml", 50, 1.4, 1.0);
    expect_analytic("tetrahedron_accelerating.yaml", 30, 0.0, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_particle_paper_cases),
        cmocka_unit_test(test_tetrahedron_paper_cases),
        cmocka_unit_test(test_previous_method_is_too_fast),
        cmocka_unit_test(test_other_angles_and_coefficients),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
