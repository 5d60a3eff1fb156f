/* export.c: a run folder's frames as DIR/cloth.usda and Blender point
 * caches (export.h).
 *
 * One pass over the frames: each frame's cloths are read (cs_frame_read)
 * and appended, as float32, to the point cache of each cloth and to a
 * temporary file of each cloth's USD time samples. Then cloth.usda is put
 * together: the stage, per cloth its mesh (topology once, the samples
 * copied in), per body its mesh in the body's own frame with its
 * transform, sampled at every frame when the body moves. */
#include "app/export.h"

#include "app/outdir.h"
#include "app/pc2_write.h"
#include "app/run.h"
#include "app/usd_write.h"
#include "common/util.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define BODY_DETAIL 64   /* segments around spheres and cylinders, as render draws them */
#define PRIM_NAME 256

const char *cs_export_up_axis(const cs_scene *scene)
{
    double up[3];
    for (int i = 0; i < 3; i++)
        up[i] = scene->camera.given ? scene->camera.up[i] : -scene->def.gravity[i];
    double a[3] = {fabs(up[0]), fabs(up[1]), fabs(up[2])};
    return a[2] > a[1] && a[2] > a[0] ? "Z" : "Y";
}

/* ------------------------------------------------------------- the job */

typedef struct job {
    const cs_scene *scene;
    const char *dir;
    int nframes;
    double fps;
    cs_export_what what;
    int ncloths, nbodies;
    char (*prims)[PRIM_NAME];   /* cloths, then bodies: their prim names */
    char **samples;             /* USD: per cloth its temporary file of samples */
    FILE **sample_fp;
    cs_pc2 *pc2;                /* per cloth */
    int **tri;                  /* per cloth frame 0's triangles: the topology */
    char *usd_path;
    float *xf;                  /* one cloth's positions as float32 */
} job;

static const char *cloth_name(const job *j, int c)
{
    return j->prims[c];
}

/* Prim names: identifiers, unique among the cloths and bodies. */
static void name_prims(job *j)
{
    const char **taken = (const char **)calloc((size_t)(j->ncloths + j->nbodies) + 1,
                                               sizeof *taken);
    for (int k = 0; k < j->ncloths + j->nbodies; k++) {
        bool cloth = k < j->ncloths;
        const char *name = cloth ? j->scene->def.cloths[k].name
                                 : j->scene->def.bodies[k - j->ncloths].name;
        char fallback[32];
        snprintf(fallback, sizeof fallback, cloth ? "cloth_%d" : "body_%d",
                 cloth ? k : k - j->ncloths);
        /* without memory for the list, the index keeps names apart */
        cs_usd_identifier(taken ? name : NULL, fallback, taken, k, j->prims[k], PRIM_NAME);
        if (taken)
            taken[k] = j->prims[k];
    }
    free(taken);
}

static void close_all(job *j, bool remove_files)
{
    for (int c = 0; c < j->ncloths; c++) {
        if (j->sample_fp && j->sample_fp[c])
            fclose(j->sample_fp[c]);
        if (j->sample_fp)
            j->sample_fp[c] = NULL;
        if (j->samples && j->samples[c] && remove_files)
            remove(j->samples[c]);
        if (j->pc2 && j->pc2[c].fp)
            cs_pc2_abandon(&j->pc2[c]);
    }
}

static void job_free(job *j)
{
    close_all(j, true);
    for (int c = 0; j->samples && c < j->ncloths; c++)
        free(j->samples[c]);
    for (int c = 0; j->tri && c < j->ncloths; c++)
        free(j->tri[c]);
    free(j->tri);
    free(j->samples);
    free(j->sample_fp);
    free(j->pc2);
    free(j->prims);
    free(j->usd_path);
    free(j->xf);
}

/* The files the pass appends to. */
static int open_outputs(job *j, char *err, size_t errlen)
{
    char path[4096];
    if (j->what.pc2) {
        snprintf(path, sizeof path, "%s/pc2", j->dir);
        if (cs_make_dirs(path) != 0) {
            cs_errorf(err, errlen, "cannot create %s: %s", path, strerror(errno));
            return CS_EXIT_OUTPUT;
        }
        for (int c = 0; c < j->ncloths; c++) {
            snprintf(path, sizeof path, "%s/pc2/%s.pc2", j->dir, cloth_name(j, c));
            if (cs_pc2_open(&j->pc2[c], path, j->scene->def.cloths[c].mesh->nv, 0.0f, 1.0f,
                            err, errlen) != 0)
                return CS_EXIT_OUTPUT;
        }
    }
    if (!j->what.usd)
        return CS_EXIT_OK;
    for (int c = 0; c < j->ncloths; c++) {
        snprintf(path, sizeof path, "%s/cloth.usda.%d.tmp", j->dir, c);
        if (!(j->samples[c] = strdup(path))) {
            cs_errorf(err, errlen, "out of memory");
            return CS_EXIT_OUTPUT;
        }
        if (!(j->sample_fp[c] = fopen(path, "w"))) {
            cs_errorf(err, errlen, "cannot write %s: %s", path, strerror(errno));
            return CS_EXIT_OUTPUT;
        }
    }
    return CS_EXIT_OK;
}

/* Frame f of every cloth into the caches and sample files. */
static int add_frame(job *j, const cs_frame_layout *layout, const char *frames_dir, int f,
                     cs_trimesh **meshes, char *err, size_t errlen)
{
    int status = cs_frame_read(layout, frames_dir, f, meshes, err, errlen);
    for (int c = 0; c < j->ncloths && status == CS_EXIT_OK; c++) {
        const cs_trimesh *scene_mesh = j->scene->def.cloths[c].mesh, *m = meshes[c];
        if (!m || m->nv != scene_mesh->nv || m->nt != scene_mesh->nt) {
            cs_errorf(err, errlen, "frame %d of %s does not hold the scene's cloth '%s' "
                      "(vertex or triangle counts differ): the scene changed since the run", f,
                      j->dir, layout->names[c]);
            status = CS_EXIT_INPUT;
            break;
        }
        /* the points and triangles as the file holds them: a format may
         * order the vertices its own way (OBJ), the same in every frame */
        size_t tri_bytes = 3 * sizeof *m->tri * (size_t)m->nt;
        if (f == 0 && (j->tri[c] = malloc(tri_bytes + 1)))
            memcpy(j->tri[c], m->tri, tri_bytes);
        if (!j->tri[c]) {
            cs_errorf(err, errlen, "out of memory");
            status = CS_EXIT_OUTPUT;
            break;
        }
        if (memcmp(j->tri[c], m->tri, tri_bytes) != 0) {
            cs_errorf(err, errlen, "frame %d of %s: cloth '%s' has other triangles than in "
                      "frame 0", f, j->dir, layout->names[c]);
            status = CS_EXIT_INPUT;
            break;
        }
        for (int i = 0; i < 3 * m->nv; i++)
            j->xf[i] = (float)m->x[i]; /* exact: the frame files hold float32 */
        if (j->what.usd)
            cs_usd_points_sample(j->sample_fp[c], f, m->nv, j->xf);
        if (j->what.pc2) {
            cs_pc2_add(&j->pc2[c], j->xf);
            char path[4096];
            snprintf(path, sizeof path, "%s/pc2/%s.obj", j->dir, cloth_name(j, c));
            if (f == 0 && cs_rest_obj_write(path, cloth_name(j, c), m->nv, j->xf, m->nt,
                                            j->tri[c], err, errlen) != 0)
                status = CS_EXIT_OUTPUT;
        }
    }
    for (int c = 0; c < j->ncloths; c++) {
        cs_trimesh_destroy(meshes[c]);
        meshes[c] = NULL;
    }
    return status;
}

/* ------------------------------------------------------------ cloth.usda */

/* A body's triangles in its own frame, as render draws them (the mesh a
 * mesh body was made from; analytic shapes tessellated; a plane a square
 * reaching well past the cloth). NULL for a body with nothing to draw or
 * without memory. */
static cs_trimesh *body_local_mesh(const cs_scene *s, int b)
{
    const cs_body_def *body = &s->def.bodies[b];
    if (s->mesh_bodies && s->mesh_bodies[b].mesh) {
        const cs_trimesh *m = s->mesh_bodies[b].mesh;
        cs_trimesh *copy = cs_trimesh_create(m->nv, m->nt);
        if (copy) {
            memcpy(copy->x, m->x, 3 * sizeof *m->x * (size_t)m->nv);
            memcpy(copy->tri, m->tri, 3 * sizeof *m->tri * (size_t)m->nt);
        }
        return copy;
    }
    cs_body_def local = *body;
    local.motion = cs_motion_static();
    double extent = 1.0, o[3];
    cs_motion_pose(&body->motion, 0.0, NULL, o, NULL, NULL);
    for (int c = 0; c < s->def.ncloths; c++) {
        const cs_trimesh *m = s->def.cloths[c].mesh;
        for (int v = 0; v < m->nv; v++) {
            double d = 0;
            for (int i = 0; i < 3; i++)
                d += (m->x[3 * v + i] - o[i]) * (m->x[3 * v + i] - o[i]);
            extent = fmax(extent, 4 * sqrt(d));
        }
    }
    return cs_body_def_tessellate(&local, 0.0, extent, BODY_DETAIL);
}

static void write_body(job *j, FILE *fp, int b, const cs_trimesh *m)
{
    const cs_scene *s = j->scene;
    const cs_body_def *body = &s->def.bodies[b];
    double R[9], c[3];
    cs_usd_begin_mesh(fp, j->prims[j->ncloths + b], body->name ? body->name : "", m->nt, m->tri,
                      s->body_colors + 3 * b);
    cs_usd_points(fp, m->nv, m->x);
    if (body->motion.kind == CS_MOTION_STATIC) {
        cs_motion_pose(&body->motion, 0.0, R, c, NULL, NULL);
        cs_usd_transform(fp, R, c);
    } else {
        cs_usd_begin_transform_samples(fp);
        for (int f = 0; f < j->nframes; f++) {
            cs_motion_pose(&body->motion, f / j->fps, R, c, NULL, NULL);
            cs_usd_transform_sample(fp, f, R, c);
        }
        cs_usd_end_samples(fp);
    }
    cs_usd_transform_order(fp);
    cs_usd_end_mesh(fp);
}

/* Copies the file at path into fp; false when it cannot be read. */
static bool copy_file(const char *path, FILE *fp)
{
    FILE *in = fopen(path, "r");
    if (!in)
        return false;
    char buf[1 << 16];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, in)) > 0)
        fwrite(buf, 1, n, fp);
    bool ok = !ferror(in);
    fclose(in);
    return ok;
}

static int fill_usd(const char *tmp, void *ctx, char *why, size_t whylen)
{
    job *j = ctx;
    const cs_scene *s = j->scene;
    FILE *fp = cs_file_open_checked(tmp, "w", why, whylen);
    if (!fp)
        return -1;
    char root[PRIM_NAME];
    cs_usd_identifier(s->name, "scene", NULL, 0, root, sizeof root);
    cs_usd_stage stage = {root, cs_export_up_axis(s), j->fps, 0, j->nframes - 1};
    cs_usd_begin_stage(fp, &stage);
    bool ok = true;
    for (int c = 0; c < j->ncloths && ok; c++) {
        cs_usd_begin_mesh(fp, j->prims[c], s->def.cloths[c].name ? s->def.cloths[c].name : "",
                          s->def.cloths[c].mesh->nt, j->tri[c], s->cloth_colors + 3 * c);
        cs_usd_begin_points_samples(fp);
        ok = copy_file(j->samples[c], fp);
        cs_usd_end_samples(fp);
        cs_usd_end_mesh(fp);
        if (!ok)
            cs_errorf(why, whylen, "cannot read back %s: %s", j->samples[c], strerror(errno));
    }
    for (int b = 0; b < j->nbodies && ok; b++) {
        cs_trimesh *m = body_local_mesh(s, b);
        if (m) /* a body given only by its distance function has nothing to draw */
            write_body(j, fp, b, m);
        cs_trimesh_destroy(m);
    }
    cs_usd_end_stage(fp);
    if (!ok) {
        fclose(fp);
        return -1;
    }
    return cs_file_close_checked(fp, why, whylen);
}

/* The sample files closed, checked, and joined into cloth.usda. */
static int finish_usd(job *j, char *err, size_t errlen)
{
    for (int c = 0; c < j->ncloths; c++) {
        char why[256];
        FILE *fp = j->sample_fp[c];
        j->sample_fp[c] = NULL;
        if (cs_file_close_checked(fp, why, sizeof why) != 0) {
            cs_errorf(err, errlen, "cannot write %s: %s", j->samples[c], why);
            return CS_EXIT_OUTPUT;
        }
    }
    if (cs_write_atomic(j->usd_path, false, fill_usd, j, err, errlen) != 0)
        return CS_EXIT_OUTPUT;
    return CS_EXIT_OK;
}

/* ------------------------------------------------------------------ main */

int cs_export_run(const cs_scene *scene, cs_mesh_format format, const char *dir, int nframes,
                  double fps, cs_export_what what, FILE *out, char *err, size_t errlen)
{
    job j = {.scene = scene, .dir = dir, .nframes = nframes, .fps = fps > 0 ? fps : 24,
             .what = what, .ncloths = scene->def.ncloths, .nbodies = scene->def.nbodies};
    if (nframes < 1) {
        cs_errorf(err, errlen, "%s holds no frame to export", dir);
        return CS_EXIT_INPUT;
    }
    size_t n = (size_t)j.ncloths + 1;
    int maxnv = 0;
    for (int c = 0; c < j.ncloths; c++)
        if (scene->def.cloths[c].mesh->nv > maxnv)
            maxnv = scene->def.cloths[c].mesh->nv;
    j.prims = calloc(n + (size_t)j.nbodies, sizeof *j.prims);
    j.samples = calloc(n, sizeof *j.samples);
    j.sample_fp = calloc(n, sizeof *j.sample_fp);
    j.pc2 = calloc(n, sizeof *j.pc2);
    j.tri = calloc(n, sizeof *j.tri);
    j.xf = malloc(3 * sizeof *j.xf * ((size_t)maxnv + 1));
    j.usd_path = cs_path_join(dir, "cloth.usda");
    const char **names = calloc(n, sizeof *names);
    cs_trimesh **meshes = calloc(n, sizeof *meshes);
    cs_frame_layout layout;
    memset(&layout, 0, sizeof layout);
    for (int c = 0; names && c < j.ncloths; c++)
        names[c] = scene->def.cloths[c].name;
    int status = CS_EXIT_OK;
    if (!j.prims || !j.samples || !j.sample_fp || !j.pc2 || !j.tri || !j.xf || !j.usd_path || !names ||
        !meshes || cs_frame_layout_init(&layout, format, j.ncloths, names) != 0) {
        cs_errorf(err, errlen, "out of memory");
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    name_prims(&j);
    char *frames_dir = cs_path_join(dir, "frames");
    if (!frames_dir) {
        cs_errorf(err, errlen, "out of memory");
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    status = open_outputs(&j, err, errlen);
    for (int f = 0; f < nframes && status == CS_EXIT_OK; f++)
        status = add_frame(&j, &layout, frames_dir, f, meshes, err, errlen);
    free(frames_dir);
    if (status == CS_EXIT_OK && what.usd && (status = finish_usd(&j, err, errlen)) == CS_EXIT_OK &&
        out)
        fprintf(out, "wrote %s: %d cloth%s, %d bod%s, time codes 0 to %d at %g per second\n",
                j.usd_path, j.ncloths, j.ncloths == 1 ? "" : "s", j.nbodies,
                j.nbodies == 1 ? "y" : "ies", nframes - 1, j.fps);
    for (int c = 0; c < j.ncloths && status == CS_EXIT_OK && what.pc2; c++) {
        if (cs_pc2_close(&j.pc2[c], err, errlen) != 0)
            status = CS_EXIT_OUTPUT;
        else if (out)
            fprintf(out, "wrote %s/pc2/%s.pc2 (%d samples from frame 0) and its rest pose "
                         "%s/pc2/%s.obj (frame 0)\n",
                    dir, cloth_name(&j, c), nframes, dir, cloth_name(&j, c));
    }
done:
    job_free(&j);
    cs_frame_layout_free(&layout);
    free(names);
    free(meshes);
    return status;
}
