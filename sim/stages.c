/* stages.c: the stage table. Every stage of a time step, of an outer
 * collision step and of a frame is one row, in the order they run, with
 * what enables it and the function that runs it; the plan (plan.c),
 * `clothsim run --plan` and the summary's stage table all read this order,
 * and one loop runs it (cs_stages_run). Adding a stage is a row here and its function.
 * The drivers that run the phases in order (cs_sim_step, the outer
 * collision step, cs_sim_advance_frame) are here too, so that the rows'
 * work (step.c, frame.c) calls nothing above it. */
#include <math.h>
#include <string.h>

#include "common/util.h"
#include "sim/stages.h"

static const cs_stage_row STAGE_ROWS[CS_STAGE_COUNT] = {
    {CS_STAGE_REPULSION_PAIRS, "repulsion_pairs",
     "A: repulsion pairs and their history (Section 5)", CS_NEED_SELF_COLLISION,
     CS_PHASE_OUTER_START, false, cs_stage_repulsion_pairs},
    {CS_STAGE_SCRIPTED_VERTICES, "scripted_vertices", "pinned and scripted vertex positions",
     CS_NEED_SCRIPTS, CS_PHASE_STEP, false, cs_stage_scripted_vertices},
    {CS_STAGE_WIND, "wind", "vertex normals and areas for wind drag (Section 8)", CS_NEED_WIND,
     CS_PHASE_STEP, false, cs_stage_wind},
    {CS_STAGE_VELOCITY_HALF, "velocity_half", "B.1 backward Euler half step, conjugate gradient",
     CS_NEED_ALWAYS, CS_PHASE_STEP, false, cs_stage_velocity_half},
    {CS_STAGE_SELF_REPULSION, "self_repulsion", "B.2 inelastic and elastic self-repulsion",
     CS_NEED_SELF_COLLISION, CS_PHASE_STEP, false, cs_stage_self_repulsion},
    {CS_STAGE_POSITION_UPDATE, "position_update", "B.3 x = x^n + dt v^(n+1/2)", CS_NEED_ALWAYS,
     CS_PHASE_STEP, false, cs_stage_position_update},
    {CS_STAGE_BODY_COLLISION, "body_collision",
     "B.4 body collisions: crossing point, Gamma (Section 6)", CS_NEED_BODIES, CS_PHASE_STEP,
     false, cs_stage_body_collision},
    {CS_STAGE_VELOCITY_FULL, "velocity_full", "B.5 projected solve (CG) and B.6 extrapolation",
     CS_NEED_ALWAYS, CS_PHASE_STEP, false, cs_stage_velocity_full},
    {CS_STAGE_BODY_FRICTION, "body_friction",
     "B.7 friction with bodies, Gamma of v_NP (Section 6)", CS_NEED_BODIES, CS_PHASE_STEP, false,
     cs_stage_body_friction},
    {CS_STAGE_SELF_FRICTION, "self_friction", "B.8 inelastic self-repulsion and friction",
     CS_NEED_SELF_COLLISION, CS_PHASE_STEP, false, cs_stage_self_friction},
    {CS_STAGE_COLLISIONS, "collisions", "C: continuous collisions and impact zones (Section 4)",
     CS_NEED_SELF_COLLISION, CS_PHASE_OUTER_END, false, cs_stage_collisions},
    /* the frame reaches rank 0 even after a failure: what the run keeps */
    {CS_STAGE_FRAME_END, "frame_end", "the frame to rank 0, counters summed over ranks",
     CS_NEED_ALWAYS, CS_PHASE_FRAME_END, true, cs_stage_frame_end},
    {CS_STAGE_VERIFY, "verify", "count intersecting triangle pairs (independent check)",
     CS_NEED_VERIFY, CS_PHASE_FRAME_END, false, cs_stage_verify},
};

static const char *const NEED_TEXT[] = {
    [CS_NEED_ALWAYS] = "always",
    [CS_NEED_SELF_COLLISION] = "effects.self_collision",
    [CS_NEED_VERIFY] = "self_collision.verify",
    [CS_NEED_SCRIPTS] = "pinned or scripted vertices",
    [CS_NEED_WIND] = "effects.wind with wind.drag > 0",
    [CS_NEED_BODIES] = "effects.bodies with a body",
};

static const char *const PHASE_TEXT[] = {
    [CS_PHASE_OUTER_START] = "each outer collision step, before its time steps",
    [CS_PHASE_STEP] = "each time step (time.collision_steps per outer step)",
    [CS_PHASE_OUTER_END] = "each outer collision step, after its time steps",
    [CS_PHASE_FRAME_END] = "each frame's end",
};

const cs_stage_row *cs_stage_rows(void) { return STAGE_ROWS; }

static const cs_stage_row *row_of(cs_stage stage)
{
    for (int i = 0; i < CS_STAGE_COUNT; i++)
        if (STAGE_ROWS[i].stage == stage)
            return STAGE_ROWS + i;
    return NULL;
}

cs_stage cs_stage_in_order(int i)
{
    return i >= 0 && i < CS_STAGE_COUNT ? STAGE_ROWS[i].stage : CS_STAGE_COUNT;
}

const char *cs_stage_name(cs_stage stage)
{
    const cs_stage_row *row = row_of(stage);
    return row ? row->name : "unknown";
}

const char *cs_stage_description(cs_stage stage)
{
    const cs_stage_row *row = row_of(stage);
    return row ? row->description : "";
}

const char *cs_stage_condition(cs_stage stage)
{
    const cs_stage_row *row = row_of(stage);
    return row ? NEED_TEXT[row->need] : "";
}

const char *cs_stage_when(cs_stage stage)
{
    const cs_stage_row *row = row_of(stage);
    return row ? PHASE_TEXT[row->phase] : "";
}

static bool has_scripts(const cs_sim_def *def)
{
    for (int c = 0; c < def->ncloths; c++)
        if (def->cloths[c].nscripts > 0)
            return true;
    return false;
}

bool cs_stage_need_met(cs_stage_need need, const cs_sim_def *def)
{
    switch (need) {
    case CS_NEED_ALWAYS: return true;
    case CS_NEED_SELF_COLLISION: return def->self_collision;
    case CS_NEED_VERIFY: return def->self.verify;
    case CS_NEED_SCRIPTS: return has_scripts(def);
    case CS_NEED_WIND: return def->wind_enabled && def->wind.drag > 0;
    case CS_NEED_BODIES: return def->bodies_enabled && def->nbodies > 0;
    }
    return false;
}

int cs_stages_run(cs_sim *sim, cs_stage_phase phase, cs_stage_ctx *ctx)
{
    for (int i = 0; i < CS_STAGE_COUNT; i++) {
        const cs_stage_row *row = STAGE_ROWS + i;
        if (row->phase != phase || !cs_plan_has(&sim->plan, row->stage))
            continue;
        if (ctx->status != CS_OK && !row->after_failure)
            continue;
        double t0 = cs_now();
        cs_par_begin(sim->par, row->stage); /* its messages are charged to it */
        const double *v = row->run(sim, ctx);
        if (v)
            cs_runaway_check(sim, v, row->stage);
        sim->timing[row->stage].seconds += cs_now() - t0;
        sim->timing[row->stage].calls++;
    }
    return ctx->status;
}

/* ------------------------------------------------------- the drivers
 *
 * A time step, an outer collision step and a frame: each runs its phases
 * of the table in order, with what lies between them (the rewind, the
 * choice of step). */

/* True on every rank when every owned particle is finite everywhere. */
int cs_sim_step(cs_sim *sim, double dt)
{
    cs_par *par = sim->par;
    cs_stage_ctx st = {.status = CS_OK, .dt = dt, .t1 = sim->t + dt,
                       .bodies = cs_plan_has(&sim->plan, CS_STAGE_BODY_COLLISION)};
    if (fabs(st.t1 - sim->frame_end) <= 1e-9 * dt)
        st.t1 = sim->frame_end; /* the frame's last step lands on its end */
    sim->half_dt = 0.5 * dt;
    /* x (owned and ghosts) is current here; v only where owned. One pass
     * keeps x^n and resets the modes (the ghosts' are never read). */
    cs_scripts_release(sim, dt);
    CS_PARALLEL_FOR_LOCAL(par, i) {
        memcpy(sim->x_prev + 3 * i, sim->x + 3 * i, 3 * sizeof(double));
        sim->mode[i] = sim->is_free[i] ? CS_FREE : CS_FIXED;
    }
    cs_runaway_begin_step(sim, st.t1);
    cs_stages_run(sim, CS_PHASE_STEP, &st);
    int not_finite = cs_runaway_not_finite(sim, sim->v_next); /* v^(n+1) taken too */
    sim->t = st.t1;
    return cs_runaway_end_step(sim, not_finite) ? CS_OK : CS_ERR_UNSTABLE;
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
 * positions and the moving scripts' cap (or the scene's fixed step).
 * Returns the number of steps. */
static long steps_for(cs_sim *sim, double remaining)
{
    if (!adaptive_step(sim)) /* fixed: the step set at creation */
        return lround(remaining / sim->dt);
    /* a cap at the undamped step needs no damped limit, which is never
     * below it (the 32 x 16 twist: the bound's passes before each outer
     * step made it 14% slower for the same steps) */
    double floor_dt = sim->def.dt_safety * sim->undamped_dt;
    double dt_max = cs_step_limit_scripts(sim, sim->t, sim->t + remaining);
    if (dt_max > floor_dt)
        dt_max = fmin(dt_max, sim->def.dt_safety * cs_step_limit_now(sim));
    double steps = ceil(remaining / fmin(dt_max, remaining) - 1e-9);
    if (!(steps >= 1))
        steps = 1;
    if (steps > CS_MAX_STEPS_PER_FRAME)
        steps = CS_MAX_STEPS_PER_FRAME;
    sim->dt = remaining / steps;
    return (long)steps;
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
