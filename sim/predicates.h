/* predicates.h: exact orientation predicates for the intersection verifier
 * (sim/verify.c), and its narrow phase. Private to the library; tests
 * include it to check the arithmetic tiers against each other and the
 * narrow phase against an oracle.
 *
 * Every orientation predicate returns the exact sign (-1, 0, +1) of a determinant of
 * doubles, for any finite input: no tolerance, no "nearly zero".
 */
#ifndef CS_PREDICATES_H
#define CS_PREDICATES_H

#include <stdbool.h>

/* Sign of det[a-d; b-d; c-d]: positive when d lies below the plane of a, b,
 * c, that is when a, b, c appear clockwise seen from d (Shewchuk's
 * convention); zero when the four points are coplanar. */
int cs_orient3d(const double a[3], const double b[3], const double c[3], const double d[3]);

/* Sign of det[a-c; b-c]: positive when a, b, c turn counter-clockwise. */
int cs_orient2d(const double a[2], const double b[2], const double c[2]);

/* The tiers behind the two above, exposed for tests. The expansion tiers
 * are exact only when every coordinate is zero or of magnitude in
 * [2^-300, 2^300] (cs_pred_in_range); the GMP tiers always are. */
int cs_orient3d_expansion(const double a[3], const double b[3], const double c[3],
                          const double d[3]);
int cs_orient2d_expansion(const double a[2], const double b[2], const double c[2]);
int cs_orient3d_gmp(const double a[3], const double b[3], const double c[3], const double d[3]);
int cs_orient2d_gmp(const double a[2], const double b[2], const double c[2]);
int cs_pred_in_range(double v);

/* verify.c: the exact narrow phase alone: whether the closed triangles p
 * and q (3 vertices of 3 doubles each, possibly degenerate) intersect. */
bool cs_triangles_intersect(const double p[9], const double q[9]);

#endif
