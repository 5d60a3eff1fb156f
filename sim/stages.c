/* stages.c: the stage table. Every stage of a time step, of an outer
 * collision step and of a frame is one row, in the order they run, with
 * what enables it and the function that runs it; the plan (plan.c),
 * `clothsim run --plan` and the summary's stage table all read this order,
 * and one loop runs it (cs_stages_run). Adding a stage is a row here and its function. */
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
