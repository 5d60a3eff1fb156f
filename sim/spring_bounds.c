/* spring_bounds.c: bounds on the springs' stiffness for the step limits
 * (step_limit.c): Gershgorin row sums at rest and at the current tension,
 * and the largest eigenvalue of M^-1 K by Lanczos. */
#include <math.h>
#include <omp.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "sim/springs.h"
#include "sim/vec3.h"

/* Gershgorin's theorem on the free particles' rows: a spring's term (the
 * norm of its 3 x 3 block) counts on row i's diagonal and, when its far end
 * is free too, once more off it; a pinned or scripted end is no unknown, so
 * it has no off-diagonal entry (beside a scripted edge, where a twist's
 * tension peaks, that halves the share of the springs that reach it).
 * The term is k = E / L0 (damped false) or the damped scheme's at dt and
 * rest (cs_spring_step_term). -1 when memory runs out. */
static double rest_row_bound(const cs_springs *s, const double *mass,
                             const unsigned char *is_free, int nparticles, bool damped,
                             double dt)
{
    double *sum = calloc((size_t)nparticles + 1, sizeof *sum);
    if (!sum)
        return -1;
    for (int k = 0; k < s->n; k++) {
        double kk = s->stiffness[k] * s->inv_rest_length[k];
        double term = damped ? cs_spring_step_term(dt, kk, s->damping[k], 0) : kk;
        int i = s->ends[2 * k], j = s->ends[2 * k + 1];
        sum[i] += term * (1 + is_free[j]);
        sum[j] += term * (1 + is_free[i]);
    }
    double bound = 0;
    for (int i = 0; i < nparticles; i++)
        if (is_free[i] && sum[i] / mass[i] > bound)
            bound = sum[i] / mass[i];
    free(sum);
    return bound;
}

double cs_springs_stiffness_bound(const cs_springs *s, const double *mass,
                                  const unsigned char *is_free, int nparticles)
{
    double bound = rest_row_bound(s, mass, is_free, nparticles, false, 0);
    return bound < 0 ? 0 : bound;
}

double cs_springs_rest_step_bound(const cs_springs *s, const double *mass,
                                  const unsigned char *is_free, int nparticles, double dt)
{
    double bound = rest_row_bound(s, mass, is_free, nparticles, true, dt);
    return bound < 0 ? INFINITY : bound;
}

double cs_springs_step_bound(const cs_springs *s, const double *mass,
                             const unsigned char *is_free, double dt, const int *rows, int n,
                             double *value)
{
    if (!rows)
        n = s->nrows;
    double bound = 0; /* a maximum: the same at any thread count */
#pragma omp parallel for schedule(static) reduction(max : bound)
    for (int k = 0; k < n; k++) {
        int r = rows ? rows[k] : k, i = s->row_particle[r];
        double row_bound = 0;
        if (is_free[i]) {
            double sum = 0;
            for (int e = s->row_start[r]; e < s->row_start[r + 1]; e++)
                sum += cs_spring_step_term(dt, s->row_stiffness[e] * s->row_inv_rest_length[e],
                                           s->row_sqrt_damping[e] * s->row_sqrt_damping[e],
                                           s->row_magnitude[e]) *
                       (1 + is_free[s->row_other[e]]); /* as rest_row_bound */
            row_bound = sum / mass[i];
        }
        if (value)
            value[k] = row_bound;
        if (row_bound > bound)
            bound = row_bound;
    }
    return bound;
}

/* out = K v over free particles: the rest-state stiffness of every spring,
 * (E / L0) u u^T with u along the spring at positions x (fixed particles
 * are constraints: their entries stay zero). */
static void stiffness_apply(const cs_springs *s, const double *x, const unsigned char *is_free,
                            int n, const double *v, double *out)
{
    memset(out, 0, sizeof *out * 3 * (size_t)n);
    for (int k = 0; k < s->n; k++) {
        int i = s->ends[2 * k], j = s->ends[2 * k + 1];
        double u[3];
        cs_sub(x + 3 * j, x + 3 * i, u);
        double l = cs_norm(u);
        if (!(l > 0))
            continue;
        double vi[3] = {0, 0, 0}, vj[3] = {0, 0, 0};
        if (is_free[i])
            memcpy(vi, v + 3 * i, sizeof vi);
        if (is_free[j])
            memcpy(vj, v + 3 * j, sizeof vj);
        double rel[3];
        cs_sub(vj, vi, rel);
        double mag = s->stiffness[k] / s->rest_length[k] * cs_dot(rel, u) / (l * l);
        if (is_free[i])
            cs_axpy(-mag, u, out + 3 * i);
        if (is_free[j])
            cs_axpy(mag, u, out + 3 * j);
    }
}

/* Largest eigenvalue of a symmetric tridiagonal matrix (diagonal a, off
 * diagonal b) by bisection on the Sturm count: exact to round-off. */
static double tridiagonal_max_eigenvalue(const double *a, const double *b, int m)
{
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < m; i++) { /* Gershgorin interval */
        double r = (i > 0 ? fabs(b[i - 1]) : 0) + (i + 1 < m ? fabs(b[i]) : 0);
        lo = fmin(lo, a[i] - r);
        hi = fmax(hi, a[i] + r);
    }
    for (int it = 0; it < 200 && hi - lo > 1e-15 * fabs(hi); it++) {
        double mid = 0.5 * (lo + hi), d = 1;
        int above = 0; /* eigenvalues greater than mid */
        for (int i = 0; i < m; i++) {
            d = a[i] - mid - (i > 0 ? b[i - 1] * b[i - 1] / d : 0);
            if (d == 0)
                d = -1e-300;
            above += d > 0;
        }
        if (above > 0)
            lo = mid;
        else
            hi = mid;
    }
    return hi;
}

double cs_springs_max_eigenvalue(const cs_springs *s, const double *x, const double *mass,
                                 const unsigned char *is_free, int n, int steps)
{
    /* Lanczos on the symmetric A = M^-1/2 K M^-1/2, which has the
     * eigenvalues of M^-1 K; its largest Ritz value converges to the top of
     * the spectrum in a few dozen steps, from below. */
    size_t len = 3 * (size_t)n;
    double *q = calloc(len + 1, sizeof *q), *q_prev = calloc(len + 1, sizeof *q_prev);
    double *w = calloc(len + 1, sizeof *w), *t = calloc(len + 1, sizeof *t);
    double *alpha = calloc((size_t)steps + 1, sizeof *alpha);
    double *beta = calloc((size_t)steps + 1, sizeof *beta);
    double result = -1;
    if (!q || !q_prev || !w || !t || !alpha || !beta)
        goto done;
    unsigned long long seed = 88172645463325252ull; /* xorshift: the same start everywhere */
    double norm = 0;
    for (size_t k = 0; k < len; k++) {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        q[k] = is_free[k / 3] ? (double)(seed >> 11) / 9007199254740992.0 - 0.5 : 0;
        norm += q[k] * q[k];
    }
    if (!(norm > 0)) {
        result = 0; /* nothing free: nothing oscillates */
        goto done;
    }
    for (size_t k = 0; k < len; k++)
        q[k] /= sqrt(norm);
    int m = 0;
    for (; m < steps; m++) {
        for (size_t k = 0; k < len; k++) /* A q = M^-1/2 K M^-1/2 q */
            t[k] = q[k] / sqrt(mass[k / 3]);
        stiffness_apply(s, x, is_free, n, t, w);
        double a = 0;
        for (size_t k = 0; k < len; k++) {
            w[k] /= sqrt(mass[k / 3]);
            a += w[k] * q[k];
        }
        alpha[m] = a;
        double bnorm = 0;
        for (size_t k = 0; k < len; k++) {
            w[k] -= a * q[k] + (m > 0 ? beta[m - 1] * q_prev[k] : 0);
            bnorm += w[k] * w[k];
        }
        beta[m] = sqrt(bnorm);
        if (!(beta[m] > 1e-12 * fabs(a))) { /* an invariant subspace: exact */
            m++;
            break;
        }
        for (size_t k = 0; k < len; k++) {
            q_prev[k] = q[k];
            q[k] = w[k] / beta[m];
        }
    }
    result = tridiagonal_max_eigenvalue(alpha, beta, m);
done:
    free(q);
    free(q_prev);
    free(w);
    free(t);
    free(alpha);
    free(beta);
    return result;
}
