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
        for (int i = 0; i < sim->n; i++) {
            const double *nrm = sim->wind_normal + 3 * i;
            cs_axpy(-c * sim->wind_area[i] * cs_dot(nrm, v + 3 * i), nrm, out + 3 * i);
        }
    }
}

void cs_system_apply(const cs_sim *sim, const double *v, double *out)
{
    int n3 = 3 * sim->n;
    memset(out, 0, sizeof *out * (size_t)n3);
    cs_damping_apply(sim, v, out);
    for (int i = 0; i < sim->n; i++)
        for (int d = 0; d < 3; d++)
            out[3 * i + d] = sim->mass[i] * v[3 * i + d] - sim->h * out[3 * i + d];
}

static void project(const cs_sim *sim, double *a)
{
    for (int i = 0; i < sim->n; i++) {
        double *ai = a + 3 * i;
        if (sim->mode[i] == CS_FIXED) {
            ai[0] = ai[1] = ai[2] = 0;
        } else if (sim->mode[i] == CS_CONTACT) {
            const double *N = sim->contact_normal + 3 * i;
            cs_axpy(-cs_dot(ai, N), N, ai);
        }
    }
}

static double dot_all(const double *a, const double *b, int n3)
{
    double s = 0;
    for (int k = 0; k < n3; k++)
        s += a[k] * b[k];
    return s;
}

/* max over particles of |r_i| / m_i: the residual in velocity units */
static double velocity_residual(const cs_sim *sim, const double *r)
{
    double worst = 0;
    for (int i = 0; i < sim->n; i++) {
        double s = cs_norm(r + 3 * i) / sim->mass[i];
        if (s > worst)
            worst = s;
    }
    return worst;
}

int cs_cg_solve(cs_sim *sim, const double *v0, const double *rhs, double *v)
{
    int n3 = 3 * sim->n;
    cs_cg_work *w = &sim->cg;

    /* Jacobi preconditioner: diagonal of M - h D */
    memset(w->diag, 0, sizeof *w->diag * (size_t)n3);
    cs_springs_add_damping_diagonal(&sim->springs, w->diag);
    for (int i = 0; i < sim->n; i++)
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
    cs_system_apply(sim, v0, w->q);
    for (int k = 0; k < n3; k++)
        w->r[k] = rhs[k] - w->q[k];
    project(sim, w->r);
    for (int i = 0; i < sim->n; i++)
        for (int d = 0; d < 3; d++)
            w->z[3 * i + d] = w->r[3 * i + d] / sim->mass[i];
    for (int k = 0; k < n3; k++)
        w->y[k] = v0[k] + w->z[k];
    cs_system_apply(sim, w->y, w->q);
    for (int k = 0; k < n3; k++)
        w->r[k] = rhs[k] - w->q[k];
    project(sim, w->r);
    for (int k = 0; k < n3; k++)
        w->y[k] = w->r[k] / w->diag[k];
    project(sim, w->y);
    memcpy(w->p, w->y, sizeof *w->p * (size_t)n3);
    double rho = dot_all(w->r, w->y, n3);

    int it = 0;
    while (it < sim->def.cg_max_iterations &&
           velocity_residual(sim, w->r) > sim->def.cg_tolerance) {
        cs_system_apply(sim, w->p, w->q);
        project(sim, w->q);
        double pq = dot_all(w->p, w->q, n3);
        if (!(pq > 0))
            break; /* not positive definite along p: nothing more to gain */
        double alpha = rho / pq;
        for (int k = 0; k < n3; k++) {
            w->z[k] += alpha * w->p[k];
            w->r[k] -= alpha * w->q[k];
        }
        for (int k = 0; k < n3; k++)
            w->y[k] = w->r[k] / w->diag[k];
        project(sim, w->y);
        double rho_next = dot_all(w->r, w->y, n3);
        double beta = rho_next / rho;
        rho = rho_next;
        for (int k = 0; k < n3; k++)
            w->p[k] = w->y[k] + beta * w->p[k];
        it++;
    }
    for (int k = 0; k < n3; k++)
        v[k] = v0[k] + w->z[k];
    return it;
}
