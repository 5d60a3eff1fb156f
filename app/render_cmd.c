/* render_cmd.c: `clothsim render TARGET`: images of a run's frames (TARGET
 * is its output folder) or of a scene's initial state (TARGET is the scene
 * file), turntables, and animations of the frames (--animation).
 *
 * A run folder holds its resolved scene, DIR/scene.yaml (an older one names
 * its scene file and the --set overrides it ran with in summary.json), so
 * the scene is reloaded exactly: cloth colours, bodies
 * and their motion, the camera. A frame keeps its cloths apart (outdir.h:
 * an object per cloth in OBJ and glTF, a file per cloth in PLY), so each is
 * read back by its name. A frame without them (written before frames kept
 * cloths apart, or the scene's cloths renamed since) is drawn as one mesh
 * in the first cloth's colour, and the command says so once.
 */
#include "app/render_cmd.h"

#include "app/cli.h"
#include "app/outdir.h"
#include "app/run.h"
#include "app/scene_render.h"
#include "common/util.h"
#include "import/import.h"
#include "render/render.h"
#include "sim/sim.h"

#include <cJSON.h>
#include <dirent.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define ERRLEN 8192
#define MAX_TURNTABLE 360

void cs_render_help(FILE *out)
{
    fputs(
        "usage: clothsim render TARGET [options]\n"
        "\n"
        "Renders PNG images of the frames of a run (TARGET is the output folder of\n"
        "'clothsim run', holding summary.json and frames/) or of the initial state of a\n"
        "scene (TARGET is a scene file). Cloth colours, bodies (at each frame's time),\n"
        "a ground for each plane and the camera come from the scene; without a camera\n"
        "block the view frames the initial state.\n"
        "\n"
        "options:\n"
        "  -o, --output DIR     write the images into DIR (default: TARGET/images, or\n"
        "                       out/<scene name>/images for a scene file; turntables go\n"
        "                       to .../turntable); images are frame_NNNN.png\n"
        "  -e, --engine ENGINE  embree: ray traced (default); preview: OSMesa rasterised\n"
        "      --frames LIST    frames to render: all (default), last, N, A-B, or a comma\n"
        "                       separated list of these, e.g. 0,10-20,last\n"
        "      --size WxH       image size in pixels (default 640x480, at most 16384 a side)\n"
        "      --samples N      samples per pixel: embree paths (default 16), preview\n"
        "                       multisampling (default 4)\n"
        "      --bounces N      embree: diffuse bounces of light (default 2)\n"
        "      --threads N      embree: threads (default: one per core)\n"
        "      --flat           preview: flat shading (one normal per triangle)\n"
        "      --wireframe      preview: draw the triangle edges over the shading\n"
        "      --turntable N    N views orbiting the scene's centre, of one frame (the\n"
        "                       last unless --frames names one): view_000.png ...,\n"
        "                       contact_sheet.png, and turntable.mp4 and turntable.gif\n"
        "                       (12 views a second) if ffmpeg is installed\n"
        "      --animation      also assemble the rendered frames, in order, into\n"
        "                       animation.mp4 (H.264, yuv420p) and animation.gif beside\n"
        "                       them, at the scene's frames per second, with the ffmpeg\n"
        "                       program; without ffmpeg the PNG frames remain and a note\n"
        "                       says so (exit status 0)\n"
        "      --set KEY=VALUE  override a scene setting, after the run's own overrides\n"
        "                       (e.g. --set camera.fov=30); repeatable\n"
        "      --scene FILE     the run's scene file, when it has moved since the run\n"
        "  -q, --quiet          print nothing but errors\n"
        "  -h, --help           show this help\n"
        "\n"
        "exit status:\n"
        "  0    every image written\n"
        "  1    bad command line\n"
        "  2    bad input: the scene is invalid, a frame file is missing or holds no\n"
        "       triangles, the size or sample count is out of range, the camera is inside\n"
        "       a body or sees nothing\n"
        "  4    an image could not be written, ffmpeg failed making an animation (its\n"
        "       message is shown; the PNG images are kept), or memory ran out\n",
        out);
}

static const cs_cli CLI = {
    "render",
    "usage: clothsim render (RUN_DIR | SCENE) [-o DIR] [--engine embree|preview]\n"
    "                       [--frames LIST] [--size WxH] [--samples N]\n"
    "                       [--turntable N | --animation] [--set KEY=VALUE]...\n"
    "'clothsim render --help' explains every option.\n",
    NULL, CS_EXIT_USAGE};

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

/* A value cs_parse_size or cs_parse_count refused: 1 not of the form
 * asked for (a bad command line), 2 out of range (bad input). */
static int value_error(int rc, const char *err)
{
    fprintf(stderr, "clothsim render: %s\n", err);
    return rc == 1 ? CS_EXIT_USAGE : CS_EXIT_INPUT;
}

enum {
    OPT_FRAMES = 256, OPT_SIZE, OPT_SAMPLES, OPT_BOUNCES, OPT_THREADS, OPT_FLAT,
    OPT_WIREFRAME, OPT_TURNTABLE, OPT_ANIMATION, OPT_SET, OPT_SCENE
};

/* -1 to go on, else an exit status. */
static int parse_options(int argc, char **argv, render_options *o)
{
    static const struct option longopts[] = {
        {"output", required_argument, NULL, 'o'},
        {"engine", required_argument, NULL, 'e'},
        {"frames", required_argument, NULL, OPT_FRAMES},
        {"size", required_argument, NULL, OPT_SIZE},
        {"samples", required_argument, NULL, OPT_SAMPLES},
        {"bounces", required_argument, NULL, OPT_BOUNCES},
        {"threads", required_argument, NULL, OPT_THREADS},
        {"flat", no_argument, NULL, OPT_FLAT},
        {"wireframe", no_argument, NULL, OPT_WIREFRAME},
        {"turntable", required_argument, NULL, OPT_TURNTABLE},
        {"animation", no_argument, NULL, OPT_ANIMATION},
        {"set", required_argument, NULL, OPT_SET},
        {"scene", required_argument, NULL, OPT_SCENE},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    memset(o, 0, sizeof *o);
    o->settings = cs_render_default_settings();
    o->overrides = calloc((size_t)argc + 1, sizeof *o->overrides);
    if (!o->overrides) {
        fprintf(stderr, "clothsim: out of memory\n");
        return CS_EXIT_OUTPUT;
    }
    char err[ERRLEN];
    int rc;
    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, ":o:e:qh", longopts, NULL)) != -1) {
        switch (c) {
        case 'o':
            if (!*optarg)
                return cs_cli_error(&CLI, "%s", "--output needs a directory name");
            o->out_dir = optarg;
            break;
        case 'e':
            if (!cs_render_engine_from_name(optarg, &o->settings.engine))
                return cs_cli_error(&CLI, "--engine: '%s' is not one of embree, preview", optarg);
            break;
        case OPT_FRAMES:
            o->frames = optarg;
            break;
        case OPT_SIZE:
            if ((rc = cs_parse_size(optarg, &o->settings.width, &o->settings.height, err,
                                    sizeof err)))
                return value_error(rc, err);
            break;
        case OPT_SAMPLES:
            if ((rc = cs_parse_count(optarg, "--samples", 1, CS_RENDER_MAX_SAMPLES,
                                     &o->settings.samples, err, sizeof err)))
                return value_error(rc, err);
            o->samples_given = true;
            break;
        case OPT_BOUNCES:
            if ((rc = cs_parse_count(optarg, "--bounces", 0, 16, &o->settings.bounces, err,
                                     sizeof err)))
                return value_error(rc, err);
            break;
        case OPT_THREADS:
            if ((rc = cs_parse_count(optarg, "--threads", 0, 1024, &o->settings.threads, err,
                                     sizeof err)))
                return value_error(rc, err);
            break;
        case OPT_FLAT:
            o->settings.flat = true;
            break;
        case OPT_WIREFRAME:
            o->settings.wireframe = true;
            break;
        case OPT_TURNTABLE:
            if ((rc = cs_parse_count(optarg, "--turntable", 1, MAX_TURNTABLE, &o->turntable,
                                     err, sizeof err)))
                return value_error(rc, err);
            break;
        case OPT_ANIMATION:
            o->animation = true;
            break;
        case OPT_SET:
            if (!strchr(optarg, '=') || optarg[0] == '=')
                return cs_cli_error(&CLI, "--set needs KEY=VALUE, got '%s'", optarg);
            o->overrides[o->noverrides++] = optarg;
            break;
        case OPT_SCENE:
            o->scene_path = optarg;
            break;
        case 'q':
            o->quiet = true;
            break;
        case 'h':
            cs_render_help(stdout);
            return CS_EXIT_OK;
        default:
            return cs_cli_option_error(&CLI, c, argv);
        }
    }
    int status = 0;
    o->target = cs_cli_operand(&CLI, argc, argv, optind, "run folder or scene file", &status);
    if (!o->target)
        return status;
    if (o->settings.engine == CS_RENDER_PREVIEW && !o->samples_given)
        o->settings.samples = 4;
    return -1;
}

/* ------------------------------------------------------------ frame list */

/* Parses LIST against frames 0 .. n-1 into a new array. Returns 0, or an
 * exit status with err. */
static int parse_frames(const char *list, int n, int **out, int *count, char *err, size_t errlen)
{
    *out = NULL;
    *count = 0;
    if (n < 1) {
        snprintf(err, errlen, "the run wrote no frames");
        return CS_EXIT_INPUT;
    }
    size_t cap = 16;
    int *frames = malloc(cap * sizeof *frames);
    char *copy = strdup(list);
    if (!frames || !copy) {
        free(frames);
        free(copy);
        snprintf(err, errlen, "out of memory");
        return CS_EXIT_OUTPUT;
    }
    int status = CS_EXIT_OK;
    char *save = NULL;
    for (char *item = strtok_r(copy, ",", &save); item && status == CS_EXIT_OK;
         item = strtok_r(NULL, ",", &save)) {
        long a, b;
        char *end;
        if (strcmp(item, "all") == 0) {
            a = 0;
            b = n - 1;
        } else if (strcmp(item, "last") == 0) {
            a = b = n - 1;
        } else {
            errno = 0;
            a = strtol(item, &end, 10);
            if (end == item || a < 0 || errno) {
                snprintf(err, errlen, "--frames: '%s' is not a frame number or range", item);
                status = CS_EXIT_USAGE;
                break;
            }
            b = a;
            if (*end == '-') {
                char *start = end + 1;
                b = strcmp(start, "last") == 0 ? n - 1 : strtol(start, &end, 10);
                if (strcmp(start, "last") != 0 && (end == start || *end || b < a)) {
                    snprintf(err, errlen, "--frames: '%s' is not a range A-B with A <= B", item);
                    status = CS_EXIT_USAGE;
                    break;
                }
            } else if (*end) {
                snprintf(err, errlen, "--frames: '%s' is not a frame number or range", item);
                status = CS_EXIT_USAGE;
                break;
            }
        }
        if (a >= n || b >= n) {
            snprintf(err, errlen, "--frames: frame %ld does not exist (the run wrote frames 0 "
                     "to %d)", a >= n ? a : b, n - 1);
            status = CS_EXIT_INPUT;
            break;
        }
        for (long f = a; f <= b; f++) {
            if ((size_t)*count == cap) {
                int *grown = cap < (1u << 24) ? realloc(frames, 2 * cap * sizeof *frames) : NULL;
                if (!grown) {
                    snprintf(err, errlen, "out of memory");
                    status = CS_EXIT_OUTPUT;
                    break;
                }
                frames = grown;
                cap *= 2;
            }
            frames[(*count)++] = (int)f;
        }
    }
    free(copy);
    if (status == CS_EXIT_OK && *count == 0) {
        snprintf(err, errlen, "--frames: '%s' names no frame", list);
        status = CS_EXIT_USAGE;
    }
    if (status != CS_EXIT_OK) {
        free(frames);
        *count = 0;
        return status;
    }
    *out = frames;
    return CS_EXIT_OK;
}

/* ---------------------------------------------------------------- frames */

/* The cloths of one frame, read by name. */
typedef struct frame_geometry {
    cs_frame_layout layout;    /* how the run's frames hold the scene's cloths */
    cs_trimesh **meshes;       /* per cloth: its mesh of the file */
    cs_trimesh *file;          /* a file without the cloths' objects, merged */
    const double **x;          /* scene file: per cloth, the scene's positions */
    cs_frame_cloths cloths;
} frame_geometry;

static void frame_geometry_clear(frame_geometry *g)
{
    cs_trimesh_destroy(g->file);
    g->file = NULL;
    for (int c = 0; g->meshes && c < g->layout.ncloths; c++) {
        cs_trimesh_destroy(g->meshes[c]);
        g->meshes[c] = NULL;
    }
}

/* ------------------------------------------------------------------ main */

typedef struct job {
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
} job;

/* Loads the geometry of frame f into j->geom: per cloth its object of the
 * frame, read by name; a file without them (an older run's, or a scene
 * changed since) is drawn as one mesh in the first cloth's colour, as the
 * command says once. */
static int get_frame(job *j, int f, char *err, size_t errlen)
{
    frame_geometry *g = &j->geom;
    frame_geometry_clear(g);
    if (!j->run_mode) {
        for (int c = 0; c < j->scene->def.ncloths; c++)
            g->x[c] = j->scene->def.cloths[c].mesh->x;
        g->cloths = (cs_frame_cloths){.x = g->x};
        return CS_EXIT_OK;
    }
    int status = cs_frame_read(&g->layout, j->frames_dir, f, g->meshes, err, errlen);
    g->cloths = (cs_frame_cloths){.meshes = (const cs_trimesh *const *)g->meshes};
    if (status != CS_EXIT_INPUT || g->layout.format == CS_MESH_PLY)
        return status;
    char path[4096], why[ERRLEN];
    cs_frame_file_path(&g->layout, j->frames_dir, f, 0, path, sizeof path);
    snprintf(why, sizeof why, "%s", err);
    if (access(path, F_OK) != 0 || !(g->file = cs_mesh_read(path, err, errlen)))
        return CS_EXIT_INPUT;
    g->cloths = (cs_frame_cloths){.merged = g->file};
    if (!j->merged_said && !j->o->quiet)
        fprintf(stderr, "clothsim render: %s: all cloth is drawn as one mesh in the first "
                        "cloth's colour\n", why);
    j->merged_said = true;
    return CS_EXIT_OK;
}

static int render_frames(job *j, const int *frames, int nframes)
{
    char err[ERRLEN];
    for (int k = 0; k < nframes; k++) {
        int f = frames[k];
        int status = get_frame(j, f, err, sizeof err);
        cs_render_stats st;
        if (status == CS_EXIT_OK)
            status = cs_scene_render_draw(j->sr, f / j->fps, &j->geom.cloths, NULL, j->image, &st,
                                          err, sizeof err);
        if (status != CS_EXIT_OK) {
            fprintf(stderr, "clothsim render: frame %d: %s\n", f, err);
            return status;
        }
        char path[4200];
        cs_frame_path(path, sizeof path, j->out_dir, f, NULL, "png");
        if (cs_image_write_png(j->image, path, err, sizeof err) != CS_OK) {
            fprintf(stderr, "clothsim render: %s\n", err);
            return CS_EXIT_OUTPUT;
        }
        if (!j->o->quiet)
            printf("frame %d: %s (%.2f s)\n", f, path, st.seconds);
    }
    if (!j->o->quiet)
        printf("rendered %d image%s into %s\n", nframes, nframes == 1 ? "" : "s", j->out_dir);
    return CS_EXIT_OK;
}

/* ------------------------------------------------------------ animations */

/* dir/leaf as an ffmpeg image pattern: a '%' of dir doubled, leaf (which
 * holds the number's conversion) as it is. 0, or -1 when it does not fit. */
static int image_pattern(const char *dir, const char *leaf, char *out, size_t len)
{
    size_t k = 0;
    bool fits = true;
    for (const char *s = dir; *s && fits; s++) {
        fits = k + 3 < len;
        if (fits && *s == '%')
            out[k++] = '%';
        if (fits)
            out[k++] = *s;
    }
    int n = fits ? snprintf(out + k, len - k, "/%s", leaf) : -1;
    if (n < 0 || (size_t)n >= len - k) {
        fprintf(stderr, "clothsim render: the folder name %s is too long for ffmpeg\n", dir);
        return -1;
    }
    return 0;
}

/* The one way turntables and --animation make an animation: the PNGs that
 * pattern numbers first .. first + count - 1, at fps, become DIR/BASE.mp4
 * and DIR/BASE.gif through the ffmpeg program (cs_render_animation); the
 * files of an earlier animation of that name go first. *made is false when
 * ffmpeg is not installed. Returns 0, or CS_EXIT_OUTPUT when ffmpeg failed
 * (its message and ours said; the PNGs stay). */
static int make_animation(const job *j, const char *pattern, int first, int count, double fps,
                          const char *base, bool *made)
{
    static const char *const exts[] = {"mp4", "gif"};
    *made = false;
    for (int e = 0; e < 2; e++) {
        char path[4300];
        snprintf(path, sizeof path, "%s/%s.%s", j->out_dir, base, exts[e]);
        if (unlink(path) != 0 && errno != ENOENT) {
            fprintf(stderr, "clothsim render: cannot remove the old %s: %s\n", path,
                    strerror(errno));
            return CS_EXIT_OUTPUT;
        }
    }
    for (int e = 0; e < 2; e++) {
        char path[4300], err[ERRLEN];
        snprintf(path, sizeof path, "%s/%s.%s", j->out_dir, base, exts[e]);
        int rc = cs_render_animation(pattern, first, count, fps, path, err, sizeof err);
        if (rc == 0)
            return CS_EXIT_OK;
        if (rc < 0) {
            fprintf(stderr, "clothsim render: %s; the images are kept in %s\n", err,
                    j->out_dir);
            return CS_EXIT_OUTPUT;
        }
        *made = true;
        if (!j->o->quiet)
            printf("animation: %s\n", path);
    }
    return CS_EXIT_OK;
}

/* Links DIR/frame_NNNN.png of the listed frames as TMPDIR/000000.png, ... in
 * their order (a hard link, else a symbolic one): what ffmpeg's numbered
 * input needs when the frames are not consecutive. Returns how many were
 * linked (all on success); the caller removes them. */
static int link_frames(const char *dir, const char *tmpdir, const int *frames, int nframes)
{
    for (int k = 0; k < nframes; k++) {
        char from[4200], to[4200], rel[64];
        cs_frame_path(from, sizeof from, dir, frames[k], NULL, "png");
        snprintf(to, sizeof to, "%s/%06d.png", tmpdir, k);
        cs_frame_path(rel, sizeof rel, "..", frames[k], NULL, "png");
        if (link(from, to) != 0 && symlink(rel, to) != 0) {
            fprintf(stderr, "clothsim render: cannot link %s as %s: %s\n", from, to,
                    strerror(errno));
            return k;
        }
    }
    return nframes;
}

/* --animation: the frames just rendered, in the order listed, at the run's
 * frames per second. */
static int render_animation(job *j, const int *frames, int nframes)
{
    bool consecutive = true;
    for (int k = 1; k < nframes; k++)
        consecutive = consecutive && frames[k] == frames[0] + k;
    char pattern[8800], tmpdir[4300] = "";
    int status = CS_EXIT_OK, linked = 0;
    bool made = false;
    if (consecutive) {
        if (image_pattern(j->out_dir, "frame_%04d.png", pattern, sizeof pattern) != 0)
            status = CS_EXIT_OUTPUT;
        else
            status = make_animation(j, pattern, frames[0], nframes, j->fps, "animation", &made);
    } else {
        snprintf(tmpdir, sizeof tmpdir, "%s/.animation.XXXXXX", j->out_dir);
        if (!mkdtemp(tmpdir)) {
            fprintf(stderr, "clothsim render: cannot create %s: %s\n", tmpdir, strerror(errno));
            return CS_EXIT_OUTPUT;
        }
        linked = link_frames(j->out_dir, tmpdir, frames, nframes);
        if (linked < nframes)
            status = CS_EXIT_OUTPUT;
        else if (image_pattern(tmpdir, "%06d.png", pattern, sizeof pattern) != 0)
            status = CS_EXIT_OUTPUT;
        else
            status = make_animation(j, pattern, 0, nframes, j->fps, "animation", &made);
        for (int k = 0; k < linked; k++) {
            char path[4400];
            snprintf(path, sizeof path, "%s/%06d.png", tmpdir, k);
            unlink(path);
        }
        rmdir(tmpdir);
    }
    if (status == CS_EXIT_OK && !made)
        fprintf(stderr, "clothsim render: no animation: ffmpeg is not installed (not on the "
                        "PATH); the %d PNG frame%s %s in %s\n", nframes,
                nframes == 1 ? "" : "s", nframes == 1 ? "is" : "are", j->out_dir);
    return status;
}

/* view_<digits>.png of an earlier turntable would join this one's animation. */
static int remove_old_views(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    int rc = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        const char *s = e->d_name;
        if (strncmp(s, "view_", 5) != 0 || s[5] < '0' || s[5] > '9')
            continue;
        s += 5;
        while (*s >= '0' && *s <= '9')
            s++;
        if (strcmp(s, ".png") != 0)
            continue;
        char path[4400];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (unlink(path) != 0) {
            fprintf(stderr, "clothsim render: cannot remove the old view %s: %s\n", path,
                    strerror(errno));
            rc = -1;
            break;
        }
    }
    closedir(d);
    return rc;
}

static int render_turntable(job *j, int f)
{
    char err[ERRLEN];
    int n = j->o->turntable;
    if (remove_old_views(j->out_dir) != 0)
        return CS_EXIT_OUTPUT;
    int status = get_frame(j, f, err, sizeof err);
    if (status != CS_EXIT_OK) {
        fprintf(stderr, "clothsim render: frame %d: %s\n", f, err);
        return status;
    }
    double t = f / j->fps, centre[3];
    cs_scene_render_centre(j->sr, t, &j->geom.cloths, centre);
    cs_render_camera cam = cs_scene_render_camera(j->sr, t);
    int thumb = j->image->width < 200 ? j->image->width : 200;
    cs_image **thumbs = calloc((size_t)n, sizeof *thumbs);
    char (*labels)[48] = calloc((size_t)n, sizeof *labels);
    const char **label_ptrs = calloc((size_t)n, sizeof *label_ptrs);
    if (!thumbs || !labels || !label_ptrs) {
        fprintf(stderr, "clothsim render: out of memory\n");
        status = CS_EXIT_OUTPUT;
    }
    for (int k = 0; k < n && status == CS_EXIT_OK; k++) {
        double angle = 2 * M_PI * k / n;
        cs_render_camera view =
            cs_render_camera_orbit(&cam, centre, cs_scene_render_up(j->sr), angle);
        cs_render_stats st;
        status = cs_scene_render_draw(j->sr, t, &j->geom.cloths, &view, j->image, &st, err,
                                      sizeof err);
        if (status != CS_EXIT_OK) {
            fprintf(stderr, "clothsim render: frame %d, view %d: %s\n", f, k, err);
            break;
        }
        char path[4200];
        snprintf(path, sizeof path, "%s/view_%03d.png", j->out_dir, k);
        if (cs_image_write_png(j->image, path, err, sizeof err) != CS_OK) {
            fprintf(stderr, "clothsim render: %s\n", err);
            status = CS_EXIT_OUTPUT;
            break;
        }
        if (!(thumbs[k] = cs_image_shrink(j->image, thumb))) {
            fprintf(stderr, "clothsim render: out of memory\n");
            status = CS_EXIT_OUTPUT;
            break;
        }
        snprintf(labels[k], sizeof labels[k], "frame %d, %.0f\u00b0", f, angle * 180 / M_PI);
        label_ptrs[k] = labels[k];
        if (!j->o->quiet)
            printf("view %d: %s (%.2f s)\n", k, path, st.seconds);
    }
    if (status == CS_EXIT_OK) {
        char path[4200];
        snprintf(path, sizeof path, "%s/contact_sheet.png", j->out_dir);
        int cols = n <= 4 ? n : n <= 8 ? 4 : (int)ceil(sqrt((double)n));
        if (cs_render_contact_sheet(path, n, (const cs_image *const *)thumbs, label_ptrs, cols,
                                    thumb, err, sizeof err) != CS_OK) {
            fprintf(stderr, "clothsim render: %s\n", err);
            status = CS_EXIT_OUTPUT;
        } else if (!j->o->quiet) {
            printf("contact sheet: %s\n", path);
        }
    }
    if (status == CS_EXIT_OK && n > 1) {
        /* Only if ffmpeg is installed; without it the sheet is the result. */
        char pattern[8800];
        bool made;
        if (image_pattern(j->out_dir, "view_%03d.png", pattern, sizeof pattern) != 0)
            status = CS_EXIT_OUTPUT;
        else
            status = make_animation(j, pattern, 0, n, 12.0, "turntable", &made);
    }
    for (int k = 0; thumbs && k < n; k++)
        cs_image_destroy(thumbs[k]);
    free(thumbs);
    free(labels);
    free(label_ptrs);
    return status;
}

int cs_render_main(int argc, char **argv)
{
    render_options o;
    int status = parse_options(argc, argv, &o);
    if (status >= 0) {
        free(o.overrides);
        return status;
    }
    job j;
    memset(&j, 0, sizeof j);
    j.o = &o;
    cs_scene *scene = NULL;
    char **all_overrides = NULL;
    int *frames = NULL, nframes = 0;
    char err[ERRLEN] = "";

    struct stat st;
    if (stat(o.target, &st) != 0) {
        fprintf(stderr, "clothsim render: cannot read %s: %s\n", o.target, strerror(errno));
        status = CS_EXIT_INPUT;
        goto done;
    }
    j.run_mode = S_ISDIR(st.st_mode);
    const char *scene_path = o.target;
    if (j.run_mode) {
        if ((status = cs_run_info_read(o.target, &j.info, err, sizeof err)) != CS_EXIT_OK) {
            fprintf(stderr, "clothsim render: %s\n", err);
            goto done;
        }
        scene_path = o.scene_path ? o.scene_path : j.info.scene_file;
    } else if (o.scene_path) {
        status = cs_cli_error(&CLI, "%s",
                              "--scene is for a run folder; TARGET is already a scene file");
        goto done;
    }

    /* The run's overrides first, then the command line's. */
    int nover = j.info.noverrides + o.noverrides;
    all_overrides = calloc((size_t)nover + 1, sizeof *all_overrides);
    if (!all_overrides) {
        fprintf(stderr, "clothsim: out of memory\n");
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    for (int i = 0; i < j.info.noverrides; i++)
        all_overrides[i] = j.info.overrides[i];
    for (int i = 0; i < o.noverrides; i++)
        all_overrides[j.info.noverrides + i] = o.overrides[i];
    int rc = cs_scene_load(scene_path, nover, (const char *const *)all_overrides, &scene, err,
                           sizeof err);
    if (rc != CS_OK) {
        fprintf(stderr, "clothsim render: %s\n", err[0] ? err : "cannot load the scene");
        if (j.run_mode && access(scene_path, R_OK) != 0)
            fprintf(stderr, "clothsim render: %s/summary.json names the scene file '%s'; run "
                            "from where the run was started, or give it with --scene FILE\n",
                    o.target, scene_path);
        status = cs_exit_status(rc);
        goto done;
    }
    j.scene = scene;
    j.fps = j.run_mode && j.info.fps > 0 ? j.info.fps : scene->def.fps;
    if (!(j.fps > 0))
        j.fps = 24;

    /* Which frames. */
    int available = j.run_mode ? j.info.frames_written : 1;
    const char *list = o.frames ? o.frames : (o.turntable ? "last" : "all");
    status = parse_frames(list, available, &frames, &nframes, err, sizeof err);
    if (status != CS_EXIT_OK) {
        if (!j.run_mode && status == CS_EXIT_INPUT)
            fprintf(stderr, "clothsim render: --frames %s: %s is a scene file, which has only "
                            "its initial state, frame 0\n", list, o.target);
        else if (status == CS_EXIT_USAGE)
            cs_cli_error(&CLI, "%s", err);
        else
            fprintf(stderr, "clothsim render: %s\n", err);
        goto done;
    }
    if (o.turntable && o.animation) {
        status = cs_cli_error(&CLI, "%s", "--animation and --turntable do not go together "
                                          "(a turntable makes its own animation)");
        goto done;
    }
    if (o.turntable && nframes != 1) {
        status = cs_cli_error(&CLI, "%s",
                              "--turntable renders one frame: give --frames N (or last)");
        goto done;
    }

    /* Where to. */
    const char *leaf = o.turntable ? "turntable" : "images";
    if (o.out_dir)
        snprintf(j.out_dir, sizeof j.out_dir, "%s", o.out_dir);
    else if (j.run_mode)
        snprintf(j.out_dir, sizeof j.out_dir, "%s/%s", o.target, leaf);
    else {
        char base[2048];
        cs_outdir_default(scene->name, base, sizeof base);
        snprintf(j.out_dir, sizeof j.out_dir, "%s/%s", base, leaf);
    }

    j.sr = cs_scene_render_create(scene, &o.settings, o.quiet ? NULL : stderr, err, sizeof err,
                                  &status);
    if (!j.sr) {
        fprintf(stderr, "clothsim render: %s\n", err);
        goto done;
    }
    j.image = cs_image_create(o.settings.width, o.settings.height);
    int ncloths = scene->def.ncloths;
    j.geom.x = calloc((size_t)ncloths + 1, sizeof *j.geom.x);
    j.geom.meshes = calloc((size_t)ncloths + 1, sizeof *j.geom.meshes);
    const char **names = calloc((size_t)ncloths + 1, sizeof *names);
    for (int c = 0; names && c < ncloths; c++)
        names[c] = scene->def.cloths[c].name;
    bool ok = names && (!j.run_mode || cs_frame_layout_init(&j.geom.layout, j.info.format,
                                                            ncloths, names) == 0);
    free(names);
    snprintf(j.frames_dir, sizeof j.frames_dir, "%s/frames", o.target);
    if (!j.image || !j.geom.x || !j.geom.meshes || !ok) {
        fprintf(stderr, "clothsim render: out of memory for a %dx%d image\n", o.settings.width,
                o.settings.height);
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    if (cs_make_dirs(j.out_dir) != 0) {
        fprintf(stderr, "clothsim render: cannot create %s: %s\n", j.out_dir, strerror(errno));
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    status = o.turntable ? render_turntable(&j, frames[0]) : render_frames(&j, frames, nframes);
    if (status == CS_EXIT_OK && o.animation)
        status = render_animation(&j, frames, nframes);

done:
    frame_geometry_clear(&j.geom);
    cs_frame_layout_free(&j.geom.layout);
    free(j.geom.meshes);
    free(j.geom.x);
    cs_image_destroy(j.image);
    cs_scene_render_destroy(j.sr);
    if (scene)
        cs_scene_destroy(scene);
    free(frames);
    free(all_overrides);
    cs_run_info_free(&j.info);
    free(o.overrides);
    return status;
}
