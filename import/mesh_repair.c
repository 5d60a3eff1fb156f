/* mesh_repair.c: what import does to a mesh after reading it, the same for
 * every format: vertices at identical positions joined (STL and unwelded
 * PLY store one per triangle corner, and glTF splits at UV seams),
 * zero-area and duplicate triangles and unreferenced vertices dropped; the
 * topology analysed (boundary, non-manifold and inconsistently oriented
 * edges, parts, closedness); and holes closed for a level set's sign.
 */
#include "import/mesh_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------- welding */

static uint64_t mix64(uint64_t h)
{
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ULL;
    h ^= h >> 33;
    return h;
}

static uint64_t hash_point(const double *p)
{
    uint64_t h = 0x9e3779b97f4a7c15ULL;
    for (int k = 0; k < 3; k++) {
        double v = p[k] + 0.0; /* -0.0 and 0.0 are one position */
        uint64_t bits;
        memcpy(&bits, &v, sizeof bits);
        h = mix64(h ^ bits) + (uint64_t)k;
    }
    return h;
}

/* Joins vertices at exactly equal positions: remap[i] is the kept index,
 * kept vertices renumbered from 0 in first-seen order. Returns the count
 * kept, or -1 when memory runs out. */
int cs_mesh_weld(const double *x, int nv, int *remap)
{
    size_t cap = 16;
    while (cap < 2 * (size_t)nv)
        cap *= 2;
    int *table = malloc(cap * sizeof *table);   /* original index of a kept vertex */
    int *first = malloc((size_t)nv * sizeof *first);
    if (!table || !first) {
        free(table);
        free(first);
        return -1;
    }
    for (size_t i = 0; i < cap; i++)
        table[i] = -1;
    int kept = 0;
    for (int i = 0; i < nv; i++) {
        const double *p = x + 3 * i;
        size_t h = (size_t)hash_point(p) & (cap - 1);
        for (;;) {
            int j = table[h];
            if (j < 0) {
                table[h] = i;
                first[i] = kept;
                remap[i] = kept++;
                break;
            }
            const double *q = x + 3 * j;
            if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) {
                remap[i] = first[j];
                break;
            }
            h = (h + 1) & (cap - 1);
        }
    }
    free(table);
    free(first);
    return kept;
}

/* ------------------------------------------------------ clean-up */

static double tri_area2(const double *x, const int *t, double cr[3])
{
    const double *a = x + 3 * t[0], *b = x + 3 * t[1], *c = x + 3 * t[2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    cr[0] = u[1] * w[2] - u[2] * w[1];
    cr[1] = u[2] * w[0] - u[0] * w[2];
    cr[2] = u[0] * w[1] - u[1] * w[0];
    return sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
}

typedef struct tri_key {
    int v[3];   /* sorted */
    int index;
} tri_key;

static int tri_key_cmp(const void *pa, const void *pb)
{
    const tri_key *a = pa, *b = pb;
    for (int k = 0; k < 3; k++)
        if (a->v[k] != b->v[k])
            return a->v[k] < b->v[k] ? -1 : 1;
    return (a->index > b->index) - (a->index < b->index);
}

static void sort3(int v[3])
{
    int t;
    if (v[0] > v[1])
        t = v[0], v[0] = v[1], v[1] = t;
    if (v[1] > v[2])
        t = v[1], v[1] = v[2], v[2] = t;
    if (v[0] > v[1])
        t = v[0], v[0] = v[1], v[1] = t;
}

/* Welds, drops zero-area and duplicate triangles and unreferenced vertices.
 * x/tri are the raw arrays (nv, nt); returns a new mesh or NULL (memory). */
cs_trimesh *cs_mesh_clean(const double *x, int nv, const int *tri, int nt, cs_mesh_report *r)
{
    int *remap = malloc(((size_t)nv + 1) * sizeof *remap);
    int *t2 = malloc(((size_t)nt * 3 + 1) * sizeof *t2);
    tri_key *keys = malloc(((size_t)nt + 1) * sizeof *keys);
    unsigned char *drop = calloc((size_t)nt + 1, 1);
    int *used = NULL;
    cs_trimesh *out = NULL;
    if (!remap || !t2 || !keys || !drop)
        goto done;
    int kept = cs_mesh_weld(x, nv, remap);
    if (kept < 0)
        goto done;
    r->welded_vertices = nv - kept;

    /* zero area, relative to the mesh's size so that units do not matter */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < nv; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], x[3 * i + k]);
            hi[k] = fmax(hi[k], x[3 * i + k]);
        }
    double diag2 = 0;
    for (int k = 0; k < 3; k++)
        diag2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    int nk = 0;
    for (int t = 0; t < nt; t++) {
        int v[3];
        double cr[3];
        for (int k = 0; k < 3; k++)
            v[k] = t2[3 * t + k] = remap[tri[3 * t + k]];
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2] ||
            !(tri_area2(x, tri + 3 * t, cr) > 1e-14 * diag2)) {
            drop[t] = 1;
            r->degenerate_triangles++;
            continue;
        }
        sort3(v);
        memcpy(keys[nk].v, v, sizeof v);
        keys[nk++].index = t;
    }
    /* duplicates, either orientation: the first in file order stays */
    qsort(keys, (size_t)nk, sizeof *keys, tri_key_cmp);
    for (int i = 1; i < nk; i++)
        if (!memcmp(keys[i].v, keys[i - 1].v, sizeof keys[i].v)) {
            drop[keys[i].index] = 1;
            r->duplicate_triangles++;
        }

    /* keep referenced vertices, in order */
    used = malloc(((size_t)kept + 1) * sizeof *used);
    if (!used)
        goto done;
    for (int i = 0; i < kept; i++)
        used[i] = -1;
    int ntri = 0, nvert = 0;
    for (int t = 0; t < nt; t++) {
        if (drop[t])
            continue;
        ntri++;
        for (int k = 0; k < 3; k++)
            if (used[t2[3 * t + k]] < 0)
                used[t2[3 * t + k]] = nvert++;
    }
    r->unreferenced_vertices = kept - nvert;
    out = cs_trimesh_create(nvert, ntri);
    if (!out)
        goto done;
    for (int i = 0; i < nv; i++) {
        int j = used[remap[i]];
        if (j >= 0)
            memcpy(out->x + 3 * j, x + 3 * i, 3 * sizeof(double));
    }
    int o = 0;
    for (int t = 0; t < nt; t++) {
        if (drop[t])
            continue;
        for (int k = 0; k < 3; k++)
            out->tri[3 * o + k] = used[t2[3 * t + k]];
        o++;
    }
done:
    free(remap);
    free(t2);
    free(keys);
    free(drop);
    free(used);
    return out;
}

/* ---------------------------------------------------------- topology */

typedef struct half_edge {
    int a, b;   /* a < b */
    int dir;    /* +1: a -> b in its triangle, -1: b -> a */
    int tri;
} half_edge;

static int half_edge_cmp(const void *pa, const void *pb)
{
    const half_edge *p = pa, *q = pb;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    return (p->tri > q->tri) - (p->tri < q->tri);
}

static int find_root(int *parent, int i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/* Boundary half-edges (as the triangle walks them: from -> to). */
typedef struct bedge {
    int from, to;
} bedge;

static int bedge_cmp(const void *pa, const void *pb)
{
    const bedge *p = pa, *q = pb;
    if (p->from != q->from)
        return p->from < q->from ? -1 : 1;
    return (p->to > q->to) - (p->to < q->to);
}

/* Every triangle's three edges, sorted so that the uses of one edge are
 * adjacent (3 nt of them); NULL when memory runs out. */
static half_edge *sorted_half_edges(const cs_trimesh *m)
{
    size_t ne = 3 * (size_t)m->nt;
    half_edge *e = malloc((ne + 1) * sizeof *e);
    if (!e)
        return NULL;
    for (int t = 0; t < m->nt; t++)
        for (int k = 0; k < 3; k++) {
            int u = m->tri[3 * t + k], v = m->tri[3 * t + (k + 1) % 3];
            half_edge *h = &e[3 * t + k];
            h->a = u < v ? u : v;
            h->b = u < v ? v : u;
            h->dir = u < v ? 1 : -1;
            h->tri = t;
        }
    qsort(e, ne, sizeof *e, half_edge_cmp);
    return e;
}

/* The boundary half-edges sorted by start vertex; count in *n. */
static bedge *boundary_edges(const cs_trimesh *m, int *n)
{
    size_t ne = 3 * (size_t)m->nt;
    half_edge *e = sorted_half_edges(m);
    bedge *b = malloc((ne + 1) * sizeof *b);
    *n = 0;
    if (!e || !b) {
        free(e);
        free(b);
        return NULL;
    }
    for (size_t i = 0; i < ne;) {
        size_t j = i;
        while (j < ne && e[j].a == e[i].a && e[j].b == e[i].b)
            j++;
        if (j - i == 1) {
            b[*n].from = e[i].dir > 0 ? e[i].a : e[i].b;
            b[*n].to = e[i].dir > 0 ? e[i].b : e[i].a;
            (*n)++;
        }
        i = j;
    }
    free(e);
    qsort(b, (size_t)*n, sizeof *b, bedge_cmp);
    return b;
}

/* Walks boundary half-edges into loops. For each closed loop calls fn with
 * its vertices in order (when fn is given). Returns the number of loops, or
 * -1 on memory. Half-edges that do not close a loop (inconsistent
 * orientation) are left alone. */
typedef int (*loop_fn)(void *ctx, const int *v, int n);

static int walk_loops(const cs_trimesh *m, loop_fn fn, void *ctx)
{
    int nb;
    bedge *b = boundary_edges(m, &nb);
    if (!b)
        return m->nt > 0 ? -1 : 0;
    int *start = malloc(((size_t)m->nv + 1) * sizeof *start);
    unsigned char *done = calloc((size_t)nb + 1, 1);
    int *loop = malloc(((size_t)nb + 1) * sizeof *loop);
    int loops = 0;
    if (!start || !done || !loop) {
        loops = -1;
        goto out;
    }
    for (int i = 0; i <= m->nv; i++)
        start[i] = nb;
    for (int i = nb - 1; i >= 0; i--)
        start[b[i].from] = i;
    for (int s = 0; s < nb; s++) {
        if (done[s])
            continue;
        /* follow unused half-edges from b[s].from until back at it */
        int n = 0, cur = s;
        bool closed = false;
        while (cur < nb && !done[cur]) {
            done[cur] = 1;
            loop[n++] = b[cur].from;
            if (b[cur].to == b[s].from) {
                closed = true;
                break;
            }
            int v = b[cur].to, next = nb;
            for (int k = start[v]; k < nb && b[k].from == v; k++)
                if (!done[k]) {
                    next = k;
                    break;
                }
            cur = next;
        }
        if (closed && n >= 3) {
            loops++;
            if (fn && fn(ctx, loop, n) != 0) {
                loops = -1;
                goto out;
            }
        } else if (closed) {
            loops++; /* a two-edge loop (a slit): nothing to fill */
        }
    }
out:
    free(b);
    free(start);
    free(done);
    free(loop);
    return loops;
}

void cs_mesh_analyse(const cs_trimesh *m, cs_mesh_report *r)
{
    r->boundary_edges = r->nonmanifold_edges = r->inconsistent_edges = 0;
    r->boundary_loops = r->parts = 0;
    r->area = r->volume = 0;
    for (int k = 0; k < 3; k++) {
        r->min[k] = m->nv > 0 ? INFINITY : 0;
        r->max[k] = m->nv > 0 ? -INFINITY : 0;
    }
    for (int i = 0; i < m->nv; i++)
        for (int k = 0; k < 3; k++) {
            r->min[k] = fmin(r->min[k], m->x[3 * i + k]);
            r->max[k] = fmax(r->max[k], m->x[3 * i + k]);
        }
    r->vertices = m->nv;
    r->triangles = m->nt;
    for (int t = 0; t < m->nt; t++) {
        double cr[3];
        const double *a = m->x + 3 * m->tri[3 * t];
        r->area += 0.5 * tri_area2(m->x, m->tri + 3 * t, cr);
        r->volume += (a[0] * cr[0] + a[1] * cr[1] + a[2] * cr[2]) / 6.0;
    }
    r->volume = fabs(r->volume);

    size_t ne = 3 * (size_t)m->nt;
    half_edge *e = sorted_half_edges(m);
    int *parent = malloc(((size_t)m->nv + 1) * sizeof *parent);
    if (e && parent) {
        for (size_t i = 0; i < ne;) {
            size_t j = i;
            while (j < ne && e[j].a == e[i].a && e[j].b == e[i].b)
                j++;
            if (j - i == 1)
                r->boundary_edges++;
            else if (j - i > 2)
                r->nonmanifold_edges++;
            else if (e[i].dir == e[i + 1].dir)
                r->inconsistent_edges++;
            i = j;
        }
        for (int i = 0; i < m->nv; i++)
            parent[i] = i;
        for (int t = 0; t < m->nt; t++) {
            int a = find_root(parent, m->tri[3 * t]);
            for (int k = 1; k < 3; k++) {
                int b = find_root(parent, m->tri[3 * t + k]);
                if (a != b)
                    parent[b] = a;
            }
        }
        for (int i = 0; i < m->nv; i++)
            r->parts += parent[i] == i;
    }
    free(e);
    free(parent);
    int loops = walk_loops(m, NULL, NULL);
    r->boundary_loops = loops > 0 ? loops : 0;
    r->closed = r->boundary_edges == 0 && r->nonmanifold_edges == 0;
}

/* ---------------------------------------------------------- hole filling */

typedef struct fill_state {
    int filled;
    double *x;
    int nv, cap_v;
    int *tri;
    int nt, cap_t;
} fill_state;

static int fill_loop(void *ctx, const int *v, int n)
{
    fill_state *f = ctx;
    if (f->nv + 1 > f->cap_v || f->nt + n > f->cap_t) {
        int cv = 2 * (f->nv + 1), ct = 2 * (f->nt + n);
        double *x = realloc(f->x, 3 * (size_t)cv * sizeof *x);
        if (!x)
            return -1;
        f->x = x;
        int *t = realloc(f->tri, 3 * (size_t)ct * sizeof *t);
        if (!t)
            return -1;
        f->tri = t;
        f->cap_v = cv;
        f->cap_t = ct;
    }
    double c[3] = {0, 0, 0};
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            c[k] += f->x[3 * v[i] + k] / n;
    int ci = f->nv++;
    f->filled++;
    memcpy(f->x + 3 * ci, c, sizeof c);
    /* The loop runs the way its triangles walk their boundary edges; the
     * fan walks each edge the other way, as a neighbour must. */
    for (int i = 0; i < n; i++) {
        int *t = f->tri + 3 * f->nt++;
        t[0] = v[(i + 1) % n];
        t[1] = v[i];
        t[2] = ci;
    }
    return 0;
}

int cs_mesh_close_holes(cs_trimesh **mesh)
{
    cs_trimesh *m = *mesh;
    fill_state f = {0};
    f.nv = f.cap_v = m->nv;
    f.nt = f.cap_t = m->nt;
    f.x = malloc(3 * ((size_t)m->nv + 1) * sizeof *f.x);
    f.tri = malloc(3 * ((size_t)m->nt + 1) * sizeof *f.tri);
    if (!f.x || !f.tri) {
        free(f.x);
        free(f.tri);
        return -1;
    }
    memcpy(f.x, m->x, 3 * (size_t)m->nv * sizeof *f.x);
    memcpy(f.tri, m->tri, 3 * (size_t)m->nt * sizeof *f.tri);
    int loops = walk_loops(m, fill_loop, &f);
    if (loops > 0 && f.filled > 0) {
        cs_trimesh *out = cs_trimesh_create(f.nv, f.nt);
        if (!out) {
            loops = -1;
        } else {
            memcpy(out->x, f.x, 3 * (size_t)f.nv * sizeof *f.x);
            memcpy(out->tri, f.tri, 3 * (size_t)f.nt * sizeof *f.tri);
            cs_trimesh_destroy(m);
            *mesh = out;
        }
    }
    free(f.x);
    free(f.tri);
    return loops < 0 ? -1 : f.filled;
}
