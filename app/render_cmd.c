/* render_cmd.c: `clothsim render TARGET`: images of a run's frames (TARGET
 * is its output folder) or of a scene's initial state (TARGET is the scene
 * file), and turntables.
 *
 * A run folder names its scene file and the --set overrides it ran with in
 * summary.json, so the scene is reloaded exactly: cloth colours, bodies
 * and their motion, the camera. A frame file holds every cloth merged, one
 * after the other in scene order, and reading it joins identical vertices;
 * OBJ also renumbers them. So a frame is split back into cloths by the
 * scene's triangle counts, each cloth taking its own triangles and the
 * vertices they use, whatever their order. When the counts disagree the
 * frame is drawn as one mesh in the first cloth's colour, and the command
 * says so once.
 */
#include "app/fsutil.h"
#include "app/render_cmd.h"

#include "app/run.h"
#include "app/scene_render.h"
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
        "                       contact_sheet.png, and turntable.gif if ffmpeg is installed\n"
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
        "  4    an image could not be written, or memory ran out\n",
        out);
}

static void usage_error(const char *fmt, const char *arg)
{
    fprintf(stderr, "clothsim render: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\nusage: clothsim render (RUN_DIR | SCENE) [-o DIR] [--engine embree|preview]\n"
                    "                       [--frames LIST] [--size WxH] [--samples N]\n"
                    "                       [--turntable N] [--set KEY=VALUE]...\n"
                    "'clothsim render --help' explains every option.\n");
}

typedef struct render_options {
    const char *target;
    const char *out_dir;
    const char *scene_path;
    const char *frames;
    cs_render_settings settings;
    bool samples_given;
    int turntable;
    int noverrides;
    char **overrides;
    bool quiet;
} render_options;

enum {
    OPT_FRAMES = 256, OPT_SIZE, OPT_SAMPLES, OPT_BOUNCES, OPT_THREADS, OPT_FLAT,
    OPT_WIREFRAME, OPT_TURNTABLE, OPT_SET, OPT_SCENE
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
            if (!*optarg) {
                usage_error("%s", "--output needs a directory name");
                return CS_EXIT_USAGE;
            }
            o->out_dir = optarg;
            break;
        case 'e':
            if (!cs_render_engine_from_name(optarg, &o->settings.engine)) {
                usage_error("--engine: '%s' is not one of embree, preview", optarg);
                return CS_EXIT_USAGE;
            }
            break;
        case OPT_FRAMES:
            o->frames = optarg;
            break;
        case OPT_SIZE:
            if ((rc = cs_parse_size(optarg, &o->settings.width, &o->settings.height, err,
                                    sizeof err))) {
                fprintf(stderr, "clothsim render: %s\n", err);
                return rc == 1 ? CS_EXIT_USAGE : CS_EXIT_INPUT;
            }
            break;
        case OPT_SAMPLES:
            if ((rc = cs_parse_count(optarg, "--samples", 1, CS_RENDER_MAX_SAMPLES,
                                     &o->settings.samples, err, sizeof err))) {
                fprintf(stderr, "clothsim render: %s\n", err);
                return rc == 1 ? CS_EXIT_USAGE : CS_EXIT_INPUT;
            }
            o->samples_given = true;
            break;
        case OPT_BOUNCES:
            if ((rc = cs_parse_count(optarg, "--bounces", 0, 16, &o->settings.bounces, err,
                                     sizeof err))) {
                fprintf(stderr, "clothsim render: %s\n", err);
                return rc == 1 ? CS_EXIT_USAGE : CS_EXIT_INPUT;
            }
            break;
        case OPT_THREADS:
            if ((rc = cs_parse_count(optarg, "--threads", 0, 1024, &o->settings.threads, err,
                                     sizeof err))) {
                fprintf(stderr, "clothsim render: %s\n", err);
                return rc == 1 ? CS_EXIT_USAGE : CS_EXIT_INPUT;
            }
            break;
        case OPT_FLAT:
            o->settings.flat = true;
            break;
        case OPT_WIREFRAME:
            o->settings.wireframe = true;
            break;
        case OPT_TURNTABLE:
            if ((rc = cs_parse_count(optarg, "--turntable", 1, MAX_TURNTABLE, &o->turntable,
                                     err, sizeof err))) {
                fprintf(stderr, "clothsim render: %s\n", err);
                return rc == 1 ? CS_EXIT_USAGE : CS_EXIT_INPUT;
            }
            break;
        case OPT_SET:
            if (!strchr(optarg, '=') || optarg[0] == '=') {
                usage_error("--set needs KEY=VALUE, got '%s'", optarg);
                return CS_EXIT_USAGE;
            }
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
        case ':':
            usage_error("option '%s' needs a value", argv[optind - 1]);
            return CS_EXIT_USAGE;
        default: {
            const char *arg = argv[optind - 1];
            char shortopt[3] = {'-', (char)optopt, '\0'};
            if (strncmp(arg, "--", 2) != 0 && optopt > ' ' && optopt < 127)
                arg = shortopt;
            usage_error("unknown option '%s'", arg);
            return CS_EXIT_USAGE;
        }
        }
    }
    if (optind >= argc) {
        usage_error("%s", "no run folder or scene file given");
        return CS_EXIT_USAGE;
    }
    if (argc - optind > 1) {
        usage_error("one run folder or scene file only; '%s' is one too many", argv[optind + 1]);
        return CS_EXIT_USAGE;
    }
    o->target = argv[optind];
    if (o->settings.engine == CS_RENDER_PREVIEW && !o->samples_given)
        o->settings.samples = 4;
    return -1;
}

/* ------------------------------------------------------------ run folder */

typedef struct run_info {
    char *scene_file;
    int noverrides;
    char **overrides;
    char format[8];
    int frames_written;
    double fps;
} run_info;

static void run_info_free(run_info *r)
{
    free(r->scene_file);
    for (int i = 0; i < r->noverrides; i++)
        free(r->overrides[i]);
    free(r->overrides);
}

static char *read_text(const char *path, char *err, size_t errlen)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) {
        snprintf(err, errlen, "cannot read %s: %s", path, strerror(errno));
        return NULL;
    }
    size_t cap = 4096, len = 0;
    char *text = malloc(cap);
    while (text) {
        size_t n = fread(text + len, 1, cap - len - 1, fp);
        len += n;
        if (len + 1 < cap)
            break;
        char *grown = cap < (64u << 20) ? realloc(text, cap * 2) : NULL;
        if (!grown) {
            free(text);
            text = NULL;
            break;
        }
        text = grown;
        cap *= 2;
    }
    fclose(fp);
    if (!text)
        snprintf(err, errlen, "cannot read %s: too large or out of memory", path);
    else
        text[len] = '\0';
    return text;
}

/* Reads DIR/summary.json; returns 0 or an exit status with err. */
static int read_run_info(const char *dir, run_info *info, char *err, size_t errlen)
{
    memset(info, 0, sizeof *info);
    char path[4096];
    snprintf(path, sizeof path, "%s/summary.json", dir);
    if (access(path, F_OK) != 0) {
        snprintf(err, errlen,
                 "%s has no summary.json: give the output folder of 'clothsim run' or a "
                 "scene file",
                 dir);
        return CS_EXIT_INPUT;
    }
    char *text = read_text(path, err, errlen);
    if (!text)
        return CS_EXIT_INPUT;
    cJSON *root = cJSON_Parse(text);
    free(text);
    const cJSON *scene = root ? cJSON_GetObjectItemCaseSensitive(root, "scene_file") : NULL;
    const cJSON *format = root ? cJSON_GetObjectItemCaseSensitive(root, "format") : NULL;
    const cJSON *written = root ? cJSON_GetObjectItemCaseSensitive(root, "frames_written") : NULL;
    const cJSON *fps = root ? cJSON_GetObjectItemCaseSensitive(root, "fps") : NULL;
    const cJSON *over = root ? cJSON_GetObjectItemCaseSensitive(root, "overrides") : NULL;
    cs_mesh_format f;
    if (!cJSON_IsString(scene) || !cJSON_IsString(format) || !cJSON_IsNumber(written) ||
        !cJSON_IsNumber(fps) || !cs_mesh_format_from_name(format->valuestring, &f) ||
        strlen(format->valuestring) >= sizeof info->format || (over && !cJSON_IsArray(over))) {
        snprintf(err, errlen,
                 "%s: not a summary written by 'clothsim run' (needs scene_file, format, "
                 "frames_written, fps)",
                 path);
        cJSON_Delete(root);
        return CS_EXIT_INPUT;
    }
    info->scene_file = strdup(scene->valuestring);
    snprintf(info->format, sizeof info->format, "%s", cs_mesh_format_extension(f));
    info->frames_written = written->valuedouble > 0 && written->valuedouble < 1e8
                               ? (int)written->valuedouble
                               : 0;
    info->fps = fps->valuedouble;
    int n = over ? cJSON_GetArraySize(over) : 0;
    info->overrides = calloc((size_t)n + 1, sizeof *info->overrides);
    bool ok = info->scene_file && info->overrides;
    const cJSON *item;
    if (ok && over)
        cJSON_ArrayForEach(item, over) {
            if (!cJSON_IsString(item)) {
                snprintf(err, errlen, "%s: \"overrides\" must be a list of strings", path);
                cJSON_Delete(root);
                return CS_EXIT_INPUT;
            }
            if (!(info->overrides[info->noverrides] = strdup(item->valuestring))) {
                ok = false;
                break;
            }
            info->noverrides++;
        }
    cJSON_Delete(root);
    if (!ok) {
        snprintf(err, errlen, "out of memory");
        return CS_EXIT_OUTPUT;
    }
    return CS_EXIT_OK;
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

/* ------------------------------------------------------------------ utils */

/* out/<scene name>, the name made safe for a path (as `clothsim run`). */
static void scene_out_dir(const char *name, char *out, size_t len)
{
    if (!name || !*name || strcmp(name, ".") == 0 || strcmp(name, "..") == 0)
        name = "scene";
    size_t n = snprintf(out, len, "out/");
    for (const char *s = name; *s && n + 1 < len; s++) {
        char ch = *s;
        bool safe = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '-' || ch == '_' || ch == '.';
        out[n++] = safe ? ch : '_';
    }
    out[n] = '\0';
}

/* The cloths of one frame, split back into the scene's cloths. */
typedef struct frame_geometry {
    cs_trimesh *file;          /* what the frame file held */
    cs_trimesh **parts;        /* per cloth: its triangles of the file */
    const double **x;          /* scene file: per cloth, the scene's positions */
    cs_frame_cloths cloths;
} frame_geometry;

static void frame_geometry_clear(frame_geometry *g, int ncloths)
{
    cs_trimesh_destroy(g->file);
    g->file = NULL;
    for (int c = 0; g->parts && c < ncloths; c++) {
        cs_trimesh_destroy(g->parts[c]);
        g->parts[c] = NULL;
    }
}

/* Cloth c is the file's triangles [first, first + scene nt_c), with the
 * vertices they use renumbered from 0. Returns false when memory runs out. */
static bool split_by_triangles(const cs_scene *scene, frame_geometry *g)
{
    const cs_trimesh *f = g->file;
    int *map = malloc(((size_t)f->nv + 1) * sizeof *map);
    if (!map)
        return false;
    for (int v = 0; v < f->nv; v++)
        map[v] = -1;
    int first = 0;
    bool ok = true;
    for (int c = 0; c < scene->def.ncloths && ok; c++) {
        int nt = scene->def.cloths[c].mesh->nt, nv = 0;
        const int *tri = f->tri + 3 * (size_t)first;
        for (int k = 0; k < 3 * nt; k++)
            if (map[tri[k]] < 0)
                map[tri[k]] = nv++;
        cs_trimesh *part = cs_trimesh_create(nv, nt);
        if (!part) {
            ok = false;
        } else {
            for (int k = 0; k < 3 * nt; k++) {
                int v = map[tri[k]];
                part->tri[k] = v;
                memcpy(part->x + 3 * (size_t)v, f->x + 3 * (size_t)tri[k], 3 * sizeof *part->x);
            }
            g->parts[c] = part;
        }
        for (int k = 0; k < 3 * nt; k++)
            map[tri[k]] = -1;
        first += nt;
    }
    free(map);
    return ok;
}

/* Reads a run's frame. Returns 0 or an exit status with err; *merged is set
 * when the file has to be drawn as one mesh. */
static int load_frame(const cs_scene *scene, const char *dir, const run_info *info, int frame,
                      frame_geometry *g, bool *merged, char *err, size_t errlen)
{
    char path[4096], msg[ERRLEN];
    snprintf(path, sizeof path, "%s/frames/frame_%04d.%s", dir, frame, info->format);
    if (access(path, F_OK) != 0) {
        snprintf(err, errlen, "%s: no such frame file (%s)", path, strerror(errno));
        return CS_EXIT_INPUT;
    }
    g->file = cs_mesh_read(path, msg, sizeof msg);
    if (!g->file) {
        snprintf(err, errlen, "%s", msg);
        return CS_EXIT_INPUT;
    }
    long total = 0;
    for (int c = 0; c < scene->def.ncloths; c++)
        total += scene->def.cloths[c].mesh->nt;
    *merged = total != g->file->nt;
    g->cloths = (cs_frame_cloths){.merged = g->file};
    if (!*merged) {
        if (!split_by_triangles(scene, g)) {
            snprintf(err, errlen, "out of memory splitting %s into cloths", path);
            return CS_EXIT_OUTPUT;
        }
        g->cloths = (cs_frame_cloths){.meshes = (const cs_trimesh *const *)g->parts};
    }
    return CS_EXIT_OK;
}

/* ------------------------------------------------------------------ main */

typedef struct job {
    render_options *o;
    const cs_scene *scene;
    bool run_mode;
    run_info info;
    double fps;
    char out_dir[4096];
    cs_scene_render *sr;
    cs_image *image;
    frame_geometry geom;
    bool merged_said;
} job;

/* Loads the geometry of frame f into j->geom. */
static int get_frame(job *j, int f, char *err, size_t errlen)
{
    frame_geometry_clear(&j->geom, j->scene->def.ncloths);
    if (!j->run_mode) {
        for (int c = 0; c < j->scene->def.ncloths; c++)
            j->geom.x[c] = j->scene->def.cloths[c].mesh->x;
        j->geom.cloths = (cs_frame_cloths){.x = j->geom.x};
        return CS_EXIT_OK;
    }
    bool merged = false;
    int status = load_frame(j->scene, j->o->target, &j->info, f, &j->geom, &merged, err, errlen);
    if (status == CS_EXIT_OK && merged && !j->merged_said && !j->o->quiet) {
        long total = 0;
        for (int c = 0; c < j->scene->def.ncloths; c++)
            total += j->scene->def.cloths[c].mesh->nt;
        fprintf(stderr,
                "clothsim render: frame %d holds %d triangles, the scene's cloths %ld: all "
                "cloth is drawn as one mesh in the first cloth's colour\n",
                f, j->geom.file->nt, total);
        j->merged_said = true;
    }
    return status;
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
        snprintf(path, sizeof path, "%s/frame_%04d.png", j->out_dir, f);
        if (cs_image_write_png(j->image, path, err, sizeof err) != CS_RENDER_OK) {
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
    const cs_render_camera *cam = cs_scene_render_camera(j->sr);
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
        cs_render_camera view = cs_render_camera_orbit(cam, centre, cam->up, angle);
        cs_render_stats st;
        status = cs_scene_render_draw(j->sr, t, &j->geom.cloths, &view, j->image, &st, err,
                                      sizeof err);
        if (status != CS_EXIT_OK) {
            fprintf(stderr, "clothsim render: frame %d, view %d: %s\n", f, k, err);
            break;
        }
        char path[4200];
        snprintf(path, sizeof path, "%s/view_%03d.png", j->out_dir, k);
        if (cs_image_write_png(j->image, path, err, sizeof err) != CS_RENDER_OK) {
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
                                    thumb, err, sizeof err) != CS_RENDER_OK) {
            fprintf(stderr, "clothsim render: %s\n", err);
            status = CS_EXIT_OUTPUT;
        } else if (!j->o->quiet) {
            printf("contact sheet: %s\n", path);
        }
    }
    if (status == CS_EXIT_OK && n > 1) {
        /* Only if ffmpeg happens to be installed; never required. */
        char pattern[4200], gif[4200];
        snprintf(pattern, sizeof pattern, "%s/view_%%03d.png", j->out_dir);
        snprintf(gif, sizeof gif, "%s/turntable.gif", j->out_dir);
        int rc = cs_render_animation(pattern, 12.0, gif, err, sizeof err);
        if (rc == 1 && !j->o->quiet)
            printf("animation: %s\n", gif);
        else if (rc < 0)
            fprintf(stderr, "clothsim render: no animation: %s\n", err);
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
        if ((status = read_run_info(o.target, &j.info, err, sizeof err)) != CS_EXIT_OK) {
            fprintf(stderr, "clothsim render: %s\n", err);
            goto done;
        }
        scene_path = o.scene_path ? o.scene_path : j.info.scene_file;
    } else if (o.scene_path) {
        usage_error("%s", "--scene is for a run folder; TARGET is already a scene file");
        status = CS_EXIT_USAGE;
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
    if (rc != CS_IMPORT_OK) {
        fprintf(stderr, "clothsim render: %s\n", err[0] ? err : "cannot load the scene");
        if (j.run_mode && access(scene_path, R_OK) != 0)
            fprintf(stderr, "clothsim render: %s/summary.json names the scene file '%s'; run "
                            "from where the run was started, or give it with --scene FILE\n",
                    o.target, scene_path);
        status = rc == CS_IMPORT_BAD_INPUT ? CS_EXIT_INPUT : CS_EXIT_OUTPUT;
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
            usage_error("%s", err);
        else
            fprintf(stderr, "clothsim render: %s\n", err);
        goto done;
    }
    if (o.turntable && nframes != 1) {
        usage_error("%s", "--turntable renders one frame: give --frames N (or last)");
        status = CS_EXIT_USAGE;
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
        scene_out_dir(scene->name, base, sizeof base);
        snprintf(j.out_dir, sizeof j.out_dir, "%s/%s", base, leaf);
    }

    j.sr = cs_scene_render_create(scene, &o.settings, o.quiet ? NULL : stderr, err, sizeof err,
                                  &status);
    if (!j.sr) {
        fprintf(stderr, "clothsim render: %s\n", err);
        goto done;
    }
    j.image = cs_image_create(o.settings.width, o.settings.height);
    j.geom.x = calloc((size_t)scene->def.ncloths + 1, sizeof *j.geom.x);
    j.geom.parts = calloc((size_t)scene->def.ncloths + 1, sizeof *j.geom.parts);
    if (!j.image || !j.geom.x || !j.geom.parts) {
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

done:
    if (scene)
        frame_geometry_clear(&j.geom, scene->def.ncloths);
    free(j.geom.parts);
    free(j.geom.x);
    cs_image_destroy(j.image);
    cs_scene_render_destroy(j.sr);
    if (scene)
        cs_scene_destroy(scene);
    free(frames);
    free(all_overrides);
    run_info_free(&j.info);
    free(o.overrides);
    return status;
}
