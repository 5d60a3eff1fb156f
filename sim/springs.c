/* springs.c: edge and bending springs, their forces and damping operator.
 * The bounds on their stiffness that limit the step are in spring_bounds.c. */
#include <math.h>
#include <omp.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h> /* the wider kernels, compiled for their targets alone */
#endif

#include "sim/shares.h"
#include "sim/springs.h"
#include "sim/vec3.h"

static int reserve(cs_springs *s, int extra)
{
    if (s->n + extra <= s->capacity)
        return 0;
    int cap = s->capacity ? s->capacity : 64;
    while (cap < s->n + extra)
        cap *= 2;
    int *ends = realloc(s->ends, sizeof *ends * 2 * (size_t)cap);
    if (ends)
        s->ends = ends;
    double **arrays[4] = {&s->rest_length, &s->stiffness, &s->damping, &s->inv_rest_length};
    int ok = ends != NULL;
    for (int k = 0; k < 4 && ok; k++) {
        double *a = realloc(*arrays[k], sizeof *a * (size_t)cap);
        if (a)
            *arrays[k] = a;
        ok = a != NULL;
    }
    if (!ok)
        return -1;
    s->capacity = cap;
    return 0;
}

static void push(cs_springs *s, int i, int j, const double *x, const double *mass,
                 double E, double xi)
{
    double u[3];
    cs_sub(x + 3 * j, x + 3 * i, u);
    double L0 = cs_norm(u);
    if (!(L0 > 1e-12)) { /* coincident vertices: no direction, no spring */
        s->skipped++;
        return;
    }
    double m_reduced = mass[i] * mass[j] / (mass[i] + mass[j]);
    int k = s->n++;
    s->ends[2 * k] = i;
    s->ends[2 * k + 1] = j;
    s->rest_length[k] = L0;
    s->inv_rest_length[k] = 1.0 / L0;
    s->stiffness[k] = E;
    s->damping[k] = xi * 2.0 * sqrt(E * m_reduced / L0);
}

/* An undirected mesh edge with the triangle it came from. */
typedef struct edge_ref {
    int a, b;      /* a < b, local vertex indices */
    int opposite;  /* the triangle's third vertex */
} edge_ref;

static int edge_cmp(const void *pa, const void *pb)
{
    const edge_ref *p = pa, *q = pb;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    return (p->opposite > q->opposite) - (p->opposite < q->opposite);
}

int cs_springs_add_mesh(cs_springs *s, int offset, int nv, int nt, const int *tri,
                        const double *x, const double *mass,
                        double edge_E, double edge_xi, double bend_E, double bend_xi)
{
    (void)nv;
    edge_ref *edges = malloc(sizeof *edges * 3 * (size_t)(nt > 0 ? nt : 1));
    if (!edges)
        return -1;
    int ne = 0;
    for (int t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            int a = tri[3 * t + k], b = tri[3 * t + (k + 1) % 3], c = tri[3 * t + (k + 2) % 3];
            edges[ne].a = a < b ? a : b;
            edges[ne].b = a < b ? b : a;
            edges[ne].opposite = c;
            ne++;
        }
    qsort(edges, (size_t)ne, sizeof *edges, edge_cmp);

    /* Edge springs first (one per distinct edge), then bending springs. */
    for (int pass = 0; pass < 2; pass++) {
        for (int i = 0; i < ne;) {
            int j = i;
            while (j < ne && edges[j].a == edges[i].a && edges[j].b == edges[i].b)
                j++;
            if (pass == 0) {
                if (reserve(s, 1)) {
                    free(edges);
                    return -1;
                }
                push(s, offset + edges[i].a, offset + edges[i].b, x, mass, edge_E, edge_xi);
            } else {
                /* every pair of triangles on this edge (more than one pair
                 * only where the mesh is non-manifold) */
                for (int p = i; p < j; p++)
                    for (int q = p + 1; q < j; q++) {
                        if (edges[p].opposite == edges[q].opposite)
                            continue; /* duplicate triangle */
                        if (reserve(s, 1)) {
                            free(edges);
                            return -1;
                        }
                        push(s, offset + edges[p].opposite, offset + edges[q].opposite, x,
                             mass, bend_E, bend_xi);
                    }
            }
            i = j;
        }
        if (pass == 0)
            s->nedge = s->n;
    }
    free(edges);
    return 0;
}

static void free_rows(cs_springs *s)
{
    free(s->row_start);
    free(s->row_other);
    double **rows[] = {&s->row_sqrt_damping, &s->row_direction, &s->row_magnitude,
                       &s->row_stiffness, &s->row_inv_rest_length};
    for (size_t k = 0; k < sizeof rows / sizeof *rows; k++) {
        free(*rows[k]);
        *rows[k] = NULL; /* cs_springs_index may fail before replacing them */
    }
    s->row_start = s->row_other = NULL;
}

int cs_springs_index(cs_springs *s, int nrows, const int *particles, int nparticles)
{
    free_rows(s);
    s->nrows = nrows;
    s->row_particle = particles;
    s->row_start = calloc((size_t)nrows + 1, sizeof *s->row_start);
    int *row_of = malloc(sizeof *row_of * ((size_t)nparticles + 1));
    int *fill = malloc(sizeof *fill * ((size_t)nrows + 1));
    if (!s->row_start || !row_of || !fill) {
        free(row_of);
        free(fill);
        return -1;
    }
    for (int i = 0; i < nparticles; i++)
        row_of[i] = -1;
    for (int r = 0; r < nrows; r++)
        row_of[particles[r]] = r;
    for (int k = 0; k < 2 * s->n; k++) {
        int r = row_of[s->ends[k]];
        if (r >= 0)
            s->row_start[r + 1]++;
    }
    for (int r = 0; r < nrows; r++) /* each row even (cs_pair2) */
        s->row_start[r + 1] += s->row_start[r] + (s->row_start[r + 1] & 1);
    size_t n = (size_t)s->row_start[nrows] + 1;
    s->row_sqrt_damping = malloc(sizeof(double) * n);
    s->row_direction = malloc(sizeof(double) * 3 * n);
    s->row_magnitude = malloc(sizeof(double) * n);
    s->row_stiffness = malloc(sizeof(double) * n);
    s->row_inv_rest_length = malloc(sizeof(double) * n);
    s->row_other = malloc(sizeof *s->row_other * n);
    if (!s->row_other || !s->row_sqrt_damping || !s->row_direction || !s->row_magnitude ||
        !s->row_stiffness || !s->row_inv_rest_length) {
        free(row_of);
        free(fill);
        return -1;
    }
    memcpy(fill, s->row_start, sizeof *fill * (size_t)nrows);
    for (int k = 0; k < s->n; k++) { /* ascending k: each row in spring order */
        for (int e = 0; e < 2; e++) {
            int r = row_of[s->ends[2 * k + e]];
            if (r < 0)
                continue;
            s->row_sqrt_damping[fill[r]] = sqrt(s->damping[k]);
            s->row_stiffness[fill[r]] = s->stiffness[k];
            s->row_inv_rest_length[fill[r]] = s->inv_rest_length[k];
            s->row_other[fill[r]++] = s->ends[2 * k + 1 - e];
        }
    }
    for (int r = 0; r < nrows; r++)
        for (int e = fill[r]; e < s->row_start[r + 1]; e++) { /* the pad */
            s->row_sqrt_damping[e] = s->row_stiffness[e] = s->row_inv_rest_length[e] = 0;
            s->row_other[e] = particles[r];
        }
    free(fill);
    free(row_of);
    return 0;
}

void cs_springs_free(cs_springs *s)
{
    free(s->ends);
    free(s->rest_length);
    free(s->inv_rest_length);
    free(s->stiffness);
    free(s->damping);
    free_rows(s);
    memset(s, 0, sizeof *s);
}

typedef long long pair2_mask __attribute__((vector_size(16))); /* all ones or zeros */

/* a where mask, b elsewhere */
static inline cs_pair2 pair2_select(pair2_mask mask, cs_pair2 a, cs_pair2 b)
{
    return (cs_pair2)(((pair2_mask)a & mask) | ((pair2_mask)b & ~mask));
}

/* a where mask, 0 elsewhere */
static inline cs_pair2 pair2_keep(cs_pair2 a, pair2_mask mask)
{
    return (cs_pair2)((pair2_mask)a & mask);
}

/* sqrt per lane, correctly rounded as sqrt() */
static inline cs_pair2 pair2_sqrt(cs_pair2 a)
{
#if defined(__SSE2__)
    return (cs_pair2)_mm_sqrt_pd((__m128d)a);
#else
    return (cs_pair2){sqrt(a[0]), sqrt(a[1])};
#endif
}

/* inv[k] = 1 / sqrt(uu[k]) where sqrt(uu[k]) > 0, else 0, for k < n (n
 * even): the elastic pass's square roots and divisions, a large part of
 * its time (bench_cg_speed times the pass). The divider takes about as
 * long for 2, 4 or 8 lanes, so the time an entry falls with the width, and
 * the widest vectors the CPU has are chosen at run time. Square roots
 * and divisions are correctly rounded at any width: the same bits. */
typedef void (*inv_lengths_fn)(const double *uu, double *inv, int n);

/* the pairs' kernel: two lanes */
static inline cs_pair2 inv_length_pair(cs_pair2 uu)
{
    cs_pair2 l = pair2_sqrt(uu);
    pair2_mask pos = l > 0;
    return pair2_keep(1.0 / pair2_select(pos, l, (cs_pair2){1, 1}), pos);
}

#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("avx2"))) static void inv_lengths_avx2(const double *uu, double *inv,
                                                             int n)
{
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
    int k = 0;
    for (; k + 4 <= n; k += 4) {
        __m256d l = _mm256_sqrt_pd(_mm256_loadu_pd(uu + k));
        __m256d pos = _mm256_cmp_pd(l, zero, _CMP_GT_OQ);
        __m256d r = _mm256_and_pd(_mm256_div_pd(one, _mm256_blendv_pd(one, l, pos)), pos);
        _mm256_storeu_pd(inv + k, r);
    }
    if (k < n) { /* n is even: one pair left */
        cs_pair2 r = inv_length_pair(cs_pair2_load(uu + k));
        memcpy(inv + k, &r, sizeof r);
    }
}

__attribute__((target("avx512f"))) static void inv_lengths_avx512(const double *uu,
                                                                  double *inv, int n)
{
    const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0);
    for (int k = 0; k < n; k += 8) {
        __mmask8 in = (__mmask8)(n - k >= 8 ? 0xff : (1u << (n - k)) - 1);
        __m512d l = _mm512_sqrt_pd(_mm512_maskz_loadu_pd(in, uu + k));
        __mmask8 pos = _mm512_mask_cmp_pd_mask(in, l, zero, _CMP_GT_OQ);
        _mm512_mask_storeu_pd(inv + k, in, _mm512_maskz_div_pd(pos, one, l));
    }
}
#endif

/* The wide kernel this CPU has; NULL for none (the pairs then stay in the
 * row loop: gathering them into batches cost more than it gained) */
static inv_lengths_fn wide_inv_lengths(void)
{
#if defined(__x86_64__) && defined(__GNUC__)
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f"))
        return inv_lengths_avx512;
    if (__builtin_cpu_supports("avx2"))
        return inv_lengths_avx2;
#endif
    return NULL;
}

/* The row arrays the elastic pass reads and writes, copied out of the
 * springs: its stores (memcpy) may alias anything, so read through the
 * struct every pointer would be loaded again for each pair. */
typedef struct row_arrays {
    const double *stiffness, *inv_rest_length, *sqrt_damping;
    double *direction, *magnitude;
} row_arrays;

/* Entries e and e + 1 of a row, u = x_other - x_self and inv their
 * inverse lengths: directions (and magnitudes) stored, the elastic force
 * added into f[3] (a row's even and odd entries in the two lanes). */
static inline __attribute__((always_inline)) void
finish_pair(row_arrays a, int e, const cs_pair2 u[3], cs_pair2 inv, bool keep_magnitude,
            cs_pair2 f[3])
{
    /* E (l / L0 - 1) / l = E / L0 - E / l, and u / l; coincident ends
     * (and the pads) have no direction to push along: inv = 0 there, and
     * so magnitude and direction. Masks, not branches: a pad's branch was
     * mispredicted in every odd row. */
    cs_pair2 mag = pair2_keep(cs_pair2_load(a.stiffness + e) *
                                  (cs_pair2_load(a.inv_rest_length + e) - inv),
                              inv != 0);
    cs_pair2 scale = inv * cs_pair2_load(a.sqrt_damping + e);
    for (int d = 0; d < 3; d++) { /* a store each: one of the array went through the stack */
        cs_pair2 w = u[d] * scale;
        memcpy(a.direction + 3 * e + 2 * d, &w, sizeof w);
    }
    if (keep_magnitude) /* a loop invariant: the compiler unswitches it */
        memcpy(a.magnitude + e, &mag, sizeof mag);
    for (int d = 0; d < 3; d++)
        f[d] += mag * u[d];
}

static row_arrays row_arrays_of(cs_springs *s)
{
    return (row_arrays){s->row_stiffness, s->row_inv_rest_length, s->row_sqrt_damping,
                        s->row_direction, s->row_magnitude};
}

/* Stored, not added: a lane sum is never -0 (the lanes start at +0, and
 * in rounding to nearest only -0 + -0 gives -0), so 0 + sum, the old
 * zeroing pass and an add, gave the same bits; the pass and its fork cost
 * more. */
static void store_row_force(const cs_springs *s, int r, const cs_pair2 fr[3], double *f)
{
    if (!f)
        return;
    int i = s->row_particle[r];
    for (int d = 0; d < 3; d++)
        f[3 * i + d] = fr[d][0] + fr[d][1];
}

/* The elastic pass with a wide kernel takes its rows in batches of at
 * most this many entries: their lengths first, then the divider's work
 * for the whole batch in one call, then the rest. Called per row, the wide
 * divisions of a row's dozen entries waited on each other and the pass
 * gained nothing; batched, the divisions overlap and the pass is faster
 * (bench_cg_speed), 64 or 256 entries about as fast as 128. A row longer than a batch goes alone,
 * in pieces. */
enum { BATCH = 128 };

typedef struct length_batch {
    cs_pair2 u[BATCH / 2][3]; /* x_other - x_self, entries in pairs */
    double uu[BATCH], inv[BATCH];
} length_batch;

/* entries [e0, e1) of row r (at most BATCH, e0 even) into b from entry
 * off (even): u and |u|^2 (pointers stepped, not indices halved: the
 * signed halving cost four instructions a pair) */
static inline __attribute__((always_inline)) void
batch_gather(const cs_springs *s, const double *x, int r, int e0, int e1, length_batch *b, int off)
{
    const double *xi = x + 3 * s->row_particle[r];
    cs_pair2(*u)[3] = b->u + off / 2;
    double *uu = b->uu + off;
    for (int e = e0; e < e1; e += 2, u++, uu += 2) {
        cs_pair2_gather(x, s->row_other, e, xi, *u);
        cs_pair2 sq = (*u)[0] * (*u)[0] + (*u)[1] * (*u)[1] + (*u)[2] * (*u)[2];
        memcpy(uu, &sq, sizeof sq);
    }
}

static inline __attribute__((always_inline)) void
batch_finish(row_arrays a, int e0, int e1, const length_batch *b, int off, bool keep_magnitude,
             cs_pair2 f[3])
{
    const cs_pair2(*u)[3] = b->u + off / 2;
    const double *inv = b->inv + off;
    for (int e = e0; e < e1; e += 2, u++, inv += 2)
        finish_pair(a, e, *u, cs_pair2_load(inv), keep_magnitude, f);
}

/* rows [r, r_end) in batches through the wide kernel */
static inline __attribute__((always_inline)) void
prepare_rows_batched(cs_springs *s, const double *x, double *f, bool keep_magnitude,
                     inv_lengths_fn inv_lengths, int r, int r_end)
{
    const int *start = s->row_start;
    row_arrays a = row_arrays_of(s);
    length_batch b;
    while (r < r_end) {
        int rb = r; /* the batch: rows [r, rb) */
        while (rb < r_end && start[rb + 1] - start[r] <= BATCH)
            rb++;
        if (rb == r) { /* a row longer than a batch, in pieces */
            cs_pair2 fr[3] = {{0, 0}, {0, 0}, {0, 0}};
            for (int e0 = start[r]; e0 < start[r + 1]; e0 += BATCH) {
                int e1 = start[r + 1] - e0 < BATCH ? start[r + 1] : e0 + BATCH;
                batch_gather(s, x, r, e0, e1, &b, 0);
                inv_lengths(b.uu, b.inv, e1 - e0);
                batch_finish(a, e0, e1, &b, 0, keep_magnitude, fr);
            }
            store_row_force(s, r, fr, f);
            r++;
            continue;
        }
        for (int q = r; q < rb; q++)
            batch_gather(s, x, q, start[q], start[q + 1], &b, start[q] - start[r]);
        inv_lengths(b.uu, b.inv, start[rb] - start[r]);
        for (int q = r; q < rb; q++) {
            cs_pair2 fr[3] = {{0, 0}, {0, 0}, {0, 0}};
            batch_finish(a, start[q], start[q + 1], &b, start[q] - start[r], keep_magnitude, fr);
            store_row_force(s, q, fr, f);
        }
        r = rb;
    }
}

/* rows [r, r_end) pair by pair, the kernel inline */
static inline __attribute__((always_inline)) void
prepare_rows_pairs(cs_springs *s, const double *x, double *f, bool keep_magnitude, int r,
                   int r_end)
{
    row_arrays a = row_arrays_of(s);
    for (; r < r_end; r++) {
        const double *xi = x + 3 * s->row_particle[r];
        cs_pair2 fr[3] = {{0, 0}, {0, 0}, {0, 0}};
        for (int e = s->row_start[r]; e < s->row_start[r + 1]; e += 2) {
            cs_pair2 u[3];
            cs_pair2_gather(x, s->row_other, e, xi, u);
            cs_pair2 inv = inv_length_pair(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            finish_pair(a, e, u, inv, keep_magnitude, fr);
        }
        store_row_force(s, r, fr, f);
    }
}

/* Seen from either end, a spring's terms are the same expression in
 * (self, other): u = x_other - x_self pulls self towards other when
 * stretched, and (v_other - v_self) . u_hat damps their approach. Every
 * row computes its own entries, so a spring between two rows is computed
 * twice; the two give the same direction negated and the same magnitude
 * (x_i - x_j = -(x_j - x_i) in floating point), and a row needs nothing
 * another thread writes: the elastic forces come in the same pass. (One
 * computation per spring, written to both ends, cost a second pass and
 * scattered writes; in pairs, two sqrt and divisions cost one.)
 *
 * Either way (batched or pairs) each row's entries take the same
 * operations in the same order: the same bits with any kernel and thread
 * count. Everything above is inlined here, so the two callers'
 * keep_magnitude is a constant. */
static inline __attribute__((always_inline)) void
prepare_rows(cs_springs *s, const double *x, double *f, bool keep_magnitude)
{
    static int probed; /* set here, before the threads start */
    static inv_lengths_fn wide;
    if (!probed) {
        wide = wide_inv_lengths();
        probed = 1;
    }
    inv_lengths_fn inv_lengths = wide;
#pragma omp parallel
    {
        /* the thread's share of the rows, clocked (shares.h) */
        double t0 = omp_get_wtime();
        int r, r_end;
        cs_shares_rows(s->shares, s->nrows, &r, &r_end);
        if (inv_lengths)
            prepare_rows_batched(s, x, f, keep_magnitude, inv_lengths, r, r_end);
        else
            prepare_rows_pairs(s, x, f, keep_magnitude, r, r_end);
        cs_shares_clock(s->shares, t0);
    }
}

/* Only the damped step limit's bound reads the magnitudes, and it prepares
 * the springs itself first: the two passes a step make do not store them
 * (a quarter of the pass's stores). */
void cs_springs_prepare(cs_springs *s, const double *x) { prepare_rows(s, x, NULL, true); }

void cs_springs_elastic(cs_springs *s, const double *x, double *f)
{
    prepare_rows(s, x, f, false);
}

void cs_springs_add_damping(const cs_springs *s, const double *v, double *out)
{
#pragma omp parallel for schedule(static)
    for (int r = 0; r < s->nrows; r++) {
        int i = s->row_particle[r];
        double acc[3] = {out[3 * i], out[3 * i + 1], out[3 * i + 2]};
        cs_springs_damping_row(s, r, v, acc);
        memcpy(out + 3 * i, acc, sizeof acc);
    }
}

void cs_springs_keep_touching(cs_springs *s, const int *owner, int rank)
{
    int kept = 0, kept_edge = 0;
    for (int k = 0; k < s->n; k++) {
        int i = s->ends[2 * k], j = s->ends[2 * k + 1];
        if (owner[i] != rank && owner[j] != rank)
            continue;
        s->ends[2 * kept] = i;
        s->ends[2 * kept + 1] = j;
        s->rest_length[kept] = s->rest_length[k];
        s->inv_rest_length[kept] = s->inv_rest_length[k];
        s->stiffness[kept] = s->stiffness[k];
        s->damping[kept] = s->damping[k];
        kept_edge += k < s->nedge;
        kept++;
    }
    s->n = kept;
    s->nedge = kept_edge;
}
