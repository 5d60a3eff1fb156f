/* plot.c: see plot.h. Pixel positions are kept on whole-pixel offsets from
 * the data where possible so that text stays crisp. */
#include "bench/plot.h"

#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

enum { TICK_FONT = 13, TITLE_FONT = 15, POINT_FONT = 11, LEGEND_SPACING = 22 };

/* An axis as drawn: lo and hi in plotted units (log10 of the value on a
 * log axis). */
typedef struct span {
    cs_plot_scale scale;
    double lo, hi, step;
} span;

struct cs_plot {
    cairo_surface_t *surface;
    cairo_t *cr;
    double left, top, right, bottom; /* the current panel's plotting area */
    span x, y;
    double legend_x, legend_y;       /* where the next legend entry's marker goes */
};

cs_plot *cs_plot_create(int width, int height)
{
    cs_plot *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    p->surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
    p->cr = cairo_create(p->surface);
    if (cairo_status(p->cr) != CAIRO_STATUS_SUCCESS) {
        cs_plot_destroy(p);
        return NULL;
    }
    cairo_set_source_rgb(p->cr, 1, 1, 1);
    cairo_paint(p->cr);
    cairo_select_font_face(p->cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    return p;
}

void cs_plot_destroy(cs_plot *p)
{
    if (!p)
        return;
    cairo_destroy(p->cr);
    cairo_surface_destroy(p->surface);
    free(p);
}

double cs_plot_nice_step(double range)
{
    if (!(range > 0) || !isfinite(range))
        return 1;
    double raw = range / 8, unit = pow(10, floor(log10(raw)));
    const double m[] = {1, 2, 5, 10};
    int k = 0;
    while (k < 3 && m[k] * unit < raw)
        k++;
    return m[k] * unit;
}

static span resolve(const cs_plot_axis *a)
{
    span s = {a->scale, a->lo, a->hi, a->step};
    if (s.scale == CS_PLOT_LOG) {
        s.lo = floor(log10(a->lo));
        s.hi = ceil(log10(a->hi));
        s.step = 1;
    }
    if (s.hi <= s.lo)
        s.hi = s.lo + 1;
    if (s.scale == CS_PLOT_LINEAR && !(s.step > 0))
        s.step = cs_plot_nice_step(s.hi - s.lo);
    return s;
}

static double unit_of(const span *s, double v) { return s->scale == CS_PLOT_LOG ? log10(v) : v; }

static double px(const cs_plot *p, double v)
{
    return p->left + (unit_of(&p->x, v) - p->x.lo) / (p->x.hi - p->x.lo) * (p->right - p->left);
}

static double py(const cs_plot *p, double v)
{
    return p->bottom - (unit_of(&p->y, v) - p->y.lo) / (p->y.hi - p->y.lo) * (p->bottom - p->top);
}

/* Tick k of s (0, 1, ...): its value, and its label in buf; 0 past the end. */
static int tick(const span *s, const cs_plot_axis *a, int k, double *value, char *buf, size_t len)
{
    if (k > 200) /* a step far too small for the range: no wall of grid lines */
        return 0;
    if (s->scale == CS_PLOT_LOG) {
        int d = (int)s->lo + k;
        if (d > (int)s->hi)
            return 0;
        *value = pow(10, d);
        snprintf(buf, len, "1e%d", d);
        return 1;
    }
    double v = (ceil(s->lo / s->step - 1e-9) + k) * s->step;
    if (v > s->hi + 1e-9 * s->step)
        return 0;
    if (fabs(v) < 1e-9 * s->step) /* no "-0" or "1e-17" at zero */
        v = 0;
    *value = v;
    snprintf(buf, len, a->tick_format ? a->tick_format : "%g", v);
    return 1;
}

static double advance(cairo_t *cr, const char *text)
{
    cairo_text_extents_t e;
    cairo_text_extents(cr, text, &e);
    return e.x_advance;
}

/* Half a number of pixels, rounded down: centred text stays on whole pixels. */
static double half(double w) { return floor(w / 2); }

static void grid_line(cairo_t *cr, double x0, double y0, double x1, double y1)
{
    cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
    cairo_move_to(cr, x0, y0);
    cairo_line_to(cr, x1, y1);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
}

void cs_plot_panel(cs_plot *p, double left, double top, double right, double bottom,
                   const cs_plot_axis *x, const cs_plot_axis *y, const char *title)
{
    cairo_t *cr = p->cr;
    p->left = left, p->top = top, p->right = right, p->bottom = bottom;
    p->x = resolve(x);
    p->y = resolve(y);
    p->legend_x = right + 20;
    p->legend_y = top + 20;

    cairo_set_font_size(cr, TICK_FONT);
    cairo_set_line_width(cr, 1);
    char lab[64];
    double v;
    for (int k = 0; tick(&p->x, x, k, &v, lab, sizeof lab); k++) {
        double at = px(p, v);
        grid_line(cr, at, top, at, bottom);
        cairo_move_to(cr, at - half(advance(cr, lab)), bottom + 18);
        cairo_show_text(cr, lab);
    }
    for (int k = 0; tick(&p->y, y, k, &v, lab, sizeof lab); k++) {
        double at = py(p, v);
        grid_line(cr, left, at, right, at);
        cairo_text_extents_t e; /* right-aligned, centred on the line */
        cairo_text_extents(cr, lab, &e);
        cairo_move_to(cr, left - 16 - e.x_advance, at + half(-e.y_bearing));
        cairo_show_text(cr, lab);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_rectangle(cr, left, top, right - left, bottom - top);
    cairo_stroke(cr);
    if (x->label) {
        cairo_move_to(cr, (left + right) / 2 - half(advance(cr, x->label)), bottom + 45);
        cairo_show_text(cr, x->label);
    }
    if (y->label) {
        cairo_save(cr);
        cairo_move_to(cr, left - 65, (top + bottom) / 2 + half(advance(cr, y->label)));
        cairo_rotate(cr, -M_PI / 2);
        cairo_show_text(cr, y->label);
        cairo_restore(cr);
    }
    if (title)
        cs_plot_text(p, left, top - 20, TITLE_FONT, title);
}

static void set_line(cairo_t *cr, const cs_plot_style *s)
{
    static const double dash[] = {6, 3};
    cairo_set_source_rgb(cr, s->rgb[0], s->rgb[1], s->rgb[2]);
    cairo_set_line_width(cr, s->line_width);
    cairo_set_dash(cr, dash, s->dashed ? 2 : 0, 0);
}

static void marker(cairo_t *cr, double x, double y, double radius)
{
    cairo_new_path(cr); /* no line from the last text's end */
    cairo_arc(cr, x, y, radius, 0, 2 * M_PI);
    cairo_fill(cr);
}

void cs_plot_series(cs_plot *p, int n, const double *x, const double *y,
                    const char *const *labels, const cs_plot_style *style)
{
    cairo_t *cr = p->cr;
    set_line(cr, style);
    cairo_set_font_size(cr, POINT_FONT);
    /* point by point, each segment stroked before the marker over its end */
    for (int i = 0; i < n; i++) {
        double at_x = px(p, x[i]), at_y = py(p, y[i]);
        if (i > 0 && style->line_width > 0) {
            cairo_move_to(cr, px(p, x[i - 1]), py(p, y[i - 1]));
            cairo_line_to(cr, at_x, at_y);
            cairo_stroke(cr);
        }
        if (style->marker_radius > 0)
            marker(cr, at_x, at_y, style->marker_radius);
        if (labels && labels[i]) {
            cairo_move_to(cr, at_x + 6, at_y + (style->labels_below ? 15 : -6));
            cairo_show_text(cr, labels[i]);
        }
    }
    cairo_set_dash(cr, NULL, 0, 0);
    cairo_set_line_width(cr, 1);
}

void cs_plot_legend_at(cs_plot *p, double x, double y)
{
    p->legend_x = x;
    p->legend_y = y;
}

void cs_plot_legend(cs_plot *p, const char *name, const cs_plot_style *style)
{
    cairo_t *cr = p->cr;
    double x = p->legend_x, y = p->legend_y;
    set_line(cr, style);
    if (style->marker_radius > 0) {
        marker(cr, x, y, style->marker_radius);
    } else {
        cairo_move_to(cr, x - 12, y); /* ends clear of the name at x + 10 */
        cairo_line_to(cr, x + 6, y);
        cairo_stroke(cr);
    }
    cairo_set_dash(cr, NULL, 0, 0);
    cairo_set_line_width(cr, 1);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_font_size(cr, TICK_FONT);
    cairo_move_to(cr, x + 10, y + 5);
    cairo_show_text(cr, name);
    p->legend_y += LEGEND_SPACING;
}

void cs_plot_text(cs_plot *p, double x, double y, double font_size, const char *text)
{
    cairo_set_source_rgb(p->cr, 0, 0, 0);
    cairo_set_font_size(p->cr, font_size);
    cairo_move_to(p->cr, x, y);
    cairo_show_text(p->cr, text);
    cairo_set_font_size(p->cr, TICK_FONT);
}

int cs_plot_write_png(cs_plot *p, const char *path)
{
    cairo_surface_flush(p->surface);
    return cairo_surface_write_to_png(p->surface, path) == CAIRO_STATUS_SUCCESS ? 0 : -1;
}
