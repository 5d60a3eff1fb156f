/* render.h: the public face of clothsim's renderer.
 *
 * It draws a list of triangle meshes (cloth, tessellated bodies, a ground),
 * each with a colour, through a camera, into an 8-bit sRGB image, and writes
 * PNG files. It knows nothing of the simulation: a caller turns frames and
 * bodies into cs_render_mesh views.
 *
 * Two engines share one camera model and one lighting setup (a sky and a
 * soft sun), so their pictures agree in framing and colour:
 *   - CS_RENDER_EMBREE: a path tracer on Embree 3 (render/embree.c): smooth
 *     vertex normals, both cloth sides shaded, sun shadows, sky light and
 *     diffuse bounces, several jittered samples per pixel, tiles on threads.
 *     Random numbers are seeded per pixel and sample, so an image does not
 *     depend on the number of threads.
 *   - CS_RENDER_PREVIEW: OSMesa rasterisation (render/preview.c): the same
 *     sky and sun without shadows, flat or smooth shading, an optional
 *     wireframe overlay, multisampling; fast enough for every frame.
 *
 * Images are gamma-correct: shading is computed in linear RGB, compressed
 * above 0.8 by a soft shoulder and encoded as sRGB.
 */
#ifndef CS_RENDER_H
#define CS_RENDER_H

#include <stdbool.h>
#include <stddef.h>

#include "common/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Statuses (common/error.h): CS_ERR_BAD_INPUT (an invalid size, mesh or
 * camera, or a camera that sees nothing) is the command's exit status 2;
 * CS_ERR_NOMEM; CS_ERR_FAILED (an engine or a file failed). */

#define CS_RENDER_MAX_SIZE 16384
#define CS_RENDER_MAX_SAMPLES 4096

/* ------------------------------------------------------------ what to draw */

/* A borrowed view of one triangle mesh. */
typedef struct cs_render_mesh {
    const char *name;       /* used in messages; may be NULL */
    int nv, nt;
    const double *x;        /* 3 per vertex */
    const int *tri;         /* 3 per triangle, counter-clockwise seen from the front */
    double color[3];        /* linear RGB albedo, each in [0, 1] */
    bool two_sided;         /* cloth: the back is shaded like the front */
    bool closed;            /* a solid's surface: the camera must not be inside it */
    bool backdrop;          /* a ground: left out of automatic framing */
} cs_render_mesh;

/* A pinhole camera. Pixel (i, j), j counted from the top, looks along
 * forward + sx * right + sy * up with sx = (2 (i + 0.5) / W - 1) tan(fov/2) W/H
 * and sy = (1 - 2 (j + 0.5) / H) tan(fov/2). */
typedef struct cs_render_camera {
    double position[3];
    double target[3];
    double up[3];
    double fov_degrees;     /* vertical field of view, in (0, 180) */
} cs_render_camera;

/* CS_OK, or CS_ERR_BAD_INPUT with one line in err saying what is
 * wrong (a non-finite value, target at the position, up along the view,
 * fov out of range). */
int cs_render_camera_check(const cs_render_camera *camera, char *err, size_t errlen);

/* Bounds of the meshes that are not backdrops; false if there are none. */
bool cs_render_bounds(int nmeshes, const cs_render_mesh *meshes, double lo[3], double hi[3]);

/* Automatic framing: looks at the centre of the box from above and in front
 * (+x, +y, +z), y up, 40 degrees, close enough that the box's bounding
 * sphere just fits an image of the given aspect (width / height). */
cs_render_camera cs_render_camera_frame(const double lo[3], const double hi[3], double aspect);

/* The camera turned by angle (radians) about the axis through centre
 * (right-handed); position, target and up all turn. */
cs_render_camera cs_render_camera_orbit(const cs_render_camera *camera, const double centre[3],
                                        const double axis[3], double angle);

/* Where world point p lands in a W x H image, in pixels from the top-left
 * corner (pixel (i, j) spans [i, i+1] x [j, j+1]); false if p is not in
 * front of the camera. */
bool cs_render_camera_project(const cs_render_camera *camera, int width, int height,
                              const double p[3], double pixel[2]);

/* The unit direction through image point (px, py), in pixels from the
 * top-left corner: the inverse of cs_render_camera_project. */
void cs_render_camera_ray(const cs_render_camera *camera, int width, int height, double px,
                          double py, double dir[3]);

/* ---------------------------------------------------------------- settings */

typedef enum cs_render_engine {
    CS_RENDER_EMBREE = 0,
    CS_RENDER_PREVIEW,
} cs_render_engine;

/* "embree", "preview"; false if unknown (engine may be NULL). */
bool cs_render_engine_from_name(const char *name, cs_render_engine *engine);
const char *cs_render_engine_name(cs_render_engine engine);

typedef struct cs_render_settings {
    cs_render_engine engine;
    int width, height;      /* pixels, 1 .. CS_RENDER_MAX_SIZE */
    int samples;            /* per pixel: embree paths (1 = the pixel centre);
                               preview: multisampling, up to what GL offers */
    int bounces;            /* embree: diffuse bounces after the first hit */
    int threads;            /* embree: 0 = one per core */
    bool flat;              /* preview: one normal per triangle */
    bool wireframe;         /* preview: edges drawn over the shading (not backdrops') */
} cs_render_settings;

/* embree, 640 x 480, 16 samples, 2 bounces, all cores, smooth, no wireframe. */
cs_render_settings cs_render_default_settings(void);

/* CS_OK, or CS_ERR_BAD_INPUT with one line in err. */
int cs_render_settings_check(const cs_render_settings *settings, char *err, size_t errlen);

/* ------------------------------------------------------------------ images */

/* 8-bit sRGB, rows top to bottom, 3 bytes per pixel; coverage holds per
 * pixel the fraction (0 to 255) of samples that hit a mesh. */
typedef struct cs_image {
    int width, height;
    unsigned char *rgb;
    unsigned char *coverage;
} cs_image;

cs_image *cs_image_create(int width, int height);
void cs_image_destroy(cs_image *image);

/* A copy shrunk to the given width (height in proportion, at least 1) by
 * averaging the pixels each new one covers, coverage too; NULL if out of
 * memory or width is not in 1 .. image->width. */
cs_image *cs_image_shrink(const cs_image *image, int width);

/* Writes an RGB PNG through libpng (atomically: PATH.tmp, then renamed). */
int cs_image_write_png(const cs_image *image, const char *path, char *err, size_t errlen);

/* Reads any PNG as RGB (coverage left NULL); NULL with err on failure. */
cs_image *cs_image_read_png(const char *path, char *err, size_t errlen);

/* ---------------------------------------------------------------- renderer */

typedef struct cs_render_stats {
    double seconds;          /* wall time of the draw */
    long long rays;          /* rays traced (embree), 0 for the preview */
    long long covered;       /* pixels where some mesh was hit */
} cs_render_stats;

/* A renderer keeps an engine's expensive state (Embree device, GL context,
 * compiled shaders) from one image to the next. Not thread-safe: one
 * renderer per thread. */
typedef struct cs_renderer cs_renderer;

cs_renderer *cs_renderer_create(const cs_render_settings *settings, char *err, size_t errlen);
void cs_renderer_destroy(cs_renderer *renderer);

/* Draws the meshes into image (its size must be the settings' size). Bad
 * input: no mesh, a mesh with no triangles, an index out of range, a
 * non-finite coordinate or colour, an invalid camera, a camera inside a
 * closed mesh, or a camera that sees no mesh at all (the image would be only
 * sky). stats may be NULL. */
int cs_renderer_draw(cs_renderer *renderer, int nmeshes, const cs_render_mesh *meshes,
                     const cs_render_camera *camera, cs_image *image, cs_render_stats *stats,
                     char *err, size_t errlen);

/* One image, start to finish: create, draw, write the PNG, destroy. */
int cs_render_png(const char *path, int nmeshes, const cs_render_mesh *meshes,
                  const cs_render_camera *camera, const cs_render_settings *settings, char *err,
                  size_t errlen);

/* -------------------------------------------------------------- turntables */

/* A contact sheet: the images (all the same size) as thumbnails in a grid of
 * `columns`, each scaled to thumb_width pixels wide and labelled with
 * labels[i] when labels is not NULL, written as a PNG through cairo. */
int cs_render_contact_sheet(const char *path, int nimages, const cs_image *const *images,
                            const char *const *labels, int columns, int thumb_width, char *err,
                            size_t errlen);

/* An animation of `count` numbered PNGs matched by pattern (printf style,
 * e.g. "dir/view_%03d.png"), numbers first .. first + count - 1, at fps
 * frames a second, made by the ffmpeg program if one is on the PATH: a GIF
 * (palettegen/paletteuse) when path ends in .gif, else an MP4 (H.264,
 * yuv420p, sides padded to even). Written atomically (path.tmp, renamed);
 * ffmpeg's own messages go to stderr. Returns 1 made, 0 skipped (no ffmpeg
 * on the PATH), or CS_ERR_FAILED with err (ffmpeg failed, or could not
 * be started; nothing is left under path). */
int cs_render_animation(const char *pattern, int first, int count, double fps,
                        const char *path, char *err, size_t errlen);

#ifdef __cplusplus
}
#endif
#endif
