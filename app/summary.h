/* summary.h: what a `clothsim run` did, as DIR/summary.json, DIR/frames.jsonl
 * and the stage table printed at the end (PETSc's -log_view, the paper's
 * Table 2).
 *
 * The cost per frame is constant however long the run: each frame appends
 * one line (its record) to frames.jsonl, and summary.json is rewritten
 * without the frame records (a size that does not grow with the frames), at
 * most once a second. At the end of the run summary.json is written once
 * more, whole, with "frames" read back from frames.jsonl. So the files on
 * disk always describe frames already written, and a run killed outright
 * leaves its records behind.
 */
#ifndef CS_APP_SUMMARY_H
#define CS_APP_SUMMARY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "import/import.h"
#include "sim/sim.h"

/* Ranks listed one by one in summary.json (more are summed in "stages"). */
#define CS_SUMMARY_MAX_RANKS 1024

/* A frame's state hash (cs_state_hash in checkpoint.h): 32 lowercase hex
 * digits and a terminator. */
#define CS_STATE_HASH_LEN 33
#define CS_STATE_HASH_ALGORITHM                                                        \
    "XXH3-128 (xxHash) of the positions then the velocities as stored: 3 doubles per " \
    "particle each, in particle order, IEEE 754 in the machine's byte order; canonical hex"

/* One simulated frame (frame 0, the initial state, has none). */
typedef struct cs_frame_record {
    int frame;
    double time;            /* simulated time at the end of the frame, s */
    cs_frame_stats stats;   /* the simulation's counters for the frame */
    double seconds;         /* wall time cs_sim_advance_frame took */
    double body_penetration; /* deepest point of the cloth surface inside a body
                                at the frame's end, m (cs_sim_body_penetration);
                                < 0: no bodies */
    char state_hash[CS_STATE_HASH_LEN]; /* positions and velocities at the end */
    const char *resampled_from; /* not simulated: another run's frame carried onto
                                   this cloth (run --start-from), that run's folder */
} cs_frame_record;

/* Totals a resumed run carries on from (cs_summary_totals): per stage
 * seconds, calls, communication seconds, bytes and messages, then the
 * total, simulation and output seconds. */
#define CS_SUMMARY_TOTALS (5 * CS_STAGE_COUNT + 3)

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
    bool scripts;                    /* frames carry script_lag */
    const char *script_zones;        /* self_collision.script_zones, with scripts */
    const char *step_limit;          /* the limit the automatic step used, auto resolved;
                                      * NULL with a fixed time.dt */
    double script_lag_max;           /* s, the most any script fell behind its keys */
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
    double output_seconds;           /* of which writing frame files and state.h5 */
    double base_seconds;             /* wall time of the runs this one resumed */
    cs_stage_timing base_timing[CS_STAGE_COUNT];
    cs_comm_stats base_comm[CS_STAGE_COUNT];
    char initial_hash[CS_STATE_HASH_LEN]; /* frame 0's state */
    int resumed_from;                /* the frame this command resumed from, else -1 */
    int nframes;                     /* records in frames.jsonl (frames 1..nframes) */
    int carried_frames;              /* of which carried from another run, not
                                        simulated (run --start-from) */
    int run_frames;                  /* of which simulated by this command, */
    long run_steps;                  /* in this many steps */
    /* frames.jsonl: open for appending, and its length after the last
     * whole record */
    const char *records_path;
    FILE *records;
    long records_size;
} cs_summary;

/* Zeroes the record; failed_frame = -1, resumed_from = -1, status "running". */
void cs_summary_init(cs_summary *s);
/* Closes frames.jsonl. */
void cs_summary_free(cs_summary *s);

/* Opens path (frames.jsonl) for the run's records, keeping those of frames
 * 1 to keep (0: none, a new run; K: resuming after frame K, when frames
 * 1..K must all be there, later ones are dropped). Returns 0, or -1 with a
 * message in err naming the file and what is wrong. */
int cs_summary_open_records(cs_summary *s, const char *path, int keep, char *err,
                            size_t errlen);

/* Appends a frame's record to frames.jsonl (one line, flushed). On failure
 * the file is cut back to its last whole record; returns -1 with err. */
int cs_summary_add_frame(cs_summary *s, const cs_frame_record *frame, char *err, size_t errlen);

/* Copies the plan's timing and per-stage bytes from the simulation (added
 * to the totals of the runs this one resumed). */
void cs_summary_take_timing(cs_summary *s, const cs_sim *sim);

/* The totals to carry on from (CS_SUMMARY_TOTALS doubles), and taking them
 * back when resuming. */
void cs_summary_totals(const cs_summary *s, double *out);
void cs_summary_set_base(cs_summary *s, const double *totals);

/* Writes summary.json to path atomically (path.tmp, checked, renamed):
 * while running without "frames" (constant size), and with final, whole,
 * "frames" read back from frames.jsonl. Returns 0, or -1 with a message in
 * err. In "stages", "share" is the stage's fraction (0 to 1) of the time of
 * all stages together. */
int cs_summary_write(const cs_summary *s, const char *path, bool final, char *err,
                     size_t errlen);

/* The stage table: per planned stage seconds, share %, calls; then totals. */
void cs_summary_print_table(const cs_summary *s, FILE *out);

#endif
