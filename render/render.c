/* render.c: settings, input checks common to both engines, vertex normals,
 * and the renderer object that hands a prepared scene to an engine. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/internal.h"
#include "common/util.h"

struct cs_renderer {
    cs_render_settings settings;
    cs_embree *embree;
    cs_preview *preview;
};

cs_render_settings cs_render_default_settings(void)
{
    cs_render_settings s;
    memset(&s, 0, sizeof s);
    s.engine = CS_RENDER_EMBREE;
    s.width = 640;
    s.height = 480;
    s.samples = 16;
    s.bounces = 2;
    s.threads = 0;
    return s;
}

bool cs_render_engine_from_name(const char *name, cs_render_engine *engine)
{
    cs_render_engine e;
    if (!name)
        return false;
    if (strcmp(name, "embree") == 0)
        e = CS_RENDER_EMBREE;
    else if (strcmp(name, "preview") == 0)
        e = CS_RENDER_PREVIEW;
    else
        return false;
    if (engine)
        *engine = e;
    return true;
}

const char *cs_render_engine_name(cs_render_engine engine)
{
    return engine == CS_RENDER_PREVIEW ? "preview" : "embree";
}

int cs_render_settings_check(const cs_render_settings *s, char *err, size_t errlen)
{
    if (s->engine != CS_RENDER_EMBREE && s->engine != CS_RENDER_PREVIEW) {
        cs_render_error(err, errlen, "unknown render engine %d", (int)s->engine);
        return CS_ERR_BAD_INPUT;
    }
    if (s->width < 1 || s->height < 1 || s->width > CS_RENDER_MAX_SIZE ||
        s->height > CS_RENDER_MAX_SIZE) {
        cs_render_error(err, errlen, "image size %dx%d: each side must be 1 to %d pixels",
                        s->width, s->height, CS_RENDER_MAX_SIZE);
        return CS_ERR_BAD_INPUT;
    }
    if (s->samples < 1 || s->samples > CS_RENDER_MAX_SAMPLES) {
        cs_render_error(err, errlen, "samples per pixel must be 1 to %d (got %d)",
                        CS_RENDER_MAX_SAMPLES, s->samples);
        return CS_ERR_BAD_INPUT;
    }
    if (s->bounces < 0 || s->bounces > 16) {
        cs_render_error(err, errlen, "bounces must be 0 to 16 (got %d)", s->bounces);
        return CS_ERR_BAD_INPUT;
    }
    if (s->threads < 0 || s->threads > 1024) {
        cs_render_error(err, errlen, "threads must be 0 (all cores) to 1024 (got %d)",
                        s->threads);
        return CS_ERR_BAD_INPUT;
    }
    return CS_OK;
}

cs_renderer *cs_renderer_create(const cs_render_settings *settings, char *err, size_t errlen)
{
    if (!settings) {
        cs_render_error(err, errlen, "no render settings given");
        return NULL;
    }
    if (cs_render_settings_check(settings, err, errlen) != CS_OK)
        return NULL;
    cs_renderer *r = calloc(1, sizeof *r);
    if (!r) {
        cs_render_error(err, errlen, "out of memory");
        return NULL;
    }
    r->settings = *settings;
    if (settings->engine == CS_RENDER_EMBREE)
        r->embree = cs_embree_create(settings, err, errlen);
    else
        r->preview = cs_preview_create(settings, err, errlen);
    if (!r->embree && !r->preview) {
        free(r);
        return NULL;
    }
    return r;
}

void cs_renderer_destroy(cs_renderer *r)
{
    if (!r)
        return;
    cs_embree_destroy(r->embree);
    cs_preview_destroy(r->preview);
    free(r);
}

/* ------------------------------------------------------------ input checks */

static const char *mesh_name(const cs_render_mesh *m, int index, char *buf, size_t len)
{
    if (m->name && *m->name)
        snprintf(buf, len, "'%s'", m->name);
    else
        snprintf(buf, len, "%d", index);
    return buf;
}

static int check_mesh(const cs_render_mesh *m, int index, char *err, size_t errlen)
{
    char name[96];
    mesh_name(m, index, name, sizeof name);
    if (m->nv < 1 || !m->x) {
        cs_render_error(err, errlen, "mesh %s has no vertices", name);
        return CS_ERR_BAD_INPUT;
    }
    if (m->nt < 1 || !m->tri) {
        cs_render_error(err, errlen, "mesh %s has no triangles to draw", name);
        return CS_ERR_BAD_INPUT;
    }
    for (int c = 0; c < 3; c++)
        if (!(m->color[c] >= 0 && m->color[c] <= 1)) {
            cs_render_error(err, errlen, "mesh %s: colour component %g is not in [0, 1]", name,
                            m->color[c]);
            return CS_ERR_BAD_INPUT;
        }
    for (size_t i = 0; i < 3 * (size_t)m->nv; i++)
        if (!isfinite(m->x[i])) {
            cs_render_error(err, errlen, "mesh %s: vertex %zu has a non-finite coordinate", name,
                            i / 3);
            return CS_ERR_BAD_INPUT;
        }
    for (size_t i = 0; i < 3 * (size_t)m->nt; i++)
        if (m->tri[i] < 0 || m->tri[i] >= m->nv) {
            cs_render_error(err, errlen,
                            "mesh %s: triangle %zu uses vertex %d of %d (out of range)", name,
                            i / 3, m->tri[i], m->nv);
            return CS_ERR_BAD_INPUT;
        }
    return CS_OK;
}

/* Crossings of the ray eye + t d (t > 0) with the mesh (Moeller-Trumbore in
 * double precision). */
static int crossings(const cs_render_mesh *m, const double eye[3], const double d[3])
{
    int n = 0;
    for (int t = 0; t < m->nt; t++) {
        const double *a = m->x + 3 * (size_t)m->tri[3 * t];
        const double *b = m->x + 3 * (size_t)m->tri[3 * t + 1];
        const double *c = m->x + 3 * (size_t)m->tri[3 * t + 2];
        double e1[3], e2[3], p[3], s[3], q[3];
        for (int i = 0; i < 3; i++) {
            e1[i] = b[i] - a[i];
            e2[i] = c[i] - a[i];
            s[i] = eye[i] - a[i];
        }
        p[0] = d[1] * e2[2] - d[2] * e2[1];
        p[1] = d[2] * e2[0] - d[0] * e2[2];
        p[2] = d[0] * e2[1] - d[1] * e2[0];
        double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
        if (fabs(det) < 1e-300)
            continue;
        double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
        if (u < 0 || u > 1)
            continue;
        q[0] = s[1] * e1[2] - s[2] * e1[1];
        q[1] = s[2] * e1[0] - s[0] * e1[2];
        q[2] = s[0] * e1[1] - s[1] * e1[0];
        double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
        if (v < 0 || u + v > 1)
            continue;
        double tt = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
        if (tt > 0)
            n++;
    }
    return n;
}

/* Inside a closed mesh by the parity of crossings along three skew
 * directions, two of three deciding (a ray through an edge can miscount). */
static bool inside_closed(const cs_render_mesh *m, const double eye[3])
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int v = 0; v < m->nv; v++)
        for (int i = 0; i < 3; i++) {
            lo[i] = fmin(lo[i], m->x[3 * (size_t)v + i]);
            hi[i] = fmax(hi[i], m->x[3 * (size_t)v + i]);
        }
    for (int i = 0; i < 3; i++)
        if (eye[i] < lo[i] || eye[i] > hi[i])
            return false;
    static const double dirs[3][3] = {
        {0.5773, 0.6127, 0.5398}, {-0.7071, 0.1234, 0.6963}, {0.1111, -0.9412, 0.3189}};
    int odd = 0;
    for (int k = 0; k < 3; k++)
        odd += crossings(m, eye, dirs[k]) & 1;
    return odd >= 2;
}

static void vertex_normals(const cs_render_mesh *m, float *n)
{
    double *acc = calloc(3 * (size_t)m->nv, sizeof *acc);
    if (acc) {
        for (int t = 0; t < m->nt; t++) {
            const int *v = m->tri + 3 * (size_t)t;
            const double *a = m->x + 3 * (size_t)v[0];
            const double *b = m->x + 3 * (size_t)v[1];
            const double *c = m->x + 3 * (size_t)v[2];
            double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            /* The cross product's length is twice the area: area weights. */
            double f[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                           e1[0] * e2[1] - e1[1] * e2[0]};
            for (int k = 0; k < 3; k++)
                for (int i = 0; i < 3; i++)
                    acc[3 * (size_t)v[k] + i] += f[i];
        }
    }
    for (int v = 0; v < m->nv; v++) {
        double *a = acc ? acc + 3 * (size_t)v : NULL;
        double len = a ? sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) : 0;
        for (int i = 0; i < 3; i++)
            n[3 * (size_t)v + i] = len > 0 ? (float)(a[i] / len) : 0.0f;
    }
    free(acc);
}

static void free_prepared(cs_prepared_scene *p)
{
    if (p->meshes)
        for (int m = 0; m < p->nmeshes; m++)
            free(p->meshes[m].normals);
    free(p->meshes);
}

int cs_renderer_draw(cs_renderer *r, int nmeshes, const cs_render_mesh *meshes,
                     const cs_render_camera *camera, cs_image *image, cs_render_stats *stats,
                     char *err, size_t errlen)
{
    double t0 = cs_now();
    cs_render_stats local;
    if (!stats)
        stats = &local;
    memset(stats, 0, sizeof *stats);
    if (!r || !image || !image->rgb || !image->coverage) {
        cs_render_error(err, errlen, "cs_renderer_draw: no renderer or no image");
        return CS_ERR_FAILED;
    }
    if (image->width != r->settings.width || image->height != r->settings.height) {
        cs_render_error(err, errlen, "image is %dx%d, the renderer draws %dx%d", image->width,
                        image->height, r->settings.width, r->settings.height);
        return CS_ERR_FAILED;
    }
    if (nmeshes < 1 || !meshes) {
        cs_render_error(err, errlen, "nothing to draw: no meshes given");
        return CS_ERR_BAD_INPUT;
    }
    int rc;
    for (int m = 0; m < nmeshes; m++)
        if ((rc = check_mesh(&meshes[m], m, err, errlen)) != CS_OK)
            return rc;
    if ((rc = cs_render_camera_check(camera, err, errlen)) != CS_OK)
        return rc;
    for (int m = 0; m < nmeshes; m++) {
        if (meshes[m].closed && inside_closed(&meshes[m], camera->position)) {
            char name[96];
            cs_render_error(err, errlen, "the camera at (%g, %g, %g) is inside mesh %s",
                            camera->position[0], camera->position[1], camera->position[2],
                            mesh_name(&meshes[m], m, name, sizeof name));
            return CS_ERR_BAD_INPUT;
        }
    }

    cs_prepared_scene p;
    memset(&p, 0, sizeof p);
    p.nmeshes = nmeshes;
    p.meshes = calloc((size_t)nmeshes, sizeof *p.meshes);
    if (!p.meshes) {
        cs_render_error(err, errlen, "out of memory");
        return CS_ERR_NOMEM;
    }
    for (int i = 0; i < 3; i++) {
        p.lo[i] = INFINITY;
        p.hi[i] = -INFINITY;
    }
    for (int m = 0; m < nmeshes; m++) {
        const cs_render_mesh *mesh = &meshes[m];
        p.meshes[m].mesh = mesh;
        p.meshes[m].normals = malloc(3 * (size_t)mesh->nv * sizeof(float));
        if (!p.meshes[m].normals) {
            free_prepared(&p);
            cs_render_error(err, errlen, "out of memory for the normals of %d vertices",
                            mesh->nv);
            return CS_ERR_NOMEM;
        }
        vertex_normals(mesh, p.meshes[m].normals);
        for (int v = 0; v < mesh->nv; v++)
            for (int i = 0; i < 3; i++) {
                p.lo[i] = fmin(p.lo[i], mesh->x[3 * (size_t)v + i]);
                p.hi[i] = fmax(p.hi[i], mesh->x[3 * (size_t)v + i]);
            }
    }

    if (r->embree)
        rc = cs_embree_draw(r->embree, &p, camera, image, stats, err, errlen);
    else
        rc = cs_preview_draw(r->preview, &p, camera, image, stats, err, errlen);
    free_prepared(&p);
    stats->seconds = cs_now() - t0;
    if (rc == CS_OK && stats->covered == 0) {
        cs_render_error(err, errlen,
                        "the camera sees nothing: no mesh is in its view (camera at (%g, %g, "
                        "%g) looking at (%g, %g, %g))",
                        camera->position[0], camera->position[1], camera->position[2],
                        camera->target[0], camera->target[1], camera->target[2]);
        return CS_ERR_BAD_INPUT;
    }
    return rc;
}

int cs_render_png(const char *path, int nmeshes, const cs_render_mesh *meshes,
                  const cs_render_camera *camera, const cs_render_settings *settings, char *err,
                  size_t errlen)
{
    if (!settings) {
        cs_render_error(err, errlen, "no render settings given");
        return CS_ERR_FAILED;
    }
    int rc = cs_render_settings_check(settings, err, errlen);
    if (rc != CS_OK)
        return rc;
    cs_image *img = cs_image_create(settings->width, settings->height);
    if (!img) {
        cs_render_error(err, errlen, "out of memory for a %dx%d image", settings->width,
                        settings->height);
        return CS_ERR_NOMEM;
    }
    cs_renderer *r = cs_renderer_create(settings, err, errlen);
    if (!r) {
        cs_image_destroy(img);
        return CS_ERR_FAILED;
    }
    rc = cs_renderer_draw(r, nmeshes, meshes, camera, img, NULL, err, errlen);
    if (rc == CS_OK)
        rc = cs_image_write_png(img, path, err, errlen);
    cs_renderer_destroy(r);
    cs_image_destroy(img);
    return rc;
}
