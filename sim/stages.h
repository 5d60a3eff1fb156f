/* stages.h: the rows of the stage table (stages.c) and what they run
 * with, private to sim/. A row's work lives with its kind: a time step's
 * stages in step.c, the outer step's and the frame's in frame.c; the
 * loops that run a step, an outer step and a frame are stages.c's. */
#ifndef CS_STAGES_H
#define CS_STAGES_H

#include "sim/internal.h"

/* When a row runs. The rows of one phase run together, in table order. */
typedef enum cs_stage_phase {
    CS_PHASE_OUTER_START = 0, /* once per outer collision step, before its time steps */
    CS_PHASE_STEP,            /* every time step */
    CS_PHASE_OUTER_END,       /* once per outer step, after its time steps */
    CS_PHASE_FRAME_END,       /* once per frame */
} cs_stage_phase;

/* What a scene must have for a row to be in its plan. */
typedef enum cs_stage_need {
    CS_NEED_ALWAYS = 0,
    CS_NEED_SELF_COLLISION,
    CS_NEED_VERIFY,
    CS_NEED_SCRIPTS,
    CS_NEED_WIND,
    CS_NEED_BODIES,
} cs_stage_need;

/* A frame's counters: taken at its start, summed over ranks at its end. */
typedef struct cs_frame_tally {
    long contacts0;
    cs_selfcol_stats self0, self; /* zero without self-collision */
    long sums[4];                 /* contacts, repulsion pairs, repulsions, collisions */
    double max_speed;
    long intersections;           /* the verifier's count; -1 when not run */
} cs_frame_tally;

/* What the rows of one phase read and write. */
typedef struct cs_stage_ctx {
    int status;     /* CS_OK until a row fails; then the phase stops */
    /* a time step of dt ending at t1; bodies: the plan has B.4 and B.7 */
    double dt, t1;
    bool bodies;
    /* an outer step of k time steps that began at t0; probe: the rewind
     * scheme asks step C only whether it would find a collision (found) */
    double t0;
    int k;
    bool probe;
    long found;
    cs_frame_tally *tally; /* the frame's end */
} cs_stage_ctx;

/* A row's work: returns the velocity it made, for the runaway check, or
 * NULL where it changed none or checked its own; a failure goes into
 * ctx->status. */
typedef const double *(*cs_stage_fn)(cs_sim *sim, cs_stage_ctx *ctx);

typedef struct cs_stage_row {
    cs_stage stage;
    const char *name, *description;
    cs_stage_need need;
    cs_stage_phase phase;
    bool after_failure; /* runs even when an earlier part of the frame failed */
    cs_stage_fn run;
} cs_stage_row;

/* The table, CS_STAGE_COUNT rows in the order they run. */
const cs_stage_row *cs_stage_rows(void);
bool cs_stage_need_met(cs_stage_need need, const cs_sim_def *def);

/* plan.c: what the scene definition calls for, without creating anything:
 * its stages in the order they run. */
cs_plan cs_plan_from_def(const cs_sim_def *def);

/* Runs the planned rows of a phase in order, each timed, counted and its
 * velocity checked in this one place; stops at the first failure (but for
 * rows that run after one). Returns ctx->status. */
int cs_stages_run(cs_sim *sim, cs_stage_phase phase, cs_stage_ctx *ctx);

/* step.c: a time step's rows (B with the scripted vertices and wind) */
const double *cs_stage_scripted_vertices(cs_sim *sim, cs_stage_ctx *ctx);
const double *cs_stage_wind(cs_sim *sim, cs_stage_ctx *ctx);
const double *cs_stage_velocity_half(cs_sim *sim, cs_stage_ctx *ctx);
const double *cs_stage_self_repulsion(cs_sim *sim, cs_stage_ctx *ctx);
const double *cs_stage_position_update(cs_sim *sim, cs_stage_ctx *ctx);
const double *cs_stage_body_collision(cs_sim *sim, cs_stage_ctx *ctx);
const double *cs_stage_velocity_full(cs_sim *sim, cs_stage_ctx *ctx);
const double *cs_stage_body_friction(cs_sim *sim, cs_stage_ctx *ctx);
const double *cs_stage_self_friction(cs_sim *sim, cs_stage_ctx *ctx);

/* frame.c: the outer step's rows (A, C) and the frame's */
const double *cs_stage_repulsion_pairs(cs_sim *sim, cs_stage_ctx *ctx);
const double *cs_stage_collisions(cs_sim *sim, cs_stage_ctx *ctx);
const double *cs_stage_frame_end(cs_sim *sim, cs_stage_ctx *ctx);
const double *cs_stage_verify(cs_sim *sim, cs_stage_ctx *ctx);

#endif
