/* sweep_plot.c: the one plotting helper of `clothsim sweep`'s pictures
 * (sweep.png, trajectory.png, cumulative_time.png): curves on linear or
 * log axes with a legend, drawn by PLplot's pngcairo device into a PNG
 * that appears atomically. A build without PLplot compiles plot_none.c
 * instead. */
#include "app/sweep_cmd.h"

#include "common/util.h"

#include <math.h>
#include <plplot.h>
#include <stdlib.h>
#include <string.h>

/* PLplot calls this instead of exit() on an error it cannot go on from. */
static int plplot_exit(const char *message)
{
    fprintf(stderr, "clothsim: PLplot: %s\n", message);
    return 1; /* let PLplot abort: nothing else can be done */
}

/* A coordinate as drawn: log10 on a log axis (NaN for v <= 0). */
static double to_axis(double v, bool log_axis)
{
    return log_axis ? (v > 0 ? log10(v) : NAN) : v;
}

/* The axis range of the drawn values lo..hi: whole decades with a tenth of
 * a decade's margin on a log axis, 4% of the range on a linear one. */
static void axis_range(double *lo, double *hi, bool log_axis)
{
    if (!isfinite(*lo)) { /* nothing to draw */
        *lo = log_axis ? -1 : 0;
        *hi = log_axis ? 0 : 1;
    }
    if (log_axis) {
        *lo = floor(*lo - 0.1);
        *hi = ceil(*hi + 0.1);
        return;
    }
    double span = *hi - *lo;
    if (!(span > 0))
        span = fabs(*hi) > 0 ? fabs(*hi) : 1;
    *lo -= 0.04 * span;
    *hi += 0.04 * span;
}

static const PLINT PALETTE[] = {1, 9, 3, 8, 13, 10, 12, 4};
#define NPALETTE ((int)(sizeof PALETTE / sizeof PALETTE[0]))
#define BLACK 15

/* Curve c's colour and line style: the palette in turn (solid, then in
 * dashes once the colours have run out), or black for colour < 0. */
static void curve_pen(const cs_sweep_figure *f, int c, PLINT *colour, PLINT *style)
{
    int k = 0; /* curves before c that take from the palette */
    for (int i = 0; i < c; i++)
        k += f->curves[i].colour >= 0;
    *colour = f->curves[c].colour < 0 ? BLACK : PALETTE[k % NPALETTE];
    *style = f->curves[c].style > 0 ? f->curves[c].style : 1 + (k / NPALETTE) % 8;
}

int cs_plot_available(char *why, size_t whylen)
{
    (void)why, (void)whylen;
    return 0;
}

bool cs_plot_has_pngcairo(void)
{
    PLCHAR_VECTOR menus[128], devs[128], *pm = menus, *pd = devs;
    int ndevs = 128;
    plgDevs(&pm, &pd, &ndevs);
    for (int i = 0; i < ndevs; i++)
        if (strcmp(devs[i], "pngcairo") == 0)
            return true;
    return false;
}

int cs_plot_open(const char *tmp, int width, int height, char *why, size_t whylen)
{
    plsexit(plplot_exit);
    if (!cs_plot_has_pngcairo()) { /* PLplot would ask on the terminal */
        snprintf(why, whylen, "PLplot has no pngcairo device (install plplot-driver-cairo)");
        return -1;
    }
    plsdev("pngcairo");
    plsfnam(tmp);
    plspage(0, 0, width, height, 0, 0);
    plscolbg(255, 255, 255);
    plscol0(BLACK, 0, 0, 0); /* black axes on white */
    return 0;
}

/* Whether the axis point (x, y), scaled to [0,1]^2 of the box lo..hi,
 * falls in corner c's legend box (w x h of the box). */
static bool in_corner(int c, double u, double v, double w, double h)
{
    bool right = c & 1, top = c & 2;
    return (right ? u >= 1 - w : u <= w) && (top ? v >= 1 - h : v <= h);
}

/* The corner for the legend (as PL_POSITION_* bits): of the four, the one
 * whose box of the legend's size the fewest curve samples (points, and
 * points along each segment; the marked line and its label) fall in; the
 * figure's choice among equals. */
static PLINT legend_corner(const cs_sweep_figure *f, int entries, const double box[4])
{
    double w = 0.5, h = 0.06 + 0.06 * entries; /* a legend's share of the box */
    int hits[4] = {0, 0, 0, 0};
    for (int c = 0; c < f->ncurves; c++) {
        const cs_sweep_curve *cv = &f->curves[c];
        for (int i = 0; i < cv->n; i++)
            for (int k = 0; k < (i + 1 < cv->n ? 8 : 1); k++) {
                double t = k / 8.0, x0 = to_axis(cv->x[i], f->log_x),
                       y0 = to_axis(cv->y[i], f->log_y);
                double x1 = i + 1 < cv->n ? to_axis(cv->x[i + 1], f->log_x) : x0,
                       y1 = i + 1 < cv->n ? to_axis(cv->y[i + 1], f->log_y) : y0;
                double u = ((1 - t) * x0 + t * x1 - box[0]) / (box[1] - box[0]),
                       v = ((1 - t) * y0 + t * y1 - box[2]) / (box[3] - box[2]);
                for (int corner = 0; corner < 4 && isfinite(u) && isfinite(v); corner++)
                    hits[corner] += in_corner(corner, u, v, w, h);
            }
    }
    double mark = to_axis(f->mark_x, f->log_x);
    double um = (mark - box[0]) / (box[1] - box[0]);
    for (int corner = 0; corner < 4 && f->mark_x > 0 && isfinite(um); corner++) {
        for (int k = 0; k <= 20; k++) /* the line */
            hits[corner] += in_corner(corner, um, k / 20.0, w, h);
        for (int k = 0; k <= 4; k++) /* its label, left of its foot */
            hits[corner] += 4 * in_corner(corner, um - 0.04 * k, 0.03, w, h);
    }
    int want = (f->legend & CS_LEGEND_RIGHT ? 1 : 0) | (f->legend & CS_LEGEND_TOP ? 2 : 0);
    int best = want;
    for (int corner = 0; corner < 4; corner++)
        if (hits[corner] < hits[best])
            best = corner;
    return (best & 1 ? PL_POSITION_RIGHT : PL_POSITION_LEFT) |
           (best & 2 ? PL_POSITION_TOP : PL_POSITION_BOTTOM);
}

static void draw_legend(const cs_sweep_figure *f, const double box[4])
{
    int n = f->ncurves, m = 0;
    PLINT *opts = calloc((size_t)n + 1, sizeof *opts), *cols = calloc((size_t)n + 1, sizeof *cols);
    PLINT *styles = calloc((size_t)n + 1, sizeof *styles),
          *nsym = calloc((size_t)n + 1, sizeof *nsym);
    PLFLT *widths = calloc((size_t)n + 1, sizeof *widths),
          *scales = calloc((size_t)n + 1, sizeof *scales);
    const char **syms = calloc((size_t)n + 1, sizeof *syms);
    const char **labels = calloc((size_t)n + 1, sizeof *labels);
    if (opts && cols && styles && nsym && widths && scales && syms && labels) {
        for (int c = 0; c < n; c++) {
            const cs_sweep_curve *cv = &f->curves[c];
            if (!cv->label)
                continue;
            curve_pen(f, c, &cols[m], &styles[m]);
            opts[m] = PL_LEGEND_LINE | (cv->points ? PL_LEGEND_SYMBOL : 0);
            widths[m] = cv->width > 0 ? cv->width : 1;
            scales[m] = 1;
            nsym[m] = 1;
            syms[m] = "#(728)";
            labels[m++] = cv->label;
        }
    }
    if (m > 0) {
        PLFLT lw, lh;
        plcol0(BLACK);
        pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
                 legend_corner(f, m, box) | PL_POSITION_INSIDE, 0.02, 0.02, 0.08, 0, BLACK, 1,
                 0, 0, m, opts, 1.0, 0.8, 2.0, 0.0, cols, labels, NULL, NULL, NULL, NULL, cols,
                 styles, widths, cols, scales, nsym, (const char *const *)syms);
    }
    free(opts);
    free(cols);
    free(styles);
    free(nsym);
    free(widths);
    free(scales);
    free(syms);
    free(labels);
}

static int fill_plot(const char *tmp, void *ctx, char *why, size_t whylen)
{
    const cs_sweep_figure *f = ctx;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (int c = 0; c < f->ncurves; c++)
        for (int i = 0; i < f->curves[c].n; i++) {
            double x = to_axis(f->curves[c].x[i], f->log_x),
                   y = to_axis(f->curves[c].y[i], f->log_y);
            if (!isfinite(x) || !isfinite(y))
                continue;
            xmin = fmin(xmin, x), xmax = fmax(xmax, x);
            ymin = fmin(ymin, y), ymax = fmax(ymax, y);
        }
    double mark = to_axis(f->mark_x, f->log_x);
    if (f->mark_x > 0 && isfinite(mark))
        xmin = fmin(xmin, mark), xmax = fmax(xmax, mark);
    axis_range(&xmin, &xmax, f->log_x);
    axis_range(&ymin, &ymax, f->log_y);

    if (cs_plot_open(tmp, 900, 640, why, whylen) != 0)
        return -1;
    plinit();
    plcol0(BLACK);
    /* 10: log x, 20: log y, 30: both; 0: linear */
    plenv(xmin, xmax, ymin, ymax, 0, (f->log_x ? 10 : 0) + (f->log_y ? 20 : 0));
    pllab(f->xlabel, f->ylabel, f->title);
    for (int c = 0; c < f->ncurves; c++) {
        const cs_sweep_curve *cv = &f->curves[c];
        PLFLT *x = malloc((size_t)(cv->n + 1) * sizeof *x),
              *y = malloc((size_t)(cv->n + 1) * sizeof *y);
        int n = 0;
        for (int i = 0; x && y && i < cv->n; i++) { /* a log axis has no 0: left out */
            x[n] = to_axis(cv->x[i], f->log_x);
            y[n] = to_axis(cv->y[i], f->log_y);
            n += isfinite(x[n]) && isfinite(y[n]);
        }
        PLINT colour, style;
        curve_pen(f, c, &colour, &style);
        plcol0(colour);
        pllsty(style);
        plwidth(cv->width > 0 ? cv->width : 1);
        if (n > 1)
            plline(n, x, y);
        if (cv->points && n > 0)
            plstring(n, x, y, "#(728)"); /* a filled circle */
        free(x);
        free(y);
    }
    plwidth(1);
    pllsty(1);
    if (f->mark_x > 0 && isfinite(mark)) { /* a dashed vertical line */
        PLFLT x[2] = {mark, mark}, y[2] = {ymin, ymax};
        plcol0(BLACK);
        pllsty(2);
        plline(2, x, y);
        pllsty(1);
        /* at the foot of the line: a legend at the top stays clear of it */
        if (f->mark_label)
            plptex(x[0], ymin + 0.04 * (ymax - ymin), 1, 0, 1.05, f->mark_label);
    }
    double box[4] = {xmin, xmax, ymin, ymax};
    draw_legend(f, box);
    plend();
    return 0;
}

int cs_sweep_plot(const char *path, const cs_sweep_figure *figure, char *err, size_t errlen)
{
    return cs_write_atomic(path, false, fill_plot, (void *)figure, err, errlen);
}
