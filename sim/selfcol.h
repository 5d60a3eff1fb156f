/* selfcol.h: self-collisions of Sections 4 and 5, private to sim/.
 *
 * Step A finds repulsion pairs in the collision-free state with their
 * history (orientation); B.2 and B.8 apply them every time step; step C
 * finds and removes collisions along the linear trajectories from the
 * collision-free state, with impact zones as the last resort. Every set of
 * pairs goes through one Gauss-Seidel routine (cs_pairs_apply), the door the
 * parallel version (Section 7) replaces. */
#ifndef CS_SELFCOL_H
#define CS_SELFCOL_H

#include "sim/bvh.h"
#include "sim/par.h"

typedef struct cs_sim cs_sim;

/* A point/triangle pair is (t0, t1, t2, point), the triangle wound so its
 * normal pointed at the point in the collision-free state. An edge/edge
 * pair is (a0, a1, b0, b1) with s0 the unit shortest vector from edge a to
 * edge b in the collision-free state. */
typedef struct cs_pair {
    int v[4];
    double s0[3];
} cs_pair;

typedef struct cs_pair_list {
    int n, capacity;
    cs_pair *p;
} cs_pair_list;

typedef struct cs_selfcol_stats {
    long repulsion_pairs;      /* found by step A (summed over outer steps) */
    long repulsions;           /* pair impulses applied in B.2 and B.8 */
    long collisions;           /* collisions found by step C */
    long passes;               /* step C iterations */
    long zones;                /* impact zones formed */
    long max_zone;             /* particles in the largest zone */
    long zones_across;         /* zone rigidifications spanning ranks */
    long held_zones;           /* zones that spanned two scripts, held in place */
    long projected_zones;      /* zones that spanned two scripts, projected */
    long rewinds;              /* outer steps redone (rewind scheme) */
    long cache_searches;       /* searches of steps A and C (selfcol_cache.c) */
    long cache_builds;         /* of them, those that traversed the trees */
    long searches_skipped;     /* step C first passes that needed no search
                                  (every pair out of reach, start_gap) */
} cs_selfcol_stats;

/* A pair a search made, with the candidate (a, b) it came from: the key
 * that orders a search's pairs. */
typedef struct cs_made_pair {
    int a, b;
    cs_pair p;
} cs_made_pair;

typedef struct cs_made_list {
    int n, capacity;
    cs_made_pair *m;
    double nearest; /* the least distance the thread's makers measured */
    /* one list per thread, side by side, written at every pair made and
     * distance measured: 64 bytes each, so that no two threads' counters
     * share a cache line */
    char pad[64 - 2 * sizeof(int) - sizeof(cs_made_pair *) - sizeof(double)];
} cs_made_list;

/* Per primitive at step A's search, the extent of its vertices' positions
 * in x_free (x) and of their velocities (v): what bounds the distance of a
 * pair of primitives from below and its relative speed from above
 * (cs_in_reach, bvh.h). */
typedef struct cs_motion_boxes {
    cs_box *x, *v;
} cs_motion_boxes;

/* Candidate pairs kept between searches (selfcol_cache.c). */
typedef struct cs_pair_cache {
    bool valid;
    double slack;                /* grown by this times the thickness; below
                                    zero, every search traverses (tests) */
    double anchor[3];            /* the centroid of x_free when it was built */
    cs_box *pbox, *ebox, *tbox;  /* the boxes it was built from, grown */
    cs_index_pairs pt, ee;       /* point/triangle, edge/edge */
    double *drift;               /* per particle: its motion relative to the
                                    centroid over step A's span, from the
                                    last step A (selfcol_cache.c's forecast) */
    int served;                  /* searches since it was built */
    /* The distance skin (step A): x_free when it was built, and per cached
     * pair the distance between its sides there (NaN until measured); per
     * particle, at the present search, how far it moved since the build
     * with the centroid's motion taken out, and its speed relative to the
     * cloth's mean velocity (selfcol_cache.c) */
    double *x_ref, *pt_ref, *ee_ref;
    int pt_ref_cap, ee_ref_cap;
    double *moved, *speed;
    bool skin_off;               /* tests: step A measures every pair */
    long skin_skips;             /* pairs the skin spared the makers, in all */
    bool reach_off;              /* tests: no reach test (sc_find_pairs) */
    long reach_skips;            /* cached candidates the reach test skipped */
    long reach_traversals;       /* step A's searches that traversed within reach */
} cs_pair_cache;

/* A collision inside an impact zone that spans two prescribed motions, as
 * a linear constraint on the span's end positions (selfcol_project.c):
 * n . sum_k c_k x_k >= gap, n and the weights c from the collision. */
typedef struct cs_zone_constraint {
    int v[4];
    double c[4], n[3];
    double gap;
    double lambda; /* its multiplier in the projection */
} cs_zone_constraint;

/* Why step C stopped (CS_ERR_SCRIPT): a zone that spans two prescribed
 * motions and has no collision-free state that follows them. */
typedef struct cs_script_conflict {
    bool found;
    double t;                  /* the outer step's end */
    int zone_size;
    int scripts[4], nscripts;  /* the first scripts in it (-1: pins) */
    bool more_scripts;
    double where[3];           /* a vertex of its worst collision */
    double shortfall;          /* m the worst constraint lacks (0: passes ran out) */
} cs_script_conflict;

typedef struct cs_selfcol {
    int n, ne, nt;
    int *edge, *tri;           /* global particle indices */
    int *ring_start, *ring;    /* each particle's neighbours along edges */
    cs_bvh ptree, etree, ttree;
    cs_box *pbox, *ebox, *tbox;
    cs_motion_boxes pmotion, emotion, tmotion; /* per particle, edge, triangle */
    /* step A's candidates when its search traversed the trees within
     * reach instead of using the cache (selfcol_cache.c), and whether the
     * present search's are those */
    cs_index_pairs reach_pt, reach_ee;
    bool reached;
    unsigned char *pdirty, *edirty, *tdirty, *vdirty;
    unsigned char *collided;   /* step C: in a pair the last pass found */
    double *x_free;            /* the last collision-free positions */
    double *x_before;          /* positions when step C began */
    double *inv_mass;          /* 0 for pinned and scripted particles */
    double proximity;          /* delta: closer than this at a coplanar time collides */
    /* Step A's lower bound on the distance in x_free between the sides of
     * any pair this rank's step C could find (0: none known); step C's
     * first search is skipped when no pair can close it over the span */
    double start_gap;
    bool use_start_gap;        /* true but in tests that compare without it */
    cs_pair_list pt, ee;       /* repulsion pairs from step A */
    cs_pair_list cpt, cee;     /* step C candidates of one pass */
    int *zone;                 /* union-find parent per particle, -1 outside zones */
    int *zone_list;            /* scratch */
    /* step C's zones across prescribed motions: the collisions found in
     * its zone passes, kept for the projection (allocated at first use) */
    cs_zone_constraint *kc;
    int nkc, kc_cap;
    int *kc_list;              /* scratch: one zone's constraints */
    cs_script_conflict conflict;
    /* Section 7: pairs go to the lowest rank owning one of their particles;
     * pairs across ranks ("boundary") are grouped into connected components,
     * each processed by one rank before the pairs internal to each rank */
    int *prim_rank;            /* scratch for the trees' rank ranges */
    int *component;            /* union-find parent per particle (scratch) */
    cs_pair_list bpt, bee;     /* boundary repulsion pairs this rank processes */
    cs_halo bhalo;             /* their particles: owners <-> this rank */
    double *x_pass;            /* positions at the last step C pass's start */
    cs_pair_cache cache;
    /* search scratch: the traversal's, and the pairs each thread made */
    cs_bvh_work bvh_work;
    cs_made_list *made;
    int nmade;
    cs_selfcol_stats stats;
    size_t bytes;
} cs_selfcol;

cs_selfcol *cs_selfcol_create(const cs_sim *sim);
void cs_selfcol_destroy(cs_selfcol *sc);

/* Particle i, held by a script until now, moves freely from now on. */
void cs_selfcol_release(cs_selfcol *sc, int i, double mass);

/* After the partition: the trees learn which ranks their primitives go
 * to. Returns 0 or -1 (no memory). */
int cs_selfcol_set_ranks(cs_sim *sim);

/* Step A: pairs near each other in the collision-free state (sim->x, which
 * equals x_free here) allowing for motion over the coming time span. */
void cs_selfcol_find_pairs(cs_sim *sim, double span);

/* B.2 (elastic true): inelastic then elastic repulsion on v~^(n+1/2) with
 * positions x^n. B.8 (elastic false): inelastic repulsion and friction on
 * v^(n+1) with positions x^(n+1). Returns how many pairs were near
 * enough to act (0: v unchanged here). */
long cs_selfcol_repulse(cs_sim *sim, double *x, double *v, double dt, bool elastic);

/* Step C over the span since the last collision-free state, k time steps
 * of it. Updates x, v and the collision-free state. With detect_only,
 * returns the number of colliding pairs of the first pass and changes
 * nothing (the rewind scheme's test). */
long cs_selfcol_collide(cs_sim *sim, double span, int k, bool detect_only);

/* Rigid motion of an impact zone (exposed for tests): from free positions
 * xf and effective velocities u of particles idx[0..n), with masses m,
 * linear velocity vcm and angular velocity omega conserving the zone's
 * linear and angular momentum (the inertia tensor pseudo-inverted through
 * its eigen decomposition, so coplanar, colinear and coincident points
 * work); writes x = xcm + span vcm + R(omega span)(xf - xcm). */
void cs_impact_zone_motion(int n, const int *idx, const double *m, const double *xf,
                           const double *u, double span, double *x, double vcm[3],
                           double omega[3]);

#endif
