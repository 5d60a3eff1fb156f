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

/* One curve of a sweep picture: n points (x[i], y[i]); on a log axis the
 * points with a coordinate <= 0 are left out. */
typedef struct cs_sweep_curve {
    const char *label;  /* in the legend; NULL: not listed */
    int n;
    const double *x, *y;
    int colour;         /* 0: the palette's next; -1: black */
    int style;          /* PLplot line style (2: dashed); 0: solid, dashed
                           once the palette's 8 colours have run out */
    double width;       /* line width; 0: 1 */
    bool points;        /* a filled circle at each point */
} cs_sweep_curve;

/* The corner a picture's legend goes in (cs_sweep_figure.legend): these
 * bits, none for the bottom left. */
enum { CS_LEGEND_RIGHT = 1, CS_LEGEND_TOP = 2 };

/* A picture: curves on linear or log axes with a legend. */
typedef struct cs_sweep_figure {
    const char *title, *xlabel, *ylabel;
    bool log_x, log_y;
    const cs_sweep_curve *curves;
    int ncurves;
    double mark_x;          /* > 0: a dashed vertical line at x = mark_x ... */
    const char *mark_label; /* ... labelled at its foot (NULL: none) */
    int legend;             /* where: CS_LEGEND_TOP | CS_LEGEND_RIGHT, ...;
                               another corner when the curves are there */
} cs_sweep_figure;

/* Draws the figure into path with PLplot (pngcairo, 900 x 640), written
 * atomically. The one plotting helper of sweep.png, trajectory.png and
 * cumulative_time.png. Returns 0, or -1 with err (sweep_plot.c). */
int cs_sweep_plot(const char *path, const cs_sweep_figure *figure, char *err, size_t errlen);

/* 0 where this build draws pictures; -1 with why in a build without
 * PLplot (plot_none.c), so that a command can refuse before its work. */
int cs_plot_available(char *why, size_t whylen);

/* Whether PLplot has its pngcairo device (without it, PLplot would ask for
 * a device on the terminal); also bench/scaling_plot.c's check. */
bool cs_plot_has_pngcairo(void);

/* Before plinit: PLplot's pngcairo device onto the file tmp, width x height
 * pixels, black on white, and a message instead of exit() on PLplot's
 * fatal errors. Returns 0, or -1 with why (no pngcairo device). Also
 * `clothsim info`'s figure (info_cmd.c). */
int cs_plot_open(const char *tmp, int width, int height, char *why, size_t whylen);

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
