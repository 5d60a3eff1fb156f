/* sweep_cmd.h: `clothsim sweep SCENE --vary KEY=V1,V2,... -o DIR`: a run
 * per combination of settings and a reference run, their cost and their
 * error against the reference (DIR/sweep.csv, sweep.md, sweep.png). */
#ifndef CS_APP_SWEEP_CMD_H
#define CS_APP_SWEEP_CMD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

/* argv[0] is "sweep"; returns the exit status. */
int cs_sweep_main(int argc, char **argv);

void cs_sweep_help(FILE *out);

/* One curve of sweep.png: a knob's runs (the other knobs at the
 * reference's values), seconds and error both > 0. */
typedef struct cs_sweep_curve {
    const char *label;
    int n;
    double *seconds, *error;
} cs_sweep_curve;

/* Draws sweep.png into path with PLplot (pngcairo): error against wall
 * seconds, log-log, a curve per knob, the reference's seconds marked (when
 * > 0). Returns 0, or -1 with err (sweep_plot.c). */
int cs_sweep_plot(const char *path, const cs_sweep_curve *curves, int ncurves,
                  double ref_seconds, char *err, size_t errlen);

/* A table of text cells (row-major; "" not applicable), written atomically
 * as CSV (fields with commas quoted) or as a Markdown table ("" shown as
 * "–"). Returns 0, or -1 with err (sweep_report.c). */
typedef struct cs_sweep_table {
    int ncols, nrows;
    const char *const *header;
    char **cells;
} cs_sweep_table;

int cs_sweep_write_table(const char *path, const cs_sweep_table *t, bool markdown, char *err,
                         size_t errlen);

/* Runs this executable (/proc/self/exe) with argv as a child, its stdout
 * and stderr into the file log, and waits for it. Returns its exit status
 * (128 + the signal that killed it), or -1 with err when it could not
 * start (sweep_report.c). */
int cs_sweep_spawn(const char *const *argv, const char *log, char *err, size_t errlen);

#endif
