/* info_plot.c: DIR/info.png of `clothsim info`: three panels against time
 * (intersecting pairs; energies; speeds), drawn by PLplot's pngcairo
 * device as sweep's pictures are (cs_plot_open, sweep_plot.c), into a PNG
 * that appears atomically. A build without PLplot compiles plot_none.c
 * instead. */
#include "app/info_cmd.h"

#include "app/sweep_cmd.h"
#include "common/util.h"

#include <math.h>
#include <plplot.h>
#include <stdlib.h>

static void range_of(const double *y, int n, double *lo, double *hi)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (int i = 0; i < n; i++)
        if (isfinite(y[i])) {
            *lo = fmin(*lo, y[i]);
            *hi = fmax(*hi, y[i]);
        }
    if (!isfinite(*lo))
        *lo = 0, *hi = 1;
    double span = *hi - *lo;
    if (!(span > 0))
        span = fabs(*hi) > 0 ? fabs(*hi) : 1;
    *lo -= 0.05 * span;
    *hi += 0.05 * span;
}

/* Draws the finite points of y against x as a line (and dots). */
static void curve(const double *x, const double *y, int n, PLINT colour, PLINT style)
{
    PLFLT *px = malloc(sizeof *px * ((size_t)n + 1)), *py = malloc(sizeof *py * ((size_t)n + 1));
    int m = 0;
    for (int i = 0; px && py && i < n; i++)
        if (isfinite(x[i]) && isfinite(y[i])) {
            px[m] = x[i];
            py[m++] = y[i];
        }
    plcol0(colour);
    pllsty(style);
    if (m > 1)
        plline(m, px, py);
    if (m > 0)
        plstring(m, px, py, "#(728)");
    pllsty(1);
    free(px);
    free(py);
}

static void panel(const double *t, int n, const double *const *ys, const char *const *labels,
                  int ncurves, const char *ylabel, const char *title)
{
    double xlo, xhi, ylo = INFINITY, yhi = -INFINITY;
    range_of(t, n, &xlo, &xhi);
    for (int c = 0; c < ncurves; c++) {
        double lo, hi;
        range_of(ys[c], n, &lo, &hi);
        ylo = fmin(ylo, lo);
        yhi = fmax(yhi, hi);
    }
    if (ncurves > 1) /* room for the legend above the curves */
        yhi += 0.15 * ncurves * (yhi - ylo);
    if (ncurves == 1 && ylo < 0 && ylo > -1) /* a count: from 0, at least to 1 */
        yhi = fmax(yhi, 1), ylo = -0.04 * yhi;
    static const PLINT colours[] = {1, 9, 3, 8};
    plcol0(15);
    plenv(xlo, xhi, ylo, yhi, 0, 0);
    pllab("time (s)", ylabel, title);
    for (int c = 0; c < ncurves; c++)
        curve(t, ys[c], n, colours[c % 4], 1 + c / 4);
    if (ncurves > 1) {
        PLINT opts[4], cols[4], styles[4], nsym[4];
        PLFLT widths[4], scales[4];
        const char *syms[4];
        for (int c = 0; c < ncurves && c < 4; c++) {
            opts[c] = PL_LEGEND_LINE;
            cols[c] = colours[c];
            styles[c] = 1;
            widths[c] = 1;
            scales[c] = 1;
            nsym[c] = 1;
            syms[c] = "#(728)";
        }
        PLFLT lw, lh;
        plcol0(15);
        pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
                 PL_POSITION_TOP | PL_POSITION_RIGHT | PL_POSITION_INSIDE, 0.02, 0.02, 0.08, 0,
                 15, 1, 0, 0, ncurves < 4 ? ncurves : 4, opts, 1.0, 0.8, 2.0, 0.0, cols,
                 labels, NULL, NULL, NULL, NULL, cols, styles, widths, cols, scales, nsym, syms);
    }
}

static int fill_plot(const char *tmp, void *vfig, char *why, size_t whylen)
{
    const cs_info_figure *f = vfig;
    int n = f->n;
    if (cs_plot_open(tmp, 900, 1100, why, whylen) != 0)
        return -1;
    plssub(1, 3);
    plinit();
    const double *y1[] = {f->pairs};
    const char *l1[] = {"pairs"};
    panel(f->t, n, y1, l1, 1, "pairs", f->title);
    const double *y2[] = {f->kinetic, f->potential, f->total};
    const char *l2[] = {"kinetic (from positions)", "potential (gravity) - frame 0's",
                        "kinetic + mid-frame potential - frame 1's"};
    panel(f->t, n, y2, l2, 3, "energy (J)", "energy");
    const double *y3[] = {f->max_speed, f->fd_speed};
    const char *l3[] = {"max_speed (frames.jsonl)", "max |dx| fps (positions)"};
    panel(f->t, n, y3, l3, 2, "speed (m/s)", "largest vertex speed");
    plend();
    return 0;
}

int cs_info_plot(const char *path, const cs_info_figure *figure, char *err, size_t errlen)
{
    return cs_write_atomic(path, false, fill_plot, (void *)figure, err, errlen);
}
