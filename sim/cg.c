/* cg.c: matrix-free preconditioned conjugate gradient for the implicit
 * damping solves (steps B.1 and B.5), with the contact projection P of
 * Section 6 applied as a filter (the modified PCG of Baraff and Witkin). */
#include <math.h>
#include <string.h>

#include "sim/internal.h"
#include "sim/vec3.h"

void cs_damping_apply(const cs_sim *sim, const double *v, double *out)
{
    cs_springs_add_damping(&sim->springs, v, out);
    if (sim->wind_normal) { /* implicit part of the linear normal drag */
        double c = sim->def.wind.drag;
        CS_FOR_OWNED(sim->par, i) {
            const double *nrm = sim->wind_normal + 3 * i;
            cs_axpy(-c * sim->wind_area[i] * cs_dot(nrm, v + 3 * i), nrm, out + 3 * i);
        }
    }
}

/* Owned entries of out; v must be current on the ghosts too. */
void cs_system_apply(const cs_sim *sim, const double *v, double *out)
{
    CS_FOR_LOCAL(sim->par, i)
        out[3 * i] = out[3 * i + 1] = out[3 * i + 2] = 0;
    cs_damping_apply(sim, v, out);
    CS_FOR_OWNED(sim->par, i)
        for (int d = 0; d < 3; d++)
            out[3 * i + d] = sim->mass[i] * v[3 * i + d] - sim->h * out[3 * i + d];
}

static void project(const cs_sim *sim, double *a)
{
    CS_FOR_OWNED(sim->par, i) {
        double *ai = a + 3 * i;
        if (sim->mode[i] == CS_FIXED) {
            ai[0] = ai[1] = ai[2] = 0;
        } else if (sim->mode[i] == CS_CONTACT) {
            const double *N = sim->contact_normal + 3 * i;
            cs_axpy(-cs_dot(ai, N), N, ai);
        }
    }
}

/* The owned part of an inner product (summed over ranks by the caller). */
static double dot_owned(const cs_sim *sim, const double *a, const double *b)
{
    double s = 0;
    CS_FOR_OWNED(sim->par, i)
        for (int d = 0; d < 3; d++)
            s += a[3 * i + d] * b[3 * i + d];
    return s;
}

/* r . y and the residual in velocity units, max over particles of
 * |r_i| / m_i, over all ranks in one reduction (a maximum is exact, so
 * every rank count stops at the same iteration). */
static double dot_and_residual(const cs_sim *sim, const double *r, const double *y,
                               double *residual)
{
    double rho = dot_owned(sim, r, y), worst = 0;
    CS_FOR_OWNED(sim->par, i) {
        double s = cs_norm(r + 3 * i) / sim->mass[i];
        if (s > worst)
            worst = s;
    }
    cs_par_sum_max(sim->par, &rho, &worst);
    *residual = worst;
    return rho;
}

/* v0 is read on the ghosts (after a refresh here); v is written where
 * owned. */
int cs_cg_solve(cs_sim *sim, double *v0, const double *rhs, double *v)
{
    cs_par *par = sim->par;
    cs_cg_work *w = &sim->cg;

    /* Jacobi preconditioner: diagonal of M - h D */
    CS_FOR_LOCAL(par, i)
        w->diag[3 * i] = w->diag[3 * i + 1] = w->diag[3 * i + 2] = 0;
    cs_springs_add_damping_diagonal(&sim->springs, w->diag);
    CS_FOR_OWNED(par, i)
        for (int d = 0; d < 3; d++) {
            double wind = 0;
            if (sim->wind_normal) {
                double nd = sim->wind_normal[3 * i + d];
                wind = sim->def.wind.drag * sim->wind_area[i] * nd * nd;
            }
            w->diag[3 * i + d] = sim->mass[i] + sim->h * (w->diag[3 * i + d] + wind);
        }

    /* Start from the explicit update z = P M^-1 r0, exact when the damping
     * does no work (rigid motion). Starting from z = 0 would let a loose
     * tolerance (Table 1's 1e-3 m/s) swallow a step's whole acceleration
     * when dt is small: the solve must resolve only the damping response. */
    cs_halo_forward(par, &par->ghosts, v0, 3);
    cs_system_apply(sim, v0, w->q);
    CS_FOR_OWNED(par, i)
        for (int d = 0; d < 3; d++) {
            int k = 3 * i + d;
            w->r[k] = rhs[k] - w->q[k];
        }
    project(sim, w->r);
    CS_FOR_OWNED(par, i)
        for (int d = 0; d < 3; d++) {
            int k = 3 * i + d;
            w->z[k] = w->r[k] / sim->mass[i];
            w->y[k] = v0[k] + w->z[k];
        }
    cs_halo_forward(par, &par->ghosts, w->y, 3);
    cs_system_apply(sim, w->y, w->q);
    CS_FOR_OWNED(par, i)
        for (int d = 0; d < 3; d++) {
            int k = 3 * i + d;
            w->r[k] = rhs[k] - w->q[k];
        }
    project(sim, w->r);
    CS_FOR_OWNED(par, i)
        for (int d = 0; d < 3; d++) {
            int k = 3 * i + d;
            w->y[k] = w->r[k] / w->diag[k];
        }
    project(sim, w->y);
    CS_FOR_OWNED(par, i)
        memcpy(w->p + 3 * i, w->y + 3 * i, 3 * sizeof(double));
    double residual, rho = dot_and_residual(sim, w->r, w->y, &residual);

    int it = 0;
    while (it < sim->def.cg_max_iterations && residual > sim->def.cg_tolerance) {
        cs_halo_forward(par, &par->ghosts, w->p, 3);
        cs_system_apply(sim, w->p, w->q);
        project(sim, w->q);
        double pq = dot_owned(sim, w->p, w->q);
        cs_par_sum(par, &pq, 1);
        if (!(pq > 0))
            break; /* not positive definite along p: nothing more to gain */
        double alpha = rho / pq;
        CS_FOR_OWNED(par, i)
            for (int d = 0; d < 3; d++) {
                int k = 3 * i + d;
                w->z[k] += alpha * w->p[k];
                w->r[k] -= alpha * w->q[k];
                w->y[k] = w->r[k] / w->diag[k];
            }
        project(sim, w->y);
        double rho_next = dot_and_residual(sim, w->r, w->y, &residual);
        double beta = rho_next / rho;
        rho = rho_next;
        CS_FOR_OWNED(par, i)
            for (int d = 0; d < 3; d++) {
                int k = 3 * i + d;
                w->p[k] = w->y[k] + beta * w->p[k];
            }
        it++;
    }
    CS_FOR_OWNED(par, i)
        for (int d = 0; d < 3; d++)
            v[3 * i + d] = v0[3 * i + d] + w->z[3 * i + d];
    return it;
}
