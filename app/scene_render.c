/* scene_render.c: a scene as render/ meshes; see scene_render.h. */
#include "app/scene_render.h"

#include "app/outdir.h"
#include "app/run.h"
#include "common/util.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

enum { BODY_NONE = 0, BODY_ANALYTIC, BODY_MESH };

/* Segments around spheres and cylinders: silhouettes stay within half a
 * pixel of the true curve for a ball a third of a 1280x720 frame high. */
#define BODY_DETAIL 64

struct cs_scene_render {
    const cs_scene *scene;
    cs_render_settings settings;
    cs_renderer *renderer;
    cs_render_camera camera;
    char *drawable;             /* per body: BODY_NONE, BODY_ANALYTIC, BODY_MESH */
    double edge;                /* longest cloth edge at rest, m */
};

/* out = c + R p: a point of a moving frame (cs_motion_pose) in the world. */
static void posed(const double R[9], const double c[3], const double p[3], double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = c[i] + R[3 * i] * p[0] + R[3 * i + 1] * p[1] + R[3 * i + 2] * p[2];
}

/* The body as drawn: a little smaller than the one the cloth collides with.
 * Cloth vertices rest on the true surface, but a flat triangle between them
 * is a chord that dips into a curved body by up to L^2 / (8 r), and the
 * body's own facets lie inside it by r (1 - cos(pi / n)); without the
 * margin the body shows through the cloth in a pattern of dots. */
static cs_body_def drawn_body(const cs_body_def *b, double edge)
{
    cs_body_def d = *b;
    double chord;
    switch (b->shape) {
    case CS_BODY_SPHERE:
    case CS_BODY_CYLINDER:
        chord = 1.2 * edge * 1.2 * edge / (8 * b->radius);
        d.radius -= fmin(3 * chord + b->radius * (1 - cos(M_PI / BODY_DETAIL)), 0.2 * b->radius);
        if (b->shape == CS_BODY_CYLINDER)
            d.half_height -= fmin(0.1 * edge, 0.2 * b->half_height);
        break;
    case CS_BODY_BOX: {
        double h = fmin(b->half_extents[0], fmin(b->half_extents[1], b->half_extents[2]));
        for (int i = 0; i < 3; i++)
            d.half_extents[i] -= fmin(0.1 * edge, 0.2 * h);
        break;
    }
    default:
        break;
    }
    return d;
}

static const char *body_name(const cs_scene *s, int b, char *buf, size_t len)
{
    const char *n = s->def.bodies[b].name;
    if (n && *n)
        return n;
    snprintf(buf, len, "body%d", b);
    return buf;
}

static const char *cloth_name(const cs_scene *s, int c, char *buf, size_t len)
{
    const char *n = s->def.cloths[c].name;
    if (n && *n)
        return n;
    snprintf(buf, len, "cloth%d", c);
    return buf;
}

static void grow(double lo[3], double hi[3], const double p[3])
{
    for (int i = 0; i < 3; i++) {
        lo[i] = fmin(lo[i], p[i]);
        hi[i] = fmax(hi[i], p[i]);
    }
}

static void grow_mesh(double lo[3], double hi[3], int nv, const double *x)
{
    for (int v = 0; v < nv; v++)
        grow(lo, hi, x + 3 * (size_t)v);
}

static bool is_plane(const cs_scene_render *sr, int b)
{
    return sr->drawable[b] == BODY_ANALYTIC && sr->scene->def.bodies[b].shape == CS_BODY_PLANE;
}

/* A solid body (not a plane) at time t in world coordinates: an analytic
 * shape tessellated (drawn a little smaller when `shrink`), or the mesh a
 * mesh body was made from, moved to its pose. NULL for planes, bodies with
 * nothing to draw, or no memory. */
static cs_trimesh *solid_at(const cs_scene_render *sr, int b, double t, int detail, bool shrink)
{
    const cs_body_def *body = &sr->scene->def.bodies[b];
    if (sr->drawable[b] == BODY_ANALYTIC && body->shape != CS_BODY_PLANE) {
        cs_body_def drawn = shrink ? drawn_body(body, sr->edge) : *body;
        return cs_body_def_tessellate(&drawn, t, 0, detail);
    }
    if (sr->drawable[b] != BODY_MESH)
        return NULL;
    const cs_trimesh *local = sr->scene->mesh_bodies[b].mesh;
    cs_trimesh *m = cs_trimesh_create(local->nv, local->nt);
    if (!m)
        return NULL;
    double R[9], c[3];
    cs_motion_pose(&body->motion, t, R, c, NULL, NULL);
    for (int v = 0; v < local->nv; v++)
        posed(R, c, local->x + 3 * (size_t)v, m->x + 3 * (size_t)v);
    memcpy(m->tri, local->tri, 3 * (size_t)local->nt * sizeof *m->tri);
    return m;
}

/* Bounds of the cloths and the drawable solid bodies at time t. */
static bool content_bounds(const cs_scene_render *sr, double t, const cs_frame_cloths *cloths,
                           double lo[3], double hi[3])
{
    const cs_scene *s = sr->scene;
    for (int i = 0; i < 3; i++) {
        lo[i] = INFINITY;
        hi[i] = -INFINITY;
    }
    if (cloths->x) {
        for (int c = 0; c < s->def.ncloths; c++)
            grow_mesh(lo, hi, s->def.cloths[c].mesh->nv, cloths->x[c]);
    } else if (cloths->meshes) {
        for (int c = 0; c < s->def.ncloths; c++)
            grow_mesh(lo, hi, cloths->meshes[c]->nv, cloths->meshes[c]->x);
    } else if (cloths->merged) {
        grow_mesh(lo, hi, cloths->merged->nv, cloths->merged->x);
    }
    for (int b = 0; b < s->def.nbodies; b++) {
        cs_trimesh *m = solid_at(sr, b, t, 16, false);
        if (m)
            grow_mesh(lo, hi, m->nv, m->x);
        cs_trimesh_destroy(m);
    }
    return lo[0] <= hi[0];
}

cs_scene_render *cs_scene_render_create(const cs_scene *scene,
                                        const cs_render_settings *settings, FILE *warn,
                                        char *err, size_t errlen, int *status)
{
    char name[64];
    *status = CS_EXIT_INPUT;
    for (int c = 0; c < scene->def.ncloths; c++) {
        const cs_trimesh *m = scene->def.cloths[c].mesh;
        if (!m || m->nt < 1) {
            snprintf(err, errlen,
                     "%s: cloth '%s' has no triangles, so there is nothing to render "
                     "(a mesh without triangles is a set of free particles)",
                     scene->path, cloth_name(scene, c, name, sizeof name));
            return NULL;
        }
    }
    if (cs_render_settings_check(settings, err, errlen) != CS_OK)
        return NULL;

    cs_scene_render *sr = calloc(1, sizeof *sr);
    if (sr)
        sr->drawable = calloc((size_t)scene->def.nbodies + 1, sizeof *sr->drawable);
    if (!sr || !sr->drawable) {
        free(sr);
        snprintf(err, errlen, "out of memory");
        *status = CS_EXIT_OUTPUT;
        return NULL;
    }
    sr->scene = scene;
    sr->settings = *settings;
    for (int c = 0; c < scene->def.ncloths; c++) {
        const cs_trimesh *m = scene->def.cloths[c].mesh;
        for (int t = 0; t < 3 * m->nt; t++) {
            const double *a = m->x + 3 * m->tri[t];
            const double *b = m->x + 3 * m->tri[t - t % 3 + (t + 1) % 3];
            double d2 = 0;
            for (int i = 0; i < 3; i++)
                d2 += (a[i] - b[i]) * (a[i] - b[i]);
            sr->edge = fmax(sr->edge, sqrt(d2));
        }
    }
    for (int b = 0; b < scene->def.nbodies; b++) {
        const cs_body_def *body = &scene->def.bodies[b];
        const cs_trimesh *mesh = scene->mesh_bodies ? scene->mesh_bodies[b].mesh : NULL;
        if (!body->phi_fn && body->shape >= CS_BODY_PLANE && body->shape <= CS_BODY_CYLINDER)
            sr->drawable[b] = BODY_ANALYTIC;
        else if (mesh && mesh->nt > 0)
            sr->drawable[b] = BODY_MESH;
        else if (warn)
            fprintf(warn, "clothsim: body '%s' has no shape or mesh to draw; it is left out "
                          "of the images\n",
                    body_name(scene, b, name, sizeof name));
    }

    if (scene->camera.given) {
        memcpy(sr->camera.position, scene->camera.position, sizeof sr->camera.position);
        memcpy(sr->camera.target, scene->camera.target, sizeof sr->camera.target);
        memcpy(sr->camera.up, scene->camera.up, sizeof sr->camera.up);
        sr->camera.fov_degrees = scene->camera.fov_degrees;
    } else {
        /* Frame the initial state and its footprint on every ground plane,
         * so cloth that falls to the ground stays in view. */
        const double **x0 = calloc((size_t)scene->def.ncloths + 1, sizeof *x0);
        if (!x0) {
            cs_scene_render_destroy(sr);
            snprintf(err, errlen, "out of memory");
            *status = CS_EXIT_OUTPUT;
            return NULL;
        }
        for (int c = 0; c < scene->def.ncloths; c++)
            x0[c] = scene->def.cloths[c].mesh->x;
        cs_frame_cloths initial = {.x = x0};
        double lo[3], hi[3];
        content_bounds(sr, 0.0, &initial, lo, hi);
        free(x0);
        double box[8][3];
        for (int k = 0; k < 8; k++)
            for (int i = 0; i < 3; i++)
                box[k][i] = (k >> i) & 1 ? hi[i] : lo[i];
        for (int b = 0; b < scene->def.nbodies; b++) {
            const cs_body_def *body = &scene->def.bodies[b];
            if (!is_plane(sr, b))
                continue;
            double R[9], o[3];
            cs_motion_pose(&body->motion, 0.0, R, o, NULL, NULL);
            double n[3] = {R[1], R[4], R[7]};   /* R times local +y */
            for (int k = 0; k < 8; k++) {
                double d = 0, p[3];
                for (int i = 0; i < 3; i++)
                    d += (box[k][i] - o[i]) * n[i];
                for (int i = 0; i < 3; i++)
                    p[i] = box[k][i] - d * n[i];
                grow(lo, hi, p);
            }
        }
        sr->camera = cs_render_camera_frame(lo, hi, (double)settings->width / settings->height);
    }
    if (cs_render_camera_check(&sr->camera, err, errlen) != CS_OK) {
        cs_scene_render_destroy(sr);
        return NULL;
    }
    sr->renderer = cs_renderer_create(settings, err, errlen);
    if (!sr->renderer) {
        cs_scene_render_destroy(sr);
        *status = CS_EXIT_OUTPUT;
        return NULL;
    }
    *status = CS_EXIT_OK;
    return sr;
}

void cs_scene_render_destroy(cs_scene_render *sr)
{
    if (!sr)
        return;
    cs_renderer_destroy(sr->renderer);
    free(sr->drawable);
    free(sr);
}

const double *cs_scene_render_up(const cs_scene_render *sr) { return sr->camera.up; }

cs_render_camera cs_scene_render_camera(const cs_scene_render *sr, double t)
{
    cs_render_camera cam = sr->camera;
    const cs_camera_def *def = &sr->scene->camera;
    if (!def->given || def->motion.kind == CS_MOTION_STATIC)
        return cam;
    /* the motion's frame starts at the target with no rotation */
    double R[9], c[3], rel[3];
    cs_motion_pose(&def->motion, t, R, c, NULL, NULL);
    for (int i = 0; i < 3; i++)
        rel[i] = def->position[i] - def->target[i];
    memcpy(cam.target, c, sizeof cam.target);
    posed(R, c, rel, cam.position);
    posed(R, (const double[3]){0, 0, 0}, def->up, cam.up);
    return cam;
}

void cs_scene_render_centre(const cs_scene_render *sr, double t, const cs_frame_cloths *cloths,
                            double centre[3])
{
    double lo[3], hi[3];
    if (!content_bounds(sr, t, cloths, lo, hi)) {
        cs_render_camera cam = cs_scene_render_camera(sr, t);
        memcpy(centre, cam.target, 3 * sizeof *centre);
        return;
    }
    for (int i = 0; i < 3; i++)
        centre[i] = 0.5 * (lo[i] + hi[i]);
}

int cs_scene_render_draw(cs_scene_render *sr, double t, const cs_frame_cloths *cloths,
                         const cs_render_camera *camera, cs_image *image,
                         cs_render_stats *stats, char *err, size_t errlen)
{
    const cs_scene *s = sr->scene;
    cs_render_camera at_t;
    if (!camera) {
        at_t = cs_scene_render_camera(sr, t);
        camera = &at_t;
    }
    char name[64];

    /* A camera inside a body would see its inside or nothing: say which. */
    for (int b = 0; b < s->def.nbodies; b++) {
        double g[3];
        if (cs_body_def_phi(&s->def.bodies[b], t, camera->position, g) < 0) {
            bool plane = s->def.bodies[b].shape == CS_BODY_PLANE && !s->def.bodies[b].phi_fn;
            snprintf(err, errlen, "the camera at (%g, %g, %g) is %s body '%s' at t=%g s",
                     camera->position[0], camera->position[1], camera->position[2],
                     plane ? "below the plane of" : "inside", body_name(s, b, name, sizeof name),
                     t);
            return CS_EXIT_INPUT;
        }
    }

    int ncloth = cloths->x || cloths->meshes ? s->def.ncloths : 1;
    int cap = ncloth + s->def.nbodies;
    cs_render_mesh *meshes = calloc((size_t)cap, sizeof *meshes);
    cs_trimesh **bodies = calloc((size_t)s->def.nbodies + 1, sizeof *bodies);
    if (!meshes || !bodies) {
        free(meshes);
        free(bodies);
        snprintf(err, errlen, "out of memory");
        return CS_EXIT_OUTPUT;
    }
    int n = 0, status = CS_EXIT_OK;
    if (cloths->x || cloths->meshes) {
        for (int c = 0; c < s->def.ncloths; c++) {
            const cs_trimesh *m = cloths->x ? s->def.cloths[c].mesh : cloths->meshes[c];
            meshes[n] = (cs_render_mesh){.name = s->def.cloths[c].name, .nv = m->nv,
                                         .nt = m->nt, .x = cloths->x ? cloths->x[c] : m->x,
                                         .tri = m->tri, .two_sided = true};
            memcpy(meshes[n].color, s->cloth_colors + 3 * c, sizeof meshes[n].color);
            n++;
        }
    } else {
        const cs_trimesh *m = cloths->merged;
        meshes[n] = (cs_render_mesh){.name = "cloth", .nv = m->nv, .nt = m->nt, .x = m->x,
                                     .tri = m->tri, .two_sided = true};
        memcpy(meshes[n].color, s->cloth_colors, sizeof meshes[n].color);
        n++;
    }

    /* Solid bodies first: their bounds size the ground. */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int k = 0; k < n; k++)
        grow_mesh(lo, hi, meshes[k].nv, meshes[k].x);
    for (int b = 0; b < s->def.nbodies && status == CS_EXIT_OK; b++) {
        if (!sr->drawable[b] || is_plane(sr, b))
            continue;
        bodies[b] = solid_at(sr, b, t, BODY_DETAIL, true);
        if (!bodies[b]) {
            snprintf(err, errlen, "cannot tessellate body '%s' (out of memory)",
                     body_name(s, b, name, sizeof name));
            status = CS_EXIT_OUTPUT;
            break;
        }
        grow_mesh(lo, hi, bodies[b]->nv, bodies[b]->x);
    }
    double centre[3], radius = 0, cam_dist = 0;
    for (int i = 0; i < 3; i++) {
        centre[i] = 0.5 * (lo[i] + hi[i]);
        radius += 0.25 * (hi[i] - lo[i]) * (hi[i] - lo[i]);
        cam_dist += (camera->position[i] - centre[i]) * (camera->position[i] - centre[i]);
    }
    radius = sqrt(radius);
    cam_dist = sqrt(cam_dist);
    /* Planes: a square about the plane's origin reaching well past the
     * content and the camera, so its edge is rarely in view. */
    for (int b = 0; b < s->def.nbodies && status == CS_EXIT_OK; b++) {
        const cs_body_def *body = &s->def.bodies[b];
        if (!is_plane(sr, b))
            continue;
        double o[3], d = 0;
        cs_motion_pose(&body->motion, t, NULL, o, NULL, NULL);
        for (int i = 0; i < 3; i++)
            d += (o[i] - centre[i]) * (o[i] - centre[i]);
        double extent = sqrt(d) + fmax(fmax(8 * radius, 4 * cam_dist), 1.0);
        bodies[b] = cs_body_def_tessellate(body, t, extent, 0);
        if (!bodies[b]) {
            snprintf(err, errlen, "cannot tessellate body '%s' (out of memory)",
                     body_name(s, b, name, sizeof name));
            status = CS_EXIT_OUTPUT;
        }
    }
    for (int b = 0; b < s->def.nbodies && status == CS_EXIT_OK; b++) {
        if (!bodies[b])
            continue;
        bool plane = is_plane(sr, b);
        /* An imported mesh is a solid only if import found it closed. */
        bool closed = sr->drawable[b] == BODY_MESH ? s->mesh_bodies[b].report.closed : !plane;
        meshes[n] = (cs_render_mesh){.name = s->def.bodies[b].name, .nv = bodies[b]->nv,
                                     .nt = bodies[b]->nt, .x = bodies[b]->x,
                                     .tri = bodies[b]->tri, .closed = closed, .backdrop = plane};
        memcpy(meshes[n].color, s->body_colors + 3 * b, sizeof meshes[n].color);
        n++;
    }

    if (status == CS_EXIT_OK) {
        int rc = cs_renderer_draw(sr->renderer, n, meshes, camera, image, stats, err, errlen);
        if (rc == CS_ERR_BAD_INPUT)
            status = CS_EXIT_INPUT;
        else if (rc != CS_OK)
            status = CS_EXIT_OUTPUT;
    }
    for (int b = 0; b < s->def.nbodies; b++)
        cs_trimesh_destroy(bodies[b]);
    free(bodies);
    free(meshes);
    return status;
}

/* ------------------------------------------------------------- parsing */

int cs_parse_count(const char *text, const char *what, long lo, long hi, int *out, char *err,
                   size_t errlen)
{
    char *end;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (end == text || *end || errno == EINVAL) {
        snprintf(err, errlen, "%s: '%s' is not a whole number", what, text);
        return 1;
    }
    if (errno == ERANGE || v < lo || v > hi) {
        snprintf(err, errlen, "%s: %s is out of range (%ld to %ld)", what, text, lo, hi);
        return 2;
    }
    *out = (int)v;
    return 0;
}

int cs_parse_size(const char *text, int *width, int *height, char *err, size_t errlen)
{
    const char *x = strpbrk(text, "xX");
    char *end;
    if (!x || x == text || !x[1]) {
        snprintf(err, errlen, "--size: '%s' is not WIDTHxHEIGHT (e.g. 640x480)", text);
        return 1;
    }
    errno = 0;
    long w = strtol(text, &end, 10);
    if (end != x || text[0] == '-' || text[0] == '+') {
        snprintf(err, errlen, "--size: '%s' is not WIDTHxHEIGHT (e.g. 640x480)", text);
        return 1;
    }
    long h = strtol(x + 1, &end, 10);
    if (*end || x[1] == '-' || x[1] == '+' || x[1] == ' ') {
        snprintf(err, errlen, "--size: '%s' is not WIDTHxHEIGHT (e.g. 640x480)", text);
        return 1;
    }
    if (errno == ERANGE || w < 1 || h < 1 || w > CS_RENDER_MAX_SIZE || h > CS_RENDER_MAX_SIZE) {
        snprintf(err, errlen, "--size %s: each side must be 1 to %d pixels", text,
                 CS_RENDER_MAX_SIZE);
        return 2;
    }
    *width = (int)w;
    *height = (int)h;
    return 0;
}

/* ------------------------------------------------- clothsim run --render */

struct cs_run_render {
    cs_scene_render *sr;
    cs_image *image;
    char *images_dir;
    const double **x;
    int ncloths;
};

/* frame_<digits>.png (or .png.tmp): images of an earlier run. */
static bool is_frame_image(const char *name)
{
    if (strncmp(name, "frame_", 6) != 0)
        return false;
    const char *s = name + 6;
    if (*s < '0' || *s > '9')
        return false;
    while (*s >= '0' && *s <= '9')
        s++;
    return strcmp(s, ".png") == 0 || strcmp(s, ".png.tmp") == 0;
}

static void set_cloth_pointers(cs_run_render *rr, const cs_sim *sim)
{
    const double *x = cs_sim_positions(sim);
    for (int c = 0; c < rr->ncloths; c++)
        rr->x[c] = x + 3 * (size_t)cs_sim_cloth_offset(sim, c);
}

cs_run_render *cs_run_render_create(const cs_scene *scene, const cs_sim *sim,
                                    const char *engine, const char *size, const char *samples,
                                    const char *out_dir, int *status)
{
    char err[1024];
    cs_render_settings settings = cs_render_default_settings();
    if (engine && !cs_render_engine_from_name(engine, &settings.engine)) {
        fprintf(stderr, "clothsim run: --render: '%s' is not one of embree, preview\n", engine);
        *status = CS_EXIT_USAGE;
        return NULL;
    }
    if (settings.engine == CS_RENDER_PREVIEW)
        settings.samples = 4;
    int rc;
    if (size && (rc = cs_parse_size(size, &settings.width, &settings.height, err, sizeof err))) {
        fprintf(stderr, "clothsim run: %s\n", err);
        *status = rc == 1 ? CS_EXIT_USAGE : CS_EXIT_INPUT;
        return NULL;
    }
    if (samples && (rc = cs_parse_count(samples, "--samples", 1, CS_RENDER_MAX_SAMPLES,
                                        &settings.samples, err, sizeof err))) {
        fprintf(stderr, "clothsim run: %s\n", err);
        *status = rc == 1 ? CS_EXIT_USAGE : CS_EXIT_INPUT;
        return NULL;
    }
    if (cs_sim_cloth_count(sim) != scene->def.ncloths) {
        fprintf(stderr, "clothsim run: the simulation has %d cloths, the scene %d\n",
                cs_sim_cloth_count(sim), scene->def.ncloths);
        *status = CS_EXIT_OUTPUT;
        return NULL;
    }

    cs_run_render *rr = calloc(1, sizeof *rr);
    if (!rr) {
        fprintf(stderr, "clothsim: out of memory\n");
        *status = CS_EXIT_OUTPUT;
        return NULL;
    }
    rr->ncloths = scene->def.ncloths;
    rr->x = calloc((size_t)rr->ncloths + 1, sizeof *rr->x);
    size_t len = strlen(out_dir) + sizeof "/images";
    rr->images_dir = malloc(len);
    if (!rr->x || !rr->images_dir) {
        fprintf(stderr, "clothsim: out of memory\n");
        *status = CS_EXIT_OUTPUT;
        cs_run_render_destroy(rr);
        return NULL;
    }
    snprintf(rr->images_dir, len, "%s/images", out_dir);
    set_cloth_pointers(rr, sim);
    cs_frame_cloths cloths = {.x = rr->x};

    /* A small ray-traced look at the initial state first: a camera inside a
     * body or seeing nothing is bad input, found before simulating. */
    cs_render_settings small = settings;
    small.engine = CS_RENDER_EMBREE;
    small.width = 96;
    small.height = (int)lround(96.0 * settings.height / settings.width);
    if (small.height < 1)
        small.height = 1;
    small.samples = 1;
    small.bounces = 0;
    cs_scene_render *check = cs_scene_render_create(scene, &small, NULL, err, sizeof err, status);
    cs_image *check_img = check ? cs_image_create(small.width, small.height) : NULL;
    if (check && !check_img) {
        snprintf(err, sizeof err, "out of memory");
        *status = CS_EXIT_OUTPUT;
    }
    if (check_img)
        *status = cs_scene_render_draw(check, 0.0, &cloths, NULL, check_img, NULL, err,
                                       sizeof err);
    cs_image_destroy(check_img);
    cs_scene_render_destroy(check);
    if (*status == CS_EXIT_OK) {
        rr->sr = cs_scene_render_create(scene, &settings, stderr, err, sizeof err, status);
        rr->image = rr->sr ? cs_image_create(settings.width, settings.height) : NULL;
        if (rr->sr && !rr->image) {
            snprintf(err, sizeof err, "out of memory for a %dx%d image", settings.width,
                     settings.height);
            *status = CS_EXIT_OUTPUT;
        }
    }
    if (*status != CS_EXIT_OK) {
        fprintf(stderr, "clothsim: cannot render %s: %s\n", scene->path, err);
        cs_run_render_destroy(rr);
        return NULL;
    }

    if (cs_make_dirs(rr->images_dir) != 0) {
        fprintf(stderr, "clothsim: cannot create %s: %s\n", rr->images_dir, strerror(errno));
        *status = CS_EXIT_OUTPUT;
        cs_run_render_destroy(rr);
        return NULL;
    }
    DIR *d = opendir(rr->images_dir);
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL) {
        if (!is_frame_image(e->d_name))
            continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", rr->images_dir, e->d_name);
        if (unlink(path) != 0) {
            fprintf(stderr, "clothsim: cannot remove the old image %s: %s\n", path,
                    strerror(errno));
            *status = CS_EXIT_OUTPUT;
            break;
        }
    }
    if (d)
        closedir(d);
    if (*status != CS_EXIT_OK) {
        cs_run_render_destroy(rr);
        return NULL;
    }
    return rr;
}

void cs_run_render_destroy(cs_run_render *rr)
{
    if (!rr)
        return;
    cs_scene_render_destroy(rr->sr);
    cs_image_destroy(rr->image);
    free(rr->images_dir);
    free(rr->x);
    free(rr);
}

int cs_run_render_frame(cs_run_render *rr, const cs_sim *sim, int frame, char *err,
                        size_t errlen)
{
    set_cloth_pointers(rr, sim);
    cs_frame_cloths cloths = {.x = rr->x};
    char msg[1024];
    int status = cs_scene_render_draw(rr->sr, cs_sim_time(sim), &cloths, NULL, rr->image, NULL,
                                      msg, sizeof msg);
    if (status != CS_EXIT_OK) {
        snprintf(err, errlen, "cannot render frame %d: %s", frame, msg);
        return -1;
    }
    char path[4096];
    cs_frame_path(path, sizeof path, rr->images_dir, frame, NULL, "png");
    if (cs_image_write_png(rr->image, path, msg, sizeof msg) != CS_OK) {
        snprintf(err, errlen, "%s", msg);
        return -1;
    }
    return 0;
}
