/* selfcol_private.h: what the self-collision files (sim/selfcol*.c) share
 * among themselves, by the file that defines it; private to them. */
#ifndef CS_SELFCOL_PRIVATE_H
#define CS_SELFCOL_PRIVATE_H

#include "sim/internal.h"
#include "sim/selfcol.h"

/* Turns a candidate (a, b) of a traversal into a pair, or says no; makers
 * only read shared state, so threads run them side by side. */
typedef bool (*pair_maker)(const void *ctx, int a, int b, cs_pair *out);

/* How a pair responds (sc_pair_respond). */
typedef struct response {
    bool inelastic, elastic, friction;
    double dt; /* for Eq. 1 */
    double thickness, k, mu, epsilon;
} response;

/* ---- selfcol_pairs.c: pair lists, union-find, pairs' ranks (Section 7) */
int sc_pair_push(cs_pair_list *l, const int v[4], const double *s0);
int sc_zone_find(int *parent, int i);
void sc_zone_union(int *parent, int a, int b);
int sc_pair_rank(const cs_par *par, const int v[4]);
int sc_distribute_boundary(cs_sim *sim, cs_pair_list *pt, cs_pair_list *ee);

/* ---- selfcol_response.c: one pair's frame and response */
void sc_pair_impulse(const cs_selfcol *sc, const cs_pair *p, const double c[4], double J,
                     const double dir[3], double *v);
double sc_pair_inverse_mass(const cs_selfcol *sc, const cs_pair *p, const double c[4]);
/* What an impulse on the pair's relative motion divides by: its inverse
 * mass, raised where one vertex would take more than SC_MAX_LEVERAGE
 * times the change of the relative velocity (see selfcol_response.c) */
double sc_pair_impulse_inverse_mass(const cs_selfcol *sc, const cs_pair *p, const double c[4],
                                    double inv_m);
double sc_pair_normal_velocity(const cs_pair *p, const double c[4], const double *v,
                               const double n[3], double rel[3]);
bool sc_pair_respond(const cs_selfcol *sc, const cs_pair *p, bool is_edge, const double *x,
                     double *v, const response *r);
double sc_ring_side(const cs_selfcol *sc, const double *x, int point, const double nrm[3]);
bool sc_sides_apart(const double *const p[4], int split, double gap);

/* ---- selfcol_cache.c: the candidate pairs kept between searches */
/* Before steps A and C search with the boxes in sc->pbox, ebox and tbox
 * (around x_free): makes the cache hold every pair whose boxes can overlap,
 * traversing the trees only when a particle's box left its grown box;
 * with v (step A: the velocities, mean their mean), measures the skin's
 * motion for this search. With reach (step A, its motion boxes in
 * sc->pmotion, emotion, tmotion), where the cache would be rebuilt from
 * this search's own boxes (it lasted no longer than that), traverses
 * within reach instead into sc->reach_pt and reach_ee and sets
 * sc->reached, leaving the cache to step C. Returns 0 or -1 (no memory). */
int sc_cache_update(cs_selfcol *sc, int rank, double thickness, const double *v,
                    const double mean[3], const cs_reach *reach);
int sc_cache_create(cs_selfcol *sc);
void sc_cache_free(cs_selfcol *sc);
/* What step A's makers keep and measure: a pair closer than
 * thickness + (relative speed) span, and distances under gap_cap
 * (start_gap's). With it, sc_find_pairs skips the pairs the skin shows
 * to be farther than both (selfcol_cache.c). */
typedef struct sc_skin {
    double thickness, span, gap_cap;
} sc_skin;
/* The cached point/triangle (edges: edge/edge) pairs whose present boxes
 * overlap (only_dirty: with a dirty side), that are within reach (NULL:
 * no test; step A's motion boxes, cs_in_reach), that skin (NULL: none)
 * does not show to be far, and that make accepts, appended to list in
 * (a, b) order at any thread count; after a search that sc->reached,
 * reach's candidates instead, those make accepts. Returns 0 or -1. */
int sc_find_pairs(cs_selfcol *sc, bool edges, bool only_dirty, const cs_reach *reach,
                  const sc_skin *skin, pair_maker make, const void *ctx, cs_pair_list *list);

/* ---- selfcol_project.c: zones across prescribed motions */
/* Keeps a collision found in a zone pass (weights c, normal n oriented from
 * the side it started on) as a constraint for sc_project_zone. Returns 0
 * or -1 (no memory). */
int sc_zone_constraint_add(cs_selfcol *sc, const int v[4], const double c[4], const double n[3],
                           double thickness);
/* Moves the free vertices of zone root in x the least that makes each of
 * its kept constraints hold, prescribed vertices fixed (selfcol_project.c).
 * Returns false, with where and how short in why, when no end state was
 * found. */
bool sc_project_zone(cs_selfcol *sc, int root, double *x, cs_script_conflict *why);

#endif
