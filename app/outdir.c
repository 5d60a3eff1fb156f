/* outdir.c: the run folder: its layout, its lock, taking it over for a new
 * run and continuing an earlier one. */
#include "app/outdir.h"

#include "app/fsutil.h"
#include "app/run.h"

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static double monotonic_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* out/<scene name>, the name made safe for a path. */
static char *default_dir(const char *scene_name)
{
    const char *name = scene_name && *scene_name ? scene_name : "scene";
    size_t len = strlen(name);
    char *dir = malloc(len + 5);
    if (!dir)
        return NULL;
    memcpy(dir, "out/", 4);
    for (size_t i = 0; i < len; i++) {
        char ch = name[i];
        bool safe = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '-' || ch == '_' || ch == '.';
        dir[4 + i] = safe ? ch : '_';
    }
    dir[4 + len] = '\0';
    if (strcmp(dir, "out/.") == 0 || strcmp(dir, "out/..") == 0)
        strcpy(dir, "out/scene");
    return dir;
}

int cs_outdir_init(cs_outdir *o, const char *dir, const char *scene_name)
{
    memset(o, 0, sizeof *o);
    o->lock = CS_DIR_LOCK_NONE;
    o->dir = dir ? strdup(dir) : default_dir(scene_name);
    if (!o->dir)
        return -1;
    o->frames_dir = cs_path_join(o->dir, "frames");
    o->summary_path = cs_path_join(o->dir, "summary.json");
    o->records_path = cs_path_join(o->dir, "frames.jsonl");
    o->state_path = cs_path_join(o->dir, "state.h5");
    return o->frames_dir && o->summary_path && o->records_path && o->state_path ? 0 : -1;
}

void cs_outdir_free(cs_outdir *o)
{
    cs_dir_lock_release(&o->lock);
    free(o->dir);
    free(o->frames_dir);
    free(o->summary_path);
    free(o->records_path);
    free(o->state_path);
    memset(o, 0, sizeof *o);
    o->lock = CS_DIR_LOCK_NONE;
}

/* "frame_<digits>.<ply|obj|glb>" with an optional ".tmp": its number in
 * *frame (a .tmp one as -1: always removed), or false. */
static bool frame_file(const char *name, int *frame)
{
    if (strncmp(name, "frame_", 6) != 0)
        return false;
    const char *s = name + 6;
    if (*s < '0' || *s > '9')
        return false;
    long n = 0;
    while (*s >= '0' && *s <= '9' && n < 100000000)
        n = 10 * n + (*s++ - '0');
    if (*s++ != '.')
        return false;
    cs_mesh_format f;
    char ext[4];
    if (strlen(s) < 3)
        return false;
    memcpy(ext, s, 3);
    ext[3] = '\0';
    if (!cs_mesh_format_from_name(ext, &f))
        return false;
    if (s[3] == '\0')
        *frame = (int)n;
    else if (strcmp(s + 3, ".tmp") == 0)
        *frame = -1;
    else
        return false;
    return true;
}

/* Removes the frame files after frame keep (keep < 0: all) and any
 * half-written ones; frames of another run would mix with this one's. */
static int remove_frames(const char *dir, int keep, char *err, size_t errlen)
{
    DIR *d = opendir(dir);
    if (!d) {
        snprintf(err, errlen, "cannot read %s: %s", dir, strerror(errno));
        return -1;
    }
    int rc = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        int frame;
        if (!frame_file(e->d_name, &frame) || (frame >= 0 && frame <= keep))
            continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (unlink(path) != 0) {
            snprintf(err, errlen, "cannot remove the old frame %s/%s: %s", dir, e->d_name,
                     strerror(errno));
            rc = -1;
            break;
        }
    }
    closedir(d);
    return rc;
}

static int remove_file(const char *path, char *err, size_t errlen)
{
    if (unlink(path) != 0 && errno != ENOENT) {
        snprintf(err, errlen, "cannot remove %s: %s", path, strerror(errno));
        return -1;
    }
    return 0;
}

/* Makes the folders and takes the lock; a new run (keep false) then
 * removes an earlier run's frames, records and state. */
static int open_dir(cs_outdir *o, bool keep, char *err, size_t errlen)
{
    if (cs_make_dirs(o->frames_dir) != 0) {
        snprintf(err, errlen, "cannot create %s: %s", o->frames_dir, strerror(errno));
        return -1;
    }
    if (cs_dir_lock_take(&o->lock, o->dir, err, errlen) != 0)
        return -1;
    o->synced = monotonic_seconds();
    if (keep)
        return 0;
    /* the state first: frames without it cannot be mistaken for a run to
     * resume, while state without its frames could */
    char *state_tmp = cs_path_tmp(o->state_path);
    int rc = !state_tmp || remove_file(o->state_path, err, errlen) != 0 ||
                     remove_file(state_tmp, err, errlen) != 0 ||
                     remove_frames(o->frames_dir, -1, err, errlen) != 0
                 ? -1
                 : 0;
    if (!state_tmp)
        snprintf(err, errlen, "out of memory");
    free(state_tmp);
    return rc;
}

static int resume(cs_outdir *o, const cs_run_identity *id, cs_sim *sim, cs_summary *s,
                  cs_mesh_format format, int frames, int *frame, char *err, size_t errlen)
{
    double totals[CS_SUMMARY_TOTALS];
    int rc = cs_checkpoint_read(o->state_path, id, sim, frame, totals, err, errlen);
    if (rc != CS_EXIT_OK)
        return rc;
    if (*frame > frames) {
        snprintf(err, errlen, "cannot resume: %s holds frame %d, past the %d frames asked for "
                 "(give --frames %d or more)", o->state_path, *frame, frames, *frame);
        return CS_EXIT_INPUT;
    }
    /* frames written after the last state are made again, the same bits */
    if (remove_frames(o->frames_dir, *frame, err, errlen) != 0)
        return CS_EXIT_OUTPUT;
    const char *ext = cs_mesh_format_extension(format);
    for (int k = 0; k <= *frame; k++) {
        char path[1024];
        struct stat st;
        snprintf(path, sizeof path, "%s/frame_%04d.%s", o->frames_dir, k, ext);
        bool missing = stat(path, &st) != 0;
        if (missing || st.st_size == 0) { /* empty: a power cut before it reached the disk */
            snprintf(err, errlen, "cannot resume after frame %d: %.900s: %s", *frame, path,
                     missing ? strerror(errno) : "empty");
            return CS_EXIT_INPUT;
        }
    }
    if (cs_summary_open_records(s, o->records_path, *frame, err, errlen) != 0)
        return CS_EXIT_OUTPUT;
    cs_summary_set_base(s, totals);
    s->frames_written = *frame + 1;
    s->resumed_from = *frame;
    return CS_EXIT_OK;
}

int cs_outdir_start(cs_outdir *o, bool resuming, bool quiet, const cs_run_identity *id,
                    cs_sim *sim, cs_summary *s, cs_mesh_format format, int frames,
                    int *first_frame)
{
    char err[1024];
    int status = CS_EXIT_OK;
    *first_frame = 0;
    if (open_dir(o, resuming, err, sizeof err) != 0)
        status = CS_EXIT_OUTPUT;
    else if (resuming)
        status = resume(o, id, sim, s, format, frames, first_frame, err, sizeof err);
    else if (cs_summary_open_records(s, o->records_path, 0, err, sizeof err) != 0)
        status = CS_EXIT_OUTPUT;
    if (status != CS_EXIT_OK)
        fprintf(stderr, "clothsim: %s\n", err);
    else if (resuming && !quiet)
        fprintf(stderr, "clothsim: resuming %s after frame %d (t=%.6g s)\n", o->dir,
                *first_frame, cs_sim_time(sim));
    return status;
}

int cs_outdir_save_state(cs_outdir *o, const cs_run_identity *id, int frame,
                         const char *state_hash, cs_sim *sim, const cs_summary *s, char *err,
                         size_t errlen)
{
    double totals[CS_SUMMARY_TOTALS];
    cs_summary_totals(s, totals);
    return cs_checkpoint_write(o->state_path, id, frame, state_hash, sim, totals, err, errlen);
}

int cs_outdir_sync(cs_outdir *o, bool now, char *err, size_t errlen)
{
    double t = monotonic_seconds();
    if (!now && t - o->synced < CS_OUTDIR_SYNC_SECONDS)
        return 0;
    o->synced = t;
    return cs_dir_sync(o->dir, err, errlen);
}
