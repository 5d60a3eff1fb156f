/* outdir.c: the run folder: its layout, its lock, taking it over for a new
 * run, continuing an earlier one and reading a finished one back. */
#include "app/outdir.h"

#include "app/run.h"
#include "common/util.h"

#include <cJSON.h>
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* name with every character but letters, digits, '-', '_' and '.' as '_',
 * into out (len > 0). */
static void safe_name(const char *name, char *out, size_t len)
{
    size_t n = 0;
    for (const char *s = name; *s && n + 1 < len; s++) {
        char ch = *s;
        bool safe = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '-' || ch == '_' || ch == '.';
        out[n++] = safe ? ch : '_';
    }
    out[n] = '\0';
}

void cs_outdir_default(const char *scene_name, char *buf, size_t len)
{
    const char *name = scene_name && *scene_name ? scene_name : "scene";
    if (strcmp(name, ".") == 0 || strcmp(name, "..") == 0)
        name = "scene";
    int n = snprintf(buf, len, "out/");
    if (n > 0 && (size_t)n < len)
        safe_name(name, buf + n, len - (size_t)n);
}

/* ---------------------------------------------------------------- frames */

void cs_frame_path(char *buf, size_t len, const char *dir, int frame, const char *part,
                   const char *ext)
{
    if (part)
        snprintf(buf, len, "%s/frame_%04d.%s.%s", dir, frame, part, ext);
    else
        snprintf(buf, len, "%s/frame_%04d.%s", dir, frame, ext);
}

int cs_frame_layout_init(cs_frame_layout *l, cs_mesh_format format, int ncloths,
                         const char *const *names)
{
    *l = (cs_frame_layout){format, ncloths, NULL, NULL};
    l->names = calloc((size_t)ncloths + 1, sizeof *l->names);
    if (!l->names)
        return -1;
    for (int c = 0; c < ncloths; c++) {
        char fallback[32];
        snprintf(fallback, sizeof fallback, "cloth_%d", c);
        if (!(l->names[c] = strdup(names[c] && *names[c] ? names[c] : fallback))) {
            cs_frame_layout_free(l);
            return -1;
        }
    }
    if (format != CS_MESH_PLY || ncloths < 2)
        return 0; /* one file, a named object per cloth */
    l->parts = calloc((size_t)ncloths, sizeof *l->parts);
    if (!l->parts) {
        cs_frame_layout_free(l);
        return -1;
    }
    for (int c = 0; c < ncloths; c++) {
        char part[256];
        safe_name(l->names[c], part, sizeof part);
        bool taken = !part[0] || strcmp(part, ".") == 0 || strcmp(part, "..") == 0;
        for (int k = 0; k < c && !taken; k++)
            taken = strcmp(l->parts[k], part) == 0;
        if (taken)
            snprintf(part, sizeof part, "cloth%d", c);
        if (!(l->parts[c] = strdup(part))) {
            cs_frame_layout_free(l);
            return -1;
        }
    }
    return 0;
}

void cs_frame_layout_free(cs_frame_layout *l)
{
    for (int c = 0; c < l->ncloths; c++) {
        if (l->names)
            free(l->names[c]);
        if (l->parts)
            free(l->parts[c]);
    }
    free(l->names);
    free(l->parts);
    l->names = l->parts = NULL;
}

void cs_frame_file_path(const cs_frame_layout *l, const char *dir, int frame, int c, char *buf,
                        size_t len)
{
    cs_frame_path(buf, len, dir, frame, l->parts ? l->parts[c] : NULL,
                  cs_mesh_format_extension(l->format));
}

int cs_frame_write(const cs_frame_layout *l, const char *frames_dir, int frame,
                   cs_mesh_view *views, char *err, size_t errlen)
{
    char path[4096];
    for (int c = 0; c < l->ncloths; c++)
        views[c].name = l->names[c];
    if (!l->parts) {
        cs_frame_file_path(l, frames_dir, frame, 0, path, sizeof path);
        return cs_mesh_write(path, l->format, l->ncloths, views, err, errlen);
    }
    int rc = CS_OK;
    for (int c = 0; c < l->ncloths && rc == CS_OK; c++) {
        cs_frame_file_path(l, frames_dir, frame, c, path, sizeof path);
        rc = cs_mesh_write(path, l->format, 1, &views[c], err, errlen);
    }
    return rc;
}

int cs_frame_read(const cs_frame_layout *l, const char *frames_dir, int frame, cs_trimesh **out,
                  char *err, size_t errlen)
{
    char path[4096];
    int rc = CS_OK;
    bool named = l->format != CS_MESH_PLY; /* else a file per cloth */
    for (int c = 0; c < l->ncloths; c++)
        out[c] = NULL;
    for (int c = 0; c < (named ? 1 : l->ncloths) && rc == CS_OK; c++) {
        cs_frame_file_path(l, frames_dir, frame, c, path, sizeof path);
        if (access(path, F_OK) != 0) {
            snprintf(err, errlen, "%s: no such frame file (%s)", path, strerror(errno));
            rc = CS_ERR_BAD_INPUT;
        } else if (!named) {
            rc = (out[c] = cs_mesh_read(path, err, errlen)) ? CS_OK : CS_ERR_BAD_INPUT;
        } else {
            rc = cs_mesh_read_named(path, l->ncloths, (const char *const *)l->names, out, err,
                                    errlen);
        }
    }
    if (rc != CS_OK)
        for (int c = 0; c < l->ncloths; c++) {
            cs_trimesh_destroy(out[c]);
            out[c] = NULL;
        }
    return cs_exit_status(rc);
}

/* ------------------------------------------------------------- the folder */

int cs_outdir_init(cs_outdir *o, const char *dir, const char *scene_name)
{
    memset(o, 0, sizeof *o);
    o->lock = CS_DIR_LOCK_NONE;
    char fallback[4096];
    cs_outdir_default(scene_name, fallback, sizeof fallback);
    o->dir = strdup(dir ? dir : fallback);
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
    cs_frame_layout_free(&o->layout);
    free(o->dir);
    free(o->frames_dir);
    free(o->summary_path);
    free(o->records_path);
    free(o->state_path);
    memset(o, 0, sizeof *o);
    o->lock = CS_DIR_LOCK_NONE;
}

/* "frame_<digits>[.<part>].<ply|obj|glb>" with an optional ".tmp": its
 * number in *frame (a .tmp one as -1: always removed), or false. */
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
    if (*s != '.')
        return false;
    size_t len = strlen(s);
    bool tmp = len >= 4 && strcmp(s + len - 4, ".tmp") == 0;
    if (tmp)
        len -= 4;
    if (len < 4 || s[len - 4] != '.')
        return false;
    char ext[4];
    memcpy(ext, s + len - 3, 3);
    ext[3] = '\0';
    if (!cs_mesh_format_from_name(ext, NULL))
        return false;
    *frame = tmp ? -1 : (int)n;
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

/* An earlier run's DIR/cloth.usda and the caches and rest poses of
 * DIR/pc2/ (app/export.h): left, they would describe other frames. */
static int remove_exports(const char *dir, char *err, size_t errlen)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/cloth.usda", dir);
    DIR *d = NULL;
    int rc = unlink(path) != 0 && errno != ENOENT ? -1 : 0;
    if (rc == 0) {
        snprintf(path, sizeof path, "%s/pc2", dir);
        d = opendir(path); /* NULL: none */
    }
    struct dirent *e;
    while (d && rc == 0 && (e = readdir(d)) != NULL) {
        size_t len = strlen(e->d_name);
        const char *ext = len > 4 ? e->d_name + len - 4 : "";
        if (strcmp(ext, ".pc2") != 0 && strcmp(ext, ".obj") != 0 && strcmp(ext, ".tmp") != 0)
            continue;
        snprintf(path, sizeof path, "%s/pc2/%s", dir, e->d_name);
        rc = unlink(path) != 0 && errno != ENOENT ? -1 : 0;
    }
    if (rc != 0)
        cs_errorf(err, errlen, "cannot remove %s: %s", path, strerror(errno));
    if (d)
        closedir(d);
    return rc;
}

/* Makes the folders and takes the lock; a new run (keep false) then
 * removes an earlier run's frames, records and state (and what was
 * exported from its frames). */
static int open_dir(cs_outdir *o, bool keep, char *err, size_t errlen)
{
    if (cs_make_dirs(o->frames_dir) != 0) {
        snprintf(err, errlen, "cannot create %s: %s", o->frames_dir, strerror(errno));
        return -1;
    }
    if (cs_dir_lock_take(&o->lock, o->dir, err, errlen) != 0)
        return -1;
    o->synced = cs_now();
    if (keep)
        return 0;
    /* the state first: frames without it cannot be mistaken for a run to
     * resume, while state without its frames could */
    char *state_tmp = cs_path_tmp(o->state_path);
    int rc = !state_tmp || remove_file(o->state_path, err, errlen) != 0 ||
                     remove_file(state_tmp, err, errlen) != 0 ||
                     remove_frames(o->frames_dir, -1, err, errlen) != 0 ||
                     remove_exports(o->dir, err, errlen) != 0
                 ? -1
                 : 0;
    if (!state_tmp)
        snprintf(err, errlen, "out of memory");
    free(state_tmp);
    return rc;
}

static int resume(cs_outdir *o, const cs_run_identity *id, cs_sim *sim, cs_summary *s,
                  int frames, int *frame, char *err, size_t errlen)
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
    const cs_frame_layout *l = &o->layout;
    for (int k = 0; k <= *frame; k++)
        for (int c = 0; c < (l->parts ? l->ncloths : 1); c++) {
            char path[1024];
            struct stat st;
            cs_frame_file_path(l, o->frames_dir, k, c, path, sizeof path);
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
                    cs_sim *sim, cs_summary *s, int frames, int *first_frame)
{
    char err[1024];
    int status = CS_EXIT_OK;
    *first_frame = 0;
    if (open_dir(o, resuming, err, sizeof err) != 0)
        status = CS_EXIT_OUTPUT;
    else if (resuming)
        status = resume(o, id, sim, s, frames, first_frame, err, sizeof err);
    else if (cs_summary_open_records(s, o->records_path, 0, err, sizeof err) != 0)
        status = CS_EXIT_OUTPUT;
    if (status != CS_EXIT_OK)
        fprintf(stderr, "clothsim: %s\n", err);
    else if (resuming && !quiet)
        fprintf(stderr, "clothsim: resuming %s after frame %d (t=%.6g s)\n", o->dir,
                *first_frame, cs_sim_time(sim));
    return status;
}

/* ------------------------------------------------------- the scene */

char *cs_outdir_scene(const char *dir)
{
    char *path = cs_path_join(dir, "scene.yaml");
    struct stat st;
    if (path && (stat(path, &st) != 0 || !S_ISREG(st.st_mode))) {
        free(path);
        path = NULL;
    }
    return path;
}

/* source into dest, unless dest is there already (a name of its content)
 * or is source itself. */
static int copy_asset(const char *source, const char *dest, char *err, size_t errlen)
{
    struct stat a, b;
    if (stat(dest, &b) == 0)
        return 0;
    if (stat(source, &a) != 0) {
        snprintf(err, errlen, "cannot read %s: %s", source, strerror(errno));
        return -1;
    }
    char *slash = strrchr(dest, '/');
    if (slash) {
        *slash = '\0';
        int made = cs_make_dirs(dest);
        *slash = '/';
        if (made != 0) {
            snprintf(err, errlen, "cannot create the folder of %s: %s", dest, strerror(errno));
            return -1;
        }
    }
    size_t len;
    char *data = cs_file_read_all(source, &len);
    if (!data) {
        snprintf(err, errlen, "cannot read %s: %s", source, strerror(errno));
        return -1;
    }
    int rc = cs_file_write_atomic(dest, data, len, err, errlen);
    free(data);
    return rc;
}

int cs_outdir_write_scene(cs_outdir *o, const cs_scene *scene, char *err, size_t errlen)
{
    for (int i = 0; i < scene->nassets; i++) {
        char *dest = cs_path_join(o->dir, scene->assets[i].name);
        int rc = dest ? copy_asset(scene->assets[i].source, dest, err, errlen) : -1;
        if (!dest)
            snprintf(err, errlen, "out of memory");
        free(dest);
        if (rc != 0)
            return -1;
    }
    char *path = cs_path_join(o->dir, "scene.yaml");
    int rc = path ? cs_file_write_atomic(path, scene->resolved, scene->resolved_len, err, errlen)
                  : -1;
    if (!path)
        snprintf(err, errlen, "out of memory");
    free(path);
    return rc;
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
    double t = cs_now();
    if (!now && t - o->synced < CS_OUTDIR_SYNC_SECONDS)
        return 0;
    o->synced = t;
    return cs_dir_sync(o->dir, err, errlen);
}

/* ------------------------------------------------- reading a run back */

void cs_run_info_free(cs_run_info *r)
{
    free(r->scene_file);
    free(r->source_file);
    for (int i = 0; i < r->noverrides; i++)
        free(r->overrides[i]);
    free(r->overrides);
    memset(r, 0, sizeof *r);
}

/* The overrides of a summary (an array of strings) into info. */
static int read_overrides(const cJSON *over, const char *path, cs_run_info *info, char *err,
                          size_t errlen)
{
    int n = over ? cJSON_GetArraySize(over) : 0;
    info->overrides = calloc((size_t)n + 1, sizeof *info->overrides);
    if (!info->overrides)
        goto nomem;
    const cJSON *item;
    if (over)
        cJSON_ArrayForEach(item, over) {
            if (!cJSON_IsString(item)) {
                snprintf(err, errlen, "%s: \"overrides\" must be a list of strings", path);
                return CS_EXIT_INPUT;
            }
            if (!(info->overrides[info->noverrides] = strdup(item->valuestring)))
                goto nomem;
            info->noverrides++;
        }
    return CS_EXIT_OK;
nomem:
    snprintf(err, errlen, "out of memory");
    return CS_EXIT_OUTPUT;
}

int cs_run_info_read(const char *dir, cs_run_info *info, char *err, size_t errlen)
{
    memset(info, 0, sizeof *info);
    char path[4096];
    snprintf(path, sizeof path, "%s/summary.json", dir);
    if (access(path, F_OK) != 0) {
        snprintf(err, errlen,
                 "%s has no summary.json: give the output folder of 'clothsim run' or a "
                 "scene file",
                 dir);
        return CS_EXIT_INPUT;
    }
    size_t len;
    char *text = cs_file_read_all(path, &len);
    if (!text) {
        snprintf(err, errlen, "cannot read %s: %s", path, strerror(errno));
        return CS_EXIT_INPUT;
    }
    cJSON *root = cJSON_Parse(text);
    free(text);
    const cJSON *scene = cJSON_GetObjectItemCaseSensitive(root, "scene_file");
    const cJSON *format = cJSON_GetObjectItemCaseSensitive(root, "format");
    const cJSON *written = cJSON_GetObjectItemCaseSensitive(root, "frames_written");
    const cJSON *fps = cJSON_GetObjectItemCaseSensitive(root, "fps");
    const cJSON *over = cJSON_GetObjectItemCaseSensitive(root, "overrides");
    if (!cJSON_IsString(scene) || !cJSON_IsString(format) || !cJSON_IsNumber(written) ||
        !cJSON_IsNumber(fps) || !cs_mesh_format_from_name(format->valuestring, &info->format) ||
        (over && !cJSON_IsArray(over))) {
        snprintf(err, errlen,
                 "%s: not a summary written by 'clothsim run' (needs scene_file, format, "
                 "frames_written, fps)",
                 path);
        cJSON_Delete(root);
        return CS_EXIT_INPUT;
    }
    info->frames_written = written->valuedouble > 0 && written->valuedouble < 1e8
                               ? (int)written->valuedouble
                               : 0;
    info->fps = fps->valuedouble;
    /* a folder with its resolved scene needs neither the file the run
     * came from nor its overrides, which that scene holds */
    char *resolved = cs_outdir_scene(dir);
    int status = resolved ? CS_EXIT_OK : read_overrides(over, path, info, err, errlen);
    info->scene_file = resolved;
    info->source_file = strdup(scene->valuestring);
    if (status == CS_EXIT_OK && !resolved && info->source_file)
        info->scene_file = strdup(info->source_file);
    if (status == CS_EXIT_OK && (!info->source_file || !info->scene_file)) {
        snprintf(err, errlen, "out of memory");
        status = CS_EXIT_OUTPUT;
    }
    cJSON_Delete(root);
    return status;
}
