/* tri_oracle.h: the intersection verifier's independent reference, for
 * the tests of sim/predicates.c and sim/verify.c: two closed triangles
 * meet iff the linear program
 *     sum a_i p_i = sum b_j q_j,  sum a_i = sum b_j = 1,  a, b >= 0
 * is feasible, decided exactly with GMP rationals by enumerating basic
 * solutions (no orientation predicate at all; it shares no code and no
 * method with the verifier). Also a seeded random stream (each test file
 * its own) and a value moved by ulps. */
#ifndef CS_TESTS_TRI_ORACLE_H
#define CS_TESTS_TRI_ORACLE_H

#include <gmp.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>

static uint64_t rng_state = 0x243F6A8885A308D3u;

static inline uint64_t rng_u64(void)
{
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15u);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9u;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBu;
    return z ^ (z >> 31);
}

static inline double rng_unit(void)
{
    return (double)(rng_u64() >> 11) * 0x1p-53;
}

static inline int rng_int(int n)
{
    return (int)(rng_u64() % (uint64_t)n);
}

/* v moved by k ulps (k may be negative). */
static inline double ulps(double v, int k)
{
    for (; k > 0; k--)
        v = nextafter(v, INFINITY);
    for (; k < 0; k++)
        v = nextafter(v, -INFINITY);
    return v;
}

/* Exact sign of det[a-d; b-d; c-d] by the rule of Sarrus in rationals. */
static inline int oracle_orient3d(const double *a, const double *b, const double *c,
                                  const double *d)
{
    mpq_t m[3][3], t, u, det;
    mpq_inits(t, u, det, NULL);
    const double *rows[3] = {a, b, c};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            mpq_init(m[i][j]);
            mpq_set_d(m[i][j], rows[i][j]);
            mpq_set_d(t, d[j]);
            mpq_sub(m[i][j], m[i][j], t);
        }
    for (int k = 0; k < 3; k++) {
        mpq_mul(t, m[0][k], m[1][(k + 1) % 3]);
        mpq_mul(t, t, m[2][(k + 2) % 3]);
        mpq_add(det, det, t);
        mpq_mul(u, m[0][k], m[1][(k + 2) % 3]);
        mpq_mul(u, u, m[2][(k + 1) % 3]);
        mpq_sub(det, det, u);
    }
    int s = mpq_sgn(det);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            mpq_clear(m[i][j]);
    mpq_clears(t, u, det, NULL);
    return s;
}

static inline int oracle_orient2d(const double *a, const double *b, const double *c)
{
    double a3[3] = {a[0], a[1], 0}, b3[3] = {b[0], b[1], 0}, c3[3] = {c[0], c[1], 0};
    double top[3] = {c[0], c[1], 1};
    /* det[a-top; b-top; c-top] = -det[a-c; b-c] (third column all -1) */
    return -oracle_orient3d(a3, b3, c3, top);
}

/* Closed triangles p and q meet iff the LP above is feasible iff it has a
 * basic feasible solution: row-reduce [A | b], then try every choice of
 * rank-many columns, solving exactly and testing for x >= 0. */
static inline bool oracle_intersect(const double p[9], const double q[9])
{
    mpq_t m[5][7], w[5][6], f;
    mpq_init(f);
    for (int i = 0; i < 5; i++) {
        for (int j = 0; j < 7; j++)
            mpq_init(m[i][j]);
        for (int j = 0; j < 6; j++)
            mpq_init(w[i][j]);
    }
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++) {
            mpq_set_d(m[k][i], p[3 * i + k]);
            mpq_set_d(m[k][3 + i], -q[3 * i + k]);
        }
    for (int i = 0; i < 3; i++) {
        mpq_set_ui(m[3][i], 1, 1);
        mpq_set_ui(m[4][3 + i], 1, 1);
    }
    mpq_set_ui(m[3][6], 1, 1);
    mpq_set_ui(m[4][6], 1, 1);

    int r = 0;
    for (int col = 0; col < 6 && r < 5; col++) {
        int piv = -1;
        for (int row = r; row < 5 && piv < 0; row++)
            if (mpq_sgn(m[row][col]) != 0)
                piv = row;
        if (piv < 0)
            continue;
        for (int j = 0; j < 7; j++)
            mpq_swap(m[piv][j], m[r][j]);
        for (int row = 0; row < 5; row++) {
            if (row == r || mpq_sgn(m[row][col]) == 0)
                continue;
            mpq_div(f, m[row][col], m[r][col]);
            for (int j = 0; j < 7; j++) {
                mpq_t t;
                mpq_init(t);
                mpq_mul(t, f, m[r][j]);
                mpq_sub(m[row][j], m[row][j], t);
                mpq_clear(t);
            }
        }
        r++;
    }
    bool consistent = true;
    for (int row = r; row < 5; row++)
        if (mpq_sgn(m[row][6]) != 0)
            consistent = false;

    bool feasible = false;
    for (int mask = 0; consistent && !feasible && mask < 64; mask++) {
        int cols[6], n = 0;
        for (int j = 0; j < 6; j++)
            if (mask >> j & 1)
                cols[n++] = j;
        if (n != r)
            continue;
        for (int i = 0; i < r; i++) {
            for (int j = 0; j < r; j++)
                mpq_set(w[i][j], m[i][cols[j]]);
            mpq_set(w[i][r], m[i][6]);
        }
        bool singular = false;
        for (int j = 0; j < r && !singular; j++) {
            int piv = -1;
            for (int i = j; i < r && piv < 0; i++)
                if (mpq_sgn(w[i][j]) != 0)
                    piv = i;
            if (piv < 0) {
                singular = true;
                break;
            }
            for (int k = 0; k <= r; k++)
                mpq_swap(w[piv][k], w[j][k]);
            for (int i = 0; i < r; i++) {
                if (i == j || mpq_sgn(w[i][j]) == 0)
                    continue;
                mpq_div(f, w[i][j], w[j][j]);
                for (int k = 0; k <= r; k++) {
                    mpq_t t;
                    mpq_init(t);
                    mpq_mul(t, f, w[j][k]);
                    mpq_sub(w[i][k], w[i][k], t);
                    mpq_clear(t);
                }
            }
        }
        if (singular)
            continue;
        bool nonneg = true;
        for (int j = 0; j < r; j++)
            if (mpq_sgn(w[j][r]) * mpq_sgn(w[j][j]) < 0)
                nonneg = false;
        feasible = nonneg;
    }
    for (int i = 0; i < 5; i++) {
        for (int j = 0; j < 7; j++)
            mpq_clear(m[i][j]);
        for (int j = 0; j < 6; j++)
            mpq_clear(w[i][j]);
    }
    mpq_clear(f);
    return feasible;
}

#endif
