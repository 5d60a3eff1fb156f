/* start_from.c: the start of `clothsim run --start-from RUN` (start_from.h). */
#include "app/start_from.h"

#include "app/checkpoint.h"
#include "app/exit.h"
#include "app/outdir.h"
#include "common/util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A vertex of the new cloth may lie this fraction of the run's mean edge
 * off the run's rest surface. The same rectangle at two resolutions gives
 * round-off (1e-16 m); another rest shape, millimetres. */
static const double REST_TOLERANCE = 0.01;

struct cs_start_from {
    char *dir;
    cs_scene *from;              /* the run's scene (its folder's scene.yaml) */
    cs_start_state state;        /* its last frame's state */
    cs_frame_layout layout;      /* its frame files */
    int ncloths;
    const cs_scene *to;
    cs_surface_map **state_map;  /* per cloth: the run's rest mesh (particle order) */
    cs_surface_map **file_map;   /* per cloth: its frame 0 file (the file's order) */
    cs_trimesh **file_rest;      /* per cloth: frame 0 as the file holds it */
};

/* The map of cloth c from mesh (the run's rest shape) onto the new rest
 * shape; refused when the shapes differ. */
static int map_cloth(const cs_start_from *s, int c, const cs_trimesh *mesh, cs_surface_map **out,
                     char *err, size_t errlen)
{
    double worst;
    const cs_trimesh *to = s->to->def.cloths[c].mesh;
    *out = cs_surface_map_create(mesh, to, &worst);
    if (!*out) {
        snprintf(err, errlen, "out of memory");
        return CS_EXIT_OUTPUT;
    }
    double allowed = REST_TOLERANCE * cs_trimesh_mean_edge(mesh);
    if (!(worst <= allowed)) {
        snprintf(err, errlen, "cannot start from %s: cloth '%s' at rest is not the run's cloth "
                 "at rest: a vertex lies %.3g m from it (at most %.3g m allowed); "
                 "--start-from carries a state between meshes of one rest shape", s->dir,
                 s->to->def.cloths[c].name ? s->to->def.cloths[c].name : "?", worst, allowed);
        return CS_EXIT_INPUT;
    }
    return CS_EXIT_OK;
}

static int check_runs(const cs_start_from *s, const cs_run_info *info, char *err, size_t errlen)
{
    const cs_sim_def *a = &s->from->def, *b = &s->to->def;
    if (a->ncloths != b->ncloths) {
        snprintf(err, errlen, "cannot start from %s: it has %d cloth%s, the scene %d", s->dir,
                 a->ncloths, a->ncloths == 1 ? "" : "s", b->ncloths);
        return CS_EXIT_INPUT;
    }
    if (info->fps != b->fps) { /* the frames would not fall at this run's frame times */
        snprintf(err, errlen, "cannot start from %s: its frame rate is %g, the scene's %g",
                 s->dir, info->fps, b->fps);
        return CS_EXIT_INPUT;
    }
    int particles = 0;
    for (int c = 0; c < a->ncloths; c++)
        particles += a->cloths[c].mesh->nv;
    if (particles != s->state.particles) {
        snprintf(err, errlen, "cannot start from %s: its state.h5 holds %d particles, its "
                 "scene.yaml's cloths %d", s->dir, s->state.particles, particles);
        return CS_EXIT_INPUT;
    }
    if (s->state.frame > s->to->frames) { /* equal: the folder to resume, nothing simulated */
        snprintf(err, errlen, "cannot start from %s: it ends at frame %d, after the %d frames "
                 "of this run (give --frames %d or more)", s->dir, s->state.frame,
                 s->to->frames, s->state.frame);
        return CS_EXIT_INPUT;
    }
    return CS_EXIT_OK;
}

/* The run's frame 0 as its files hold it (their vertex order), mapped. */
static int map_files(cs_start_from *s, char *err, size_t errlen)
{
    char *frames = cs_path_join(s->dir, "frames");
    int status = frames ? cs_frame_read(&s->layout, frames, 0, s->file_rest, err, errlen)
                        : CS_EXIT_OUTPUT;
    free(frames);
    for (int c = 0; c < s->ncloths && status == CS_EXIT_OK; c++) {
        const cs_trimesh *m = s->file_rest[c], *rest = s->from->def.cloths[c].mesh;
        if (!m || m->nv != rest->nv || m->nt != rest->nt) {
            snprintf(err, errlen, "cannot start from %s: its frame 0 does not hold the cloths "
                     "of its scene.yaml", s->dir);
            return CS_EXIT_INPUT;
        }
        status = map_cloth(s, c, m, &s->file_map[c], err, errlen);
    }
    return status;
}

int cs_start_from_open(const char *dir, const cs_scene *scene, cs_start_from **out, char *err,
                       size_t errlen)
{
    *out = NULL;
    cs_start_from *s = calloc(1, sizeof *s);
    cs_run_info info;
    memset(&info, 0, sizeof info);
    if (!s || !(s->dir = strdup(dir))) {
        free(s);
        snprintf(err, errlen, "out of memory");
        return CS_EXIT_OUTPUT;
    }
    s->to = scene;
    char *scene_path = cs_outdir_scene(dir);
    int status = CS_EXIT_OK;
    if (!scene_path) {
        snprintf(err, errlen, "cannot start from %s: it is no run folder (no scene.yaml)", dir);
        status = CS_EXIT_INPUT;
    } else if ((status = cs_run_info_read(dir, &info, err, errlen)) == CS_EXIT_OK) {
        char why[1024];
        int rc = cs_scene_load(scene_path, 0, NULL, &s->from, why, sizeof why);
        if (rc != CS_OK) {
            snprintf(err, errlen, "cannot start from %s: %s", dir, why);
            status = cs_exit_status(rc);
        }
    }
    free(scene_path);
    /* a build without HDF5 has no state file name, and refuses here */
    const char *name = cs_checkpoint_file_name();
    char *state_path = status == CS_EXIT_OK ? cs_path_join(dir, name ? name : "state.h5") : NULL;
    if (status == CS_EXIT_OK)
        status = state_path ? cs_checkpoint_read_start(state_path, &s->state, err, errlen)
                            : CS_EXIT_OUTPUT;
    free(state_path);
    if (status == CS_EXIT_OK)
        status = check_runs(s, &info, err, errlen);
    if (status == CS_EXIT_OK) {
        s->ncloths = scene->def.ncloths;
        size_t n = (size_t)s->ncloths + 1;
        const char **names = calloc(n, sizeof *names);
        s->state_map = calloc(n, sizeof *s->state_map);
        s->file_map = calloc(n, sizeof *s->file_map);
        s->file_rest = calloc(n, sizeof *s->file_rest);
        for (int c = 0; names && c < s->ncloths; c++)
            names[c] = s->from->def.cloths[c].name;
        if (!names || !s->state_map || !s->file_map || !s->file_rest ||
            cs_frame_layout_init(&s->layout, info.format, s->ncloths, names) != 0) {
            snprintf(err, errlen, "out of memory");
            status = CS_EXIT_OUTPUT;
        }
        free(names);
    }
    for (int c = 0; c < s->ncloths && status == CS_EXIT_OK; c++)
        status = map_cloth(s, c, s->from->def.cloths[c].mesh, &s->state_map[c], err, errlen);
    if (status == CS_EXIT_OK)
        status = map_files(s, err, errlen);
    cs_run_info_free(&info);
    if (status != CS_EXIT_OK) {
        cs_start_from_close(s);
        return status;
    }
    *out = s;
    return CS_EXIT_OK;
}

void cs_start_from_close(cs_start_from *s)
{
    if (!s)
        return;
    for (int c = 0; c < s->ncloths; c++) {
        if (s->state_map)
            cs_surface_map_destroy(s->state_map[c]);
        if (s->file_map)
            cs_surface_map_destroy(s->file_map[c]);
        if (s->file_rest)
            cs_trimesh_destroy(s->file_rest[c]);
    }
    free(s->state_map);
    free(s->file_map);
    free(s->file_rest);
    cs_frame_layout_free(&s->layout);
    cs_start_state_free(&s->state);
    cs_scene_destroy(s->from);
    free(s->dir);
    free(s);
}

int cs_start_from_frame(const cs_start_from *s)
{
    return s->state.frame;
}

static double *state_array(cs_sim *sim, const char *name, size_t *count)
{
    cs_state_array a[CS_STATE_MAX_ARRAYS];
    int na = cs_sim_state_arrays(sim, a);
    for (int k = 0; k < na; k++)
        if (strcmp(a[k].name, name) == 0) {
            *count = a[k].count;
            return a[k].data;
        }
    *count = 0;
    return NULL;
}

/* values (3 per particle of the run, in its particle order) carried onto
 * every cloth of sim through maps */
static void carry(const cs_start_from *s, cs_surface_map *const *maps,
                  cs_trimesh *const *from_meshes, const double *values, cs_sim *sim, double *out)
{
    size_t from_offset = 0;
    for (int c = 0; c < s->ncloths; c++) {
        const cs_trimesh *from = from_meshes ? from_meshes[c] : s->from->def.cloths[c].mesh;
        cs_surface_map_apply(maps[c], from, values + 3 * from_offset,
                             out + 3 * (size_t)cs_sim_cloth_offset(sim, c));
        from_offset += (size_t)from->nv;
    }
}

int cs_start_from_load_frame(const cs_start_from *s, int f, cs_sim *sim, char *err,
                             size_t errlen)
{
    size_t nx, nv, nt, nfree, nlag;
    double *x = state_array(sim, "positions", &nx), *v = state_array(sim, "velocities", &nv);
    double *t = state_array(sim, "time", &nt);
    double *x_free = state_array(sim, "self_collision/x_free", &nfree);
    double *lag = state_array(sim, "scripts/lag", &nlag);
    if (f == s->state.frame) {
        if ((int)nlag != s->state.nlag) {
            snprintf(err, errlen, "cannot start from %s: it has %d script%s, the scene %zu",
                     s->dir, s->state.nlag, s->state.nlag == 1 ? "" : "s", nlag);
            return CS_EXIT_INPUT;
        }
        carry(s, s->state_map, NULL, s->state.x, sim, x);
        carry(s, s->state_map, NULL, s->state.v, sim, v);
        if (x_free)
            memcpy(x_free, x, sizeof *x * nx);
        if (nlag > 0)
            memcpy(lag, s->state.lag, sizeof *lag * nlag);
        *t = s->state.time;
        return CS_EXIT_OK;
    }
    /* an earlier frame, from its files */
    char *frames = cs_path_join(s->dir, "frames");
    cs_trimesh **meshes = calloc((size_t)s->ncloths + 1, sizeof *meshes);
    int status = frames && meshes ? cs_frame_read(&s->layout, frames, f, meshes, err, errlen)
                                  : CS_EXIT_OUTPUT;
    size_t total = 0;
    for (int c = 0; c < s->ncloths && status == CS_EXIT_OK; c++) {
        const cs_trimesh *m = meshes[c], *rest = s->file_rest[c];
        if (!m || m->nv != rest->nv || m->nt != rest->nt ||
            memcmp(m->tri, rest->tri, sizeof *m->tri * 3 * (size_t)m->nt) != 0) {
            snprintf(err, errlen, "cannot start from %s: its frame %d has other cloths than "
                     "its frame 0", s->dir, f);
            status = CS_EXIT_INPUT;
        }
        total += m ? (size_t)m->nv : 0;
    }
    double *all = status == CS_EXIT_OK ? malloc(sizeof *all * 3 * (total + 1)) : NULL;
    if (status == CS_EXIT_OK && !all) {
        snprintf(err, errlen, "out of memory");
        status = CS_EXIT_OUTPUT;
    }
    for (int c = 0, at = 0; all && c < s->ncloths; at += meshes[c]->nv, c++)
        memcpy(all + 3 * (size_t)at, meshes[c]->x, sizeof *all * 3 * (size_t)meshes[c]->nv);
    if (all) {
        carry(s, s->file_map, s->file_rest, all, sim, x);
        memset(v, 0, sizeof *v * nv);
        if (x_free)
            memcpy(x_free, x, sizeof *x * nx);
        *t = f / s->to->def.fps;
    }
    free(all);
    for (int c = 0; meshes && c < s->ncloths; c++)
        cs_trimesh_destroy(meshes[c]);
    free(meshes);
    free(frames);
    if (status == CS_EXIT_OK && !frames) {
        snprintf(err, errlen, "out of memory");
        status = CS_EXIT_OUTPUT;
    }
    return status;
}
