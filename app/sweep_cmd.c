/* sweep_cmd.c: `clothsim sweep SCENE --vary KEY=V1,V2,... -o DIR`.
 *
 * Order of events: parse the command line; pick each knob's reference
 * value (--reference, else the tightest by the table below); list the
 * combinations (every value of every knob) and the reference; load the
 * scene with each one's overrides (a bad key or value stops everything
 * before a folder is made, exit 2); then run them one after another, the
 * reference first, each a child `clothsim run` into a folder of its own;
 * last, read every run back, compare its frames with the reference's (and
 * with --analytic with the analytic solution) and write the tables and
 * pictures (sweep_output.c).
 */
#include "app/sweep_cmd.h"
#include "app/sweep_internal.h"

#include "app/cli.h"
#include "app/outdir.h"
#include "app/progress.h"
#include "app/run.h"
#include "app/sweep_metrics.h"
#include "common/util.h"
#include "import/import.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#define ERRLEN 1024
#define MAX_RUNS 1000

/* Which value of a knob is the tightest (the reference) when --reference
 * does not say: the smallest, or the largest where larger_tighter. A value
 * measures as its number, or for a list ("[40,40]") the product of its
 * numbers; '*' in a key stands for a cloth's index. time.dt `auto` (or 0)
 * has no measure: give --reference. */
static const struct {
    const char *key;
    bool larger_tighter;
} TIGHTEST[] = {
    {"time.dt", false},                    /* a smaller step */
    {"time.dt_safety", false},             /* a smaller fraction of the stability limit */
    {"time.cg_tolerance", false},          /* a smaller residual */
    {"time.collision_steps", false},       /* k_i: step C more often */
    {"time.cg_max_iterations", true},      /* a higher cap */
    {"self_collision.thickness", false},   /* a thinner repulsion layer */
    {"self_collision.zone_iterations", true}, /* more passes before impact zones */
    {"cloths.*.grid.resolution", true},    /* a finer mesh */
};
#define NTIGHTEST ((int)(sizeof TIGHTEST / sizeof TIGHTEST[0]))

void cs_sweep_help(FILE *out)
{
    fputs(
        "usage: clothsim sweep SCENE --vary KEY=V1,V2,... [--vary ...] -o DIR [options]\n"
        "\n"
        "Runs the scene once per combination of the varied settings, plus a reference\n"
        "run at the tightest value of each knob, and measures each run's cost and its\n"
        "error against the reference. The runs execute one after another, each a\n"
        "'clothsim run' with all threads (the --threads default), so their seconds\n"
        "compare.\n"
        "\n"
        "options:\n"
        "  -o, --output DIR       write into DIR: a run folder per combination,\n"
        "                         DIR/run_NNN_KEY=V.../ (frames, summary.json, run.log,\n"
        "                         errors.csv: the error per frame), DIR/reference_KEY=V.../\n"
        "                         when the reference is no combination, and DIR/sweep.csv,\n"
        "                         DIR/sweep.md (a row per run), DIR/sweep.png (error\n"
        "                         against seconds, log-log, a curve per knob) and\n"
        "                         DIR/cumulative_time.png (wall seconds summed over the\n"
        "                         frames, a curve per run)\n"
        "      --vary KEY=V1,V2,...\n"
        "                         a knob: KEY and values as for 'run --set' (a value\n"
        "                         may be a YAML list, [40,40]); repeatable, every\n"
        "                         combination runs (1000 at most)\n"
        "      --reference KEY=V  the reference's value of a varied KEY (default: the\n"
        "                         tightest: the smallest time.dt, time.dt_safety,\n"
        "                         time.cg_tolerance, time.collision_steps,\n"
        "                         self_collision.thickness; the largest\n"
        "                         time.cg_max_iterations, self_collision.zone_iterations,\n"
        "                         cloths.N.grid.resolution); required for other keys\n"
        "      --set KEY=VALUE    a setting of every run, e.g. --set time.frames=10\n"
        "      --repeat N         run each N times, one after another, and take the\n"
        "                         median wall seconds (default 1; the folder keeps the\n"
        "                         last run's frames and frames.jsonl)\n"
        "      --analytic incline\n"
        "                         measure each run against the analytic solution of a\n"
        "                         rigid body sliding with Coulomb friction on the scene's\n"
        "                         one plane (Figs. 7, 8): errors.csv and the tables get\n"
        "                         analytic_m (centre of mass against the analytic one,\n"
        "                         m), errors.csv the distance down the slope of both\n"
        "                         (travel_m, travel_analytic_m), sweep.png draws\n"
        "                         analytic_m, DIR/trajectory.png the distance against\n"
        "                         time; a knob without a tightest value needs no\n"
        "                         --reference (its first value is the reference)\n"
        "  -q, --quiet            no progress lines\n"
        "  -h, --help             show this help\n"
        "\n"
        "Errors (metres, the largest over frames; README, 'clothsim sweep'): vertex\n"
        "RMS and largest distance when the vertex counts match; centre of mass,\n"
        "bounding box and Hausdorff distance always; analytic_m with --analytic.\n"
        "\n"
        "exit status:\n"
        "  0    every run finished\n"
        "  1    bad command line\n"
        "  2    a --vary, --reference or --set setting (or the scene) is invalid;\n"
        "       nothing was run\n"
        "  3    a run did not finish (its row says how); the tables are written\n"
        "  4    output could not be written\n"
        "  130  interrupted\n",
        out);
}

static const cs_cli CLI = {
    "sweep",
    "usage: clothsim sweep SCENE --vary KEY=V1,V2,... [--vary ...] [--reference KEY=V]...\n"
    "                      [--set KEY=VALUE]... [--analytic incline] [--repeat N] -o DIR\n"
    "                      [--quiet]\n"
    "'clothsim sweep --help' explains every option.\n",
    NULL, CS_EXIT_USAGE};

/* ---------------------------------------------------------------- options */

static void free_options(sweep_options *o)
{
    for (int k = 0; k < o->nknobs; k++) {
        for (int i = 0; i < o->knobs[k].n; i++)
            free(o->knobs[k].values[i]);
        free(o->knobs[k].values);
        free(o->knobs[k].key);
    }
    free(o->knobs);
    free(o->refs);
    free(o->sets);
}

/* A bad setting: "clothsim sweep: what", exit 2 (nothing run yet). */
static int bad_setting(const char *fmt, const char *arg)
{
    fprintf(stderr, "clothsim sweep: ");
    fprintf(stderr, fmt, arg);
    fputc('\n', stderr);
    return CS_EXIT_INPUT;
}

/* "KEY=V1,V2,...": the values split at commas outside brackets. Returns -1
 * to go on, else an exit status. */
static int parse_vary(const char *arg, knob *k)
{
    const char *eq = strchr(arg, '=');
    if (!eq || eq == arg)
        return bad_setting("--vary needs KEY=V1,V2,..., got '%s'", arg);
    k->key = strndup(arg, (size_t)(eq - arg));
    k->values = calloc(strlen(eq) + 1, sizeof *k->values);
    if (!k->key || !k->values)
        return bad_setting("%s", "out of memory");
    int depth = 0;
    for (const char *p = eq + 1, *start = p;; p++) {
        if (*p == '[' || *p == '{')
            depth++;
        else if ((*p == ']' || *p == '}') && depth > 0)
            depth--;
        if (*p && (*p != ',' || depth > 0))
            continue;
        size_t len = (size_t)(p - start);
        if (len == 0)
            return bad_setting("--vary %s: an empty value", arg);
        if (!(k->values[k->n++] = strndup(start, len)))
            return bad_setting("%s", "out of memory");
        if (!*p)
            break;
        start = p + 1;
    }
    return -1;
}

enum { OPT_VARY = 256, OPT_REFERENCE, OPT_SET, OPT_ANALYTIC, OPT_REPEAT };

/* Returns -1 to go on, else an exit status. */
static int parse_options(int argc, char **argv, sweep_options *o)
{
    static const struct option longopts[] = {
        {"output", required_argument, NULL, 'o'},
        {"vary", required_argument, NULL, OPT_VARY},
        {"reference", required_argument, NULL, OPT_REFERENCE},
        {"set", required_argument, NULL, OPT_SET},
        {"analytic", required_argument, NULL, OPT_ANALYTIC},
        {"repeat", required_argument, NULL, OPT_REPEAT},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    memset(o, 0, sizeof *o);
    o->repeat = 1;
    o->knobs = calloc((size_t)argc + 1, sizeof *o->knobs);
    o->refs = calloc((size_t)argc + 1, sizeof *o->refs);
    o->sets = calloc((size_t)argc + 1, sizeof *o->sets);
    if (!o->knobs || !o->refs || !o->sets)
        return bad_setting("%s", "out of memory");
    opterr = 0;
    optind = 1;
    int c, status;
    while ((c = getopt_long(argc, argv, ":o:qh", longopts, NULL)) != -1) {
        switch (c) {
        case 'o':
            if (!*optarg)
                return cs_cli_error(&CLI, "%s", "--output needs a directory name");
            o->out_dir = optarg;
            break;
        case OPT_VARY:
            if ((status = parse_vary(optarg, &o->knobs[o->nknobs++])) >= 0)
                return status;
            for (int k = 0; k < o->nknobs - 1; k++)
                if (strcmp(o->knobs[k].key, o->knobs[o->nknobs - 1].key) == 0)
                    return bad_setting("--vary %s: the key is varied twice", optarg);
            break;
        case OPT_REFERENCE:
        case OPT_SET:
            if (!strchr(optarg, '=') || optarg[0] == '=')
                return bad_setting(c == OPT_SET ? "--set needs KEY=VALUE, got '%s'"
                                                : "--reference needs KEY=VALUE, got '%s'",
                                   optarg);
            if (c == OPT_SET)
                o->sets[o->nsets++] = optarg;
            else
                o->refs[o->nrefs++] = optarg;
            break;
        case OPT_ANALYTIC: /* the command's own option: a bad one is a usage error */
            if (strcmp(optarg, "incline") != 0)
                return cs_cli_error(&CLI, "--analytic: '%s' is no analytic solution known "
                                          "(there is: incline)", optarg);
            o->analytic = optarg;
            break;
        case OPT_REPEAT: {
            char *end;
            long n = strtol(optarg, &end, 10);
            if (end == optarg || *end || n < 1 || n > 100)
                return cs_cli_error(&CLI, "--repeat: '%s' is not a whole number from 1 to 100",
                                    optarg);
            o->repeat = (int)n;
            break;
        }
        case 'q':
            o->quiet = true;
            break;
        case 'h':
            cs_sweep_help(stdout);
            return CS_EXIT_OK;
        default:
            return cs_cli_option_error(&CLI, c, argv);
        }
    }
    o->scene_path = cs_cli_operand(&CLI, argc, argv, optind, "scene file", &status);
    if (!o->scene_path)
        return status;
    if (o->nknobs == 0)
        return cs_cli_error(&CLI, "%s", "nothing to vary: give --vary KEY=V1,V2,...");
    if (!o->out_dir)
        return cs_cli_error(&CLI, "%s", "no output folder: give -o DIR");
    return -1;
}

/* ------------------------------------------------------------ reference */

/* Each knob's reference value. Returns -1 to go on, else an exit status. */
static int pick_references(sweep_options *o)
{
    for (int r = 0; r < o->nrefs; r++) {
        const char *eq = strchr(o->refs[r], '=');
        knob *k = NULL;
        for (int i = 0; i < o->nknobs && !k; i++)
            if (strlen(o->knobs[i].key) == (size_t)(eq - o->refs[r]) &&
                strncmp(o->knobs[i].key, o->refs[r], (size_t)(eq - o->refs[r])) == 0)
                k = &o->knobs[i];
        if (!k)
            return bad_setting("--reference %s: the key is not one --vary varies", o->refs[r]);
        k->ref = eq + 1; /* a later one wins */
    }
    for (int i = 0; i < o->nknobs; i++) {
        knob *k = &o->knobs[i];
        if (k->ref)
            continue;
        int rule = -1;
        for (int t = 0; t < NTIGHTEST && rule < 0; t++)
            if (cs_sweep_key_matches(TIGHTEST[t].key, k->key))
                rule = t;
        if (rule < 0 && o->analytic) { /* the analytic solution is the yardstick */
            k->ref = k->values[0];
            continue;
        }
        if (rule < 0)
            return bad_setting("no rule says which value of %s is the tightest: give "
                               "--reference KEY=VALUE",
                               k->key);
        int best = -1;
        for (int v = 0; v < k->n; v++) {
            double m = cs_sweep_measure(k->values[v]),
                   b = best >= 0 ? cs_sweep_measure(k->values[best]) : NAN;
            if (isnan(m))
                return bad_setting("cannot tell how tight %s is (a positive number, or a list "
                                   "of them, is needed): give --reference KEY=VALUE",
                                   k->values[v]);
            if (best < 0 || (TIGHTEST[rule].larger_tighter ? m > b : m < b))
                best = v;
        }
        k->ref = k->values[best];
    }
    return -1;
}

/* ----------------------------------------------------------------- runs */

static void free_runs(sweep_run *runs, int nruns, int nsets)
{
    for (int r = 0; runs && r < nruns; r++) {
        for (int i = nsets; runs[r].overrides && i < runs[r].noverrides; i++)
            free(runs[r].overrides[i]);
        free(runs[r].overrides);
        free(runs[r].value);
        free(runs[r].dir);
        free(runs[r].travel);
        cs_sweep_counts_free(&runs[r].counts);
    }
    free(runs);
}

/* The run's folder: "run_NNN_KEY=V_KEY=V" (brackets and blanks dropped,
 * ',' as 'x', other characters unsafe in a path as '_'), or for a separate
 * reference "reference_KEY=V...". */
static char *run_dir(const sweep_options *o, const sweep_run *r)
{
    char name[256];
    size_t len = 0;
    if (r->number == 0)
        len = (size_t)snprintf(name, sizeof name, "reference");
    else
        len = (size_t)snprintf(name, sizeof name, "run_%03d", r->number);
    for (int k = 0; k < o->nknobs && len < sizeof name - 2; k++) {
        char part[512];
        snprintf(part, sizeof part, "_%s=%s", o->knobs[k].key, r->value[k]);
        for (const char *p = part; *p && len < sizeof name - 1; p++) {
            char ch = *p;
            if (strchr("[]{} \t\"'", ch))
                continue;
            if (ch == ',')
                ch = 'x';
            else if (!((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                       (ch >= '0' && ch <= '9') || strchr("-_.=+", ch)))
                ch = '_';
            name[len++] = ch;
        }
    }
    name[len] = '\0';
    return cs_path_join(o->out_dir, name);
}

/* Fills run r's values and overrides (value[k] per knob). Returns 0, or -1
 * when memory runs out. */
static int make_run(const sweep_options *o, sweep_run *r)
{
    r->overrides = calloc((size_t)(o->nsets + o->nknobs) + 1, sizeof *r->overrides);
    if (!r->overrides)
        return -1;
    for (int i = 0; i < o->nsets; i++)
        r->overrides[r->noverrides++] = o->sets[i];
    for (int k = 0; k < o->nknobs; k++) {
        size_t len = strlen(o->knobs[k].key) + strlen(r->value[k]) + 2;
        char *s = malloc(len);
        if (!s)
            return -1;
        snprintf(s, len, "%s=%s", o->knobs[k].key, r->value[k]);
        r->overrides[r->noverrides++] = s;
    }
    r->exit = -1;
    r->reference = true;
    for (int k = 0; k < o->nknobs; k++)
        r->reference = r->reference && strcmp(r->value[k], o->knobs[k].ref) == 0;
    return (r->dir = run_dir(o, r)) ? 0 : -1;
}

/* Every combination (the last knob varying fastest), then the reference
 * unless it is one of them. Returns -1 to go on, else an exit status. */
static int list_runs(const sweep_options *o, sweep_run **out, int *nruns, int *ref)
{
    long n = 1;
    for (int k = 0; k < o->nknobs; k++)
        if ((n *= o->knobs[k].n) > MAX_RUNS)
            return bad_setting("more than %s combinations to run", "1000");
    sweep_run *runs = calloc((size_t)n + 1, sizeof *runs);
    *out = runs;
    *nruns = 0;
    *ref = -1;
    if (!runs)
        return bad_setting("%s", "out of memory");
    for (long i = 0; i <= n; i++) {
        sweep_run *r = &runs[i];
        if (i == n && *ref >= 0)
            break;
        r->number = i < n ? (int)i + 1 : 0;
        if (!(r->value = calloc((size_t)o->nknobs, sizeof *r->value)))
            return bad_setting("%s", "out of memory");
        for (int k = o->nknobs - 1, rest = (int)i; k >= 0; k--) {
            r->value[k] = i < n ? o->knobs[k].values[rest % o->knobs[k].n] : o->knobs[k].ref;
            rest /= o->knobs[k].n;
        }
        (*nruns)++;
        if (make_run(o, r) != 0)
            return bad_setting("%s", "out of memory");
        if (r->reference)
            *ref = (int)i;
    }
    return -1;
}

/* Loads the scene with overrides: what `clothsim run` would refuse is
 * refused with its message. Returns -1 to go on (the scene in *out if
 * given, else destroyed), else an exit status. */
static int load(const char *path, int n, char **overrides, cs_scene **out)
{
    char err[ERRLEN] = "";
    cs_scene *scene = NULL;
    int rc = cs_scene_load(path, n, (const char *const *)overrides, &scene, err, sizeof err);
    if (rc != CS_OK) {
        fprintf(stderr, "clothsim: %s\n", err[0] ? err : "cannot load the scene");
        return cs_exit_status(rc);
    }
    if (out)
        *out = scene;
    else
        cs_scene_destroy(scene);
    return -1;
}

/* Each value of each knob on its own (before the tightest is judged), with
 * the --set ones. Returns -1 to go on, else an exit status. */
static int validate_values(const sweep_options *o)
{
    char **overrides = calloc((size_t)o->nsets + 2, sizeof *overrides);
    int status = overrides ? -1 : bad_setting("%s", "out of memory");
    for (int i = 0; overrides && i < o->nsets; i++)
        overrides[i] = o->sets[i];
    for (int k = 0; k < o->nknobs && status < 0; k++)
        for (int v = 0; v < o->knobs[k].n && status < 0; v++) {
            size_t len = strlen(o->knobs[k].key) + strlen(o->knobs[k].values[v]) + 2;
            char *s = malloc(len);
            if (!s) {
                status = bad_setting("%s", "out of memory");
                break;
            }
            snprintf(s, len, "%s=%s", o->knobs[k].key, o->knobs[k].values[v]);
            overrides[o->nsets] = s;
            status = load(o->scene_path, o->nsets + 1, overrides, NULL);
            free(s);
        }
    free(overrides);
    return status;
}

/* Every run's overrides together; the reference's scene is kept (the
 * cloths' names); with --analytic each run's incline. Returns -1 to go on,
 * else an exit status. */
static int validate(const sweep_options *o, sweep_run *runs, int nruns, int ref,
                    cs_scene **ref_scene)
{
    int status = -1;
    for (int i = 0; i < nruns && status < 0; i++) {
        cs_scene *scene = NULL;
        char err[ERRLEN];
        status = load(o->scene_path, runs[i].noverrides, runs[i].overrides, &scene);
        if (status < 0 && o->analytic &&
            cs_sweep_analytic_init(&scene->def, &runs[i].analytic, err, sizeof err) != 0)
            status = bad_setting("%s", err);
        if (status < 0 && i == ref)
            *ref_scene = scene;
        else if (scene)
            cs_scene_destroy(scene);
    }
    return status;
}
/* ------------------------------------------------------------ executing */

/* `clothsim run SCENE --set ... -o DIR --quiet` as a child, its output in
 * DIR/run.log; returns as cs_sweep_spawn. */
static int run_child(const sweep_options *o, const sweep_run *r, char *err, size_t errlen)
{
    char *log = cs_path_join(r->dir, "run.log");
    const char **argv = calloc((size_t)(2 * r->noverrides + 8), sizeof *argv);
    int n = 0, status = -1;
    if (log && argv) {
        argv[n++] = "clothsim";
        argv[n++] = "run";
        argv[n++] = o->scene_path;
        for (int i = 0; i < r->noverrides; i++) {
            argv[n++] = "--set";
            argv[n++] = r->overrides[i];
        }
        argv[n++] = "-o";
        argv[n++] = r->dir;
        argv[n++] = "--quiet";
        status = cs_sweep_spawn(argv, log, err, errlen);
    } else {
        snprintf(err, errlen, "out of memory");
    }
    free(log);
    free(argv);
    return status;
}

static volatile sig_atomic_t interrupted = 0;

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void on_signal(int sig)
{
    interrupted = sig;
}

/* The runs one after another, the reference first. Returns -1 to go on,
 * else an exit status. */
static int execute(const sweep_options *o, sweep_run *runs, int nruns, int ref)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal; /* the child gets the signal too, and stops */
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    char err[ERRLEN];
    double spent = 0;
    for (int done = 0; done < nruns; done++) {
        int i = done == 0 ? ref : (done <= ref ? done - 1 : done);
        sweep_run *r = &runs[i];
        if (cs_make_dirs(r->dir) != 0) {
            fprintf(stderr, "clothsim sweep: cannot create %s: %s\n", r->dir, strerror(errno));
            return CS_EXIT_OUTPUT;
        }
        if (!o->quiet) {
            char eta[32] = "--";
            if (done > 0)
                cs_format_duration(spent / done * (nruns - done), eta, sizeof eta);
            fprintf(stderr, "run %d of %d (", done + 1, nruns);
            for (int k = 0; k < o->nknobs; k++)
                fprintf(stderr, "%s%s=%s", k ? " " : "", o->knobs[k].key, r->value[k]);
            fprintf(stderr, "%s) ... ETA %s\n", r->reference ? ", reference" : "", eta);
        }
        double walls[100];
        int n = 0;
        do { /* --repeat: again while it finishes; the median of the seconds */
            double t0 = cs_now();
            r->exit = run_child(o, r, err, sizeof err);
            walls[n] = cs_now() - t0;
            spent += walls[n++] / o->repeat;
        } while (n < o->repeat && r->exit == CS_EXIT_OK && !interrupted);
        qsort(walls, (size_t)n, sizeof *walls, compare_doubles);
        r->wall = n % 2 ? walls[n / 2] : 0.5 * (walls[n / 2 - 1] + walls[n / 2]);
        if (r->exit < 0) {
            fprintf(stderr, "clothsim sweep: %s\n", err);
            return CS_EXIT_OUTPUT;
        }
        if (interrupted || r->exit == CS_EXIT_INTERRUPTED || r->exit == 128 + SIGINT) {
            fprintf(stderr, "clothsim sweep: interrupted; the runs so far are in %s\n",
                    o->out_dir);
            return CS_EXIT_INTERRUPTED;
        }
        if (r->exit != CS_EXIT_OK)
            fprintf(stderr, "clothsim sweep: run %d exited with status %d; see %s/run.log\n",
                    done + 1, r->exit, r->dir);
    }
    /* the runs are over: measuring and writing stop at a signal as usual */
    sa.sa_handler = SIG_DFL;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    return -1;
}

/* ------------------------------------------------------------- measuring */

/* Each run's counters and its error against the reference (per frame in
 * its folder's errors.csv). Returns -1 to go on, else an exit status. */
static int measure_runs(const sweep_options *o, sweep_run *runs, int nruns, int ref,
                        const cs_scene *scene)
{
    char err[ERRLEN];
    cs_run_info info;
    if (cs_run_info_read(runs[ref].dir, &info, err, sizeof err) != CS_EXIT_OK) {
        fprintf(stderr, "clothsim sweep: the reference: %s\n", err);
        return CS_EXIT_UNSTABLE;
    }
    int ref_frames = info.frames_written;
    /* The frames are this sweep's own, written by its child runs: nothing
     * untrusted to read in a process of its own (import/mesh_guard.c), and
     * a process per frame file costs more than the comparison. */
    setenv("CLOTHSIM_IMPORT_ISOLATION", "0", 0);
    cs_frame_layout layout;
    int ncloths = scene->def.ncloths;
    const char **names = calloc((size_t)ncloths + 1, sizeof *names);
    for (int c = 0; names && c < ncloths; c++)
        names[c] = scene->def.cloths[c].name;
    int rc = names ? cs_frame_layout_init(&layout, info.format, ncloths, names) : -1;
    free(names);
    cs_run_info_free(&info);
    if (rc != 0) {
        fprintf(stderr, "clothsim sweep: out of memory\n");
        return CS_EXIT_OUTPUT;
    }
    int status = -1;
    for (int i = 0; i < nruns && status < 0; i++) {
        sweep_run *r = &runs[i];
        if (r->exit < 0)
            continue;
        if (cs_sweep_read_counts(r->dir, &r->counts, err, sizeof err) != 0) {
            fprintf(stderr, "clothsim sweep: %s\n", err);
            continue; /* a run that wrote no summary: a row without numbers */
        }
        r->have_counts = true;
        int frames = r->counts.frames_written < ref_frames ? r->counts.frames_written
                                                           : ref_frames;
        char *path = cs_path_join(r->dir, "errors.csv");
        FILE *per_frame = path ? fopen(path, "w") : NULL;
        r->nframes = frames;
        if (o->analytic && !(r->travel = calloc((size_t)frames + 1, sizeof *r->travel)))
            rc = CS_EXIT_OUTPUT, snprintf(err, sizeof err, "out of memory");
        else
            rc = cs_sweep_compare(&layout, r->dir, runs[ref].dir, frames,
                                  o->analytic ? &r->analytic : NULL, per_frame, r->travel,
                                  &r->error, err, sizeof err);
        if (per_frame && fclose(per_frame) != 0 && rc == CS_EXIT_OK) {
            snprintf(err, sizeof err, "cannot write %s: %s", path, strerror(errno));
            rc = CS_EXIT_OUTPUT;
        }
        free(path);
        if (rc == CS_EXIT_OUTPUT) {
            fprintf(stderr, "clothsim sweep: %s\n", err);
            status = CS_EXIT_OUTPUT;
        } else if (rc != CS_EXIT_OK) {
            fprintf(stderr, "clothsim sweep: %s\n", err);
        } else {
            r->have_error = frames > 0;
        }
    }
    cs_frame_layout_free(&layout);
    return status;
}

int cs_sweep_main(int argc, char **argv)
{
    sweep_options o;
    sweep_run *runs = NULL;
    int nruns = 0, ref = -1;
    cs_scene *scene = NULL;
    int status = parse_options(argc, argv, &o);
    char why[256];
    if (status < 0 && cs_plot_available(why, sizeof why) != 0) { /* before any run */
        fprintf(stderr, "clothsim sweep: %s\n", why);
        status = CS_EXIT_OUTPUT;
    }
    if (status < 0)
        status = validate_values(&o);
    if (status < 0)
        status = pick_references(&o);
    if (status < 0)
        status = list_runs(&o, &runs, &nruns, &ref);
    if (status < 0)
        status = validate(&o, runs, nruns, ref, &scene);
    if (status < 0)
        status = execute(&o, runs, nruns, ref);
    if (status < 0)
        status = measure_runs(&o, runs, nruns, ref, scene);
    if (status < 0)
        status = cs_sweep_report(&o, runs, nruns, ref);
    if (status < 0) {
        status = CS_EXIT_OK;
        for (int i = 0; i < nruns; i++)
            if (runs[i].exit != CS_EXIT_OK)
                status = CS_EXIT_UNSTABLE;
        printf("%d run%s in %s: sweep.csv, sweep.md, sweep.png, %scumulative_time.png\n", nruns,
               nruns == 1 ? "" : "s", o.out_dir, o.analytic ? "trajectory.png, " : "");
    }
    if (scene)
        cs_scene_destroy(scene);
    free_runs(runs, nruns, o.nsets);
    free_options(&o);
    return status;
}
