/* sweep_internal.h: what the parts of `clothsim sweep` share: the command
 * line (sweep_cmd.c parses it) and the runs (sweep_cmd.c executes and
 * measures them; sweep_output.c writes the tables and pictures). */
#ifndef CS_APP_SWEEP_INTERNAL_H
#define CS_APP_SWEEP_INTERNAL_H

#include <stdbool.h>

#include "app/sweep_metrics.h"

typedef struct knob {
    char *key;
    int n;
    char **values;
    const char *ref;  /* the reference's value: values[k] or --reference's */
} knob;

typedef struct sweep_options {
    const char *scene_path, *out_dir;
    const char *analytic; /* --analytic: "incline", or NULL */
    int repeat;           /* --repeat: runs of each, the median seconds kept */
    bool quiet;
    int nknobs, nrefs, nsets;
    knob *knobs;
    char **refs;       /* --reference KEY=V, as given */
    char **sets;       /* --set KEY=VALUE, as given */
} sweep_options;

typedef struct sweep_run {
    int number;          /* 1.. for combinations, 0 for a separate reference */
    const char **value;  /* per knob */
    char **overrides;    /* --set ones, then "KEY=VALUE" per knob (owned) */
    int noverrides;
    char *dir;           /* DIR/run_NNN_... or DIR/reference_... */
    bool reference;
    int exit;            /* the child's exit status; -1 not run */
    double wall;         /* its wall seconds (the median of --repeat's) */
    bool have_counts, have_error;
    cs_sweep_counts counts;
    cs_sweep_error error;
    cs_sweep_analytic analytic; /* with --analytic: its scene's incline */
    int nframes;         /* frames compared (frame 0 included) ... */
    double *travel;      /* ... with --analytic, each one's distance downhill; owned */
} sweep_run;

/* Writes DIR/sweep.csv, sweep.md and sweep.png, and with --analytic
 * DIR/trajectory.png; DIR/cumulative_time.png always (sweep_output.c).
 * Returns -1 to go on, else an exit status (the message printed). */
int cs_sweep_report(const sweep_options *o, const sweep_run *runs, int nruns, int ref);

#endif
