/* accuracy_time: what accuracy costs in time, on the analytic incline.
 *
 * Runs the damped tetrahedron of scenes/validation (Fig. 8) through sweeps
 * of the knobs that trade accuracy for speed: the step (time.dt_safety),
 * the CG tolerance (time.cg_tolerance) and the friction method. Each point
 * is the largest error of the centre of mass against the analytic solution
 * over 1 s, and the median wall time of three runs. Writes a CSV table and
 * a log-log PNG plot (cairo) into the output folder.
 *
 * usage: bench_accuracy_time [OUT_DIR]      (default: .)
 */
#include <cairo.h>
#include <stdlib.h>

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

typedef struct axes {
    double x0, x1, y0, y1;       /* log10 data range */
    double left, right, top, bottom;
} axes;

static double px(const axes *a, double v) { return a->left + (log10(v) - a->x0) / (a->x1 - a->x0) * (a->right - a->left); }
static double py(const axes *a, double v) { return a->bottom - (log10(v) - a->y0) / (a->y1 - a->y0) * (a->bottom - a->top); }

static void plot(const point *p, int n, const char *path)
{
    const int W = 900, H = 600;
    cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
    cairo_t *cr = cairo_create(surf);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);

    axes a = {1e9, -1e9, 1e9, -1e9, 90, W - 230, 50, H - 70};
    for (int i = 0; i < n; i++) {
        double e = fmax(p[i].error, 1e-12);
        a.x0 = fmin(a.x0, floor(log10(p[i].seconds)));
        a.x1 = fmax(a.x1, ceil(log10(p[i].seconds)));
        a.y0 = fmin(a.y0, floor(log10(e)));
        a.y1 = fmax(a.y1, ceil(log10(e)));
    }
    if (a.x1 <= a.x0) a.x1 = a.x0 + 1;
    if (a.y1 <= a.y0) a.y1 = a.y0 + 1;

    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, 13);
    cairo_set_line_width(cr, 1);
    for (int d = (int)a.x0; d <= (int)a.x1; d++) { /* decade grid and labels */
        double x = px(&a, pow(10, d));
        cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
        cairo_move_to(cr, x, a.top);
        cairo_line_to(cr, x, a.bottom);
        cairo_stroke(cr);
        char lab[16];
        snprintf(lab, sizeof lab, "1e%d", d);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, x - 14, a.bottom + 18);
        cairo_show_text(cr, lab);
    }
    for (int d = (int)a.y0; d <= (int)a.y1; d++) {
        double y = py(&a, pow(10, d));
        cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
        cairo_move_to(cr, a.left, y);
        cairo_line_to(cr, a.right, y);
        cairo_stroke(cr);
        char lab[16];
        snprintf(lab, sizeof lab, "1e%d", d);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, a.left - 45, y + 4);
        cairo_show_text(cr, lab);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_rectangle(cr, a.left, a.top, a.right - a.left, a.bottom - a.top);
    cairo_stroke(cr);
    cairo_move_to(cr, (a.left + a.right) / 2 - 90, H - 25);
    cairo_show_text(cr, "wall time of 1 s simulated (s)");
    cairo_save(cr);
    cairo_move_to(cr, 25, (a.top + a.bottom) / 2 + 120);
    cairo_rotate(cr, -M_PI / 2);
    cairo_show_text(cr, "max centre-of-mass error vs analytic (m)");
    cairo_restore(cr);
    cairo_set_font_size(cr, 15);
    cairo_move_to(cr, a.left, 30);
    cairo_show_text(cr, "Accuracy against time: tetrahedron on the incline (Fig. 8), theta = 36 deg, mu = 0.6");

    const double colors[][3] = {{0.80, 0.20, 0.15}, {0.15, 0.40, 0.80}, {0.30, 0.60, 0.25},
                                {0.55, 0.30, 0.65}};
    const char *seen[8];
    int nseen = 0;
    for (int i = 0; i < n; i++) {
        int s = 0;
        while (s < nseen && strcmp(seen[s], p[i].series) != 0)
            s++;
        if (s == nseen)
            seen[nseen++] = p[i].series;
        const double *c = colors[s % 4];
        cairo_set_source_rgb(cr, c[0], c[1], c[2]);
        cairo_set_line_width(cr, 2);
        double x = px(&a, p[i].seconds), y = py(&a, fmax(p[i].error, 1e-12));
        if (i > 0 && strcmp(p[i - 1].series, p[i].series) == 0) {
            cairo_move_to(cr, px(&a, p[i - 1].seconds), py(&a, fmax(p[i - 1].error, 1e-12)));
            cairo_line_to(cr, x, y);
            cairo_stroke(cr);
        }
        cairo_arc(cr, x, y, 4.5, 0, 2 * M_PI);
        cairo_fill(cr);
        char lab[32];
        snprintf(lab, sizeof lab, "%g", p[i].value);
        cairo_set_font_size(cr, 11);
        cairo_move_to(cr, x + 6, y - 6);
        cairo_show_text(cr, lab);
    }
    cairo_set_font_size(cr, 13);
    for (int s = 0; s < nseen; s++) {
        const double *c = colors[s % 4];
        cairo_set_source_rgb(cr, c[0], c[1], c[2]);
        cairo_arc(cr, a.right + 20, a.top + 20 + 22 * s, 4.5, 0, 2 * M_PI);
        cairo_fill(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, a.right + 30, a.top + 25 + 22 * s);
        cairo_show_text(cr, seen[s]);
    }
    cairo_surface_write_to_png(surf, path);
    cairo_destroy(cr);
    cairo_surface_destroy(surf);
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
    plot(pts, n, path);
    printf("wrote %s/accuracy_time.csv and %s\n", dir, path);
    return 0;
}
