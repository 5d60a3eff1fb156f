/* sweep_report.c: the plumbing of `clothsim sweep`: starting a run as a
 * child process, and the tables (sweep.csv, sweep.md) it writes (the
 * pictures: sweep_plot.c). */
#include "app/sweep_cmd.h"

#include "common/util.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
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
