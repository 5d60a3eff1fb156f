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
#include "app/run.h"

#include "app/checkpoint.h"
#include "app/cli.h"
#include "app/export.h"
#include "app/input_check.h"
#include "app/outdir.h"
#include "app/progress.h"
#include "app/scene_render.h"
#include "app/summary.h"
#include "common/util.h"
#include "import/import.h"
#include "sim/sim.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
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
    char *scene_in_dir;       /* owned DIR/scene.yaml when SCENE is a run folder */
    char *format_override;    /* owned "output.format=FMT" for --format: loaded
                                 last, so the resolved scene holds the format */
    bool plan_only;
    bool quiet;
    bool resume;              /* --resume: continue the run in DIR */
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
        "a table of time per stage at the end. DIR/scene.yaml is the scene resolved\n"
        "(every setting written out, overrides applied) and DIR/assets/ the mesh\n"
        "files and level sets it read: SCENE may be such a run folder, which then\n"
        "stands for its scene.yaml and is the output folder (run DIR --resume).\n"
        "\n"
        "options:\n"
        "  -o, --output DIR     write into DIR (default: out/<scene name>): frames as\n"
        "                       DIR/frames/frame_0000.<ext>, ..., DIR/summary.json,\n"
        "                       DIR/frames.jsonl (a record per frame) and DIR/state.h5\n"
        "                       (what --resume needs); the frames, records and state\n"
        "                       of an earlier run in DIR are removed; one run at a time\n"
        "                       (another run writing into DIR is refused, exit 4);\n"
        "                       at the end DIR/cloth.usda (output.usd, on) and DIR/pc2/\n"
        "                       (output.pc2, off), even if stopped: 'clothsim help export'\n"
        "      --resume         continue the run in DIR from its last frame (after a\n"
        "                       kill, a crash or --frames K): the same scene and --set\n"
        "                       overrides are required (--frames may grow), and the\n"
        "                       frames are the bits of a run never interrupted (same\n"
        "                       rank count)\n"
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
        "While the run goes, each frame appends its record to DIR/frames.jsonl and\n"
        "DIR/summary.json is rewritten at most once a second without the records; at\n"
        "the end it is written whole. Its \"status\" is \"running\" until the run\n"
        "ends as \"ok\", \"unstable\", \"interrupted\" or \"failed\" (a run killed\n"
        "outright stays \"running\": --resume continues it).\n"
        "\n"
        "exit status:\n"
        "  0    every frame written\n"
        "  1    bad command line\n"
        "  2    the scene is invalid (message: FILE:LINE: KEY: what was expected)\n"        "       or --resume refused: the scene, an override or the format changed\n"
        "       (the difference named), or DIR holds no state to resume from\n"
        "  3    the simulation became unstable, or no collision-free state follows\n"
        "       its scripts; the frames before are kept\n"
        "  4    output could not be written (the message names the file and why),\n"
        "       DIR is in use by another run, or memory ran out; the frames before\n"
        "       are kept\n"
        "  130  interrupted by SIGINT or SIGTERM; the frames before are kept\n",
        out);
}

static const cs_cli CLI = {
    "run",
    "usage: clothsim run SCENE [-o DIR] [--set KEY=VALUE]... [--format ply|obj|glb]\n"
    "                    [--frames N] [--threads N] [--plan] [--resume] [--quiet]\n"
    "'clothsim run --help' explains every option.\n",
    NULL, CS_EXIT_USAGE};

enum { OPT_SET = 256, OPT_FORMAT, OPT_FRAMES, OPT_PLAN, OPT_RENDER, OPT_SIZE, OPT_SAMPLES,
       OPT_THREADS, OPT_RESUME };

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
        {"resume", no_argument, NULL, OPT_RESUME},
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
            if (!*optarg)
                return cs_cli_error(&CLI, "%s", "--output needs a directory name");
            o->out_dir = optarg;
            break;
        case OPT_SET:
            if (!strchr(optarg, '=') || optarg[0] == '=')
                return cs_cli_error(&CLI, "--set needs KEY=VALUE, got '%s'", optarg);
            o->overrides[o->noverrides++] = optarg;
            break;
        case OPT_FORMAT:
            if (!cs_mesh_format_from_name(optarg, NULL))
                return cs_cli_error(&CLI, "--format: '%s' is not one of ply, obj, glb", optarg);
            o->format = optarg;
            break;
        case OPT_FRAMES:
            if (!whole_number(optarg, 0, CS_MAX_FRAMES, NULL))
                return cs_cli_error(&CLI,
                                    "--frames: '%s' is not a whole number from 0 to 100000000",
                                    optarg);
            frames = optarg;
            break;
        case OPT_THREADS:
            if (!whole_number(optarg, 1, 4096, &o->threads))
                return cs_cli_error(&CLI, "--threads: '%s' is not a whole number from 1 to 4096",
                                    optarg);
            break;
        case OPT_PLAN:
            o->plan_only = true;
            break;
        case OPT_RESUME:
            o->resume = true;
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
        default:
            return cs_cli_option_error(&CLI, c, argv);
        }
    }
    int status = 0;
    o->scene_path = cs_cli_operand(&CLI, argc, argv, optind, "scene file", &status);
    if (!o->scene_path)
        return status;
    /* a run folder stands for its resolved scene, and is the output */
    struct stat st;
    if (stat(o->scene_path, &st) == 0 && S_ISDIR(st.st_mode)) {
        if (!(o->scene_in_dir = cs_outdir_scene(o->scene_path))) {
            fprintf(stderr, "clothsim run: %s is a folder without scene.yaml: give a scene "
                            "file, or a run folder written by 'clothsim run'\n", o->scene_path);
            return CS_EXIT_INPUT;
        }
        if (!o->out_dir)
            o->out_dir = o->scene_path;
        o->scene_path = o->scene_in_dir;
    }
    if ((o->render_size || o->render_samples) && !o->render)
        return cs_cli_error(&CLI, "%s", "--size and --samples go with --render ENGINE");
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
    free(o->scene_in_dir);
    free(o->format_override);
}

/* ------------------------------------------------------------------ utils */

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
    /* a file-size limit (ulimit -f) then fails the write (EFBIG), which is
     * reported with exit 4, instead of killing the run mid-file */
    signal(SIGXFSZ, SIG_IGN);
}

/* ----------------------------------------------------------------- output */

typedef struct run_state {
    const cs_scene *scene;
    cs_sim *sim;
    cs_mesh_format format;
    cs_outdir out;           /* the folder, its paths and its lock */
    const char *frames_dir;  /* out's, for the messages */
    const char *summary_path;
    cs_run_identity id;      /* what a resumed run must be made from */
    int first_frame;         /* frame 0, or the frame --resume continues after */
    double summary_at;       /* cs_now() of the last summary.json written */
    cs_mesh_view *views;     /* one per cloth */
    cs_run_render *render;   /* --render: an image per frame too */
    cs_summary summary;
    double start;            /* cs_now() when the command began */
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
    double t0 = cs_now();
    int rc = cs_frame_write(&r->out.layout, r->frames_dir, frame, r->views, err, errlen);
    if (rc == CS_OK && r->render && cs_run_render_frame(r->render, r->sim, frame, err,
                                                               errlen) != 0)
        rc = CS_ERR_BAD_INPUT;
    r->summary.output_seconds += cs_now() - t0;
    if (rc == CS_OK)
        r->summary.frames_written = frame + 1;
    return rc;
}

/* The summary's wall time and stage table brought up to now */
static void take_totals(run_state *r)
{
    r->summary.total_seconds = r->summary.base_seconds + cs_now() - r->start;
    cs_summary_take_timing(&r->summary, r->sim);
}

/* While the status is "running" summary.json leaves the frame records to
 * frames.jsonl (a constant cost per frame); once it is final, whole. */
static int write_summary(run_state *r, char *err, size_t errlen)
{
    take_totals(r);
    bool final = strcmp(r->summary.status, "running") != 0;
    r->summary_at = cs_now();
    return cs_summary_write(&r->summary, r->summary_path, final, err, errlen);
}

/* Rank 0, after frame's file (and record): the state --resume continues
 * from (cs_sim_state_gather came first, on every rank). */
static int save_state(run_state *r, int frame, const char *hash, char *err, size_t errlen)
{
    /* the totals a resumed run carries on from are those of this frame
     * (the summary is written at most once a second, so its totals could
     * lag frames behind, and a resumed run's stage table lost them) */
    take_totals(r);
    double t0 = cs_now();
    int rc = cs_outdir_save_state(&r->out, &r->id, frame, hash, r->sim, &r->summary, err,
                                  errlen);
    r->summary.output_seconds += cs_now() - t0;
    return rc;
}

/* ------------------------------------------------------------------- plan */

static int steps_per_frame(double fps, double dt)
{
    if (!(fps > 0) || !(dt > 0))
        return 0;
    long n = lround(1.0 / fps / dt);   /* as cs_sim_advance_frame counts them */
    return n > 0 ? (int)n : 1;
}

/* Every row of the stage table in the order they run: the plan's numbered,
 * the others with what would bring them in. */
static void print_plan(const cs_scene *scene, const cs_sim *sim, FILE *out)
{
    const cs_plan *plan = cs_sim_plan(sim);
    int width = 0;
    for (int i = 0; i < CS_STAGE_COUNT; i++) {
        int n = (int)strlen(cs_stage_name(cs_stage_in_order(i)));
        if (n > width)
            width = n;
    }
    fprintf(out, "plan of scene '%s' (%s): %d of %d stages\n", scene->name, scene->path,
            plan->nstages, CS_STAGE_COUNT);
    const char *when = NULL;
    for (int i = 0, number = 0; i < CS_STAGE_COUNT; i++) {
        cs_stage st = cs_stage_in_order(i);
        if (!when || strcmp(when, cs_stage_when(st)) != 0)
            fprintf(out, " %s:\n", when = cs_stage_when(st));
        if (cs_plan_has(plan, st))
            fprintf(out, "  %2d. %-*s  %s\n", ++number, width, cs_stage_name(st),
                    cs_stage_description(st));
        else
            fprintf(out, "   -  %-*s  left out: needs %s\n", width, cs_stage_name(st),
                    cs_stage_condition(st));
    }
    double dt = cs_sim_dt(sim);
    fprintf(out, "step size %.6g s (stability limit %.6g s): %d steps per frame at %g fps\n",
            dt, cs_sim_stable_dt(sim), steps_per_frame(scene->def.fps, dt), scene->def.fps);
    fprintf(out, "  (limits at rest: undamped 2/omega_max %.6g s by Lanczos iterations, %.6g s "
            "by Gershgorin's bound; the damped scheme's %.6g s)\n", cs_sim_undamped_dt(sim),
            cs_sim_gershgorin_dt(sim), cs_sim_damped_dt(sim));
    if (!(scene->def.dt > 0)) {
        bool damped = cs_sim_step_limit(sim) == CS_STEP_DAMPED;
        fprintf(out, "  time.step_limit %s%s", scene->def.step_limit == CS_STEP_AUTO ? "auto: " : "",
                damped ? "damped" : "undamped");
        if (damped)
            fprintf(out, ": the step is chosen again before every outer step, smaller where "
                    "the cloth is stretched");
        fputc('\n', out);
    }
    if (scene->def.self_collision && scene->def.self.pruning == CS_PRUNING_PATH)
        fprintf(out, "  self_collision.pruning path: step A keeps only the pairs whose straight "
                "relative paths come within the thickness\n");
    fprintf(out, "%d frames after the initial one: %.6g s of simulated time; %d particles\n",
            scene->frames, scene->def.fps > 0 ? scene->frames / scene->def.fps : 0.0,
            cs_sim_particle_count(sim));
    /* a plan holds the scene, the mesh, the bodies' level sets and the
     * springs; a run adds the step's scratch (plan_only leaves it out) */
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) == 0)
        fprintf(out, "memory for the setup: %.0f MiB at its peak (this process); a run adds "
                "the step's arrays and the pair lists, which grow with the contacts\n",
                ru.ru_maxrss / 1024.0);
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

/* Rank 0: a write failed; says what, and which frames are kept. */
static int output_failed(run_state *r, cs_progress *progress, const char *err, const char *what,
                         int frame)
{
    cs_summary *s = &r->summary;
    char kept[64];
    cs_progress_finish(progress);
    frames_kept(s->frames_written, kept, sizeof kept);
    fprintf(stderr, "clothsim: %s\nclothsim: %s; %s kept in %s\n", err, what, kept,
            r->frames_dir);
    s->status = "failed";
    s->error = what;
    s->failed_frame = frame;
    return CS_EXIT_OUTPUT;
}

/* Rank 0, after a frame simulated: the frame file, its record, the state
 * to resume from and the summary, in that order (a state is never ahead of
 * its frame and record). Returns CS_EXIT_OK to go on, a status to stop
 * with the report, or minus a status to stop without it. */
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
    cs_state_hash(r->sim, rec.state_hash);
    if (write_frame(r, frame, err, sizeof err) != CS_OK)
        return output_failed(r, progress, err, "a frame file could not be written", frame);
    if (cs_summary_add_frame(s, &rec, err, sizeof err) != 0)
        return output_failed(r, progress, err, "the frame's record could not be written", frame);
    if (save_state(r, frame, rec.state_hash, err, sizeof err) != 0)
        return output_failed(r, progress, err, "the state to resume from could not be written",
                             frame);
    if (cs_outdir_sync(&r->out, false, err, sizeof err) != 0)
        return output_failed(r, progress, err, "the output could not be written to the disk",
                             frame);
    /* while running, at most once a second: frames.jsonl has every frame */
    if (cs_now() - r->summary_at >= 1.0 && write_summary(r, err, sizeof err) != 0) {
        cs_progress_finish(progress);
        fprintf(stderr, "clothsim: %s\n", err);
        return -CS_EXIT_OUTPUT;
    }
    cs_progress_frame(progress, frame, rec.time, cs_now() - sim_start);
    if (!interrupted)
        return CS_EXIT_OK;
    s->status = "interrupted"; /* the frame is kept; nothing more is simulated */
    return CS_EXIT_INTERRUPTED;
}

/* Rank 0, before the first frame simulated: frame 0 and its state, or
 * after --resume only the summary. Returns as record_frame does. */
static int start_output(run_state *r, cs_progress *progress)
{
    char err[ERRLEN];
    if (r->first_frame == 0 && write_frame(r, 0, err, sizeof err) != CS_OK)
        return output_failed(r, progress, err, "a frame file could not be written", 0);
    if (r->first_frame == 0 && save_state(r, 0, r->summary.initial_hash, err, sizeof err) != 0)
        return output_failed(r, progress, err, "the state to resume from could not be written",
                             0);
    /* before any frame is simulated: the folder runs, renders and resumes
     * on its own (after --resume with the frames asked for now) */
    if (cs_outdir_write_scene(&r->out, r->scene, err, sizeof err) != 0)
        return output_failed(r, progress, err, "the resolved scene could not be written",
                             r->first_frame);
    if (write_summary(r, err, sizeof err) != 0) {
        fprintf(stderr, "clothsim: %s\n", err);
        return -CS_EXIT_OUTPUT; /* stop without the report */
    }
    return CS_EXIT_OK;
}

/* Rank 0, after the last frame: DIR/cloth.usda and the point caches
 * (output.usd, output.pc2) of the frames written, those of a run that
 * stopped early too. Returns the run's status, or CS_EXIT_OUTPUT when a
 * run that was ok could not write them. */
static int export_frames(run_state *r, int status)
{
    cs_export_what what = {r->scene->output_usd, r->scene->output_pc2};
    cs_summary *s = &r->summary;
    if ((!what.usd && !what.pc2) || s->frames_written < 1)
        return status;
    char err[ERRLEN];
    double t0 = cs_now();
    int rc = cs_export_run(r->scene, r->format, r->out.dir, s->frames_written, r->scene->def.fps,
                           what, NULL, err, sizeof err);
    s->output_seconds += cs_now() - t0;
    if (rc != CS_EXIT_OK)
        fprintf(stderr, "clothsim: %s\n", err);
    if (rc == CS_EXIT_OK || status != CS_EXIT_OK)
        return status; /* the run's own failure comes first */
    s->status = "failed";
    s->error = "the USD stage or the point caches could not be written";
    return CS_EXIT_OUTPUT;
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
    if (root)
        status = cs_outdir_start(&r->out, o->resume, o->quiet, &r->id, r->sim, &r->summary,
                                 r->scene->frames, &r->first_frame);
    if ((status = cs_sim_agree(r->sim, status)) != CS_EXIT_OK)
        return status;
    r->first_frame = cs_sim_agree(r->sim, r->first_frame);
    if (o->resume && cs_sim_state_scatter(r->sim) != CS_OK) { /* every rank takes it */
        if (root)
            fprintf(stderr, "clothsim: out of memory\n");
        return CS_EXIT_OUTPUT;
    }

    cs_progress progress;
    cs_progress_init(&progress, stderr, o->quiet || !root, r->first_frame, r->scene->frames);

    cs_sim_state_gather(r->sim);
    if (root) {
        if (interrupted) {
            s->status = "interrupted";
            status = CS_EXIT_INTERRUPTED;
        } else {
            status = start_output(r, &progress);
        }
    }
    if ((status = cs_sim_agree(r->sim, status)) < 0)
        return -status;

    cs_progress_frame(&progress, r->first_frame, cs_sim_time(r->sim), 0.0);
    double sim_start = cs_now();
    for (int frame = r->first_frame + 1; status == CS_EXIT_OK && frame <= r->scene->frames;
         frame++) {
        cs_frame_stats stats;
        memset(&stats, 0, sizeof stats);
        double t0 = cs_now();
        int rc = cs_sim_advance_frame(r->sim, &stats);
        double seconds = cs_now() - t0;
        s->simulation_seconds += seconds;

        if (rc == CS_ERR_UNSTABLE) { /* every rank sees the same rc */
            cs_progress_finish(&progress);
            char kept[64];
            frames_kept(s->frames_written, kept, sizeof kept);
            static char why[192]; /* lives as long as the summary that points at it */
            const char *stage = "?";
            double speed = 0, limit = 0;
            if (!cs_sim_runaway(r->sim, &stage, &speed, &limit))
                snprintf(why, sizeof why, "NaN or runaway velocity");
            else if (isfinite(speed))
                snprintf(why, sizeof why,
                         "speed %.3g m/s after stage %s, beyond the %.3g m/s the scene's "
                         "gravity, bodies, scripts and wind can explain", speed, stage, limit);
            else
                snprintf(why, sizeof why, "NaN or infinite velocity after stage %s", stage);
            if (root)
                fprintf(stderr,
                        "clothsim: the simulation became unstable in frame %d (t=%.4g s): "
                        "%s; %s in %s\n",
                        frame, cs_sim_time(r->sim), why, kept, r->frames_dir);
            s->status = "unstable";
            s->error = why;
            s->failed_frame = frame;
            status = CS_EXIT_UNSTABLE;
            break;
        }
        if (rc == CS_ERR_SCRIPT) { /* every rank sees the same rc */
            cs_progress_finish(&progress);
            char kept[64];
            frames_kept(s->frames_written, kept, sizeof kept);
            static char why[1024]; /* lives as long as the summary that points at it */
            if (!cs_sim_script_conflict(r->sim, why, sizeof why))
                snprintf(why, sizeof why, "no collision-free state follows the scripts");
            if (root)
                fprintf(stderr, "clothsim: %s: frame %d cannot follow its script: %s; %s in %s\n",
                        r->scene->path, frame, why, kept, r->frames_dir);
            s->status = "unstable";
            s->error = why;
            s->failed_frame = frame;
            status = CS_EXIT_UNSTABLE;
            break;
        }
        if (rc != CS_OK) {
            cs_progress_finish(&progress);
            if (root)
                fprintf(stderr, "clothsim: frame %d failed (%s)\n", frame,
                        cs_status_message(rc));
            s->status = "failed";
            s->error = cs_status_message(rc);
            s->failed_frame = frame;
            status = cs_exit_status(rc);
            break;
        }
        cs_sim_state_gather(r->sim); /* the state to resume from, on rank 0 */
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
    if (status == CS_EXIT_OK || status == CS_EXIT_UNSTABLE || status == CS_EXIT_INTERRUPTED)
        status = export_frames(r, status);
    if (write_summary(r, err, sizeof err) != 0 ||
        cs_outdir_sync(&r->out, true, err, sizeof err) != 0) {
        fprintf(stderr, "clothsim: %s\n", err);
        if (status == CS_EXIT_OK)
            status = CS_EXIT_OUTPUT;
    }
    cs_summary_print_table(s, stdout);
    if (status == CS_EXIT_OK)
        printf("wrote %d frame file%s to %s, summary in %s\n", s->frames_written,
               s->frames_written == 1 ? "" : "s", r->frames_dir, r->summary_path);
    if (status == CS_EXIT_OK && r->scene->output_usd)
        printf("the frames as one animated USD stage: %s/cloth.usda\n", r->out.dir);
    if (status == CS_EXIT_OK && r->scene->output_pc2)
        printf("Blender point caches and their rest poses: %s/pc2/\n", r->out.dir);
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
    r.out.lock = CS_DIR_LOCK_NONE;
    r.start = cs_now();
    cs_summary_init(&r.summary);
    cs_scene *scene = NULL;
    char err[ERRLEN] = "";

    /* every rank loads the scene: the same file gives the same result, so
     * only rank 0 speaks */
    bool root = cs_parallel_rank() == 0;
    cs_parallel_set_threads(o.threads);
    /* --format as an override loaded after the others (the resolved scene
     * holds it); the run's identity and summary keep the overrides given */
    if (o.format) {
        size_t len = strlen("output.format=") + strlen(o.format) + 1;
        if (!(o.format_override = malloc(len))) {
            fprintf(stderr, "clothsim: out of memory\n");
            status = CS_EXIT_OUTPUT;
            goto done;
        }
        snprintf(o.format_override, len, "output.format=%s", o.format);
        o.overrides[o.noverrides] = o.format_override;
    }
    int rc = cs_scene_load(o.scene_path, o.noverrides + (o.format ? 1 : 0),
                           (const char *const *)o.overrides, &scene, err, sizeof err);
    if (rc != CS_OK) {
        if (root)
            fprintf(stderr, "clothsim: %s\n", err[0] ? err : "cannot load the scene");
        status = cs_exit_status(rc);
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

    scene->def.plan_only = o.plan_only; /* --plan allocates nothing the step needs */
    rc = cs_sim_create_checked(&scene->def, &r.sim, err, sizeof err);
    if (rc != CS_OK) {
        if (root)
            fprintf(stderr, "clothsim: %s: %s\n", scene->path, err[0] ? err : "invalid scene");
        status = cs_exit_status(rc);
        goto done;
    }
    if (root && scene->def.dt > cs_sim_damped_dt(r.sim)) /* allowed: a sufficient bound */
        fprintf(stderr,
                "clothsim: warning: %s: time.dt %.3g s is %.3g times the stability limit "
                "%.3g s of the cloth at rest (damping included); it may still run, and a "
                "run that blows up stops with exit status 3\n",
                scene->path, scene->def.dt, scene->def.dt / cs_sim_damped_dt(r.sim),
                cs_sim_damped_dt(r.sim));
    if (o.plan_only) {
        if (root)
            print_plan(scene, r.sim, stdout);
        status = CS_EXIT_OK;
        goto done;
    }

    /* The start's intersections and other problems (app/input_check.c):
     * an intersecting start is refused unless the scene accepts it. */
    if (!o.resume) {
        status = root ? cs_input_check_start(scene, o.quiet, stderr) : CS_EXIT_OK;
        if ((status = cs_sim_agree(r.sim, status)) != CS_EXIT_OK)
            goto done;
    }

    int ncloths = cs_sim_cloth_count(r.sim);
    r.views = calloc(ncloths > 0 ? (size_t)ncloths : 1, sizeof *r.views);
    if (cs_outdir_init(&r.out, o.out_dir, scene->name) != 0 || !r.views) {
        fprintf(stderr, "clothsim: out of memory\n");
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    r.frames_dir = r.out.frames_dir;
    r.summary_path = r.out.summary_path;
    /* every rank: the same file gives the same outcome */
    if (cs_run_identity_init(&r.id, scene->path, o.noverrides, (const char *const *)o.overrides,
                             cs_mesh_format_extension(r.format), r.sim, scene, err,
                             sizeof err) != 0) {
        if (root)
            fprintf(stderr, "clothsim: %s\n", err);
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    /* the folder's own scene.yaml: rewritten as the run goes, so only its
     * resolved scene can tell whether it is the run's */
    char *own = cs_outdir_scene(r.out.dir);
    struct stat a, b;
    r.id.own_scene = own && stat(own, &a) == 0 && stat(scene->path, &b) == 0 &&
                     a.st_dev == b.st_dev && a.st_ino == b.st_ino;
    free(own);
    cs_state_hash(r.sim, r.summary.initial_hash); /* frame 0's, before any resume */

    cs_summary *s = &r.summary;
    int triangles = 0;
    const char **names = calloc(ncloths > 0 ? (size_t)ncloths : 1, sizeof *names);
    for (int c = 0; names && c < ncloths; c++) {
        names[c] = cs_sim_cloth_name(r.sim, c);
        triangles += cs_sim_cloth_mesh(r.sim, c)->nt;
    }
    if (!names || cs_frame_layout_init(&r.out.layout, r.format, ncloths, names) != 0) {
        free(names);
        fprintf(stderr, "clothsim: out of memory\n");
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    free(names);
    s->scene = scene->name;
    s->self_collision = scene->def.self_collision;
    for (int c = 0; c < scene->def.ncloths; c++)
        s->scripts = s->scripts || scene->def.cloths[c].nscripts > 0;
    s->script_zones =
        scene->def.self.script_zones == CS_SCRIPT_ZONES_HOLD ? "hold" : "follow";
    s->scene_file = scene->path;
    s->noverrides = o.noverrides;
    s->overrides = (const char *const *)o.overrides;
    s->version = CS_VERSION;
    s->format = cs_mesh_format_extension(r.format);
    s->output_dir = r.out.dir;
    s->frames_requested = scene->frames;
    s->fps = scene->def.fps;
    s->dt = cs_sim_dt(r.sim);
    if (!(scene->def.dt > 0))
        s->step_limit = cs_sim_step_limit(r.sim) == CS_STEP_DAMPED ? "damped" : "undamped";
    s->steps_per_frame = steps_per_frame(scene->def.fps, s->dt);
    s->particles = cs_sim_particle_count(r.sim);
    s->springs = cs_sim_spring_count(r.sim);
    s->triangles = triangles;
    s->plan = *cs_sim_plan(r.sim);

    if (o.render && root) {
        r.render = cs_run_render_create(scene, r.sim, o.render, o.render_size, o.render_samples,
                                        r.out.dir, &status);
        if (!r.render)
            goto done;
    }
    status = simulate(&r, &o);

done:
    cs_run_render_destroy(r.render);
    cs_summary_free(&r.summary);
    free(r.views);
    cs_run_identity_free(&r.id);
    cs_outdir_free(&r.out); /* the lock goes last */
    if (r.sim)
        cs_sim_destroy(r.sim);
    if (scene)
        cs_scene_destroy(scene);
    free_options(&o);
    return status;
}
