/* frame.c: the outer collision loop of Section 4 around the time step, a
 * frame of outer steps, and the rows of the stage table (stages.c) that
 * run once per outer step (A, C) or once per frame. */
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

/* One outer collision step of k time steps (Section 4): step A, k steps of
 * B, step C. The rewind scheme (Bridson et al. 2002) first runs the k steps
 * and, if step C would find a collision, goes back and tries again with k
 * halved, until k = 1. Returns CS_OK, CS_ERR_UNSTABLE or CS_ERR_SCRIPT. */
static int outer_step(cs_sim *sim, int k)
{
    cs_selfcol *sc = sim->selfcol;
    if (!sc) {
        for (int i = 0; i < k; i++)
            if (cs_sim_step(sim, sim->dt) != CS_OK)
                return CS_ERR_UNSTABLE;
        return CS_OK;
    }
    bool rewind = sim->def.self.scheme == CS_COLLISION_REWIND;
    size_t bytes = sizeof(double) * 3 * (size_t)sim->n;
    cs_stage_ctx ctx = {.status = CS_OK, .t0 = sim->t, .k = k};
    if (rewind) /* keep the start to come back to; x equals x_free here */
        memcpy(sim->v_rewind, sim->v, bytes);
    if (sim->nscripts > 0) /* where a hold in step C sets the scripts' clocks back to */
        memcpy(sim->script_lag_start, sim->script_lag, sizeof(double) * (size_t)sim->nscripts);
    cs_stages_run(sim, CS_PHASE_OUTER_START, &ctx);
    for (int i = 0; i < k; i++)
        if (cs_sim_step(sim, sim->dt) != CS_OK)
            return CS_ERR_UNSTABLE;
    if (rewind && k > 1) {
        ctx.probe = true;
        cs_stages_run(sim, CS_PHASE_OUTER_END, &ctx);
        ctx.probe = false;
        if (ctx.found > 0) {
            memcpy(sim->x, sc->x_free, bytes);
            memcpy(sim->v, sim->v_rewind, bytes);
            if (sim->nscripts > 0)
                memcpy(sim->script_lag, sim->script_lag_start,
                       sizeof(double) * (size_t)sim->nscripts);
            sim->t = ctx.t0;
            sc->stats.rewinds++;
            /* the halves run one after another, each from its own start */
            int first = k / 2, status = outer_step(sim, first);
            if (status != CS_OK)
                return status;
            return outer_step(sim, k - first);
        }
    }
    if (cs_stages_run(sim, CS_PHASE_OUTER_END, &ctx) != CS_OK)
        return ctx.status;
    return cs_runaway_end_step(sim, cs_runaway_not_finite(sim, NULL)) ? CS_OK : CS_ERR_UNSTABLE;
}

static bool adaptive_step(const cs_sim *sim)
{
    return !(sim->def.dt > 0) && sim->step_limit == CS_STEP_DAMPED;
}

/* The step for the rest of a frame: the frame's remaining time in equal
 * steps no longer than dt_safety times the stability limit at the current
 * positions (or the scene's fixed step). Returns the number of steps. */
static long steps_for(cs_sim *sim, double remaining)
{
    if (!adaptive_step(sim)) /* fixed: the step set at creation */
        return lround(remaining / sim->dt);
    double dt_max = sim->def.dt_safety * cs_step_limit_now(sim);
    double steps = ceil(remaining / fmin(dt_max, remaining) - 1e-9);
    if (!(steps >= 1))
        steps = 1;
    if (steps > CS_MAX_STEPS_PER_FRAME)
        steps = CS_MAX_STEPS_PER_FRAME;
    sim->dt = remaining / steps;
    return (long)steps;
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

int cs_sim_advance_frame(cs_sim *sim, cs_frame_stats *stats)
{
    double frame = 1.0 / sim->def.fps;
    double t_end = sim->t + frame;
    sim->frame_end = t_end;
    long steps = 0;
    long cg0 = sim->cg_iterations;
    cs_frame_tally tally = {.contacts0 = sim->contacts, .intersections = -1};
    if (sim->selfcol) {
        sim->selfcol->stats.max_zone = 0; /* the largest zone of this frame */
        tally.self0 = sim->selfcol->stats;
    }
    int status = CS_OK;
    /* The outer collision loop: k_i time steps, then step C. Chunks never
     * straddle a frame end, so every frame ends collision-free. The step is
     * chosen afresh before each chunk, from the tension the cloth has then
     * (step_limit.c); the steps left divide the frame's remaining time. */
    bool adaptive = adaptive_step(sim);
    /* the last step lands on t_end (cs_sim_step), free of the steps'
     * round-off */
    long left = steps_for(sim, frame);
    while (left > 0 && status == CS_OK) {
        long chunk = left < sim->def.collision_steps ? left : sim->def.collision_steps;
        status = outer_step(sim, (int)chunk);
        steps += chunk;
        left -= chunk;
        if (left > 0 && adaptive && status == CS_OK)
            left = steps_for(sim, t_end - sim->t);
    }
    cs_stage_ctx ctx = {.status = status, .tally = &tally};
    cs_stages_run(sim, CS_PHASE_FRAME_END, &ctx);
    cs_par_report(sim->par, sim->timing, sim->timing_all, sim->comm_all, sim->rank_comm);
    if (stats) {
        const cs_selfcol_stats *self = &tally.self, *self0 = &tally.self0;
        memset(stats, 0, sizeof *stats);
        stats->steps = (int)steps;
        stats->dt = frame / (double)steps; /* the mean step */
        stats->cg_iterations = sim->cg_iterations - cg0;
        stats->body_contacts = tally.sums[0];
        stats->max_speed = tally.max_speed;
        if (sim->selfcol) { /* passes, zones and rewinds are the same on every rank */
            stats->repulsion_pairs = tally.sums[1];
            stats->repulsions = tally.sums[2];
            stats->collisions = tally.sums[3];
            stats->collision_passes = self->passes - self0->passes;
            stats->impact_zones = self->zones - self0->zones;
            stats->max_zone_size = self->max_zone;
            stats->held_zones = self->held_zones - self0->held_zones;
            stats->projected_zones = self->projected_zones - self0->projected_zones;
            stats->rewinds = self->rewinds - self0->rewinds;
            stats->pair_searches = self->cache_searches - self0->cache_searches;
            stats->pair_traversals = self->cache_builds - self0->cache_builds;
        }
        stats->intersections = tally.intersections;
        for (int sc = 0; sc < sim->nscripts; sc++)
            if (!sim->scripts[sc].released)
                stats->script_lag = fmax(stats->script_lag, sim->script_lag[sc]);
    }
    return status;
}
