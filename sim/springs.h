/* springs.h: the mass-spring model of Section 3, private to sim/.
 *
 * Edge springs join the two ends of every mesh edge; bending springs join the
 * two unshared vertices of every pair of triangles sharing an edge (Fig. 4).
 * The force on particle i of a spring (i, j), u = x_j - x_i, is
 *   f_i = [E (|u|/L0 - 1) + d (v_j - v_i) . u_hat] u_hat,   f_j = -f_i.
 * (The paper writes the damping term with V1 - V2; with u = X2 - X1 that
 * sign would add energy, so we use the dissipative one.)
 */
#ifndef CS_SPRINGS_H
#define CS_SPRINGS_H

#include <math.h>
#include <stddef.h>
#include <string.h>

typedef struct cs_springs {
    int n, capacity;
    int *ends;           /* 2 per spring: i, j (global particle indices) */
    double *rest_length; /* L0 */
    double *inv_rest_length; /* 1 / L0 */
    double *stiffness;   /* E, N */
    double *damping;     /* d, N s / m */
    int nedge;           /* the first nedge springs are edge springs */
    int skipped;         /* degenerate (zero rest length) springs left out */
    /* Each updated particle's springs (cs_springs_index), in spring order:
     * row r is particle row_particle[r], its springs the entries
     * [row_start[r], row_start[r + 1]) with far ends row_other[...]. The kernels gather
     * per particle instead of scattering per spring, so threads never write
     * the same particle and every particle sums its springs in the same
     * order at any thread count. A row has an even number of entries (see
     * cs_pair2), padded with an entry of zero constants whose far end is
     * the particle itself: it adds exactly zero. */
    int nrows;
    const int *row_particle;
    int *row_start, *row_other;
    /* per row entry, so the gathers stream: the spring's constants, and
     * from cs_springs_prepare its direction seen from the row's particle,
     * scaled by sqrt(d) (w = sqrt(d) u_hat, so the damping force is
     * (dv . w) w: one load and one multiply fewer per entry in every CG
     * iteration), and its elastic magnitude E (l/L0 - 1) / l. The
     * directions of entries 2p and 2p + 1 lie interleaved (x x y y z z
     * from row_direction + 3 * 2p), so one load fills a pair. */
    double *row_sqrt_damping, *row_stiffness, *row_inv_rest_length;
    double *row_direction, *row_magnitude;
    /* how the rows are split among the threads (shares.h); NULL: equally */
    struct cs_shares *shares;
} cs_springs;

/* Appends the edge and bending springs of a triangle mesh whose vertices are
 * particles [offset, offset + nv) of the global arrays x and mass (triangle
 * indices are local to the mesh). Stiffness, overdamping fractions and
 * masses give E and d (d = xi * 2 sqrt(E m_reduced / L0)). Returns 0 or -1
 * on allocation failure. */
int cs_springs_add_mesh(cs_springs *s, int offset, int nv, int nt, const int *tri,
                        const double *x, const double *mass,
                        double edge_E, double edge_xi, double bend_E, double bend_xi);
void cs_springs_free(cs_springs *s);

/* Two row entries at a time, one per lane of GCC's two-double vector
 * (SSE2 on x86-64, NEON on AArch64): the spring kernels were bound by
 * scalar arithmetic, not memory (halving the directions' bytes with
 * floats gained nothing measurable; pairs made CG's setup pass and the
 * damping pass markedly faster). A row sums its even and odd entries in
 * the two lanes and adds the lanes at the end: one fixed order at any
 * thread count. */
typedef double cs_pair2 __attribute__((vector_size(16)));

static inline cs_pair2 cs_pair2_load(const double *p)
{
    cs_pair2 a;
    memcpy(&a, p, sizeof a);
    return a;
}

/* u[d] = component d of the far ends of entries e and e + 1, less the
 * row's own. The ends' addresses are taken once, in pointer arithmetic, so
 * the three components are loads at fixed offsets (indexing with the int
 * 3 * other + d made GCC sign-extend each of the six, a good part of
 * the CG operator's instructions). */
static inline void cs_pair2_gather(const double *x, const int *other, int e, const double *own,
                                   cs_pair2 u[3])
{
    const double *a = x + 3 * (ptrdiff_t)other[e], *b = x + 3 * (ptrdiff_t)other[e + 1];
    for (int d = 0; d < 3; d++)
        u[d] = (cs_pair2){a[d], b[d]} - own[d];
}

/* Entries e and e + 1 of a row whose particle has velocity vi: loads
 * their directions w (x, y, z pairs) and returns the damping magnitudes
 * (v_other - v_self) . w */
static inline cs_pair2 cs_springs_pair_damping(const cs_springs *s, int e, const double *v,
                                               const double *vi, cs_pair2 w[3])
{
    const double *we = s->row_direction + 3 * e;
    w[0] = cs_pair2_load(we), w[1] = cs_pair2_load(we + 2), w[2] = cs_pair2_load(we + 4);
    cs_pair2 dv[3];
    cs_pair2_gather(v, s->row_other, e, vi, dv);
    return dv[0] * w[0] + dv[1] * w[1] + dv[2] * w[2];
}

/* Row r's damping force (D v) added into acc: the kernel of
 * cs_springs_add_damping, inlined where a caller fuses it with more work. */
static inline void cs_springs_damping_row(const cs_springs *s, int r, const double *v,
                                          double acc[3])
{
    const double *vi = v + 3 * s->row_particle[r];
    cs_pair2 ax = {0, 0}, ay = {0, 0}, az = {0, 0};
    for (int e = s->row_start[r]; e < s->row_start[r + 1]; e += 2) {
        cs_pair2 w[3], mag = cs_springs_pair_damping(s, e, v, vi, w);
        ax += mag * w[0];
        ay += mag * w[1];
        az += mag * w[2];
    }
    acc[0] += ax[0] + ax[1];
    acc[1] += ay[0] + ay[1];
    acc[2] += az[0] + az[1];
}

/* Builds the per-particle rows for the nrows particles listed (kept, not
 * copied); call again after the springs change. Returns 0 or -1. */
int cs_springs_index(cs_springs *s, int nrows, const int *particles, int nparticles);

/* The kernels below write the rows' particles only (OpenMP threads share
 * them). */
/* Stores sqrt(d) u_hat and the elastic magnitude of every spring at positions x,
 * for the damping operator and cs_springs_step_bound. */
void cs_springs_prepare(cs_springs *s, const double *x);
/* Elastic forces only (the explicit part) at positions x, stored into f
 * at the rows' particles (the others untouched);
 * stores the directions at x as cs_springs_prepare does (one pass over the
 * springs serves both), but not the magnitudes. */
void cs_springs_elastic(cs_springs *s, const double *x, double *f);
/* out += D v, the damping force (D is the velocity Jacobian, symmetric
 * negative semi-definite), with the directions from cs_springs_prepare. */
void cs_springs_add_damping(const cs_springs *s, const double *v, double *out);
/* Keeps only the springs with an end owned by rank (Section 7: a spring
 * across ranks is computed by both owners, redundantly). */
void cs_springs_keep_touching(cs_springs *s, const int *owner, int rank);

/* spring_bounds.c: what limits the step (step_limit.c). */
/* Largest eigenvalue bound (Gershgorin) of M^-1 K_elastic over particles
 * with is_free[i] set: per particle 2 * sum(E/L0) / m. */
double cs_springs_stiffness_bound(const cs_springs *s, const double *mass,
                                  const unsigned char *is_free, int nparticles);
/* The largest eigenvalue of M^-1 K for the rest-state stiffness K at
 * positions x, over particles with is_free set, by `steps` Lanczos
 * iterations (a lower estimate that converges quickly; the Gershgorin bound
 * above is an upper one). Returns -1 when memory runs out. */
double cs_springs_max_eigenvalue(const cs_springs *s, const double *x, const double *mass,
                                 const unsigned char *is_free, int n, int steps);

/* The damped scheme's stability test (see step_limit.c). One spring of
 * axial stiffness k = E / L0, damping c and tension stiffness g = E (1/L0 -
 * 1/l) adds to its ends' rows of dt^2 K - 2 dt D a block of norm
 * max(dt^2 k - 2 dt c, dt^2 |g|, 0): along the spring the damping offsets
 * the stiffness, across it nothing damps the tension (or, for a compressed
 * spring, the negative stiffness whose growth the step must not outrun). */
static inline double cs_spring_step_term(double dt, double k, double c, double g)
{
    double along = dt * (dt * k - 2.0 * c), across = dt * dt * fabs(g);
    return along > across ? (along > 0 ? along : 0) : (across > 0 ? across : 0);
}
/* Gershgorin's bound on the largest eigenvalue of M^-1 (dt^2 K - 2 dt D)
 * at the rest state, over all springs and the free particles:
 * max_i (1 / m_i) sum over i's springs of cs_spring_step_term, each
 * counted twice where its far end is free (diagonal and off-diagonal
 * entry), once where it is pinned or scripted. */
double cs_springs_rest_step_bound(const cs_springs *s, const double *mass,
                                  const unsigned char *is_free, int nparticles, double dt);
/* The same over the rows (cs_springs_index) at the positions last given to
 * cs_springs_prepare, tension included: over rows[0..n) (row indices), or
 * every row when rows is NULL; with value, each listed row's own bound
 * goes to value[k] (0 for a particle that is not free). A row's bound
 * never decreases as dt grows: each term is 0 or a product of non-negative
 * factors that grow with dt, and rounding keeps that order, so a row that
 * passes at one dt passes at every smaller one (step_limit.c's bisection
 * drops such rows). */
double cs_springs_step_bound(const cs_springs *s, const double *mass,
                             const unsigned char *is_free, double dt, const int *rows, int n,
                             double *value);

#endif
