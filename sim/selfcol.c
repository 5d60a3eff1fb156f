/* selfcol.c: history-based repulsions (Section 5): the pairs of step A
 * with their history, their response in B.2 and B.8, and the pairs' ranks
 * (Section 7). Step C is in selfcol_collide.c. */
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "sim/ccd.h"
#include "sim/selfcol_private.h"
#include "sim/vec3.h"

/* Eq. 1: the elastic repulsion impulse is at most m (0.1 d / dt - v_N),
 * enough to close a tenth of the overlap d in one step */
static const double REPULSION_CLOSING = 0.1;
/* Step C's proximity tolerance: a pair that comes this close at a coplanar
 * time counts as colliding; tiny against both the thickness and the edges
 * (a round-off guard for the coplanar test, not a physical distance) */
static const double PROXIMITY_PER_THICKNESS = 1e-3, PROXIMITY_PER_EDGE = 1e-4;

void cs_selfcol_release(cs_selfcol *sc, int i, double mass) { sc->inv_mass[i] = 1.0 / mass; }

/* ------------------------------------------------------------ topology */

int sc_pair_push(cs_pair_list *l, const int v[4], const double *s0)
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

int sc_zone_find(int *parent, int i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

void sc_zone_union(int *parent, int a, int b)
{
    if (parent[a] < 0)
        parent[a] = a;
    if (parent[b] < 0)
        parent[b] = b;
    a = sc_zone_find(parent, a);
    b = sc_zone_find(parent, b);
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
    sc->use_start_gap = true;
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
    sc->collided = calloc((size_t)n + 1, 1);
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
    if (!sc->pbox || !sc->ebox || !sc->tbox || !sc->pdirty || !sc->vdirty || !sc->collided ||
        !sc->edirty || !sc->tdirty || !sc->x_free || !sc->x_before || !sc->inv_mass || !sc->zone ||
        !sc->zone_list)
        goto fail;
    memcpy(sc->x_free, sim->x, sizeof(double) * 3 * (size_t)n);
    double mean_edge = 0;
    for (int k = 0; k < ne; k++) {
        double d[3];
        cs_sub(sim->x + 3 * e[2 * k + 1], sim->x + 3 * e[2 * k], d);
        mean_edge += cs_norm(d) / ne;
    }
    sc->proximity = fmin(PROXIMITY_PER_THICKNESS * sim->def.self.thickness,
                         PROXIMITY_PER_EDGE * (mean_edge > 0 ? mean_edge : 1));
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
    cs_bvh_set_vertices(&sc->etree, sc->edge, 2);
    cs_bvh_set_vertices(&sc->ttree, sc->tri, 3);
    if (sc_cache_create(sc))
        goto fail;
    sc->bytes = sizeof(cs_box) * (size_t)(n + ne + nt) * 4 + sizeof(double) * 16 * (size_t)n +
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
    void *arrays[] = {sc->edge, sc->tri, sc->ring_start, sc->ring, sc->pbox, sc->ebox, sc->tbox, sc->pdirty, sc->collided, sc->edirty,
                      sc->tdirty, sc->vdirty, sc->x_free, sc->x_before, sc->inv_mass, sc->zone,
                      sc->zone_list, sc->pt.p, sc->ee.p, sc->cpt.p, sc->cee.p,
                      sc->prim_rank, sc->component, sc->bpt.p, sc->bee.p, sc->x_pass,
                      sc->kc, sc->kc_list};
    for (size_t k = 0; k < sizeof arrays / sizeof *arrays; k++)
        free(arrays[k]);
    cs_halo_free(&sc->bhalo);
    sc_cache_free(sc);
    cs_bvh_work_free(&sc->bvh_work);
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

double sc_pair_inverse_mass(const cs_selfcol *sc, const cs_pair *p, const double c[4])
{
    double s = 0;
    for (int k = 0; k < 4; k++)
        s += c[k] * c[k] * sc->inv_mass[p->v[k]];
    return s;
}

double sc_pair_normal_velocity(const cs_pair *p, const double c[4], const double *v,
                               const double n[3], double rel[3])
{
    rel[0] = rel[1] = rel[2] = 0;
    for (int k = 0; k < 4; k++)
        cs_axpy(c[k], v + 3 * p->v[k], rel);
    return cs_dot(rel, n);
}

/* v_k += c_k J / m_k dir: an impulse J on the pair's relative motion */
void sc_pair_impulse(const cs_selfcol *sc, const cs_pair *p, const double c[4], double J,
                     const double dir[3], double *v)
{
    for (int k = 0; k < 4; k++)
        cs_axpy(c[k] * J * sc->inv_mass[p->v[k]], dir, v + 3 * p->v[k]);
}

/* ------------------------------------------------- pair response, once */


/* Applies one pair's response to velocities v at positions x; returns true
 * if it interacted. Inelastic: I = m v_N stops approach; elastic: Eq. 1
 * with d from Eq. 2 (larger when the pair has crossed, so it pulls back);
 * friction: Coulomb with the normal velocity change. */
/* Whether the boxes of a pair's two sides (vertices [0, split) and
 * [split, 4) at positions p[k]) are more than gap apart along an axis:
 * then the sides are farther apart than gap. */
bool sc_sides_apart(const double *const p[4], int split, double gap)
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
 * are not interacting now; a box test thickened by the thickness settles
 * that cheaply. */
static bool pair_near(const cs_pair *p, bool is_edge, const double *x, double thickness)
{
    const double *const pts[4] = {x + 3 * p->v[0], x + 3 * p->v[1], x + 3 * p->v[2],
                                  x + 3 * p->v[3]};
    return !sc_sides_apart(pts, is_edge ? 2 : 3, thickness);
}

/* Bridson's proximity condition for a repulsion: a point/triangle pair
 * only where the point projects inside the triangle (within the thickness
 * over the triangle's size), an edge/edge pair only where the closest
 * points are inside both edges. Elsewhere the other kind of pair is the
 * right one; without this, in-plane neighbours closer than the thickness
 * would push each other out of a flat sheet along its normal. */
static bool pair_interior(const cs_pair *p, bool is_edge, const double *x, const double c[4],
                          double thickness)
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
    double tol = thickness / sqrt(sqrt(nn)); /* thickness over the triangle's size */
    return w0 > -tol && w1 > -tol && w2 > -tol;
}

bool sc_pair_respond(const cs_selfcol *sc, const cs_pair *p, bool is_edge, const double *x,
                     double *v, const response *r)
{
    if (!pair_near(p, is_edge, x, r->thickness))
        return false;
    double c[4], n[3], dist, sd;
    if (!pair_frame(p, is_edge, x, r->epsilon, c, n, &dist, &sd))
        return false;
    if (!(dist < r->thickness) || !pair_interior(p, is_edge, x, c, r->thickness))
        return false;
    double inv_m = sc_pair_inverse_mass(sc, p, c);
    if (!(inv_m > 0))
        return false;
    double rel[3];
    double vn = sc_pair_normal_velocity(p, c, v, n, rel), dvn = 0;
    if (r->inelastic && vn < 0) {
        sc_pair_impulse(sc, p, c, -vn / inv_m, n, v);
        dvn = -vn;
        vn = 0;
    }
    if (r->elastic) {
        double d = r->thickness - sd;
        double J = fmin(r->dt * r->k * d, (REPULSION_CLOSING * d / r->dt - vn) / inv_m);
        if (J > 0) {
            sc_pair_impulse(sc, p, c, J, n, v);
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
            sc_pair_impulse(sc, p, c, -drop / inv_m, dir, v);
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
        applied += sc_pair_respond(sc, pt->p + i, false, x, v, r);
    for (int i = 0; i < ee->n; i++)
        applied += sc_pair_respond(sc, ee->p + i, true, x, v, r);
    return applied;
}

/* Which side of a plane (normal nrm) a point belongs on when it lies in
 * the plane itself: the side its own cloth is on, judged by its neighbours
 * along edges. Zero when that says nothing either (a lone particle, or a
 * cloth lying in the plane). */
double sc_ring_side(const cs_selfcol *sc, const double *x, int point, const double nrm[3])
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

int sc_pair_rank(const cs_par *par, const int v[4])
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
    sc->cache.valid = false; /* its pairs were pruned for other ranks */
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
int sc_distribute_boundary(cs_sim *sim, cs_pair_list *pt, cs_pair_list *ee)
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
            sc_zone_union(parent, all[k].v[0], all[k].v[j]);
    for (int k = 0; k < nall; k++)
        root_rank[sc_zone_find(parent, all[k].v[0])] = par->size;
    int *user = malloc(sizeof *user * (4 * (size_t)nall + 1));
    int *particle = malloc(sizeof *particle * (4 * (size_t)nall + 1));
    if (!user || !particle)
        rc = -1;
    for (int k = 0; k < nall; k++) {
        int root = sc_zone_find(parent, all[k].v[0]);
        if (all[k].rank < root_rank[root])
            root_rank[root] = all[k].rank;
    }
    for (int l = 0; l < 2 && !rc; l++) /* point/triangle pairs first, as on one rank */
        for (int k = 0; k < nall && !rc; k++) {
            if (all[k].is_edge != l)
                continue;
            int proc = root_rank[sc_zone_find(parent, all[k].v[0])];
            for (int j = 0; j < 4; j++) {
                user[4 * k + j] = proc;
                particle[4 * k + j] = all[k].v[j];
            }
            if (proc == par->rank)
                rc = sc_pair_push(l ? &sc->bee : &sc->bpt, all[k].v, all[k].s0);
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
    double thickness, span;
} finder;

/* Keep a pair only if it can come within the thickness during the span at
 * its present relative velocity: distance in the free state less the largest relative
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
    return dist < f->thickness + rel * f->span;
}

/* The makers below turn a candidate (a, b) of a traversal into a pair
 * (pair_maker, selfcol_private.h). */

/* The makers measure every pair step C could find (wings and pairs of
 * held particles too, which step A itself leaves out), for start_gap. */
static void note_distance(const finder *f, double dist)
{
    cs_made_list *mine = f->sc->made + omp_get_thread_num();
    if (!(dist >= mine->nearest)) /* NaN too: then step C skips nothing */
        mine->nearest = dist;
}

static bool make_repulsion_point_triangle(const void *ctx, int point, int t, cs_pair *out)
{
    const finder *f = ctx;
    const cs_selfcol *sc = f->sc;
    const int *tri = sc->tri + 3 * t;
    if (point == tri[0] || point == tri[1] || point == tri[2])
        return false;
    int quad[4] = {tri[0], tri[1], tri[2], point};
    if (sc_pair_rank(f->sim->par, quad) != f->sim->par->rank)
        return false; /* another rank's to find */
    const double *x = sc->x_free;
    double w[3];
    double dist = cs_point_triangle_closest(x + 3 * point, x + 3 * tri[0], x + 3 * tri[1],
                                            x + 3 * tri[2], w);
    note_distance(f, dist);
    if (wing_pair(sc, point, tri))
        return false;
    if (sc->inv_mass[point] == 0 && sc->inv_mass[tri[0]] == 0 && sc->inv_mass[tri[1]] == 0 &&
        sc->inv_mass[tri[2]] == 0)
        return false;
    int v[4] = {tri[0], tri[1], tri[2], point};
    if (!may_meet(f, v, 3, dist))
        return false;
    /* history: wind the triangle so its normal points at the free point
     * (the paper's reordering; swapping two triangle vertices flips it) */
    double e1[3], e2[3], nrm[3], r[3];
    cs_sub(x + 3 * tri[1], x + 3 * tri[0], e1);
    cs_sub(x + 3 * tri[2], x + 3 * tri[0], e2);
    cs_cross(e1, e2, nrm);
    cs_sub(x + 3 * point, x + 3 * tri[0], r);
    double side = cs_dot(nrm, r);
    if (fabs(side) <= 1e-12 * cs_norm(nrm) * (cs_norm(r) + cs_norm(e1)))
        side = sc_ring_side(sc, x, point, nrm); /* in the plane: ambiguous */
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
    if (sc_pair_rank(f->sim->par, quad) != f->sim->par->rank)
        return false; /* another rank's to find */
    const double *x = sc->x_free;
    double s, t, s0[3];
    note_distance(f, cs_segment_segment_closest(x + 3 * a[0], x + 3 * a[1], x + 3 * b[0],
                                                x + 3 * b[1], &s, &t));
    if (sc->inv_mass[a[0]] == 0 && sc->inv_mass[a[1]] == 0 && sc->inv_mass[b[0]] == 0 &&
        sc->inv_mass[b[1]] == 0)
        return false;
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

void cs_selfcol_find_pairs(cs_sim *sim, double span)
{
    cs_selfcol *sc = sim->selfcol;
    const double *x = sc->x_free; /* the same on every rank */
    cs_par_allgather(sim->par, sim->v, 3); /* velocities widen the boxes */
    double thickness = sim->def.self.thickness;
    sc->pt.n = sc->ee.n = 0;
    /* The particles' boxes (def.self.pruning). `speed`, the paper's
     * non-aggressive pruning: half the thickness plus the distance the
     * particle would cover in the span at its present velocity relative to
     * the cloth's mean velocity, along all three axes (a pair's relative
     * speed is at most the sum of its particles' speeds relative to any
     * common velocity, so every pair may_meet keeps is found). `path`: the
     * particle's straight path relative to the mean, x + (v - mean) s for s
     * in [0, span], grown by half the thickness; if a pair's straight
     * relative path comes within the thickness at some s, the points x_a +
     * (v_a - mean) s and x_b + (v_b - mean) s are within it, so the boxes
     * overlap. A pair must pass both the boxes and may_meet, so `path`
     * drops the pairs within may_meet's reach whose straight paths miss:
     * another rule, not only a faster search (the same frames on drapes,
     * not on cloth folding onto itself; docs/performance.md, "Step A's
     * boxes along the path").
     * Either way only relative motion widens a box: a sheet
     * falling rigidly needs no wider boxes than one at rest. A pair that
     * comes closer faster than that is step C's to catch. */
    double mean[3] = {0, 0, 0};
    for (int i = 0; i < sc->n; i++)
        cs_axpy(1.0 / sc->n, sim->v + 3 * i, mean);
    bool path = sim->def.self.pruning == CS_PRUNING_PATH;
    /* the boxes: one writer each, so threads change no bit */
#pragma omp parallel for schedule(static)
    for (int i = 0; i < sc->n; i++) {
        double rel[3], end[3];
        cs_sub(sim->v + 3 * i, mean, rel);
        double *drift = sc->cache.drift + 3 * i; /* the motion over the span */
        for (int d = 0; d < 3; d++)
            drift[d] = rel[d] * span;
        cs_box_empty(sc->pbox + i);
        cs_box_add_point(sc->pbox + i, x + 3 * i);
        if (path) {
            for (int d = 0; d < 3; d++)
                end[d] = x[3 * i + d] + drift[d];
            cs_box_add_point(sc->pbox + i, end);
            cs_box_thicken(sc->pbox + i, 0.5 * thickness);
        } else {
            cs_box_thicken(sc->pbox + i, 0.5 * thickness + cs_norm(rel) * span);
        }
    }
#pragma omp parallel for schedule(static)
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
#pragma omp parallel for schedule(static)
    for (int k = 0; k < sc->nt; k++) {
        cs_box *b = sc->tbox + k;
        cs_box_empty(b);
        for (int j = 0; j < 3; j++) {
            int i = sc->tri[3 * k + j];
            cs_box_add_point(b, sc->pbox[i].lo);
            cs_box_add_point(b, sc->pbox[i].hi);
        }
    }
    finder f = {sim, sc, thickness, span};
    for (int t = 0; t < sc->nmade; t++) /* threads added by the searches start at 0 */
        sc->made[t].nearest = INFINITY;
    /* start_gap: the makers measured every pair of this rank whose boxes
     * overlap but those the skin showed farther than this; the others'
     * boxes, each at least half the thickness around its particles, lie
     * apart, so their sides are a thickness apart (less a thousandth for
     * the boxes' round-off) */
    double gap = 0.999 * thickness;
    sc_skin skin = {thickness, span, gap}, *use = sc->cache.skin_off ? NULL : &skin;
    int failed = sc_cache_update(sc, sim->par->rank, thickness, sim->v, mean) ||
                 sc_find_pairs(sc, false, false, use, make_repulsion_point_triangle, &f, &sc->pt) ||
                 sc_find_pairs(sc, true, false, use, make_repulsion_edge_edge, &f, &sc->ee);
    for (int t = 0; t < sc->nmade; t++)
        if (!(sc->made[t].nearest >= gap))
            gap = sc->made[t].nearest;
    sc->start_gap = failed ? 0 : gap;
    sc->stats.repulsion_pairs += sc->pt.n + sc->ee.n;
    if (sc_distribute_boundary(sim, &sc->pt, &sc->ee) != 0)
        failed = 1;
    if (failed) /* out of memory: without pairs step C still keeps the cloth apart */
        sc->pt.n = sc->ee.n = sc->bpt.n = sc->bee.n = 0;
}

/* Fig. 12: phase I, each rank its components of boundary pairs (their
 * particles' state brought from the owners and the new velocities sent
 * back); phase II, every rank its internal pairs. The result is that of
 * one serial Gauss-Seidel order. */
long cs_selfcol_repulse(cs_sim *sim, double *x, double *v, double dt, bool elastic)
{
    cs_selfcol *sc = sim->selfcol;
    cs_par *par = sim->par;
    const cs_self_collision_def *d = &sim->def.self;
    response r = {true, elastic, !elastic, dt, d->thickness, d->stiffness, d->friction,
                  d->edge_flip_epsilon};
    long before = sc->stats.repulsions;
    if (par->size > 1) {
        cs_halo_forward(par, &sc->bhalo, x, 3);
        cs_halo_forward(par, &sc->bhalo, v, 3);
        sc->stats.repulsions += cs_pairs_apply(sc, &sc->bpt, &sc->bee, x, v, &r);
        cs_halo_reverse(par, &sc->bhalo, v, 3);
    }
    sc->stats.repulsions += cs_pairs_apply(sc, &sc->pt, &sc->ee, x, v, &r);
    return sc->stats.repulsions - before;
}
