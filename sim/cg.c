/* cg.c: matrix-free preconditioned conjugate gradient for the implicit
 * damping solves (steps B.1 and B.5), with the contact projection P of
 * Section 6 applied as a filter (the modified PCG of Baraff and Witkin).
 *
 * Threads (OpenMP) share the owned particles in fixed blocks of
 * CS_BLOCK; each loop does all of a particle's work in one pass, and an
 * inner product is summed block by block in block order, so the result is
 * the same bits at every thread count. */
#include <math.h>
#include <string.h>

#include "sim/internal.h"
#include "sim/shares.h"
#include "sim/vec3.h"

static int block_count(const cs_par *par) { return (par->nowned + CS_BLOCK - 1) / CS_BLOCK; }

/* out_i = ((M - (dt/2) D) v)_i for row r (particle i) */
static inline void system_row(const cs_sim *sim, int r, int i, const double *v, double out[3])
{
    double acc[3] = {0, 0, 0};
    cs_damping_row(sim, r, i, v, acc);
    for (int d = 0; d < 3; d++)
        out[d] = sim->mass[i] * v[3 * i + d] - sim->half_dt * acc[d];
}

/* Row r's damping force (D v) added into acc, as cs_springs_damping_row,
 * and in the same walk over its springs B = the 6 distinct entries (xx yy
 * zz xy xz yz) of its diagonal block of D, negated: sum of w w^T */
static inline void damping_row_and_block(const cs_springs *s, int r, const double *v,
                                         double acc[3], double B[6])
{
    const double *vi = v + 3 * s->row_particle[r];
    cs_pair2 ax = {0, 0}, ay = {0, 0}, az = {0, 0};
    cs_pair2 b0 = {0, 0}, b1 = {0, 0}, b2 = {0, 0}, b3 = {0, 0}, b4 = {0, 0}, b5 = {0, 0};
    for (int e = s->row_start[r]; e < s->row_start[r + 1]; e += 2) {
        cs_pair2 w[3], mag = cs_springs_pair_damping(s, e, v, vi, w);
        ax += mag * w[0];
        ay += mag * w[1];
        az += mag * w[2];
        b0 += w[0] * w[0];
        b1 += w[1] * w[1];
        b2 += w[2] * w[2];
        b3 += w[0] * w[1];
        b4 += w[0] * w[2];
        b5 += w[1] * w[2];
    }
    acc[0] += ax[0] + ax[1];
    acc[1] += ay[0] + ay[1];
    acc[2] += az[0] + az[1];
    B[0] = b0[0] + b0[1], B[1] = b1[0] + b1[1], B[2] = b2[0] + b2[1];
    B[3] = b3[0] + b3[1], B[4] = b4[0] + b4[1], B[5] = b5[0] + b5[1];
}

/* B += the wind drag's block c n n^T */
static inline void wind_block(const cs_sim *sim, int i, double B[6])
{
    const double *nd = sim->wind_normal + 3 * i;
    double c = sim->def.wind.drag * sim->wind_area[i];
    B[0] += c * nd[0] * nd[0];
    B[1] += c * nd[1] * nd[1];
    B[2] += c * nd[2] * nd[2];
    B[3] += c * nd[0] * nd[1];
    B[4] += c * nd[0] * nd[2];
    B[5] += c * nd[1] * nd[2];
}

/* out = a symmetric 3 x 3 block stored as xx yy zz xy xz yz, times r */
static inline void sym_block_apply(const double a[6], const double r[3], double out[3])
{
    out[0] = a[0] * r[0] + a[3] * r[1] + a[4] * r[2];
    out[1] = a[3] * r[0] + a[1] * r[1] + a[5] * r[2];
    out[2] = a[4] * r[0] + a[5] * r[1] + a[2] * r[2];
}

/* The particle's block m I + (dt/2) B of M - (dt/2) D (xx yy zz xy xz
 * yz); the damping acts along spring directions, which a diagonal alone
 * misses. A particle in contact moves only in its tangent plane, and CG
 * solves the system filtered by P (Section 6), whose block there is
 * S A S with S = I - N N^T: that block, with m N N^T added so that it can
 * be inverted (it maps the tangent plane to itself, so the added normal
 * part never reaches a projected residual). Preconditioning with the
 * unfiltered block's inverse, projected after, mixed the normal row into
 * the tangent answer, and the contact solves took markedly more
 * iterations. */
static inline void system_block(const cs_sim *sim, int i, const double B[6], double a[6])
{
    double m = sim->mass[i], hd = sim->half_dt;
    for (int k = 0; k < 6; k++)
        a[k] = hd * B[k] + (k < 3 ? m : 0);
    if (sim->mode[i] != CS_CONTACT)
        return;
    const double *N = sim->contact_normal + 3 * i;
    double u[3];
    sym_block_apply(a, N, u);
    double c = cs_dot(N, u) + m; /* N . a N, plus the m N N^T part */
    static const int row[6] = {0, 1, 2, 0, 0, 1}, col[6] = {0, 1, 2, 1, 2, 2};
    for (int k = 0; k < 6; k++) /* a - N u^T - u N^T + c N N^T, u = a N */
        a[k] += -N[row[k]] * u[col[k]] - u[row[k]] * N[col[k]] + c * N[row[k]] * N[col[k]];
}

/* inv = the inverse of a symmetric positive definite 3 x 3 block (xx yy
 * zz xy xz yz), by cofactors and one division */
static inline void invert_block(const double a6[6], double inv[6])
{
    double a = a6[0], b = a6[1], cz = a6[2], xy = a6[3], xz = a6[4], yz = a6[5];
    double c00 = b * cz - yz * yz, c01 = xz * yz - xy * cz, c02 = xy * yz - xz * b;
    double inv_det = 1.0 / (a * c00 + xy * c01 + xz * c02);
    inv[0] = c00 * inv_det;
    inv[1] = (a * cz - xz * xz) * inv_det;
    inv[2] = (a * b - xy * xy) * inv_det;
    inv[3] = c01 * inv_det;
    inv[4] = c02 * inv_det;
    inv[5] = (xy * xz - a * yz) * inv_det;
}

/* P: fixed velocities and contact normals projected out */
static inline void project_row(const cs_sim *sim, int i, double a[3])
{
    if (sim->mode[i] == CS_FIXED) {
        a[0] = a[1] = a[2] = 0;
    } else if (sim->mode[i] == CS_CONTACT) {
        const double *N = sim->contact_normal + 3 * i;
        cs_axpy(-cs_dot(a, N), N, a);
    }
}

/* y_i = P B_i^-1 r_i, adding r_i . y_i to *sum and raising *worst to the
 * squared residual in velocity units |r_i|^2 / m_i^2 (squared: no square
 * root or division per particle; the caller takes one root of the max) */
static inline void precondition_row(const cs_sim *sim, int i, const double *ri, double *yi,
                                    double *sum, double *worst)
{
    sym_block_apply(sim->cg.block + 6 * i, ri, yi); /* B_i^-1 r_i */
    project_row(sim, i, yi);
    for (int d = 0; d < 3; d++)
        *sum += ri[d] * yi[d];
    double inv_m = sim->cg.inv_mass[i];
    double res = cs_dot(ri, ri) * (inv_m * inv_m);
    if (res > *worst)
        *worst = res;
}

/* Owned entries of out; v must be current on the ghosts too. */
void cs_system_apply(const cs_sim *sim, const double *v, double *out)
{
    const int *own = cs_par_owned(sim->par);
#pragma omp parallel for schedule(static)
    for (int r = 0; r < sim->par->nowned; r++)
        system_row(sim, r, own[r], v, out + 3 * own[r]);
}

/* The solve runs in one parallel region: its passes are worksharing loops
 * whose ends are barriers, and every thread sums the block partials
 * itself, in block order, so all hold the same scalars and take the same
 * branches. A region per pass would cost a fork and a join each, several
 * times a barrier's cost, dozens of times a step. Messages (more than one rank) go through one thread, the
 * others waiting at the end of its single block. */

/* Sums block partials in block order and over ranks (with the maximum of
 * the block maxima when max is given); called by every thread. */
static double reduce(cs_sim *sim, const double *sum, const double *max, double *max_out)
{
    int nb = block_count(sim->par);
    double s = 0, m = 0;
    for (int b = 0; b < nb; b++) {
        s += sum[b];
        if (max && max[b] > m)
            m = max[b];
    }
    if (cs_par_distributed(sim->par)) {
#pragma omp single copyprivate(s, m)
        {
            if (max)
                cs_par_sum_max(sim->par, &s, &m);
            else
                cs_par_sum(sim->par, &s, 1);
        }
    }
    if (max)
        *max_out = sqrt(m); /* the blocks' maxima are squared residuals */
    return s;
}

/* The ghosts' values of a, from their owners; called by every thread
 * after a barrier */
static void forward_ghosts(cs_par *par, double *a)
{
    if (cs_par_distributed(par)) {
#pragma omp single
        cs_halo_forward(par, &par->ghosts, a, 3);
    }
}

/* The loops walk blocks of the owned list: rows [r0, r1) of block b, the
 * calling thread's share of the blocks (shares.h: shares follow the
 * threads' measured speeds). Each pass clocks its thread from t0 and
 * ends at a barrier of its own (END_PASS). */
#define FOR_MY_BLOCKS(sim, t0, b, r0, r1)                                            \
    for (int b = ((t0) = omp_get_wtime(),                                            \
                  cs_shares_bound(&(sim)->shares, block_count((sim)->par), 0)),       \
             b##_end = cs_shares_bound(&(sim)->shares, block_count((sim)->par), 1);   \
         b < b##_end; b++)                                                           \
        for (int r0 = b * CS_BLOCK, r1 = r0 + CS_BLOCK < (sim)->par->nowned          \
                                             ? r0 + CS_BLOCK : (sim)->par->nowned;   \
             r0 < r1; r0 = r1)
#define END_PASS(sim, t0)                                                            \
    do {                                                                             \
        cs_shares_clock(&(sim)->shares, t0);                                         \
        _Pragma("omp barrier")                                                       \
    } while (0)

/* The warm start's weight on the damping response of the solve before the
 * last (the last's is 1 minus it). Table 1's damping is 15 times critical,
 * and the trapezoidal step turns a mode damped that hard into one whose
 * velocity flips sign from step to step, so the response two steps back
 * predicts those modes and the last one the smooth rest. Of the weights
 * 0, 0.5, 0.75 and 1, 0.75 took the fewest CG iterations on the benchmark
 * sheet, at both step limits; on the twisting cloth the weight made no
 * difference. */
static const double WARM_BEFORE_WEIGHT = 0.75;

/* v0 is read and v written where owned (y, the start, is sent to the
 * ghosts). The stopping test is the residual in velocity units, max over
 * particles of |r_i| / m_i: a maximum is exact, so every rank and thread
 * count stops at the same iteration. */
int cs_cg_solve(cs_sim *sim, const double *v0, const double *rhs, double *v, const double *base,
                double *warm, double *warm_before, int check_stage)
{
    cs_par *par = sim->par;
    cs_cg_work *w = &sim->cg;
    const int *own = cs_par_owned(par);
    const cs_springs *s = &sim->springs;
    /* the setup's and update passes' block sums and maxima; the operator
     * pass's sums apart, so that a thread may begin it while another still
     * sums the update pass's */
    int nb = block_count(par), iterations = 0;
    double *part_sum = w->partial, *part_max = w->partial + nb, *op_sum = w->partial + 2 * nb;

    /* Start from the explicit update z = P M^-1 (rhs - M v0): gravity
     * and the elastic forces, exact when the damping does no work (rigid
     * motion). Starting from z = 0 would let a loose tolerance (Table 1's
     * 1e-3 m/s) swallow a step's whole acceleration when dt is small: the
     * solve must resolve only the damping response. With warm, add the
     * damping response of this solve's last two calls, blended (projected
     * by today's contacts): it changes little from one step to the next
     * but for the modes that flip (WARM_BEFORE_WEIGHT), so CG starts near
     * the answer (the stopping test is the same, only fewer iterations
     * reach it). With base (B.5 gets B.1's response of the same step),
     * the history is of this solve's excess over base, and base is added:
     * B.1's response already holds what changed since the last step.
     * Predicting B.5 from B.1's response saves CG iterations at every size
     * and both step limits against B.5's own history; B.1 predicted
     * likewise from B.5 gained nothing: the velocity is extrapolated
     * between them (B.6), which flips the hardest-damped modes. The explicit update leaves the damping out so
     * that it needs no pass over the springs: the one pass below takes the
     * residual and builds the block Jacobi preconditioner from the same
     * directions (two passes before; the warm start carries the damping). */
#pragma omp parallel
    {
        double t0; /* the start of this thread's part of a pass */
        FOR_MY_BLOCKS(sim, t0, b, r0, r1)
        for (int r = r0; r < r1; r++) {
            int i = own[r];
            double ri[3];
            for (int d = 0; d < 3; d++)
                ri[d] = rhs[3 * i + d] - sim->mass[i] * v0[3 * i + d];
            project_row(sim, i, ri);
            double guess[3] = {0, 0, 0};
            if (warm) {
                for (int d = 0; d < 3; d++)
                    guess[d] = (1.0 - WARM_BEFORE_WEIGHT) * warm[3 * i + d] +
                               WARM_BEFORE_WEIGHT * warm_before[3 * i + d] +
                               (base ? base[3 * i + d] : 0.0);
                project_row(sim, i, guess);
            }
            double inv_m = w->inv_mass[i];
            for (int d = 0; d < 3; d++) {
                w->explicit_z[3 * i + d] = ri[d] * inv_m;
                w->z[3 * i + d] = w->explicit_z[3 * i + d] + guess[d];
                w->y[3 * i + d] = v0[3 * i + d] + w->z[3 * i + d];
            }
        }
        END_PASS(sim, t0);
        forward_ghosts(par, w->y);
        /* r = P (rhs - A y), p = P B^-1 r, with B the diagonal blocks of A
         * (y is read across particles here, so the preconditioned residual
         * goes straight into p) */
        FOR_MY_BLOCKS(sim, t0, b, r0, r1) {
            double sum = 0, worst = 0;
            for (int r = r0; r < r1; r++) {
                int i = own[r];
                double acc[3] = {0, 0, 0}, B[6], *ri = w->r + 3 * i, *pi = w->p + 3 * i;
                damping_row_and_block(s, r, w->y, acc, B);
                if (sim->wind_normal) {
                    cs_wind_drag_row(sim, i, w->y, acc);
                    wind_block(sim, i, B);
                }
                double a[6];
                system_block(sim, i, B, a);
                invert_block(a, w->block + 6 * i);
                for (int d = 0; d < 3; d++)
                    ri[d] = rhs[3 * i + d] -
                            (sim->mass[i] * w->y[3 * i + d] - sim->half_dt * acc[d]);
                project_row(sim, i, ri);
                precondition_row(sim, i, ri, pi, &sum, &worst);
            }
            part_sum[b] = sum;
            part_max[b] = worst;
        }
        END_PASS(sim, t0);
        double residual = 0, rho = reduce(sim, part_sum, part_max, &residual);

        /* Two passes an iteration: the direction's update p = y + beta p is
         * folded into the next operator pass, which applies A to y instead
         * and takes P A p = P A y + beta q (A and P are fixed within the
         * solve), saving a third pass and its fork and join (the first iteration applies A to p, which the
         * setup pass made). */
        int it = 0;
        double beta = 0, pending = 0; /* pending: the last alpha, not yet in z */
        while (it < sim->def.cg_max_iterations && residual > sim->def.cg_tolerance) {
            double *operand = it == 0 ? w->p : w->y;
            forward_ghosts(par, operand);
            FOR_MY_BLOCKS(sim, t0, b, r0, r1) { /* z += alpha p, p = y + beta p, q = P A p, p . q */
                double sum = 0;
                for (int r = r0; r < r1; r++) {
                    int i = own[r];
                    double *qi = w->q + 3 * i, *pi = w->p + 3 * i, *zi = w->z + 3 * i, a[3];
                    system_row(sim, r, i, operand, a);
                    project_row(sim, i, a);
                    for (int d = 0; d < 3; d++) {
                        if (it > 0) {
                            zi[d] += pending * pi[d];
                            pi[d] = w->y[3 * i + d] + beta * pi[d];
                            qi[d] = a[d] + beta * qi[d];
                        } else {
                            qi[d] = a[d];
                        }
                        sum += pi[d] * qi[d];
                    }
                }
                op_sum[b] = sum;
            }
            END_PASS(sim, t0);
            pending = 0; /* the pass above took it into z */
            double pq = reduce(sim, op_sum, NULL, NULL);
            if (!(pq > 0))
                break; /* not positive definite along p: nothing more to gain */
            double alpha = rho / pq;
            /* z += alpha p waits for the next pass over p (the operator's, or
             * the last one below): this pass then reads neither p nor z, and z
             * gets the same sums in the same order */
            pending = alpha;
            FOR_MY_BLOCKS(sim, t0, b, r0, r1) {
                double sum = 0, worst = 0;
                for (int r = r0; r < r1; r++) {
                    int i = own[r];
                    double *yi = w->y + 3 * i, *ri = w->r + 3 * i;
                    for (int d = 0; d < 3; d++)
                        ri[d] -= alpha * w->q[3 * i + d];
                    precondition_row(sim, i, ri, yi, &sum, &worst);
                }
                part_sum[b] = sum;
                part_max[b] = worst;
            }
            END_PASS(sim, t0);
            double rho_next = reduce(sim, part_sum, part_max, &residual);
            beta = rho_next / rho;
            rho = rho_next;
            it++;
        }
        FOR_MY_BLOCKS(sim, t0, b, r0, r1) {
            double worst = 0;
            int nan_seen = 0;
            for (int r = r0; r < r1; r++) {
                int i = own[r];
                for (int d = 0; d < 3; d++) {
                    int k = 3 * i + d;
                    /* only a pending step is added: z + 0 p would turn a -0
                     * into +0 (or a non-finite p into NaN) and change the bits */
                    double z = pending != 0 ? w->z[k] + pending * w->p[k] : w->z[k];
                    v[k] = v0[k] + z;
                    if (warm) {
                        warm_before[k] = warm[k];
                        warm[k] = z - w->explicit_z[k] - (base ? base[k] : 0.0);
                    }
                }
                if (check_stage >= 0 && sim->is_free[i])
                    cs_speed_seen(v + 3 * i, &worst, &nan_seen);
            }
            /* op_sum is free: every thread read it before the last update
             * pass's barrier (-1: a NaN seen) */
            op_sum[b] = nan_seen ? -1 : worst;
        }
        cs_shares_clock(&sim->shares, t0); /* the region's end is the barrier */
#pragma omp master
        iterations = it;
    }
    cs_shares_update(&sim->shares);
    if (check_stage >= 0) {
        double worst = 0;
        int nan_seen = 0;
        for (int b = 0; b < nb; b++)
            if (op_sum[b] < 0)
                nan_seen = 1;
            else
                worst = fmax(worst, op_sum[b]);
        cs_runaway_note(sim, (cs_stage)check_stage, worst, nan_seen);
    }
    return iterations;
}
