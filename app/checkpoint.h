/* checkpoint.h: DIR/state.h5, what `clothsim run --resume` continues from,
 * and the hash of a frame's state.
 *
 * After every frame rank 0 writes the simulation's state arrays
 * (cs_sim_state_arrays, gathered to it: one file whatever the rank count)
 * with what the run came from, in HDF5 so that h5dump, h5py or any HDF5
 * reader can open it:
 *   /state/time, /state/positions (n x 3), /state/velocities (n x 3),
 *   /state/cg/warm_half, /state/cg/warm_full_less_half,
 *   /state/cg/warm_half_before, /state/cg/warm_full_less_half_before, /state/self_collision/x_free
 *   /scene/text        the scene file's bytes when the run began
 *   /scene/resolved    the resolved scene without time.frames (what a run
 *                      from DIR/scene.yaml compares)
 *   /scene/overrides   its --set overrides, as given
 *   /run/totals        stage times and counts to carry the summary on
 *   attributes of /: format "clothsim state", format_version, frame,
 *   time, particles, ranks, threads, mesh_format, clothsim_version,
 *   scene_file, definition_hash, state_hash.
 * HDF5 builds the file in memory; its bytes are written as state.h5.tmp,
 * every write checked, fsync'd and renamed, so state.h5 is always a whole
 * checkpoint of some frame. */
#ifndef CS_APP_CHECKPOINT_H
#define CS_APP_CHECKPOINT_H

#include <stdbool.h>
#include <stddef.h>

#include "app/summary.h"
#include "import/import.h"
#include "sim/sim.h"

/* What a run is made from; a resumed run must be made from the same. */
typedef struct cs_run_identity {
    const char *scene_file;          /* as loaded */
    char *scene_text;                /* its bytes (owned) */
    size_t scene_len;
    int noverrides;                  /* --set, as given; time.frames ones may */
    const char *const *overrides;    /* differ when resuming */
    const char *format;              /* "ply", "obj", "glb" */
    const char *resolved;            /* cs_scene.resolved_setup (the scene's) */
    size_t resolved_len;
    bool own_scene;                  /* scene_file is the run folder's scene.yaml */
    int particles;
    /* XXH3-128 of the particle count, the step, and the initial positions,
     * velocities and masses: what the scene's text does not show (mesh
     * files it reads, the code's defaults) */
    char definition_hash[CS_STATE_HASH_LEN];
} cs_run_identity;

/* Reads the scene file and hashes the definition of sim (just created
 * from scene): what the scene's text does not hold, the contents of the
 * mesh files it names (cloths through the initial positions, bodies through
 * their meshes as imported). Returns 0, or -1 with err. */
int cs_run_identity_init(cs_run_identity *id, const char *scene_file, int noverrides,
                         const char *const *overrides, const char *format, const cs_sim *sim,
                         const cs_scene *scene, char *err, size_t errlen);
void cs_run_identity_free(cs_run_identity *id);

/* XXH3-128 of the positions then the velocities as stored (rank 0 after a
 * frame holds them all), as 32 hex digits (CS_STATE_HASH_ALGORITHM). */
void cs_state_hash(const cs_sim *sim, char hex[CS_STATE_HASH_LEN]);

/* The state file of a run folder, "state.h5"; NULL in a build without
 * HDF5 (checkpoint_none.c), which keeps none: there cs_checkpoint_write
 * writes nothing and cs_checkpoint_read refuses to resume. */
const char *cs_checkpoint_file_name(void);

/* Rank 0, after cs_sim_state_gather: writes path atomically with the
 * identity, the frame, its state hash and the summary totals
 * (CS_SUMMARY_TOTALS doubles). Returns 0, or -1 with err naming the file. */
int cs_checkpoint_write(const char *path, const cs_run_identity *id, int frame,
                        const char *state_hash, cs_sim *sim, const double *totals, char *err,
                        size_t errlen);

/* Rank 0: reads path, refuses it unless the run is made from the same
 * identity (the difference named in err): the same resolved scene (but for
 * time.frames), or else the same scene file and overrides, and writes its state into sim's
 * arrays (cs_sim_state_scatter then gives them to every rank). *frame: the
 * frame it was written after; totals: CS_SUMMARY_TOTALS doubles. Returns 0,
 * CS_EXIT_INPUT (nothing to resume, or not the same run) or CS_EXIT_OUTPUT
 * (unreadable), with err. */
int cs_checkpoint_read(const char *path, const cs_run_identity *id, cs_sim *sim, int *frame,
                       double *totals, char *err, size_t errlen);

/* Another run's state, the start of `clothsim run --start-from`: read
 * without comparing identities (the caller maps it onto its own cloth). */
typedef struct cs_start_state {
    int frame;            /* the frame it was written after */
    double time;
    int particles;
    double *x, *v;        /* 3 per particle (malloc'd) */
    int nlag;             /* the scripts' lags (NULL, 0 without scripts) */
    double *lag;
} cs_start_state;

/* Returns 0, CS_EXIT_INPUT (not a state file) or CS_EXIT_OUTPUT
 * (unreadable), with err naming the file. */
int cs_checkpoint_read_start(const char *path, cs_start_state *st, char *err, size_t errlen);
void cs_start_state_free(cs_start_state *st);

#endif
