/* plot.h: the benchmarks' one piece of plotting code (cairo, PNG out).
 *
 * A canvas holds one or more panels; a panel is a rectangle of plotting area
 * with a linear or log axis each way, a grey grid at the ticks, tick labels,
 * axis labels and a title. Series (polylines with markers and a label beside
 * each point) and legend entries go into the panel started last.
 *
 *     cs_plot *p = cs_plot_create(900, 600);
 *     cs_plot_panel(p, 90, 50, 670, 530, &x_axis, &y_axis, "title");
 *     cs_plot_series(p, n, x, y, labels, &style);
 *     cs_plot_legend(p, "name", &style);
 *     cs_plot_write_png(p, "out.png");
 *     cs_plot_destroy(p);
 */
#ifndef CS_BENCH_PLOT_H
#define CS_BENCH_PLOT_H

typedef enum cs_plot_scale { CS_PLOT_LINEAR, CS_PLOT_LOG } cs_plot_scale;

typedef struct cs_plot_axis {
    cs_plot_scale scale;
    double lo, hi;           /* data range; a log axis (lo > 0) widens it to whole decades */
    double step;             /* linear tick spacing; 0: 1, 2 or 5 times a power of ten */
    const char *label;       /* axis label; NULL: none */
    const char *tick_format; /* printf format of a linear tick's value; NULL: "%g" */
} cs_plot_axis;

typedef struct cs_plot_style {
    double rgb[3];
    double line_width;    /* 0: markers only */
    int dashed;
    double marker_radius; /* filled circles; 0: line only */
    int labels_below;     /* point labels below right of the point, not above right */
} cs_plot_style;

typedef struct cs_plot cs_plot;

/* 1, 2 or 5 times a power of ten: a tick spacing giving at most about 8
 * ticks over range (what a linear axis with step 0 uses). */
double cs_plot_nice_step(double range);

/* A white canvas of width x height pixels; NULL if cairo cannot make one. */
cs_plot *cs_plot_create(int width, int height);
void cs_plot_destroy(cs_plot *p);

/* Starts a panel whose plotting area is the pixel rectangle (left, top) to
 * (right, bottom): draws its grid, tick labels, frame, axis labels and
 * title (NULL: none). The legend starts to the right of the area. */
void cs_plot_panel(cs_plot *p, double left, double top, double right, double bottom,
                   const cs_plot_axis *x, const cs_plot_axis *y, const char *title);

/* n points in data coordinates of the current panel, joined in order by
 * the style's line, a marker on each; labels[i] (labels or labels[i] may be
 * NULL) is written beside point i in the series' colour. */
void cs_plot_series(cs_plot *p, int n, const double *x, const double *y,
                    const char *const *labels, const cs_plot_style *style);

/* Moves the next legend entry's marker to pixel (x, y); later entries
 * follow below it. */
void cs_plot_legend_at(cs_plot *p, double x, double y);
/* One legend entry: the style's marker (or a stretch of its line) and name. */
void cs_plot_legend(cs_plot *p, const char *name, const cs_plot_style *style);

/* Black text with its baseline starting at pixel (x, y). */
void cs_plot_text(cs_plot *p, double x, double y, double font_size, const char *text);

/* 0 on success, -1 if the file cannot be written. */
int cs_plot_write_png(cs_plot *p, const char *path);

#endif
