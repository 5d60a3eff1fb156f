/* shares.h: how a rank's rows are split among its OpenMP threads, private
 * to sim/.
 *
 * Equal shares leave the faster thread waiting at every barrier when the
 * cores run at different speeds: a cloud VM's vCPUs when the host runs
 * something else on one of them (one thread can take twice as long as the
 * other over whole frames, the other waiting in libgomp), or big and
 * little cores. So the split
 * follows the threads' measured speeds: each thread clocks its own part
 * of the heavy passes (CG's, the springs', B.5's damping pass), and after
 * each solve the shares move towards rows in proportion to rows per
 * second.
 *
 * Results do not depend on the split: every row's work is the same
 * wherever it runs, and sums are taken per block (CS_BLOCK rows) in block
 * order (cg.c). So a given thread count gives the same bits whatever the
 * timing. The split moves in whole blocks. */
#ifndef CS_SHARES_H
#define CS_SHARES_H

#include <omp.h>
#include <stdbool.h>

/* one per thread, on its own cache line (the threads write them at once) */
typedef struct cs_thread_clock {
    double busy; /* seconds in clocked passes since the last update */
    double pad[7];
} cs_thread_clock;

typedef struct cs_shares {
    int threads;  /* the team size the split is for */
    int nrows, block, nblocks;
    int *first;   /* threads + 1 block indices: thread t has [first[t], first[t + 1]) */
    double *speed; /* per thread: rows per second, smoothed (0: not measured yet) */
    cs_thread_clock *clock;
} cs_shares;

/* Equal shares of nrows rows in blocks of block rows, for the team size
 * omp_get_max_threads() gives now. Returns 0 or -1 (no memory). */
int cs_shares_init(cs_shares *s, int nrows, int block);
void cs_shares_free(cs_shares *s);

/* Whether s holds a split for the calling thread's team (inside a
 * parallel region); a team of another size, or no split, gets equal
 * shares. */
static inline bool cs_shares_fit(const cs_shares *s)
{
    return s && s->first && s->threads == omp_get_num_threads();
}

/* The first row of block b (nrows for the blocks' end) */
static inline int cs_shares_row(const cs_shares *s, int b)
{
    long r = (long)b * s->block;
    return r < s->nrows ? (int)r : s->nrows;
}

/* The calling thread's equal share [*lo, *hi) of n items */
static inline void cs_equal_share(int n, int *lo, int *hi)
{
    int threads = omp_get_num_threads(), me = omp_get_thread_num();
    *lo = (int)((long)n * me / threads);
    *hi = (int)((long)n * (me + 1) / threads);
}

/* The calling thread's blocks [*b0, *b1) of nblocks */
static inline void cs_shares_blocks(const cs_shares *s, int nblocks, int *b0, int *b1)
{
    if (cs_shares_fit(s) && s->nblocks == nblocks) {
        *b0 = s->first[omp_get_thread_num()];
        *b1 = s->first[omp_get_thread_num() + 1];
    } else {
        cs_equal_share(nblocks, b0, b1);
    }
}

/* The first (end 0) or the end (end 1) of the calling thread's blocks */
static inline int cs_shares_bound(const cs_shares *s, int nblocks, int end)
{
    int b[2];
    cs_shares_blocks(s, nblocks, b, b + 1);
    return b[end];
}

/* The calling thread's rows [*r0, *r1) of nrows: its blocks' rows */
static inline void cs_shares_rows(const cs_shares *s, int nrows, int *r0, int *r1)
{
    if (cs_shares_fit(s) && s->nrows == nrows) {
        *r0 = cs_shares_row(s, s->first[omp_get_thread_num()]);
        *r1 = cs_shares_row(s, s->first[omp_get_thread_num() + 1]);
    } else {
        cs_equal_share(nrows, r0, r1);
    }
}

/* Charges the seconds since t0 (omp_get_wtime) to the calling thread. */
static inline void cs_shares_clock(cs_shares *s, double t0)
{
    if (cs_shares_fit(s))
        s->clock[omp_get_thread_num()].busy += omp_get_wtime() - t0;
}

/* Outside any parallel region: moves the split towards the speeds the
 * clocks measured since the last call, and resets them. */
void cs_shares_update(cs_shares *s);

#endif
