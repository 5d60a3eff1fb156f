/* accuracy_time: what accuracy costs in time, on the analytic incline.
 *
 * Runs the damped tetrahedron of scenes/validation (Fig. 8) through sweeps
 * of the knobs that trade accuracy for speed: the step (time.dt_safety),
 * the CG tolerance (time.cg_tolerance) and the friction method. Each point
 * is the largest error of the centre of mass against the analytic solution
 * over 1 s, and the median wall time of three runs. Writes a CSV table and
 * a log-log PNG plot (bench/plot.h) into the output folder.
 *
 * usage: bench_accuracy_time [OUT_DIR]      (default: .)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/plot.h"
#include "tests/incline_analytic.h"

typedef struct point {
    const char *series;
    const char *knob;
    double value;
    double seconds;
    double error;
    long cg_iterations;
} point;

#define MAX_POINTS 64

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static int measure(const char *series, const char *method, const char *knob, double value,
                   point *out)
{
    /* a tight CG tolerance unless CG is the knob: the later --set wins */
    char knob_set[96], err[512];
    snprintf(knob_set, sizeof knob_set, "time.%s=%.17g", knob, value);
    const char *extra[2] = {"time.cg_tolerance=1e-9", knob_set};
    double secs[3];
    incline_result r = {0};
    for (int k = 0; k < 3; k++) {
        if (run_incline("tetrahedron_accelerating.yaml", 36, 0.6, 0, method, 2, extra, &r, err,
                        sizeof err)) {
            fprintf(stderr, "bench_accuracy_time: %s\n", err);
            return -1;
        }
        secs[k] = r.seconds;
    }
    qsort(secs, 3, sizeof *secs, cmp_double);
    *out = (point){series, knob, value, secs[1], r.max_error, r.cg_iterations};
    return 0;
}

/* --------------------------------------------------------------- plot */

/* Error against wall time, log-log; one polyline a series, each point
 * labelled with its knob's value. The points of a series are consecutive. */
static int plot(const point *p, int n, const char *path)
{
    cs_plot_axis x = {CS_PLOT_LOG, 1e300, 0, 0, "wall time of 1 s simulated (s)", NULL};
    cs_plot_axis y = {CS_PLOT_LOG, 1e300, 0, 0, "max centre-of-mass error vs analytic (m)", NULL};
    double xs[MAX_POINTS], ys[MAX_POINTS];
    char text[MAX_POINTS][32];
    const char *labels[MAX_POINTS];
    for (int i = 0; i < n; i++) {
        xs[i] = p[i].seconds;
        ys[i] = fmax(p[i].error, 1e-12); /* a log axis has no zero */
        snprintf(text[i], sizeof text[i], "%g", p[i].value);
        labels[i] = text[i];
        x.lo = fmin(x.lo, xs[i]), x.hi = fmax(x.hi, xs[i]);
        y.lo = fmin(y.lo, ys[i]), y.hi = fmax(y.hi, ys[i]);
    }
    cs_plot *pl = cs_plot_create(900, 600);
    if (!pl)
        return -1;
    cs_plot_panel(pl, 90, 50, 900 - 230, 600 - 70, &x, &y,
                  "Accuracy against time: tetrahedron on the incline (Fig. 8), theta = 36 deg, mu = 0.6");
    const double colors[][3] = {{0.80, 0.20, 0.15}, {0.15, 0.40, 0.80}, {0.30, 0.60, 0.25},
                                {0.55, 0.30, 0.65}};
    for (int i = 0, s = 0; i < n; s++) {
        int j = i;
        while (j < n && strcmp(p[j].series, p[i].series) == 0)
            j++;
        const double *c = colors[s % 4];
        cs_plot_style style = {{c[0], c[1], c[2]}, 2, 0, 4.5, 0};
        cs_plot_series(pl, j - i, xs + i, ys + i, labels + i, &style);
        cs_plot_legend(pl, p[i].series, &style);
        i = j;
    }
    int rc = cs_plot_write_png(pl, path);
    cs_plot_destroy(pl);
    return rc;
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : ".";
    point pts[MAX_POINTS];
    int n = 0;
    const double safety[] = {1.0, 0.5, 0.25, 0.1, 0.05};
    const double tolerance[] = {1e-1, 1e-2, 1e-3, 1e-5, 1e-8};
    for (int k = 0; k < 5; k++)
        if (measure("improved: time.dt_safety", "improved", "dt_safety", safety[k], &pts[n++]))
            return 1;
    for (int k = 0; k < 5; k++)
        if (measure("improved: time.cg_tolerance", "improved", "cg_tolerance", tolerance[k], &pts[n++]))
            return 1;
    for (int k = 0; k < 5; k++)
        if (measure("previous: time.dt_safety", "projection", "dt_safety", safety[k], &pts[n++]))
            return 1;

    char path[1024];
    snprintf(path, sizeof path, "%s/accuracy_time.csv", dir);
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "bench_accuracy_time: cannot write %s\n", path);
        return 1;
    }
    fprintf(f, "series,knob,value,median_seconds,max_error_m,cg_iterations\n");
    printf("%-30s %10s %12s %12s %10s\n", "series", "value", "seconds", "error (m)", "CG its");
    for (int i = 0; i < n; i++) {
        fprintf(f, "%s,%s,%g,%.6f,%.6e,%ld\n", pts[i].series, pts[i].knob, pts[i].value,
                pts[i].seconds, pts[i].error, pts[i].cg_iterations);
        printf("%-30s %10g %12.4f %12.3e %10ld\n", pts[i].series, pts[i].value, pts[i].seconds,
               pts[i].error, pts[i].cg_iterations);
    }
    fclose(f);
    snprintf(path, sizeof path, "%s/accuracy_time.png", dir);
    if (plot(pts, n, path)) {
        fprintf(stderr, "bench_accuracy_time: cannot write %s\n", path);
        return 1;
    }
    printf("wrote %s/accuracy_time.csv and %s\n", dir, path);
    return 0;
}
