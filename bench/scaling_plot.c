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
 * Drawn with PLplot's pngcairo device (plplot-driver-cairo), as clothsim
 * sweep's pictures.
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

#include <plplot.h>
#include <stdbool.h>

#include "app/sweep_cmd.h"

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

/* PLplot calls this instead of exit() on an error it cannot go on from. */
static int plplot_exit(const char *message)
{
    fprintf(stderr, "bench_scaling_plot: PLplot: %s\n", message);
    return 1;
}

enum { BLACK = 15, GREY = 7, BLUE = 9 };

/* One panel: the ideal line (dashed grey), the measured points joined
 * (blue), each labelled (above or below the point), and a legend. */
static void panel(double left, double right, double xmax, double ymax, const char *ylabel,
                  const char *title, int n,
                  const double *x, const double *y, const double ideal_x[2],
                  const double ideal_y[2], const char *ideal_label, char (*text)[32],
                  bool labels_below, PLINT legend_position)
{
    plcol0(BLACK);
    plvpor(left, right, 0.12, 0.80);
    plwind(0, xmax, 0, ymax);
    plbox("bcnst", xmax <= 12 ? 1 : 0, 0, "bcnstv", 0, 0); /* whole ranks when few */
    pllab("MPI ranks (processes)", ylabel, title);
    plcol0(GREY);
    pllsty(2);
    plline(2, ideal_x, ideal_y);
    pllsty(1);
    plcol0(BLUE);
    plwidth(2);
    if (n > 1)
        plline(n, x, y);
    plwidth(1);
    plstring(n, x, y, "#(728)");
    plcol0(BLACK);
    for (int i = 0; i < n; i++) /* dy in character heights as a fraction of the range */
        plptex(x[i], y[i] + (labels_below ? -0.07 : 0.05) * ymax, 1, 0, 0.5, text[i]);
    PLINT opts[2] = {PL_LEGEND_LINE, PL_LEGEND_LINE | PL_LEGEND_SYMBOL};
    PLINT cols[2] = {GREY, BLUE}, styles[2] = {2, 1}, nsym[2] = {1, 1};
    PLFLT widths[2] = {1, 2}, scales[2] = {1, 1};
    const char *syms[2] = {"#(728)", "#(728)"}, *labels[2] = {ideal_label, "measured"};
    PLFLT lw, lh;
    pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
             legend_position | PL_POSITION_INSIDE, 0.03, 0.03, 0.08, 0, BLACK, 1, 0, 0, 2, opts,
             1.0, 0.8, 2.0, 0.0, cols, labels, NULL, NULL, NULL, NULL, cols, styles, widths, cols,
             scales, nsym, syms);
}

static int draw(const table *t, const char *out)
{
    int n = t->n;
    double *ranks = malloc(4 * (size_t)n * sizeof *ranks);
    char (*eff_text)[32] = malloc((size_t)n * sizeof *eff_text);
    char (*sec_text)[32] = malloc((size_t)n * sizeof *sec_text);
    if (!ranks || !eff_text || !sec_text) {
        free(ranks), free(eff_text), free(sec_text);
        return -1;
    }
    double *speedup = ranks + n, *efficiency = ranks + 2 * n, *seconds = ranks + 3 * n;
    const sample *base = &t->rows[0];
    double top_speedup = 0, top_efficiency = 0;
    for (int i = 0; i < n; i++) {
        ranks[i] = t->rows[i].ranks;
        seconds[i] = t->rows[i].seconds;
        speedup[i] = base->ranks * base->seconds / seconds[i];
        efficiency[i] = 100 * speedup[i] / ranks[i];
        top_speedup = fmax(top_speedup, speedup[i]);
        top_efficiency = fmax(top_efficiency, efficiency[i]);
        snprintf(eff_text[i], sizeof eff_text[i], "%.0f%%", efficiency[i]);
        snprintf(sec_text[i], sizeof sec_text[i], "%.3g s", seconds[i]);
    }
    double most = fmax(2, ranks[n - 1]);
    double ideal_x[] = {base->ranks, most}, ideal_speedup[] = {base->ranks, most},
           ideal_efficiency[] = {100, 100};
    char speedup_label[64], title[512];
    if (base->ranks == 1)
        snprintf(speedup_label, sizeof speedup_label, "speedup over 1 rank");
    else
        snprintf(speedup_label, sizeof speedup_label, "speedup (%d ranks taken as ideal)",
                 base->ranks);
    snprintf(title, sizeof title, "%s", t->title ? t->title : "Strong scaling");

    plsexit(plplot_exit);
    if (!cs_plot_has_pngcairo()) {
        fprintf(stderr, "bench_scaling_plot: PLplot has no pngcairo device (install "
                        "plplot-driver-cairo)\n");
        free(ranks), free(eff_text), free(sec_text);
        return -1;
    }
    FILE *probe = fopen(out, "wb"); /* PLplot would ask for another name */
    if (!probe) {
        fprintf(stderr, "bench_scaling_plot: cannot write %s: %s\n", out, strerror(errno));
        free(ranks), free(eff_text), free(sec_text);
        return -1;
    }
    fclose(probe);
    plsdev("pngcairo");
    plsfnam(out);
    plspage(0, 0, 1200, 560, 0, 0);
    plscolbg(255, 255, 255);
    plscol0(BLACK, 0, 0, 0);
    plscol0(GREY, 110, 110, 110);
    plinit();
    pladv(0);
    /* speedup labels below the line, where the ideal line is not; efficiency
     * labels above it, where the falling line is not */
    panel(0.09, 0.46, 1.15 * most, fmax(most, ceil(top_speedup)) * 1.1, speedup_label,
          "Speedup (labels: parallel efficiency)", n, ranks, speedup, ideal_x, ideal_speedup,
          "ideal: speedup = ranks", eff_text, true, PL_POSITION_TOP | PL_POSITION_LEFT);
    panel(0.60, 0.97, 1.15 * most, fmax(120, 20 * ceil(top_efficiency / 20 + 0.25)),
          "parallel efficiency = speedup / ranks, %", "Parallel efficiency (labels: s / frame)",
          n, ranks, efficiency, ideal_x, ideal_efficiency, "ideal: 100%", sec_text, false,
          PL_POSITION_BOTTOM | PL_POSITION_LEFT);
    /* the overall title above both panels */
    plvpor(0, 1, 0, 1);
    plwind(0, 1, 0, 1);
    plcol0(BLACK);
    plptex(0.5, 0.95, 1, 0, 0.5, title);
    plend();
    free(ranks), free(eff_text), free(sec_text);
    FILE *f = fopen(out, "rb"); /* PLplot reports no write error of its own */
    if (!f)
        return -1;
    fclose(f);
    return 0;
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
