/* sweep_report.c: the plumbing of `clothsim sweep`: starting a run as a
 * child process, and the tables (sweep.csv, sweep.md) and the picture
 * (sweep.png, PLplot) it writes. */
#include "app/sweep_cmd.h"

#include "common/util.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <plplot.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

/* ------------------------------------------------------------ the runs */

int cs_sweep_spawn(const char *const *argv, const char *log, char *err, size_t errlen)
{
    int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    pid_t pid = fd < 0 ? -1 : fork();
    if (pid == 0) {
        dup2(fd, STDOUT_FILENO);
        dup2(fd, STDERR_FILENO);
        execv("/proc/self/exe", (char *const *)argv);
        _exit(127);
    }
    int saved = errno;
    if (fd >= 0)
        close(fd);
    if (pid < 0) {
        snprintf(err, errlen, "cannot start 'clothsim %s' (log %s): %s", argv[1], log,
                 strerror(saved));
        return -1;
    }
    int wstatus;
    while (waitpid(pid, &wstatus, 0) < 0)
        if (errno != EINTR) {
            snprintf(err, errlen, "waiting for 'clothsim %s': %s", argv[1], strerror(errno));
            return -1;
        }
    return WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 128 + WTERMSIG(wstatus);
}

/* ---------------------------------------------------------------- tables */

/* A field: CSV quotes one holding a comma or a quote; Markdown escapes '|'. */
static void put_field(FILE *f, const char *s, bool markdown)
{
    bool quote = !markdown && strpbrk(s, ",\"\n");
    if (quote)
        fputc('"', f);
    for (; *s; s++) {
        if ((*s == '"' && quote) || (*s == '|' && markdown))
            fputc(*s == '"' ? '"' : '\\', f);
        fputc(*s, f);
    }
    if (quote)
        fputc('"', f);
}

typedef struct table_job {
    const cs_sweep_table *t;
    bool markdown;
} table_job;

static int fill_table(const char *tmp, void *ctx, char *why, size_t whylen)
{
    const table_job *j = ctx;
    const cs_sweep_table *t = j->t;
    FILE *f = fopen(tmp, "w");
    if (!f) {
        snprintf(why, whylen, "%s", strerror(errno));
        return -1;
    }
    for (int r = -1; r < t->nrows; r++) {
        if (j->markdown)
            fputs("| ", f);
        for (int c = 0; c < t->ncols; c++) {
            const char *cell = r < 0 ? t->header[c] : t->cells[(size_t)r * t->ncols + c];
            if (j->markdown && !*cell)
                cell = "–"; /* not applicable */
            put_field(f, cell, j->markdown);
            fputs(c + 1 < t->ncols ? (j->markdown ? " | " : ",") : (j->markdown ? " |\n" : "\n"),
                  f);
        }
        for (int c = 0; r < 0 && j->markdown && c < t->ncols; c++)
            fputs(c ? " --- |" : "| --- |", f);
        if (r < 0 && j->markdown)
            fputc('\n', f);
    }
    bool failed = ferror(f) != 0;
    if (fclose(f) != 0 || failed) {
        snprintf(why, whylen, "%s", strerror(errno ? errno : EIO));
        return -1;
    }
    return 0;
}

int cs_sweep_write_table(const char *path, const cs_sweep_table *t, bool markdown, char *err,
                         size_t errlen)
{
    table_job j = {t, markdown};
    return cs_write_atomic(path, false, fill_table, &j, err, errlen);
}

/* ------------------------------------------------------------------ plot */

typedef struct plot_job {
    const cs_sweep_curve *curves;
    int ncurves;
    double ref_seconds;
} plot_job;

/* PLplot calls this instead of exit() on an error it cannot go on from. */
static int plplot_exit(const char *message)
{
    fprintf(stderr, "clothsim sweep: PLplot: %s\n", message);
    return 1; /* let PLplot abort: nothing else can be done */
}

static int fill_plot(const char *tmp, void *ctx, char *why, size_t whylen)
{
    const plot_job *j = ctx;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (int c = 0; c < j->ncurves; c++)
        for (int i = 0; i < j->curves[c].n; i++) {
            xmin = fmin(xmin, log10(j->curves[c].seconds[i]));
            xmax = fmax(xmax, log10(j->curves[c].seconds[i]));
            ymin = fmin(ymin, log10(j->curves[c].error[i]));
            ymax = fmax(ymax, log10(j->curves[c].error[i]));
        }
    if (j->ref_seconds > 0) {
        xmin = fmin(xmin, log10(j->ref_seconds));
        xmax = fmax(xmax, log10(j->ref_seconds));
    }
    if (!isfinite(xmin)) { /* nothing to draw: an empty decade */
        xmin = -1;
        xmax = 0;
    }
    if (!isfinite(ymin)) {
        ymin = -6;
        ymax = -5;
    }
    /* a margin of a tenth of a decade, whole decades at least */
    xmin = floor(xmin - 0.1);
    xmax = ceil(xmax + 0.1);
    ymin = floor(ymin - 0.1);
    ymax = ceil(ymax + 0.1);

    plsexit(plplot_exit);
    PLCHAR_VECTOR menus[128], devs[128], *pm = menus, *pd = devs;
    int ndevs = 128;
    bool have = false;
    plgDevs(&pm, &pd, &ndevs);
    for (int i = 0; i < ndevs && !have; i++)
        have = strcmp(devs[i], "pngcairo") == 0;
    if (!have) { /* PLplot would ask on the terminal */
        snprintf(why, whylen, "PLplot has no pngcairo device (install plplot-driver-cairo)");
        return -1;
    }
    plsdev("pngcairo");
    plsfnam(tmp);
    plspage(0, 0, 800, 600, 0, 0);
    plscolbg(255, 255, 255);
    plscol0(15, 0, 0, 0); /* black axes on white */
    plinit();
    plcol0(15);
    plenv(xmin, xmax, ymin, ymax, 0, 30); /* 30: log x and log y */
    pllab("wall seconds of the run", "error against the reference, m",
          "clothsim sweep: error against cost");
    static const PLINT colours[] = {1, 3, 9, 8, 13, 4, 12, 10};
    int n = j->ncurves;
    PLINT *opts = calloc((size_t)n + 1, sizeof *opts), *cols = calloc((size_t)n + 1, sizeof *cols);
    PLINT *styles = calloc((size_t)n + 1, sizeof *styles), *nsym = calloc((size_t)n + 1, sizeof *nsym);
    PLFLT *widths = calloc((size_t)n + 1, sizeof *widths), *scales = calloc((size_t)n + 1, sizeof *scales);
    const char **syms = calloc((size_t)n + 1, sizeof *syms);
    const char **labels = calloc((size_t)n + 1, sizeof *labels);
    for (int c = 0; c < n; c++) {
        const cs_sweep_curve *cv = &j->curves[c];
        PLFLT *x = malloc((size_t)(cv->n + 1) * sizeof *x), *y = malloc((size_t)(cv->n + 1) * sizeof *y);
        for (int i = 0; x && y && i < cv->n; i++) {
            x[i] = log10(cv->seconds[i]);
            y[i] = log10(cv->error[i]);
        }
        plcol0(colours[c % 8]);
        if (x && y && cv->n > 1)
            plline(cv->n, x, y);
        if (x && y && cv->n > 0)
            plstring(cv->n, x, y, "#(728)"); /* a filled circle */
        free(x);
        free(y);
        if (opts) {
            opts[c] = PL_LEGEND_LINE | PL_LEGEND_SYMBOL;
            cols[c] = colours[c % 8];
            styles[c] = 1;
            widths[c] = 1;
            scales[c] = 1;
            nsym[c] = 1;
            syms[c] = "#(728)";
        }
        if (labels)
            labels[c] = cv->label;
    }
    if (j->ref_seconds > 0) { /* the reference: a dashed vertical line */
        PLFLT x[2] = {log10(j->ref_seconds), log10(j->ref_seconds)}, y[2] = {ymin, ymax};
        plcol0(15);
        pllsty(2);
        plline(2, x, y);
        pllsty(1);
        /* at the foot of the line: the legend stands at the top right */
        plptex(x[0], ymin + 0.04 * (ymax - ymin), 1, 0, 1.05, "reference");
    }
    if (opts && cols && styles && nsym && widths && scales && syms && labels && n > 0) {
        PLFLT lw, lh;
        plcol0(15);
        pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
                 PL_POSITION_TOP | PL_POSITION_RIGHT | PL_POSITION_INSIDE, 0.02, 0.02, 0.08, 0,
                 15, 1, 0, 0, n, opts, 1.0, 0.8, 2.0, 0.0, cols, labels,
                 NULL, NULL, NULL, NULL, cols, styles, widths, cols, scales, nsym,
                 (const char *const *)syms);
    }
    plend();
    free(opts);
    free(cols);
    free(styles);
    free(nsym);
    free(widths);
    free(scales);
    free(syms);
    free(labels);
    return 0;
}

int cs_sweep_plot(const char *path, const cs_sweep_curve *curves, int ncurves,
                  double ref_seconds, char *err, size_t errlen)
{
    plot_job j = {curves, ncurves, ref_seconds};
    return cs_write_atomic(path, false, fill_plot, &j, err, errlen);
}
