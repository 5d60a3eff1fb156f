/* shares.c: thread shares that follow the threads' measured speeds (see
 * shares.h). */
#include "sim/shares.h"

#include <math.h>
#include <stdlib.h>

/* A measure moves a thread's speed this far towards itself: the split
 * follows a vCPU that slowed within a few solves (a step makes two). */
static const double SPEED_GAIN = 0.3;
/* One measure changes a speed by at most this factor, so that a thread
 * the host descheduled once does not hand its rows away. */
static const double MAX_CHANGE = 2.0;
/* Every thread keeps at least this fraction of an equal share, so that
 * it goes on being measured. */
static const double MIN_SHARE = 0.25;

int cs_shares_init(cs_shares *s, int nrows, int block)
{
    *s = (cs_shares){0};
    s->threads = omp_get_max_threads();
    s->nrows = nrows;
    s->block = block;
    s->nblocks = (nrows + block - 1) / block;
    s->first = malloc(sizeof *s->first * ((size_t)s->threads + 1));
    s->speed = calloc((size_t)s->threads, sizeof *s->speed);
    s->clock = calloc((size_t)s->threads, sizeof *s->clock);
    if (!s->first || !s->speed || !s->clock) {
        cs_shares_free(s);
        return -1;
    }
    for (int t = 0; t <= s->threads; t++)
        s->first[t] = (int)((long)s->nblocks * t / s->threads);
    return 0;
}

void cs_shares_free(cs_shares *s)
{
    free(s->first);
    free(s->speed);
    free(s->clock);
    *s = (cs_shares){0};
}

void cs_shares_update(cs_shares *s)
{
    if (!s->first || s->threads < 2)
        return;
    bool measured = true;
    for (int t = 0; t < s->threads; t++) {
        double rows = cs_shares_row(s, s->first[t + 1]) - cs_shares_row(s, s->first[t]);
        double busy = s->clock[t].busy, *speed = s->speed + t;
        s->clock[t].busy = 0;
        if (rows > 0 && busy > 0) {
            double rate = rows / busy;
            if (*speed > 0)
                *speed += SPEED_GAIN * (fmin(fmax(rate, *speed / MAX_CHANGE), *speed * MAX_CHANGE) -
                                        *speed);
            else
                *speed = rate;
        }
        measured = measured && *speed > 0;
    }
    if (!measured)
        return;
    double total = 0, floor_share = MIN_SHARE / s->threads, wsum = 0;
    for (int t = 0; t < s->threads; t++)
        total += s->speed[t];
    for (int t = 0; t < s->threads; t++)
        wsum += fmax(s->speed[t] / total, floor_share);
    double cum = 0;
    for (int t = 0; t < s->threads; t++) {
        cum += fmax(s->speed[t] / total, floor_share);
        int next = (int)lround(s->nblocks * (cum / wsum));
        s->first[t + 1] = next < s->first[t] ? s->first[t] : next > s->nblocks ? s->nblocks : next;
    }
    s->first[s->threads] = s->nblocks;
}
