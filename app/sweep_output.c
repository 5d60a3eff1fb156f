/* sweep_output.c: what `clothsim sweep` writes once every run is measured:
 * DIR/sweep.csv and DIR/sweep.md (a row per run), and the pictures, all
 * drawn by cs_sweep_plot (sweep_plot.c): sweep.png (error against cost, a
 * curve per knob), trajectory.png (with --analytic: the distance travelled
 * downhill against time, the analytic body's and each run's: the paper's
 * Figs. 7 and 8) and cumulative_time.png (wall seconds summed over the
 * frames, a curve per run: Fig. 14). */
#include "app/sweep_cmd.h"
#include "app/sweep_internal.h"

#include "app/run.h"
#include "common/util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ERRLEN 1024

/* ---------------------------------------------------------------- tables */

static const char *COLUMNS[] = {"reference", "status", "wall_s", "steps", "cg_iterations",
                                "collisions", "impact_zones", "intersecting_pairs_max",
                                "body_penetration_max_m", "vertex_rms_m", "vertex_max_m",
                                "com_m", "bbox_m", "hausdorff_m", "analytic_m", "error_m"};
#define NCOLUMNS ((int)(sizeof COLUMNS / sizeof COLUMNS[0]))

/* A number as a cell: "" when not applicable (NaN, or < 0: not counted). */
static char *num_cell(double v)
{
    char buf[32] = "";
    if (!isnan(v) && v >= 0)
        snprintf(buf, sizeof buf, "%.6g", v);
    return strdup(buf);
}

/* Fills t (header and cells, a row per run; cs_sweep_table in
 * sweep_cmd.h). Returns 0, or -1 when memory runs out (t freed by caller). */
static int build_table(const sweep_options *o, const sweep_run *runs, int nruns,
                       cs_sweep_table *t, const char **header)
{
    t->ncols = 2 + o->nknobs + NCOLUMNS;
    t->nrows = nruns;
    t->header = header;
    header[0] = "run";
    header[1] = "folder";
    for (int k = 0; k < o->nknobs; k++)
        header[2 + k] = o->knobs[k].key;
    for (int c = 0; c < NCOLUMNS; c++)
        header[2 + o->nknobs + c] = COLUMNS[c];
    t->cells = calloc((size_t)t->ncols * (size_t)nruns + 1, sizeof *t->cells);
    if (!t->cells)
        return -1;
    for (int i = 0; i < nruns; i++) {
        const sweep_run *r = &runs[i];
        char **row = t->cells + (size_t)i * t->ncols, num[16];
        const cs_sweep_counts *c = &r->counts;
        const cs_sweep_error *e = &r->error;
        bool n = r->have_counts, m = r->have_error;
        snprintf(num, sizeof num, "%d", r->number);
        row[0] = strdup(r->number ? num : "reference");
        row[1] = strdup(strrchr(r->dir, '/') ? strrchr(r->dir, '/') + 1 : r->dir);
        for (int k = 0; k < o->nknobs; k++)
            row[2 + k] = strdup(r->value[k]);
        row = row + 2 + o->nknobs;
        row[0] = strdup(r->reference ? "yes" : "no");
        row[1] = strdup(n ? c->status : r->exit < 0 ? "not run" : "failed");
        double nums[NCOLUMNS - 2] = {
            r->exit >= 0 ? r->wall : NAN, n ? (double)c->steps : NAN,
            n ? (double)c->cg_iterations : NAN, n ? (double)c->collisions : NAN,
            n ? (double)c->impact_zones : NAN, n ? (double)c->intersections : NAN,
            n ? c->penetration : NAN, m ? e->vertex_rms : NAN, m ? e->vertex_max : NAN,
            m ? e->com : NAN, m ? e->bbox : NAN, m ? e->hausdorff : NAN,
            m ? e->analytic : NAN, m ? cs_sweep_error_headline(e) : NAN};
        for (int k = 0; k < NCOLUMNS - 2; k++)
            row[2 + k] = num_cell(nums[k]);
    }
    for (size_t k = 0; k < (size_t)t->ncols * (size_t)nruns; k++)
        if (!t->cells[k])
            return -1;
    return 0;
}

static void free_table(cs_sweep_table *t)
{
    for (size_t k = 0; t->cells && k < (size_t)t->ncols * (size_t)t->nrows; k++)
        free(t->cells[k]);
    free(t->cells);
}

static int compare_seconds(const void *a, const void *b)
{
    const double *x = a, *y = b;
    return (x[0] > y[0]) - (x[0] < y[0]);
}

/* Draws fig into DIR/name. Returns 0, or -1 with err. */
static int draw(const sweep_options *o, const char *name, const cs_sweep_figure *fig, char *err,
                size_t errlen)
{
    char *path = cs_path_join(o->out_dir, name);
    int rc = path ? cs_sweep_plot(path, fig, err, errlen) : -1;
    if (!path)
        snprintf(err, errlen, "out of memory");
    free(path);
    return rc;
}

/* sweep.png: per knob the runs whose other knobs are at the reference's
 * values. Returns 0, or -1 with err. */
static int plot_error(const sweep_options *o, const sweep_run *runs, int nruns, int ref,
                      char *err, size_t errlen)
{
    cs_sweep_curve *curves = calloc((size_t)o->nknobs, sizeof *curves);
    double *pairs = calloc(2 * (size_t)nruns + 1, sizeof *pairs);
    double *xy = calloc(2 * (size_t)nruns * (size_t)o->nknobs + 1, sizeof *xy);
    int rc = -1;
    if (!curves || !pairs || !xy) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    for (int k = 0; k < o->nknobs; k++) {
        int n = 0;
        for (int i = 0; i < nruns; i++) {
            const sweep_run *r = &runs[i];
            bool on_curve = r->have_error && r->exit == CS_EXIT_OK && r->wall > 0;
            for (int j = 0; j < o->nknobs && on_curve; j++)
                on_curve = j == k || strcmp(r->value[j], o->knobs[j].ref) == 0;
            double e = on_curve ? cs_sweep_error_headline(&r->error) : NAN;
            if (e > 0 && isfinite(e)) { /* log axes: the reference's 0 is the line */
                pairs[2 * n] = r->wall;
                pairs[2 * n++ + 1] = e;
            }
        }
        qsort(pairs, (size_t)n, 2 * sizeof *pairs, compare_seconds);
        double *x = xy + 2 * (size_t)nruns * k, *y = x + nruns;
        for (int i = 0; i < n; i++) {
            x[i] = pairs[2 * i];
            y[i] = pairs[2 * i + 1];
        }
        curves[k] = (cs_sweep_curve){.label = o->knobs[k].key, .n = n, .x = x, .y = y,
                                     .points = true};
    }
    cs_sweep_figure fig = {
        "clothsim sweep: error against cost", "wall seconds of the run",
        o->analytic ? "error against the analytic solution, m" : "error against the reference, m",
        true, true, curves, o->nknobs, runs[ref].wall, "reference",
        CS_LEGEND_TOP | CS_LEGEND_RIGHT};
    rc = draw(o, "sweep.png", &fig, err, errlen);
done:
    free(curves);
    free(pairs);
    free(xy);
    return rc;
}

/* A run's name in a legend: its knobs' values, each key by its last part
 * ("friction=improved"), "(reference)" after the reference's. */
static char *run_label(const sweep_options *o, const sweep_run *r)
{
    char label[256];
    size_t len = 0;
    label[0] = '\0';
    for (int k = 0; k < o->nknobs && len < sizeof label; k++) {
        const char *key = strrchr(o->knobs[k].key, '.');
        len += (size_t)snprintf(label + len, sizeof label - len, "%s%s=%s", k ? ", " : "",
                                key ? key + 1 : o->knobs[k].key, r->value[k]);
    }
    if (r->reference && len < sizeof label)
        snprintf(label + len, sizeof label - len, " (reference)");
    return strdup(label);
}

static bool same_incline(const cs_sweep_analytic *a, const cs_sweep_analytic *b)
{
    return memcmp(&a->motion, &b->motion, sizeof a->motion) == 0 &&
           memcmp(a->down, b->down, sizeof a->down) == 0 && a->fps == b->fps;
}

#define ANALYTIC_POINTS 201

/* trajectory.png: downhill distance against time, the analytic body's
 * (dashed black; one per distinct incline among the runs) and each run's.
 * Returns 0, or -1 with err. */
static int plot_trajectory(const sweep_options *o, const sweep_run *runs, int nruns, char *err,
                           size_t errlen)
{
    size_t total = ANALYTIC_POINTS;
    double end = 0;
    for (int i = 0; i < nruns; i++)
        if (runs[i].travel && runs[i].nframes > 0) {
            total += (size_t)runs[i].nframes;
            end = fmax(end, (runs[i].nframes - 1) / runs[i].analytic.fps);
        }
    cs_sweep_curve *curves = calloc(2 * (size_t)nruns + 1, sizeof *curves);
    char **labels = calloc(2 * (size_t)nruns + 1, sizeof *labels);
    double *times = malloc(total * sizeof *times);
    double *exact = malloc(((size_t)nruns * ANALYTIC_POINTS + 1) * sizeof *exact);
    int n = 0, nexact = 0, rc = -1;
    if (!curves || !labels || !times || !exact) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    double *fine = times, *t = times + ANALYTIC_POINTS; /* ANALYTIC_POINTS over [0, end] */
    for (int k = 0; k < ANALYTIC_POINTS; k++)
        fine[k] = end * k / (ANALYTIC_POINTS - 1);
    for (int i = 0; i < nruns; i++) { /* the analytic curves first: under the runs' */
        bool seen = false;
        for (int j = 0; j < i && !seen; j++)
            seen = runs[j].travel && same_incline(&runs[i].analytic, &runs[j].analytic);
        if (!runs[i].travel || seen)
            continue;
        double *y = exact + (size_t)nexact++ * ANALYTIC_POINTS, v;
        for (int k = 0; k < ANALYTIC_POINTS; k++)
            cs_incline_motion(&runs[i].analytic.motion, fine[k], &y[k], &v);
        char *name = run_label(o, &runs[i]), text[300];
        snprintf(text, sizeof text, "analytic (as %s)", name ? name : "");
        free(name);
        labels[n] = strdup(text);
        curves[n++] = (cs_sweep_curve){NULL, ANALYTIC_POINTS, fine, y, -1, 1 + nexact, 2.5, false};
    }
    if (nexact == 1) { /* one incline: just "analytic" */
        free(labels[0]);
        labels[0] = strdup("analytic");
    }
    for (int i = 0; i < nruns; i++) {
        if (!runs[i].travel || runs[i].nframes <= 0)
            continue;
        for (int k = 0; k < runs[i].nframes; k++) /* each run's own frame rate */
            t[k] = k / runs[i].analytic.fps;
        labels[n] = run_label(o, &runs[i]);
        curves[n++] = (cs_sweep_curve){NULL, runs[i].nframes, t, runs[i].travel, 0, 0, 1.5,
                                       runs[i].nframes <= 30};
        t += runs[i].nframes;
    }
    for (int c = 0; c < n; c++)
        curves[c].label = labels[c];
    cs_sweep_figure fig = {"clothsim sweep: distance travelled down the slope", "time, s",
                           "centre of mass: distance down the slope, m", false, false, curves, n,
                           0, NULL, CS_LEGEND_TOP};
    rc = draw(o, "trajectory.png", &fig, err, errlen);
done:
    for (int c = 0; labels && c < n; c++)
        free(labels[c]);
    free(labels);
    free(curves);
    free(times);
    free(exact);
    return rc;
}

/* cumulative_time.png: each run's wall seconds summed over its frames (the
 * frames' "seconds": simulation and output, start-up not), from frame 0 at
 * 0 s; log seconds when the runs' totals differ by more than 30 times.
 * Returns 0, or -1 with err. */
static int plot_cumulative(const sweep_options *o, const sweep_run *runs, int nruns, char *err,
                           size_t errlen)
{
    size_t total = 1;
    int most = 0;
    double lo = INFINITY, hi = 0;
    for (int i = 0; i < nruns; i++)
        if (runs[i].have_counts) {
            total += (size_t)runs[i].counts.nseconds + 1;
            most = runs[i].counts.nseconds > most ? runs[i].counts.nseconds : most;
            double sum = 0;
            for (int k = 0; k < runs[i].counts.nseconds; k++)
                sum += isfinite(runs[i].counts.seconds[k]) ? runs[i].counts.seconds[k] : 0;
            lo = fmin(lo, sum), hi = fmax(hi, sum);
        }
    bool log_y = lo > 0 && hi > 30 * lo;
    cs_sweep_curve *curves = calloc((size_t)nruns + 1, sizeof *curves);
    char **labels = calloc((size_t)nruns + 1, sizeof *labels);
    double *frame = malloc(((size_t)most + 1) * sizeof *frame);
    double *sums = malloc(total * sizeof *sums);
    int n = 0, rc = -1;
    if (!curves || !labels || !frame || !sums) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    for (int k = 0; k <= most; k++)
        frame[k] = k;
    double *y = sums;
    for (int i = 0; i < nruns; i++) {
        const cs_sweep_counts *c = &runs[i].counts;
        if (!runs[i].have_counts)
            continue;
        y[0] = 0; /* frame 0, the initial state, costs nothing */
        for (int k = 0; k < c->nseconds; k++)
            y[k + 1] = y[k] + (isfinite(c->seconds[k]) ? c->seconds[k] : 0);
        labels[n] = run_label(o, &runs[i]);
        curves[n] = (cs_sweep_curve){labels[n], c->nseconds + 1, frame, y, 0, 0, 1.5,
                                     c->nseconds <= 30};
        n++;
        y += c->nseconds + 1;
    }
    cs_sweep_figure fig = {"clothsim sweep: cumulative wall time", "frame",
                           "wall seconds, summed over the frames so far", false, log_y, curves, n,
                           0, NULL, CS_LEGEND_TOP};
    rc = draw(o, "cumulative_time.png", &fig, err, errlen);
done:
    for (int c = 0; labels && c < n; c++)
        free(labels[c]);
    free(labels);
    free(curves);
    free(frame);
    free(sums);
    return rc;
}

int cs_sweep_report(const sweep_options *o, const sweep_run *runs, int nruns, int ref)
{
    char err[ERRLEN] = "out of memory";
    const char **header = calloc((size_t)(2 + o->nknobs + NCOLUMNS), sizeof *header);
    cs_sweep_table t = {0};
    int rc = header ? build_table(o, runs, nruns, &t, header) : -1;
    const char *names[] = {"sweep.csv", "sweep.md"};
    for (int m = 0; m < 2 && rc == 0; m++) {
        char *path = cs_path_join(o->out_dir, names[m]);
        rc = path ? cs_sweep_write_table(path, &t, m == 1, err, sizeof err) : -1;
        free(path);
    }
    free_table(&t);
    free(header);
    if (rc == 0)
        rc = plot_error(o, runs, nruns, ref, err, sizeof err);
    if (rc == 0 && o->analytic)
        rc = plot_trajectory(o, runs, nruns, err, sizeof err);
    if (rc == 0)
        rc = plot_cumulative(o, runs, nruns, err, sizeof err);
    if (rc != 0) {
        fprintf(stderr, "clothsim sweep: %s\n", err);
        return CS_EXIT_OUTPUT;
    }
    return -1;
}
