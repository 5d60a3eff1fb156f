/* run_options.c: the command line of `clothsim run`: its help, its
 * options checked and the scene and overrides they name. */
#include "app/run.h"
#include "app/run_internal.h"

#include "app/cli.h"
#include "app/outdir.h"
#include "import/import.h"

#include <errno.h>
#include <getopt.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

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
        "                       rank count)\n",
        out);
    fputs(
        "      --start-from RUN begin where the run folder RUN ended: its last state\n"
        "                       (and its frames, as frames 1 to N here) carried onto\n"
        "                       this scene's cloths of the same rest shape, at any\n"
        "                       resolution; then frames N+1 to --frames are simulated\n"
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
    "                    [--frames N] [--threads N] [--plan] [--resume] [--start-from RUN]\n"
    "                    [--quiet]\n"
    "'clothsim run --help' explains every option.\n",
    NULL, CS_EXIT_USAGE};

enum { OPT_SET = 256, OPT_FORMAT, OPT_FRAMES, OPT_PLAN, OPT_RENDER, OPT_SIZE, OPT_SAMPLES,
       OPT_THREADS, OPT_RESUME, OPT_START_FROM };

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

int cs_run_parse_options(int argc, char **argv, run_options *o)
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
        {"start-from", required_argument, NULL, OPT_START_FROM},
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
        case OPT_START_FROM:
            if (!*optarg)
                return cs_cli_error(&CLI, "%s", "--start-from needs a run folder");
            o->start_from = optarg;
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
    if (o->start_from && o->resume)
        return cs_cli_error(&CLI, "%s", "--start-from begins a new run; --resume continues one: "
                                        "give one of them");
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

void cs_run_free_options(run_options *o)
{
    free(o->overrides);
    free(o->frames_override);
    free(o->scene_in_dir);
    free(o->format_override);
}
