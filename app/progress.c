/* progress.c: the per-frame progress display of `clothsim run`. */
#include "app/progress.h"

#include <math.h>
#include <string.h>
#include <unistd.h>

#define BAR_WIDTH 20

void cs_progress_init(cs_progress *p, FILE *out, bool quiet, int first_frame, int total_frames)
{
    memset(p, 0, sizeof *p);
    p->out = out;
    p->enabled = !quiet && out != NULL;
    p->tty = p->enabled && isatty(fileno(out));
    p->first = first_frame;
    p->total = total_frames;
}

void cs_format_duration(double seconds, char *buf, size_t len)
{
    if (!isfinite(seconds) || seconds < 0) {
        snprintf(buf, len, "--");
        return;
    }
    long s = lround(seconds);
    if (s < 60)
        snprintf(buf, len, "%lds", s);
    else if (s < 3600)
        snprintf(buf, len, "%ldm%02lds", s / 60, s % 60);
    else
        snprintf(buf, len, "%ldh%02ldm", s / 3600, (s % 3600) / 60);
}

void cs_progress_frame(cs_progress *p, int frame, double sim_time, double elapsed)
{
    if (!p->enabled || (frame == p->first && !p->tty))
        return;
    /* a resumed run's earlier frames took no time in this process */
    double per_frame = frame > p->first ? elapsed / (frame - p->first) : NAN;
    int left = p->total - frame;
    char eta[32];
    cs_format_duration(left > 0 ? per_frame * left : 0.0, eta, sizeof eta);

    char text[160];
    if (frame > p->first)
        snprintf(text, sizeof text, "frame %d/%d  t=%.3f s  %.3g s/frame  ETA %s",
                 frame, p->total, sim_time, per_frame, eta);
    else
        snprintf(text, sizeof text, "frame %d/%d  t=%.3f s  -- s/frame  ETA --", frame,
                 p->total, sim_time);

    if (!p->tty) {
        fprintf(p->out, "%s\n", text);
        fflush(p->out);
        return;
    }
    char bar[BAR_WIDTH + 1];
    int filled = p->total > 0 ? (int)((long)BAR_WIDTH * frame / p->total) : BAR_WIDTH;
    for (int i = 0; i < BAR_WIDTH; i++)
        bar[i] = i < filled ? '#' : '.';
    bar[BAR_WIDTH] = '\0';

    char line[200];
    int len = snprintf(line, sizeof line, "[%s] %s", bar, text);
    if (len < 0)
        return;
    if (len >= (int)sizeof line)
        len = (int)sizeof line - 1;
    /* Blank what a longer previous line left on screen. */
    int pad = p->last_len > len ? p->last_len - len : 0;
    fprintf(p->out, "\r%s%*s", line, pad, "");
    fflush(p->out);
    p->last_len = len;
    p->line_open = true;
}

void cs_progress_finish(cs_progress *p)
{
    if (p->enabled && p->line_open) {
        fputc('\n', p->out);
        fflush(p->out);
    }
    p->line_open = false;
    p->last_len = 0;
}
