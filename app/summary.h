/* summary.h: what a `clothsim run` did, as DIR/summary.json and as the
 * stage table printed at the end (PETSc's -log_view, the paper's Table 2).
 *
 * The run fills the record as it goes and rewrites the JSON after every
 * frame, so the file on disk always describes the frames already written.
 */
#ifndef CS_APP_SUMMARY_H
#define CS_APP_SUMMARY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "sim/sim.h"

/* Ranks listed one by one in summary.json (more are summed in "stages"). */
#define CS_SUMMARY_MAX_RANKS 1024

/* One simulated frame (frame 0, the initial state, has none). */
typedef struct cs_frame_record {
    int frame;
    double time;            /* simulated time at the end of the frame, s */
    cs_frame_stats stats;   /* the simulation's counters for the frame */
    double seconds;         /* wall time cs_sim_advance_frame took */
    double body_penetration; /* deepest free vertex inside a body at the frame's
                                end, m (cs_sim_body_penetration); < 0: no bodies */
} cs_frame_record;

typedef struct cs_summary {
    /* Borrowed strings, alive as long as the summary. */
    const char *scene;
    const char *scene_file;
    int noverrides;                  /* the run's --set overrides, as given, so */
    const char *const *overrides;    /* `clothsim render` can reload the scene */
    const char *version;
    const char *format;              /* "ply", "obj", "glb" */
    const char *output_dir;
    const char *status;              /* "running", "ok", "unstable", "interrupted", "failed" */
    const char *error;               /* why, when not "ok"; NULL otherwise */
    bool self_collision;             /* frames carry the self-collision counters */
    int failed_frame;                /* the frame that went unstable, else -1 */
    int frames_requested;            /* simulated frames asked for */
    int frames_written;              /* files on disk, frame 0 included */
    double fps, dt;
    int steps_per_frame;
    int particles, triangles, springs;
    cs_plan plan;
    cs_stage_timing timing[CS_STAGE_COUNT];
    size_t bytes[CS_STAGE_COUNT];
    cs_comm_stats comm[CS_STAGE_COUNT];   /* messages per stage, all ranks */
    int ranks;
    int threads;                          /* OpenMP threads per rank */
    cs_comm_stats rank_comm[CS_SUMMARY_MAX_RANKS]; /* sent by each rank */
    double total_seconds;            /* wall time of the whole command so far */
    double simulation_seconds;       /* of which in cs_sim_advance_frame */
    double output_seconds;           /* of which writing frame files */
    int nframes, capacity;
    cs_frame_record *frames;
} cs_summary;

/* Zeroes the record; failed_frame = -1, status "running". */
void cs_summary_init(cs_summary *s);
void cs_summary_free(cs_summary *s);

/* Appends a frame record; returns 0, or -1 when memory runs out. */
int cs_summary_add_frame(cs_summary *s, const cs_frame_record *frame);

/* Copies the plan's timing and per-stage bytes from the simulation. */
void cs_summary_take_timing(cs_summary *s, const cs_sim *sim);

/* Writes the JSON to path atomically (path.tmp, then rename). Returns 0, or
 * -1 with a message in err. In "stages", "share" is the stage's fraction
 * (0 to 1) of the time of all stages together. */
int cs_summary_write(const cs_summary *s, const char *path, char *err, size_t errlen);

/* The stage table: per planned stage seconds, share %, calls; then totals. */
void cs_summary_print_table(const cs_summary *s, FILE *out);

#endif
