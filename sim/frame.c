/* frame.c: the rows of the stage table (stages.c) that run once per outer
 * collision step (A, C of Section 4) or once per frame; the outer step and
 * the frame around them are stages.c's. */
#include <math.h>
#include <string.h>

#include "sim/stages.h"
#include "sim/vec3.h"

/* A: the repulsion pairs for the coming k time steps */
const double *cs_stage_repulsion_pairs(cs_sim *sim, cs_stage_ctx *ctx)
{
    cs_selfcol_find_pairs(sim, ctx->k * sim->dt);
    return NULL;
}

/* C: collisions since the outer step's start. A probe only counts them
 * (the rewind scheme); otherwise a script conflict fails the step, and the
 * velocities C changed are checked. */
const double *cs_stage_collisions(cs_sim *sim, cs_stage_ctx *ctx)
{
    long found = cs_selfcol_collide(sim, sim->t - ctx->t0, ctx->k, ctx->probe);
    if (ctx->probe) {
        ctx->found = found;
        return NULL;
    }
    if (sim->selfcol->conflict.found) { /* the same on every rank */
        ctx->status = CS_ERR_SCRIPT;
        return NULL;
    }
    return sim->v;
}

/* The frame's end: rank 0 gets the whole state (frames are written once),
 * and the counters each rank kept for its own particles and pairs are
 * summed. */
const double *cs_stage_frame_end(cs_sim *sim, cs_stage_ctx *ctx)
{
    cs_frame_tally *tally = ctx->tally;
    cs_par_gather_root(sim->par, sim->x, 3);
    cs_par_gather_root(sim->par, sim->v, 3);
    if (sim->selfcol)
        tally->self = sim->selfcol->stats;
    const cs_selfcol_stats *s0 = &tally->self0, *s1 = &tally->self;
    long sums[4] = {sim->contacts - tally->contacts0, s1->repulsion_pairs - s0->repulsion_pairs,
                    s1->repulsions - s0->repulsions, s1->collisions - s0->collisions};
    cs_par_sum_long(sim->par, sums, 4);
    memcpy(tally->sums, sums, sizeof sums);
    double max_speed = 0;
    CS_FOR_OWNED(sim->par, i)
        max_speed = fmax(max_speed, cs_norm(sim->v + 3 * i));
    cs_par_max(sim->par, &max_speed, 1);
    tally->max_speed = max_speed;
    return NULL;
}

/* The verifier's count of intersecting triangle pairs, on rank 0 (which
 * holds the whole frame now) */
const double *cs_stage_verify(cs_sim *sim, cs_stage_ctx *ctx)
{
    if (sim->par->rank == 0)
        ctx->tally->intersections = cs_sim_count_intersections(sim);
    return NULL;
}
