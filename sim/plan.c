/* plan.c: the plan of stages a scene calls for, and the stages' names. */
#include "sim/sim.h"

static const struct {
    const char *name, *description;
} stage_info[CS_STAGE_COUNT] = {
    [CS_STAGE_REPULSION_PAIRS] = {"repulsion_pairs", "A: repulsion pairs and their history (Section 5)"},
    [CS_STAGE_SCRIPTED_VERTICES] = {"scripted_vertices", "pinned and scripted vertex positions"},
    [CS_STAGE_WIND] = {"wind", "vertex normals and areas for wind drag (Section 8)"},
    [CS_STAGE_VELOCITY_HALF] = {"velocity_half", "B.1 backward Euler half step, conjugate gradient"},
    [CS_STAGE_SELF_REPULSION] = {"self_repulsion", "B.2 inelastic and elastic self-repulsion"},
    [CS_STAGE_POSITION_UPDATE] = {"position_update", "B.3 x = x^n + dt v^(n+1/2)"},
    [CS_STAGE_BODY_COLLISION] = {"body_collision", "B.4 body collisions: crossing point, Gamma (Section 6)"},
    [CS_STAGE_VELOCITY_FULL] = {"velocity_full", "B.5 projected solve (CG) and B.6 extrapolation"},
    [CS_STAGE_BODY_FRICTION] = {"body_friction", "B.7 friction with bodies, Gamma of v_NP (Section 6)"},
    [CS_STAGE_SELF_FRICTION] = {"self_friction", "B.8 inelastic self-repulsion and friction"},
    [CS_STAGE_COLLISIONS] = {"collisions", "C: continuous collisions and impact zones (Section 4)"},
    [CS_STAGE_VERIFY] = {"verify", "count intersecting triangle pairs (independent check)"},
    [CS_STAGE_FRAME_END] = {"frame_end", "the frame to rank 0, counters summed over ranks"},
};

const char *cs_stage_name(cs_stage stage)
{
    return (unsigned)stage < CS_STAGE_COUNT ? stage_info[stage].name : "unknown";
}

const char *cs_stage_description(cs_stage stage)
{
    return (unsigned)stage < CS_STAGE_COUNT ? stage_info[stage].description : "";
}

static bool has_scripts(const cs_sim_def *def)
{
    for (int c = 0; c < def->ncloths; c++)
        if (def->cloths[c].nscripts > 0)
            return true;
    return false;
}

cs_plan cs_plan_from_def(const cs_sim_def *def)
{
    bool self = def->self_collision;
    bool wanted[CS_STAGE_COUNT] = {
        [CS_STAGE_REPULSION_PAIRS] = self,
        [CS_STAGE_SELF_REPULSION] = self,
        [CS_STAGE_SELF_FRICTION] = self,
        [CS_STAGE_COLLISIONS] = self,
        [CS_STAGE_VERIFY] = def->self.verify,
        [CS_STAGE_SCRIPTED_VERTICES] = has_scripts(def),
        [CS_STAGE_WIND] = def->wind_enabled && def->wind.drag > 0,
        [CS_STAGE_VELOCITY_HALF] = true,
        [CS_STAGE_POSITION_UPDATE] = true,
        [CS_STAGE_BODY_COLLISION] = def->bodies_enabled && def->nbodies > 0,
        [CS_STAGE_VELOCITY_FULL] = true,
        [CS_STAGE_BODY_FRICTION] = def->bodies_enabled && def->nbodies > 0,
        [CS_STAGE_FRAME_END] = true,
    };
    cs_plan plan = {0};
    for (int s = 0; s < CS_STAGE_COUNT; s++)
        if (wanted[s])
            plan.stages[plan.nstages++] = (cs_stage)s;
    return plan;
}

bool cs_plan_has(const cs_plan *plan, cs_stage stage)
{
    for (int i = 0; i < plan->nstages; i++)
        if (plan->stages[i] == stage)
            return true;
    return false;
}

/* Peak resident bytes per particle of a run, measured on the sheet-and-ball
 * benchmark (Release, one thread, first frame; the difference between 60 x 60
 * and 120 x 120 quads), with self-collision (BVH, pairs, history, impact
 * zones) and without, plus a margin: contacts and zones grow a run's memory
 * after its first frame. */
static const double BYTES_PER_PARTICLE_SELF = 6000.0, BYTES_PER_PARTICLE = 2500.0;

double cs_sim_estimate_bytes(double particles, bool self_collision)
{
    return particles * (self_collision ? BYTES_PER_PARTICLE_SELF : BYTES_PER_PARTICLE);
}
