/* scene_render.h: a scene drawn by render/: its cloths (at a frame's
 * positions) and bodies (tessellated at the frame's time), a ground quad for
 * each plane, the scene's camera or an automatic one. Shared by
 * `clothsim render` and `clothsim run --render`. */
#ifndef CS_APP_SCENE_RENDER_H
#define CS_APP_SCENE_RENDER_H

#include <stdbool.h>
#include <stdio.h>

#include "import/import.h"
#include "render/render.h"
#include "sim/sim.h"

typedef struct cs_scene_render cs_scene_render;

/* Checks that every cloth has triangles, creates the renderer and fixes the
 * camera: the scene's, or one framing the initial state (cloths at rest
 * where the scene puts them, bodies at t = 0, and their shadow on each
 * ground plane), so every frame of a scene is seen from the same place
 * (or, with the scene's camera.motion, from where it carries the camera).
 * warn (may be NULL) hears about bodies that cannot be drawn. On failure
 * returns NULL, a message in err and the exit status in *status. */
cs_scene_render *cs_scene_render_create(const cs_scene *scene,
                                        const cs_render_settings *settings, FILE *warn,
                                        char *err, size_t errlen, int *status);
void cs_scene_render_destroy(cs_scene_render *sr);

/* The camera at time t: the fixed one, carried by the scene's
 * camera.motion when it has one. */
cs_render_camera cs_scene_render_camera(const cs_scene_render *sr, double t);

/* The scene's up direction as given (or the automatic camera's): the axis
 * turntables orbit, so a camera the motion has tilted still circles the
 * scene level. */
const double *cs_scene_render_up(const cs_scene_render *sr);

/* The cloths of one frame, the first of these that is not NULL:
 *   x:      per cloth its positions, in the scene's vertex order (the
 *           scene's triangles apply), as the simulation holds them;
 *   meshes: per cloth a mesh of its own (as read back from a frame file);
 *   merged: all cloth in one mesh, drawn in the first cloth's colour. */
typedef struct cs_frame_cloths {
    const double *const *x;            /* scene->def.ncloths pointers */
    const cs_trimesh *const *meshes;   /* scene->def.ncloths meshes */
    const cs_trimesh *merged;
} cs_frame_cloths;

/* Centre of the frame's cloths and drawn bodies (not the ground), for
 * turntables. */
void cs_scene_render_centre(const cs_scene_render *sr, double t, const cs_frame_cloths *cloths,
                            double centre[3]);

/* Draws the frame at time t through camera (NULL: the scene's at t) into
 * image. Returns an exit status (0, 2 bad input such as a camera inside a
 * body or seeing nothing, 4 failure) with a message in err. */
int cs_scene_render_draw(cs_scene_render *sr, double t, const cs_frame_cloths *cloths,
                         const cs_render_camera *camera, cs_image *image,
                         cs_render_stats *stats, char *err, size_t errlen);

/* "WxH" -> sizes. Returns 0, 1 when it is not of that form, 2 when a side
 * is outside 1 .. CS_RENDER_MAX_SIZE; err says which. */
int cs_parse_size(const char *text, int *width, int *height, char *err, size_t errlen);

/* A whole number in [lo, hi]: 0, 1 not a number, 2 out of range. */
int cs_parse_count(const char *text, const char *what, long lo, long hi, int *out, char *err,
                   size_t errlen);

/* ------------------------------------------------- clothsim run --render */

typedef struct cs_run_render cs_run_render;

/* Sets up rendering of every frame of a run into out_dir/images (created;
 * PNG frames of an earlier run there are removed): validates the engine,
 * size and samples given on the command line (NULL: defaults), draws the
 * initial state once small to catch a camera inside a body or seeing
 * nothing. NULL with a message on stderr and *status set on failure. */
cs_run_render *cs_run_render_create(const cs_scene *scene, const cs_sim *sim,
                                    const char *engine, const char *size, const char *samples,
                                    const char *out_dir, int *status);
void cs_run_render_destroy(cs_run_render *rr);

/* Renders the simulation's current state as out_dir/images/frame_NNNN.png.
 * Returns 0, or -1 with a message in err. */
int cs_run_render_frame(cs_run_render *rr, const cs_sim *sim, int frame, char *err,
                        size_t errlen);

#endif
