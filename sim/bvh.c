/* bvh.c: build, refit and pair traversal of box hierarchies. */
#include <math.h>
#include <limits.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "sim/bvh.h"

enum { LEAF_SIZE = 4 };

typedef struct builder {
    cs_bvh *t;
    const cs_box *pb;
    double *centroid; /* 3 per primitive */
    int axis;
} builder;

static builder *sort_ctx; /* qsort has no context argument in C11 */

static int by_centroid(const void *pa, const void *pb)
{
    double a = sort_ctx->centroid[3 * *(const int *)pa + sort_ctx->axis];
    double b = sort_ctx->centroid[3 * *(const int *)pb + sort_ctx->axis];
    return (a > b) - (a < b);
}

static int build_node(builder *b, int first, int count)
{
    cs_bvh *t = b->t;
    int node = t->nnodes++;
    t->first[node] = first;
    t->count[node] = count;
    t->child[2 * node] = t->child[2 * node + 1] = -1;
    if (count <= LEAF_SIZE)
        return node;
    cs_box c;
    cs_box_empty(&c);
    for (int k = first; k < first + count; k++)
        cs_box_add_point(&c, b->centroid + 3 * t->order[k]);
    int axis = 0;
    for (int d = 1; d < 3; d++)
        if (c.hi[d] - c.lo[d] > c.hi[axis] - c.lo[axis])
            axis = d;
    b->axis = axis;
    sort_ctx = b;
    qsort(t->order + first, (size_t)count, sizeof *t->order, by_centroid);
    int half = count / 2;
    int left = build_node(b, first, half);
    int right = build_node(b, first + half, count - half);
    t->child[2 * node] = left;
    t->child[2 * node + 1] = right;
    return node;
}

int cs_bvh_build(cs_bvh *t, int nprims, const cs_box *pb)
{
    memset(t, 0, sizeof *t);
    t->nprims = nprims;
    int cap = 2 * (nprims > 0 ? nprims : 1);
    t->box = calloc((size_t)cap, sizeof *t->box);
    t->child = calloc(2 * (size_t)cap, sizeof *t->child);
    t->first = calloc((size_t)cap, sizeof *t->first);
    t->count = calloc((size_t)cap, sizeof *t->count);
    t->order = calloc((size_t)nprims + 1, sizeof *t->order);
    t->leaf_box = calloc((size_t)nprims + 1, sizeof *t->leaf_box);
    builder b = {t, pb, calloc(3 * (size_t)nprims + 3, sizeof(double)), 0};
    if (!t->box || !t->child || !t->first || !t->count || !t->order ||
        !t->leaf_box || !b.centroid) {
        free(b.centroid);
        cs_bvh_free(t);
        return -1;
    }
    for (int i = 0; i < nprims; i++) {
        t->order[i] = i;
        for (int d = 0; d < 3; d++)
            b.centroid[3 * i + d] = 0.5 * (pb[i].lo[d] + pb[i].hi[d]);
    }
    if (nprims > 0)
        build_node(&b, 0, nprims);
    free(b.centroid);
    cs_bvh_refit(t, pb);
    return 0;
}

void cs_bvh_free(cs_bvh *t)
{
    free(t->box);
    free(t->child);
    free(t->first);
    free(t->count);
    free(t->order);
    free(t->leaf_box);
    free(t->vbox);
    free(t->leaf_vbox);
    free(t->rank_lo);
    free(t->rank_hi);
    memset(t, 0, sizeof *t);
}

/* node_box from the primitives' boxes pb, bottom-up; leaf_box gets them in
 * leaf order */
static void refit_boxes(cs_bvh *t, const cs_box *pb, cs_box *node_box, cs_box *leaf_box)
{
    for (int node = t->nnodes - 1; node >= 0; node--) {
        cs_box *b = node_box + node;
        int l = t->child[2 * node];
        if (l < 0) {
            cs_box_empty(b);
            for (int k = t->first[node]; k < t->first[node] + t->count[node]; k++) {
                int p = t->order[k];
                leaf_box[k] = pb[p];
                cs_box_add_point(b, pb[p].lo);
                cs_box_add_point(b, pb[p].hi);
            }
        } else {
            int r = t->child[2 * node + 1];
            *b = node_box[l];
            cs_box_add_point(b, node_box[r].lo);
            cs_box_add_point(b, node_box[r].hi);
        }
    }
}

void cs_bvh_refit(cs_bvh *t, const cs_box *pb)
{
    refit_boxes(t, pb, t->box, t->leaf_box);
}

int cs_bvh_refit_motion(cs_bvh *t, const cs_box *prim_box, const cs_box *prim_vbox)
{
    if (!t->vbox) {
        t->vbox = malloc(sizeof *t->vbox * ((size_t)t->nnodes + 1));
        t->leaf_vbox = malloc(sizeof *t->leaf_vbox * ((size_t)t->nprims + 1));
        if (!t->vbox || !t->leaf_vbox) {
            free(t->vbox);
            free(t->leaf_vbox);
            t->vbox = t->leaf_vbox = NULL;
            return -1;
        }
    }
    refit_boxes(t, prim_box, t->box, t->leaf_box);
    refit_boxes(t, prim_vbox, t->vbox, t->leaf_vbox);
    return 0;
}

typedef struct traversal {
    const cs_bvh *A, *B;
    bool self;
    int rank;
    const cs_reach *reach; /* NULL: box overlap */
    int depth;            /* planning: node pairs this deep become tasks */
    cs_bvh_work *plan;    /* planning: where the tasks go; NULL when traversing */
    cs_index_pairs *out;  /* traversing: where the pairs go */
    int failed;
} traversal;

static bool push_pair(cs_index_pairs *l, int a, int b)
{
    if (l->n == l->capacity) {
        int cap = l->capacity ? 2 * l->capacity : 1024;
        int *ab = realloc(l->ab, sizeof *ab * 2 * (size_t)cap);
        if (!ab)
            return false;
        l->ab = ab;
        l->capacity = cap;
    }
    l->ab[2 * l->n] = a;
    l->ab[2 * l->n++ + 1] = b;
    return true;
}

void cs_bvh_set_vertices(cs_bvh *t, const int *vertices, int nvertices)
{
    t->vertices = vertices;
    t->nvertices = nvertices;
}

/* Primitive k's particles: vertices + nvertices * k, or k itself; their
 * count in *n. */
static inline const int *prim_vertices(const cs_bvh *t, const int *k, int *n)
{
    *n = t->vertices ? t->nvertices : 1;
    return t->vertices ? t->vertices + (ptrdiff_t)t->nvertices * *k : k;
}

/* Pairs sharing a particle are never a collision pair (the makers reject
 * them first), and such pairs always overlap: on the benchmark sheet they
 * are most of the point/triangle and edge/edge box overlaps of a search
 * of the kept pairs. */
static inline bool share_vertex(const cs_bvh *A, int a, const cs_bvh *B, int b)
{
    int na, nb;
    const int *va = prim_vertices(A, &a, &na), *vb = prim_vertices(B, &b, &nb);
    for (int p = 0; p < na; p++)
        for (int q = 0; q < nb; q++)
            if (va[p] == vb[q])
                return true;
    return false;
}

static void leaf_pairs(traversal *tr, int i, int j)
{
    const cs_bvh *A = tr->A, *B = tr->B;
    /* the bounds in locals: push_pair's stores may alias the tree's arrays */
    const int ka_end = A->first[i] + A->count[i], kb_end = B->first[j] + B->count[j];
    const cs_box *node_b = B->box + j;
    const cs_reach *reach = tr->reach;
    for (int ka = A->first[i]; ka < ka_end; ka++) {
        int a = A->order[ka];
        const cs_box *ba = A->leaf_box + ka, *va = reach ? A->leaf_vbox + ka : NULL;
        /* most leaf pairs' primitives miss each other: one test against
         * the other leaf's box spares the primitives' tests */
        if (reach ? !cs_in_reach(ba, va, node_b, B->vbox + j, reach)
                  : !cs_box_overlap_branchless(ba, node_b))
            continue;
        int kb0 = (tr->self && i == j) ? ka + 1 : B->first[j];
        for (int kb = kb0; kb < kb_end; kb++) {
            if (reach ? !cs_in_reach(ba, va, B->leaf_box + kb, B->leaf_vbox + kb, reach)
                      : !cs_box_overlap_branchless(ba, B->leaf_box + kb))
                continue;
            int b = B->order[kb];
            if (share_vertex(A, a, B, b))
                continue;
            bool ok = tr->self && a > b ? push_pair(tr->out, b, a) : push_pair(tr->out, a, b);
            tr->failed |= !ok;
        }
    }
}

/* Planning stops here, deep enough or at leaves: the node pair is a task
 * for later. */
static bool planned(traversal *tr, int i, int j, int depth, bool leaves)
{
    if (!tr->plan || (depth < tr->depth && !leaves))
        return false;
    cs_bvh_work *w = tr->plan;
    if (w->ntasks == w->task_capacity) {
        int cap = w->task_capacity ? 2 * w->task_capacity : 256;
        int *t = realloc(w->task, sizeof *t * 2 * (size_t)cap);
        if (!t) {
            tr->failed = 1;
            return true;
        }
        w->task = t;
        w->task_capacity = cap;
    }
    w->task[2 * w->ntasks] = i;
    w->task[2 * w->ntasks++ + 1] = j;
    return true;
}

static void descend(traversal *tr, int i, int j, int depth)
{
    const cs_bvh *A = tr->A, *B = tr->B;
    if (tr->rank >= 0 && A->rank_lo && B->rank_lo) {
        /* every pair below goes to a rank in [lo, hi]: none is ours */
        int lo = A->rank_lo[i] < B->rank_lo[j] ? A->rank_lo[i] : B->rank_lo[j];
        int hi = A->rank_hi[i] < B->rank_hi[j] ? A->rank_hi[i] : B->rank_hi[j];
        if (tr->rank < lo || tr->rank > hi)
            return;
    }
    if (tr->self && i == j) {
        int l = A->child[2 * i];
        if (planned(tr, i, i, depth, l < 0))
            return;
        if (l < 0) {
            leaf_pairs(tr, i, i);
            return;
        }
        int r = A->child[2 * i + 1];
        descend(tr, l, l, depth + 1);
        descend(tr, r, r, depth + 1);
        descend(tr, l, r, depth + 1);
        return;
    }
    if (tr->reach ? !cs_in_reach(A->box + i, A->vbox + i, B->box + j, B->vbox + j, tr->reach)
                  : !cs_box_overlap(A->box + i, B->box + j))
        return;
    int la = A->child[2 * i], lb = B->child[2 * j];
    if (planned(tr, i, j, depth, la < 0 && lb < 0))
        return;
    if (la < 0 && lb < 0) {
        leaf_pairs(tr, i, j);
        return;
    }
    /* split the larger box (or the only inner node) */
    bool split_a = lb < 0;
    if (la >= 0 && lb >= 0) {
        double va = 1, vb = 1;
        for (int d = 0; d < 3; d++) {
            va *= A->box[i].hi[d] - A->box[i].lo[d];
            vb *= B->box[j].hi[d] - B->box[j].lo[d];
        }
        split_a = va >= vb;
    }
    if (split_a) {
        descend(tr, la, j, depth + 1);
        descend(tr, A->child[2 * i + 1], j, depth + 1);
    } else {
        descend(tr, i, lb, depth + 1);
        descend(tr, i, B->child[2 * j + 1], depth + 1);
    }
}

/* Node pairs this deep become tasks: up to 4^depth of them, many per thread
 * so uneven ones even out. */
enum { TASK_DEPTH = 8 };

int cs_bvh_collect(const cs_bvh *A, const cs_bvh *B, int rank, const cs_reach *reach,
                   cs_bvh_work *w, cs_index_pairs *out)
{
    out->n = 0;
    w->ntasks = 0;
    if (A->nnodes == 0 || B->nnodes == 0)
        return 0;
    if (reach && (!A->vbox || !B->vbox))
        return -1;
    traversal plan = {A, B, A == B, rank, reach, TASK_DEPTH, w, NULL, 0};
    descend(&plan, 0, 0, 0);
    if (plan.failed)
        return -1;
    /* A list per task kept its own capacity from call to call: over a
     * landing most of the 4^TASK_DEPTH task slots came to hold a buffer,
     * 40% of the 20k drape's heap. One list per thread holds only what
     * that thread found, and each task's place in it. */
    if (w->ntasks > w->task_slots) {
        int *f = realloc(w->task_first, sizeof *f * 3 * (size_t)w->ntasks);
        if (!f)
            return -1;
        w->task_first = f;
        w->task_slots = w->ntasks;
    }
    int nthreads = omp_get_max_threads();
    if (nthreads > w->nthreads) {
        cs_index_pairs *f = realloc(w->found, sizeof *f * (size_t)nthreads);
        if (!f)
            return -1;
        memset(f + w->nthreads, 0, sizeof *f * (size_t)(nthreads - w->nthreads));
        w->found = f;
        w->nthreads = nthreads;
    }
    int failed = 0;
#pragma omp parallel reduction(| : failed)
    {
        /* the thread's list filled in a copy on its stack: lists side by
         * side in w->found share cache lines, and two threads pushing onto
         * neighbours passed a line back and forth at every pair */
        int me = omp_get_thread_num();
        cs_index_pairs found = w->found[me];
        found.n = 0;
#pragma omp for schedule(dynamic, 1)
        for (int t = 0; t < w->ntasks; t++) {
            int first = found.n;
            traversal tr = {A, B, A == B, rank, reach, 0, NULL, &found, 0};
            descend(&tr, w->task[2 * t], w->task[2 * t + 1], 0);
            w->task_first[3 * t] = first;
            w->task_first[3 * t + 1] = found.n - first;
            w->task_first[3 * t + 2] = me;
            failed |= tr.failed;
        }
        w->found[me] = found;
    }
    long total = 0;
    for (int t = 0; t < w->ntasks; t++)
        total += w->task_first[3 * t + 1];
    if (failed || total > INT_MAX / 2)
        return -1;
    if (total > out->capacity) {
        int *ab = realloc(out->ab, sizeof *ab * 2 * (size_t)total);
        if (!ab)
            return -1;
        out->ab = ab;
        out->capacity = (int)total;
    }
    for (int t = 0; t < w->ntasks; t++) { /* task order: the depth-first order */
        const int *f = w->task_first + 3 * t;
        if (f[1] > 0)
            memcpy(out->ab + 2 * (size_t)out->n, w->found[f[2]].ab + 2 * (size_t)f[0],
                   sizeof *out->ab * 2 * (size_t)f[1]);
        out->n += f[1];
    }
    return 0;
}

void cs_bvh_work_free(cs_bvh_work *w)
{
    for (int t = 0; t < w->nthreads; t++)
        free(w->found[t].ab);
    free(w->found);
    free(w->task);
    free(w->task_first);
    memset(w, 0, sizeof *w);
}

int cs_bvh_set_ranks(cs_bvh *t, const int *prim_rank)
{
    if (!t->rank_lo) {
        t->rank_lo = malloc(sizeof *t->rank_lo * ((size_t)t->nnodes + 1));
        t->rank_hi = malloc(sizeof *t->rank_hi * ((size_t)t->nnodes + 1));
        if (!t->rank_lo || !t->rank_hi)
            return -1;
    }
    for (int node = t->nnodes - 1; node >= 0; node--) { /* children first */
        int l = t->child[2 * node], lo = INT_MAX, hi = INT_MIN;
        if (l < 0) {
            for (int k = t->first[node]; k < t->first[node] + t->count[node]; k++) {
                int r = prim_rank[t->order[k]];
                lo = r < lo ? r : lo;
                hi = r > hi ? r : hi;
            }
        } else {
            int r = t->child[2 * node + 1];
            lo = t->rank_lo[l] < t->rank_lo[r] ? t->rank_lo[l] : t->rank_lo[r];
            hi = t->rank_hi[l] > t->rank_hi[r] ? t->rank_hi[l] : t->rank_hi[r];
        }
        t->rank_lo[node] = lo;
        t->rank_hi[node] = hi;
    }
    return 0;
}
