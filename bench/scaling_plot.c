/* scaling_plot: draws the strong-scaling picture (the paper's Fig. 16) from
 * the table that bench/scaling.sh measures.
 *
 * usage: bench_scaling_plot IN.csv OUT.png
 *
 * IN.csv: a header "ranks,seconds_per_frame" (",title" may follow), then one
 * line "N,S" a rank count (distinct) with its seconds per frame, optionally
 * ",TITLE"; lines starting with '#' are comments, "# title: TITLE" among
 * them. The picture's title is the first title column, else the comment.
 *
 * Left panel: speedup against ranks with the ideal line, each point
 * labelled with its parallel efficiency (speedup / ranks). Right panel: the
 * efficiency in %, each point labelled with its seconds per frame. Speedup
 * is measured from the smallest rank count r0 as r0 * S(r0) / S(N), so it
 * is the usual S(1) / S(N) whenever 1 rank was measured.
 *
 * exit status: 0 written; 1 bad command line; 2 bad input (message
 * FILE:LINE: what was expected); 4 the picture could not be written.
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/plot.h"

typedef struct sample {
    int ranks;
    double seconds;
} sample;

typedef struct table {
    sample *rows;
    int n, cap;
    char *title; /* NULL: none given */
} table;

static void table_destroy(table *t)
{
    free(t->rows);
    free(t->title);
    *t = (table){0};
}

/* Prints FILE:LINE: expected, and returns 2 (the exit status of bad input). */
static int bad(const char *file, long line, const char *expected)
{
    fprintf(stderr, "bench_scaling_plot: %s:%ld: %s\n", file, line, expected);
    return 2;
}

/* Removes trailing white space (and the '\r' of a CRLF file). */
static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    size_t n = strlen(s);
    while (n > 0 && isspace((unsigned char)s[n - 1]))
        s[--n] = '\0';
    return s;
}

static int set_title(table *t, const char *title)
{
    if (t->title || !*title)
        return 0;
    t->title = malloc(strlen(title) + 1);
    if (!t->title)
        return -1;
    strcpy(t->title, title);
    return 0;
}

/* One data line "N,S[,TITLE]" into t; NULL, or what was expected. */
static const char *parse_row(table *t, char *s)
{
    char *end;
    errno = 0;
    long ranks = strtol(s, &end, 10);
    if (end == s || *end != ',' || errno || ranks < 1 || ranks > 1000000)
        return "a rank count (an integer >= 1) then ','";
    s = end + 1;
    double seconds = strtod(s, &end);
    while (isspace((unsigned char)*end))
        end++;
    if (end == s || (*end != ',' && *end != '\0') || !isfinite(seconds) || seconds <= 0)
        return "seconds per frame (a number > 0) after the rank count";
    for (int i = 0; i < t->n; i++)
        if (t->rows[i].ranks == ranks)
            return "a rank count not given on an earlier line";
    if (*end == ',' && set_title(t, trim(end + 1)))
        return "a shorter title (out of memory)";
    if (t->n == t->cap) {
        int cap = t->cap ? 2 * t->cap : 16;
        sample *rows = realloc(t->rows, (size_t)cap * sizeof *rows);
        if (!rows)
            return "fewer lines (out of memory)";
        t->rows = rows, t->cap = cap;
    }
    t->rows[t->n++] = (sample){(int)ranks, seconds};
    return NULL;
}

/* Reads path into t (empty on entry); 0, or the exit status 2 after the
 * message. */
static int table_read(table *t, const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "bench_scaling_plot: %s:0: a readable file (%s)\n", path,
                strerror(errno));
        return 2;
    }
    char *buf = NULL, *comment_title = NULL;
    size_t cap = 0;
    long line = 0;
    int header = 0, rc = 0;
    while (rc == 0 && getline(&buf, &cap, f) >= 0) {
        line++;
        char *s = trim(buf);
        if (*s == '#') {
            s = trim(s + 1);
            if (!comment_title && strncmp(s, "title:", 6) == 0) {
                s = trim(s + 6);
                comment_title = malloc(strlen(s) + 1);
                if (comment_title)
                    strcpy(comment_title, s);
            }
        } else if (!*s) {
            continue;
        } else if (!header) {
            if (strcmp(s, "ranks,seconds_per_frame") != 0 &&
                strcmp(s, "ranks,seconds_per_frame,title") != 0)
                rc = bad(path, line, "the header \"ranks,seconds_per_frame\" (\",title\" may follow)");
            header = 1;
        } else {
            const char *expected = parse_row(t, s);
            if (expected)
                rc = bad(path, line, expected);
        }
    }
    if (rc == 0 && ferror(f))
        rc = bad(path, line + 1, "a readable line (read error)");
    if (rc == 0 && t->n == 0)
        rc = bad(path, line + 1, header ? "a data line \"RANKS,SECONDS\" (e.g. \"1,6.0\")"
                                        : "the header \"ranks,seconds_per_frame\"");
    if (rc == 0 && comment_title && set_title(t, comment_title))
        rc = bad(path, line, "a shorter title (out of memory)");
    free(comment_title);
    free(buf);
    fclose(f);
    return rc;
}

static int by_ranks(const void *a, const void *b)
{
    int x = ((const sample *)a)->ranks, y = ((const sample *)b)->ranks;
    return (x > y) - (x < y);
}

enum { W = 1100, H = 520, PANEL_W = 420, TOP = 85, BOTTOM = H - 75 };

static int draw(const table *t, const char *out)
{
    int n = t->n;
    double *ranks = malloc(4 * (size_t)n * sizeof *ranks);
    char (*text)[2][32] = malloc((size_t)n * sizeof *text);
    const char **labels = malloc(2 * (size_t)n * sizeof *labels);
    cs_plot *p = cs_plot_create(W, H);
    int rc = -1;
    if (!ranks || !text || !labels || !p)
        goto done;
    double *speedup = ranks + n, *efficiency = ranks + 2 * n, *seconds = ranks + 3 * n;
    const sample *base = &t->rows[0];
    double top_speedup = 0;
    for (int i = 0; i < n; i++) {
        ranks[i] = t->rows[i].ranks;
        seconds[i] = t->rows[i].seconds;
        speedup[i] = base->ranks * base->seconds / seconds[i];
        efficiency[i] = 100 * speedup[i] / ranks[i];
        top_speedup = fmax(top_speedup, speedup[i]);
        snprintf(text[i][0], sizeof text[i][0], "%.0f%%", efficiency[i]);
        snprintf(text[i][1], sizeof text[i][1], "%.3g s", seconds[i]);
        labels[i] = text[i][0];
        labels[n + i] = text[i][1];
    }
    double most = fmax(2, ranks[n - 1]);
    double ideal_x[] = {base->ranks, most}, ideal_speedup[] = {base->ranks, most},
           ideal_efficiency[] = {100, 100};
    /* speedup labels below the line, where the ideal line is not;
     * efficiency labels above it, where the falling line is not */
    const cs_plot_style speedup_style = {{0.15, 0.40, 0.80}, 2, 0, 4.5, 1};
    const cs_plot_style efficiency_style = {{0.15, 0.40, 0.80}, 2, 0, 4.5, 0};
    const cs_plot_style ideal = {{0.45, 0.45, 0.45}, 1.5, 1, 0, 0};

    cs_plot_text(p, 90, 30, 15, t->title ? t->title : "Strong scaling");
    /* ranks in whole steps (no tick at 1.5 ranks); room on the right for
     * the last point's label */
    cs_plot_axis x = {CS_PLOT_LINEAR, 0, 1.1 * most, fmax(1, cs_plot_nice_step(most)),
                      "MPI ranks (processes)", NULL};
    char speedup_label[64];
    if (base->ranks == 1)
        snprintf(speedup_label, sizeof speedup_label, "speedup over 1 rank");
    else
        snprintf(speedup_label, sizeof speedup_label, "speedup (%d ranks taken as ideal)",
                 base->ranks);
    cs_plot_axis y = {CS_PLOT_LINEAR, 0, fmax(most, ceil(top_speedup)), 0, speedup_label, NULL};
    cs_plot_panel(p, 90, TOP, 90 + PANEL_W, BOTTOM, &x, &y,
                  "Speedup (labels: parallel efficiency)");
    cs_plot_legend_at(p, 90 + 25, TOP + 20);
    cs_plot_series(p, 2, ideal_x, ideal_speedup, NULL, &ideal);
    cs_plot_legend(p, "ideal: speedup = ranks", &ideal);
    cs_plot_series(p, n, ranks, speedup, labels, &speedup_style);
    cs_plot_legend(p, "measured", &speedup_style);

    double top_efficiency = 0;
    for (int i = 0; i < n; i++)
        top_efficiency = fmax(top_efficiency, efficiency[i]);
    cs_plot_axis e = {CS_PLOT_LINEAR, 0, fmax(120, 20 * ceil(top_efficiency / 20 + 0.25)), 20,
                      "parallel efficiency = speedup / ranks", "%g%%"};
    int left = W - 80 - PANEL_W;
    cs_plot_panel(p, left, TOP, left + PANEL_W, BOTTOM, &x, &e,
                  "Parallel efficiency (labels: s / frame)");
    cs_plot_legend_at(p, left + 25, BOTTOM - 40);
    cs_plot_series(p, 2, ideal_x, ideal_efficiency, NULL, &ideal);
    cs_plot_legend(p, "ideal: 100%", &ideal);
    cs_plot_series(p, n, ranks, efficiency, labels + n, &efficiency_style);
    cs_plot_legend(p, "measured", &efficiency_style);
    rc = cs_plot_write_png(p, out);
done:
    cs_plot_destroy(p);
    free(labels);
    free(text);
    free(ranks);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: bench_scaling_plot IN.csv OUT.png\n"
                        "IN.csv: lines ranks,seconds_per_frame (bench/scaling.sh writes it)\n");
        return 1;
    }
    table t = {0};
    int rc = table_read(&t, argv[1]);
    if (rc == 0) {
        qsort(t.rows, (size_t)t.n, sizeof *t.rows, by_ranks);
        if (draw(&t, argv[2])) {
            fprintf(stderr, "bench_scaling_plot: cannot write %s\n", argv[2]);
            rc = 4;
        }
    }
    table_destroy(&t);
    return rc;
}
