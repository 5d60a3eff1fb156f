/* ccd.h: continuous collision tests of Section 4, private to sim/.
 * Four points move linearly from x0 to x1 over t in [0, 1]; a point/triangle
 * or edge/edge pair can only meet when they are coplanar, i.e. at a root of
 * the cubic f(t) = (x2 - x1) x (x3 - x1) . (x4 - x1). */
#ifndef CS_CCD_H
#define CS_CCD_H

#include <stdbool.h>

/* Candidate times in [0, 1], ascending, at most CS_CCD_MAX_TIMES: every
 * sign-change root of the cubic (bisection on monotone pieces, so none is
 * missed at double precision), both endpoints, critical points where |f| is
 * within round-off of zero (grazing contacts, double roots), and, when the
 * cubic vanishes identically to round-off (motion within one plane), evenly
 * spaced samples. False candidates only cost a proximity test. */
enum { CS_CCD_MAX_TIMES = 48 };
int cs_coplanarity_times(const double a[3], const double b[3], const double c[3],
                         const double d[3], const double va[3], const double vb[3],
                         const double vc[3], const double vd[3], double *times);

/* The real roots of a t^3 + b t^2 + c t + d in [0, 1] where the polynomial
 * changes sign, plus near-zero critical points; returns the count. */
int cs_cubic_roots_01(double a, double b, double c, double d, double *roots);

/* Closest point of triangle (a, b, c) to p: barycentric weights w (sum 1,
 * each >= 0); returns the distance. Degenerate triangles are handled as
 * their longest edge. */
double cs_point_triangle_closest(const double p[3], const double a[3], const double b[3],
                                 const double c[3], double w[3]);

/* Closest points of segments (p0, p1) and (q0, q1): parameters s, t in
 * [0, 1] along each; returns the distance. Parallel segments get the middle
 * of their overlap. */
double cs_segment_segment_closest(const double p0[3], const double p1[3], const double q0[3],
                                  const double q1[3], double *s, double *t);

#endif
