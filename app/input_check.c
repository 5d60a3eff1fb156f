/* input_check.c: what is wrong with a scene's initial state, found before a
 * run (`clothsim check SCENE` and the start of `clothsim run`): each kind
 * of finding looked for. See input_check.h and docs/input-check.md.
 *
 * Every cloth's vertices are put in one array, in the simulation's particle
 * order (cloth after cloth), and its triangles in global indices: the mesh
 * cs_sim_count_intersections gives the verifier, so the pairs found here are
 * exactly the ones `clothsim intersections` finds in frame 0 of a run
 * (written as one OBJ or glTF file). Bodies are asked at time 0 through
 * their public signed distance (cs_body_def_phi).
 */
#include "app/input_check_internal.h"

#include "sim/sim.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define INSIDE_EPS 1e-9      /* m: phi below -this is inside a body */
#define DEGEN_RATIO 1e-8     /* |e1 x e2| / longest edge^2 below this: degenerate */

void cs_cloth_set_free(cloth_set *s)
{
    free(s->voff);
    free(s->toff);
    free(s->x);
    free(s->tri);
    free(s->tcloth);
    free(s->vcloth);
    memset(s, 0, sizeof *s);
}

int cs_cloth_set_init(cloth_set *s, const cs_scene *scene)
{
    memset(s, 0, sizeof *s);
    s->scene = scene;
    int nc = s->ncloths = scene->def.ncloths;
    s->voff = calloc((size_t)nc + 1, sizeof *s->voff);
    s->toff = calloc((size_t)nc + 1, sizeof *s->toff);
    if (!s->voff || !s->toff)
        return -1;
    for (int c = 0; c < nc; c++) {
        const cs_trimesh *m = scene->def.cloths[c].mesh;
        s->voff[c + 1] = s->voff[c] + m->nv;
        s->toff[c + 1] = s->toff[c] + m->nt;
    }
    s->nv = s->voff[nc];
    s->nt = s->toff[nc];
    s->x = malloc(3 * sizeof *s->x * ((size_t)s->nv + 1));
    s->tri = malloc(3 * sizeof *s->tri * ((size_t)s->nt + 1));
    s->tcloth = malloc(sizeof *s->tcloth * ((size_t)s->nt + 1));
    s->vcloth = malloc(sizeof *s->vcloth * ((size_t)s->nv + 1));
    if (!s->x || !s->tri || !s->tcloth || !s->vcloth)
        return -1;
    for (int c = 0; c < nc; c++) {
        const cs_trimesh *m = scene->def.cloths[c].mesh;
        memcpy(s->x + 3 * (size_t)s->voff[c], m->x, 3 * sizeof *m->x * (size_t)m->nv);
        for (int v = 0; v < m->nv; v++)
            s->vcloth[s->voff[c] + v] = c;
        for (int t = 0; t < m->nt; t++) {
            s->tcloth[s->toff[c] + t] = c;
            for (int k = 0; k < 3; k++)
                s->tri[3 * ((size_t)s->toff[c] + t) + k] = s->voff[c] + m->tri[3 * t + k];
        }
    }
    return 0;
}

const char *cs_cloth_set_name(const cloth_set *s, int c)
{
    const char *n = s->scene->def.cloths[c].name;
    return n ? n : "?";
}

static void add(report *r, int kind, const finding *f)
{
    kind_list *l = &r->k[kind];
    l->count++;
    if (l->n < LIST_MAX)
        l->first[l->n++] = *f;
}

static const double *vx(const cloth_set *s, int v) { return s->x + 3 * (size_t)v; }

/* The mean of n vertices of the set. */
static void mean_of(const cloth_set *s, const int *v, int n, double out[3])
{
    out[0] = out[1] = out[2] = 0;
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            out[k] += vx(s, v[i])[k] / n;
}

/* ------------------------------------------------------------ intersections */

static int check_intersections(const cloth_set *s, report *r)
{
    int cap = 4096;
    int *pairs = malloc(2 * sizeof *pairs * (size_t)cap);
    if (!pairs)
        return -1;
    long n = cs_find_intersections(s->nv, s->x, s->nt, s->tri, cap, pairs);
    if (n > cap && n <= INT_MAX / 2) {
        free(pairs);
        cap = (int)n;
        pairs = malloc(2 * sizeof *pairs * (size_t)cap);
        if (!pairs)
            return -1;
        n = cs_find_intersections(s->nv, s->x, s->nt, s->tri, cap, pairs);
    }
    if (n < 0) {
        free(pairs);
        return -1;
    }
    r->verifier_pairs = n;
    for (long k = 0; k < n && k < cap; k++) {
        int t = pairs[2 * k], u = pairs[2 * k + 1];
        int ct = s->tcloth[t], cu = s->tcloth[u];
        int v6[6];
        memcpy(v6, s->tri + 3 * (size_t)t, 3 * sizeof *v6);
        memcpy(v6 + 3, s->tri + 3 * (size_t)u, 3 * sizeof *v6);
        finding f = {.cloth = ct, .a = t - s->toff[ct], .cloth2 = cu, .b = u - s->toff[cu],
                     .body = -1};
        mean_of(s, v6, 6, f.pos);
        add(r, ct == cu ? K_SELF : K_CROSS, &f);
    }
    free(pairs);
    return 0;
}

/* ------------------------------------------------------------------- edges */

typedef struct edge {
    int a, b, t; /* a < b, global vertices; t the global triangle */
} edge;

static int edge_cmp(const void *p, const void *q)
{
    const edge *e = p, *f = q;
    if (e->a != f->a)
        return e->a < f->a ? -1 : 1;
    if (e->b != f->b)
        return e->b < f->b ? -1 : 1;
    return (e->t > f->t) - (e->t < f->t);
}

/* Every triangle's three edges, sorted: a run of equal (a, b) is one edge. */
static edge *all_edges(const cloth_set *s)
{
    edge *e = malloc(sizeof *e * (3 * (size_t)s->nt + 1));
    if (!e)
        return NULL;
    for (int t = 0; t < s->nt; t++)
        for (int k = 0; k < 3; k++) {
            int a = s->tri[3 * (size_t)t + k], b = s->tri[3 * (size_t)t + (k + 1) % 3];
            e[3 * (size_t)t + k] = (edge){a < b ? a : b, a < b ? b : a, t};
        }
    qsort(e, 3 * (size_t)s->nt, sizeof *e, edge_cmp);
    return e;
}

static void check_topology(const cloth_set *s, const edge *e, report *r)
{
    for (int t = 0; t < s->nt; t++) {
        const int *v = s->tri + 3 * (size_t)t;
        const double *p = vx(s, v[0]), *q = vx(s, v[1]), *w = vx(s, v[2]);
        double e1[3], e2[3], n[3];
        for (int k = 0; k < 3; k++)
            e1[k] = q[k] - p[k], e2[k] = w[k] - p[k];
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double cross = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double longest = fmax(cs_dist3(p, q), fmax(cs_dist3(q, w), cs_dist3(w, p)));
        if (!(cross > DEGEN_RATIO * longest * longest) || longest == 0) {
            int c = s->tcloth[t];
            finding f = {.cloth = c, .a = t - s->toff[c], .cloth2 = -1, .b = -1, .body = -1,
                         .value = 0.5 * cross};
            mean_of(s, v, 3, f.pos);
            add(r, K_DEGEN, &f);
        }
    }
    size_t ne = 3 * (size_t)s->nt;
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && e[j].a == e[i].a && e[j].b == e[i].b)
            j++;
        if (j - i > 2) {
            int c = s->vcloth[e[i].a];
            finding f = {.cloth = c, .a = e[i].a - s->voff[c], .cloth2 = c,
                         .b = e[i].b - s->voff[c], .body = -1, .value = (double)(j - i)};
            int ab[2] = {e[i].a, e[i].b};
            mean_of(s, ab, 2, f.pos);
            add(r, K_NONMANIFOLD, &f);
        }
        i = j;
    }
}

/* ------------------------------------------------------------------ bodies */

static int check_bodies(const cloth_set *s, const edge *e, report *r)
{
    const cs_scene *scene = s->scene;
    if (!cs_input_bodies_on(scene))
        return 0;
    r->bodies_checked = true;
    double *phi = malloc(sizeof *phi * ((size_t)s->nv + 1));
    if (!phi)
        return -1;
    size_t ne = 3 * (size_t)s->nt;
    for (int b = 0; b < scene->def.nbodies; b++) {
        const cs_body_def *bd = &scene->def.bodies[b];
        double thr = cs_input_body_threshold(scene, b);
        for (int v = 0; v < s->nv; v++) {
            double g[3];
            phi[v] = cs_body_def_phi(bd, 0.0, vx(s, v), g);
            int c = s->vcloth[v];
            finding f = {.cloth = c, .a = v - s->voff[c], .cloth2 = -1, .b = -1, .body = b};
            memcpy(f.pos, vx(s, v), sizeof f.pos);
            if (phi[v] < -INSIDE_EPS) {
                f.value = -phi[v];
                add(r, K_BODY_IN, &f);
            } else if (phi[v] < thr) {
                f.value = phi[v];
                add(r, K_BODY_NEAR, &f);
            }
        }
        /* edges whose ends are outside: a few points along them (phi is a
         * distance, so an edge shorter than its ends' phi cannot reach in) */
        for (size_t i = 0; i < ne; i++) {
            if (i > 0 && e[i].a == e[i - 1].a && e[i].b == e[i - 1].b)
                continue;
            int a = e[i].a, bb = e[i].b;
            double len = cs_dist3(vx(s, a), vx(s, bb));
            if (phi[a] < -INSIDE_EPS || phi[bb] < -INSIDE_EPS || fmin(phi[a], phi[bb]) > len)
                continue;
            double worst = 0, at[3] = {0, 0, 0};
            for (int k = 1; k < 8; k++) {
                double t = k / 8.0, p[3], g[3];
                for (int d = 0; d < 3; d++)
                    p[d] = (1 - t) * vx(s, a)[d] + t * vx(s, bb)[d];
                double ph = cs_body_def_phi(bd, 0.0, p, g);
                if (ph < worst) {
                    worst = ph;
                    memcpy(at, p, sizeof at);
                }
            }
            if (worst < -INSIDE_EPS) {
                int c = s->vcloth[a];
                finding f = {.cloth = c, .a = a - s->voff[c], .cloth2 = c, .b = bb - s->voff[c],
                             .body = b, .value = -worst};
                memcpy(f.pos, at, sizeof f.pos);
                add(r, K_BODY_EDGE, &f);
            }
        }
    }
    free(phi);
    return 0;
}

/* -------------------------------------------------------------- closeness */

/* The point of triangle abc closest to p (Ericson, Real-Time Collision
 * Detection, 5.1.5). */
static void closest_on_triangle(const double *p, const double *a, const double *b,
                                const double *c, double out[3])
{
    double ab[3], ac[3], ap[3];
    for (int k = 0; k < 3; k++)
        ab[k] = b[k] - a[k], ac[k] = c[k] - a[k], ap[k] = p[k] - a[k];
#define DOT(u, v) ((u)[0] * (v)[0] + (u)[1] * (v)[1] + (u)[2] * (v)[2])
    double d1 = DOT(ab, ap), d2 = DOT(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        memcpy(out, a, 3 * sizeof *out);
        return;
    }
    double bp[3], cp[3];
    for (int k = 0; k < 3; k++)
        bp[k] = p[k] - b[k], cp[k] = p[k] - c[k];
    double d3 = DOT(ab, bp), d4 = DOT(ac, bp);
    if (d3 >= 0 && d4 <= d3) {
        memcpy(out, b, 3 * sizeof *out);
        return;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; k++)
            out[k] = a[k] + v * ab[k];
        return;
    }
    double d5 = DOT(ab, cp), d6 = DOT(ac, cp);
    if (d6 >= 0 && d5 <= d6) {
        memcpy(out, c, 3 * sizeof *out);
        return;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double w = d2 / (d2 - d6);
        for (int k = 0; k < 3; k++)
            out[k] = a[k] + w * ac[k];
        return;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; k++)
            out[k] = b[k] + w * (c[k] - b[k]);
        return;
    }
    double den = va + vb + vc;
    if (!(fabs(den) > 0)) { /* degenerate: the nearest vertex will do */
        memcpy(out, a, 3 * sizeof *out);
        return;
    }
    double v = vb / den, w = vc / den;
    for (int k = 0; k < 3; k++)
        out[k] = a[k] + ab[k] * v + ac[k] * w;
#undef DOT
}

static uint64_t cell_hash(long i, long j, long k)
{
    uint64_t h = (uint64_t)i * 73856093u ^ (uint64_t)j * 19349663u ^ (uint64_t)k * 83492791u;
    return h * 0x9E3779B97F4A7C15ull;
}

/* Vertex-triangle pairs (the vertex not a corner of the triangle) closer
 * than the thickness h: vertices in a hash grid of cells at least h wide,
 * each triangle's box grown by h looked up in it. */
static int check_closeness(const cloth_set *s, report *r)
{
    double h = s->scene->def.self.thickness;
    if (!s->scene->def.self_collision || !(h > 0) || s->nt == 0)
        return 0;
    r->self_checked = true;
    double edges = 0;
    for (int t = 0; t < s->nt; t++)
        edges += cs_dist3(vx(s, s->tri[3 * (size_t)t]), vx(s, s->tri[3 * (size_t)t + 1]));
    double cell = fmax(h, edges / s->nt);
    size_t nb = 1;
    while (nb < 2 * (size_t)s->nv + 1)
        nb <<= 1;
    long (*vc)[3] = malloc(sizeof *vc * ((size_t)s->nv + 1));
    size_t *start = calloc(nb + 1, sizeof *start);
    int *order = malloc(sizeof *order * ((size_t)s->nv + 1));
    if (!vc || !start || !order) {
        free(vc);
        free(start);
        free(order);
        return -1;
    }
    for (int v = 0; v < s->nv; v++) {
        for (int k = 0; k < 3; k++)
            vc[v][k] = (long)floor(vx(s, v)[k] / cell);
        start[(cell_hash(vc[v][0], vc[v][1], vc[v][2]) & (nb - 1)) + 1]++;
    }
    for (size_t i = 0; i < nb; i++)
        start[i + 1] += start[i];
    {
        size_t *fill = malloc(sizeof *fill * (nb + 1));
        if (!fill) {
            free(vc);
            free(start);
            free(order);
            return -1;
        }
        memcpy(fill, start, sizeof *fill * (nb + 1));
        for (int v = 0; v < s->nv; v++)
            order[fill[cell_hash(vc[v][0], vc[v][1], vc[v][2]) & (nb - 1)]++] = v;
        free(fill);
    }
    for (int t = 0; t < s->nt; t++) {
        const int *tv = s->tri + 3 * (size_t)t;
        const double *a = vx(s, tv[0]), *b = vx(s, tv[1]), *c = vx(s, tv[2]);
        long lo[3], hi[3];
        for (int k = 0; k < 3; k++) {
            lo[k] = (long)floor((fmin(a[k], fmin(b[k], c[k])) - h) / cell);
            hi[k] = (long)floor((fmax(a[k], fmax(b[k], c[k])) + h) / cell);
        }
        for (long i = lo[0]; i <= hi[0]; i++)
            for (long j = lo[1]; j <= hi[1]; j++)
                for (long k = lo[2]; k <= hi[2]; k++) {
                    size_t bucket = cell_hash(i, j, k) & (nb - 1);
                    for (size_t q = start[bucket]; q < start[bucket + 1]; q++) {
                        int v = order[q];
                        if (vc[v][0] != i || vc[v][1] != j || vc[v][2] != k || v == tv[0] ||
                            v == tv[1] || v == tv[2])
                            continue;
                        double cp[3];
                        closest_on_triangle(vx(s, v), a, b, c, cp);
                        double d = cs_dist3(vx(s, v), cp);
                        if (d < h) {
                            int cv = s->vcloth[v], ct = s->tcloth[t];
                            finding f = {.cloth = cv, .a = v - s->voff[cv], .cloth2 = ct,
                                         .b = t - s->toff[ct], .body = -1, .value = d};
                            memcpy(f.pos, vx(s, v), sizeof f.pos);
                            add(r, K_SELF_NEAR, &f);
                        }
                    }
                }
    }
    free(vc);
    free(start);
    free(order);
    return 0;
}

/* --------------------------------------------------------------- analysis */

int cs_input_analyse(const cloth_set *s, report *r)
{
    memset(r, 0, sizeof *r);
    r->thickness = s->scene->def.self.thickness;
    edge *e = all_edges(s);
    if (!e)
        return -1;
    int rc = check_intersections(s, r);
    if (rc == 0)
        check_topology(s, e, r);
    if (rc == 0)
        rc = check_bodies(s, e, r);
    if (rc == 0)
        rc = check_closeness(s, r);
    free(e);
    return rc;
}
