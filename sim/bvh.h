/* bvh.h: axis-aligned bounding box hierarchies over points, segments and
 * triangles (van den Bergen 1997, the paper's [49]), private to sim/.
 * The topology is built once from the primitives' boxes at creation (median
 * split of centroids along the widest axis); every use refits the boxes
 * bottom-up. Nodes are stored parents before children, so a reverse sweep
 * refits. */
#ifndef CS_BVH_H
#define CS_BVH_H

#include <math.h>
#include <stdbool.h>

typedef struct cs_box {
    double lo[3], hi[3];
} cs_box;

typedef struct cs_bvh {
    int nprims, nnodes;
    cs_box *box;          /* per node */
    int *child;           /* 2 per node: left, right; -1 for a leaf */
    int *first, *count;   /* leaf: primitives order[first .. first+count) */
    int *order;           /* primitive ids in leaf order */
    cs_box *leaf_box;     /* their boxes in leaf order, from the last refit */
    /* per node and per primitive in leaf order: the extent of the
     * primitives' velocities, from the last cs_bvh_refit_motion (NULL
     * before it) */
    cs_box *vbox, *leaf_vbox;
    int *rank_lo, *rank_hi; /* per node: the ranks its primitives go to */
    /* each primitive's particles, nvertices apiece (cs_bvh_set_vertices;
     * NULL: primitive k is particle k) */
    const int *vertices;
    int nvertices;
} cs_bvh;

int cs_bvh_build(cs_bvh *t, int nprims, const cs_box *prim_box);
void cs_bvh_free(cs_bvh *t);
/* Sets node boxes from primitive boxes. */
void cs_bvh_refit(cs_bvh *t, const cs_box *prim_box);

/* Sets node boxes from the primitives' position and velocity boxes, for a
 * traversal within reach. Returns 0 or -1 (no memory). */
int cs_bvh_refit_motion(cs_bvh *t, const cs_box *prim_box, const cs_box *prim_vbox);

/* Section 7: each primitive's rank (the lowest owner of its particles); a
 * pair goes to the lower of its two primitives' ranks. */
int cs_bvh_set_ranks(cs_bvh *t, const int *prim_rank);

/* Names each primitive's particles (kept, not copied), nvertices apiece,
 * so that cs_bvh_collect leaves out pairs sharing one: a triangle and its
 * own vertex, two edges with a common end. */
void cs_bvh_set_vertices(cs_bvh *t, const int *vertices, int nvertices);

/* Primitive pairs as (a, b) integer pairs, 2 ints each. */
typedef struct cs_index_pairs {
    int n, capacity;
    int *ab;
} cs_index_pairs;

/* Scratch a traversal reuses from call to call. */
typedef struct cs_bvh_work {
    int ntasks, task_capacity;
    int *task;                 /* 2 per task: a node of A, a node of B */
    int *task_first;           /* 3 per task: its first pair in its thread's */
    int task_slots;            /* list, how many, which thread; for task_slots tasks */
    cs_index_pairs *found;     /* per thread */
    int nthreads;
} cs_bvh_work;
void cs_bvh_work_free(cs_bvh_work *w);

/* Every pair of primitives a of A and b of B whose boxes overlap and that
 * share no particle (for A == B each unordered pair once, as a < b), into
 * out in the order of a depth-first traversal whatever the thread count:
 * the node pairs near the top become tasks that OpenMP threads traverse
 * into one list per thread, joined in task order. The boxes are those of the
 * last cs_bvh_refit of each tree. With rank >= 0 (after cs_bvh_set_ranks
 * on both trees), node pairs that cannot hold a pair going to rank. With
 * reach, the pairs within reach (cs_in_reach) instead of those whose boxes
 * overlap, from the last cs_bvh_refit_motion of each tree.
 * Returns 0 or -1 (no memory). */
typedef struct cs_reach cs_reach;
int cs_bvh_collect(const cs_bvh *A, const cs_bvh *B, int rank, const cs_reach *reach,
                   cs_bvh_work *w, cs_index_pairs *out);

static inline bool cs_box_overlap(const cs_box *a, const cs_box *b)
{
    return a->lo[0] <= b->hi[0] && b->lo[0] <= a->hi[0] && a->lo[1] <= b->hi[1] &&
           b->lo[1] <= a->hi[1] && a->lo[2] <= b->hi[2] && b->lo[2] <= a->hi[2];
}

/* The same test with all six comparisons and no early exit, for the
 * inner loops where the outcome is unpredictable (a leaf pair's boxes,
 * the kept candidates): there the early exits were mispredicted. */
static inline bool cs_box_overlap_branchless(const cs_box *a, const cs_box *b)
{
    return (a->lo[0] <= b->hi[0]) & (b->lo[0] <= a->hi[0]) & (a->lo[1] <= b->hi[1]) &
           (b->lo[1] <= a->hi[1]) & (a->lo[2] <= b->hi[2]) & (b->lo[2] <= a->hi[2]);
}

/* Step A's reach: its makers keep a pair only if it is closer than
 * thickness + (relative speed) span, the speed the largest between a
 * vertex of each side. */
struct cs_reach {
    double thickness, span;
};

/* Whether two primitives (or two nodes' worth of them) whose vertices lie
 * in the position boxes xa and xb and move at velocities in va and vb may
 * hold such a pair: the boxes' gap, which bounds every distance between
 * them from below, is short of the thickness plus the largest relative
 * speed the velocity boxes allow (every speed between them is at most
 * that) times the span. Neither bound needs a common velocity, so a sheet
 * moving fast against its mean velocity but slowly against its neighbours
 * reaches only them. The factors 1 -+ 1e-9 are far above the makers'
 * round-off, so a pair out of reach is one the makers drop. */
static inline bool cs_in_reach(const cs_box *xa, const cs_box *va, const cs_box *xb,
                               const cs_box *vb, const cs_reach *r)
{
    double gap = 0, rel = 0;
    for (int d = 0; d < 3; d++) {
        double g = xb->lo[d] - xa->hi[d], h = xa->lo[d] - xb->hi[d];
        g = g > h ? g : h;
        g = g > 0 ? g : 0;
        gap += g * g;
        double u = va->hi[d] - vb->lo[d], w = vb->hi[d] - va->lo[d];
        u = u > w ? u : w;
        rel += u * u;
    }
    return !(sqrt(gap) * (1 - 1e-9) >= r->thickness + sqrt(rel) * (1 + 1e-9) * r->span);
}

static inline void cs_box_empty(cs_box *b)
{
    for (int d = 0; d < 3; d++) {
        b->lo[d] = INFINITY;
        b->hi[d] = -INFINITY;
    }
}

static inline void cs_box_add_point(cs_box *b, const double p[3])
{
    for (int d = 0; d < 3; d++) {
        if (p[d] < b->lo[d])
            b->lo[d] = p[d];
        if (p[d] > b->hi[d])
            b->hi[d] = p[d];
    }
}

static inline void cs_box_thicken(cs_box *b, double h)
{
    for (int d = 0; d < 3; d++) {
        b->lo[d] -= h;
        b->hi[d] += h;
    }
}

#endif
