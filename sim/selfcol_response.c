/* selfcol_response.c: one pair's response (Section 5), for B.2, B.8 and
 * step C: the pair's frame (weights, normal and signed distance, with the
 * history rule), the tests of whether it is near, and the inelastic,
 * elastic and friction impulses. */
#include <math.h>
#include <string.h>

#include "sim/ccd.h"
#include "sim/selfcol_private.h"
#include "sim/vec3.h"

/* Eq. 1: the elastic repulsion impulse is at most m (0.1 d / dt - v_N),
 * enough to close a tenth of the overlap d in one step */
static const double REPULSION_CLOSING = 0.1;

/* ----------------------------------------------------------- geometry */

/* The relative position of a pair as sum_k c_k x_k, its unit normal and
 * signed distance along it, at positions x. Returns false where the pair
 * has no usable normal (a degenerate triangle). For edge/edge pairs the
 * normal follows the history rule: the shortest vector s is flipped when
 * s0 . s < epsilon (the edges have passed through each other). */
static bool pair_frame(const cs_pair *p, bool is_edge, const double *x, double epsilon,
                       double c[4], double n[3], double *dist, double *signed_dist)
{
    const double *a = x + 3 * p->v[0], *b = x + 3 * p->v[1], *cc = x + 3 * p->v[2],
                 *d = x + 3 * p->v[3];
    if (!is_edge) {
        double w[3], e1[3], e2[3];
        *dist = cs_point_triangle_closest(d, a, b, cc, w);
        cs_sub(b, a, e1);
        cs_sub(cc, a, e2);
        cs_cross(e1, e2, n);
        double len = cs_norm(n);
        if (!(len > 1e-14 * (cs_dot(e1, e1) + cs_dot(e2, e2))))
            return false;
        for (int k = 0; k < 3; k++)
            n[k] /= len;
        c[0] = -w[0], c[1] = -w[1], c[2] = -w[2], c[3] = 1;
        double rel[3] = {0, 0, 0};
        for (int k = 0; k < 4; k++)
            cs_axpy(c[k], x + 3 * p->v[k], rel);
        *signed_dist = cs_dot(rel, n);
        return true;
    }
    double s, t;
    *dist = cs_segment_segment_closest(a, b, cc, d, &s, &t);
    c[0] = -(1 - s), c[1] = -s, c[2] = 1 - t, c[3] = t;
    double rel[3] = {0, 0, 0};
    for (int k = 0; k < 4; k++)
        cs_axpy(c[k], x + 3 * p->v[k], rel);
    double len = cs_norm(rel);
    if (len > 1e-12 * (*dist + 1e-300) && len > 0) {
        for (int k = 0; k < 3; k++)
            n[k] = rel[k] / len;
    } else {
        memcpy(n, p->s0, 3 * sizeof *n); /* touching: the history knows the side */
    }
    if (cs_dot(n, p->s0) < epsilon) {
        for (int k = 0; k < 3; k++)
            n[k] = -n[k];
        *signed_dist = -len;
    } else {
        *signed_dist = len;
    }
    return true;
}

double sc_pair_inverse_mass(const cs_selfcol *sc, const cs_pair *p, const double c[4])
{
    double s = 0;
    for (int k = 0; k < 4; k++)
        s += c[k] * c[k] * sc->inv_mass[p->v[k]];
    return s;
}

/* An impulse J on the pair's relative motion changes vertex k's velocity
 * by c_k J / m_k and the relative velocity by J inv_m, so vertex k moves
 * |c_k| / (m_k inv_m) times the relative change: at most 1 when the four
 * are free and of one mass, but 1 / |c_k| when the others are held (pins,
 * scripts) or far heavier. Stopping an approach at an edge's held end
 * through a free vertex of weight 1e-8 gave that vertex 8e14 m/s. Past
 * SC_MAX_LEVERAGE the impulse stops only part of the approach: later
 * passes and, in step C, impact zones do the rest, as for any pair that
 * its impulses cannot separate. */
#define SC_MAX_LEVERAGE 4.0

double sc_pair_impulse_inverse_mass(const cs_selfcol *sc, const cs_pair *p, const double c[4],
                                    double inv_m)
{
    double lever = 0;
    for (int k = 0; k < 4; k++)
        lever = fmax(lever, fabs(c[k]) * sc->inv_mass[p->v[k]]);
    return fmax(inv_m, lever / SC_MAX_LEVERAGE);
}

double sc_pair_normal_velocity(const cs_pair *p, const double c[4], const double *v,
                               const double n[3], double rel[3])
{
    rel[0] = rel[1] = rel[2] = 0;
    for (int k = 0; k < 4; k++)
        cs_axpy(c[k], v + 3 * p->v[k], rel);
    return cs_dot(rel, n);
}

/* v_k += c_k J / m_k dir: an impulse J on the pair's relative motion */
void sc_pair_impulse(const cs_selfcol *sc, const cs_pair *p, const double c[4], double J,
                     const double dir[3], double *v)
{
    for (int k = 0; k < 4; k++)
        cs_axpy(c[k] * J * sc->inv_mass[p->v[k]], dir, v + 3 * p->v[k]);
}

/* ------------------------------------------------- pair response, once */

/* Whether the boxes of a pair's two sides (vertices [0, split) and
 * [split, 4) at positions p[k]) are more than gap apart along an axis:
 * then the sides are farther apart than gap. */
bool sc_sides_apart(const double *const p[4], int split, double gap)
{
    for (int d = 0; d < 3; d++) {
        double lo_a = INFINITY, hi_a = -INFINITY, lo_b = INFINITY, hi_b = -INFINITY;
        for (int k = 0; k < 4; k++) {
            double c = p[k][d];
            if (k < split) {
                lo_a = c < lo_a ? c : lo_a;
                hi_a = c > hi_a ? c : hi_a;
            } else {
                lo_b = c < lo_b ? c : lo_b;
                hi_b = c > hi_b ? c : hi_b;
            }
        }
        if (lo_a - hi_b > gap || lo_b - hi_a > gap)
            return true;
    }
    return false;
}

/* The per-step prune of Section 5: step A keeps pairs generously, so most
 * are not interacting now; a box test thickened by the thickness settles
 * that cheaply. */
static bool pair_near(const cs_pair *p, bool is_edge, const double *x, double thickness)
{
    const double *const pts[4] = {x + 3 * p->v[0], x + 3 * p->v[1], x + 3 * p->v[2],
                                  x + 3 * p->v[3]};
    return !sc_sides_apart(pts, is_edge ? 2 : 3, thickness);
}

/* Bridson's proximity condition for a repulsion: a point/triangle pair
 * only where the point projects inside the triangle (within the thickness
 * over the triangle's size), an edge/edge pair only where the closest
 * points are inside both edges. Elsewhere the other kind of pair is the
 * right one; without this, in-plane neighbours closer than the thickness
 * would push each other out of a flat sheet along its normal. */
static bool pair_interior(const cs_pair *p, bool is_edge, const double *x, const double c[4],
                          double thickness)
{
    if (is_edge) { /* closest points clamped to an end: a point's business */
        double s = -c[1], t = c[3];
        return s > 0 && s < 1 && t > 0 && t < 1;
    }
    /* barycentric weights of the projection onto the plane, unclamped */
    const double *a = x + 3 * p->v[0], *b = x + 3 * p->v[1], *cc = x + 3 * p->v[2],
                 *q = x + 3 * p->v[3];
    double e1[3], e2[3], r[3], n[3];
    cs_sub(b, a, e1);
    cs_sub(cc, a, e2);
    cs_sub(q, a, r);
    cs_cross(e1, e2, n);
    double nn = cs_dot(n, n);
    if (!(nn > 0))
        return false;
    double t1[3], t2[3];
    cs_cross(r, e2, t1);
    cs_cross(e1, r, t2);
    double w1 = cs_dot(t1, n) / nn, w2 = cs_dot(t2, n) / nn, w0 = 1 - w1 - w2;
    double tol = thickness / sqrt(sqrt(nn)); /* thickness over the triangle's size */
    return w0 > -tol && w1 > -tol && w2 > -tol;
}

/* Applies one pair's response to velocities v at positions x; returns true
 * if it interacted. Inelastic: I = m v_N stops approach; elastic: Eq. 1
 * with d from Eq. 2 (larger when the pair has crossed, so it pulls back);
 * friction: Coulomb with the normal velocity change. */
bool sc_pair_respond(const cs_selfcol *sc, const cs_pair *p, bool is_edge, const double *x,
                     double *v, const response *r)
{
    if (!pair_near(p, is_edge, x, r->thickness))
        return false;
    double c[4], n[3], dist, sd;
    if (!pair_frame(p, is_edge, x, r->epsilon, c, n, &dist, &sd))
        return false;
    if (!(dist < r->thickness) || !pair_interior(p, is_edge, x, c, r->thickness))
        return false;
    double inv_m = sc_pair_inverse_mass(sc, p, c);
    if (!(inv_m > 0))
        return false;
    double inv_j = sc_pair_impulse_inverse_mass(sc, p, c, inv_m), rel[3];
    double vn = sc_pair_normal_velocity(p, c, v, n, rel), dvn = 0;
    if (r->inelastic && vn < 0) {
        sc_pair_impulse(sc, p, c, -vn / inv_j, n, v);
        dvn = -vn * (inv_m / inv_j);
        vn += dvn;
    }
    if (r->elastic) {
        double d = r->thickness - sd;
        double J = fmin(r->dt * r->k * d, (REPULSION_CLOSING * d / r->dt - vn) / inv_j);
        if (J > 0) {
            sc_pair_impulse(sc, p, c, J, n, v);
            dvn += J * inv_m;
        }
    }
    if (r->friction && dvn > 0 && r->mu > 0) {
        double vt[3];
        for (int k = 0; k < 3; k++)
            vt[k] = rel[k] - (cs_dot(rel, n)) * n[k];
        double speed = cs_norm(vt);
        if (speed > 0) {
            double drop = fmin(r->mu * dvn, speed);
            double dir[3] = {vt[0] / speed, vt[1] / speed, vt[2] / speed};
            sc_pair_impulse(sc, p, c, -drop / inv_j, dir, v);
        }
    }
    return true;
}

/* Which side of a plane (normal nrm) a point belongs on when it lies in
 * the plane itself: the side its own cloth is on, judged by its neighbours
 * along edges. Zero when that says nothing either (a lone particle, or a
 * cloth lying in the plane). */
double sc_ring_side(const cs_selfcol *sc, const double *x, int point, const double nrm[3])
{
    double side = 0;
    for (int k = sc->ring_start[point]; k < sc->ring_start[point + 1]; k++) {
        double r[3];
        cs_sub(x + 3 * sc->ring[k], x + 3 * point, r);
        side += cs_dot(r, nrm);
    }
    return side;
}
