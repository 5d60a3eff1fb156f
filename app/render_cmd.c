/* render_cmd.c: `clothsim render TARGET`: its command line, the scene
 * reloaded, and which frames are drawn into which folder, for images of a
 * run's frames (TARGET is its output folder) or of a scene's initial state
 * (TARGET is the scene file), turntables, and animations of the frames
 * (--animation); render_frames.c, render_turntable.c and
 * render_animation.c draw and assemble them.
 *
 * A run folder holds its resolved scene, DIR/scene.yaml (an older one names
 * its scene file and the --set overrides it ran with in summary.json), so
 * the scene is reloaded exactly: cloth colours, bodies
 * and their motion, the camera.
 */
#include "app/render_cmd.h"
#include "app/render_cmd_internal.h"

#include "app/cli.h"
#include "app/outdir.h"
#include "app/run.h"
#include "app/scene_render.h"
#include "common/util.h"
#include "import/import.h"
#include "render/render.h"

#include <errno.h>
#include <getopt.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

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

int cs_render_main(int argc, char **argv)
{
    render_options o;
    int status = parse_options(argc, argv, &o);
    if (status >= 0) {
        free(o.overrides);
        return status;
    }
    render_job j;
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
    status = o.turntable ? cs_render_cmd_turntable(&j, frames[0])
                         : cs_render_cmd_frames(&j, frames, nframes);
    if (status == CS_EXIT_OK && o.animation)
        status = cs_render_cmd_animation(&j, frames, nframes);

done:
    cs_frame_geometry_clear(&j.geom);
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
