/* predicates.c: exact signs of orient3d and orient2d.
 *
 * Method (three tiers, each exact where it answers):
 *
 * 1. Floating-point filter (Shewchuk 1997, "Adaptive precision floating-point
 *    arithmetic and fast robust geometric predicates", stage A). The
 *    determinant is evaluated in doubles together with its permanent (the
 *    same expression with every term made positive). Shewchuk proves
 *    |det_computed - det_exact| <= (7 + 56 eps) eps * permanent for orient3d
 *    and (3 + 16 eps) eps * permanent for orient2d, eps = 2^-53, provided
 *    no operation overflows or underflows. We make that proviso true: the
 *    filter runs only when every coordinate difference is zero or of
 *    magnitude in [2^-300, 2^300], so each product of two or three
 *    differences is a normal double (or exactly zero) and sums of such stay
 *    below 2^910. When |det| exceeds the bound its sign is the exact sign;
 *    a zero permanent means every term has an exactly-zero factor, so the
 *    determinant is exactly zero.
 *
 * 2. Exact expansion arithmetic (Shewchuk's nonoverlapping expansions).
 *    Each difference a - d is split exactly into two doubles by two_diff,
 *    each product exactly into two by two_product (fma gives the rounding
 *    error of a*b exactly), and sums of expansions are merged with two_sum
 *    (fast_expansion_sum_zeroelim, round-to-nearest-even assumed, which
 *    IEEE doubles on every supported target give). The expansion's sign is
 *    that of its largest component. This is exact when nothing underflows
 *    or overflows: with every coordinate zero or of magnitude in
 *    [2^-300, 2^300], each coordinate is a multiple of 2^-352, every
 *    component of a product of three is a multiple of 2^-1056 (above the
 *    2^-1074 subnormal grain) and below 2^910.
 *
 *    Coordinates outside that range are first scaled by one power of two,
 *    exactly, when that brings them all inside (the determinant's sign does
 *    not change).
 *
 * 3. GMP rationals when even that fails (nonzero coordinates more than
 *    2^598 apart in one predicate, such as 1e-310 next to 1):
 *    mpq_set_d converts a double exactly, and rational arithmetic is exact.
 *    Rare in practice, so its cost does not matter.
 *
 * The compiler must not contract a*b+c into an fma in the filter (it would
 * change the rounding the bound was proved for): GCC in ISO C mode does
 * not, and every product is a separate statement so that Clang's default
 * (contraction within one expression) cannot either.
 */
#include "sim/predicates.h"

#include <gmp.h>
#include <math.h>
#include <stdbool.h>

#define PRED_EPS 0x1p-53
#define RANGE_LO 0x1p-300
#define RANGE_HI 0x1p300

static const double o3d_bound = (7.0 + 56.0 * PRED_EPS) * PRED_EPS;
static const double o2d_bound = (3.0 + 16.0 * PRED_EPS) * PRED_EPS;

int cs_pred_in_range(double v)
{
    double m = fabs(v);
    return m == 0.0 || (m >= RANGE_LO && m <= RANGE_HI);
}

static int sign_of(double v)
{
    return (v > 0.0) - (v < 0.0);
}

/* ------------------------------------------------------------ expansions */

/* x + y == a + b exactly, x = fl(a + b). */
static inline void two_sum(double a, double b, double *x, double *y)
{
    double s = a + b;
    double bv = s - a;
    double av = s - bv;
    double br = b - bv;
    double ar = a - av;
    *x = s;
    *y = ar + br;
}

/* x + y == a - b exactly, x = fl(a - b). */
static inline void two_diff(double a, double b, double *x, double *y)
{
    double s = a - b;
    double bv = a - s;
    double av = s + bv;
    double br = bv - b;
    double ar = a - av;
    *x = s;
    *y = ar + br;
}

/* x + y == a * b exactly (no underflow), x = fl(a * b). */
static inline void two_product(double a, double b, double *x, double *y)
{
    double p = a * b;
    *x = p;
    *y = fma(a, b, -p);
}

/* h = a - b as an expansion of 1 or 2 components, smallest first. */
static int diff_exp(double a, double b, double *h)
{
    double x, y;
    two_diff(a, b, &x, &y);
    if (y == 0.0) {
        h[0] = x;
        return 1;
    }
    h[0] = y;
    h[1] = x;
    return 2;
}

/* h = b * e (Shewchuk's scale_expansion_zeroelim); h holds 2 * elen. */
static int scale_exp(int elen, const double *e, double b, double *h)
{
    double q, hh, p1, p0, sum;
    int n = 0;
    two_product(e[0], b, &q, &hh);
    if (hh != 0.0)
        h[n++] = hh;
    for (int i = 1; i < elen; i++) {
        two_product(e[i], b, &p1, &p0);
        two_sum(q, p0, &sum, &hh);
        if (hh != 0.0)
            h[n++] = hh;
        two_sum(p1, sum, &q, &hh);   /* |p1| >= |sum|: same as fast_two_sum */
        if (hh != 0.0)
            h[n++] = hh;
    }
    if (q != 0.0 || n == 0)
        h[n++] = q;
    return n;
}

/* h = e + f (Shewchuk's fast_expansion_sum_zeroelim, written so that it
 * never reads past either input); h holds elen + flen. */
static int sum_exp(int elen, const double *e, int flen, const double *f, double *h)
{
    int i = 0, j = 0, n = 0;
    double q, qn, hh, next;
#define TAKE_E (j >= flen || (i < elen && (f[j] > e[i]) == (f[j] > -e[i])))
    q = TAKE_E ? e[i++] : f[j++];
    while (i < elen || j < flen) {
        next = TAKE_E ? e[i++] : f[j++];
        two_sum(q, next, &qn, &hh);
        q = qn;
        if (hh != 0.0)
            h[n++] = hh;
    }
#undef TAKE_E
    if (q != 0.0 || n == 0)
        h[n++] = q;
    return n;
}

/* h = e * f for f of one or two components; h holds 4 * elen, tmp 4 * elen. */
static int mul_exp(int elen, const double *e, int flen, const double *f, double *h, double *tmp)
{
    if (flen == 1)
        return scale_exp(elen, e, f[0], h);
    int n0 = scale_exp(elen, e, f[0], tmp);
    int n1 = scale_exp(elen, e, f[1], tmp + 2 * elen);
    return sum_exp(n0, tmp, n1, tmp + 2 * elen, h);
}

static void negate_exp(int n, double *e)
{
    for (int i = 0; i < n; i++)
        e[i] = -e[i];
}

/* p*q - r*s for 1-2 component factors: at most 16 components. */
static int minor_exp(int pn, const double *p, int qn, const double *q,
                     int rn, const double *r, int sn, const double *s, double *h)
{
    double a[8], b[8], tmp[8];
    int na = mul_exp(pn, p, qn, q, a, tmp);
    int nb = mul_exp(rn, r, sn, s, b, tmp);
    negate_exp(nb, b);
    return sum_exp(na, a, nb, b, h);
}

int cs_orient3d_expansion(const double a[3], const double b[3], const double c[3],
                          const double d[3])
{
    double ad[3][2], bd[3][2], cd[3][2];
    int an[3], bn[3], cn[3];
    for (int k = 0; k < 3; k++) {
        an[k] = diff_exp(a[k], d[k], ad[k]);
        bn[k] = diff_exp(b[k], d[k], bd[k]);
        cn[k] = diff_exp(c[k], d[k], cd[k]);
    }
    /* adz (bdx cdy - cdx bdy) + bdz (cdx ady - adx cdy) + cdz (adx bdy - bdx ady) */
    double m[16], t1[64], t2[64], t3[64], s12[128], det[192], tmp[64];
    int nm, n1, n2, n3, n12, nd;
    nm = minor_exp(bn[0], bd[0], cn[1], cd[1], cn[0], cd[0], bn[1], bd[1], m);
    n1 = mul_exp(nm, m, an[2], ad[2], t1, tmp);
    nm = minor_exp(cn[0], cd[0], an[1], ad[1], an[0], ad[0], cn[1], cd[1], m);
    n2 = mul_exp(nm, m, bn[2], bd[2], t2, tmp);
    nm = minor_exp(an[0], ad[0], bn[1], bd[1], bn[0], bd[0], an[1], ad[1], m);
    n3 = mul_exp(nm, m, cn[2], cd[2], t3, tmp);
    n12 = sum_exp(n1, t1, n2, t2, s12);
    nd = sum_exp(n12, s12, n3, t3, det);
    return sign_of(det[nd - 1]);
}

int cs_orient2d_expansion(const double a[2], const double b[2], const double c[2])
{
    double acx[2], acy[2], bcx[2], bcy[2], det[16];
    int nax = diff_exp(a[0], c[0], acx), nay = diff_exp(a[1], c[1], acy);
    int nbx = diff_exp(b[0], c[0], bcx), nby = diff_exp(b[1], c[1], bcy);
    int nd = minor_exp(nax, acx, nby, bcy, nay, acy, nbx, bcx, det);
    return sign_of(det[nd - 1]);
}

/* ------------------------------------------------------------------- GMP */

/* r = x - y exactly, for doubles x and y. */
static void diff_q(mpq_t r, double x, double y, mpq_t tmp)
{
    mpq_set_d(r, x);
    mpq_set_d(tmp, y);
    mpq_sub(r, r, tmp);
}

int cs_orient3d_gmp(const double a[3], const double b[3], const double c[3], const double d[3])
{
    mpq_t ad[3], bd[3], cd[3], m, p, det, tmp;
    mpq_inits(m, p, det, tmp, NULL);
    for (int k = 0; k < 3; k++) {
        mpq_inits(ad[k], bd[k], cd[k], NULL);
        diff_q(ad[k], a[k], d[k], tmp);
        diff_q(bd[k], b[k], d[k], tmp);
        diff_q(cd[k], c[k], d[k], tmp);
    }
    /* det = sum over the z column of z * (2x2 minor of x and y) */
    mpq_t *z[3] = {&ad[2], &bd[2], &cd[2]};
    mpq_t *px[3] = {&bd[0], &cd[0], &ad[0]}, *qy[3] = {&cd[1], &ad[1], &bd[1]};
    mpq_t *rx[3] = {&cd[0], &ad[0], &bd[0]}, *sy[3] = {&bd[1], &cd[1], &ad[1]};
    for (int k = 0; k < 3; k++) {
        mpq_mul(m, *px[k], *qy[k]);
        mpq_mul(p, *rx[k], *sy[k]);
        mpq_sub(m, m, p);
        mpq_mul(m, m, *z[k]);
        mpq_add(det, det, m);
    }
    int s = mpq_sgn(det);
    for (int k = 0; k < 3; k++)
        mpq_clears(ad[k], bd[k], cd[k], NULL);
    mpq_clears(m, p, det, tmp, NULL);
    return s;
}

int cs_orient2d_gmp(const double a[2], const double b[2], const double c[2])
{
    mpq_t acx, acy, bcx, bcy, tmp;
    mpq_inits(acx, acy, bcx, bcy, tmp, NULL);
    diff_q(acx, a[0], c[0], tmp);
    diff_q(acy, a[1], c[1], tmp);
    diff_q(bcx, b[0], c[0], tmp);
    diff_q(bcy, b[1], c[1], tmp);
    mpq_mul(acx, acx, bcy);
    mpq_mul(acy, acy, bcx);
    int s = mpq_cmp(acx, acy);
    mpq_clears(acx, acy, bcx, bcy, tmp, NULL);
    return (s > 0) - (s < 0);
}

/* ------------------------------------------------------------ the filter */

/* The expansion tier needs every coordinate zero or in [2^-300, 2^300].
 * Uniformly tiny or huge inputs get there by one exact scaling with a power
 * of two (the signs of both determinants are invariant under it); only a
 * spread of more than 2^598 between nonzero coordinates needs GMP. */
enum { SCALE_NONE, SCALE_DONE, SCALE_ZERO, SCALE_WIDE };

static int exact_scale(const double *const *pts, int n, int dim, double out[][3])
{
    bool in_range = true, any = false;
    int emin = 0, emax = 0;
    for (int i = 0; i < n; i++)
        for (int k = 0; k < dim; k++) {
            double v = pts[i][k];
            in_range = in_range && cs_pred_in_range(v);
            if (v == 0.0)
                continue;
            int e = ilogb(v);
            emin = any ? (e < emin ? e : emin) : e;
            emax = any ? (e > emax ? e : emax) : e;
            any = true;
        }
    if (!any)
        return SCALE_ZERO;
    if (in_range)
        return SCALE_NONE;
    if (emax - emin > 598)
        return SCALE_WIDE;
    int shift = -300 - emin;   /* smallest lands on 2^-300, largest below 2^299 */
    for (int i = 0; i < n; i++)
        for (int k = 0; k < dim; k++)
            out[i][k] = ldexp(pts[i][k], shift);
    return SCALE_DONE;
}

int cs_orient3d(const double a[3], const double b[3], const double c[3], const double d[3])
{
    double adx = a[0] - d[0], bdx = b[0] - d[0], cdx = c[0] - d[0];
    double ady = a[1] - d[1], bdy = b[1] - d[1], cdy = c[1] - d[1];
    double adz = a[2] - d[2], bdz = b[2] - d[2], cdz = c[2] - d[2];
    if (cs_pred_in_range(adx) && cs_pred_in_range(bdx) && cs_pred_in_range(cdx) &&
        cs_pred_in_range(ady) && cs_pred_in_range(bdy) && cs_pred_in_range(cdy) &&
        cs_pred_in_range(adz) && cs_pred_in_range(bdz) && cs_pred_in_range(cdz)) {
        double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
        double cdxady = cdx * ady, adxcdy = adx * cdy;
        double adxbdy = adx * bdy, bdxady = bdx * ady;
        double t1 = bdxcdy - cdxbdy, t2 = cdxady - adxcdy, t3 = adxbdy - bdxady;
        double u1 = adz * t1, u2 = bdz * t2, u3 = cdz * t3;
        double det = u1 + u2;
        det = det + u3;
        double p1 = fabs(bdxcdy) + fabs(cdxbdy);
        double p2 = fabs(cdxady) + fabs(adxcdy);
        double p3 = fabs(adxbdy) + fabs(bdxady);
        double q1 = p1 * fabs(adz), q2 = p2 * fabs(bdz), q3 = p3 * fabs(cdz);
        double permanent = q1 + q2;
        permanent = permanent + q3;
        if (permanent == 0.0)
            return 0;
        double errbound = o3d_bound * permanent;
        if (det > errbound || -det > errbound)
            return sign_of(det);
    }
    const double *in[4] = {a, b, c, d};
    double sc[4][3];
    int s = exact_scale(in, 4, 3, sc);
    if (s == SCALE_ZERO)
        return 0;
    if (s == SCALE_NONE)
        return cs_orient3d_expansion(a, b, c, d);
    if (s == SCALE_DONE)
        return cs_orient3d_expansion(sc[0], sc[1], sc[2], sc[3]);
    return cs_orient3d_gmp(a, b, c, d);
}

int cs_orient2d(const double a[2], const double b[2], const double c[2])
{
    double acx = a[0] - c[0], bcx = b[0] - c[0];
    double acy = a[1] - c[1], bcy = b[1] - c[1];
    if (cs_pred_in_range(acx) && cs_pred_in_range(bcx) && cs_pred_in_range(acy) &&
        cs_pred_in_range(bcy)) {
        double left = acx * bcy, right = acy * bcx;
        double det = left - right;
        double detsum = fabs(left) + fabs(right);
        if (detsum == 0.0)
            return 0;
        double errbound = o2d_bound * detsum;
        if (det > errbound || -det > errbound)
            return sign_of(det);
    }
    const double *in[3] = {a, b, c};
    double sc[3][3];
    int s = exact_scale(in, 3, 2, sc);
    if (s == SCALE_ZERO)
        return 0;
    if (s == SCALE_NONE)
        return cs_orient2d_expansion(a, b, c);
    if (s == SCALE_DONE)
        return cs_orient2d_expansion(sc[0], sc[1], sc[2]);
    return cs_orient2d_gmp(a, b, c);
}
