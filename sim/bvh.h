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
 * on both trees), node pairs that cannot hold a pair going to rank.
 * Returns 0 or -1 (no memory). */
int cs_bvh_collect(const cs_bvh *A, const cs_bvh *B, int rank, cs_bvh_work *w,
                   cs_index_pairs *out);

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
