/* plan.c: the plan of stages a scene calls for, read off the stage table
 * (stages.c) without creating anything, and what such a run will cost. */
#include "sim/stages.h"

cs_plan cs_plan_from_def(const cs_sim_def *def)
{
    cs_plan plan = {0};
    const cs_stage_row *rows = cs_stage_rows();
    for (int i = 0; i < CS_STAGE_COUNT; i++)
        if (cs_stage_need_met(rows[i].need, def))
            plan.stages[plan.nstages++] = rows[i].stage;
    return plan;
}

/* Peak resident bytes per particle of a run, measured on the sheet-and-ball
 * benchmark (Release, one thread, first frame; the difference between 60 x 60
 * and 120 x 120 quads), with self-collision (BVH, pairs, history, impact
 * zones) and without, plus a margin: contacts and zones grow a run's memory
 * after its first frame. */
static const double BYTES_PER_PARTICLE_SELF = 6000.0, BYTES_PER_PARTICLE = 2500.0;
/* The same with the cloth in self-contact: the benchmark's peak over its
 * first 12 frames (the sheet lands on the ball and folds onto itself, 2
 * threads) less its --plan's, per particle: 12.9 kB at 100 x 100 and 12.0
 * kB at 200 x 200 quads (docs/performance.md), with a margin. */
static const double BYTES_PER_PARTICLE_SELF_CONTACT = 13500.0;

double cs_sim_estimate_bytes(double particles, bool self_collision, bool in_contact)
{
    if (!self_collision)
        return particles * BYTES_PER_PARTICLE;
    return particles * (in_contact ? BYTES_PER_PARTICLE_SELF_CONTACT : BYTES_PER_PARTICLE_SELF);
}
