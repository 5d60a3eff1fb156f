/* test_verify.c: the exact self-intersection verifier (sim/verify.c) on
 * whole meshes: its broad phase against a brute-force O(n^2) pass of the
 * narrow phase (and of the exact oracle, tests/tri_oracle.h) on random
 * triangle soups, and meshes with known counts: a flat sheet (0), a sheet
 * folded through itself (6M - 2, worked out below), its two halves
 * stacked at tiny separation (0). The predicates and the triangle pair
 * test: test_predicates.c. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "sim/predicates.h"
#include "sim/sim.h"
#include "tests/tri_oracle.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ------------------------------------------------------------- utilities */

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ------------------------------------------------------ broad phase */

static long brute_force(int nv, const double *x, int nt, const int *tri, int maxpairs,
                        int *pairs, bool use_oracle)
{
    (void)nv;
    long count = 0;
    for (int i = 0; i < nt; i++)
        for (int j = i + 1; j < nt; j++) {
            const int *a = tri + 3 * i, *b = tri + 3 * j;
            bool adjacent = false;
            for (int u = 0; u < 3; u++)
                for (int v = 0; v < 3; v++)
                    adjacent = adjacent || a[u] == b[v];
            if (adjacent)
                continue;
            double p[9], q[9];
            for (int k = 0; k < 3; k++) {
                memcpy(p + 3 * k, x + 3 * a[k], 3 * sizeof *p);
                memcpy(q + 3 * k, x + 3 * b[k], 3 * sizeof *q);
            }
            if (!(use_oracle ? oracle_intersect(p, q) : cs_triangles_intersect(p, q)))
                continue;
            if (count < maxpairs) {
                pairs[2 * count] = i;
                pairs[2 * count + 1] = j;
            }
            count++;
        }
    return count;
}

/* The grid count equals brute force, with the same first pairs in order. */
static void check_against_brute(int nv, const double *x, int nt, const int *tri, bool oracle,
                                const char *what)
{
    int got_pairs[40], want_pairs[40];
    long got = cs_find_intersections(nv, x, nt, tri, 20, got_pairs);
    long want = brute_force(nv, x, nt, tri, 20, want_pairs, oracle);
    print_message("%s: %ld intersecting pairs of %d triangles\n", what, want, nt);
    if (got != want)
        fail_msg("%s: grid %ld, brute force %ld", what, got, want);
    for (long k = 0; k < want && k < 20; k++) {
        assert_int_equal(got_pairs[2 * k], want_pairs[2 * k]);
        assert_int_equal(got_pairs[2 * k + 1], want_pairs[2 * k + 1]);
    }
    assert_int_equal(cs_count_intersections(nv, x, nt, tri), want);
}

/* A soup of triangles on a vertex pool (so some share vertices), with
 * coordinates from `coord` and some degenerate triangles. */
static void make_soup(int nv, double *x, int nt, int *tri, double (*coord)(void))
{
    for (int i = 0; i < 3 * nv; i++)
        x[i] = coord();
    for (int t = 0; t < nt; t++) {
        int a = rng_int(nv);
        /* mostly nearby vertices, so triangles are small */
        int b = (a + 1 + rng_int(6)) % nv, c = (a + 1 + rng_int(6)) % nv;
        if (t % 17 == 0)
            c = b;   /* repeated vertex: a segment */
        tri[3 * t] = a;
        tri[3 * t + 1] = b;
        tri[3 * t + 2] = c;
    }
}

static double coord_unit(void)
{
    return rng_unit();
}

static double coord_int(void)
{
    return rng_int(6);
}

static double coord_quarter(void)
{
    return rng_int(25) / 4.0;
}

/* Vertex i near a random walk, so a triangle's vertices are close. */
static double walk_pos[3];
static int walk_axis;
static double coord_walk(void)
{
    int k = walk_axis;
    walk_axis = (walk_axis + 1) % 3;
    walk_pos[k] += (rng_unit() - 0.5) * 0.2;
    if (walk_pos[k] < 0 || walk_pos[k] > 1)
        walk_pos[k] = rng_unit();
    return walk_pos[k];
}

static void test_broad_phase_against_brute_force(void **state)
{
    (void)state;
    enum { NV = 300, NT = 400 };
    double *x = malloc(3 * NV * sizeof *x);
    int *tri = malloc(3 * NT * sizeof *tri);
    assert_non_null(x);
    assert_non_null(tri);

    make_soup(NV, x, NT, tri, coord_walk);
    check_against_brute(NV, x, NT, tri, false, "random-walk soup");
    make_soup(NV, x, NT, tri, coord_unit);
    check_against_brute(NV, x, NT, tri, false, "uniform soup");
    make_soup(NV, x, NT, tri, coord_int);
    check_against_brute(NV, x, NT, tri, false, "integer soup");
    make_soup(NV, x, NT, tri, coord_quarter);
    check_against_brute(NV, x, NT, tri, false, "quarter-grid soup");

    /* scaled by powers of two (exact): the same counts */
    make_soup(NV, x, NT, tri, coord_walk);
    long base = cs_count_intersections(NV, x, NT, tri);
    for (int i = 0; i < 3 * NV; i++)
        x[i] *= 0x1p900;
    assert_int_equal(cs_count_intersections(NV, x, NT, tri), base);
    for (int i = 0; i < 3 * NV; i++)
        x[i] = x[i] * 0x1p-980 * 0x1p-980;   /* now below 2^-1060: subnormal */
    check_against_brute(NV, x, NT, tri, false, "subnormal soup");

    /* a few huge triangles among small ones (forces a coarser grid) */
    make_soup(NV, x, NT, tri, coord_walk);
    for (int i = 0; i < 9; i++)
        x[i] = (rng_unit() - 0.5) * 1e6;
    check_against_brute(NV, x, NT, tri, false, "soup with huge triangles");

    /* the oracle as brute force on a smaller soup */
    make_soup(60, x, 70, tri, coord_int);
    check_against_brute(60, x, 70, tri, true, "integer soup against the oracle");
    make_soup(60, x, 70, tri, coord_walk);
    check_against_brute(60, x, 70, tri, true, "walk soup against the oracle");

    free(x);
    free(tri);
}

/* ------------------------------------------------------------- sheets */

/* An (nu x nv)-cell grid sheet, vertex (i, j) at index j * (nu + 1) + i,
 * cell (i, j) split along its (i, j)-(i+1, j+1) diagonal into
 * (i,j)(i+1,j)(i+1,j+1) and (i,j)(i+1,j+1)(i,j+1). place() maps (u, v) to
 * space. */
typedef struct sheet {
    int nv, nt;
    double *x;
    int *tri;
} sheet;

static sheet make_sheet(int nu, int nvv, void (*place)(double u, double v, double out[3], void *),
                        void *ctx)
{
    sheet s;
    s.nv = (nu + 1) * (nvv + 1);
    s.nt = 2 * nu * nvv;
    s.x = malloc((size_t)s.nv * 3 * sizeof *s.x);
    s.tri = malloc((size_t)s.nt * 3 * sizeof *s.tri);
    assert_non_null(s.x);
    assert_non_null(s.tri);
    for (int j = 0; j <= nvv; j++)
        for (int i = 0; i <= nu; i++)
            place(i, j, s.x + 3 * (j * (nu + 1) + i), ctx);
    int t = 0;
    for (int j = 0; j < nvv; j++)
        for (int i = 0; i < nu; i++) {
            int a = j * (nu + 1) + i, b = a + 1, c = a + nu + 2, d = a + nu + 1;
            int *f = s.tri + 3 * t;
            f[0] = a, f[1] = b, f[2] = c;
            f[3] = a, f[4] = c, f[5] = d;
            t += 2;
        }
    return s;
}

static void free_sheet(sheet *s)
{
    free(s->x);
    free(s->tri);
}

static void place_flat(double u, double v, double out[3], void *ctx)
{
    const double *rot = ctx;   /* a 3x3 matrix or NULL */
    double p[3] = {u * 0.1, v * 0.1, 0.0};
    if (!rot) {
        memcpy(out, p, sizeof p);
        return;
    }
    for (int k = 0; k < 3; k++)
        out[k] = rot[3 * k] * p[0] + rot[3 * k + 1] * p[1] + rot[3 * k + 2] * p[2] + 0.3;
}

static void test_flat_sheet(void **state)
{
    (void)state;
    sheet s = make_sheet(40, 30, place_flat, NULL);
    assert_int_equal(cs_count_intersections(s.nv, s.x, s.nt, s.tri), 0);
    free_sheet(&s);
    /* rotated (rounded coordinates, nearly coplanar neighbours) */
    double c = cos(0.7), sn = sin(0.7), c2 = cos(0.3), s2 = sin(0.3);
    double rot[9] = {c, -sn * c2, sn * s2, sn, c * c2, -c * s2, 0, s2, c2};
    s = make_sheet(40, 30, place_flat, rot);
    assert_int_equal(cs_count_intersections(s.nv, s.x, s.nt, s.tri), 0);
    free_sheet(&s);
}

/* The folded sheet, u in [0, 12] and v in [0, M]:
 *   panel 1, u <= 6:      (u, v, 0)
 *   panel 2, 6 <= u <= 9: (6, v, u - 6)               straight up
 *   panel 3, u >= 9:      (15 - u, v, 3 - 2 (u - 9))  back down through panel 1
 * Panel 3 crosses z = 0 at u = 10.5, above x = 4.5: the line L = {x = 4.5,
 * z = 0}. Only column 4 of panel 1 and column 10 of panel 3 meet L, each
 * cutting it into 2M intervals [m/2, (m+1)/2] in y (the diagonals cross the
 * mid-column at half-integers). Two triangles meet iff their intervals do,
 * iff |m - n| <= 1: 2M + 2 (2M - 1) = 6M - 2 pairs, touching ones included.
 * Panels meet nowhere else except along the folds, where only triangles
 * sharing a vertex touch. All coordinates are small integers: exact. */
typedef struct fold_map {
    double scale;     /* a power of two */
    double shift[3];  /* integers */
    int swap;         /* permute axes */
    const double *rot;
} fold_map;

static void place_folded(double u, double v, double out[3], void *ctx)
{
    const fold_map *m = ctx;
    double p[3];
    if (u <= 6) {
        p[0] = u, p[1] = v, p[2] = 0;
    } else if (u <= 9) {
        p[0] = 6, p[1] = v, p[2] = u - 6;
    } else {
        p[0] = 15 - u, p[1] = v, p[2] = 3 - 2 * (u - 9);
    }
    if (m && m->rot) {
        double r[3];
        for (int k = 0; k < 3; k++)
            r[k] = m->rot[3 * k] * p[0] + m->rot[3 * k + 1] * p[1] + m->rot[3 * k + 2] * p[2];
        memcpy(p, r, sizeof r);
    }
    if (m && m->swap) {
        double t = p[0];
        p[0] = p[2], p[2] = p[1], p[1] = t;
    }
    for (int k = 0; k < 3; k++)
        out[k] = m ? (p[k] + m->shift[k]) * m->scale : p[k];
}

static void test_folded_sheet(void **state)
{
    (void)state;
    const int M = 10;
    sheet s = make_sheet(12, M, place_folded, NULL);
    long want = 6 * M - 2;
    int pairs[40];
    long n = cs_find_intersections(s.nv, s.x, s.nt, s.tri, 20, pairs);
    assert_int_equal(n, want);
    /* the listed pairs are ordered and are panel 1 column 4 against
     * panel 3 column 10 */
    for (int k = 0; k < 20; k++) {
        int i = pairs[2 * k], j = pairs[2 * k + 1];
        assert_true(i < j);
        if (k > 0)
            assert_true(pairs[2 * k - 2] < i || (pairs[2 * k - 2] == i && pairs[2 * k - 1] < j));
        int ci = (i / 2) % 12, cj = (j / 2) % 12;
        assert_true((ci == 4 && cj == 10) || (ci == 10 && cj == 4));
    }
    check_against_brute(s.nv, s.x, s.nt, s.tri, false, "folded sheet");
    free_sheet(&s);

    /* exact transforms keep the exact count: scale by powers of two
     * (huge and tiny), integer shifts, axis permutation */
    static const double scales[] = {0x1p-3, 0x1p990, 0x1p-1060};
    for (int k = 0; k < 3; k++) {
        fold_map m = {scales[k], {-7, 3, 11}, k % 2, NULL};
        s = make_sheet(12, M, place_folded, &m);
        assert_int_equal(cs_count_intersections(s.nv, s.x, s.nt, s.tri), want);
        free_sheet(&s);
    }
    /* a rotation rounds the coordinates: the robust pairs (|m - n| = 0)
     * stay, touching ones may come or go */
    double c = cos(0.4), sn = sin(0.4);
    double rot[9] = {c, 0, sn, 0, 1, 0, -sn, 0, c};
    fold_map m = {1.0, {0, 0, 0}, 0, rot};
    s = make_sheet(12, M, place_folded, &m);
    n = cs_count_intersections(s.nv, s.x, s.nt, s.tri);
    assert_true(n >= 2 * M && n <= want);
    check_against_brute(s.nv, s.x, s.nt, s.tri, false, "rotated folded sheet");
    free_sheet(&s);
}

/* Two halves stacked: u in [0, m] at z = 0, the column u in [m, m + 1] is
 * the fold (height delta), u >= m + 1 lies at z = delta right above the
 * first half, mirrored. delta > 0: no pair intersects. delta = 0: the
 * halves coincide. */
static double stack_delta;
static int stack_m;
static void place_stacked(double u, double v, double out[3], void *ctx)
{
    (void)ctx;
    if (u <= stack_m) {
        out[0] = u * 0.25, out[1] = v * 0.25, out[2] = 0;
    } else {
        out[0] = (2 * stack_m + 1 - u) * 0.25, out[1] = v * 0.25, out[2] = stack_delta;
    }
}

static void test_stacked_sheet(void **state)
{
    (void)state;
    stack_m = 15;
    static const double deltas[] = {1e-9, 0x1p-52, 1e-300, 0x1p-1074};
    for (int k = 0; k < 4; k++) {
        stack_delta = deltas[k];
        sheet s = make_sheet(2 * stack_m + 1, 16, place_stacked, NULL);
        long n = cs_count_intersections(s.nv, s.x, s.nt, s.tri);
        if (n != 0)
            fail_msg("stacked at %g: %ld intersecting pairs, expected 0", stack_delta, n);
        free_sheet(&s);
    }
    /* delta = 0: the halves coincide */
    stack_delta = 0;
    sheet s = make_sheet(2 * stack_m + 1, 16, place_stacked, NULL);
    long touching = cs_count_intersections(s.nv, s.x, s.nt, s.tri);
    assert_true(touching > 2 * stack_m * 16);
    for (int i = 0; i < s.nv; i++)
        if (s.x[3 * i] != 0 && i % (2 * stack_m + 2) > stack_m)
            s.x[3 * i + 2] = ulps(0.0, 1 + rng_int(3));
    /* vertices of the upper half now sit 1-3 subnormal ulps above z = 0,
     * except those over x = 0 which stay at 0 and touch the lower half */
    long n = cs_count_intersections(s.nv, s.x, s.nt, s.tri);
    assert_true(n > 0 && n < touching);
    check_against_brute(s.nv, s.x, s.nt, s.tri, false, "wavy stacked sheet");
    free_sheet(&s);
}

/* ------------------------------------------------------------- timing */

static void place_crumpled(double u, double v, double out[3], void *ctx)
{
    (void)ctx;
    /* a sheet rolled into a three-turn spiral with wrinkles: many close,
     * nearly parallel layers */
    double s = u / 100.0, t = v / 100.0;
    double theta = 6 * M_PI * s;
    double r = 0.5 - 0.12 * theta / (2 * M_PI);
    r += 0.004 * sin(40 * s) * cos(25 * t);
    out[0] = r * cos(theta);
    out[1] = t + 0.01 * sin(30 * s);
    out[2] = r * sin(theta);
}

static void test_crumpled_sheet_timing(void **state)
{
    (void)state;
    sheet s = make_sheet(100, 100, place_crumpled, NULL);
    assert_int_equal(s.nt, 20000);
    double t0 = now_seconds();
    long n = cs_count_intersections(s.nv, s.x, s.nt, s.tri);
    double t1 = now_seconds();
    print_message("crumpled sheet: %d triangles, %ld intersecting pairs, %.3f s\n", s.nt, n,
                  t1 - t0);
    assert_true(n >= 0);
    /* push one row of vertices out through the next layer (radius doubled,
     * more than the 0.12 between layers): now some intersect */
    for (int i = 0; i <= 100; i++) {
        s.x[3 * (50 * 101 + i) + 0] *= 2;
        s.x[3 * (50 * 101 + i) + 2] *= 2;
    }
    long m = cs_count_intersections(s.nv, s.x, s.nt, s.tri);
    print_message("crumpled sheet, one row pushed out: %ld intersecting pairs\n", m);
    assert_true(m > n);
    free_sheet(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_broad_phase_against_brute_force),
        cmocka_unit_test(test_flat_sheet),
        cmocka_unit_test(test_folded_sheet),
        cmocka_unit_test(test_stacked_sheet),
        cmocka_unit_test(test_crumpled_sheet_timing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
