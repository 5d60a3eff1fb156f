/* selfcol_repulsion.c: the history-based repulsions of Section 5: step A
 * finds the pairs near each other in the collision-free state, with their
 * history, and B.2 and B.8 apply them every time step in one Gauss-Seidel
 * order (cs_pairs_apply). */
#include <math.h>
#include <omp.h>
#include <string.h>

#include "sim/ccd.h"
#include "sim/selfcol_private.h"
#include "sim/vec3.h"

/* ------------------------------------------------------------- step A */

/* A point joined by edges to two of a triangle's vertices sits across an
 * edge from it: a bending wing of the mesh (or a degenerate sliver lying on
 * its neighbour). How close it is, is the bending springs' business: a
 * repulsion there would fight them. Step C still watches it. */
static bool wing_pair(const cs_selfcol *sc, int point, const int *tri)
{
    int joined = 0;
    for (int k = sc->ring_start[point]; k < sc->ring_start[point + 1]; k++) {
        int q = sc->ring[k];
        joined += q == tri[0] || q == tri[1] || q == tri[2];
    }
    return joined >= 2;
}

typedef struct finder {
    cs_sim *sim;
    cs_selfcol *sc;
    double thickness, span;
} finder;

/* Keep a pair only if it can come within the thickness during the span at
 * its present relative velocity: distance in the free state less the largest relative
 * speed between its two sides times the span. (The boxes that found it had
 * to allow for each particle's motion; a patch moving fast but rigidly,
 * like the twisted strip's ends, has little relative motion.) */
static bool may_meet(const finder *f, const int v[4], int split, double dist)
{
    const double *vel = f->sim->v;
    double rel = 0;
    for (int i = 0; i < split; i++)
        for (int j = split; j < 4; j++) {
            double d[3];
            cs_sub(vel + 3 * v[i], vel + 3 * v[j], d);
            rel = fmax(rel, cs_norm(d));
        }
    return dist < f->thickness + rel * f->span;
}

/* The makers below turn a candidate (a, b) of a traversal into a pair
 * (pair_maker, selfcol_private.h). */

/* The makers measure every pair step C could find (wings and pairs of
 * held particles too, which step A itself leaves out), for start_gap. */
static void note_distance(const finder *f, double dist)
{
    cs_made_list *mine = f->sc->made + omp_get_thread_num();
    if (!(dist >= mine->nearest)) /* NaN too: then step C skips nothing */
        mine->nearest = dist;
}

static bool make_repulsion_point_triangle(const void *ctx, int point, int t, cs_pair *out)
{
    const finder *f = ctx;
    const cs_selfcol *sc = f->sc;
    const int *tri = sc->tri + 3 * t;
    if (point == tri[0] || point == tri[1] || point == tri[2])
        return false;
    int quad[4] = {tri[0], tri[1], tri[2], point};
    if (sc_pair_rank(f->sim->par, quad) != f->sim->par->rank)
        return false; /* another rank's to find */
    const double *x = sc->x_free;
    double w[3];
    double dist = cs_point_triangle_closest(x + 3 * point, x + 3 * tri[0], x + 3 * tri[1],
                                            x + 3 * tri[2], w);
    note_distance(f, dist);
    if (wing_pair(sc, point, tri))
        return false;
    if (sc->inv_mass[point] == 0 && sc->inv_mass[tri[0]] == 0 && sc->inv_mass[tri[1]] == 0 &&
        sc->inv_mass[tri[2]] == 0)
        return false;
    int v[4] = {tri[0], tri[1], tri[2], point};
    if (!may_meet(f, v, 3, dist))
        return false;
    /* history: wind the triangle so its normal points at the free point
     * (the paper's reordering; swapping two triangle vertices flips it) */
    double e1[3], e2[3], nrm[3], r[3];
    cs_sub(x + 3 * tri[1], x + 3 * tri[0], e1);
    cs_sub(x + 3 * tri[2], x + 3 * tri[0], e2);
    cs_cross(e1, e2, nrm);
    cs_sub(x + 3 * point, x + 3 * tri[0], r);
    double side = cs_dot(nrm, r);
    if (fabs(side) <= 1e-12 * cs_norm(nrm) * (cs_norm(r) + cs_norm(e1)))
        side = sc_ring_side(sc, x, point, nrm); /* in the plane: ambiguous */
    if (side < 0) {
        v[1] = tri[2];
        v[2] = tri[1];
    }
    memcpy(out->v, v, sizeof v);
    out->s0[0] = out->s0[1] = out->s0[2] = 0;
    return true;
}

static bool make_repulsion_edge_edge(const void *ctx, int ea, int eb, cs_pair *out)
{
    const finder *f = ctx;
    const cs_selfcol *sc = f->sc;
    const int *a = sc->edge + 2 * ea, *b = sc->edge + 2 * eb;
    if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1])
        return false;
    int quad[4] = {a[0], a[1], b[0], b[1]};
    if (sc_pair_rank(f->sim->par, quad) != f->sim->par->rank)
        return false; /* another rank's to find */
    const double *x = sc->x_free;
    double s, t, s0[3];
    note_distance(f, cs_segment_segment_closest(x + 3 * a[0], x + 3 * a[1], x + 3 * b[0],
                                                x + 3 * b[1], &s, &t));
    if (sc->inv_mass[a[0]] == 0 && sc->inv_mass[a[1]] == 0 && sc->inv_mass[b[0]] == 0 &&
        sc->inv_mass[b[1]] == 0)
        return false;
    for (int k = 0; k < 3; k++)
        s0[k] = (x[3 * b[0] + k] + t * (x[3 * b[1] + k] - x[3 * b[0] + k])) -
                (x[3 * a[0] + k] + s * (x[3 * a[1] + k] - x[3 * a[0] + k]));
    double len = cs_norm(s0);
    if (!may_meet(f, quad, 2, len))
        return false;
    if (!(len > 0)) { /* touching in the free state: the edges' common normal */
        double da[3], db[3];
        cs_sub(x + 3 * a[1], x + 3 * a[0], da);
        cs_sub(x + 3 * b[1], x + 3 * b[0], db);
        cs_cross(da, db, s0);
        len = cs_norm(s0);
        if (!(len > 0))
            return false; /* parallel and touching: the point/triangle pairs decide */
    }
    memcpy(out->v, quad, sizeof quad);
    for (int k = 0; k < 3; k++)
        out->s0[k] = s0[k] / len;
    return true;
}

/* primitive k's motion boxes: the extents of its count vertices' positions
 * in x and velocities in v */
static void motion_boxes(cs_motion_boxes *m, int k, const int *vert, int count,
                         const double *x, const double *v)
{
    cs_box *bx = m->x + k, *bv = m->v + k;
    cs_box_empty(bx);
    cs_box_empty(bv);
    for (int j = 0; j < count; j++) {
        cs_box_add_point(bx, x + 3 * vert[j]);
        cs_box_add_point(bv, v + 3 * vert[j]);
    }
}

void cs_selfcol_find_pairs(cs_sim *sim, double span)
{
    cs_selfcol *sc = sim->selfcol;
    const double *x = sc->x_free; /* the same on every rank */
    cs_par_allgather(sim->par, sim->v, 3); /* velocities widen the boxes */
    double thickness = sim->def.self.thickness;
    sc->pt.n = sc->ee.n = 0;
    /* The particles' boxes (def.self.pruning). `speed`, the paper's
     * non-aggressive pruning: half the thickness plus the distance the
     * particle would cover in the span at its present velocity relative to
     * the cloth's mean velocity, along all three axes (a pair's relative
     * speed is at most the sum of its particles' speeds relative to any
     * common velocity; a pair is kept where its boxes overlap and may_meet
     * holds, whichever way sc_find_pairs took its candidates). `path`: the
     * particle's straight path relative to the mean, x + (v - mean) s for s
     * in [0, span], grown by half the thickness; if a pair's straight
     * relative path comes within the thickness at some s, the points x_a +
     * (v_a - mean) s and x_b + (v_b - mean) s are within it, so the boxes
     * overlap. A pair must pass both the boxes and may_meet, so `path`
     * drops the pairs within may_meet's reach whose straight paths miss:
     * another rule, not only a faster search (the same frames on drapes,
     * not on cloth folding onto itself; docs/performance.md, "Step A's
     * boxes along the path").
     * Either way only relative motion widens a box: a sheet
     * falling rigidly needs no wider boxes than one at rest. A pair that
     * comes closer faster than that is step C's to catch. */
    double mean[3] = {0, 0, 0};
    for (int i = 0; i < sc->n; i++)
        cs_axpy(1.0 / sc->n, sim->v + 3 * i, mean);
    bool path = sim->def.self.pruning == CS_PRUNING_PATH;
    /* the boxes: one writer each, so threads change no bit */
#pragma omp parallel for schedule(static)
    for (int i = 0; i < sc->n; i++) {
        double rel[3], end[3];
        cs_sub(sim->v + 3 * i, mean, rel);
        double *drift = sc->cache.drift + 3 * i; /* the motion over the span */
        for (int d = 0; d < 3; d++)
            drift[d] = rel[d] * span;
        cs_box_empty(sc->pbox + i);
        cs_box_add_point(sc->pbox + i, x + 3 * i);
        if (path) {
            for (int d = 0; d < 3; d++)
                end[d] = x[3 * i + d] + drift[d];
            cs_box_add_point(sc->pbox + i, end);
            cs_box_thicken(sc->pbox + i, 0.5 * thickness);
        } else {
            cs_box_thicken(sc->pbox + i, 0.5 * thickness + cs_norm(rel) * span);
        }
        motion_boxes(&sc->pmotion, i, &i, 1, x, sim->v); /* for the reach test */
    }
#pragma omp parallel for schedule(static)
    for (int k = 0; k < sc->ne; k++) {
        motion_boxes(&sc->emotion, k, sc->edge + 2 * k, 2, x, sim->v);
        cs_box *b = sc->ebox + k;
        cs_box_empty(b);
        for (int j = 0; j < 2; j++) {
            int i = sc->edge[2 * k + j];
            cs_box pb = sc->pbox[i];
            cs_box_add_point(b, pb.lo);
            cs_box_add_point(b, pb.hi);
        }
    }
#pragma omp parallel for schedule(static)
    for (int k = 0; k < sc->nt; k++) {
        motion_boxes(&sc->tmotion, k, sc->tri + 3 * k, 3, x, sim->v);
        cs_box *b = sc->tbox + k;
        cs_box_empty(b);
        for (int j = 0; j < 3; j++) {
            int i = sc->tri[3 * k + j];
            cs_box_add_point(b, sc->pbox[i].lo);
            cs_box_add_point(b, sc->pbox[i].hi);
        }
    }
    cs_reach reach = {thickness, span}, *reaching = sc->cache.reach_off ? NULL : &reach;
    finder f = {sim, sc, thickness, span};
    for (int t = 0; t < sc->nmade; t++) /* threads added by the searches start at 0 */
        sc->made[t].nearest = INFINITY;
    /* start_gap: the makers measured every pair of this rank whose boxes
     * overlap but those the skin showed farther than this; the others'
     * boxes, each at least half the thickness around its particles, lie
     * apart, so their sides are a thickness apart (less a thousandth for
     * the boxes' round-off) */
    double gap = 0.999 * thickness;
    sc_skin skin = {thickness, span, gap}, *use = sc->cache.skin_off ? NULL : &skin;
    int failed = sc_cache_update(sc, sim->par->rank, thickness, sim->v, mean, reaching) ||
                 sc_find_pairs(sc, false, false, reaching, use, make_repulsion_point_triangle, &f,
                               &sc->pt) ||
                 sc_find_pairs(sc, true, false, reaching, use, make_repulsion_edge_edge, &f, &sc->ee);
    for (int t = 0; t < sc->nmade; t++)
        if (!(sc->made[t].nearest >= gap))
            gap = sc->made[t].nearest;
    sc->start_gap = failed ? 0 : gap;
    sc->stats.repulsion_pairs += sc->pt.n + sc->ee.n;
    if (sc_distribute_boundary(sim, &sc->pt, &sc->ee) != 0)
        failed = 1;
    if (failed) /* out of memory: without pairs step C still keeps the cloth apart */
        sc->pt.n = sc->ee.n = sc->bpt.n = sc->bee.n = 0;
}

/* --------------------------------------------------------- B.2 and B.8 */

/* The one door for applying a set of pairs: Gauss-Seidel order, point/
 * triangle pairs before edge/edge pairs, each seeing the newest velocities. */
static long cs_pairs_apply(const cs_selfcol *sc, const cs_pair_list *pt, const cs_pair_list *ee,
                           const double *x, double *v, const response *r)
{
    long applied = 0;
    for (int i = 0; i < pt->n; i++)
        applied += sc_pair_respond(sc, pt->p + i, false, x, v, r);
    for (int i = 0; i < ee->n; i++)
        applied += sc_pair_respond(sc, ee->p + i, true, x, v, r);
    return applied;
}

/* Fig. 12: phase I, each rank its components of boundary pairs (their
 * particles' state brought from the owners and the new velocities sent
 * back); phase II, every rank its internal pairs. The result is that of
 * one serial Gauss-Seidel order. */
long cs_selfcol_repulse(cs_sim *sim, double *x, double *v, double dt, bool elastic)
{
    cs_selfcol *sc = sim->selfcol;
    cs_par *par = sim->par;
    const cs_self_collision_def *d = &sim->def.self;
    response r = {true, elastic, !elastic, dt, d->thickness, d->stiffness, d->friction,
                  d->edge_flip_epsilon};
    long before = sc->stats.repulsions;
    if (par->size > 1) {
        cs_halo_forward(par, &sc->bhalo, x, 3);
        cs_halo_forward(par, &sc->bhalo, v, 3);
        sc->stats.repulsions += cs_pairs_apply(sc, &sc->bpt, &sc->bee, x, v, &r);
        cs_halo_reverse(par, &sc->bhalo, v, 3);
    }
    sc->stats.repulsions += cs_pairs_apply(sc, &sc->pt, &sc->ee, x, v, &r);
    return sc->stats.repulsions - before;
}
