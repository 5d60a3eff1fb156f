/* outdir.h: the run folder: the one module that knows the layout of the
 * folder a `clothsim run` writes, DIR, and reads it back (`clothsim render`):
 *   DIR/frames/frame_NNNN.EXT   a mesh per frame, frame 0 the initial state
 *                               (frame naming, cs_frame_path: also the
 *                               images, DIR/images/frame_NNNN.png)
 *   DIR/frames.jsonl            a record per simulated frame, one JSON a line
 *   DIR/summary.json            the run as a whole (summary.h)
 *   DIR/state.h5                what --resume continues from (checkpoint.h)
 *   DIR/scene.yaml              the resolved scene (cs_scene.resolved): every
 *                               key with its value, its files in DIR/assets/
 *   DIR/assets/                 the mesh files and level sets the scene read,
 *                               named by their content
 *   DIR/.lock                   held while a run writes (lock.h)
 * A new run takes the folder over: frames, records and state of an earlier
 * run there are removed, with DIR/cloth.usda and DIR/pc2/'s caches made
 * from them (export.h). --resume continues the earlier run instead.
 *
 * A frame keeps its cloths apart, so that they read back by name: in OBJ
 * and glTF each cloth is an object of its own (a node and a mesh named like
 * the cloth); PLY has no objects, so a scene of several cloths writes a
 * file per cloth, frame_NNNN.NAME.ply, NAME the cloth's name made safe for
 * a path (letters, digits, '-', '_' and '.' kept, others '_'; a name taken
 * by an earlier cloth becomes clothK, K its index). Every file is written
 * atomically (common/util.h). */
#ifndef CS_APP_OUTDIR_H
#define CS_APP_OUTDIR_H

#include <stdbool.h>
#include <stddef.h>

#include "app/checkpoint.h"
#include "app/lock.h"
#include "app/summary.h"
#include "import/import.h"

/* "dir/frame_NNNN.ext", or with part "dir/frame_NNNN.part.ext", in buf. */
void cs_frame_path(char *buf, size_t len, const char *dir, int frame, const char *part,
                   const char *ext);

/* How a run's frames hold its cloths. */
typedef struct cs_frame_layout {
    cs_mesh_format format;
    int ncloths;
    char **names;              /* per cloth its object's name */
    char **parts;              /* per cloth its file's part (PLY, several cloths), else NULL */
} cs_frame_layout;

/* The layout of ncloths cloths named names[c] (a cloth without a name is
 * cloth_C). Returns 0, or -1 when memory runs out. */
int cs_frame_layout_init(cs_frame_layout *l, cs_mesh_format format, int ncloths,
                         const char *const *names);
void cs_frame_layout_free(cs_frame_layout *l);

/* Writes frame's files into frames_dir: views[c] is cloth c (its name
 * from the layout). Returns a cs_status with err. */
int cs_frame_write(const cs_frame_layout *l, const char *frames_dir, int frame,
                   cs_mesh_view *views, char *err, size_t errlen);

/* The path of the file of frame that holds cloth c, in buf. */
void cs_frame_file_path(const cs_frame_layout *l, const char *dir, int frame, int c, char *buf,
                        size_t len);

/* Reads frame's cloths by name into out[c] (the caller destroys them).
 * Returns an exit status (CS_EXIT_INPUT: a file missing or unreadable, or
 * without an object of a cloth's name) with err. */
int cs_frame_read(const cs_frame_layout *l, const char *frames_dir, int frame, cs_trimesh **out,
                  char *err, size_t errlen);

/* out/<scene name>, the name made safe for a path, in buf. */
void cs_outdir_default(const char *scene_name, char *buf, size_t len);

typedef struct cs_outdir {
    char *dir, *frames_dir, *summary_path, *records_path, *state_path;
    cs_frame_layout layout;  /* the frames' files (cs_frame_layout_init before starting) */
    cs_dir_lock lock;
    double synced;  /* when cs_outdir_sync last reached the disk (monotonic s) */
} cs_outdir;

/* Seconds between syncs of the folder to the disk during a run. */
#define CS_OUTDIR_SYNC_SECONDS 10.0

/* The paths of dir, or when dir is NULL of out/<scene name> (made safe for
 * a path); returns 0, or -1 when memory runs out. */
int cs_outdir_init(cs_outdir *o, const char *dir, const char *scene_name);
/* Frees the paths and the layout, and releases the lock. */
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
                    cs_sim *sim, cs_summary *s, int frames, int *first_frame);

/* Rank 0, once the folder is taken: DIR/scene.yaml (atomically) and the
 * files it names copied into DIR/assets/ (a file already there under its
 * content's name is kept), so that DIR alone runs, renders and resumes.
 * Returns 0, or -1 with err naming the file. */
int cs_outdir_write_scene(cs_outdir *o, const cs_scene *scene, char *err, size_t errlen);

/* "DIR/scene.yaml" when dir holds one (malloc'd), else NULL. */
char *cs_outdir_scene(const char *dir);

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

/* What `clothsim render`, `info`, `export` and `sweep` read back from a run
 * folder: its summary.json, and its scene.yaml when it has one. */
typedef struct cs_run_info {
    char *scene_file;        /* DIR/scene.yaml when DIR has it (its overrides
                                are in it: none below), else the scene file
                                the run came from */
    char *source_file;       /* the scene file the run came from */
    int noverrides;
    char **overrides;        /* the run's --set overrides, as given */
    cs_mesh_format format;
    int frames_written;
    double fps;
} cs_run_info;

/* Reads DIR/summary.json. Returns 0, or an exit status (CS_EXIT_INPUT: no
 * summary, or not one 'clothsim run' wrote) with err. */
int cs_run_info_read(const char *dir, cs_run_info *info, char *err, size_t errlen);
void cs_run_info_free(cs_run_info *info);

#endif
