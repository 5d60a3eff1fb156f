/* selfcol_pairs.c: lists of pairs and where they go: growing a list,
 * union-find over particles (impact zones, components of boundary pairs),
 * and Section 7's ranks: the rank a pair belongs to, the trees' ranks, and
 * the boundary pairs shared among the ranks (Fig. 12). */
#include <stdlib.h>
#include <string.h>

#include "sim/selfcol_private.h"

/* ------------------------------------------- pair lists and union-find */

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
