/* par.h: distributed memory parallelism (Section 7), private to sim/. The
 * only file that calls MPI is par.c; a build without MPI compiles it
 * against par_one_rank.h instead of <mpi.h>.
 *
 * Every rank keeps the global particle arrays, indexed as on one rank, but
 * owns a subset of the particles (a recursive median split of the initial
 * positions) and updates only those; the particles its forces touch and it
 * does not own are its ghosts, refreshed from their owners, neighbours
 * only. Loops walk index ranges (CS_FOR_OWNED, CS_FOR_LOCAL), so one rank
 * is the same code with one range [0, n) and no messages: a simulation
 * made without MPI initialised, or with CS_COMM_NONE, is one rank.
 *
 * Keeping global arrays costs O(n) memory per rank; the paper synchronises
 * every position to every processor for its collision hierarchies anyway,
 * and it keeps indices, topology and the verifier the same at every rank
 * count. */
#ifndef CS_PAR_H
#define CS_PAR_H

#include <stdbool.h>
#include <stddef.h>

#ifdef CS_HAVE_MPI
#include <mpi.h>
#else
#include "sim/par_one_rank.h" /* a build without MPI: one rank (see there) */
#endif

#include "sim/sim.h"

/* Particles some ranks send to others, both sides listing them in the same
 * (ascending) order: send[] are particles this rank has that the link's
 * rank needs; recv[] the link rank's particles this rank needs. */
typedef struct cs_halo_link {
    int rank;
    int nsend, nrecv;
    int *send, *recv;
} cs_halo_link;

typedef struct cs_halo {
    int nlinks;
    cs_halo_link *link;
} cs_halo;

typedef struct cs_par {
    bool mpi;                 /* false: one rank, no MPI calls at all */
    MPI_Comm comm;            /* a duplicate of the simulation's communicator */
    int rank, size, n;
    int *owner;               /* per particle: the rank that updates it */
    int nowned;
    int nown, *own;           /* owned particles as [lo, hi) ranges */
    int nlocal, *local;       /* owned and ghost particles as ranges */
    cs_halo ghosts;           /* particles forces reach across ranks */
    int *order;               /* particles grouped by owner, ascending within */
    int *counts, *displs;     /* per rank: 3 * particles owned, offsets */
    double *buffer;           /* 3 * n: packing for gathers and halos */
    size_t buffer_size;
    MPI_Request *requests;
    MPI_Op sum_max;           /* for cs_par_sum_max, made on first use */
    int stage;                /* the stage communication is charged to */
    cs_comm_stats stats[CS_STAGE_COUNT];  /* per stage, this rank */
    size_t bytes;             /* memory the partition itself holds */
} cs_par;

#define CS_FOR_RANGES(ranges, nranges, i)                                          \
    for (int r_##i = 0; r_##i < (nranges); r_##i++)                                \
        for (int i = (ranges)[2 * r_##i]; i < (ranges)[2 * r_##i + 1]; i++)
#define CS_FOR_OWNED(par, i) CS_FOR_RANGES((par)->own, (par)->nown, i)
#define CS_FOR_LOCAL(par, i) CS_FOR_RANGES((par)->local, (par)->nlocal, i)
/* The same loops shared among the OpenMP threads, each range in fixed
 * contiguous shares; clauses are OpenMP's, e.g. reduction(max : worst),
 * or none for per-particle work with no reduction. */
#define CS_OMP_PRAGMA(text) _Pragma(#text)
#define CS_PARALLEL_FOR_RANGES_WITH(ranges, nranges, i, clauses)                   \
    for (int r_##i = 0; r_##i < (nranges); r_##i++)                                \
        CS_OMP_PRAGMA(omp parallel for schedule(static) clauses)                   \
        for (int i = (ranges)[2 * r_##i]; i < (ranges)[2 * r_##i + 1]; i++)
#define CS_PARALLEL_FOR_RANGES(ranges, nranges, i)                                 \
    CS_PARALLEL_FOR_RANGES_WITH(ranges, nranges, i, )
#define CS_PARALLEL_FOR_OWNED(par, i) CS_PARALLEL_FOR_RANGES((par)->own, (par)->nown, i)
#define CS_PARALLEL_FOR_LOCAL(par, i) CS_PARALLEL_FOR_RANGES((par)->local, (par)->nlocal, i)
#define CS_PARALLEL_FOR_OWNED_WITH(par, i, clauses)                                \
    CS_PARALLEL_FOR_RANGES_WITH((par)->own, (par)->nown, i, clauses)

/* Partitions n particles at positions x by recursive median split over
 * the ranks of comm; springs (2 ends each) decide the ghosts. Returns NULL
 * when memory runs out. */
cs_par *cs_par_create(cs_comm comm, int n, const double *x, int nsprings, const int *ends);
void cs_par_destroy(cs_par *p);

/* Recursive median split (exposed for tests): owner[i] in [0, parts) for
 * n points, sizes differing by at most one per level. */
void cs_par_median_split(int n, const double *x, int parts, int *owner);

/* True when the particles are shared among ranks, so messages go between
 * them (false for one rank, with MPI or without) */
static inline bool cs_par_distributed(const cs_par *p) { return p->mpi && p->size > 1; }
static inline bool cs_par_owns(const cs_par *p, int i) { return p->owner[i] == p->rank; }
/* This rank's particles, ascending (nowned of them). */
static inline const int *cs_par_owned(const cs_par *p) { return p->order + p->displs[p->rank]; }

/* Owners send their values (width doubles per particle) to the ranks that
 * list them: a ghost refresh. */
void cs_halo_forward(cs_par *p, const cs_halo *h, double *a, int width);
/* The reverse: ranks send back the values of particles they received and
 * the owners overwrite theirs (results of work done elsewhere). */
void cs_halo_reverse(cs_par *p, const cs_halo *h, double *a, int width);
void cs_halo_free(cs_halo *h);
/* A halo from a list of (user rank, particle) needs, the same list on every
 * rank: each particle goes from its owner to the user. Returns 0 or -1. */
int cs_halo_from_needs(const cs_par *p, int nneeds, const int *user, const int *particle,
                       cs_halo *h);

/* Every rank gets every owned value (width doubles per particle). */
void cs_par_allgather(cs_par *p, double *a, int width);
/* Rank 0 gets every owned value. */
void cs_par_gather_root(cs_par *p, double *a, int width);

/* Global reductions, in place. */
void cs_par_sum(cs_par *p, double *a, int count);
void cs_par_sum_long(cs_par *p, long *a, int count);
void cs_par_max(cs_par *p, double *a, int count);
/* A sum and a maximum in one reduction (half the latency of two). */
void cs_par_sum_max(cs_par *p, double *sum, double *max);
/* Every rank's count items of size bytes, concatenated in rank order into
 * *out (malloc'd, *nout items); returns 0 or -1. */
int cs_par_allgather_items(cs_par *p, const void *items, int count, size_t size, void **out,
                           int *nout);

/* A collective: rank 0 gets every stage's slowest time and longest
 * communication, bytes and messages summed over ranks, and each rank's
 * totals (rank_comm, size entries). One rank copies its own. */
void cs_par_report(cs_par *p, const cs_stage_timing *timing, cs_stage_timing *timing_all,
                   cs_comm_stats *comm_all, cs_comm_stats *rank_comm);

/* Rank 0's value, on every rank. */
int cs_par_bcast_int(cs_par *p, int value);

/* Timing and byte counts of one stage's messages: cs_par_begin(p, stage)
 * before a stage's work charges what follows to it. */
static inline void cs_par_begin(cs_par *p, int stage) { p->stage = stage; }

#endif
