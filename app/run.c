/* run.c: `clothsim run SCENE`: load, simulate, write one mesh file per
 * frame, then report.
 *
 * Order of events: parse the command line; load the scene with the
 * overrides; build the plan and the simulation; (--plan: print and stop);
 * write frame 0; then per frame advance, write the mesh file, rewrite
 * summary.json. Every file appears atomically, so whatever stops the run
 * (instability, a signal, a full disk) leaves complete frames and a summary
 * that describes exactly them.
 */
#include "app/fsutil.h"
#include "app/run.h"

#include "app/progress.h"
#include "app/scene_render.h"
#include "app/summary.h"
#include "import/import.h"
#include "sim/sim.h"

#include <dirent.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#ifndef CS_VERSION
#define CS_VERSION "unknown"
#endif

#define ERRLEN 1024

/* ---------------------------------------------------------------- options */

typedef struct run_options {
    const char *scene_path;
    const char *out_dir;      /* NULL: out/<scene name> */
    const char *format;       /* NULL: the scene's output.format */
    int noverrides;
    char **overrides;         /* "KEY=VALUE", --frames last */
    char *frames_override;    /* owned "time.frames=N" */
    bool plan_only;
    bool quiet;
    const char *render;       /* --render ENGINE, --size, --samples; NULL: none */
    const char *render_size, *render_samples;
    int threads;              /* --threads N; 0: one per core (see cs_parallel_set_threads) */
} run_options;

void cs_run_help(FILE *out)
{
    fputs(
        "usage: clothsim run SCENE [options]\n"
        "\n"
        "Simulates the scene file SCENE (YAML) and writes one mesh file per frame,\n"
        "frame 0 being the initial state, with a progress display while it runs and\n"
        "a table of time per stage at the end.\n"
        "\n"
        "options:\n"
        "  -o, --output DIR     write into DIR (default: out/<scene name>): frames as\n"
        "                       DIR/frames/frame_0000.<ext>, ... and DIR/summary.json;\n"
        "                       frame files of an earlier run in DIR/frames are removed\n"
        "      --set KEY=VALUE  override a scene setting; KEY is a dotted path, VALUE is\n"
        "                       YAML, e.g. --set time.frames=10 --set gravity=[0,-9.8,0]\n"
        "                       --set cloths.0.material.node_mass=2e-6; repeatable, a\n"
        "                       later one wins over an earlier one\n"
        "      --frames N       simulate N frames after the initial one\n"
        "                       (shorthand for --set time.frames=N, applied last)\n"
        "      --format FMT     mesh format of the frames: ply (binary), obj or glb\n"
        "                       (glTF 2.0 binary); overrides the scene's output.format\n"
        "      --plan           print the stages a time step will run and the step size,\n"
        "                       then exit without simulating or writing anything\n"
        "      --render ENGINE  also render each frame as DIR/images/frame_NNNN.png:\n"
        "                       embree (ray traced) or preview (OSMesa); see\n"
        "                       'clothsim render --help' for rendering after a run\n"
        "      --size WxH       with --render: image size (default 640x480)\n"
        "      --samples N      with --render: samples per pixel (default 16; preview 4)\n"
        "      --threads N      OpenMP threads per rank (default: OMP_NUM_THREADS, else\n"
        "                       one per core the process may use, shared among the\n"
        "                       ranks mpirun started on the machine); the frames are\n"
        "                       the same bits at every thread count\n"
        "  -q, --quiet          no progress display\n"
        "  -h, --help           show this help\n"
        "\n"
        "DIR/summary.json is rewritten after every frame; its \"status\" is \"running\"\n"
        "until the run ends as \"ok\", \"unstable\", \"interrupted\" or \"failed\".\n"
        "\n"
        "exit status:\n"
        "  0    every frame written\n"
        "  1    bad command line\n"
        "  2    the scene is invalid (message: FILE:LINE: KEY: what was expected)\n"
        "  3    the simulation became unstable; the frames before are kept\n"
        "  4    output could not be written, or memory ran out\n"
        "  130  interrupted by SIGINT or SIGTERM; the frames before are kept\n",
        out);
}

static void usage_error(const char *fmt, const char *arg)
{
    fprintf(stderr, "clothsim run: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\nusage: clothsim run SCENE [-o DIR] [--set KEY=VALUE]... [--format ply|obj|glb]\n"
                    "                    [--frames N] [--threads N] [--plan] [--quiet]\n"
                    "'clothsim run --help' explains every option.\n");
}

enum { OPT_SET = 256, OPT_FORMAT, OPT_FRAMES, OPT_PLAN, OPT_RENDER, OPT_SIZE, OPT_SAMPLES,
       OPT_THREADS };

/* Whether text is a whole number in [lo, hi] (stored in *out if given). */
static bool whole_number(const char *text, long lo, long hi, int *out)
{
    char *end;
    errno = 0;
    long n = strtol(text, &end, 10);
    if (end == text || *end || errno || n < lo || n > hi)
        return false;
    if (out)
        *out = (int)n;
    return true;
}

/* Returns -1 to go on, else an exit status. */
static int parse_options(int argc, char **argv, run_options *o)
{
    static const struct option longopts[] = {
        {"output", required_argument, NULL, 'o'},
        {"set", required_argument, NULL, OPT_SET},
        {"format", required_argument, NULL, OPT_FORMAT},
        {"frames", required_argument, NULL, OPT_FRAMES},
        {"plan", no_argument, NULL, OPT_PLAN},
        {"render", required_argument, NULL, OPT_RENDER},
        {"size", required_argument, NULL, OPT_SIZE},
        {"samples", required_argument, NULL, OPT_SAMPLES},
        {"threads", required_argument, NULL, OPT_THREADS},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    memset(o, 0, sizeof *o);
    /* At most one override per argument, plus --frames. */
    o->overrides = calloc((size_t)argc + 1, sizeof *o->overrides);
    if (!o->overrides) {
        fprintf(stderr, "clothsim: out of memory\n");
        return CS_EXIT_OUTPUT;
    }
    const char *frames = NULL;

    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, ":o:qh", longopts, NULL)) != -1) {
        switch (c) {
        case 'o':
            if (!*optarg) {
                usage_error("%s", "--output needs a directory name");
                return CS_EXIT_USAGE;
            }
            o->out_dir = optarg;
            break;
        case OPT_SET:
            if (!strchr(optarg, '=') || optarg[0] == '=') {
                usage_error("--set needs KEY=VALUE, got '%s'", optarg);
                return CS_EXIT_USAGE;
            }
            o->overrides[o->noverrides++] = optarg;
            break;
        case OPT_FORMAT:
            if (!cs_mesh_format_from_name(optarg, NULL)) {
                usage_error("--format: '%s' is not one of ply, obj, glb", optarg);
                return CS_EXIT_USAGE;
            }
            o->format = optarg;
            break;
        case OPT_FRAMES:
            if (!whole_number(optarg, 0, 100000000, NULL)) {
                usage_error("--frames: '%s' is not a whole number of frames", optarg);
                return CS_EXIT_USAGE;
            }
            frames = optarg;
            break;
        case OPT_THREADS:
            if (!whole_number(optarg, 1, 4096, &o->threads)) {
                usage_error("--threads: '%s' is not a whole number from 1 to 4096", optarg);
                return CS_EXIT_USAGE;
            }
            break;
        case OPT_PLAN:
            o->plan_only = true;
            break;
        case OPT_RENDER:
            o->render = optarg;
            break;
        case OPT_SIZE:
            o->render_size = optarg;
            break;
        case OPT_SAMPLES:
            o->render_samples = optarg;
            break;
        case 'q':
            o->quiet = true;
            break;
        case 'h':
            cs_run_help(stdout);
            return CS_EXIT_OK;
        case ':':
            usage_error("option '%s' needs a value", argv[optind - 1]);
            return CS_EXIT_USAGE;
        default: {
            const char *arg = argv[optind - 1];
            char shortopt[3] = {'-', (char)optopt, '\0'};
            if (strncmp(arg, "--", 2) != 0 && optopt > ' ' && optopt < 127)
                arg = shortopt;   /* e.g. the x of -qx */
            usage_error("unknown option '%s'", arg);
            return CS_EXIT_USAGE;
        }
        }
    }
    if (optind >= argc) {
        usage_error("%s", "no scene file given");
        return CS_EXIT_USAGE;
    }
    if (argc - optind > 1) {
        usage_error("one scene file only; '%s' is one too many", argv[optind + 1]);
        return CS_EXIT_USAGE;
    }
    o->scene_path = argv[optind];
    if ((o->render_size || o->render_samples) && !o->render) {
        usage_error("%s", "--size and --samples go with --render ENGINE");
        return CS_EXIT_USAGE;
    }
    if (frames) {
        size_t len = strlen("time.frames=") + strlen(frames) + 1;
        o->frames_override = malloc(len);
        if (!o->frames_override) {
            fprintf(stderr, "clothsim: out of memory\n");
            return CS_EXIT_OUTPUT;
        }
        snprintf(o->frames_override, len, "time.frames=%s", frames);
        o->overrides[o->noverrides++] = o->frames_override;
    }
    return -1;
}

static void free_options(run_options *o)
{
    free(o->overrides);
    free(o->frames_override);
}

/* ------------------------------------------------------------------ utils */

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static volatile sig_atomic_t interrupted = 0;

static void on_signal(int sig)
{
    interrupted = sig;
}

/* The first SIGINT/SIGTERM asks the run to stop after the current frame;
 * the handler then resets, so a second one ends the process at once. */
static void install_signal_handlers(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND | SA_RESTART;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

/* "frame_<digits>.<ply|obj|glb>" with an optional ".tmp". */
static bool is_frame_file(const char *name)
{
    if (strncmp(name, "frame_", 6) != 0)
        return false;
    const char *s = name + 6;
    if (*s < '0' || *s > '9')
        return false;
    while (*s >= '0' && *s <= '9')
        s++;
    if (*s++ != '.')
        return false;
    cs_mesh_format f;
    char ext[4];
    if (strlen(s) < 3)
        return false;
    memcpy(ext, s, 3);
    ext[3] = '\0';
    if (!cs_mesh_format_from_name(ext, &f))
        return false;
    return s[3] == '\0' || strcmp(s + 3, ".tmp") == 0;
}

/* Frames of an earlier run would mix with this one's; remove them. */
static int remove_old_frames(const char *dir, char *err, size_t errlen)
{
    DIR *d = opendir(dir);
    if (!d) {
        snprintf(err, errlen, "cannot read %s: %s", dir, strerror(errno));
        return -1;
    }
    int rc = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (!is_frame_file(e->d_name))
            continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (unlink(path) != 0) {
            snprintf(err, errlen, "cannot remove the old frame %s/%s: %s", dir, e->d_name,
                     strerror(errno));
            rc = -1;
            break;
        }
    }
    closedir(d);
    return rc;
}

/* out/<scene name>, the name made safe for a path. */
static char *default_out_dir(const char *scene_name)
{
    const char *name = scene_name && *scene_name ? scene_name : "scene";
    size_t len = strlen(name);
    char *dir = malloc(len + 5);
    if (!dir)
        return NULL;
    memcpy(dir, "out/", 4);
    for (size_t i = 0; i < len; i++) {
        char ch = name[i];
        bool safe = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '-' || ch == '_' || ch == '.';
        dir[4 + i] = safe ? ch : '_';
    }
    dir[4 + len] = '\0';
    if (strcmp(dir, "out/.") == 0 || strcmp(dir, "out/..") == 0)
        strcpy(dir, "out/scene");
    return dir;
}

/* ----------------------------------------------------------------- output */

typedef struct run_state {
    const cs_scene *scene;
    cs_sim *sim;
    cs_mesh_format format;
    char *out_dir;
    char *frames_dir;
    char *summary_path;
    cs_mesh_view *views;     /* one per cloth */
    cs_run_render *render;   /* --render: an image per frame too */
    cs_summary summary;
    double start;            /* now_seconds() when the command began */
} run_state;

static int write_frame(run_state *r, int frame, char *err, size_t errlen)
{
    const double *x = cs_sim_positions(r->sim);
    int ncloths = cs_sim_cloth_count(r->sim);
    for (int c = 0; c < ncloths; c++) {
        const cs_trimesh *mesh = cs_sim_cloth_mesh(r->sim, c);
        r->views[c].x = x + 3 * (size_t)cs_sim_cloth_offset(r->sim, c);
        r->views[c].nv = mesh->nv;
        r->views[c].nt = mesh->nt;
        r->views[c].tri = mesh->tri;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/frame_%04d.%s", r->frames_dir, frame,
             cs_mesh_format_extension(r->format));
    double t0 = now_seconds();
    int rc = cs_mesh_write(path, r->format, ncloths, r->views, err, errlen);
    if (rc == CS_IMPORT_OK && r->render && cs_run_render_frame(r->render, r->sim, frame, err,
                                                               errlen) != 0)
        rc = CS_IMPORT_BAD_INPUT;
    r->summary.output_seconds += now_seconds() - t0;
    if (rc == CS_IMPORT_OK)
        r->summary.frames_written = frame + 1;
    return rc;
}

static int write_summary(run_state *r, char *err, size_t errlen)
{
    r->summary.total_seconds = now_seconds() - r->start;
    cs_summary_take_timing(&r->summary, r->sim);
    return cs_summary_write(&r->summary, r->summary_path, err, errlen);
}

static char *join_path(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    char *p = malloc(la + lb + 2);
    if (p) {
        memcpy(p, a, la);
        p[la] = '/';
        memcpy(p + la + 1, b, lb + 1);
    }
    return p;
}

/* ------------------------------------------------------------------- plan */

static int steps_per_frame(double fps, double dt)
{
    if (!(fps > 0) || !(dt > 0))
        return 0;
    long n = lround(1.0 / fps / dt);   /* as cs_sim_advance_frame counts them */
    return n > 0 ? (int)n : 1;
}

static void print_plan(const cs_scene *scene, const cs_sim *sim, FILE *out)
{
    cs_plan plan = cs_plan_from_def(&scene->def);
    int width = 0;
    for (int i = 0; i < plan.nstages; i++) {
        int n = (int)strlen(cs_stage_name(plan.stages[i]));
        if (n > width)
            width = n;
    }
    fprintf(out, "plan of scene '%s' (%s): %d stage%s per time step\n", scene->name,
            scene->path, plan.nstages, plan.nstages == 1 ? "" : "s");
    for (int i = 0; i < plan.nstages; i++)
        fprintf(out, "  %d. %-*s  %s\n", i + 1, width, cs_stage_name(plan.stages[i]),
                cs_stage_description(plan.stages[i]));
    double dt = cs_sim_dt(sim);
    fprintf(out, "step size %.6g s (stability limit %.6g s): %d steps per frame at %g fps\n",
            dt, cs_sim_stable_dt(sim), steps_per_frame(scene->def.fps, dt), scene->def.fps);
    fprintf(out, "  (2/omega_max, omega_max^2 by Lanczos iterations; Gershgorin's bound would "
            "give %.6g s)\n", cs_sim_gershgorin_dt(sim));
    fprintf(out, "%d frames after the initial one: %.6g s of simulated time; %d particles\n",
            scene->frames, scene->def.fps > 0 ? scene->frames / scene->def.fps : 0.0,
            cs_sim_particle_count(sim));
}

/* -------------------------------------------------------------- the run */

/* "frames 0 to 12 are", "frame 0 is", "no frame is": what a stopped run kept. */
static void frames_kept(int written, char *buf, size_t len)
{
    if (written > 1)
        snprintf(buf, len, "frames 0 to %d are", written - 1);
    else if (written == 1)
        snprintf(buf, len, "frame 0 is");
    else
        snprintf(buf, len, "no frame is");
}

/* Rank 0, after a frame simulated: the frame file, its record and the
 * summary. Returns CS_EXIT_OK to go on, a status to stop with the report,
 * or minus a status to stop without it. */
static int record_frame(run_state *r, int frame, const cs_frame_stats *stats, double seconds,
                        cs_progress *progress, double sim_start)
{
    char err[ERRLEN];
    cs_summary *s = &r->summary;
    if (interrupted) { /* arrived during the frame: write nothing more */
        s->status = "interrupted";
        return CS_EXIT_INTERRUPTED;
    }
    cs_frame_record rec = {
        .frame = frame,
        .time = cs_sim_time(r->sim),
        .stats = *stats,
        .seconds = seconds,
        .body_penetration = cs_plan_has(cs_sim_plan(r->sim), CS_STAGE_BODY_COLLISION)
                                ? cs_sim_body_penetration(r->sim)
                                : -1,
    };
    if (write_frame(r, frame, err, sizeof err) != CS_IMPORT_OK) {
        cs_progress_finish(progress);
        fprintf(stderr, "clothsim: %s\n", err);
        s->status = "failed";
        s->error = "a frame file could not be written";
        s->failed_frame = frame;
        return CS_EXIT_OUTPUT;
    }
    if (cs_summary_add_frame(s, &rec) != 0) {
        cs_progress_finish(progress);
        fprintf(stderr, "clothsim: out of memory\n");
        s->status = "failed";
        s->error = "out of memory";
        return CS_EXIT_OUTPUT;
    }
    if (write_summary(r, err, sizeof err) != 0) {
        cs_progress_finish(progress);
        fprintf(stderr, "clothsim: %s\n", err);
        return -CS_EXIT_OUTPUT;
    }
    cs_progress_frame(progress, frame, rec.time, now_seconds() - sim_start);
    if (!interrupted)
        return CS_EXIT_OK;
    s->status = "interrupted"; /* the frame is kept; nothing more is simulated */
    return CS_EXIT_INTERRUPTED;
}

/* Rank 0 writes, prints and decides; the others simulate their particles
 * and follow its decision after every frame (cs_sim_agree), so a failed
 * write or an interrupt stops every rank at the same frame. */
static int simulate(run_state *r, const run_options *o)
{
    char err[ERRLEN];
    cs_summary *s = &r->summary;
    bool root = cs_sim_rank(r->sim) == 0;
    int status = CS_EXIT_OK;

    install_signal_handlers();
    if (root) {
        if (cs_make_dirs(r->frames_dir) != 0) {
            fprintf(stderr, "clothsim: cannot create %s: %s\n", r->frames_dir, strerror(errno));
            status = CS_EXIT_OUTPUT;
        } else if (remove_old_frames(r->frames_dir, err, sizeof err) != 0) {
            fprintf(stderr, "clothsim: %s\n", err);
            status = CS_EXIT_OUTPUT;
        }
    }
    if ((status = cs_sim_agree(r->sim, status)) != CS_EXIT_OK)
        return status;

    cs_progress progress;
    cs_progress_init(&progress, stderr, o->quiet || !root, r->scene->frames);

    if (root) {
        if (interrupted) {
            s->status = "interrupted";
            status = CS_EXIT_INTERRUPTED;
        } else if (write_frame(r, 0, err, sizeof err) != CS_IMPORT_OK ||
                   write_summary(r, err, sizeof err) != 0) {
            fprintf(stderr, "clothsim: %s\n", err);
            status = -CS_EXIT_OUTPUT; /* stop without the report */
        }
    }
    if ((status = cs_sim_agree(r->sim, status)) < 0)
        return -status;

    cs_progress_frame(&progress, 0, cs_sim_time(r->sim), 0.0);
    double sim_start = now_seconds();
    for (int frame = 1; status == CS_EXIT_OK && frame <= r->scene->frames; frame++) {
        cs_frame_stats stats;
        memset(&stats, 0, sizeof stats);
        double t0 = now_seconds();
        int rc = cs_sim_advance_frame(r->sim, &stats);
        double seconds = now_seconds() - t0;
        s->simulation_seconds += seconds;

        if (rc == CS_ERR_UNSTABLE) { /* every rank sees the same rc */
            cs_progress_finish(&progress);
            char kept[64];
            frames_kept(s->frames_written, kept, sizeof kept);
            if (root)
                fprintf(stderr,
                        "clothsim: the simulation became unstable in frame %d (t=%.4g s): "
                        "NaN or runaway velocity; %s in %s\n",
                        frame, cs_sim_time(r->sim), kept, r->frames_dir);
            s->status = "unstable";
            s->error = "NaN or runaway velocity";
            s->failed_frame = frame;
            status = CS_EXIT_UNSTABLE;
            break;
        }
        if (rc != CS_OK) {
            cs_progress_finish(&progress);
            if (root)
                fprintf(stderr, "clothsim: frame %d failed (%s)\n", frame,
                        rc == CS_ERR_NOMEM ? "out of memory" : "simulation error");
            s->status = "failed";
            s->error = rc == CS_ERR_NOMEM ? "out of memory" : "simulation error";
            s->failed_frame = frame;
            status = CS_EXIT_OUTPUT;
            break;
        }
        if (root)
            status = record_frame(r, frame, &stats, seconds, &progress, sim_start);
        if ((status = cs_sim_agree(r->sim, status)) < 0)
            return -status;
    }
    cs_progress_finish(&progress);
    if (!root)
        return status;

    if (status == CS_EXIT_OK)
        s->status = "ok";
    if (status == CS_EXIT_INTERRUPTED) {
        char kept[64];
        frames_kept(s->frames_written, kept, sizeof kept);
        fprintf(stderr, "clothsim: interrupted; %s in %s\n", kept, r->frames_dir);
    }
    if (write_summary(r, err, sizeof err) != 0) {
        fprintf(stderr, "clothsim: %s\n", err);
        if (status == CS_EXIT_OK)
            status = CS_EXIT_OUTPUT;
    }
    cs_summary_print_table(s, stdout);
    if (status == CS_EXIT_OK)
        printf("wrote %d frame file%s to %s, summary in %s\n", s->frames_written,
               s->frames_written == 1 ? "" : "s", r->frames_dir, r->summary_path);
    fflush(stdout);
    return status;
}

int cs_run_main(int argc, char **argv)
{
    run_options o;
    int status = parse_options(argc, argv, &o);
    if (status >= 0) {
        free_options(&o);
        return status;
    }

    run_state r;
    memset(&r, 0, sizeof r);
    r.start = now_seconds();
    cs_summary_init(&r.summary);
    cs_scene *scene = NULL;
    char err[ERRLEN] = "";

    /* every rank loads the scene: the same file gives the same result, so
     * only rank 0 speaks */
    bool root = cs_parallel_rank() == 0;
    cs_parallel_set_threads(o.threads);
    int rc = cs_scene_load(o.scene_path, o.noverrides, (const char *const *)o.overrides, &scene,
                           err, sizeof err);
    if (rc != CS_IMPORT_OK) {
        if (root)
            fprintf(stderr, "clothsim: %s\n", err[0] ? err : "cannot load the scene");
        status = rc == CS_IMPORT_BAD_INPUT ? CS_EXIT_INPUT : CS_EXIT_OUTPUT;
        goto done;
    }
    r.scene = scene;
    for (int i = 0; i < scene->nnotes && root; i++) /* what import did with mesh files */
        fprintf(stderr, "clothsim: %s\n", scene->notes[i]);

    const char *format_name = o.format ? o.format : scene->output_format;
    if (!format_name)
        format_name = "ply";
    if (!cs_mesh_format_from_name(format_name, &r.format)) {
        if (root)
            fprintf(stderr, "clothsim: %s: output.format '%s' is not one of ply, obj, glb\n",
                scene->path, format_name);
        status = CS_EXIT_INPUT;
        goto done;
    }

    r.sim = cs_sim_create(&scene->def, err, sizeof err);
    if (!r.sim) {
        if (root)
            fprintf(stderr, "clothsim: %s: %s\n", scene->path, err[0] ? err : "invalid scene");
        status = CS_EXIT_INPUT;
        goto done;
    }
    if (o.plan_only) {
        if (root)
            print_plan(scene, r.sim, stdout);
        status = CS_EXIT_OK;
        goto done;
    }

    r.out_dir = o.out_dir ? strdup(o.out_dir) : default_out_dir(scene->name);
    r.frames_dir = r.out_dir ? join_path(r.out_dir, "frames") : NULL;
    r.summary_path = r.out_dir ? join_path(r.out_dir, "summary.json") : NULL;
    int ncloths = cs_sim_cloth_count(r.sim);
    r.views = calloc(ncloths > 0 ? (size_t)ncloths : 1, sizeof *r.views);
    if (!r.out_dir || !r.frames_dir || !r.summary_path || !r.views) {
        fprintf(stderr, "clothsim: out of memory\n");
        status = CS_EXIT_OUTPUT;
        goto done;
    }

    cs_summary *s = &r.summary;
    int triangles = 0;
    char (*names)[32] = calloc(ncloths > 0 ? (size_t)ncloths : 1, sizeof *names);
    if (!names) {
        fprintf(stderr, "clothsim: out of memory\n");
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    for (int c = 0; c < ncloths; c++) {
        const char *name = cs_sim_cloth_name(r.sim, c);
        if (!name || !*name) {
            snprintf(names[c], sizeof names[c], "cloth_%d", c);
            name = names[c];
        }
        r.views[c].name = name;
        triangles += cs_sim_cloth_mesh(r.sim, c)->nt;
    }
    s->scene = scene->name;
    s->self_collision = scene->def.self_collision;
    s->scene_file = scene->path;
    s->noverrides = o.noverrides;
    s->overrides = (const char *const *)o.overrides;
    s->version = CS_VERSION;
    s->format = cs_mesh_format_extension(r.format);
    s->output_dir = r.out_dir;
    s->frames_requested = scene->frames;
    s->fps = scene->def.fps;
    s->dt = cs_sim_dt(r.sim);
    s->steps_per_frame = steps_per_frame(scene->def.fps, s->dt);
    s->particles = cs_sim_particle_count(r.sim);
    s->springs = cs_sim_spring_count(r.sim);
    s->triangles = triangles;
    s->plan = *cs_sim_plan(r.sim);

    if (o.render && root) {
        r.render = cs_run_render_create(scene, r.sim, o.render, o.render_size, o.render_samples,
                                        r.out_dir, &status);
        if (!r.render) {
            free(names);
            goto done;
        }
    }
    status = simulate(&r, &o);
    free(names);

done:
    cs_run_render_destroy(r.render);
    cs_summary_free(&r.summary);
    free(r.views);
    free(r.out_dir);
    free(r.frames_dir);
    free(r.summary_path);
    if (r.sim)
        cs_sim_destroy(r.sim);
    if (scene)
        cs_scene_destroy(scene);
    free_options(&o);
    return status;
}
