/* embree.c: the path tracer on Embree 3.
 *
 * Per pixel, `samples` paths start at jittered points of the pixel. At each
 * hit the surface is Lambertian with the mesh's colour, the shading normal
 * is the interpolated vertex normal turned towards the viewer (so both sides
 * of cloth are lit alike), the sun is sampled with a shadow ray, and a
 * cosine-distributed bounce continues the path; after the last bounce that
 * direction only asks whether the sky is visible (ambient occlusion), which
 * is what makes wrinkles read.
 *
 * Threads take 16x16 tiles from a shared counter. Every random number comes
 * from a generator seeded by the pixel and sample index, never by the
 * thread, so an image is the same bit for bit for any number of threads.
 */
#include <embree3/rtcore.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#if defined(__SSE__) || defined(__x86_64__)
#include <pmmintrin.h>
#include <xmmintrin.h>
#define CS_HAVE_MXCSR 1
#endif

#include "render/internal.h"

#define TILE 16

struct cs_embree {
    RTCDevice device;
    cs_render_settings settings;
    int threads;
    char error[256];          /* set by Embree's error callback */
};

static void on_embree_error(void *user, enum RTCError code, const char *str)
{
    cs_embree *e = user;
    snprintf(e->error, sizeof e->error, "Embree error %d: %s", (int)code, str ? str : "");
}

cs_embree *cs_embree_create(const cs_render_settings *settings, char *err, size_t errlen)
{
    cs_embree *e = calloc(1, sizeof *e);
    if (!e) {
        cs_render_error(err, errlen, "out of memory");
        return NULL;
    }
    e->settings = *settings;
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    e->threads = settings->threads > 0 ? settings->threads : (cores > 0 ? (int)cores : 1);
    char config[64];
    snprintf(config, sizeof config, "threads=%d,verbose=0", e->threads);
    e->device = rtcNewDevice(config);
    if (!e->device) {
        cs_render_error(err, errlen, "cannot start Embree: %s",
                        rtcGetDeviceError(NULL) == RTC_ERROR_UNSUPPORTED_CPU
                            ? "this CPU is not supported"
                            : "rtcNewDevice failed");
        free(e);
        return NULL;
    }
    rtcSetDeviceErrorFunction(e->device, on_embree_error, e);
    return e;
}

void cs_embree_destroy(cs_embree *e)
{
    if (!e)
        return;
    rtcReleaseDevice(e->device);
    free(e);
}

/* ------------------------------------------------------------ small maths */

typedef struct vec3f {
    float x, y, z;
} vec3f;

static inline vec3f v3(float x, float y, float z) { return (vec3f){x, y, z}; }
static inline vec3f vadd(vec3f a, vec3f b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3f vscale(vec3f a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline vec3f vmul(vec3f a, vec3f b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline float vdot(vec3f a, vec3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3f vneg(vec3f a) { return v3(-a.x, -a.y, -a.z); }

static inline vec3f vnorm(vec3f a)
{
    float n = sqrtf(vdot(a, a));
    return n > 0 ? vscale(a, 1.0f / n) : a;
}

/* An orthonormal basis around unit n (Duff et al. 2017, branchless). */
static inline void onb(vec3f n, vec3f *t, vec3f *b)
{
    float sign = copysignf(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float c = n.x * n.y * a;
    *t = v3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
    *b = v3(c, sign + n.y * n.y * a, -n.y);
}

/* ------------------------------------------------------- random numbers */

/* splitmix64: a counter-based generator, seeded per pixel and sample. */
static inline uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static inline float rnd(uint64_t *state)
{
    *state += 0x9E3779B97F4A7C15ull;
    return (float)(mix64(*state) >> 40) * (1.0f / 16777216.0f);
}

static inline float frac(float x) { return x - floorf(x); }

/* The R2 sequence (Roberts 2018): well spread points for any count. */
#define R2_A1 0.75487766624669276f
#define R2_A2 0.56984029099805327f

/* ---------------------------------------------------------------- shading */

typedef struct shade_mesh {
    const float *normals;
    const int *tri;
    vec3f color;
} shade_mesh;

typedef struct job {
    RTCScene scene;
    const shade_mesh *meshes;
    vec3f eye, forward, right, up;
    float sx_scale, sy_scale;      /* tan(fov/2) * aspect, tan(fov/2) */
    vec3f sun;
    vec3f sun_e;                   /* sun irradiance / pi */
    float sun_cos;
    float eps;                     /* offset of secondary ray origins */
    int width, height, samples, bounces;
    int tiles_x, ntiles;
    cs_image *image;
    atomic_int next_tile;
    atomic_llong rays, covered;
} job;

static inline void sky(vec3f d, vec3f *out)
{
    float dd[3] = {d.x, d.y, d.z}, o[3];
    cs_sky_radiance(dd, o);
    *out = v3(o[0], o[1], o[2]);
}

static inline void init_ray(struct RTCRay *r, vec3f o, vec3f d, float tfar)
{
    r->org_x = o.x;
    r->org_y = o.y;
    r->org_z = o.z;
    r->tnear = 0.0f;
    r->dir_x = d.x;
    r->dir_y = d.y;
    r->dir_z = d.z;
    r->time = 0.0f;
    r->tfar = tfar;
    r->mask = 0xFFFFFFFFu;
    r->id = 0;
    r->flags = 0;
}

static inline bool occluded(const job *j, struct RTCIntersectContext *ctx, vec3f o, vec3f d,
                            long long *rays)
{
    struct RTCRay r;
    init_ray(&r, o, d, INFINITY);
    rtcOccluded1(j->scene, ctx, &r);
    (*rays)++;
    return r.tfar < 0.0f;   /* Embree sets tfar to -inf on a hit */
}

/* Cosine-weighted direction about n from two uniform numbers. */
static inline vec3f cosine_dir(vec3f n, float u1, float u2)
{
    vec3f t, b;
    onb(n, &t, &b);
    float r = sqrtf(u1), phi = 2.0f * (float)M_PI * u2;
    float z = sqrtf(fmaxf(0.0f, 1.0f - u1));
    return vnorm(vadd(vadd(vscale(t, r * cosf(phi)), vscale(b, r * sinf(phi))), vscale(n, z)));
}

/* Radiance along one camera path; *hit says whether the camera ray hit. */
static vec3f trace(const job *j, struct RTCIntersectContext *ctx, vec3f o, vec3f d,
                   uint64_t *rng, const float first[4], bool *hit, long long *rays)
{
    vec3f L = v3(0, 0, 0), T = v3(1, 1, 1);
    *hit = false;
    for (int depth = 0;; depth++) {
        struct RTCRayHit rh;
        init_ray(&rh.ray, o, d, INFINITY);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(j->scene, ctx, &rh);
        (*rays)++;
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
            vec3f s;
            sky(d, &s);
            return vadd(L, vmul(T, s));
        }
        if (depth == 0)
            *hit = true;

        const shade_mesh *m = &j->meshes[rh.hit.geomID];
        vec3f p = vadd(o, vscale(d, rh.ray.tfar));
        vec3f ng = vnorm(v3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
        if (vdot(ng, d) > 0)
            ng = vneg(ng);   /* the side the ray arrived on */
        const int *t = m->tri + 3 * (size_t)rh.hit.primID;
        const float *n0 = m->normals + 3 * (size_t)t[0];
        const float *n1 = m->normals + 3 * (size_t)t[1];
        const float *n2 = m->normals + 3 * (size_t)t[2];
        float u = rh.hit.u, v = rh.hit.v, w = 1.0f - u - v;
        vec3f ns = v3(w * n0[0] + u * n1[0] + v * n2[0], w * n0[1] + u * n1[1] + v * n2[1],
                      w * n0[2] + u * n1[2] + v * n2[2]);
        ns = vdot(ns, ns) > 1e-12f ? vnorm(ns) : ng;
        if (vdot(ns, ng) < 0)
            ns = vneg(ns);   /* both sides shaded: follow the visible side */
        vec3f origin = vadd(p, vscale(ng, j->eps * fmaxf(1.0f, rh.ray.tfar)));
        T = vmul(T, m->color);

        /* The sun: a cone of small angular radius, sampled uniformly. */
        float u1 = depth == 0 ? first[0] : rnd(rng);
        float u2 = depth == 0 ? first[1] : rnd(rng);
        float cz = 1.0f - u1 * (1.0f - j->sun_cos);
        float sz = sqrtf(fmaxf(0.0f, 1.0f - cz * cz)), phi = 2.0f * (float)M_PI * u2;
        vec3f st, sb;
        onb(j->sun, &st, &sb);
        vec3f ws = vadd(vadd(vscale(st, sz * cosf(phi)), vscale(sb, sz * sinf(phi))),
                        vscale(j->sun, cz));
        float cs = vdot(ns, ws);
        if (cs > 0 && vdot(ng, ws) > 0 && !occluded(j, ctx, origin, ws, rays))
            L = vadd(L, vmul(T, vscale(j->sun_e, cs)));

        /* The next direction, kept above the geometric surface. */
        vec3f wi = cosine_dir(ns, depth == 0 ? first[2] : rnd(rng),
                              depth == 0 ? first[3] : rnd(rng));
        float below = vdot(wi, ng);
        if (below <= 0)
            wi = vnorm(vadd(wi, vscale(ng, -2.0f * below + 1e-4f)));
        if (depth >= j->bounces) {
            if (!occluded(j, ctx, origin, wi, rays)) {
                vec3f s;
                sky(wi, &s);
                L = vadd(L, vmul(T, s));
            }
            return L;
        }
        o = origin;
        d = wi;
    }
}

static void render_tile(job *j, int tile, struct RTCIntersectContext *ctx, long long *rays,
                        long long *covered)
{
    int tx = tile % j->tiles_x, ty = tile / j->tiles_x;
    int x0 = tx * TILE, y0 = ty * TILE;
    int x1 = x0 + TILE < j->width ? x0 + TILE : j->width;
    int y1 = y0 + TILE < j->height ? y0 + TILE : j->height;
    int n = j->samples;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            uint64_t pixel = (uint64_t)y * (uint64_t)j->width + (uint64_t)x;
            /* Per-pixel shifts and index offsets decorrelate the R2 points
             * of neighbouring pixels and of the jitter, sun and bounce. */
            uint64_t ps = mix64(pixel * 0x9E3779B97F4A7C15ull + 0x1234567ull);
            float shift[6];
            for (int k = 0; k < 6; k++)
                shift[k] = rnd(&ps);
            int off_sun = (int)(mix64(ps) % (uint64_t)n);
            int off_bounce = (int)(mix64(ps + 1) % (uint64_t)n);
            vec3f sum = v3(0, 0, 0);
            int hits = 0;
            for (int s = 0; s < n; s++) {
                uint64_t rng = mix64((pixel << 20) ^ (uint64_t)s ^ 0xC0FFEEull);
                float jx = 0.5f, jy = 0.5f;
                if (n > 1) {
                    jx = frac(shift[0] + (float)s * R2_A1);
                    jy = frac(shift[1] + (float)s * R2_A2);
                }
                int ks = (s + off_sun) % n, kb = (s + off_bounce) % n;
                float first[4] = {frac(shift[2] + (float)ks * R2_A1),
                                  frac(shift[3] + (float)ks * R2_A2),
                                  frac(shift[4] + (float)kb * R2_A1),
                                  frac(shift[5] + (float)kb * R2_A2)};
                float sx = (2.0f * ((float)x + jx) / (float)j->width - 1.0f) * j->sx_scale;
                float sy = (1.0f - 2.0f * ((float)y + jy) / (float)j->height) * j->sy_scale;
                vec3f d = vnorm(vadd(j->forward, vadd(vscale(j->right, sx), vscale(j->up, sy))));
                bool hit;
                vec3f L = trace(j, ctx, j->eye, d, &rng, first, &hit, rays);
                sum = vadd(sum, L);
                hits += hit;
            }
            sum = vscale(sum, 1.0f / (float)n);
            unsigned char *px = j->image->rgb + 3 * pixel;
            px[0] = cs_encode_srgb(sum.x);
            px[1] = cs_encode_srgb(sum.y);
            px[2] = cs_encode_srgb(sum.z);
            j->image->coverage[pixel] = (unsigned char)((hits * 255 + n / 2) / n);
            *covered += hits > 0;
        }
}

static void *worker(void *arg)
{
    job *j = arg;
#ifdef CS_HAVE_MXCSR
    /* Embree's advice: denormals cost much and change nothing we can see.
     * The caller's thread runs a worker too, so its mode is put back. */
    unsigned int saved_csr = _mm_getcsr();
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#endif
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    long long rays = 0, covered = 0;
    for (;;) {
        int tile = atomic_fetch_add(&j->next_tile, 1);
        if (tile >= j->ntiles)
            break;
        render_tile(j, tile, &ctx, &rays, &covered);
    }
    atomic_fetch_add(&j->rays, rays);
    atomic_fetch_add(&j->covered, covered);
#ifdef CS_HAVE_MXCSR
    _mm_setcsr(saved_csr);
#endif
    return NULL;
}

/* ------------------------------------------------------------------ draw */

static RTCScene build_scene(cs_embree *e, const cs_prepared_scene *ps, shade_mesh *meshes,
                            char *err, size_t errlen)
{
    RTCScene scene = rtcNewScene(e->device);
    if (!scene) {
        cs_render_error(err, errlen, "cannot create an Embree scene: %s", e->error);
        return NULL;
    }
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    for (int m = 0; m < ps->nmeshes; m++) {
        const cs_render_mesh *mesh = ps->meshes[m].mesh;
        RTCGeometry g = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_TRIANGLE);
        float *vb = g ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                3 * sizeof(float), (size_t)mesh->nv)
                      : NULL;
        unsigned *ib = g ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                   3 * sizeof(unsigned), (size_t)mesh->nt)
                         : NULL;
        if (!vb || !ib) {
            cs_render_error(err, errlen, "Embree: no memory for mesh %d (%d triangles): %s", m,
                            mesh->nt, e->error);
            if (g)
                rtcReleaseGeometry(g);
            rtcReleaseScene(scene);
            return NULL;
        }
        for (size_t i = 0; i < 3 * (size_t)mesh->nv; i++)
            vb[i] = (float)mesh->x[i];
        for (size_t i = 0; i < 3 * (size_t)mesh->nt; i++)
            ib[i] = (unsigned)mesh->tri[i];
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(scene, g, (unsigned)m);   /* geomID = mesh index */
        rtcReleaseGeometry(g);
        meshes[m].normals = ps->meshes[m].normals;
        meshes[m].tri = mesh->tri;
        meshes[m].color = v3((float)mesh->color[0], (float)mesh->color[1], (float)mesh->color[2]);
    }
    rtcCommitScene(scene);
    if (e->error[0]) {
        cs_render_error(err, errlen, "cannot build the Embree scene: %s", e->error);
        rtcReleaseScene(scene);
        return NULL;
    }
    return scene;
}

int cs_embree_draw(cs_embree *e, const cs_prepared_scene *ps, const cs_render_camera *camera,
                   cs_image *image, cs_render_stats *stats, char *err, size_t errlen)
{
    e->error[0] = '\0';
    shade_mesh *meshes = calloc((size_t)ps->nmeshes, sizeof *meshes);
    job *j = calloc(1, sizeof *j);
    if (!meshes || !j) {
        free(meshes);
        free(j);
        cs_render_error(err, errlen, "out of memory");
        return CS_ERR_NOMEM;
    }
    j->scene = build_scene(e, ps, meshes, err, errlen);
    if (!j->scene) {
        free(meshes);
        free(j);
        return CS_ERR_FAILED;
    }

    cs_camera_basis b;
    cs_camera_basis_make(camera, image->width, image->height, &b);
    j->meshes = meshes;
    j->eye = v3((float)b.eye[0], (float)b.eye[1], (float)b.eye[2]);
    j->forward = v3((float)b.forward[0], (float)b.forward[1], (float)b.forward[2]);
    j->right = v3((float)b.right[0], (float)b.right[1], (float)b.right[2]);
    j->up = v3((float)b.up[0], (float)b.up[1], (float)b.up[2]);
    j->sx_scale = (float)(b.tan_half * b.aspect);
    j->sy_scale = (float)b.tan_half;
    double sun[3];
    cs_sun_direction(sun);
    j->sun = v3((float)sun[0], (float)sun[1], (float)sun[2]);
    j->sun_e = v3((float)(cs_sun_irradiance[0] / M_PI), (float)(cs_sun_irradiance[1] / M_PI),
                  (float)(cs_sun_irradiance[2] / M_PI));
    j->sun_cos = (float)CS_SUN_COS_RADIUS;
    /* Secondary rays start off the surface by a few float ulps of the
     * scene's size (scaled by hit distance in trace). */
    double size = 0;
    for (int i = 0; i < 3; i++)
        size = fmax(size, fmax(fabs(ps->lo[i]), fabs(ps->hi[i])));
    j->eps = (float)(fmax(size, 1e-3) * 2e-6);
    j->width = image->width;
    j->height = image->height;
    j->samples = e->settings.samples;
    j->bounces = e->settings.bounces;
    j->tiles_x = (image->width + TILE - 1) / TILE;
    j->ntiles = j->tiles_x * ((image->height + TILE - 1) / TILE);
    j->image = image;
    atomic_init(&j->next_tile, 0);
    atomic_init(&j->rays, 0);
    atomic_init(&j->covered, 0);

    int nthreads = e->threads < j->ntiles ? e->threads : j->ntiles;
    pthread_t *threads = calloc(nthreads > 1 ? (size_t)nthreads - 1 : 1, sizeof *threads);
    int started = 0;
    if (threads)
        for (; started < nthreads - 1; started++)
            if (pthread_create(&threads[started], NULL, worker, j) != 0)
                break;   /* fewer threads: the tiles still all get done */
    worker(j);
    for (int t = 0; t < started; t++)
        pthread_join(threads[t], NULL);
    free(threads);

    stats->rays = atomic_load(&j->rays);
    stats->covered = atomic_load(&j->covered);
    rtcReleaseScene(j->scene);
    int rc = CS_OK;
    if (e->error[0]) {
        cs_render_error(err, errlen, "Embree failed while tracing: %s", e->error);
        rc = CS_ERR_FAILED;
    }
    free(meshes);
    free(j);
    return rc;
}
