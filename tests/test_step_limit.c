/* The damped step limit (sim/step_limit.c) against the spectrum it bounds:
 * at the step it returns, the largest eigenvalue of
 * M^-1/2 (dt^2 K - 2 dt D) M^-1/2 over the free particles, with K the
 * springs' true linearised stiffness (k along each spring, its signed
 * tension g = E (1/L0 - 1/l) across it) and D their damping, must be at
 * most 4; the matrix is built here from the springs alone and its
 * eigenvalues found by Jacobi rotations, independently of the Gershgorin
 * sums the limit uses. A strip held at both ends, stretched, is where the
 * tension bounds the step and where the limiting rows touch the held
 * particles. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sim/internal.h"
#include "sim/vec3.h"
#include "grid_cloth.h"

/* The largest eigenvalue of the symmetric n x n matrix a (destroyed), by
 * cyclic Jacobi rotations until the off-diagonal part is negligible */
static double symmetric_max_eigenvalue(double *a, int n)
{
    for (int sweep = 0; sweep < 100; sweep++) {
        double off = 0, diag = 0;
        for (int p = 0; p < n; p++) {
            diag += a[p * n + p] * a[p * n + p];
            for (int q = p + 1; q < n; q++)
                off += a[p * n + q] * a[p * n + q];
        }
        if (off <= 1e-30 * diag)
            break;
        for (int p = 0; p < n; p++)
            for (int q = p + 1; q < n; q++) {
                double apq = a[p * n + q];
                if (apq == 0)
                    continue;
                double theta = (a[q * n + q] - a[p * n + p]) / (2 * apq);
                double t = (theta >= 0 ? 1 : -1) / (fabs(theta) + sqrt(theta * theta + 1));
                double c = 1 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < n; k++) { /* columns p, q */
                    double akp = a[k * n + p], akq = a[k * n + q];
                    a[k * n + p] = c * akp - s * akq;
                    a[k * n + q] = s * akp + c * akq;
                }
                for (int k = 0; k < n; k++) { /* rows p, q */
                    double apk = a[p * n + k], aqk = a[q * n + k];
                    a[p * n + k] = c * apk - s * aqk;
                    a[q * n + k] = s * apk + c * aqk;
                }
            }
    }
    double top = -INFINITY;
    for (int p = 0; p < n; p++)
        top = fmax(top, a[p * n + p]);
    return top;
}

/* The largest eigenvalue of M^-1/2 (dt^2 K - 2 dt D) M^-1/2 at sim->x over
 * the free particles' coordinates */
static double scheme_max_eigenvalue(const cs_sim *sim, double dt)
{
    int *dof = malloc(sizeof *dof * (size_t)sim->n), n = 0;
    assert_non_null(dof);
    for (int i = 0; i < sim->n; i++)
        dof[i] = sim->is_free[i] ? 3 * n++ : -1;
    n *= 3;
    double *a = calloc((size_t)n * n, sizeof *a);
    assert_non_null(a);
    const cs_springs *s = &sim->springs;
    for (int k = 0; k < s->n; k++) {
        int ends[2] = {s->ends[2 * k], s->ends[2 * k + 1]};
        double u[3];
        cs_sub(sim->x + 3 * ends[1], sim->x + 3 * ends[0], u);
        double l = cs_norm(u);
        for (int d = 0; d < 3; d++)
            u[d] /= l;
        double kk = s->stiffness[k] / s->rest_length[k];
        double g = s->stiffness[k] * (1 / s->rest_length[k] - 1 / l);
        double along = dt * dt * kk - 2 * dt * s->damping[k], across = dt * dt * g;
        double block[3][3];
        for (int p = 0; p < 3; p++)
            for (int q = 0; q < 3; q++)
                block[p][q] = (along - across) * u[p] * u[q] + (p == q ? across : 0);
        for (int e = 0; e < 2; e++)
            for (int f = 0; f < 2; f++) {
                int r = dof[ends[e]], c = dof[ends[f]];
                if (r < 0 || c < 0)
                    continue;
                double sign = e == f ? 1 : -1;
                double scale = sign / sqrt(sim->mass[ends[e]] * sim->mass[ends[f]]);
                for (int p = 0; p < 3; p++)
                    for (int q = 0; q < 3; q++)
                        a[(r + p) * n + c + q] += scale * block[p][q];
            }
    }
    double top = symmetric_max_eigenvalue(a, n);
    free(a);
    free(dof);
    return top;
}

/* A 1 m x 0.25 m strip of 12 x 3 quads, its two short ends held by
 * scripts that do not move */
static cs_sim *held_strip(cs_trimesh **mesh, int *held)
{
    double size[2] = {1, 0.25}, q[4] = {1, 0, 0, 0}, c[3] = {0, 0, 0};
    int res[2] = {12, 3};
    *mesh = cs_trimesh_create_grid(size, res, q, c);
    int nheld = 0;
    for (int i = 0; i < (*mesh)->nv; i++)
        if (fabs(fabs((*mesh)->x[3 * i]) - 0.5) < 1e-9)
            held[nheld++] = i;
    assert_int_equal(nheld, 8);
    static cs_vertex_script ends;
    ends = (cs_vertex_script){nheld, held, cs_motion_static(), 0};
    static cs_cloth_def cloth;
    cloth = (cs_cloth_def){.name = "strip", .mesh = *mesh,
                           .material = cs_default_cloth_material(), .nscripts = 1,
                           .scripts = &ends};
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = &cloth;
    def.gravity[0] = def.gravity[1] = def.gravity[2] = 0;
    def.step_limit = CS_STEP_DAMPED;
    char err[512];
    cs_sim *sim = NULL;
    assert_int_equal(cs_sim_create_checked(&def, &sim, err, sizeof err), CS_OK);
    return sim;
}

/* At rest only the damping offsets the stiffness: the limit taken at
 * creation is stable there (at 1.0 of 4, Gershgorin's sums being loose
 * where the damping outweighs the stiffness along every spring) */
static void test_rest_limit_is_stable(void **state)
{
    (void)state;
    cs_trimesh *mesh;
    int held[64];
    cs_sim *sim = held_strip(&mesh, held);
    double dt = cs_sim_damped_dt(sim);
    assert_true(dt > 10 * cs_sim_undamped_dt(sim)); /* the damping's gain */
    double top = scheme_max_eigenvalue(sim, dt);
    assert_true(top <= 4 * (1 + 1e-9));
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* Stretched by 1% along its length and by 12% in the cells beside its
 * held ends (and jittered out of its plane), as a twisted strip is beside
 * its scripted ends: the tension across the springs bounds the step, the
 * limit from the current positions is stable, within 15% of the largest
 * stable step, and twice it is not stable */
static void test_stretched_limit_is_stable(void **state)
{
    (void)state;
    cs_trimesh *mesh;
    int held[64];
    cs_sim *sim = held_strip(&mesh, held);
    double rest = cs_sim_damped_dt(sim);
    unsigned seed = 7;
    for (int i = 0; i < sim->n; i++) {
        sim->x[3 * i] *= 1.01;
        if (!sim->is_free[i]) /* the ends' cells stretched by 12% */
            sim->x[3 * i] += sim->x[3 * i] > 0 ? 0.01 : -0.01;
        sim->x[3 * i + 1] += 0.002 * frand(&seed);
    }
    double dt = cs_step_limit_now(sim);
    assert_true(dt < 0.5 * rest);                 /* the tension decides it */
    assert_true(dt > cs_sim_undamped_dt(sim));    /* the damped test, not its floor */
    double top = scheme_max_eigenvalue(sim, dt);
    assert_true(top <= 4 * (1 + 1e-9));
    assert_true(top > 3); /* counting the held ends' springs twice gave 1.9 */
    assert_true(scheme_max_eigenvalue(sim, 2 * dt) > 4);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rest_limit_is_stable),
        cmocka_unit_test(test_stretched_limit_is_stable),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
