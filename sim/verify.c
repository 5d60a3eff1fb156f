/* verify.c: exact self-intersection count of a triangle mesh.
 *
 * The proof that the cloth stayed collision-free (Selle et al., Sections 4-5)
 * must not lean on the code it checks, so this file shares nothing with the
 * collision code but sim.h (and the simulation's cloths, internal.h, for
 * cs_sim_count_intersections): its own broad phase, its own narrow phase, and
 * exact predicates (sim/predicates.c: filtered doubles, expansion
 * arithmetic, GMP) so that no answer depends on a tolerance.
 *
 * Broad phase: a uniform hash grid over triangle bounding boxes. Each
 * triangle is entered in every cell its closed box touches; a pair that
 * shares a cell is reported only from the cell holding the lowest corner of
 * the two boxes' intersection, so each pair comes out once without a set.
 * Cell indices come from a monotone function of the coordinate, so closed
 * boxes that touch always share that corner's cell, whatever the rounding.
 * The pairs are then put in (i, j) order, which makes the list of offending
 * pairs deterministic.
 *
 * Narrow phase: closed triangles T and U (each a triangle, a segment or a
 * point) intersect iff some edge of one meets the other. (Non-coplanar:
 * T and U cut the common line in two intervals whose endpoints lie on
 * their edges; two intervals that meet contain an endpoint of one of them.
 * Coplanar: either the boundaries cross or one contains the other. A
 * degenerate triangle is the union of its edges.) An edge ab meets a
 * non-degenerate triangle pqr iff
 *   - a and b are not strictly on one side of its plane (orient3d), and
 *   - if ab crosses the plane transversally, the line ab passes through the
 *     closed triangle: orient3d(a,b,p,q), (a,b,q,r), (a,b,r,p) are not of
 *     mixed strict sign;
 *   - if ab lies in the plane, the test is done in 2D after dropping the
 *     coordinate axis of a nonzero normal component (an exact orient2d of
 *     the projected triangle is nonzero, so the projection is injective on
 *     the plane and every 2D predicate on it is exact).
 * Segment against segment (degenerate triangles) is done in 2D the same
 * way, after an exact coplanarity check and a projection that is injective
 * on the points' affine hull.
 */
#include "sim/internal.h"
#include "sim/sim.h"

#include "sim/predicates.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* A triangle prepared for the narrow phase. */
typedef struct vtri {
    const double *v[3];
    bool degen;   /* collinear or coincident vertices: a segment or a point */
    int axis;     /* if not degen: axis to drop for the 2D (coplanar) tests */
} vtri;

static void proj(const double *p, int k, double out[2])
{
    out[0] = p[(k + 1) % 3];
    out[1] = p[(k + 2) % 3];
}

static void tri_setup(vtri *t, const double *a, const double *b, const double *c)
{
    t->v[0] = a;
    t->v[1] = b;
    t->v[2] = c;
    /* The normal's components are the orient2d of the three projections:
     * exact signs decide degeneracy; the rounded normal only picks the
     * best-conditioned of the usable axes. */
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                   e1[0] * e2[1] - e1[1] * e2[0]};
    int best = -1;
    double bestmag = 0.0;
    for (int k = 0; k < 3; k++) {
        double pa[2], pb[2], pc[2];
        proj(a, k, pa);
        proj(b, k, pb);
        proj(c, k, pc);
        if (cs_orient2d(pa, pb, pc) != 0 && (best < 0 || fabs(n[k]) > bestmag)) {
            best = k;
            bestmag = fabs(n[k]);
        }
    }
    t->degen = best < 0;
    t->axis = best;
}

/* -------------------------------------------------------------------- 2D */

static bool lex_le(const double a[2], const double b[2])
{
    return a[0] < b[0] || (a[0] == b[0] && a[1] <= b[1]);
}

/* Closed segments ab and cd in the plane; either may be a single point. */
static bool seg_seg_2d(const double a[2], const double b[2], const double c[2],
                       const double d[2])
{
    int o1 = cs_orient2d(a, b, c), o2 = cs_orient2d(a, b, d);
    if (o1 * o2 > 0)
        return false;
    int o3 = cs_orient2d(c, d, a), o4 = cs_orient2d(c, d, b);
    if (o3 * o4 > 0)
        return false;
    if (o1 || o2 || o3 || o4)
        return true;   /* proper or endpoint crossing of non-collinear segments */
    /* All four points on one line (or the segments are points): lexicographic
     * order is an order along that line, so compare the intervals. */
    const double *lo1 = lex_le(a, b) ? a : b, *hi1 = lex_le(a, b) ? b : a;
    const double *lo2 = lex_le(c, d) ? c : d, *hi2 = lex_le(c, d) ? d : c;
    return lex_le(lo1, hi2) && lex_le(lo2, hi1);
}

/* Closed point-in-triangle for a non-degenerate triangle abc. */
static bool point_in_tri_2d(const double p[2], const double a[2], const double b[2],
                            const double c[2])
{
    int s1 = cs_orient2d(a, b, p), s2 = cs_orient2d(b, c, p), s3 = cs_orient2d(c, a, p);
    bool pos = s1 > 0 || s2 > 0 || s3 > 0, neg = s1 < 0 || s2 < 0 || s3 < 0;
    return !(pos && neg);
}

/* Closed segment ab against closed non-degenerate triangle pqr, in 2D. */
static bool seg_tri_2d(const double a[2], const double b[2], const double p[2],
                       const double q[2], const double r[2])
{
    return point_in_tri_2d(a, p, q, r) || point_in_tri_2d(b, p, q, r) ||
           seg_seg_2d(a, b, p, q) || seg_seg_2d(a, b, q, r) || seg_seg_2d(a, b, r, p);
}

/* -------------------------------------------------------------------- 3D */

/* An axis whose projection is injective on the affine hull of four
 * coplanar points: the projection that keeps the most dimensions. */
static int hull_axis(const double *const pts[4])
{
    static const int triples[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
    int best = 0, bestrank = -1;
    for (int k = 0; k < 3; k++) {
        double p[4][2];
        for (int i = 0; i < 4; i++)
            proj(pts[i], k, p[i]);
        int rank = 0;
        for (int t = 0; t < 4 && rank < 2; t++)
            if (cs_orient2d(p[triples[t][0]], p[triples[t][1]], p[triples[t][2]]) != 0)
                rank = 2;
        for (int i = 1; i < 4 && rank < 1; i++)
            if (p[i][0] != p[0][0] || p[i][1] != p[0][1])
                rank = 1;
        if (rank > bestrank) {
            best = k;
            bestrank = rank;
        }
        if (rank == 2)
            break;
    }
    return best;
}

/* Closed segments ab and cd in space; either may be a point. */
static bool seg_seg_3d(const double *a, const double *b, const double *c, const double *d)
{
    for (int k = 0; k < 3; k++)
        if (fmax(a[k], b[k]) < fmin(c[k], d[k]) || fmax(c[k], d[k]) < fmin(a[k], b[k]))
            return false;
    if (cs_orient3d(a, b, c, d) != 0)
        return false;
    const double *pts[4] = {a, b, c, d};
    int k = hull_axis(pts);
    double pa[2], pb[2], pc[2], pd[2];
    proj(a, k, pa);
    proj(b, k, pb);
    proj(c, k, pc);
    proj(d, k, pd);
    return seg_seg_2d(pa, pb, pc, pd);
}

/* Closed segment ab against closed triangle t; sa, sb are the orient3d of
 * a and b against t's plane (unused when t is degenerate). */
static bool seg_tri_3d(const double *a, const double *b, int sa, int sb, const vtri *t)
{
    const double *p = t->v[0], *q = t->v[1], *r = t->v[2];
    if (t->degen)
        return seg_seg_3d(a, b, p, q) || seg_seg_3d(a, b, q, r) || seg_seg_3d(a, b, r, p);
    if (sa * sb > 0)
        return false;
    if (sa == 0 && sb == 0) {
        double pa[2], pb[2], pp[2], pq[2], pr[2];
        proj(a, t->axis, pa);
        proj(b, t->axis, pb);
        proj(p, t->axis, pp);
        proj(q, t->axis, pq);
        proj(r, t->axis, pr);
        return seg_tri_2d(pa, pb, pp, pq, pr);
    }
    /* ab crosses the plane at one point of the segment: is it in pqr? */
    int s1 = cs_orient3d(a, b, p, q), s2 = cs_orient3d(a, b, q, r), s3 = cs_orient3d(a, b, r, p);
    bool pos = s1 > 0 || s2 > 0 || s3 > 0, neg = s1 < 0 || s2 < 0 || s3 < 0;
    return !(pos && neg);
}

/* Signs of the vertices of u against t's plane; false if u lies strictly on
 * one side (no intersection possible). */
static bool plane_signs(const vtri *t, const vtri *u, int s[3])
{
    if (t->degen) {
        s[0] = s[1] = s[2] = 0;
        return true;
    }
    for (int i = 0; i < 3; i++)
        s[i] = cs_orient3d(t->v[0], t->v[1], t->v[2], u->v[i]);
    return !((s[0] > 0 && s[1] > 0 && s[2] > 0) || (s[0] < 0 && s[1] < 0 && s[2] < 0));
}

static bool tri_tri(const vtri *t, const vtri *u)
{
    int st[3], su[3];   /* t's vertices against u's plane, u's against t's */
    if (!plane_signs(u, t, st) || !plane_signs(t, u, su))
        return false;
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3;
        if (seg_tri_3d(t->v[i], t->v[j], st[i], st[j], u))
            return true;
    }
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3;
        if (seg_tri_3d(u->v[i], u->v[j], su[i], su[j], t))
            return true;
    }
    return false;
}

bool cs_triangles_intersect(const double p[9], const double q[9])
{
    for (int k = 0; k < 3; k++) {
        double pmin = fmin(fmin(p[k], p[3 + k]), p[6 + k]);
        double pmax = fmax(fmax(p[k], p[3 + k]), p[6 + k]);
        double qmin = fmin(fmin(q[k], q[3 + k]), q[6 + k]);
        double qmax = fmax(fmax(q[k], q[3 + k]), q[6 + k]);
        if (pmax < qmin || qmax < pmin)
            return false;
    }
    vtri t, u;
    tri_setup(&t, p, p + 3, p + 6);
    tri_setup(&u, q, q + 3, q + 6);
    return tri_tri(&t, &u);
}

/* ------------------------------------------------------------ broad phase */

#define CELL_BITS 21
#define CELL_MAX ((1 << CELL_BITS) - 1)

typedef struct grid {
    double origin[3];   /* half the lowest coordinate per axis */
    double h;           /* cell size in halved coordinates */
} grid;

/* Monotone in v, so touching closed boxes share the cell of their contact.
 * Halving keeps huge coordinates from overflowing the difference. */
static int cell_of(const grid *g, int k, double v)
{
    double s = (0.5 * v - g->origin[k]) / g->h;
    if (!(s > 0.0))
        return 0;
    if (s >= (double)CELL_MAX)
        return CELL_MAX;
    return (int)s;
}

static uint64_t cell_key(const int c[3])
{
    return (uint64_t)c[0] | (uint64_t)c[1] << CELL_BITS | (uint64_t)c[2] << (2 * CELL_BITS);
}

static uint64_t hash_key(uint64_t key)
{
    key ^= key >> 31;
    key *= UINT64_C(0x9E3779B97F4A7C15);
    key ^= key >> 29;
    return key;
}

/* Cells touched by box b (lo[3], hi[3]) and how many. */
static int64_t box_cells(const grid *g, const double *b, int lo[3], int hi[3])
{
    int64_t n = 1;
    for (int k = 0; k < 3; k++) {
        lo[k] = cell_of(g, k, b[k]);
        hi[k] = cell_of(g, k, b[3 + k]);
        n *= hi[k] - lo[k] + 1;
    }
    return n;
}

typedef struct pair_list {
    uint64_t *v;
    size_t n, cap;
} pair_list;

static bool pair_push(pair_list *l, uint64_t p)
{
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 1024;
        uint64_t *v = realloc(l->v, cap * sizeof *v);
        if (!v)
            return false;
        l->v = v;
        l->cap = cap;
    }
    l->v[l->n++] = p;
    return true;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static bool share_vertex(const int *a, const int *b)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (a[i] == b[j])
                return true;
    return false;
}

/* Candidate pairs (i < j packed as i << 32 | j): closed boxes overlap, no
 * shared vertex; each pair once, sorted. Returns false on no memory. */
static bool broad_phase(int nt, const int *tri, const double *box, pair_list *out)
{
    /* Cell size: the mean box extent, so a typical triangle touches up to
     * 8 cells; at least 1/2^20 of the whole extent so indices fit. */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double mean = 0.0;
    for (int t = 0; t < nt; t++) {
        const double *b = box + 6 * t;
        double ext = 0.0;
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], b[k]);
            hi[k] = fmax(hi[k], b[3 + k]);
            ext = fmax(ext, 0.5 * b[3 + k] - 0.5 * b[k]);
        }
        mean += (ext - mean) / (t + 1);
    }
    grid g;
    double whole = 0.0;
    for (int k = 0; k < 3; k++) {
        g.origin[k] = 0.5 * lo[k];
        whole = fmax(whole, 0.5 * hi[k] - 0.5 * lo[k]);
    }
    g.h = fmax(mean, whole / (1 << 20));
    if (!(g.h > 0.0))
        g.h = whole > 0.0 ? whole : 1.0;

    /* A few huge triangles among small ones would fill many cells: coarsen
     * until the total stays linear in nt. */
    int64_t total;
    const int64_t limit = 16 * (int64_t)nt + 64;
    for (;;) {
        total = 0;
        for (int t = 0; t < nt && total <= limit; t++) {
            int clo[3], chi[3];
            total += box_cells(&g, box + 6 * t, clo, chi);
        }
        if (total <= limit)
            break;
        g.h *= 2.0;
    }

    size_t nb = 1;
    while (nb < (size_t)total)
        nb <<= 1;
    int shift = 64;
    for (size_t s = nb; s > 1; s >>= 1)
        shift--;
    uint64_t *key = malloc((size_t)total * sizeof *key);
    int *etri = malloc((size_t)total * sizeof *etri);
    uint64_t *skey = malloc((size_t)total * sizeof *skey);
    int *stri = malloc((size_t)total * sizeof *stri);
    size_t *start = calloc(nb + 1, sizeof *start);
    bool ok = key && etri && skey && stri && start;
    if (ok) {
        /* Enter every triangle in its cells, then bucket by hash (counting sort). */
        size_t e = 0;
        for (int t = 0; t < nt; t++) {
            int clo[3], chi[3], c[3];
            box_cells(&g, box + 6 * t, clo, chi);
            for (c[2] = clo[2]; c[2] <= chi[2]; c[2]++)
                for (c[1] = clo[1]; c[1] <= chi[1]; c[1]++)
                    for (c[0] = clo[0]; c[0] <= chi[0]; c[0]++) {
                        key[e] = cell_key(c);
                        etri[e++] = t;
                    }
        }
        for (size_t i = 0; i < e; i++)
            start[(nb > 1 ? hash_key(key[i]) >> shift : 0) + 1]++;
        for (size_t b = 0; b < nb; b++)
            start[b + 1] += start[b];
        for (size_t i = 0; i < e; i++) {
            size_t b = nb > 1 ? hash_key(key[i]) >> shift : 0;
            size_t at = start[b]++;
            skey[at] = key[i];
            stri[at] = etri[i];
        }
        /* start[b] is now the end of bucket b, i.e. the start of b + 1. */
        for (size_t b = 0; b < nb && ok; b++) {
            size_t b0 = b == 0 ? 0 : start[b - 1], b1 = start[b];
            for (size_t u = b0; u < b1 && ok; u++) {
                for (size_t w = u + 1; w < b1 && ok; w++) {
                    if (skey[u] != skey[w])
                        continue;   /* another cell hashed here */
                    int i = stri[u], j = stri[w];
                    const double *bi = box + 6 * i, *bj = box + 6 * j;
                    bool overlap = true;
                    int c[3];
                    for (int k = 0; k < 3 && overlap; k++) {
                        overlap = bi[3 + k] >= bj[k] && bj[3 + k] >= bi[k];
                        c[k] = cell_of(&g, k, fmax(bi[k], bj[k]));
                    }
                    if (!overlap || cell_key(c) != skey[u] || share_vertex(tri + 3 * i, tri + 3 * j))
                        continue;
                    int a = i < j ? i : j, z = i < j ? j : i;
                    ok = pair_push(out, (uint64_t)a << 32 | (uint64_t)z);
                }
            }
        }
    }
    free(key);
    free(etri);
    free(skey);
    free(stri);
    free(start);
    if (!ok)
        return false;

    /* Sort: counting sort on the first triangle, then each group on the
     * second (groups are short). */
    size_t *cnt = calloc((size_t)nt + 1, sizeof *cnt);
    uint64_t *sorted = malloc((out->n ? out->n : 1) * sizeof *sorted);
    if (!cnt || !sorted) {
        free(cnt);
        free(sorted);
        return false;
    }
    for (size_t i = 0; i < out->n; i++)
        cnt[(out->v[i] >> 32) + 1]++;
    for (int t = 0; t < nt; t++)
        cnt[t + 1] += cnt[t];
    for (size_t i = 0; i < out->n; i++)
        sorted[cnt[out->v[i] >> 32]++] = out->v[i];
    /* cnt[t] is now the end of group t. */
    for (int t = 0; t < nt; t++) {
        size_t s = t == 0 ? 0 : cnt[t - 1];
        if (cnt[t] - s > 1)
            qsort(sorted + s, cnt[t] - s, sizeof *sorted, cmp_u64);
    }
    free(cnt);
    free(out->v);
    out->v = sorted;
    out->cap = out->n ? out->n : 1;
    return true;
}

/* ------------------------------------------------------------- the count */

long cs_find_intersections(int nv, const double *x, int nt, const int *tri, int maxpairs,
                           int *pairs)
{
    if (nv < 0 || nt < 0 || (nt > 0 && (!x || !tri)) || (maxpairs > 0 && !pairs))
        return CS_ERR_INVALID;
    if (nt == 0)
        return 0;
    for (int t = 0; t < 3 * nt; t++)
        if (tri[t] < 0 || tri[t] >= nv)
            return CS_ERR_INVALID;

    double *box = malloc((size_t)nt * 6 * sizeof *box);
    vtri *vt = malloc((size_t)nt * sizeof *vt);
    pair_list cand = {0};
    long count = CS_ERR_NOMEM;
    if (!box || !vt)
        goto done;
    for (int t = 0; t < nt; t++) {
        const int *f = tri + 3 * t;
        for (int k = 0; k < 3; k++) {
            for (int i = 0; i < 3; i++) {
                if (!isfinite(x[3 * f[i] + k])) {
                    count = CS_ERR_INVALID;
                    goto done;
                }
            }
            double a = x[3 * f[0] + k], b = x[3 * f[1] + k], c = x[3 * f[2] + k];
            box[6 * t + k] = fmin(fmin(a, b), c);
            box[6 * t + 3 + k] = fmax(fmax(a, b), c);
        }
        tri_setup(&vt[t], x + 3 * f[0], x + 3 * f[1], x + 3 * f[2]);
    }
    if (!broad_phase(nt, tri, box, &cand))
        goto done;

    count = 0;
    for (size_t p = 0; p < cand.n; p++) {
        int i = (int)(cand.v[p] >> 32), j = (int)(cand.v[p] & 0xffffffffu);
        if (!tri_tri(&vt[i], &vt[j]))
            continue;
        if (count < maxpairs) {
            pairs[2 * count] = i;
            pairs[2 * count + 1] = j;
        }
        count++;
    }
done:
    free(box);
    free(vt);
    free(cand.v);
    return count;
}

long cs_count_intersections(int nv, const double *x, int nt, const int *tri)
{
    return cs_find_intersections(nv, x, nt, tri, 0, NULL);
}

/* here, with the verifier, for the verify stage (frame.c) below sim.c */
long cs_sim_count_intersections(const cs_sim *sim)
{
    /* every cloth's triangles in global particle indices, as one mesh */
    long nt = 0;
    for (int c = 0; c < sim->ncloths; c++)
        nt += sim->cloths[c].mesh->nt;
    int *tri = malloc(sizeof *tri * 3 * (size_t)(nt + 1));
    if (!tri)
        return -1;
    long t = 0;
    for (int c = 0; c < sim->ncloths; c++) {
        const cs_trimesh *m = sim->cloths[c].mesh;
        for (int k = 0; k < 3 * m->nt; k++)
            tri[3 * t + k] = sim->cloths[c].offset + m->tri[k];
        t += m->nt;
    }
    long count = cs_count_intersections(sim->n, sim->x, (int)nt, tri);
    free(tri);
    return count;
}
