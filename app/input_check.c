/* input_check.c: what is wrong with a scene's initial state, found before a
 * run: `clothsim check SCENE [--fix -o DIR]` and the start of `clothsim run`
 * (cs_input_check_start). See input_check.h and docs/input-check.md.
 *
 * Every cloth's vertices are put in one array, in the simulation's particle
 * order (cloth after cloth), and its triangles in global indices: the mesh
 * cs_sim_count_intersections gives the verifier, so the pairs found here are
 * exactly the ones `clothsim intersections` finds in frame 0 of a run
 * (written as one OBJ or glTF file). Bodies are asked at time 0 through
 * their public signed distance (cs_body_def_phi).
 */
#include "app/input_check.h"

#include "app/cli.h"
#include "app/run.h"
#include "common/util.h"
#include "import/import.h"
#include "sim/sim.h"

#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define ERRLEN 1024
#define LIST_MAX 20          /* findings listed per kind */
#define INSIDE_EPS 1e-9      /* m: phi below -this is inside a body */
#define DEGEN_RATIO 1e-8     /* |e1 x e2| / longest edge^2 below this: degenerate */

enum kind {
    K_CROSS,       /* triangles of two cloths intersect */
    K_SELF,        /* triangles of one cloth intersect */
    K_BODY_IN,     /* a vertex inside a body */
    K_BODY_EDGE,   /* an edge through a body, both ends outside */
    K_BODY_NEAR,   /* a vertex outside a body but closer than the threshold */
    K_SELF_NEAR,   /* a vertex closer than the thickness to a triangle not its own */
    K_DEGEN,       /* a triangle of (near) zero area */
    K_NONMANIFOLD, /* an edge in more than two triangles */
    K_COUNT
};

static const struct {
    const char *what; /* after the count */
    bool error;       /* what `run` refuses */
} KINDS[K_COUNT] = {
    [K_CROSS] = {"intersecting triangle pairs between different cloths", true},
    [K_SELF] = {"intersecting triangle pairs within a cloth", true},
    [K_BODY_IN] = {"cloth vertices inside a body", true},
    [K_BODY_EDGE] = {"cloth edges through a body with both ends outside it", false},
    [K_BODY_NEAR] = {"cloth vertices outside a body but closer than the threshold", false},
    [K_SELF_NEAR] = {"vertex-triangle pairs of cloth closer than the thickness", false},
    [K_DEGEN] = {"degenerate triangles (zero or near-zero area)", false},
    [K_NONMANIFOLD] = {"non-manifold edges (in more than two triangles)", false},
};

typedef struct finding {
    int cloth, a;    /* cloth and its triangle (pairs, degenerate), vertex or edge end */
    int cloth2, b;   /* the other triangle, or the edge's other end; -1 if none */
    int body;        /* the body, or -1 */
    double pos[3];   /* where, world */
    double value;    /* depth, distance, area or triangle count */
} finding;

typedef struct kind_list {
    long count;
    int n;
    finding first[LIST_MAX];
} kind_list;

typedef struct report {
    kind_list k[K_COUNT];
    long verifier_pairs; /* cs_find_intersections' count, all cloths as one mesh */
    bool self_checked;   /* closeness to itself looked at (self-collision on) */
    bool bodies_checked; /* bodies looked at (effects.bodies on, bodies present) */
    double thickness;
} report;

/* All cloth as one mesh, in particle order. */
typedef struct cloth_set {
    const cs_scene *scene;
    int ncloths, nv, nt;
    int *voff, *toff;   /* per cloth: first vertex and first triangle; [ncloths]: totals */
    double *x;
    int *tri;           /* global vertex indices */
    int *tcloth;        /* per triangle its cloth */
    int *vcloth;        /* per vertex its cloth */
} cloth_set;

static void set_free(cloth_set *s)
{
    free(s->voff);
    free(s->toff);
    free(s->x);
    free(s->tri);
    free(s->tcloth);
    free(s->vcloth);
    memset(s, 0, sizeof *s);
}

static int set_init(cloth_set *s, const cs_scene *scene)
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

static const char *cloth_name(const cloth_set *s, int c)
{
    const char *n = s->scene->def.cloths[c].name;
    return n ? n : "?";
}

static const char *body_name(const cs_scene *scene, int b)
{
    const char *n = scene->def.bodies[b].name;
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

static double dist3(const double *a, const double *b)
{
    double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

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
        double longest = fmax(dist3(p, q), fmax(dist3(q, w), dist3(w, p)));
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

static bool bodies_on(const cs_scene *scene)
{
    return scene->def.bodies_enabled && scene->def.nbodies > 0;
}

/* The distance below which a vertex is too close to body b. */
static double body_threshold(const cs_scene *scene, int b)
{
    return fmax(scene->def.self.thickness, scene->def.bodies[b].offset);
}

static int check_bodies(const cloth_set *s, const edge *e, report *r)
{
    const cs_scene *scene = s->scene;
    if (!bodies_on(scene))
        return 0;
    r->bodies_checked = true;
    double *phi = malloc(sizeof *phi * ((size_t)s->nv + 1));
    if (!phi)
        return -1;
    size_t ne = 3 * (size_t)s->nt;
    for (int b = 0; b < scene->def.nbodies; b++) {
        const cs_body_def *bd = &scene->def.bodies[b];
        double thr = body_threshold(scene, b);
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
            double len = dist3(vx(s, a), vx(s, bb));
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
        edges += dist3(vx(s, s->tri[3 * (size_t)t]), vx(s, s->tri[3 * (size_t)t + 1]));
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
                        double d = dist3(vx(s, v), cp);
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

static int analyse(const cloth_set *s, report *r)
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

static long errors_of(const report *r)
{
    long n = 0;
    for (int k = 0; k < K_COUNT; k++)
        if (KINDS[k].error)
            n += r->k[k].count;
    return n;
}

static void print_finding(FILE *out, const cloth_set *s, int kind, const finding *f)
{
    const cs_scene *scene = s->scene;
    char at[128];
    snprintf(at, sizeof at, "(%.6g, %.6g, %.6g)", f->pos[0], f->pos[1], f->pos[2]);
    switch (kind) {
    case K_CROSS:
        fprintf(out, "  cloth '%s' triangle %d and cloth '%s' triangle %d, near %s\n",
                cloth_name(s, f->cloth), f->a, cloth_name(s, f->cloth2), f->b, at);
        break;
    case K_SELF:
        fprintf(out, "  cloth '%s' triangles %d and %d, near %s\n", cloth_name(s, f->cloth), f->a,
                f->b, at);
        break;
    case K_BODY_IN:
        fprintf(out, "  cloth '%s' vertex %d at %s: %.4g m inside body '%s'\n",
                cloth_name(s, f->cloth), f->a, at, f->value, body_name(scene, f->body));
        break;
    case K_BODY_EDGE:
        fprintf(out, "  cloth '%s' edge %d-%d: %.4g m inside body '%s' at %s\n",
                cloth_name(s, f->cloth), f->a, f->b, f->value, body_name(scene, f->body), at);
        break;
    case K_BODY_NEAR:
        fprintf(out, "  cloth '%s' vertex %d at %s: %.4g m from body '%s' (threshold %.4g m)\n",
                cloth_name(s, f->cloth), f->a, at, f->value, body_name(scene, f->body),
                body_threshold(scene, f->body));
        break;
    case K_SELF_NEAR:
        fprintf(out, "  cloth '%s' vertex %d at %s: %.4g m from cloth '%s' triangle %d\n",
                cloth_name(s, f->cloth), f->a, at, f->value, cloth_name(s, f->cloth2), f->b);
        break;
    case K_DEGEN: {
        const int *tv = scene->def.cloths[f->cloth].mesh->tri + 3 * (size_t)f->a;
        fprintf(out, "  cloth '%s' triangle %d (vertices %d %d %d) at %s: area %.3g m^2\n",
                cloth_name(s, f->cloth), f->a, tv[0], tv[1], tv[2], at, f->value);
        break;
    }
    case K_NONMANIFOLD:
        fprintf(out, "  cloth '%s' edge %d-%d at %s: in %.0f triangles\n", cloth_name(s, f->cloth),
                f->a, f->b, at, f->value);
        break;
    }
}

/* The findings of every kind, errors first: a count and the first 20. */
static void print_report(FILE *out, const cloth_set *s, const report *r, const char *prefix)
{
    for (int pass = 0; pass < 2; pass++)
        for (int k = 0; k < K_COUNT; k++) {
            const kind_list *l = &r->k[k];
            if (KINDS[k].error != (pass == 0) || l->count == 0)
                continue;
            fprintf(out, "%s%s: %ld %s", prefix, KINDS[k].error ? "error" : "warning", l->count,
                    KINDS[k].what);
            if (k == K_SELF_NEAR)
                fprintf(out, " (%.4g m)", r->thickness);
            if (k == K_BODY_NEAR)
                fprintf(out, " (the larger of the thickness and the body's collision_offset)");
            fputc('\n', out);
            for (int i = 0; i < l->n; i++)
                print_finding(out, s, k, &l->first[i]);
            if (l->count > l->n)
                fprintf(out, "  (first %d of %ld shown)\n", l->n, l->count);
        }
}

/* ------------------------------------------------------------------ --fix */

typedef struct fix_result {
    long moved;        /* vertices moved */
    long stuck;        /* vertices still inside or too close after the fix */
    double max_move;   /* m */
} fix_result;

/* Lifts every vertex closer than body_threshold to a body (or inside it)
 * out along the body's gradient to the threshold, for a few rounds (a
 * vertex between two bodies may be pushed back and forth). */
static void fix_bodies(cloth_set *s, fix_result *fr)
{
    memset(fr, 0, sizeof *fr);
    const cs_scene *scene = s->scene;
    if (!bodies_on(scene))
        return;
    for (int v = 0; v < s->nv; v++) {
        double *x = s->x + 3 * (size_t)v, x0[3];
        memcpy(x0, x, sizeof x0);
        bool clear = false;
        for (int round = 0; round < 8 && !clear; round++) {
            clear = true;
            for (int b = 0; b < scene->def.nbodies; b++) {
                double g[3], thr = body_threshold(scene, b);
                double phi = cs_body_def_phi(&scene->def.bodies[b], 0.0, x, g);
                if (phi >= thr)
                    continue;
                clear = false;
                double gl = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
                if (!(gl > 0.5)) /* no gradient (deep in a band-limited grid) */
                    continue;
                double target = thr * (1 + 1e-6) + 1e-12;
                for (int k = 0; k < 3; k++)
                    x[k] += (target - phi) * g[k] / gl;
            }
        }
        double d = dist3(x, x0);
        if (d > 0) {
            fr->moved++;
            fr->max_move = fmax(fr->max_move, d);
        }
        for (int b = 0; b < scene->def.nbodies; b++) {
            double g[3];
            if (cs_body_def_phi(&scene->def.bodies[b], 0.0, x, g) < body_threshold(scene, b)) {
                fr->stuck++;
                break;
            }
        }
    }
}

/* A cloth's name made safe for a file name. */
static void safe_name(const char *name, int c, char *buf, size_t len)
{
    snprintf(buf, len, "%s", name && *name ? name : "cloth");
    for (char *p = buf; *p; p++)
        if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') ||
              *p == '-' || *p == '_'))
            *p = '_';
    (void)c;
}

/* DIR/NAME.ply per cloth (the fixed positions, world coordinates) and
 * DIR/cloths.yaml, the snippet that uses them. */
static int write_fixed(const cloth_set *s, const char *dir, char *err, size_t errlen)
{
    if (cs_make_dirs(dir) != 0) {
        snprintf(err, errlen, "cannot make the folder %s: %s", dir, strerror(errno));
        return -1;
    }
    char *abs = realpath(dir, NULL);
    const char *base = abs ? abs : dir;
    size_t cap = 4096 + (size_t)s->ncloths * 1200;
    char *yaml = malloc(cap);
    if (!yaml) {
        free(abs);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    size_t n = (size_t)snprintf(
        yaml, cap,
        "# clothsim check --fix %s: the cloths with their vertices lifted out of the\n"
        "# bodies. Replace each cloth's grid: or mesh: block with the mesh: below (the\n"
        "# file holds world positions: no scale, rotation or translate) and keep its\n"
        "# other keys. Pins and scripts selected by grid_points must become vertices:\n"
        "# lists (vertex j * (resolution[0] + 1) + i). The vertex numbering is kept\n"
        "# unless the import drops zero-area triangles or unreferenced vertices (it\n"
        "# says so when it loads the scene).\n"
        "cloths:\n",
        s->scene->path);
    int rc = 0;
    for (int c = 0; c < s->ncloths && rc == 0; c++) {
        char name[256], path[4096];
        safe_name(s->scene->def.cloths[c].name, c, name, sizeof name);
        /* a name taken by an earlier cloth gets the index */
        for (int d = 0; d < c; d++) {
            char other[256];
            safe_name(s->scene->def.cloths[d].name, d, other, sizeof other);
            if (strcmp(other, name) == 0) {
                snprintf(name, sizeof name, "cloth%d", c);
                break;
            }
        }
        snprintf(path, sizeof path, "%s/%s.ply", base, name);
        const cs_trimesh *m = s->scene->def.cloths[c].mesh;
        cs_mesh_view view = {cloth_name(s, c), m->nv, s->x + 3 * (size_t)s->voff[c], m->nt,
                             m->tri};
        if (cs_mesh_write(path, CS_MESH_PLY, 1, &view, err, errlen) != CS_OK)
            rc = -1;
        else if (n < cap)
            n += (size_t)snprintf(yaml + n, cap - n, "  - name: %s\n    mesh: {file: \"%s\"}\n",
                                  cloth_name(s, c), path);
    }
    if (rc == 0) {
        char ypath[4096];
        snprintf(ypath, sizeof ypath, "%s/cloths.yaml", base);
        rc = cs_file_write_atomic(ypath, yaml, strlen(yaml), err, errlen);
    }
    free(yaml);
    free(abs);
    return rc;
}

/* ------------------------------------------------------------------- run */

int cs_input_check_start(const cs_scene *scene, bool quiet, FILE *err)
{
    cloth_set s;
    report r;
    if (set_init(&s, scene) != 0 || analyse(&s, &r) != 0) {
        set_free(&s);
        fprintf(err, "clothsim: out of memory checking the initial state of %s\n", scene->path);
        return CS_EXIT_OUTPUT;
    }
    long errors = errors_of(&r);
    int status = CS_EXIT_OK;
    if (errors > 0 && !scene->allow_intersecting_start) {
        fprintf(err, "clothsim: %s: the initial state intersects (%ld finding%s); refused:\n",
                scene->path, errors, errors == 1 ? "" : "s");
        print_report(err, &s, &r, "clothsim: ");
        fprintf(err,
                "clothsim: %s: move the cloth apart ('clothsim check %s --fix -o DIR' lifts "
                "vertices out of bodies), or set check: {allow_intersecting_start: true} to run "
                "it anyway\n",
                scene->path, scene->path);
        status = CS_EXIT_INPUT;
    } else if (errors > 0) {
        fprintf(err,
                "clothsim: warning: %s: the cloth starts intersecting (%ld intersecting triangle "
                "pairs, %ld vertices inside a body); check.allow_intersecting_start lets it "
                "run; self-collision keeps such pairs (it prevents crossings, it does not undo "
                "them)\n",
                scene->path, r.k[K_CROSS].count + r.k[K_SELF].count, r.k[K_BODY_IN].count);
    }
    if (status == CS_EXIT_OK && !quiet) {
        long w = 0;
        for (int k = 0; k < K_COUNT; k++)
            w += KINDS[k].error ? 0 : r.k[k].count;
        if (w > 0) {
            fprintf(err, "clothsim: warning: %s: the initial state has", scene->path);
            const char *sep = " ";
            for (int k = 0; k < K_COUNT; k++)
                if (!KINDS[k].error && r.k[k].count > 0) {
                    fprintf(err, "%s%ld %s", sep, r.k[k].count, KINDS[k].what);
                    sep = ", ";
                }
            fprintf(err, "; 'clothsim check %s' lists them\n", scene->path);
        }
    }
    set_free(&s);
    return status;
}

/* ----------------------------------------------------------------- check */

void cs_check_help(FILE *out)
{
    fputs("usage: clothsim check SCENE [options]\n"
          "\n"
          "Checks the initial state of the scene file SCENE, as 'clothsim run' starts it,\n"
          "and lists what it finds, grouped by kind, the first 20 of each with a count:\n"
          "  errors (run refuses them, exit 2, unless the scene sets\n"
          "  check: {allow_intersecting_start: true}):\n"
          "    triangles of two cloths, or of one cloth, that intersect (the exact\n"
          "    verifier 'clothsim intersections' uses: every pair it counts)\n"
          "    cloth vertices inside a body (negative signed distance)\n"
          "  warnings:\n"
          "    cloth edges through a body with both ends outside it\n"
          "    cloth vertices closer to a body than the larger of\n"
          "    self_collision.thickness and the body's collision_offset\n"
          "    vertex-triangle pairs of cloth closer than self_collision.thickness\n"
          "    (the vertex not a corner of the triangle; with self-collision on)\n"
          "    degenerate triangles and non-manifold edges\n"
          "A selection (pin or script) that selects no vertex is an error of the scene\n"
          "file itself, reported with its file and line like any other.\n"
          "\n"
          "options:\n"
          "      --set KEY=VALUE  override a scene setting, as for 'clothsim run'\n"
          "      --fix            lift cloth vertices inside or too close to a body out\n"
          "                       along the body's gradient to the threshold, say how\n"
          "                       many moved and how far, and check again\n"
          "  -o, --output DIR     with --fix: write the fixed cloths as DIR/NAME.ply (world\n"
          "                       positions, the vertex numbering kept) and DIR/cloths.yaml,\n"
          "                       the scene lines that use them\n"
          "  -h, --help           show this help\n"
          "\n"
          "exit status:\n"
          "  0    no error (warnings may be listed)\n"
          "  1    errors found (after --fix: errors left)\n"
          "  2    bad command line, or the scene is invalid\n"
          "  4    out of memory, or a fixed file could not be written\n"
          "\n"
          "docs/input-check.md explains each finding.\n",
          out);
}

static const cs_cli CLI = {"check", NULL, cs_check_help, CS_EXIT_INPUT};

static void print_clean(FILE *out, const report *r)
{
    fprintf(out, "checked: intersections (verifier: %ld pairs)%s%s, degenerate triangles, "
                 "non-manifold edges\n",
            r->verifier_pairs,
            r->bodies_checked ? ", bodies (inside, edges through, closer than the threshold)"
                              : ", no bodies (none, or effects.bodies off)",
            r->self_checked ? ", cloth closer than the thickness"
                            : ", not closeness to itself (self-collision off)");
}

int cs_check_main(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"set", required_argument, NULL, 's'},
        {"fix", no_argument, NULL, 'f'},
        {"output", required_argument, NULL, 'o'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    char **overrides = calloc((size_t)argc + 1, sizeof *overrides);
    int noverrides = 0;
    bool fix = false;
    const char *out_dir = NULL;
    if (!overrides) {
        fprintf(stderr, "clothsim check: out of memory\n");
        return CS_EXIT_OUTPUT;
    }
    optind = 1;
    opterr = 0;
    int c, status = 0;
    while ((c = getopt_long(argc, argv, ":o:h", longopts, NULL)) != -1) {
        switch (c) {
        case 's':
            if (!strchr(optarg, '=') || optarg[0] == '=') {
                free(overrides);
                return cs_cli_error(&CLI, "--set needs KEY=VALUE, got '%s'", optarg);
            }
            overrides[noverrides++] = optarg;
            break;
        case 'f':
            fix = true;
            break;
        case 'o':
            out_dir = optarg;
            break;
        case 'h':
            free(overrides);
            cs_check_help(stdout);
            return CS_EXIT_OK;
        default:
            free(overrides);
            return cs_cli_option_error(&CLI, c, argv);
        }
    }
    const char *path = cs_cli_operand(&CLI, argc, argv, optind, "scene file", &status);
    if (!path) {
        free(overrides);
        return status;
    }
    if (fix != (out_dir != NULL)) {
        free(overrides);
        return cs_cli_error(&CLI, "%s", "--fix and -o DIR go together");
    }
    char err[ERRLEN] = "";
    cs_scene *scene = NULL;
    int rc = cs_scene_load(path, noverrides, (const char *const *)overrides, &scene, err,
                           sizeof err);
    free(overrides);
    if (rc != CS_OK) {
        fprintf(stderr, "clothsim check: %s\n", err[0] ? err : "cannot load the scene");
        return cs_exit_status(rc);
    }
    for (int i = 0; i < scene->nnotes; i++)
        fprintf(stderr, "clothsim check: %s\n", scene->notes[i]);

    cloth_set s;
    report r;
    if (set_init(&s, scene) != 0 || analyse(&s, &r) != 0) {
        fprintf(stderr, "clothsim check: out of memory\n");
        set_free(&s);
        cs_scene_destroy(scene);
        return CS_EXIT_OUTPUT;
    }
    printf("%s: %d cloth%s, %d vertices, %d triangles, %d bod%s%s; self-collision %s, "
           "thickness %.4g m\n",
           scene->path, s.ncloths, s.ncloths == 1 ? "" : "s", s.nv, s.nt, scene->def.nbodies,
           scene->def.nbodies == 1 ? "y" : "ies", bodies_on(scene) || !scene->def.nbodies ? ""
                                                                                          : " (off)",
           scene->def.self_collision ? "on" : "off", scene->def.self.thickness);
    print_clean(stdout, &r);
    print_report(stdout, &s, &r, "");
    long errors = errors_of(&r);
    status = errors > 0 ? 1 : CS_EXIT_OK;
    if (fix) {
        fix_result fr;
        fix_bodies(&s, &fr);
        printf("--fix: moved %ld vertices out of bodies, at most %.4g m", fr.moved, fr.max_move);
        if (fr.stuck > 0)
            printf("; %ld vertices could not be moved clear (no gradient, or between bodies)",
                   fr.stuck);
        printf("\n");
        if (write_fixed(&s, out_dir, err, sizeof err) != 0) {
            fprintf(stderr, "clothsim check: %s\n", err);
            status = CS_EXIT_OUTPUT;
        } else {
            printf("--fix: wrote the fixed cloths to %s/ (one NAME.ply a cloth) and the scene "
                   "lines that use them to %s/cloths.yaml\n",
                   out_dir, out_dir);
            report after;
            if (analyse(&s, &after) != 0) {
                fprintf(stderr, "clothsim check: out of memory\n");
                status = CS_EXIT_OUTPUT;
            } else {
                printf("after --fix:\n");
                print_report(stdout, &s, &after, "");
                long left = errors_of(&after);
                long pairs0 = r.k[K_CROSS].count + r.k[K_SELF].count;
                long pairs1 = after.k[K_CROSS].count + after.k[K_SELF].count;
                printf("after --fix: %ld error%s left\n", left, left == 1 ? "" : "s");
                if (pairs1 > pairs0)
                    printf("after --fix: the moved vertices made %ld more intersecting triangle "
                           "pairs: lifting along the gradient folds a cloth that lies deep in "
                           "a body; move that cloth by hand\n",
                           pairs1 - pairs0);
                errors = left;
                status = left > 0 ? 1 : CS_EXIT_OK;
            }
        }
    }
    const char *state = fix ? "the fixed state" : "this start";
    if (status == CS_EXIT_OUTPUT)
        printf("result: the fixed cloths were not written\n");
    else if (errors > 0 && !scene->allow_intersecting_start)
        printf("result: %ld error%s: 'clothsim run' refuses %s (exit 2) unless the "
               "scene sets check: {allow_intersecting_start: true}\n",
               errors, errors == 1 ? "" : "s", state);
    else if (errors > 0)
        printf("result: %ld error%s, accepted by check.allow_intersecting_start\n", errors,
               errors == 1 ? "" : "s");
    else
        printf("result: no error; 'clothsim run' starts from %s\n", state);
    set_free(&s);
    cs_scene_destroy(scene);
    return status;
}
