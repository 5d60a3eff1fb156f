/* selfcol.c: history-based repulsions (Section 5), continuous collisions
 * and impact zones (Section 4). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sim/ccd.h"
#include "sim/internal.h"
#include "sim/selfcol.h"
#include "sim/vec3.h"

/* ------------------------------------------------------------ topology */

static int pair_push(cs_pair_list *l, const int v[4], const double *s0)
{
    if (l->n == l->capacity) {
        int cap = l->capacity ? 2 * l->capacity : 256;
        cs_pair *p = realloc(l->p, sizeof *p * (size_t)cap);
        if (!p)
            return -1;
        l->p = p;
        l->capacity = cap;
    }
    cs_pair *q = l->p + l->n++;
    memcpy(q->v, v, sizeof q->v);
    if (s0)
        memcpy(q->s0, s0, sizeof q->s0);
    else
        q->s0[0] = q->s0[1] = q->s0[2] = 0;
    return 0;
}

static int zone_find(int *parent, int i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

static void zone_union(int *parent, int a, int b)
{
    if (parent[a] < 0)
        parent[a] = a;
    if (parent[b] < 0)
        parent[b] = b;
    a = zone_find(parent, a);
    b = zone_find(parent, b);
    if (a != b)
        parent[a < b ? b : a] = a < b ? a : b;
}

cs_selfcol *cs_selfcol_create(const cs_sim *sim)
{
    cs_selfcol *sc = calloc(1, sizeof *sc);
    if (!sc)
        return NULL;
    int n = sim->n, nt = 0;
    for (int c = 0; c < sim->ncloths; c++)
        nt += sim->cloths[c].mesh->nt;
    sc->n = n;
    sc->nt = nt;
    sc->tri = malloc(sizeof *sc->tri * 3 * (size_t)(nt + 1));
    int *e = malloc(sizeof *e * 6 * (size_t)(nt + 1));
    if (!sc->tri || !e)
        goto fail;
    int t = 0;
    for (int c = 0; c < sim->ncloths; c++) {
        const cs_trimesh *m = sim->cloths[c].mesh;
        for (int k = 0; k < 3 * m->nt; k++)
            sc->tri[3 * t + k] = sim->cloths[c].offset + m->tri[k];
        t += m->nt;
    }
    for (t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            int a = sc->tri[3 * t + k], b = sc->tri[3 * t + (k + 1) % 3];
            e[6 * t + 2 * k] = a < b ? a : b;
            e[6 * t + 2 * k + 1] = a < b ? b : a;
        }
    int ne = cs_sort_unique_pairs(e, 3 * nt);
    sc->edge = e;
    sc->ne = ne;
    sc->ring_start = calloc((size_t)n + 2, sizeof *sc->ring_start);
    sc->ring = malloc(sizeof *sc->ring * 2 * (size_t)(ne + 1));
    if (!sc->ring_start || !sc->ring)
        goto fail;
    for (int k = 0; k < 2 * ne; k++)
        sc->ring_start[e[k] + 2]++;
    for (int i = 0; i < n; i++)
        sc->ring_start[i + 2] += sc->ring_start[i + 1];
    for (int k = 0; k < ne; k++) {
        sc->ring[sc->ring_start[e[2 * k] + 1]++] = e[2 * k + 1];
        sc->ring[sc->ring_start[e[2 * k + 1] + 1]++] = e[2 * k];
    }

    sc->pbox = calloc((size_t)n + 1, sizeof *sc->pbox);
    sc->ebox = calloc((size_t)ne + 1, sizeof *sc->ebox);
    sc->tbox = calloc((size_t)nt + 1, sizeof *sc->tbox);
    sc->pdirty = calloc((size_t)n + 1, 1);
    sc->vdirty = calloc((size_t)n + 1, 1);
    sc->edirty = calloc((size_t)ne + 1, 1);
    sc->tdirty = calloc((size_t)nt + 1, 1);
    sc->x_free = malloc(sizeof(double) * 3 * (size_t)(n + 1));
    sc->x_before = malloc(sizeof(double) * 3 * (size_t)(n + 1));
    sc->inv_mass = malloc(sizeof(double) * (size_t)(n + 1));
    sc->zone = malloc(sizeof(int) * (size_t)(n + 1));
    sc->zone_list = malloc(sizeof(int) * (size_t)(n + 1));
    int most = n > ne ? n : ne;
    most = most > nt ? most : nt;
    sc->prim_rank = malloc(sizeof(int) * (size_t)(most + 1));
    sc->component = malloc(sizeof(int) * (size_t)(n + 1));
    sc->x_pass = malloc(sizeof(double) * 3 * (size_t)(n + 1));
    if (!sc->prim_rank || !sc->component || !sc->x_pass)
        goto fail;
    if (!sc->pbox || !sc->ebox || !sc->tbox || !sc->pdirty || !sc->vdirty || !sc->edirty ||
        !sc->tdirty || !sc->x_free || !sc->x_before || !sc->inv_mass || !sc->zone ||
        !sc->zone_list)
        goto fail;
    memcpy(sc->x_free, sim->x, sizeof(double) * 3 * (size_t)n);
    double mean_edge = 0;
    for (int k = 0; k < ne; k++) {
        double d[3];
        cs_sub(sim->x + 3 * e[2 * k + 1], sim->x + 3 * e[2 * k], d);
        mean_edge += cs_norm(d) / ne;
    }
    sc->proximity = fmin(1e-3 * sim->def.self.thickness, 1e-4 * (mean_edge > 0 ? mean_edge : 1));
    for (int i = 0; i < n; i++) {
        sc->inv_mass[i] = sim->is_free[i] ? 1.0 / sim->mass[i] : 0.0;
        sc->zone[i] = -1;
        cs_box_empty(sc->pbox + i);
        cs_box_add_point(sc->pbox + i, sim->x + 3 * i);
    }
    for (int k = 0; k < ne; k++) {
        cs_box_empty(sc->ebox + k);
        cs_box_add_point(sc->ebox + k, sim->x + 3 * e[2 * k]);
        cs_box_add_point(sc->ebox + k, sim->x + 3 * e[2 * k + 1]);
    }
    for (int k = 0; k < nt; k++) {
        cs_box_empty(sc->tbox + k);
        for (int j = 0; j < 3; j++)
            cs_box_add_point(sc->tbox + k, sim->x + 3 * sc->tri[3 * k + j]);
    }
    if (cs_bvh_build(&sc->ptree, n, sc->pbox) || cs_bvh_build(&sc->etree, ne, sc->ebox) ||
        cs_bvh_build(&sc->ttree, nt, sc->tbox))
        goto fail;
    sc->bytes = sizeof(cs_box) * (size_t)(n + ne + nt) * 3 + sizeof(double) * 13 * (size_t)n +
                sizeof(int) * (size_t)(2 * ne + 3 * nt + 3 * n + most);
    return sc;
fail:
    cs_selfcol_destroy(sc);
    return NULL;
}

void cs_selfcol_destroy(cs_selfcol *sc)
{
    if (!sc)
        return;
    cs_bvh_free(&sc->ptree);
    cs_bvh_free(&sc->etree);
    cs_bvh_free(&sc->ttree);
    void *arrays[] = {sc->edge, sc->tri, sc->ring_start, sc->ring, sc->pbox, sc->ebox, sc->tbox, sc->pdirty, sc->edirty,
                      sc->tdirty, sc->vdirty, sc->x_free, sc->x_before, sc->inv_mass, sc->zone,
                      sc->zone_list, sc->pt.p, sc->ee.p, sc->cpt.p, sc->cee.p,
                      sc->prim_rank, sc->component, sc->bpt.p, sc->bee.p, sc->x_pass};
    for (size_t k = 0; k < sizeof arrays / sizeof *arrays; k++)
        free(arrays[k]);
    cs_halo_free(&sc->bhalo);
    cs_bvh_work_free(&sc->bvh_work);
    free(sc->candidates.ab);
    free(sc->made);
    free(sc->keep);
    free(sc);
}

/* ----------------------------------------------------------- geometry */

/* The relative position of a pair as sum_k c_k x_k, its unit normal and
 * signed distance along it, at positions x. Returns false where the pair
 * has no usable normal (a degenerate triangle). For edge/edge pairs the
 * normal follows the history rule: the shortest vector s is flipped when
 * s0 . s < epsilon (the edges have passed through each other). */
static bool pair_frame(const cs_pair *p, bool is_edge, const double *x, double epsilon,
                       double c[4], double n[3], double *dist, double *signed_dist)
{
    const double *a = x + 3 * p->v[0], *b = x + 3 * p->v[1], *cc = x + 3 * p->v[2],
                 *d = x + 3 * p->v[3];
    if (!is_edge) {
        double w[3], e1[3], e2[3];
        *dist = cs_point_triangle_closest(d, a, b, cc, w);
        cs_sub(b, a, e1);
        cs_sub(cc, a, e2);
        cs_cross(e1, e2, n);
        double len = cs_norm(n);
        if (!(len > 1e-14 * (cs_dot(e1, e1) + cs_dot(e2, e2))))
            return false;
        for (int k = 0; k < 3; k++)
            n[k] /= len;
        c[0] = -w[0], c[1] = -w[1], c[2] = -w[2], c[3] = 1;
        double rel[3] = {0, 0, 0};
        for (int k = 0; k < 4; k++)
            cs_axpy(c[k], x + 3 * p->v[k], rel);
        *signed_dist = cs_dot(rel, n);
        return true;
    }
    double s, t;
    *dist = cs_segment_segment_closest(a, b, cc, d, &s, &t);
    c[0] = -(1 - s), c[1] = -s, c[2] = 1 - t, c[3] = t;
    double rel[3] = {0, 0, 0};
    for (int k = 0; k < 4; k++)
        cs_axpy(c[k], x + 3 * p->v[k], rel);
    double len = cs_norm(rel);
    if (len > 1e-12 * (*dist + 1e-300) && len > 0) {
        for (int k = 0; k < 3; k++)
            n[k] = rel[k] / len;
    } else {
        memcpy(n, p->s0, 3 * sizeof *n); /* touching: the history knows the side */
    }
    if (cs_dot(n, p->s0) < epsilon) {
        for (int k = 0; k < 3; k++)
            n[k] = -n[k];
        *signed_dist = -len;
    } else {
        *signed_dist = len;
    }
    return true;
}

static double pair_inverse_mass(const cs_selfcol *sc, const cs_pair *p, const double c[4])
{
    double s = 0;
    for (int k = 0; k < 4; k++)
        s += c[k] * c[k] * sc->inv_mass[p->v[k]];
    return s;
}

static double pair_normal_velocity(const cs_pair *p, const double c[4], const double *v,
                                   const double n[3], double rel[3])
{
    rel[0] = rel[1] = rel[2] = 0;
    for (int k = 0; k < 4; k++)
        cs_axpy(c[k], v + 3 * p->v[k], rel);
    return cs_dot(rel, n);
}

/* v_k += c_k J / m_k dir: an impulse J on the pair's relative motion */
static void pair_impulse(const cs_selfcol *sc, const cs_pair *p, const double c[4], double J,
                         const double dir[3], double *v)
{
    for (int k = 0; k < 4; k++)
        cs_axpy(c[k] * J * sc->inv_mass[p->v[k]], dir, v + 3 * p->v[k]);
}

/* ------------------------------------------------- pair response, once */

typedef struct response {
    bool inelastic, elastic, friction;
    double dt;          /* for Eq. 1 */
    double h, k, mu, epsilon;
} response;

/* Applies one pair's response to velocities v at positions x; returns true
 * if it interacted. Inelastic: I = m v_N stops approach; elastic: Eq. 1
 * with d from Eq. 2 (larger when the pair has crossed, so it pulls back);
 * friction: Coulomb with the normal velocity change. */
/* Whether the boxes of a pair's two sides (vertices [0, split) and
 * [split, 4) at positions p[k]) are more than gap apart along an axis:
 * then the sides are farther apart than gap. */
static bool sides_apart(const double *const p[4], int split, double gap)
{
    for (int d = 0; d < 3; d++) {
        double lo_a = INFINITY, hi_a = -INFINITY, lo_b = INFINITY, hi_b = -INFINITY;
        for (int k = 0; k < 4; k++) {
            double c = p[k][d];
            if (k < split) {
                lo_a = c < lo_a ? c : lo_a;
                hi_a = c > hi_a ? c : hi_a;
            } else {
                lo_b = c < lo_b ? c : lo_b;
                hi_b = c > hi_b ? c : hi_b;
            }
        }
        if (lo_a - hi_b > gap || lo_b - hi_a > gap)
            return true;
    }
    return false;
}

/* The per-step prune of Section 5: step A keeps pairs generously, so most
 * are not interacting now; an h-thickened box test settles that cheaply. */
static bool pair_near(const cs_pair *p, bool is_edge, const double *x, double h)
{
    const double *const pts[4] = {x + 3 * p->v[0], x + 3 * p->v[1], x + 3 * p->v[2],
                                  x + 3 * p->v[3]};
    return !sides_apart(pts, is_edge ? 2 : 3, h);
}

/* Bridson's proximity condition for a repulsion: a point/triangle pair
 * only where the point projects inside the triangle (within h over the
 * triangle's size), an edge/edge pair only where the closest points are
 * inside both edges. Elsewhere the other kind of pair is the right one; without this, in-plane neighbours closer than h would push
 * each other out of a flat sheet along its normal. */
static bool pair_interior(const cs_pair *p, bool is_edge, const double *x, const double c[4],
                          double h)
{
    if (is_edge) { /* closest points clamped to an end: a point's business */
        double s = -c[1], t = c[3];
        return s > 0 && s < 1 && t > 0 && t < 1;
    }
    /* barycentric weights of the projection onto the plane, unclamped */
    const double *a = x + 3 * p->v[0], *b = x + 3 * p->v[1], *cc = x + 3 * p->v[2],
                 *q = x + 3 * p->v[3];
    double e1[3], e2[3], r[3], n[3];
    cs_sub(b, a, e1);
    cs_sub(cc, a, e2);
    cs_sub(q, a, r);
    cs_cross(e1, e2, n);
    double nn = cs_dot(n, n);
    if (!(nn > 0))
        return false;
    double t1[3], t2[3];
    cs_cross(r, e2, t1);
    cs_cross(e1, r, t2);
    double w1 = cs_dot(t1, n) / nn, w2 = cs_dot(t2, n) / nn, w0 = 1 - w1 - w2;
    double tol = h / sqrt(sqrt(nn)); /* h over the triangle's size */
    return w0 > -tol && w1 > -tol && w2 > -tol;
}

static bool pair_respond(const cs_selfcol *sc, const cs_pair *p, bool is_edge, const double *x,
                         double *v, const response *r)
{
    if (!pair_near(p, is_edge, x, r->h))
        return false;
    double c[4], n[3], dist, sd;
    if (!pair_frame(p, is_edge, x, r->epsilon, c, n, &dist, &sd))
        return false;
    if (!(dist < r->h) || !pair_interior(p, is_edge, x, c, r->h))
        return false;
    double inv_m = pair_inverse_mass(sc, p, c);
    if (!(inv_m > 0))
        return false;
    double rel[3];
    double vn = pair_normal_velocity(p, c, v, n, rel), dvn = 0;
    if (r->inelastic && vn < 0) {
        pair_impulse(sc, p, c, -vn / inv_m, n, v);
        dvn = -vn;
        vn = 0;
    }
    if (r->elastic) {
        double d = r->h - sd;
        double J = fmin(r->dt * r->k * d, (0.1 * d / r->dt - vn) / inv_m);
        if (J > 0) {
            pair_impulse(sc, p, c, J, n, v);
            dvn += J * inv_m;
        }
    }
    if (r->friction && dvn > 0 && r->mu > 0) {
        double vt[3];
        for (int k = 0; k < 3; k++)
            vt[k] = rel[k] - (cs_dot(rel, n)) * n[k];
        double speed = cs_norm(vt);
        if (speed > 0) {
            double drop = fmin(r->mu * dvn, speed);
            double dir[3] = {vt[0] / speed, vt[1] / speed, vt[2] / speed};
            pair_impulse(sc, p, c, -drop / inv_m, dir, v);
        }
    }
    return true;
}

/* The one door for applying a set of pairs: Gauss-Seidel order, point/
 * triangle pairs before edge/edge pairs, each seeing the newest velocities. */
static long cs_pairs_apply(const cs_selfcol *sc, const cs_pair_list *pt, const cs_pair_list *ee,
                           const double *x, double *v, const response *r)
{
    long applied = 0;
    for (int i = 0; i < pt->n; i++)
        applied += pair_respond(sc, pt->p + i, false, x, v, r);
    for (int i = 0; i < ee->n; i++)
        applied += pair_respond(sc, ee->p + i, true, x, v, r);
    return applied;
}

/* Which side of a plane (normal nrm) a point belongs on when it lies in
 * the plane itself: the side its own cloth is on, judged by its neighbours
 * along edges. Zero when that says nothing either (a lone particle, or a
 * cloth lying in the plane). */
static double ring_side(const cs_selfcol *sc, const double *x, int point, const double nrm[3])
{
    double side = 0;
    for (int k = sc->ring_start[point]; k < sc->ring_start[point + 1]; k++) {
        double r[3];
        cs_sub(x + 3 * sc->ring[k], x + 3 * point, r);
        side += cs_dot(r, nrm);
    }
    return side;
}

/* A point joined by edges to two of a triangle's vertices sits across an
 * edge from it: a bending wing of the mesh (or a degenerate sliver lying on
 * its neighbour). How close it is, is the bending springs' business: a
 * repulsion there would fight them. Step C still watches it. */
static bool wing_pair(const cs_selfcol *sc, int point, const int *tri)
{
    int joined = 0;
    for (int k = sc->ring_start[point]; k < sc->ring_start[point + 1]; k++) {
        int q = sc->ring[k];
        joined += q == tri[0] || q == tri[1] || q == tri[2];
    }
    return joined >= 2;
}

/* ------------------------------------------------- Section 7: ranks */

static int pair_rank(const cs_par *par, const int v[4])
{
    int r = par->owner[v[0]];
    for (int k = 1; k < 4; k++)
        r = par->owner[v[k]] < r ? par->owner[v[k]] : r;
    return r;
}

static bool pair_internal(const cs_par *par, const int v[4])
{
    for (int k = 0; k < 4; k++)
        if (par->owner[v[k]] != par->rank)
            return false;
    return true;
}

int cs_selfcol_set_ranks(cs_sim *sim)
{
    cs_selfcol *sc = sim->selfcol;
    const int *owner = sim->par->owner;
    if (sim->par->size == 1)
        return 0; /* nothing to prune */
    int *r = sc->prim_rank;
    for (int i = 0; i < sc->n; i++)
        r[i] = owner[i];
    if (cs_bvh_set_ranks(&sc->ptree, r))
        return -1;
    for (int k = 0; k < sc->ne; k++) {
        int a = owner[sc->edge[2 * k]], b = owner[sc->edge[2 * k + 1]];
        r[k] = a < b ? a : b;
    }
    if (cs_bvh_set_ranks(&sc->etree, r))
        return -1;
    for (int k = 0; k < sc->nt; k++) {
        int m = owner[sc->tri[3 * k]];
        for (int j = 1; j < 3; j++)
            m = owner[sc->tri[3 * k + j]] < m ? owner[sc->tri[3 * k + j]] : m;
        r[k] = m;
    }
    return cs_bvh_set_ranks(&sc->ttree, r);
}

/* A pair as sent between ranks. */
typedef struct wire_pair {
    int v[4];
    int is_edge, rank; /* rank: the rank that found it */
    double s0[3];
} wire_pair;

/* Fig. 12's bookkeeping. Moves this rank's boundary pairs (a particle
 * owned elsewhere) out of pt and ee, which keep the internal ones; every
 * rank learns every boundary pair (four indices and a history vector: the
 * internal pairs, nearly all of them, never leave their rank), joins them
 * into connected components by flood fill (union-find over particles) and
 * keeps in bpt and bee, in one Gauss-Seidel order, the pairs of the
 * components it processes: those whose lowest finding rank it is. bhalo
 * links their particles to their owners. Returns 0 or -1 (no memory). */
static int distribute_boundary(cs_sim *sim, cs_pair_list *pt, cs_pair_list *ee)
{
    cs_selfcol *sc = sim->selfcol;
    cs_par *par = sim->par;
    sc->bpt.n = sc->bee.n = 0;
    cs_halo_free(&sc->bhalo);
    if (par->size == 1)
        return 0;
    int nmine = 0;
    for (int l = 0; l < 2; l++) {
        cs_pair_list *list = l == 0 ? pt : ee;
        for (int i = 0; i < list->n; i++)
            nmine += !pair_internal(par, list->p[i].v);
    }
    wire_pair *mine = malloc(sizeof *mine * ((size_t)nmine + 1));
    if (!mine)
        return -1;
    int m = 0;
    for (int l = 0; l < 2; l++) {
        cs_pair_list *list = l == 0 ? pt : ee;
        int kept = 0;
        for (int i = 0; i < list->n; i++) {
            cs_pair *q = list->p + i;
            if (pair_internal(par, q->v)) {
                list->p[kept++] = *q;
                continue;
            }
            wire_pair *w = mine + m++;
            memcpy(w->v, q->v, sizeof w->v);
            memcpy(w->s0, q->s0, sizeof w->s0);
            w->is_edge = l;
            w->rank = par->rank;
        }
        list->n = kept;
    }
    void *gathered;
    int nall;
    int rc = cs_par_allgather_items(par, mine, nmine, sizeof *mine, &gathered, &nall);
    free(mine);
    if (rc)
        return -1;
    const wire_pair *all = gathered;

    /* components, and the lowest finding rank of each (at its root) */
    int *parent = sc->component, *root_rank = sc->prim_rank;
    for (int i = 0; i < sc->n; i++)
        parent[i] = -1;
    for (int k = 0; k < nall; k++)
        for (int j = 1; j < 4; j++)
            zone_union(parent, all[k].v[0], all[k].v[j]);
    for (int k = 0; k < nall; k++)
        root_rank[zone_find(parent, all[k].v[0])] = par->size;
    int *user = malloc(sizeof *user * (4 * (size_t)nall + 1));
    int *particle = malloc(sizeof *particle * (4 * (size_t)nall + 1));
    if (!user || !particle)
        rc = -1;
    for (int k = 0; k < nall; k++) {
        int root = zone_find(parent, all[k].v[0]);
        if (all[k].rank < root_rank[root])
            root_rank[root] = all[k].rank;
    }
    for (int l = 0; l < 2 && !rc; l++) /* point/triangle pairs first, as on one rank */
        for (int k = 0; k < nall && !rc; k++) {
            if (all[k].is_edge != l)
                continue;
            int proc = root_rank[zone_find(parent, all[k].v[0])];
            for (int j = 0; j < 4; j++) {
                user[4 * k + j] = proc;
                particle[4 * k + j] = all[k].v[j];
            }
            if (proc == par->rank)
                rc = pair_push(l ? &sc->bee : &sc->bpt, all[k].v, all[k].s0);
        }
    if (!rc)
        rc = cs_halo_from_needs(par, 4 * nall, user, particle, &sc->bhalo);
    free(user);
    free(particle);
    free(gathered);
    return rc;
}

/* ------------------------------------------------------------- step A */

typedef struct finder {
    cs_sim *sim;
    cs_selfcol *sc;
    double h, span;
} finder;

/* Keep a pair only if it can come within h during the span at its present
 * relative velocity: distance in the free state less the largest relative
 * speed between its two sides times the span. (The boxes that found it had
 * to allow for each particle's motion; a patch moving fast but rigidly,
 * like the twisted strip's ends, has little relative motion.) */
static bool may_meet(const finder *f, const int v[4], int split, double dist)
{
    const double *vel = f->sim->v;
    double rel = 0;
    for (int i = 0; i < split; i++)
        for (int j = split; j < 4; j++) {
            double d[3];
            cs_sub(vel + 3 * v[i], vel + 3 * v[j], d);
            rel = fmax(rel, cs_norm(d));
        }
    return dist < f->h + rel * f->span;
}

/* The makers below turn a candidate (a, b) of a traversal into a pair, or
 * say no; they only read shared state, so threads run them side by side. */
typedef bool (*pair_maker)(const void *ctx, int a, int b, cs_pair *out);

static bool make_repulsion_point_triangle(const void *ctx, int point, int t, cs_pair *out)
{
    const finder *f = ctx;
    const cs_selfcol *sc = f->sc;
    const int *tri = sc->tri + 3 * t;
    if (point == tri[0] || point == tri[1] || point == tri[2] || wing_pair(sc, point, tri))
        return false;
    int quad[4] = {tri[0], tri[1], tri[2], point};
    if (pair_rank(f->sim->par, quad) != f->sim->par->rank)
        return false; /* another rank's to find */
    if (sc->inv_mass[point] == 0 && sc->inv_mass[tri[0]] == 0 && sc->inv_mass[tri[1]] == 0 &&
        sc->inv_mass[tri[2]] == 0)
        return false;
    /* history: wind the triangle so its normal points at the free point
     * (the paper's reordering; swapping two triangle vertices flips it) */
    const double *x = sc->x_free;
    double e1[3], e2[3], nrm[3], r[3];
    cs_sub(x + 3 * tri[1], x + 3 * tri[0], e1);
    cs_sub(x + 3 * tri[2], x + 3 * tri[0], e2);
    cs_cross(e1, e2, nrm);
    cs_sub(x + 3 * point, x + 3 * tri[0], r);
    int v[4] = {tri[0], tri[1], tri[2], point};
    double w[3];
    double dist = cs_point_triangle_closest(x + 3 * point, x + 3 * tri[0], x + 3 * tri[1],
                                            x + 3 * tri[2], w);
    if (!may_meet(f, v, 3, dist))
        return false;
    double side = cs_dot(nrm, r);
    if (fabs(side) <= 1e-12 * cs_norm(nrm) * (cs_norm(r) + cs_norm(e1)))
        side = ring_side(sc, x, point, nrm); /* in the plane: ambiguous */
    if (side < 0) {
        v[1] = tri[2];
        v[2] = tri[1];
    }
    memcpy(out->v, v, sizeof v);
    out->s0[0] = out->s0[1] = out->s0[2] = 0;
    return true;
}

static bool make_repulsion_edge_edge(const void *ctx, int ea, int eb, cs_pair *out)
{
    const finder *f = ctx;
    const cs_selfcol *sc = f->sc;
    const int *a = sc->edge + 2 * ea, *b = sc->edge + 2 * eb;
    if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1])
        return false;
    int quad[4] = {a[0], a[1], b[0], b[1]};
    if (pair_rank(f->sim->par, quad) != f->sim->par->rank)
        return false; /* another rank's to find */
    if (sc->inv_mass[a[0]] == 0 && sc->inv_mass[a[1]] == 0 && sc->inv_mass[b[0]] == 0 &&
        sc->inv_mass[b[1]] == 0)
        return false;
    const double *x = sc->x_free;
    double s, t, s0[3];
    cs_segment_segment_closest(x + 3 * a[0], x + 3 * a[1], x + 3 * b[0], x + 3 * b[1], &s, &t);
    for (int k = 0; k < 3; k++)
        s0[k] = (x[3 * b[0] + k] + t * (x[3 * b[1] + k] - x[3 * b[0] + k])) -
                (x[3 * a[0] + k] + s * (x[3 * a[1] + k] - x[3 * a[0] + k]));
    double len = cs_norm(s0);
    if (!may_meet(f, quad, 2, len))
        return false;
    if (!(len > 0)) { /* touching in the free state: the edges' common normal */
        double da[3], db[3];
        cs_sub(x + 3 * a[1], x + 3 * a[0], da);
        cs_sub(x + 3 * b[1], x + 3 * b[0], db);
        cs_cross(da, db, s0);
        len = cs_norm(s0);
        if (!(len > 0))
            return false; /* parallel and touching: the point/triangle pairs decide */
    }
    memcpy(out->v, quad, sizeof quad);
    for (int k = 0; k < 3; k++)
        out->s0[k] = s0[k] / len;
    return true;
}

/* Traverses A against B and appends the pairs make accepts to list, in the
 * traversal's order at any thread count: threads make pairs from the
 * candidates in place, then they are kept in order. Returns 0 or -1. */
static int find_pairs(cs_selfcol *sc, const cs_bvh *A, const cs_bvh *B, bool only_dirty, int rank,
                      pair_maker make, const void *ctx, cs_pair_list *list)
{
    if (cs_bvh_collect(A, B, only_dirty, rank, &sc->bvh_work, &sc->candidates))
        return -1;
    int n = sc->candidates.n;
    if (n > sc->made_capacity) {
        cs_pair *made = realloc(sc->made, sizeof *made * (size_t)n);
        unsigned char *keep = realloc(sc->keep, (size_t)n);
        if (made)
            sc->made = made;
        if (keep)
            sc->keep = keep;
        if (!made || !keep)
            return -1;
        sc->made_capacity = n;
    }
    const int *ab = sc->candidates.ab;
#pragma omp parallel for schedule(dynamic, 256)
    for (int k = 0; k < n; k++)
        sc->keep[k] = make(ctx, ab[2 * k], ab[2 * k + 1], sc->made + k);
    for (int k = 0; k < n; k++)
        if (sc->keep[k] && pair_push(list, sc->made[k].v, sc->made[k].s0))
            return -1;
    return 0;
}

void cs_selfcol_find_pairs(cs_sim *sim, double span)
{
    cs_selfcol *sc = sim->selfcol;
    const double *x = sc->x_free; /* the same on every rank */
    cs_par_allgather(sim->par, sim->v, 3); /* velocities widen the boxes */
    double h = sim->def.self.thickness;
    sc->pt.n = sc->ee.n = 0;
    /* non-aggressive pruning: boxes grow by h/2 plus the distance each
     * particle would cover in the span at its present velocity relative to
     * the cloth's mean velocity (a pair's relative speed is at most the sum
     * of its particles' speeds relative to any common velocity, and only
     * relative motion brings a pair closer: a sheet falling rigidly needs
     * no wider boxes than one at rest). A pair that comes closer faster
     * than that is step C's to catch. */
    double mean[3] = {0, 0, 0};
    for (int i = 0; i < sc->n; i++)
        cs_axpy(1.0 / sc->n, sim->v + 3 * i, mean);
    double *margin = sim->force; /* scratch, free between steps */
    for (int i = 0; i < sc->n; i++) {
        double rel[3];
        cs_sub(sim->v + 3 * i, mean, rel);
        margin[i] = 0.5 * h + cs_norm(rel) * span;
        cs_box_empty(sc->pbox + i);
        cs_box_add_point(sc->pbox + i, x + 3 * i);
        cs_box_thicken(sc->pbox + i, margin[i]);
    }
    for (int k = 0; k < sc->ne; k++) {
        cs_box *b = sc->ebox + k;
        cs_box_empty(b);
        for (int j = 0; j < 2; j++) {
            int i = sc->edge[2 * k + j];
            cs_box pb = sc->pbox[i];
            cs_box_add_point(b, pb.lo);
            cs_box_add_point(b, pb.hi);
        }
    }
    for (int k = 0; k < sc->nt; k++) {
        cs_box *b = sc->tbox + k;
        cs_box_empty(b);
        for (int j = 0; j < 3; j++) {
            int i = sc->tri[3 * k + j];
            cs_box_add_point(b, sc->pbox[i].lo);
            cs_box_add_point(b, sc->pbox[i].hi);
        }
    }
    cs_bvh_refit(&sc->ptree, sc->pbox, NULL);
    cs_bvh_refit(&sc->etree, sc->ebox, NULL);
    cs_bvh_refit(&sc->ttree, sc->tbox, NULL);
    finder f = {sim, sc, h, span};
    int rank = sim->par->rank;
    int failed = find_pairs(sc, &sc->ptree, &sc->ttree, false, rank,
                            make_repulsion_point_triangle, &f, &sc->pt) ||
                 find_pairs(sc, &sc->etree, &sc->etree, false, rank, make_repulsion_edge_edge,
                            &f, &sc->ee);
    sc->stats.repulsion_pairs += sc->pt.n + sc->ee.n;
    if (distribute_boundary(sim, &sc->pt, &sc->ee) != 0)
        failed = 1;
    if (failed) /* out of memory: without pairs step C still keeps the cloth apart */
        sc->pt.n = sc->ee.n = sc->bpt.n = sc->bee.n = 0;
}

/* Fig. 12: phase I, each rank its components of boundary pairs (their
 * particles' state brought from the owners and the new velocities sent
 * back); phase II, every rank its internal pairs. The result is that of
 * one serial Gauss-Seidel order. */
void cs_selfcol_repulse(cs_sim *sim, double *x, double *v, double dt, bool elastic)
{
    cs_selfcol *sc = sim->selfcol;
    cs_par *par = sim->par;
    const cs_self_collision_def *d = &sim->def.self;
    response r = {true, elastic, !elastic, dt, d->thickness, d->stiffness, d->friction,
                  d->edge_flip_epsilon};
    if (par->size > 1) {
        cs_halo_forward(par, &sc->bhalo, x, 3);
        cs_halo_forward(par, &sc->bhalo, v, 3);
        sc->stats.repulsions += cs_pairs_apply(sc, &sc->bpt, &sc->bee, x, v, &r);
        cs_halo_reverse(par, &sc->bhalo, v, 3);
    }
    sc->stats.repulsions += cs_pairs_apply(sc, &sc->pt, &sc->ee, x, v, &r);
}

/* ------------------------------------------------------------- step C */

/* Positions of a pair's particles at time t of the trajectories. */
static void pair_at(const cs_selfcol *sc, const cs_pair *p, const double *x, double t,
                    double out[12])
{
    for (int k = 0; k < 4; k++)
        for (int d = 0; d < 3; d++) {
            double a = sc->x_free[3 * p->v[k] + d], b = x[3 * p->v[k] + d];
            out[3 * k + d] = a + t * (b - a);
        }
}

/* The conservative filter before any root finding. Along linear
 * trajectories the relative position of the pair at fixed weights moves by
 * a convex combination of the displacements of one side's vertices
 * relative to the other's, so the distance between the primitives never
 * drops faster than the largest such relative displacement ("reach"): a
 * pair farther apart at the start than the proximity tolerance plus its
 * reach cannot collide over the span. A sheet moving rigidly (reach 0) is
 * settled by one distance per pair instead of a vanishing cubic sampled 31
 * times. The slack covers the round-off of the distances compared. */
static bool out_of_reach(const cs_selfcol *sc, bool is_edge, const double *x0, const double *dx)
{
    int split = is_edge ? 2 : 3; /* one side: vertices [0, split) */
    double reach2 = 0, scale = 0;
    for (int i = 0; i < split; i++)
        for (int j = split; j < 4; j++) {
            double r[3];
            cs_sub(dx + 3 * j, dx + 3 * i, r);
            double r2 = cs_dot(r, r);
            reach2 = r2 > reach2 ? r2 : reach2;
        }
    for (int k = 0; k < 12; k++)
        scale = fabs(x0[k]) + fabs(dx[k]) > scale ? fabs(x0[k]) + fabs(dx[k]) : scale;
    double need = sc->proximity + sqrt(reach2);
    need += 64 * DBL_EPSILON * (scale + need);
    /* a separating axis of the start boxes bounds the distance first */
    const double *const pts[4] = {x0, x0 + 3, x0 + 6, x0 + 9};
    if (sides_apart(pts, split, need))
        return true;
    double d0, w[3], s, t;
    if (is_edge)
        d0 = cs_segment_segment_closest(x0, x0 + 3, x0 + 6, x0 + 9, &s, &t);
    else
        d0 = cs_point_triangle_closest(x0 + 9, x0, x0 + 3, x0 + 6, w);
    return d0 > need;
}

/* Continuous test: the first coplanar time at which the pair comes within
 * the proximity tolerance; fills the weights c and a unit normal oriented
 * from the free state's side. */
static bool pair_collides(const cs_selfcol *sc, const cs_pair *p, bool is_edge, const double *x,
                          double c[4], double n[3])
{
    double x0[12], x1[12], dx[12], times[CS_CCD_MAX_TIMES];
    pair_at(sc, p, x, 0, x0);
    pair_at(sc, p, x, 1, x1);
    for (int k = 0; k < 12; k++)
        dx[k] = x1[k] - x0[k];
    if (out_of_reach(sc, is_edge, x0, dx))
        return false;
    int nt = cs_coplanarity_times(x0, x0 + 3, x0 + 6, x0 + 9, dx, dx + 3, dx + 6, dx + 9, times);
    for (int i = 0; i < nt; i++) {
        double xt[12], dist, w[3], s, t;
        for (int k = 0; k < 12; k++)
            xt[k] = x0[k] + times[i] * dx[k];
        if (!is_edge) {
            dist = cs_point_triangle_closest(xt + 9, xt, xt + 3, xt + 6, w);
            c[0] = -w[0], c[1] = -w[1], c[2] = -w[2], c[3] = 1;
        } else {
            dist = cs_segment_segment_closest(xt, xt + 3, xt + 6, xt + 9, &s, &t);
            c[0] = -(1 - s), c[1] = -s, c[2] = 1 - t, c[3] = t;
        }
        if (!(dist < sc->proximity))
            continue;
        /* normal at the collision time: the triangle's, or the two edges'
         * common perpendicular; falling back on the separation direction */
        double e1[3], e2[3];
        if (!is_edge) {
            cs_sub(xt + 3, xt, e1);
            cs_sub(xt + 6, xt, e2);
        } else {
            cs_sub(xt + 3, xt, e1);
            cs_sub(xt + 9, xt + 6, e2);
        }
        cs_cross(e1, e2, n);
        double len = cs_norm(n);
        double rel0[3] = {0, 0, 0}, relv[3] = {0, 0, 0};
        for (int k = 0; k < 4; k++) {
            cs_axpy(c[k], x0 + 3 * k, rel0);
            cs_axpy(c[k], dx + 3 * k, relv);
        }
        if (!(len > 1e-12 * (cs_dot(e1, e1) + cs_dot(e2, e2)))) {
            memcpy(n, rel0, sizeof rel0);
            len = cs_norm(n);
            if (!(len > 0)) {
                memcpy(n, relv, sizeof relv);
                len = cs_norm(n);
                if (!(len > 0))
                    continue; /* nothing moves and nothing separates: no impulse helps */
            }
        }
        for (int k = 0; k < 3; k++)
            n[k] /= len;
        /* orient from the side the pair started on; starting in contact, the
         * side the point's cloth is on; failing that, against the approach */
        double side = cs_dot(rel0, n);
        if (!is_edge && fabs(side) <= 1e-12 * cs_norm(rel0))
            side = ring_side(sc, sc->x_free, p->v[3], n);
        if (side < 0 || (side == 0 && cs_dot(relv, n) > 0))
            for (int k = 0; k < 3; k++)
                n[k] = -n[k];
        /* in contact at the start and moving apart: that is the response
         * of an earlier pass working, not a collision */
        if (times[i] == 0 && cs_dot(relv, n) >= 0)
            continue;
        return true;
    }
    return false;
}

/* A colliding pair's history, as step A gives its pairs: the side it
 * started on in the collision-free state (nrm, from pair_collides). An
 * edge/edge pair keeps it as s0; a point/triangle pair is wound so the
 * triangle's normal points at that side. Without it the elastic push of
 * the response reads no history (an edge pair) or pushes a point that came
 * from behind a triangle through it (a point pair). */
static void set_history(const cs_selfcol *sc, cs_pair *p, bool is_edge, const double nrm[3])
{
    memcpy(p->s0, nrm, sizeof p->s0);
    if (is_edge)
        return;
    const double *x = sc->x_free;
    double e1[3], e2[3], wn[3];
    cs_sub(x + 3 * p->v[1], x + 3 * p->v[0], e1);
    cs_sub(x + 3 * p->v[2], x + 3 * p->v[0], e2);
    cs_cross(e1, e2, wn);
    if (cs_dot(wn, nrm) < 0) {
        int swap = p->v[1];
        p->v[1] = p->v[2];
        p->v[2] = swap;
    }
}

typedef struct collector {
    const cs_selfcol *sc;
    const cs_par *par;
    const double *x;
} collector;

/* The pair (v) this rank finds, if it collides, with its history. */
static bool collision_of(const collector *cl, const int v[4], bool is_edge, cs_pair *out)
{
    if (pair_rank(cl->par, v) != cl->par->rank)
        return false;
    memcpy(out->v, v, sizeof out->v);
    double c[4], nrm[3];
    if (!pair_collides(cl->sc, out, is_edge, cl->x, c, nrm))
        return false;
    set_history(cl->sc, out, is_edge, nrm);
    return true;
}

static bool make_collision_point_triangle(const void *ctx, int point, int t, cs_pair *out)
{
    const collector *cl = ctx;
    const int *tri = cl->sc->tri + 3 * t;
    if (point == tri[0] || point == tri[1] || point == tri[2])
        return false; /* wings stay: a wing point crossing drags its other triangles through */
    int v[4] = {tri[0], tri[1], tri[2], point};
    return collision_of(cl, v, false, out);
}

static bool make_collision_edge_edge(const void *ctx, int ea, int eb, cs_pair *out)
{
    const collector *cl = ctx;
    const int *a = cl->sc->edge + 2 * ea, *b = cl->sc->edge + 2 * eb;
    if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1])
        return false;
    int v[4] = {a[0], a[1], b[0], b[1]};
    return collision_of(cl, v, true, out);
}

/* Swept boxes from the free positions to x, and the pairs among their
 * primitives that collide along the trajectories, with their history (only
 * near changed particles when only_dirty). Returns how many, or -1 when
 * memory ran out. */
static long find_collisions(cs_selfcol *sc, const cs_par *par, const double *x,
                            bool only_dirty)
{
    double pad = sc->proximity;
#pragma omp parallel for schedule(static)
    for (int i = 0; i < sc->n; i++) {
        cs_box *b = sc->pbox + i;
        cs_box_empty(b);
        cs_box_add_point(b, sc->x_free + 3 * i);
        cs_box_add_point(b, x + 3 * i);
        cs_box_thicken(b, pad);
        sc->pdirty[i] = sc->vdirty[i];
    }
#pragma omp parallel for schedule(static)
    for (int k = 0; k < sc->ne; k++) {
        cs_box *b = sc->ebox + k;
        int i = sc->edge[2 * k], j = sc->edge[2 * k + 1];
        *b = sc->pbox[i];
        cs_box_add_point(b, sc->pbox[j].lo);
        cs_box_add_point(b, sc->pbox[j].hi);
        sc->edirty[k] = sc->vdirty[i] | sc->vdirty[j];
    }
#pragma omp parallel for schedule(static)
    for (int k = 0; k < sc->nt; k++) {
        cs_box *b = sc->tbox + k;
        const int *t = sc->tri + 3 * k;
        *b = sc->pbox[t[0]];
        cs_box_add_point(b, sc->pbox[t[1]].lo);
        cs_box_add_point(b, sc->pbox[t[1]].hi);
        cs_box_add_point(b, sc->pbox[t[2]].lo);
        cs_box_add_point(b, sc->pbox[t[2]].hi);
        sc->tdirty[k] = sc->vdirty[t[0]] | sc->vdirty[t[1]] | sc->vdirty[t[2]];
    }
    cs_bvh_refit(&sc->ptree, sc->pbox, sc->pdirty);
    cs_bvh_refit(&sc->etree, sc->ebox, sc->edirty);
    cs_bvh_refit(&sc->ttree, sc->tbox, sc->tdirty);
    sc->cpt.n = sc->cee.n = 0;
    collector cl = {sc, par, x};
    if (find_pairs(sc, &sc->ptree, &sc->ttree, only_dirty, par->rank,
                   make_collision_point_triangle, &cl, &sc->cpt) ||
        find_pairs(sc, &sc->etree, &sc->etree, only_dirty, par->rank, make_collision_edge_edge,
                   &cl, &sc->cee))
        return -1;
    return sc->cpt.n + sc->cee.n;
}

/* Symmetric 3x3 eigen decomposition by cyclic Jacobi rotations:
 * A = Q diag(l) Q^T, Q's columns the eigenvectors. */
static void eigen_symmetric(const double A_in[9], double l[3], double Q[9])
{
    double A[9];
    memcpy(A, A_in, sizeof A);
    for (int k = 0; k < 9; k++)
        Q[k] = (k % 4 == 0) ? 1 : 0;
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = fabs(A[1]) + fabs(A[2]) + fabs(A[5]);
        if (off <= 1e-300 || off < 1e-18 * (fabs(A[0]) + fabs(A[4]) + fabs(A[8])))
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                double apq = A[3 * p + q];
                if (apq == 0)
                    continue;
                double theta = (A[3 * q + q] - A[3 * p + p]) / (2 * apq);
                double t = copysign(1.0, theta) / (fabs(theta) + sqrt(theta * theta + 1));
                double c = 1 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < 3; k++) { /* A = J^T A J */
                    double akp = A[3 * k + p], akq = A[3 * k + q];
                    A[3 * k + p] = c * akp - s * akq;
                    A[3 * k + q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) {
                    double apk = A[3 * p + k], aqk = A[3 * q + k];
                    A[3 * p + k] = c * apk - s * aqk;
                    A[3 * q + k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; k++) {
                    double qkp = Q[3 * k + p], qkq = Q[3 * k + q];
                    Q[3 * k + p] = c * qkp - s * qkq;
                    Q[3 * k + q] = s * qkp + c * qkq;
                }
            }
    }
    l[0] = A[0], l[1] = A[4], l[2] = A[8];
}

void cs_impact_zone_motion(int n, const int *idx, const double *m, const double *xf,
                           const double *u, double span, double *x, double vcm[3],
                           double omega[3])
{
    double M = 0, xcm[3] = {0, 0, 0};
    vcm[0] = vcm[1] = vcm[2] = 0;
    for (int k = 0; k < n; k++) {
        int i = idx[k];
        M += m[i];
        cs_axpy(m[i], xf + 3 * i, xcm);
        cs_axpy(m[i], u + 3 * i, vcm);
    }
    for (int d = 0; d < 3; d++) {
        xcm[d] /= M;
        vcm[d] /= M;
    }
    double L[3] = {0, 0, 0}, I[9] = {0};
    for (int k = 0; k < n; k++) {
        int i = idx[k];
        double r[3], du[3], rxu[3];
        cs_sub(xf + 3 * i, xcm, r);
        cs_sub(u + 3 * i, vcm, du);
        cs_cross(r, du, rxu);
        cs_axpy(m[i], rxu, L);
        double rr = cs_dot(r, r);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                I[3 * a + b] += m[i] * ((a == b ? rr : 0) - r[a] * r[b]);
    }
    /* omega = I^+ L: eigenvalues below round-off of the largest count as
     * zero (coplanar, colinear, coincident points) */
    double l[3], Q[9];
    eigen_symmetric(I, l, Q);
    double lmax = fmax(fabs(l[0]), fmax(fabs(l[1]), fabs(l[2])));
    double qL[3];
    cs_mat_apply_transpose(Q, L, qL);
    for (int k = 0; k < 3; k++)
        qL[k] = fabs(l[k]) > 1e-12 * lmax && l[k] != 0 ? qL[k] / l[k] : 0;
    cs_mat_apply(Q, qL, omega);
    double q[4], R[9];
    cs_quat_from_rotation_vector(omega, span, q);
    cs_quat_to_matrix(q, R);
    for (int k = 0; k < n; k++) {
        int i = idx[k];
        double r[3], Rr[3];
        cs_sub(xf + 3 * i, xcm, r);
        cs_mat_apply(R, r, Rr);
        for (int d = 0; d < 3; d++)
            x[3 * i + d] = xcm[d] + span * vcm[d] + Rr[d];
    }
}

/* Moves every impact zone rigidly; pinned and scripted particles weigh
 * far more than the rest and keep their prescribed positions. */
static void rigidify_zones(cs_sim *sim, double span, double *dv)
{
    cs_selfcol *sc = sim->selfcol;
    int n = sc->n;
    /* scratch, free during step C: v_half, and CG's explicit start */
    double *u = sim->v_half, *mw = sim->cg.explicit_z;
    double heaviest = 0;
    for (int i = 0; i < n; i++)
        heaviest = fmax(heaviest, sim->mass[i]);
    for (int i = 0; i < n; i++) {
        for (int d = 0; d < 3; d++)
            u[3 * i + d] = (sim->x[3 * i + d] - sc->x_free[3 * i + d]) / span;
        mw[i] = sim->is_free[i] ? sim->mass[i] : 1e6 * heaviest;
    }
    for (int root = 0; root < n; root++) {
        if (sc->zone[root] < 0 || zone_find(sc->zone, root) != root)
            continue;
        int count = 0;
        for (int i = 0; i < n; i++)
            if (sc->zone[i] >= 0 && zone_find(sc->zone, i) == root)
                sc->zone_list[count++] = i;
        double vcm[3], w[3];
        cs_impact_zone_motion(count, sc->zone_list, mw, sc->x_free, u, span, sim->x, vcm, w);
        for (int k = 0; k < count; k++) {
            int i = sc->zone_list[k];
            if (!sim->is_free[i])
                memcpy(sim->x + 3 * i, sc->x_before + 3 * i, 3 * sizeof(double));
            for (int d = 0; d < 3; d++) /* a zone is an inelastic merge: v follows */
                dv[3 * i + d] += (sim->x[3 * i + d] - sc->x_free[3 * i + d]) / span - u[3 * i + d];
            sc->vdirty[i] = 1;
        }
        if (count > sc->stats.max_zone)
            sc->stats.max_zone = count;
        for (int k = 1; k < count; k++)
            if (sim->par->owner[sc->zone_list[k]] != sim->par->owner[sc->zone_list[0]]) {
                sc->stats.zones_across++;
                break;
            }
    }
}

/* One colliding pair's response in step C: inelastic on the effective
 * velocities u (the real velocity's change accumulates in dv), then an
 * elastic push if the end positions are too close. Returns false when the
 * pair no longer collides (an earlier response moved it). */
static bool collision_respond(cs_selfcol *sc, const cs_pair *p, bool is_edge, double *x,
                              double *u, double *dv, double span, const response *elastic)
{
    double c[4], nrm[3];
    if (!pair_collides(sc, p, is_edge, x, c, nrm))
        return false;
    double inv_m = pair_inverse_mass(sc, p, c), rel[3];
    if (!(inv_m > 0))
        return true;
    double un = pair_normal_velocity(p, c, u, nrm, rel);
    if (un < 0) {
        pair_impulse(sc, p, c, -un / inv_m, nrm, u);
        pair_impulse(sc, p, c, -un / inv_m, nrm, dv);
    }
    for (int q = 0; q < 4; q++) {
        int i = p->v[q];
        for (int e = 0; e < 3; e++)
            x[3 * i + e] = sc->x_free[3 * i + e] + span * u[3 * i + e];
    }
    if (pair_respond(sc, p, is_edge, x, u, elastic))
        for (int q = 0; q < 4; q++) {
            int i = p->v[q];
            for (int e = 0; e < 3; e++)
                x[3 * i + e] = sc->x_free[3 * i + e] + span * u[3 * i + e];
        }
    return true;
}

static void respond_all(cs_selfcol *sc, const cs_pair_list *pt, const cs_pair_list *ee,
                        double *x, double *u, double *dv, double span, const response *elastic)
{
    for (int j = 0; j < pt->n; j++)
        collision_respond(sc, pt->p + j, false, x, u, dv, span, elastic);
    for (int j = 0; j < ee->n; j++)
        collision_respond(sc, ee->p + j, true, x, u, dv, span, elastic);
}

/* Impact zones over all ranks: every rank merges every colliding pair's
 * particles in the same order, so all hold the same zones. Returns 0 or
 * -1. */
static int merge_zones(cs_sim *sim)
{
    cs_selfcol *sc = sim->selfcol;
    int nmine = sc->cpt.n + sc->cee.n;
    int *mine = malloc(sizeof *mine * 4 * ((size_t)nmine + 1));
    if (!mine)
        return -1;
    for (int l = 0, m = 0; l < 2; l++) {
        const cs_pair_list *list = l == 0 ? &sc->cpt : &sc->cee;
        for (int j = 0; j < list->n; j++, m++)
            memcpy(mine + 4 * m, list->p[j].v, 4 * sizeof *mine);
    }
    void *gathered;
    int nall;
    int rc = cs_par_allgather_items(sim->par, mine, nmine, 4 * sizeof *mine, &gathered, &nall);
    free(mine);
    if (rc)
        return -1;
    const int *all = gathered;
    for (int k = 0; k < nall; k++)
        for (int q = 1; q < 4; q++)
            zone_union(sc->zone, all[4 * k], all[4 * k + q]);
    free(gathered);
    return 0;
}

/* Step C on several ranks: each pass starts from positions synchronised to
 * every rank; each rank finds its assigned colliding pairs; responses run
 * in Fig. 12's two phases (components of boundary pairs, results sent to
 * the owners, then internal pairs); the pass count, the decision to stop
 * and the impact zones are global. On one rank there are no messages and
 * no boundary pairs. */
long cs_selfcol_collide(cs_sim *sim, double span, int k, bool detect_only)
{
    cs_selfcol *sc = sim->selfcol;
    cs_par *par = sim->par;
    const cs_self_collision_def *d = &sim->def.self;
    int n = sc->n;
    double *x = sim->x;
    size_t bytes = sizeof(double) * 3 * (size_t)n;
    cs_par_allgather(par, x, 3);
    memcpy(sc->x_before, x, bytes);
    for (int i = 0; i < n; i++) {
        sc->vdirty[i] = 1;
        sc->zone[i] = -1;
    }
    /* elastic repulsion after a collision uses the average step of the
     * loop, not the whole span: later steps' repulsions do the rest */
    response elastic = {false, true, false, span / (k > 0 ? k : 1), d->thickness, d->stiffness,
                        0, d->edge_flip_epsilon};
    double *u = sim->v_next; /* effective velocities; scratch between steps */
    /* The real velocity takes the inelastic changes only (impulses and
     * zones); the elastic push moves positions, as in B.2 (Section 5). */
    double *dv = sim->v0;
    memset(dv, 0, bytes);
    long first_pass = 0;
    int zones_formed = 0;
    for (int pass = 0;; pass++) {
        if (pass > 0) { /* what moved since the last pass, on any rank */
            cs_par_allgather(par, x, 3);
            for (int i = 0; i < n; i++)
                sc->vdirty[i] = memcmp(x + 3 * i, sc->x_pass + 3 * i, 3 * sizeof *x) != 0;
        }
        memcpy(sc->x_pass, x, bytes);
        long found = find_collisions(sc, par, x, pass > 0), found_all = found;
        if (found < 0)
            abort(); /* out of memory finding collisions: no collision-free state to keep */
        sc->stats.passes++;
        bool zone_mode = pass >= d->zone_iterations;
        for (int i = 0; i < n; i++)
            for (int c = 0; c < 3; c++)
                u[3 * i + c] = (x[3 * i + c] - sc->x_free[3 * i + c]) / span;
        cs_par_sum_long(par, &found_all, 1);
        if (pass == 0)
            first_pass = found_all;
        sc->stats.collisions += found;
        if (detect_only || found_all == 0)
            break;
        if (zone_mode) {
            if (merge_zones(sim) != 0)
                abort(); /* out of memory in the last resort: nothing safe to do */
            zones_formed++;
            rigidify_zones(sim, span, dv);
        } else {
            if (distribute_boundary(sim, &sc->cpt, &sc->cee) != 0)
                abort();
            /* phase I: the state is synchronised; results go to the owners */
            respond_all(sc, &sc->bpt, &sc->bee, x, u, dv, span, &elastic);
            cs_halo_reverse(par, &sc->bhalo, x, 3);
            cs_halo_reverse(par, &sc->bhalo, u, 3);
            cs_halo_reverse(par, &sc->bhalo, dv, 3);
            /* phase II */
            respond_all(sc, &sc->cpt, &sc->cee, x, u, dv, span, &elastic);
        }
        if (pass > d->zone_iterations + 1000) {
            /* cannot happen in exact arithmetic (zones only grow); stop
             * the free particles at the collision-free state rather than
             * loop forever */
            for (int i = 0; i < n; i++)
                if (sim->is_free[i])
                    memcpy(x + 3 * i, sc->x_free + 3 * i, 3 * sizeof(double));
            break;
        }
    }
    if (detect_only)
        return first_pass;
    if (zones_formed) {
        int roots = 0;
        for (int i = 0; i < n; i++)
            roots += sc->zone[i] >= 0 && zone_find(sc->zone, i) == i;
        sc->stats.zones += roots;
    }
    CS_FOR_OWNED(par, i)
        for (int c = 0; c < 3; c++)
            sim->v[3 * i + c] += dv[3 * i + c];
    memcpy(sc->x_free, x, bytes); /* the same on every rank */
    return first_pass;
}
