/* Unit tests of the simulation core: spring forces and their damping
 * Jacobian against finite differences, the CG solve against a dense
 * factorisation, bodies' phi and grad phi, Gamma in each friction regime,
 * motions, the plan of stages, and the automatic time step. */
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
#include "sim/vec3.h"

static double frand(unsigned *seed)
{
    *seed = *seed * 1103515245u + 12345u;
    return ((*seed >> 8) & 0xffff) / 65535.0 * 2.0 - 1.0;
}

/* A small jittered grid cloth definition; the mesh is returned for freeing. */
static cs_sim_def grid_def(cs_cloth_def *cloth, cs_trimesh **mesh, int res, unsigned seed)
{
    double size[2] = {1, 1}, q[4] = {1, 0, 0, 0}, c[3] = {0, 1, 0};
    int r[2] = {res, res};
    *mesh = cs_trimesh_create_grid(size, r, q, c);
    for (int k = 0; k < 3 * (*mesh)->nv; k++)
        (*mesh)->x[k] += 0.01 * frand(&seed);
    memset(cloth, 0, sizeof *cloth);
    cloth->name = "grid";
    cloth->mesh = *mesh;
    cloth->material = cs_default_cloth_material();
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = cloth;
    return def;
}

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
    cs_springs_add_elastic(&sim->springs, sim->x, f);
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
    cs_springs_add_elastic(&sim->springs, sim->x, f);
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
    int it = cs_cg_solve(sim, v0, rhs, v, NULL, NULL);
    assert_true(it > 3); /* the damping couples particles: real work */
    dense_solve(n3, A, ref);
    double worst = 0, scale = 0;
    for (int k = 0; k < n3; k++) {
        worst = fmax(worst, fabs(v[k] - ref[k]));
        scale = fmax(scale, fabs(ref[k]));
    }
    assert_true(worst < 1e-9 * scale);

    /* with contact projection: normal velocities keep their start values and
     * the tangential residual vanishes */
    double N[3] = {0, 1, 0};
    sim->contact_normal = calloc((size_t)n3, sizeof *sim->contact_normal);
    for (int i = 0; i < sim->n; i += 3) {
        sim->mode[i] = CS_CONTACT;
        memcpy(sim->contact_normal + 3 * i, N, sizeof N);
    }
    sim->mode[1] = CS_FIXED;
    for (int k = 0; k < n3; k++)
        v0[k] = 0.1 * frand(&seed);
    cs_cg_solve(sim, v0, rhs, v, NULL, NULL);
    cs_system_apply(sim, v, col);
    for (int i = 0; i < sim->n; i++) {
        double r[3];
        for (int d = 0; d < 3; d++)
            r[d] = (rhs[3 * i + d] - col[3 * i + d]) / sim->mass[i];
        if (sim->mode[i] == CS_FIXED) {
            for (int d = 0; d < 3; d++)
                assert_true(v[3 * i + d] == v0[3 * i + d]);
        } else if (sim->mode[i] == CS_CONTACT) {
            assert_true(fabs(v[3 * i + 1] - v0[3 * i + 1]) < 1e-15);
            assert_true(fabs(r[0]) < 1e-11 && fabs(r[2]) < 1e-11);
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

static void test_plan_omits_absent_stages(void **state)
{
    (void)state;
    cs_cloth_def cloth;
    cs_trimesh *mesh;
    cs_sim_def def = grid_def(&cloth, &mesh, 4, 19);
    def.wind.drag = 1;              /* wind given but switched off */
    def.wind_enabled = false;
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    const cs_plan *plan = cs_sim_plan(sim);
    assert_false(cs_plan_has(plan, CS_STAGE_BODY_COLLISION));
    assert_false(cs_plan_has(plan, CS_STAGE_BODY_FRICTION));
    assert_false(cs_plan_has(plan, CS_STAGE_WIND));
    assert_false(cs_plan_has(plan, CS_STAGE_SCRIPTED_VERTICES));
    assert_true(cs_plan_has(plan, CS_STAGE_VELOCITY_HALF));
    assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
    const cs_stage_timing *t = cs_sim_stage_timing(sim);
    cs_stage absent[] = {CS_STAGE_BODY_COLLISION, CS_STAGE_BODY_FRICTION, CS_STAGE_WIND,
                         CS_STAGE_SCRIPTED_VERTICES, CS_STAGE_REPULSION_PAIRS,
                         CS_STAGE_SELF_REPULSION, CS_STAGE_SELF_FRICTION, CS_STAGE_COLLISIONS,
                         CS_STAGE_VERIFY};
    for (size_t k = 0; k < sizeof absent / sizeof *absent; k++) {
        assert_int_equal(t[absent[k]].calls, 0);
        assert_true(t[absent[k]].seconds == 0);
        assert_int_equal(cs_sim_stage_bytes(sim, absent[k]), 0);
    }
    assert_null(sim->contact_normal);
    assert_null(sim->wind_normal);
    assert_null(sim->selfcol); /* self-collision off: no hierarchy, no pairs */
    assert_true(t[CS_STAGE_VELOCITY_HALF].calls > 0);
    cs_sim_destroy(sim);

    /* with a body, wind and a pin, all three appear and run */
    cs_body_def body = cs_default_body_def();
    int pinned = 0;
    cs_vertex_script pin = {1, &pinned, cs_motion_static(), 0};
    cloth.nscripts = 1;
    cloth.scripts = &pin;
    def.nbodies = 1;
    def.bodies = &body;
    def.wind_enabled = true;
    sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    plan = cs_sim_plan(sim);
    assert_true(cs_plan_has(plan, CS_STAGE_BODY_COLLISION) && cs_plan_has(plan, CS_STAGE_WIND) &&
                cs_plan_has(plan, CS_STAGE_SCRIPTED_VERTICES));
    assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
    t = cs_sim_stage_timing(sim);
    assert_true(t[CS_STAGE_BODY_COLLISION].calls > 0 && t[CS_STAGE_WIND].calls > 0);
    assert_true(cs_sim_stage_bytes(sim, CS_STAGE_BODY_COLLISION) > 0);
    /* the pinned vertex has not moved */
    for (int d = 0; d < 3; d++)
        assert_true(cs_sim_positions(sim)[d] == mesh->x[d]);
    cs_sim_destroy(sim);

    /* self-collision on: its four stages run and own their memory */
    def.self_collision = true;
    sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    cs_stage self_stages[] = {CS_STAGE_REPULSION_PAIRS, CS_STAGE_SELF_REPULSION,
                              CS_STAGE_SELF_FRICTION, CS_STAGE_COLLISIONS};
    assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
    t = cs_sim_stage_timing(sim);
    for (size_t k = 0; k < 4; k++) {
        assert_true(cs_plan_has(cs_sim_plan(sim), self_stages[k]));
        assert_true(t[self_stages[k]].calls > 0);
    }
    assert_true(cs_sim_stage_bytes(sim, CS_STAGE_COLLISIONS) > 0);
    assert_false(cs_plan_has(cs_sim_plan(sim), CS_STAGE_VERIFY)); /* not asked for */
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* A hanging cloth pinned at two corners stays stable at several resolutions
 * with the automatic step; the step shrinks as the springs get shorter. */
static void test_automatic_dt_is_stable_across_resolutions(void **state)
{
    (void)state;
    double last_dt = INFINITY;
    int resolutions[] = {4, 8, 16};
    for (int r = 0; r < 3; r++) {
        double size[2] = {1, 1}, q[4] = {1, 0, 0, 0}, c[3] = {0, 0, 0};
        int res[2] = {resolutions[r], resolutions[r]};
        cs_trimesh *mesh = cs_trimesh_create_grid(size, res, q, c);
        int corners[2] = {0, resolutions[r]};
        cs_vertex_script pin = {2, corners, cs_motion_static(), 0};
        cs_cloth_def cloth = {.name = "c", .mesh = mesh, .material = cs_default_cloth_material(),
                              .nscripts = 1, .scripts = &pin};
        cs_sim_def def = cs_default_sim_def();
        def.ncloths = 1;
        def.cloths = &cloth;
        def.fps = 60;
        cs_sim *sim = cs_sim_create(&def, NULL, 0);
        assert_non_null(sim);
        assert_true(cs_sim_dt(sim) < last_dt);
        assert_true(cs_sim_dt(sim) <= 0.5 * cs_sim_stable_dt(sim) * (1 + 1e-12));
        last_dt = cs_sim_dt(sim);
        cs_frame_stats st;
        for (int f = 0; f < 30; f++) {
            assert_int_equal(cs_sim_advance_frame(sim, &st), CS_OK);
            assert_true(st.max_speed < 10);
        }
        /* it fell, and hangs below the pins without flying apart */
        const double *x = cs_sim_positions(sim);
        double lowest = 0;
        for (int i = 0; i < cs_sim_particle_count(sim); i++) {
            assert_true(cs_norm(x + 3 * i) < 2.5);
            lowest = fmin(lowest, x[3 * i + 1]);
        }
        assert_true(lowest < -0.3);
        cs_sim_destroy(sim);
        cs_trimesh_destroy(mesh);
    }
}

/* A hanging cloth like the one above (8 x 8, pinned at two corners). */
static cs_sim *hanging_cloth(cs_trimesh **mesh, double dt, double stiffness, char *err,
                             size_t errlen, int *status)
{
    double size[2] = {1, 1}, q[4] = {1, 0, 0, 0}, c[3] = {0, 0, 0};
    int res[2] = {8, 8};
    static int corners[2] = {0, 8};
    static cs_vertex_script pin;
    pin = (cs_vertex_script){2, corners, cs_motion_static(), 0};
    *mesh = cs_trimesh_create_grid(size, res, q, c);
    static cs_cloth_def cloth;
    cloth = (cs_cloth_def){.name = "c", .mesh = *mesh, .material = cs_default_cloth_material(),
                           .nscripts = 1, .scripts = &pin};
    if (stiffness > 0)
        cloth.material.edge_stiffness = stiffness;
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = &cloth;
    def.fps = 60;
    def.dt = dt;
    cs_sim *sim = NULL;
    *status = cs_sim_create_checked(&def, &sim, err, errlen);
    return sim;
}

/* Steps the scene cannot take are refused at creation with the reason, not
 * run: a step so small that a frame needs more than CS_MAX_STEPS_PER_FRAME
 * of them (it used to overflow an int and become one step per frame), and a
 * stiffness that makes the stability limit that small. A fixed step above
 * the undamped limit is allowed (damping keeps it stable, see below). */
static void test_impossible_steps_are_refused(void **state)
{
    (void)state;
    cs_trimesh *mesh;
    char err[512];
    int status;
    cs_sim *sim = hanging_cloth(&mesh, 0, 0, err, sizeof err, &status);
    assert_int_equal(status, CS_OK);
    double limit = cs_sim_stable_dt(sim);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);

    sim = hanging_cloth(&mesh, 1.01 * limit, 0, err, sizeof err, &status);
    assert_int_equal(status, CS_OK);
    assert_true(cs_sim_dt(sim) == 1.01 * limit || cs_sim_dt(sim) < 1.01 * limit);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);

    sim = hanging_cloth(&mesh, 1e-12, 0, err, sizeof err, &status);
    assert_null(sim);
    assert_int_equal(status, CS_ERR_INVALID);
    assert_non_null(strstr(err, "time.dt is too small"));
    cs_trimesh_destroy(mesh);

    sim = hanging_cloth(&mesh, 0, 1e308, err, sizeof err, &status);
    assert_null(sim);
    assert_int_equal(status, CS_ERR_INVALID);
    assert_non_null(strstr(err, "stiffness and mass"));
    cs_trimesh_destroy(mesh);
}

/* The runaway bound follows what drives the cloth: cloth keeps the speed a
 * script gave it after the script stops, and a script step C held back
 * catches up at twice its speed. A twist whose ends stop at their last key
 * (tests/data/scenes/twist_jam.yaml) whipped at 16.8 m/s a step later and
 * was called unstable: the bound had dropped from 10 times the ends' speed
 * to the wave term alone. */
static void test_runaway_bound_keeps_what_scripts_gave(void **state)
{
    (void)state;
    double size[2] = {1, 1}, q[4] = {1, 0, 0, 0}, c[3] = {0, 0, 0};
    int res[2] = {4, 4};
    int corners[2] = {0, 4};
    /* the pinned corners move 1 m along x in 0.5 s (2 m/s), then stop */
    cs_keyframe keys[2] = {{0, {0, 0, 0}, {1, 0, 0, 0}}, {0.5, {1, 0, 0}, {1, 0, 0, 0}}};
    cs_motion motion = cs_motion_static();
    motion.kind = CS_MOTION_KEYFRAMES;
    motion.nkeys = 2;
    motion.keys = keys;
    cs_vertex_script pin = {2, corners, motion, 0};
    cs_trimesh *mesh = cs_trimesh_create_grid(size, res, q, c);
    cs_cloth_def cloth = {.name = "c", .mesh = mesh, .material = cs_default_cloth_material(),
                          .nscripts = 1, .scripts = &pin};
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = &cloth;
    def.gravity[0] = def.gravity[1] = def.gravity[2] = 0;
    char err[512];
    cs_sim *sim = NULL;
    assert_int_equal(cs_sim_create_checked(&def, &sim, err, sizeof err), CS_OK);
    /* at t = 0 the script has not moved yet (a motion is still before its
     * first key): the terms without it */
    double still = cs_runaway_limit(sim, 0);
    assert_true(still > 0);
    /* the script's speed is 2 m/s plus nothing turning: 10 x 2 while it
     * moves, and still after its last key */
    assert_true(fabs(cs_runaway_limit(sim, 0.25) - (still + 20)) < 1e-9);
    assert_true(fabs(cs_runaway_limit(sim, 2.0) - (still + 20)) < 1e-9);
    /* held 0.3 s behind: at t = 0.6 its clock reads 0.3, inside the keys,
     * and it catches up at 4 m/s */
    sim->script_lag[0] = 0.3;
    assert_true(fabs(cs_runaway_limit(sim, 0.6) - (still + 40)) < 1e-9);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* Far past the stability limit the explicit elastic forces grow
 * geometrically: 91 times the undamped limit (the one step per frame that
 * time.dt: 1e-12 used to become) must be caught early (the issue saw the
 * drape reach 1.4e6 m/s and exit "ok"), named with the stage that saw it;
 * the same cloth at the automatic step runs 60 frames without a false
 * alarm. (Up to 40 times the limit this damped cloth stays stable.) */
static void test_runaway_is_detected_with_its_stage(void **state)
{
    (void)state;
    cs_trimesh *mesh;
    char err[512];
    int status;
    cs_sim *sim = hanging_cloth(&mesh, 0, 0, err, sizeof err, &status);
    assert_int_equal(status, CS_OK);
    double dt = 91 * cs_sim_undamped_dt(sim);
    int steps = 0, rc = CS_OK;
    while (rc == CS_OK && steps < 200) {
        rc = cs_sim_step(sim, dt);
        steps++;
    }
    assert_int_equal(rc, CS_ERR_UNSTABLE);
    const char *stage = NULL;
    double speed = 0, limit = 0;
    assert_true(cs_sim_runaway(sim, &stage, &speed, &limit));
    assert_true(strcmp(stage, "velocity_half") == 0 || strcmp(stage, "velocity_full") == 0);
    assert_true(speed > limit);
    /* caught early: a limit of hundreds of m/s, not after the state is NaN */
    assert_true(isfinite(speed));
    assert_true(limit < 1000);
    assert_true(steps < 40);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);

    sim = hanging_cloth(&mesh, 0, 0, err, sizeof err, &status);
    cs_frame_stats st;
    for (int f = 0; f < 60; f++) {
        if (cs_sim_advance_frame(sim, &st) != CS_OK) {
            cs_sim_runaway(sim, &stage, &speed, &limit);
            fail_msg("frame %d: %s %g > %g", f, stage, speed, limit);
        }
    }
    assert_false(cs_sim_runaway(sim, NULL, NULL, NULL));
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}


/* Linear normal drag (Section 8): a horizontal sheet of areal density rho
 * falling in still air feels -c A (v.n) n per vertex and m = rho A, so every
 * vertex follows v(t) = v_t (1 - exp(-c t / rho)), v_t = rho g / c, exactly. */
static void test_wind_drag_terminal_velocity(void **state)
{
    (void)state;
    double size[2] = {1, 1}, q[4] = {1, 0, 0, 0}, c[3] = {0, 0, 0};
    int res[2] = {6, 6};
    cs_trimesh *mesh = cs_trimesh_create_grid(size, res, q, c);
    cs_cloth_def cloth = {.name = "sheet", .mesh = mesh, .material = cs_default_cloth_material()};
    cloth.material.density = 0.1;
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = &cloth;
    def.fps = 100;
    def.wind_enabled = true;
    def.wind.drag = 1.0;
    def.cg_tolerance = 1e-10;
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    double rho = 0.1, cd = 1.0, vt = rho * 9.8 / cd;
    for (int f = 1; f <= 50; f++) {
        assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
        double t = cs_sim_time(sim), exact = -vt * (1 - exp(-cd * t / rho));
        for (int i = 0; i < cs_sim_particle_count(sim); i++) {
            const double *v = cs_sim_velocities(sim) + 3 * i;
            assert_true(fabs(v[1] - exact) < 1e-4 * vt);
            assert_true(fabs(v[0]) < 1e-9 && fabs(v[2]) < 1e-9);
        }
    }
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* Friction from a moving body: a particle at rest on a plane sliding along
 * x at 1 m/s is dragged at mu g until it moves with the plane, then rides
 * along (static friction). */
static void test_moving_body_drags_particle(void **state)
{
    (void)state;
    cs_trimesh *mesh = cs_trimesh_create(1, 0);
    cs_cloth_def cloth = {.name = "p", .mesh = mesh, .material = cs_default_cloth_material()};
    cs_body_def belt = cs_default_body_def();
    belt.friction = 0.5;
    belt.motion.kind = CS_MOTION_CONSTANT;
    belt.motion.velocity[0] = 1.0;
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = &cloth;
    def.nbodies = 1;
    def.bodies = &belt;
    def.fps = 100;
    def.dt = 1e-3;
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    double a = 0.5 * 9.8, t_match = 1.0 / a;
    for (int f = 1; f <= 50; f++) {
        assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
        double t = cs_sim_time(sim);
        double x = t < t_match ? 0.5 * a * t * t : 0.5 * a * t_match * t_match + (t - t_match);
        double v = t < t_match ? a * t : 1.0;
        const double *px = cs_sim_positions(sim), *pv = cs_sim_velocities(sim);
        assert_true(fabs(px[0] - x) < 1e-3 * 1e-1 + 1e-6);
        assert_true(fabs(pv[0] - v) < 1e-9 + (fabs(t - t_match) < 2e-3 ? a * 1e-3 : 0));
        assert_true(fabs(px[1]) < 1e-12); /* stays on the belt */
    }
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* Keyframed vertices land exactly on their path; free ones follow. */
static void test_scripted_vertices_follow_keys(void **state)
{
    (void)state;
    double size[2] = {1, 1}, q[4] = {1, 0, 0, 0}, c[3] = {0, 0, 0};
    int res[2] = {4, 4};
    cs_trimesh *mesh = cs_trimesh_create_grid(size, res, q, c);
    int moved[2] = {0, 4};
    cs_keyframe keys[2] = {{0, {0, 0, -0.5}, {1, 0, 0, 0}}, {1, {0, 2, -0.5}, {1, 0, 0, 0}}};
    cs_vertex_script script = {2, moved, cs_motion_static(), 0};
    script.motion.kind = CS_MOTION_KEYFRAMES;
    script.motion.position[2] = -0.5;
    script.motion.nkeys = 2;
    script.motion.keys = keys;
    cs_cloth_def cloth = {.name = "c", .mesh = mesh, .material = cs_default_cloth_material(),
                          .nscripts = 1, .scripts = &script};
    cloth.material.density = 0.1;
    cs_sim_def def = cs_default_sim_def();
    def.ncloths = 1;
    def.cloths = &cloth;
    def.fps = 10;
    cs_sim *sim = cs_sim_create(&def, NULL, 0);
    assert_non_null(sim);
    for (int f = 1; f <= 10; f++) {
        assert_int_equal(cs_sim_advance_frame(sim, NULL), CS_OK);
        double t = cs_sim_time(sim);
        for (int k = 0; k < 2; k++) {
            const double *x = cs_sim_positions(sim) + 3 * moved[k];
            const double *v = cs_sim_velocities(sim) + 3 * moved[k];
            assert_true(fabs(x[1] - 2 * t) < 1e-12);
            assert_true(fabs(x[0] - mesh->x[3 * moved[k]]) < 1e-12);
            assert_true(fabs(v[1] - 2) < 1e-12);
        }
    }
    /* the cloth was lifted with its pinned edge, and hangs below it */
    const double *x = cs_sim_positions(sim);
    double centre_y = x[3 * 12 + 1];
    assert_true(centre_y > 0.8 && centre_y < 2.0);
    cs_sim_destroy(sim);
    cs_trimesh_destroy(mesh);
}

/* Several cloths in one simulation behave as each would alone: particle
 * indices, springs and masses of the second cloth are offset correctly. */
static void test_two_cloths_match_each_alone(void **state)
{
    (void)state;
    double size_a[2] = {1, 1}, size_b[2] = {0.7, 1.3}, q[4] = {1, 0, 0, 0};
    double ca[3] = {0, 0, 0}, cb[3] = {3, 1, 0};
    int ra[2] = {5, 4}, rb[2] = {3, 6};
    cs_trimesh *ma = cs_trimesh_create_grid(size_a, ra, q, ca);
    cs_trimesh *mb = cs_trimesh_create_grid(size_b, rb, q, cb);
    int pin_a = 0, pin_b = 2;
    cs_vertex_script sa = {1, &pin_a, cs_motion_static(), 0}, sb = {1, &pin_b, cs_motion_static(), 0};
    cs_cloth_def cloths[2] = {
        {.name = "a", .mesh = ma, .material = cs_default_cloth_material(), .nscripts = 1, .scripts = &sa},
        {.name = "b", .mesh = mb, .material = cs_default_cloth_material(), .nscripts = 1, .scripts = &sb},
    };
    cloths[0].material.density = 0.1;
    cloths[1].material.density = 0.2;
    cloths[1].material.edge_stiffness = 20;
    cs_sim_def def = cs_default_sim_def();
    def.cloths = cloths;
    def.cg_tolerance = 1e-13;
    def.fps = 30;
    def.dt = 1e-4;
    def.ncloths = 2;
    cs_sim *both = cs_sim_create(&def, NULL, 0);
    def.ncloths = 1;
    cs_sim *alone_a = cs_sim_create(&def, NULL, 0);
    def.cloths = cloths + 1;
    cs_sim *alone_b = cs_sim_create(&def, NULL, 0);
    assert_non_null(both);
    assert_non_null(alone_a);
    assert_non_null(alone_b);
    assert_int_equal(cs_sim_cloth_offset(both, 1), ma->nv);
    for (int f = 0; f < 6; f++) {
        assert_int_equal(cs_sim_advance_frame(both, NULL), CS_OK);
        assert_int_equal(cs_sim_advance_frame(alone_a, NULL), CS_OK);
        assert_int_equal(cs_sim_advance_frame(alone_b, NULL), CS_OK);
    }
    const double *x = cs_sim_positions(both);
    double moved = 0;
    for (int k = 0; k < 3 * ma->nv; k++)
        assert_true(fabs(x[k] - cs_sim_positions(alone_a)[k]) < 1e-9);
    for (int k = 0; k < 3 * mb->nv; k++) {
        assert_true(fabs(x[3 * ma->nv + k] - cs_sim_positions(alone_b)[k]) < 1e-9);
        moved = fmax(moved, fabs(x[3 * ma->nv + k] - mb->x[k]));
    }
    assert_true(moved > 0.05);
    cs_sim_destroy(both);
    cs_sim_destroy(alone_a);
    cs_sim_destroy(alone_b);
    cs_trimesh_destroy(ma);
    cs_trimesh_destroy(mb);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_spring_force_is_minus_energy_gradient),
        cmocka_unit_test(test_damping_jacobian_matches_finite_differences),
        cmocka_unit_test(test_cg_matches_dense_solve),
        cmocka_unit_test(test_analytic_bodies),
        cmocka_unit_test(test_gamma_regimes),
        cmocka_unit_test(test_keyframe_motion),
        cmocka_unit_test(test_plan_omits_absent_stages),
        cmocka_unit_test(test_automatic_dt_is_stable_across_resolutions),
        cmocka_unit_test(test_impossible_steps_are_refused),
        cmocka_unit_test(test_runaway_is_detected_with_its_stage),
        cmocka_unit_test(test_runaway_bound_keeps_what_scripts_gave),
        cmocka_unit_test(test_wind_drag_terminal_velocity),
        cmocka_unit_test(test_moving_body_drags_particle),
        cmocka_unit_test(test_scripted_vertices_follow_keys),
        cmocka_unit_test(test_two_cloths_match_each_alone),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
