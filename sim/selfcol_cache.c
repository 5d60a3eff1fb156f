/* selfcol_cache.c: the candidate pairs of steps A and C kept from one
 * search to the next (a Verlet list, as molecular dynamics keeps
 * neighbours).
 *
 * A search's boxes (sc->pbox, ebox, tbox) lie around the collision-free
 * positions x_free. Box overlap does not change when every box moves by the
 * same translation, so the cache is built once from boxes grown by a slack,
 * and a later search may use it while each particle's box, moved back by
 * how far the cloth's centroid has gone, stays inside its grown box: every
 * pair whose present boxes overlap then had overlapping grown boxes. A
 * falling or sliding sheet moves nearly rigidly, so one traversal serves
 * many outer steps; each search costs a containment test per particle and
 * an overlap test per cached pair.
 *
 * A search's pairs are sorted by (a, b) (sc_find_pairs), so they come in
 * one order whatever the cache's history (when it was built, or a run
 * resumed from a checkpoint with an empty cache): the makers are exact,
 * and the present boxes, which decide with them, are tested on every
 * candidate whichever way it came (the cache, or step A's traversal within
 * reach), so the lists do not depend on the broad phase at all. */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "sim/ccd.h"
#include "sim/selfcol_private.h"
#include "sim/vec3.h"

/* The slack a rebuild grows each particle's box by, per thickness: wider
 * lives longer but holds more pairs to filter (measured on the 100 x 100
 * benchmark sheet; docs/performance.md, "Step A's pair cache"). */
static const double CACHE_SLACK_PER_THICKNESS = 0.5;
/* A particle moving relative to the cloth, whose search box reaches m past
 * half the thickness around it (its motion over the span), gets m more
 * slack: it will have moved about as far by the next search. With the fixed slack alone
 * the falling rim of a sheet landing on a ball escaped at every outer step,
 * so every search rebuilt. A particle moving more than this many thicknesses a span gets
 * none: no slack it could use would keep its list short (the damped step
 * limit's long spans), and its neighbours' lists would grow for nothing.
 * The motion slack roughly halves step A's traversals at the default step
 * and changes little at the damped limit; the frames are the same bits. */
static const double CACHE_MOTION_SLACK_MAX = 2.0;
/* The cache follows the cloth's centroid, but a sheet landing on a body
 * stops where it touches while the rest falls on: seen from the centroid,
 * the stopped part rises at the centroid's speed and left its grown box
 * within two or three outer steps. So a rebuild also reaches each box along
 * the particle's motion relative to the centroid over this many of step
 * A's spans (its drift), a forecast that holds while the relative motion
 * does: about half the traversals in the landing frames, the same bits
 * (the lists do not depend on the cache). Where motion changes faster
 * than a few spans, as in the 200 x 200 landing at the damped step limit
 * with `path` boxes (a drift of many millimetres a span, every other
 * search rebuilding whatever the boxes), longer boxes only add candidates
 * and make step A slower. So the forecast is made only when the cache it replaces served at least
 * CACHE_FORECAST_AFTER searches: the motion was steady enough for boxes to
 * last. */
static const double CACHE_FORECAST_SPANS = 8.0;
enum { CACHE_FORECAST_AFTER = 3 };
/* Where the cloth moves more between searches than any slack allows (a
 * sheet landing at the damped step limit rebuilds at most of step A's
 * searches), the slack, the motion slack and the forecast only double the
 * candidates each search filters and the traversal's work. So a cache
 * that served no more searches than this (the one that built it and step
 * C's after it) is replaced by one built from the search's own boxes; a
 * cache that then lasts (rigid motion) is replaced by a grown one again.
 * On the 100 x 100 benchmark sheet it halves the candidates; the lists do
 * not depend on the boxes, so the frames are the same bits. */
enum { CACHE_TIGHT_SERVED = 2 };
_Static_assert((int)CACHE_FORECAST_AFTER > (int)CACHE_TIGHT_SERVED, "a cache that forecasts is never tight");

static void centroid(const cs_selfcol *sc, double c[3])
{
    double s[3] = {0, 0, 0};
    for (int i = 0; i < sc->n; i++)
        for (int d = 0; d < 3; d++)
            s[d] += sc->x_free[3 * i + d];
    for (int d = 0; d < 3; d++)
        c[d] = sc->n ? s[d] / sc->n : 0;
}

/* Every present particle box, moved back by T, inside its grown box. The
 * comparison uses the rounded moved corners, and rounding is monotone, so
 * two present boxes that overlap still do once both are moved: no
 * round-off allowance is needed. */
static bool contained(const cs_selfcol *sc, const double T[3])
{
    const cs_box *grown = sc->cache.pbox;
    int inside = 1;
#pragma omp parallel for schedule(static) reduction(& : inside)
    for (int i = 0; i < sc->n; i++)
        for (int d = 0; d < 3; d++)
            inside &= sc->pbox[i].lo[d] - T[d] >= grown[i].lo[d] &&
                      sc->pbox[i].hi[d] - T[d] <= grown[i].hi[d];
    return inside;
}

/* ------------------------------------------------------------ the skin
 *
 * Step A's makers measure the exact distance of every pair whose boxes
 * overlap, and keep almost none: on the benchmark sheet in free fall tens
 * of thousands a search, all of them farther than the thickness. As
 * molecular dynamics does with a Verlet list's skin, the cache keeps each
 * pair's distance at the positions it was built from (x_ref), measured the
 * first time the pair is asked about; since then the distance changed by at
 * most how far its sides moved relative to each other, and a point of a
 * segment or triangle moves at most as far as its farthest vertex, so
 *   distance now >= distance at x_ref - moved(side A) - moved(side B),
 * with moved measured after taking out the centroid's translation (which
 * moves no distance). A pair whose bound reaches past what the makers keep
 * (thickness + relative speed * span, the speed bounded by the sum of its
 * sides' speeds relative to the mean) and past start_gap's cap is one the
 * makers would drop without lowering start_gap: skipping it changes no
 * pair and no bit. The margin is far above the distances' round-off. */
static const double SKIN_MARGIN_PER_THICKNESS = 1e-6;

static int fill_unknown(double **ref, int *cap, int n)
{
    if (n > *cap) {
        double *r = realloc(*ref, sizeof *r * (size_t)n);
        if (!r)
            return -1;
        *ref = r;
        *cap = n;
    }
#pragma omp parallel for schedule(static)
    for (int k = 0; k < n; k++)
        (*ref)[k] = NAN;
    return 0;
}

/* a rebuilt cache: x_ref is x_free, no distance measured */
static int skin_reset(cs_selfcol *sc)
{
    cs_pair_cache *c = &sc->cache;
    memcpy(c->x_ref, sc->x_free, sizeof *c->x_ref * 3 * (size_t)sc->n);
    return fill_unknown(&c->pt_ref, &c->pt_ref_cap, c->pt.n) ||
           fill_unknown(&c->ee_ref, &c->ee_ref_cap, c->ee.n);
}

/* each particle's motion since the build (the centroid now at now) */
static void skin_measure(cs_selfcol *sc, const double *v, const double mean[3],
                         const double now[3])
{
    cs_pair_cache *c = &sc->cache;
    double T[3];
    cs_sub(now, c->anchor, T);
#pragma omp parallel for schedule(static)
    for (int i = 0; i < sc->n; i++) {
        double d[3], u[3];
        for (int k = 0; k < 3; k++)
            d[k] = sc->x_free[3 * i + k] - c->x_ref[3 * i + k] - T[k];
        cs_sub(v + 3 * i, mean, u);
        double m = cs_norm(d), sp = cs_norm(u);
        c->moved[i] = m == m ? m : INFINITY; /* NaN: never far (skin_far's maxima) */
        c->speed[i] = sp == sp ? sp : INFINITY;
    }
}

/* Whether candidate k, (a, b), is shown farther than the makers keep or
 * measure; measures its distance at x_ref the first time */
static bool skin_far(cs_selfcol *sc, bool edges, int k, int a, int b, const sc_skin *skin)
{
    cs_pair_cache *c = &sc->cache;
    const double *x = c->x_ref;
    int v[4], split;
    if (edges) {
        v[0] = sc->edge[2 * a], v[1] = sc->edge[2 * a + 1];
        v[2] = sc->edge[2 * b], v[3] = sc->edge[2 * b + 1];
        split = 2;
    } else {
        v[0] = a, v[1] = sc->tri[3 * b], v[2] = sc->tri[3 * b + 1], v[3] = sc->tri[3 * b + 2];
        split = 1;
    }
    double *ref = (edges ? c->ee_ref : c->pt_ref) + k;
    if (isnan(*ref)) { /* one thread owns candidate k: no race */
        double s, t, w[3];
        *ref = edges ? cs_segment_segment_closest(x + 3 * v[0], x + 3 * v[1], x + 3 * v[2],
                                                  x + 3 * v[3], &s, &t)
                     : cs_point_triangle_closest(x + 3 * v[0], x + 3 * v[1], x + 3 * v[2],
                                                 x + 3 * v[3], w);
    }
    double moved[2] = {0, 0}, speed[2] = {0, 0}; /* (comparisons: fmax is a call) */
    for (int i = 0; i < 4; i++) {
        int side = i >= split;
        double m = c->moved[v[i]], sp = c->speed[v[i]];
        moved[side] = m > moved[side] ? m : moved[side];
        speed[side] = sp > speed[side] ? sp : speed[side];
    }
    double keep = skin->thickness + (speed[0] + speed[1]) * skin->span;
    keep = keep > skin->gap_cap ? keep : skin->gap_cap;
    return *ref - (moved[0] + moved[1]) >= keep + SKIN_MARGIN_PER_THICKNESS * skin->thickness;
}

/* Whether the cache served no more searches than CACHE_TIGHT_SERVED, this
 * one included: the one that built it and step C's after it */
static bool lasted_one_search(const cs_pair_cache *c)
{
    return c->valid && c->served <= CACHE_TIGHT_SERVED;
}

static int rebuild(cs_selfcol *sc, int rank, double thickness, const double anchor[3])
{
    cs_pair_cache *c = &sc->cache;
    bool tight = lasted_one_search(c);
    double slack = tight ? 0 : fmax(c->slack, 0) * thickness;
    bool forecast = c->valid && c->served >= CACHE_FORECAST_AFTER; /* never tight */
    /* room for step A's boxes (half the thickness around x_free, more for
     * particles moving relative to the rest) whichever search rebuilds */
#pragma omp parallel for schedule(static)
    for (int i = 0; i < sc->n; i++) {
        cs_box *b = c->pbox + i, around;
        *b = sc->pbox[i];
        cs_box_empty(&around);
        cs_box_add_point(&around, sc->x_free + 3 * i);
        cs_box_thicken(&around, 0.5 * thickness);
        cs_box_add_point(b, around.lo);
        cs_box_add_point(b, around.hi);
        /* how far the search's box reaches past half the thickness around
         * x_free: step A's margin for motion, step C's sweep */
        double moving = 0;
        for (int d = 0; d < 3; d++)
            moving = fmax(moving, fmax(sc->pbox[i].hi[d] - around.hi[d],
                                       around.lo[d] - sc->pbox[i].lo[d]));
        bool steady = !tight && moving > 0 && moving <= CACHE_MOTION_SLACK_MAX * thickness;
        if (forecast) {
            cs_box ahead = *b;
            for (int d = 0; d < 3; d++) {
                double reach = CACHE_FORECAST_SPANS * c->drift[3 * i + d];
                ahead.lo[d] += reach;
                ahead.hi[d] += reach;
            }
            cs_box_add_point(b, ahead.lo);
            cs_box_add_point(b, ahead.hi);
        }
        cs_box_thicken(b, slack + (steady ? moving : 0));
    }
#pragma omp parallel for schedule(static)
    for (int k = 0; k < sc->ne; k++) {
        cs_box *b = c->ebox + k;
        *b = c->pbox[sc->edge[2 * k]];
        cs_box_add_point(b, c->pbox[sc->edge[2 * k + 1]].lo);
        cs_box_add_point(b, c->pbox[sc->edge[2 * k + 1]].hi);
    }
#pragma omp parallel for schedule(static)
    for (int k = 0; k < sc->nt; k++) {
        cs_box *b = c->tbox + k;
        *b = c->pbox[sc->tri[3 * k]];
        for (int j = 1; j < 3; j++) {
            cs_box_add_point(b, c->pbox[sc->tri[3 * k + j]].lo);
            cs_box_add_point(b, c->pbox[sc->tri[3 * k + j]].hi);
        }
    }
    cs_bvh_refit(&sc->ptree, c->pbox);
    cs_bvh_refit(&sc->etree, c->ebox);
    cs_bvh_refit(&sc->ttree, c->tbox);
    c->valid = false;
    if (cs_bvh_collect(&sc->ptree, &sc->ttree, rank, NULL, &sc->bvh_work, &c->pt) ||
        cs_bvh_collect(&sc->etree, &sc->etree, rank, NULL, &sc->bvh_work, &c->ee))
        return -1;
    if (skin_reset(sc))
        return -1;
    memcpy(c->anchor, anchor, sizeof c->anchor);
    c->valid = true;
    c->served = 0;
    sc->stats.cache_builds++;
    return 0;
}

/* Step A's candidates within reach (cs_in_reach), from one traversal of
 * the trees refitted to the motion boxes, into sc->reach_pt and reach_ee */
static int traverse_within_reach(cs_selfcol *sc, int rank, const cs_reach *reach)
{
    if (cs_bvh_refit_motion(&sc->ptree, sc->pmotion.x, sc->pmotion.v) ||
        cs_bvh_refit_motion(&sc->etree, sc->emotion.x, sc->emotion.v) ||
        cs_bvh_refit_motion(&sc->ttree, sc->tmotion.x, sc->tmotion.v) ||
        cs_bvh_collect(&sc->ptree, &sc->ttree, rank, reach, &sc->bvh_work, &sc->reach_pt) ||
        cs_bvh_collect(&sc->etree, &sc->etree, rank, reach, &sc->bvh_work, &sc->reach_ee))
        return -1;
    sc->stats.cache_builds++;
    sc->cache.reach_traversals++;
    return 0;
}

int sc_cache_update(cs_selfcol *sc, int rank, double thickness, const double *v,
                    const double mean[3], const cs_reach *reach)
{
    double now[3], T[3];
    centroid(sc, now);
    sc->stats.cache_searches++;
    sc->cache.served++;
    sc->reached = false;
    cs_sub(now, sc->cache.anchor, T);
    bool fits = sc->cache.valid && sc->cache.slack >= 0 && contained(sc, T);
    /* A cache that lasted no longer than its own build and step C's search
     * after it would be rebuilt from this search's boxes, which grow by
     * the particles' speeds against the mean: in a landing, millions of
     * candidates that reach would drop. Step A then traverses within reach
     * (about a twentieth of the candidates, and a cheaper traversal) and
     * leaves the cache, which did not serve it, to step C, whose boxes are
     * smaller. Once step C's caches last, step A rebuilds the cache again
     * and shares it. */
    if (!fits && reach && lasted_one_search(&sc->cache)) {
        sc->cache.served--;
        sc->reached = true;
        return traverse_within_reach(sc, rank, reach);
    }
    int failed = fits ? 0 : rebuild(sc, rank, thickness, now);
    if (v && !failed)
        skin_measure(sc, v, mean, now);
    return failed;
}

int sc_cache_create(cs_selfcol *sc)
{
    cs_pair_cache *c = &sc->cache;
    c->slack = CACHE_SLACK_PER_THICKNESS;
    c->pbox = malloc(sizeof *c->pbox * ((size_t)sc->n + 1));
    c->ebox = malloc(sizeof *c->ebox * ((size_t)sc->ne + 1));
    c->tbox = malloc(sizeof *c->tbox * ((size_t)sc->nt + 1));
    c->drift = calloc(3 * ((size_t)sc->n + 1), sizeof *c->drift);
    c->x_ref = malloc(sizeof *c->x_ref * 3 * ((size_t)sc->n + 1));
    c->moved = malloc(sizeof *c->moved * ((size_t)sc->n + 1));
    c->speed = malloc(sizeof *c->speed * ((size_t)sc->n + 1));
    return c->pbox && c->ebox && c->tbox && c->drift && c->x_ref && c->moved && c->speed ? 0
                                                                                     : -1;
}

void sc_cache_free(cs_selfcol *sc)
{
    cs_pair_cache *c = &sc->cache;
    free(c->pbox);
    free(c->ebox);
    free(c->tbox);
    free(c->drift);
    free(c->x_ref);
    free(c->pt_ref);
    free(c->ee_ref);
    free(c->moved);
    free(c->speed);
    free(c->pt.ab);
    free(c->ee.ab);
    memset(c, 0, sizeof *c);
    for (int t = 0; t < sc->nmade; t++)
        free(sc->made[t].m);
    free(sc->made);
    sc->made = NULL;
    sc->nmade = 0;
}

static int made_push(cs_made_list *l, int a, int b, const cs_pair *p)
{
    if (l->n == l->capacity) {
        int cap = l->capacity ? 2 * l->capacity : 256;
        cs_made_pair *m = realloc(l->m, sizeof *m * (size_t)cap);
        if (!m)
            return -1;
        l->m = m;
        l->capacity = cap;
    }
    l->m[l->n++] = (cs_made_pair){a, b, *p};
    return 0;
}

static int by_candidate(const void *pa, const void *pb)
{
    const cs_made_pair *x = pa, *y = pb;
    return x->a != y->a ? (x->a > y->a) - (x->a < y->a) : (x->b > y->b) - (x->b < y->b);
}

/* Step A's reach test on cached candidates: a pair out of reach is one the
 * makers would drop (past may_meet's reach) without lowering start_gap
 * (capped below the thickness), so skipping it changes no bit. The box
 * overlap that found the candidate widens every box by its particles'
 * speeds relative to the cloth's mean velocity; in a landing most of the
 * sheet moves fast against the mean but slowly against its neighbours,
 * and the reach test leaves the makers about 5% of the 100 x 100 sheet's
 * candidates (docs/performance.md, "Step A's reach"). */
int sc_find_pairs(cs_selfcol *sc, bool edges, bool only_dirty, const cs_reach *reach,
                  const sc_skin *skin, pair_maker make, const void *ctx, cs_pair_list *list)
{
    bool reached = reach && sc->reached; /* the candidates are within reach */
    const cs_index_pairs *cand = reached ? (edges ? &sc->reach_ee : &sc->reach_pt)
                                         : (edges ? &sc->cache.ee : &sc->cache.pt);
    const cs_motion_boxes *ma = edges ? &sc->emotion : &sc->pmotion;
    const cs_motion_boxes *mb = edges ? &sc->emotion : &sc->tmotion;
    if (reached)
        skin = NULL; /* its distances are the cache's */
    const cs_box *boxa = edges ? sc->ebox : sc->pbox, *boxb = edges ? sc->ebox : sc->tbox;
    const unsigned char *da = edges ? sc->edirty : sc->pdirty;
    const unsigned char *db = edges ? sc->edirty : sc->tdirty;
    int threads = omp_get_max_threads();
    if (threads > sc->nmade) {
        cs_made_list *m = realloc(sc->made, sizeof *m * (size_t)threads);
        if (!m)
            return -1;
        memset(m + sc->nmade, 0, sizeof *m * (size_t)(threads - sc->nmade));
        sc->made = m;
        sc->nmade = threads;
    }
    int failed = 0;
    long skipped = 0, unreached = 0;
#pragma omp parallel reduction(| : failed) reduction(+ : skipped, unreached)
    {
        cs_made_list *mine = sc->made + omp_get_thread_num();
        mine->n = 0;
#pragma omp for schedule(dynamic, 1024)
        for (int k = 0; k < cand->n; k++) {
            int a = cand->ab[2 * k], b = cand->ab[2 * k + 1];
            cs_pair p;
            /* the boxes decide with the makers, within reach or not: a
             * box grows around each vertex by that vertex's speed, so a
             * pair near a triangle's slow side and reaching its fast
             * vertex can pass may_meet and miss the boxes, and so is no
             * pair of a search's through the cache. Reach holds every pair
             * may_meet keeps, and the boxes leave the same pairs on either
             * way, whatever the cache's history (a resumed run's first
             * search). */
            if ((only_dirty && !da[a] && !db[b]) || !cs_box_overlap_branchless(boxa + a, boxb + b))
                continue;
            if (reach && !reached &&
                !cs_in_reach(ma->x + a, ma->v + a, mb->x + b, mb->v + b, reach)) {
                unreached++;
                continue;
            }
            if (skin && skin_far(sc, edges, k, a, b, skin)) {
                skipped++;
                continue;
            }
            if (!make(ctx, a, b, &p))
                continue;
            failed |= made_push(mine, a, b, &p);
        }
    }
    sc->cache.skin_skips += skipped;
    sc->cache.reach_skips += unreached;
    if (failed)
        return -1;
    /* the threads' pairs joined, then in (a, b) order */
    cs_made_list *all = sc->made;
    for (int t = 1; t < threads; t++)
        for (int k = 0; k < sc->made[t].n; k++)
            if (made_push(all, sc->made[t].m[k].a, sc->made[t].m[k].b, &sc->made[t].m[k].p))
                return -1;
    if (all->n > 1)
        qsort(all->m, (size_t)all->n, sizeof *all->m, by_candidate);
    for (int k = 0; k < all->n; k++)
        if (sc_pair_push(list, all->m[k].p.v, all->m[k].p.s0))
            return -1;
    return 0;
}
