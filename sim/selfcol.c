/* selfcol.c: the self-collision state of Sections 4 and 5, created from
 * the simulation and freed: the cloths' edges and each particle's ring of
 * neighbours, the boxes and trees over points, edges and triangles, and
 * the collision-free positions. Step A and B.2 and B.8 are in
 * selfcol_repulsion.c, one pair's response in selfcol_response.c, pair
 * lists and their ranks in selfcol_pairs.c, step C in selfcol_collide.c. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sim/selfcol_private.h"
#include "sim/vec3.h"

/* Step C's proximity tolerance: a pair that comes this close at a coplanar
 * time counts as colliding; tiny against both the thickness and the edges
 * (a round-off guard for the coplanar test, not a physical distance) */
static const double PROXIMITY_PER_THICKNESS = 1e-3, PROXIMITY_PER_EDGE = 1e-4;

void cs_selfcol_release(cs_selfcol *sc, int i, double mass) { sc->inv_mass[i] = 1.0 / mass; }

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
    cs_motion_boxes *motion[3] = {&sc->pmotion, &sc->emotion, &sc->tmotion};
    int motion_count[3] = {n, ne, nt};
    for (int k = 0; k < 3; k++) {
        motion[k]->x = malloc(sizeof(cs_box) * ((size_t)motion_count[k] + 1));
        motion[k]->v = malloc(sizeof(cs_box) * ((size_t)motion_count[k] + 1));
        if (!motion[k]->x || !motion[k]->v)
            goto fail;
    }
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
    void *arrays[] = {sc->edge, sc->tri, sc->ring_start, sc->ring, sc->pbox, sc->ebox, sc->tbox,
                      sc->pmotion.x, sc->pmotion.v, sc->emotion.x, sc->emotion.v,
                      sc->tmotion.x, sc->tmotion.v, sc->reach_pt.ab, sc->reach_ee.ab, sc->pdirty, sc->collided, sc->edirty,
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
