/* Unit tests of the simulation core's parts: spring forces and their
 * damping Jacobian against finite differences, the CG solve against a dense
 * factorisation, bodies' phi and grad phi, Gamma in each friction regime,
 * and motions. The time step as a whole is tested in test_sim_step.c. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim/internal.h"
#include "sim/vec3.h"
#include "grid_cloth.h"

static double spring_energy(const cs_springs *s, const double *x)
{
    double e = 0;
    for (int k = 0; k < s->n; k++) {
        double u[3];
        cs_sub(x + 3 * s->ends[2 * k + 1], x + 3 * s->ends[2 * k], u);
        double l = cs_norm(u), L0 = s->rest_length[k];
        e += 0.5 * s->stiffness[k] / L0 * (l - L0) * (l - L0);
    }
    return e;
}

static void test_spring_force_is_minus_energy_gradient(void **state)
{
    (void)state;
    cs_cloth_def cloth;
    cs_trimesh *mesh;
    cs_sim_def def = grid_def(&cloth, &mesh, 3, 7);
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    assert_true(sim->springs.n > sim->springs.nedge); /* bending springs exist */
    unsigned seed = 3;
    for (int k = 0; k < 3 * sim->n; k++) /* deform: stretch some, squash others */
        sim->x[k] += 0.02 * frand(&seed);
    double *f = calloc(3 * (size_t)sim->n, sizeof *f);
    cs_springs_elastic(&sim->springs, sim->x, f);
    double eps = 1e-7, worst = 0, scale = 0;
    for (int k = 0; k < 3 * sim->n; k++) {
        double keep = sim->x[k];
        sim->x[k] = keep + eps;
        double ep = spring_energy(&sim->springs, sim->x);
        sim->x[k] = keep - eps;
        double em = spring_energy(&sim->springs, sim->x);
        sim->x[k] = keep;
        double fd = -(ep - em) / (2 * eps);
        worst = fmax(worst, fabs(fd - f[k]));
        scale = fmax(scale, fabs(f[k]));
    }
    assert_true(scale > 1e-3);
    assert_true(worst < 1e-6 * scale + 1e-9);
    free(f);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* total spring force (elastic + damping) for positions x, velocities v */
static void spring_force(cs_sim *sim, const double *v, double *f)
{
    memset(f, 0, sizeof *f * 3 * (size_t)sim->n);
    cs_springs_elastic(&sim->springs, sim->x, f);
    cs_springs_prepare(&sim->springs, sim->x);
    cs_springs_add_damping(&sim->springs, v, f);
}

static void test_damping_jacobian_matches_finite_differences(void **state)
{
    (void)state;
    cs_cloth_def cloth;
    cs_trimesh *mesh;
    cs_sim_def def = grid_def(&cloth, &mesh, 3, 11);
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    int n3 = 3 * sim->n;
    unsigned seed = 5;
    double *v = calloc((size_t)n3, sizeof *v), *fp = calloc((size_t)n3, sizeof *fp),
           *fm = calloc((size_t)n3, sizeof *fm), *e = calloc((size_t)n3, sizeof *e),
           *De = calloc((size_t)n3, sizeof *De);
    for (int k = 0; k < n3; k++) {
        v[k] = frand(&seed);
        sim->x[k] += 0.02 * frand(&seed);
    }
    double eps = 1e-6, worst = 0, scale = 0;
    for (int col = 0; col < n3; col++) {
        v[col] += eps;
        spring_force(sim, v, fp);
        v[col] -= 2 * eps;
        spring_force(sim, v, fm);
        v[col] += eps;
        memset(e, 0, sizeof *e * (size_t)n3);
        memset(De, 0, sizeof *De * (size_t)n3);
        e[col] = 1;
        cs_springs_add_damping(&sim->springs, e, De);
        for (int row = 0; row < n3; row++) {
            double fd = (fp[row] - fm[row]) / (2 * eps);
            worst = fmax(worst, fabs(fd - De[row]));
            scale = fmax(scale, fabs(De[row]));
        }
        assert_true(De[col] <= 0); /* D is negative semi-definite */
    }
    assert_true(scale > 0);
    assert_true(worst < 1e-6 * scale);
    free(v), free(fp), free(fm), free(e), free(De);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* Dense Gaussian elimination with partial pivoting, for reference. */
static void dense_solve(int n, double *A, double *b)
{
    for (int c = 0; c < n; c++) {
        int p = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(A[r * n + c]) > fabs(A[p * n + c]))
                p = r;
        for (int k = 0; k < n; k++) {
            double t = A[c * n + k];
            A[c * n + k] = A[p * n + k];
            A[p * n + k] = t;
        }
        double t = b[c];
        b[c] = b[p];
        b[p] = t;
        for (int r = c + 1; r < n; r++) {
            double f = A[r * n + c] / A[c * n + c];
            for (int k = c; k < n; k++)
                A[r * n + k] -= f * A[c * n + k];
            b[r] -= f * b[c];
        }
    }
    for (int r = n - 1; r >= 0; r--) {
        for (int k = r + 1; k < n; k++)
            b[r] -= A[r * n + k] * b[k];
        b[r] /= A[r * n + r];
    }
}

static void test_cg_matches_dense_solve(void **state)
{
    (void)state;
    cs_cloth_def cloth;
    cs_trimesh *mesh;
    cs_sim_def def = grid_def(&cloth, &mesh, 4, 13);
    def.cg_tolerance = 1e-12;
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    int n3 = 3 * sim->n;
    sim->half_dt = 0.5e-3;
    cs_springs_prepare(&sim->springs, sim->x);
    for (int i = 0; i < sim->n; i++)
        sim->mode[i] = CS_FREE;
    /* assemble A = M - h D column by column from the operator */
    double *A = calloc((size_t)n3 * n3, sizeof *A), *e = calloc((size_t)n3, sizeof *e),
           *col = calloc((size_t)n3, sizeof *col), *rhs = calloc((size_t)n3, sizeof *rhs),
           *v0 = calloc((size_t)n3, sizeof *v0), *v = calloc((size_t)n3, sizeof *v),
           *ref = calloc((size_t)n3, sizeof *ref);
    for (int c = 0; c < n3; c++) {
        memset(e, 0, sizeof *e * (size_t)n3);
        e[c] = 1;
        cs_system_apply(sim, e, col);
        for (int r = 0; r < n3; r++)
            A[r * n3 + c] = col[r];
    }
    for (int r = 0; r < n3; r++) /* symmetric */
        for (int c = 0; c < r; c++)
            assert_true(fabs(A[r * n3 + c] - A[c * n3 + r]) < 1e-15);
    unsigned seed = 17;
    for (int k = 0; k < n3; k++) {
        rhs[k] = 1e-6 * frand(&seed);
        ref[k] = rhs[k];
    }
    int it = cs_cg_solve(sim, v0, rhs, v, NULL, NULL, NULL, -1);
    assert_true(it > 3); /* the damping couples particles: real work */
    dense_solve(n3, A, ref);
    double worst = 0, scale = 0;
    for (int k = 0; k < n3; k++) {
        worst = fmax(worst, fabs(v[k] - ref[k]));
        scale = fmax(scale, fabs(ref[k]));
    }
    assert_true(worst < 1e-9 * scale);

    /* the warm start: base plus the blend of the histories is added to the
     * explicit update M^-1 rhs (v0 = 0 here). Histories that, with base,
     * make the exact response start CG at the answer; a misleading base
     * costs iterations but not accuracy; the history shifts and receives
     * the response less base. */
    double *base = calloc((size_t)n3, sizeof *base), *warm = calloc((size_t)n3, sizeof *warm),
           *before = calloc((size_t)n3, sizeof *before);
    for (int k = 0; k < n3; k++) {
        double response = ref[k] - rhs[k] / sim->mass[k / 3];
        base[k] = 1e-6 * frand(&seed);
        warm[k] = before[k] = response - base[k];
    }
    double *old = malloc(sizeof *old * (size_t)n3);
    memcpy(old, warm, sizeof *old * (size_t)n3);
    assert_int_equal(cs_cg_solve(sim, v0, rhs, v, base, warm, before, -1), 0);
    for (int k = 0; k < n3; k++) {
        double response = ref[k] - rhs[k] / sim->mass[k / 3];
        assert_true(fabs(v[k] - ref[k]) < 1e-9 * scale);
        assert_true(fabs(warm[k] - (response - base[k])) < 1e-9 * scale);
        assert_true(before[k] == old[k]); /* the last response moved back */
        warm[k] = before[k] = 0;
        base[k] = 1e-4 * frand(&seed); /* a hundred times the answer's size */
    }
    assert_true(cs_cg_solve(sim, v0, rhs, v, base, warm, before, -1) > 3);
    for (int k = 0; k < n3; k++)
        assert_true(fabs(v[k] - ref[k]) < 1e-9 * scale);
    free(base), free(warm), free(before), free(old);

    /* with contact projection: normal velocities keep their start values and
     * the tangential residual vanishes; the normals are tilted off the axes,
     * so the filtered diagonal blocks CG preconditions with couple all three
     * components */
    sim->contact_normal = calloc((size_t)n3, sizeof *sim->contact_normal);
    for (int i = 0; i < sim->n; i += 3) {
        double N[3] = {0.3 * frand(&seed), 1, 0.3 * frand(&seed)};
        double len = cs_norm(N);
        for (int d = 0; d < 3; d++)
            N[d] /= len;
        sim->mode[i] = CS_CONTACT;
        memcpy(sim->contact_normal + 3 * i, N, sizeof N);
    }
    sim->mode[1] = CS_FIXED;
    for (int k = 0; k < n3; k++)
        v0[k] = 0.1 * frand(&seed);
    cs_cg_solve(sim, v0, rhs, v, NULL, NULL, NULL, -1);
    cs_system_apply(sim, v, col);
    for (int i = 0; i < sim->n; i++) {
        double r[3], dv[3];
        for (int d = 0; d < 3; d++) {
            r[d] = (rhs[3 * i + d] - col[3 * i + d]) / sim->mass[i];
            dv[d] = v[3 * i + d] - v0[3 * i + d];
        }
        if (sim->mode[i] == CS_FIXED) {
            for (int d = 0; d < 3; d++)
                assert_true(dv[d] == 0);
        } else if (sim->mode[i] == CS_CONTACT) {
            const double *N = sim->contact_normal + 3 * i;
            assert_true(fabs(cs_dot(dv, N)) < 1e-15);
            cs_axpy(-cs_dot(r, N), N, r); /* the tangential part */
            assert_true(cs_norm(r) < 1e-11);
        } else {
            assert_true(cs_norm(r) < 1e-11);
        }
    }
    free(sim->contact_normal);
    sim->contact_normal = NULL;
    free(A), free(e), free(col), free(rhs), free(v0), free(v), free(ref);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* Thread shares (shares.h) follow the threads' measured speeds, a stall
 * moves them only so far, a thread that stalls for good keeps a quarter of
 * an equal share; and where the rows go changes no bit of CG's answer. */
static void set_busy(cs_shares *s, const double *speed)
{
    for (int t = 0; t < s->threads; t++)
        s->clock[t].busy = (s->first[t + 1] - s->first[t]) * (double)s->block / speed[t];
}

static void test_thread_shares(void **state)
{
    (void)state;
    int threads_before = omp_get_max_threads();
    omp_set_num_threads(2);
    cs_shares s;
    assert_int_equal(cs_shares_init(&s, 64 * 90 - 10, 64), 0);
    assert_int_equal(s.nblocks, 90);
    assert_int_equal(s.first[1], 45);
    double half[2] = {1e6, 0.5e6}; /* rows per second: thread 1 at half speed */
    for (int k = 0; k < 40; k++) {
        set_busy(&s, half);
        cs_shares_update(&s);
    }
    assert_true(abs(s.first[1] - 60) <= 1); /* two thirds of the rows to thread 0 */
    double stalled[2] = {1e6, 0.5e6 / 100}; /* descheduled for one solve */
    int was = s.first[1];
    set_busy(&s, stalled);
    cs_shares_update(&s);
    assert_true(s.first[1] > was && s.first[1] <= was + 4);
    double gone[2] = {1e6, 1.0};
    for (int k = 0; k < 100; k++) {
        set_busy(&s, gone);
        cs_shares_update(&s);
    }
    assert_int_equal(s.first[1], 80); /* 90 / (1 + 1/8) */
    assert_int_equal(s.first[2], 90);
    cs_shares_free(&s);

    /* the same solve under three splits of its four blocks (196 particles) */
    cs_cloth_def cloth;
    cs_trimesh *mesh;
    cs_sim_def def = grid_def(&cloth, &mesh, 13, 13);
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    assert_int_equal(sim->shares.threads, 2);
    assert_int_equal(sim->shares.nblocks, 4);
    int n3 = 3 * sim->n;
    sim->half_dt = 0.5e-3;
    cs_springs_prepare(&sim->springs, sim->x);
    for (int i = 0; i < sim->n; i++)
        sim->mode[i] = CS_FREE;
    double *rhs = calloc((size_t)n3, sizeof *rhs), *v0 = calloc((size_t)n3, sizeof *v0),
           *v[3];
    unsigned seed = 29;
    for (int k = 0; k < n3; k++) {
        rhs[k] = 1e-6 * frand(&seed);
        v0[k] = 1e-3 * frand(&seed);
    }
    int split[3] = {2, 0, 3}, iterations[3];
    for (int c = 0; c < 3; c++) {
        v[c] = calloc((size_t)n3, sizeof *v[c]);
        sim->shares.first[1] = split[c];
        iterations[c] = cs_cg_solve(sim, v0, rhs, v[c], NULL, NULL, NULL, -1);
    }
    assert_true(iterations[0] > 3);
    for (int c = 1; c < 3; c++) {
        assert_int_equal(iterations[c], iterations[0]);
        assert_memory_equal(v[c], v[0], sizeof *v[0] * (size_t)n3);
    }
    for (int c = 0; c < 3; c++)
        free(v[c]);
    free(rhs), free(v0);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
    omp_set_num_threads(threads_before);
}

static void check_phi(const cs_body_def *b, double t, double x, double y, double z,
                      double want_phi, const double *want_grad)
{
    double p[3] = {x, y, z}, g[3];
    double phi = cs_body_def_phi(b, t, p, g);
    assert_true(fabs(phi - want_phi) < 1e-12);
    assert_true(fabs(cs_norm(g) - 1) < 1e-12);
    if (want_grad)
        for (int d = 0; d < 3; d++)
            assert_true(fabs(g[d] - want_grad[d]) < 1e-9);
    /* away from kinks the gradient is the finite difference of phi */
    double eps = 1e-6, fd[3], gg[3];
    for (int d = 0; d < 3; d++) {
        double q[3] = {x, y, z};
        q[d] += eps;
        double a = cs_body_def_phi(b, t, q, gg);
        q[d] -= 2 * eps;
        fd[d] = (a - cs_body_def_phi(b, t, q, gg)) / (2 * eps);
    }
    if (want_grad)
        for (int d = 0; d < 3; d++)
            assert_true(fabs(fd[d] - g[d]) < 1e-6);
}

static void test_analytic_bodies(void **state)
{
    (void)state;
    cs_body_def b = cs_default_body_def();
    double up[3] = {0, 1, 0}, down[3] = {0, -1, 0}, px[3] = {1, 0, 0};
    b.shape = CS_BODY_PLANE;
    check_phi(&b, 0, 3, 0.25, -2, 0.25, up);
    check_phi(&b, 0, 0, -0.5, 0, -0.5, up);

    b.shape = CS_BODY_SPHERE;
    b.radius = 2;
    check_phi(&b, 0, 0, 3, 0, 1, up);
    check_phi(&b, 0, 0, -0.5, 0, -1.5, down);
    double diag[3] = {1 / sqrt(3.0), 1 / sqrt(3.0), 1 / sqrt(3.0)};
    check_phi(&b, 0, 1, 1, 1, sqrt(3.0) - 2, diag);

    b.shape = CS_BODY_BOX;
    b.half_extents[0] = 1, b.half_extents[1] = 2, b.half_extents[2] = 3;
    check_phi(&b, 0, 1.5, 0, 0, 0.5, px);             /* outside a face */
    check_phi(&b, 0, 0, -1.5, 0.2, -0.5, down);       /* inside, nearest face */
    double corner[3] = {1 / sqrt(2.0), 1 / sqrt(2.0), 0};
    check_phi(&b, 0, 2, 3, 0, sqrt(2.0), corner);     /* outside an edge */

    b.shape = CS_BODY_CYLINDER;
    b.radius = 1, b.half_height = 2;
    check_phi(&b, 0, 3, 0.5, 0, 2, px);               /* side */
    check_phi(&b, 0, 0.2, 2.5, 0.1, 0.5, up);         /* cap */
    check_phi(&b, 0, 0.5, 0, 0, -0.5, px);            /* inside, nearest the side */
    double rim[3] = {0.6, 0.8, 0};
    check_phi(&b, 0, 1.6, 2.8, 0, 1, rim);            /* beyond the rim */

    /* a sphere moving and spinning: phi follows its centre, the velocity of
     * a surface point is v + w x r */
    b.shape = CS_BODY_SPHERE;
    b.radius = 1;
    b.motion.kind = CS_MOTION_CONSTANT;
    b.motion.velocity[0] = 2;
    b.motion.angular_velocity[1] = 3;
    check_phi(&b, 0.5, 1, 2, 0, 1, up);               /* centre at (1, 0, 0) */
    double vel[3], x[3] = {2, 0, 0};
    cs_body_def_velocity(&b, 0.5, x, vel);
    assert_true(fabs(vel[0] - 2) < 1e-12 && fabs(vel[1]) < 1e-12 && fabs(vel[2] + 3) < 1e-12);
}

static void test_gamma_regimes(void **state)
{
    (void)state;
    double N[3] = {0, 1, 0}, still[3] = {0, 0, 0}, out[3];
    /* separating: untouched */
    double sep[3] = {1, 0.5, 0};
    cs_gamma(sep, N, still, 0.5, out);
    for (int d = 0; d < 3; d++)
        assert_true(out[d] == sep[d]);
    /* sliding: the normal part is removed, the tangential speed drops by
     * mu times the normal speed removed */
    double slide[3] = {2, -1, 0};
    cs_gamma(slide, N, still, 0.5, out);
    assert_true(fabs(out[0] - 1.5) < 1e-15 && out[1] == 0 && out[2] == 0);
    /* sticking: friction enough to stop the tangential motion entirely */
    double stick[3] = {0.3, -1, 0.4};
    cs_gamma(stick, N, still, 0.6, out);
    assert_true(out[0] == 0 && out[1] == 0 && out[2] == 0);
    /* moving body: everything relative to it; the body may pull away (its
     * normal velocity is the floor) */
    double body[3] = {1, 0.2, 0}, v[3] = {1.5, -0.3, 0};
    cs_gamma(v, N, body, 0.2, out);
    assert_true(fabs(out[1] - 0.2) < 1e-15);
    assert_true(fabs(out[0] - (1 + 0.5 - 0.2 * 0.5)) < 1e-15);
    /* zero friction keeps the tangential velocity */
    cs_gamma(slide, N, still, 0, out);
    assert_true(out[0] == 2);
}

static void test_keyframe_motion(void **state)
{
    (void)state;
    cs_keyframe keys[2] = {{0, {0, 0, 0}, {1, 0, 0, 0}}, {2, {2, 4, 0}, {0, 0, 0, 0}}};
    double axis_q[4];
    double w[3] = {0, 0, M_PI / 2}; /* 90 degrees about z over the span */
    cs_quat_from_rotation_vector(w, 1, axis_q);
    memcpy(keys[1].rotation, axis_q, sizeof axis_q);
    cs_motion m = cs_motion_static();
    m.kind = CS_MOTION_KEYFRAMES;
    m.nkeys = 2;
    m.keys = keys;
    double R[9], c[3], v[3], om[3];
    cs_motion_pose(&m, 1, R, c, v, om);
    assert_true(fabs(c[0] - 1) < 1e-15 && fabs(c[1] - 2) < 1e-15);
    assert_true(fabs(v[0] - 1) < 1e-15 && fabs(v[1] - 2) < 1e-15);
    assert_true(fabs(om[2] - M_PI / 4) < 1e-12);
    /* R at the middle is 45 degrees about z */
    assert_true(fabs(R[0] - cos(M_PI / 4)) < 1e-12 && fabs(R[3] - sin(M_PI / 4)) < 1e-12);
    /* held before the first and after the last key */
    cs_motion_pose(&m, 5, R, c, v, om);
    assert_true(c[0] == 2 && v[0] == 0 && om[2] == 0);
    assert_true(fabs(R[1] + 1) < 1e-12);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_spring_force_is_minus_energy_gradient),
        cmocka_unit_test(test_damping_jacobian_matches_finite_differences),
        cmocka_unit_test(test_cg_matches_dense_solve),
        cmocka_unit_test(test_thread_shares),
        cmocka_unit_test(test_analytic_bodies),
        cmocka_unit_test(test_gamma_regimes),
        cmocka_unit_test(test_keyframe_motion),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
