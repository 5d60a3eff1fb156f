/* outdir.h: the folder a `clothsim run` writes, DIR:
 *   DIR/frames/frame_NNNN.EXT   a mesh per frame, frame 0 the initial state
 *   DIR/frames.jsonl            a record per simulated frame, one JSON a line
 *   DIR/summary.json            the run as a whole (summary.h)
 *   DIR/state.h5                what --resume continues from (checkpoint.h)
 *   DIR/.lock                   held while a run writes (lock.h)
 * A new run takes the folder over: frames, records and state of an earlier
 * run there are removed. --resume continues the earlier run instead. */
#ifndef CS_APP_OUTDIR_H
#define CS_APP_OUTDIR_H

#include <stdbool.h>
#include <stddef.h>

#include "app/checkpoint.h"
#include "app/lock.h"
#include "app/summary.h"
#include "import/import.h"

typedef struct cs_outdir {
    char *dir, *frames_dir, *summary_path, *records_path, *state_path;
    cs_dir_lock lock;
    double synced;  /* when cs_outdir_sync last reached the disk (monotonic s) */
} cs_outdir;

/* Seconds between syncs of the folder to the disk during a run. */
#define CS_OUTDIR_SYNC_SECONDS 10.0

/* The paths of dir, or when dir is NULL of out/<scene name> (made safe for
 * a path); returns 0, or -1 when memory runs out. */
int cs_outdir_init(cs_outdir *o, const char *dir, const char *scene_name);
/* Frees the paths and releases the lock. */
void cs_outdir_free(cs_outdir *o);

/* Rank 0, before the run writes: makes the folders and takes the lock;
 * then a new run removes an earlier run's frames, records and state and
 * opens its records, while --resume (resume) reads DIR/state.h5 into sim
 * (cs_checkpoint_read: refused unless made from id), keeps frames 0..K and
 * their records (later ones, from after the last state written, are made
 * again) and carries the summary on; *first_frame: K (0 for a new run).
 * frames: the frames asked for now. Says what is wrong, or that it resumes
 * (unless quiet), on stderr. Returns an exit status. */
int cs_outdir_start(cs_outdir *o, bool resume, bool quiet, const cs_run_identity *id,
                    cs_sim *sim, cs_summary *s, cs_mesh_format format, int frames,
                    int *first_frame);

/* Rank 0, after frame (after cs_sim_state_gather): DIR/state.h5 for it,
 * with the summary's totals. Returns 0, or -1 with err. */
int cs_outdir_save_state(cs_outdir *o, const cs_run_identity *id, int frame,
                         const char *state_hash, cs_sim *sim, const cs_summary *s, char *err,
                         size_t errlen);

/* Rank 0: everything written so far reaches the disk (cs_dir_sync), when
 * now or CS_OUTDIR_SYNC_SECONDS have passed since the last time: a power
 * cut loses at most that much, at a cost that does not grow with the frame
 * rate. Returns 0, or -1 with err. */
int cs_outdir_sync(cs_outdir *o, bool now, char *err, size_t errlen);

#endif
