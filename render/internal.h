/* internal.h: what render/'s files share and nobody else sees: the camera
 * basis, the lighting both engines use, the tone curve, and the engines'
 * entry points. */
#ifndef CS_RENDER_INTERNAL_H
#define CS_RENDER_INTERNAL_H

#include "common/util.h"

#include <math.h>

#include "render/render.h"

/* ------------------------------------------------------------------ camera */

typedef struct cs_camera_basis {
    double eye[3];
    double forward[3], right[3], up[3];   /* orthonormal; right = forward x up */
    double tan_half;                      /* tan(fov / 2), vertical */
    double aspect;                        /* width / height */
} cs_camera_basis;

/* The camera must have passed cs_render_camera_check. */
void cs_camera_basis_make(const cs_render_camera *camera, int width, int height,
                          cs_camera_basis *basis);

/* ---------------------------------------------------------------- lighting */

/* One light setup for both engines, in linear RGB: a sky dome (bright at the
 * horizon, bluer overhead, dark grey below the horizon) and a sun of small
 * angular radius whose soft shadows show the cloth's folds. The sun sits
 * high in front and to the left of the default view. */
#define CS_SUN_DIR_X (-0.40)
#define CS_SUN_DIR_Y 1.00
#define CS_SUN_DIR_Z 0.55
#define CS_SUN_COS_RADIUS 0.9945   /* about 6 degrees */
static const double cs_sun_irradiance[3] = {3.10, 2.95, 2.70};
static const double cs_sky_zenith[3] = {0.27, 0.35, 0.52};
static const double cs_sky_horizon[3] = {0.58, 0.62, 0.70};
static const double cs_sky_below[3] = {0.20, 0.20, 0.20};
#define CS_EXPOSURE 0.95

static inline void cs_sun_direction(double s[3])
{
    double n = sqrt(CS_SUN_DIR_X * CS_SUN_DIR_X + CS_SUN_DIR_Y * CS_SUN_DIR_Y +
                    CS_SUN_DIR_Z * CS_SUN_DIR_Z);
    s[0] = CS_SUN_DIR_X / n;
    s[1] = CS_SUN_DIR_Y / n;
    s[2] = CS_SUN_DIR_Z / n;
}

/* Radiance of the sky seen along unit direction d (the sun left out). */
static inline void cs_sky_radiance(const float d[3], float out[3])
{
    float y = d[1];
    if (y >= 0.0f) {
        float w = sqrtf(y);
        for (int i = 0; i < 3; i++)
            out[i] = (float)cs_sky_horizon[i] + w * (float)(cs_sky_zenith[i] - cs_sky_horizon[i]);
    } else {
        /* Fade to the ground colour just below the horizon. */
        float w = fminf(-y * 8.0f, 1.0f);
        for (int i = 0; i < 3; i++)
            out[i] = (float)cs_sky_horizon[i] + w * (float)(cs_sky_below[i] - cs_sky_horizon[i]);
    }
}

/* Linear value to an 8-bit sRGB code: exposure, a soft shoulder above 0.8
 * so highlights do not clip to flat colour, then the sRGB curve. */
static inline unsigned char cs_encode_srgb(float v)
{
    v *= (float)CS_EXPOSURE;
    if (!(v > 0.0f))
        return 0;
    if (v > 0.8f)
        v = 0.8f + 0.2f * (1.0f - expf(-(v - 0.8f) / 0.2f));
    float s = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
    int code = (int)(s * 255.0f + 0.5f);
    return (unsigned char)(code > 255 ? 255 : code);
}

/* ------------------------------------------------------------- the scene */

/* The meshes of one draw after validation, with smooth vertex normals
 * (area-weighted averages of the triangle normals around each vertex). */
typedef struct cs_prepared_mesh {
    const cs_render_mesh *mesh;
    float *normals;           /* 3 per vertex, unit (or zero where undefined) */
} cs_prepared_mesh;

typedef struct cs_prepared_scene {
    int nmeshes;
    cs_prepared_mesh *meshes;
    double lo[3], hi[3];      /* bounds of every mesh, backdrops included */
} cs_prepared_scene;

/* ----------------------------------------------------------------- engines */

typedef struct cs_embree cs_embree;
cs_embree *cs_embree_create(const cs_render_settings *settings, char *err, size_t errlen);
void cs_embree_destroy(cs_embree *engine);
int cs_embree_draw(cs_embree *engine, const cs_prepared_scene *scene,
                   const cs_render_camera *camera, cs_image *image, cs_render_stats *stats,
                   char *err, size_t errlen);

typedef struct cs_preview cs_preview;
cs_preview *cs_preview_create(const cs_render_settings *settings, char *err, size_t errlen);
void cs_preview_destroy(cs_preview *engine);
int cs_preview_draw(cs_preview *engine, const cs_prepared_scene *scene,
                    const cs_render_camera *camera, cs_image *image, cs_render_stats *stats,
                    char *err, size_t errlen);

/* snprintf into err when err is not NULL (common/util.h). */
#define cs_render_error cs_errorf

#endif
