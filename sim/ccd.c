/* ccd.c: the coplanarity cubic and closest-point kernels. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "sim/ccd.h"
#include "sim/vec3.h"

/* Times sampled when the coplanarity cubic vanishes identically: the
 * pair moves within a plane, and a crossing between samples is caught by
 * the proximity tests at the sampled times (1/32 of the step apart). */
enum { COPLANAR_SAMPLES = 32 };

static double poly(double a, double b, double c, double d, double t)
{
    return ((a * t + b) * t + c) * t + d;
}

/* Bisection on [l, r] where f(l) and f(r) differ in sign: terminates when
 * the interval stops shrinking in double precision, so it cannot miss. */
static double bisect(double a, double b, double c, double d, double l, double r, double fl)
{
    for (int it = 0; it < 200; it++) {
        double m = 0.5 * (l + r);
        if (m <= l || m >= r)
            break;
        double fm = poly(a, b, c, d, m);
        if (fm == 0)
            return m;
        if ((fm < 0) == (fl < 0)) {
            l = m;
            fl = fm;
        } else {
            r = m;
        }
    }
    return 0.5 * (l + r);
}

/* Roots of the derivative 3a t^2 + 2b t + c strictly inside (0, 1),
 * ascending, by the cancellation-free quadratic formula. */
static int critical_points(double a, double b, double c, double *t)
{
    double A = 3 * a, B = 2 * b, C = c;
    int n = 0;
    double r[2];
    if (A == 0) {
        if (B != 0)
            r[n++] = -C / B;
    } else {
        double disc = B * B - 4 * A * C;
        if (disc >= 0) {
            double q = -0.5 * (B + copysign(sqrt(disc), B));
            r[n++] = q / A;
            r[n++] = q != 0 ? C / q : 0; /* q = 0 only if B = C = 0: double root at 0 */
        }
    }
    int m = 0;
    for (int k = 0; k < n; k++)
        if (r[k] > 0 && r[k] < 1)
            t[m++] = r[k];
    if (m == 2 && t[0] > t[1]) {
        double s = t[0];
        t[0] = t[1];
        t[1] = s;
    }
    return m;
}

int cs_cubic_roots_01(double a, double b, double c, double d, double *roots)
{
    /* round-off scale of evaluating f on [0, 1] */
    double scale = (fabs(a) + fabs(b) + fabs(c) + fabs(d)) * 8 * DBL_EPSILON;
    double knots[4];
    int nk = 0;
    knots[nk++] = 0;
    double cp[2];
    int ncp = critical_points(a, b, c, cp);
    for (int k = 0; k < ncp; k++)
        knots[nk++] = cp[k];
    knots[nk++] = 1;
    int n = 0;
    for (int k = 0; k + 1 < nk; k++) {
        double l = knots[k], r = knots[k + 1];
        double fl = poly(a, b, c, d, l), fr = poly(a, b, c, d, r);
        if (fl == 0)
            roots[n++] = l;
        else if (fr != 0 && (fl < 0) != (fr < 0))
            roots[n++] = bisect(a, b, c, d, l, r, fl);
    }
    /* ends within round-off of zero count: a touch exactly at t = 0 or 1 */
    if (fabs(d) <= scale && (n == 0 || roots[0] != 0))
        roots[n++] = 0;
    if (fabs(poly(a, b, c, d, 1)) <= scale)
        roots[n++] = 1;
    for (int k = 0; k < ncp; k++) /* grazing: a near-zero extremum */
        if (fabs(poly(a, b, c, d, cp[k])) <= scale)
            roots[n++] = cp[k];
    return n;
}

int cs_coplanarity_times(const double a[3], const double b[3], const double c[3],
                         const double d[3], const double va[3], const double vb[3],
                         const double vc[3], const double vd[3], double *times)
{
    /* positions relative to a: e(t) = e0 + t de, f(t) = ..., g(t) = ... */
    double e0[3], f0[3], g0[3], de[3], df[3], dg[3];
    cs_sub(b, a, e0);
    cs_sub(c, a, f0);
    cs_sub(d, a, g0);
    cs_sub(vb, va, de);
    cs_sub(vc, va, df);
    cs_sub(vd, va, dg);
    /* (e0 + t de) x (f0 + t df) . (g0 + t dg), expanded */
    double c00[3], c01[3], c10[3], c11[3];
    cs_cross(e0, f0, c00);
    cs_cross(e0, df, c01);
    cs_cross(de, f0, c10);
    cs_cross(de, df, c11);
    double k1[3] = {c01[0] + c10[0], c01[1] + c10[1], c01[2] + c10[2]};
    double p3 = cs_dot(c11, dg);
    double p2 = cs_dot(c11, g0) + cs_dot(k1, dg);
    double p1 = cs_dot(k1, g0) + cs_dot(c00, dg);
    double p0 = cs_dot(c00, g0);

    int n = 0;
    times[n++] = 0;
    double roots[8];
    int nr = cs_cubic_roots_01(p3, p2, p1, p0, roots);
    for (int k = 0; k < nr; k++)
        times[n++] = roots[k];
    times[n++] = 1;

    /* Identically zero to round-off: the four points move within a plane,
     * and the cubic says nothing; sample the motion instead. */
    double lengths = cs_norm(e0) + cs_norm(de) + cs_norm(f0) + cs_norm(df) + cs_norm(g0) +
                     cs_norm(dg);
    double bound = 64 * DBL_EPSILON * lengths * lengths * lengths;
    if (fabs(p0) + fabs(p1) + fabs(p2) + fabs(p3) <= bound)
        for (int k = 1; k < COPLANAR_SAMPLES && n < CS_CCD_MAX_TIMES; k++)
            times[n++] = k / (double)COPLANAR_SAMPLES;

    /* ascending, duplicates removed */
    for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && times[j - 1] > times[j]; j--) {
            double s = times[j];
            times[j] = times[j - 1];
            times[j - 1] = s;
        }
    int m = 0;
    for (int i = 0; i < n; i++)
        if (m == 0 || times[i] != times[m - 1])
            times[m++] = times[i];
    return m;
}

double cs_segment_segment_closest(const double p0[3], const double p1[3], const double q0[3],
                                  const double q1[3], double *s_out, double *t_out)
{
    double d1[3], d2[3], r[3];
    cs_sub(p1, p0, d1);
    cs_sub(q1, q0, d2);
    cs_sub(p0, q0, r);
    double a = cs_dot(d1, d1), e = cs_dot(d2, d2), f = cs_dot(d2, r);
    double s, t;
    if (a <= DBL_MIN && e <= DBL_MIN) {
        s = t = 0;
    } else if (a <= DBL_MIN) {
        s = 0;
        t = fmin(fmax(f / e, 0), 1);
    } else {
        double c = cs_dot(d1, r);
        if (e <= DBL_MIN) {
            t = 0;
            s = fmin(fmax(-c / a, 0), 1);
        } else {
            double b = cs_dot(d1, d2), denom = a * e - b * b;
            if (denom > 1e-14 * a * e) {
                s = fmin(fmax((b * f - c * e) / denom, 0), 1);
            } else {
                /* parallel: the middle of the overlap of the projections
                 * of q's ends onto p, a stable choice */
                double s0 = -c / a, s1 = (b - c) / a;
                double lo = fmax(fmin(s0, s1), 0), hi = fmin(fmax(s0, s1), 1);
                s = lo <= hi ? 0.5 * (lo + hi) : (fmin(s0, s1) > 1 ? 1 : 0);
            }
            t = (b * s + f) / e;
            if (t < 0) {
                t = 0;
                s = fmin(fmax(-c / a, 0), 1);
            } else if (t > 1) {
                t = 1;
                s = fmin(fmax((b - c) / a, 0), 1);
            }
        }
    }
    double cp[3], cq[3], diff[3];
    for (int k = 0; k < 3; k++) {
        cp[k] = p0[k] + s * d1[k];
        cq[k] = q0[k] + t * d2[k];
    }
    cs_sub(cq, cp, diff);
    *s_out = s;
    *t_out = t;
    return cs_norm(diff);
}

double cs_point_triangle_closest(const double p[3], const double a[3], const double b[3],
                                 const double c[3], double w[3])
{
    double ab[3], ac[3], ap[3], n[3];
    cs_sub(b, a, ab);
    cs_sub(c, a, ac);
    cs_sub(p, a, ap);
    cs_cross(ab, ac, n);
    double nn = cs_dot(n, n), scale = cs_dot(ab, ab) + cs_dot(ac, ac);
    if (!(nn > 1e-24 * scale * scale)) {
        /* degenerate: closest of the three edges */
        const double *v[3] = {a, b, c};
        double best = INFINITY;
        for (int k = 0; k < 3; k++) {
            double s, t, q0[3], dist;
            memcpy(q0, p, sizeof q0);
            dist = cs_segment_segment_closest(v[k], v[(k + 1) % 3], q0, q0, &s, &t);
            if (dist < best) {
                best = dist;
                w[k] = 1 - s;
                w[(k + 1) % 3] = s;
                w[(k + 2) % 3] = 0;
            }
        }
        return best;
    }
    /* Ericson, Real-Time Collision Detection 5.1.5: Voronoi regions */
    double d1 = cs_dot(ab, ap), d2 = cs_dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        w[0] = 1, w[1] = 0, w[2] = 0;
    } else {
        double bp[3], cp[3];
        cs_sub(p, b, bp);
        cs_sub(p, c, cp);
        double d3 = cs_dot(ab, bp), d4 = cs_dot(ac, bp);
        double d5 = cs_dot(ab, cp), d6 = cs_dot(ac, cp);
        double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
        if (d3 >= 0 && d4 <= d3) {
            w[0] = 0, w[1] = 1, w[2] = 0;
        } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
            double v = d1 / (d1 - d3);
            w[0] = 1 - v, w[1] = v, w[2] = 0;
        } else if (d6 >= 0 && d5 <= d6) {
            w[0] = 0, w[1] = 0, w[2] = 1;
        } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
            double v = d2 / (d2 - d6);
            w[0] = 1 - v, w[1] = 0, w[2] = v;
        } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
            double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            w[0] = 0, w[1] = 1 - v, w[2] = v;
        } else {
            double denom = 1.0 / (va + vb + vc);
            w[1] = vb * denom;
            w[2] = vc * denom;
            w[0] = 1 - w[1] - w[2];
        }
    }
    double q[3];
    for (int k = 0; k < 3; k++)
        q[k] = w[0] * a[k] + w[1] * b[k] + w[2] * c[k];
    double diff[3];
    cs_sub(p, q, diff);
    return cs_norm(diff);
}
