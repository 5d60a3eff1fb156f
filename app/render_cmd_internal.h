/* render_cmd_internal.h: what the parts of `clothsim render` share: its
 * options (render_cmd.c parses them and sets up the job), the frames read
 * back and drawn (render_frames.c), turntables (render_turntable.c) and
 * animations through ffmpeg (render_animation.c). */
#ifndef CS_APP_RENDER_CMD_INTERNAL_H
#define CS_APP_RENDER_CMD_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>

#include "app/outdir.h"
#include "app/scene_render.h"
#include "import/import.h"
#include "render/render.h"

#define ERRLEN 8192

typedef struct render_options {
    const char *target;
    const char *out_dir;
    const char *scene_path;
    const char *frames;
    cs_render_settings settings;
    bool samples_given;
    int turntable;
    bool animation;
    int noverrides;
    char **overrides;
    bool quiet;
} render_options;

/* The cloths of one frame, read by name. */
typedef struct frame_geometry {
    cs_frame_layout layout;    /* how the run's frames hold the scene's cloths */
    cs_trimesh **meshes;       /* per cloth: its mesh of the file */
    cs_trimesh *file;          /* a file without the cloths' objects, merged */
    const double **x;          /* scene file: per cloth, the scene's positions */
    cs_frame_cloths cloths;
} frame_geometry;

void cs_frame_geometry_clear(frame_geometry *g);

typedef struct render_job {
    render_options *o;
    const cs_scene *scene;
    bool run_mode;
    cs_run_info info;
    double fps;
    char frames_dir[4096];
    char out_dir[4096];
    cs_scene_render *sr;
    cs_image *image;
    frame_geometry geom;
    bool merged_said;
} render_job;

/* Loads the geometry of frame f into j->geom (see render_frames.c).
 * Returns an exit status with err. */
int cs_render_cmd_get_frame(render_job *j, int f, char *err, size_t errlen);
/* An image per listed frame, DIR/frame_NNNN.png. Returns an exit status. */
int cs_render_cmd_frames(render_job *j, const int *frames, int nframes);
/* --turntable N: N views of frame f orbiting the scene's centre, their
 * contact sheet and animation. Returns an exit status. */
int cs_render_cmd_turntable(render_job *j, int f);

/* dir/leaf as an ffmpeg image pattern (render_animation.c). 0, or -1 when
 * it does not fit. */
int cs_render_cmd_image_pattern(const char *dir, const char *leaf, char *out, size_t len);
/* The PNGs that pattern numbers first .. first + count - 1, at fps, as
 * DIR/BASE.mp4 and DIR/BASE.gif; *made is false without ffmpeg. Returns 0,
 * or CS_EXIT_OUTPUT. */
int cs_render_cmd_make_animation(const render_job *j, const char *pattern, int first, int count,
                                 double fps, const char *base, bool *made);
/* --animation: the frames just rendered, in the order listed. Returns an
 * exit status. */
int cs_render_cmd_animation(render_job *j, const int *frames, int nframes);

#endif
