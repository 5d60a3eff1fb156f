/* par.c: the partition, ghost exchange and reductions of Section 7; the
 * one file of the project that calls MPI. */
#include "sim/par.h"

#include "sim/internal.h"
#include "common/util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <omp.h>

/* Charges a communication to the current stage. */
static void charge(cs_par *p, double t0, long bytes, long messages)
{
    cs_comm_stats *c = p->stats + p->stage;
    c->seconds += cs_now() - t0;
    c->bytes += bytes;
    c->messages += messages;
}

/* ------------------------------------------------------------ partition */

typedef struct keyed {
    double key;
    int id;
} keyed;

static int cmp_keyed(const void *a, const void *b)
{
    const keyed *p = a, *q = b;
    if (p->key != q->key)
        return p->key < q->key ? -1 : 1;
    return (p->id > q->id) - (p->id < q->id); /* ties by index: the same on every rank */
}

/* Splits ids[0..n) into parts groups owned by ranks first.. along the
 * widest axis of their box, the split proportional to the parts each
 * side gets (so 3 ranks get thirds, not a half and two quarters). */
static void split(const double *x, keyed *k, int *ids, int n, int parts, int first, int *owner)
{
    if (parts <= 1 || n == 0) {
        for (int i = 0; i < n; i++)
            owner[ids[i]] = first;
        return;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < n; i++)
        for (int d = 0; d < 3; d++) {
            double c = x[3 * ids[i] + d];
            lo[d] = c < lo[d] ? c : lo[d];
            hi[d] = c > hi[d] ? c : hi[d];
        }
    int axis = 0;
    for (int d = 1; d < 3; d++)
        if (hi[d] - lo[d] > hi[axis] - lo[axis])
            axis = d;
    for (int i = 0; i < n; i++) {
        k[i].key = x[3 * ids[i] + axis];
        k[i].id = ids[i];
    }
    qsort(k, (size_t)n, sizeof *k, cmp_keyed);
    for (int i = 0; i < n; i++)
        ids[i] = k[i].id;
    int left = parts / 2;
    int cut = (int)((long long)n * left / parts);
    split(x, k, ids, cut, left, first, owner);
    split(x, k, ids + cut, n - cut, parts - left, first + left, owner);
}

void cs_par_median_split(int n, const double *x, int parts, int *owner)
{
    int *ids = malloc(sizeof *ids * ((size_t)n + 1));
    keyed *k = malloc(sizeof *k * ((size_t)n + 1));
    if (!ids || !k) { /* no memory: contiguous blocks, still a partition */
        for (int i = 0; i < n; i++)
            owner[i] = (int)((long long)i * parts / (n > 0 ? n : 1));
    } else {
        for (int i = 0; i < n; i++)
            ids[i] = i;
        split(x, k, ids, n, parts, 0, owner);
    }
    free(ids);
    free(k);
}

/* Ranges [lo, hi) of the particles with mark[i] set. */
static int *ranges_of(const unsigned char *mark, int n, int *nranges)
{
    int count = 0;
    for (int i = 0; i < n; i++)
        count += mark[i] && (i == 0 || !mark[i - 1]);
    int *r = malloc(sizeof *r * (2 * (size_t)count + 2));
    if (!r)
        return NULL;
    int k = 0;
    for (int i = 0; i < n; i++) {
        if (mark[i] && (i == 0 || !mark[i - 1]))
            r[2 * k] = i;
        if (mark[i] && (i == n - 1 || !mark[i + 1]))
            r[2 * k++ + 1] = i + 1;
    }
    *nranges = count;
    return r;
}

/* Builds h from (other rank, particle) entries for what this rank sends
 * and what it receives, each sorted and made unique here. */
static int halo_build(const cs_par *p, int nsend, int *send, int nrecv, int *recv, cs_halo *h)
{
    memset(h, 0, sizeof *h);
    int *lists[2] = {send, recv}, counts[2] = {nsend, nrecv};
    for (int s = 0; s < 2; s++) {
        counts[s] = cs_sort_unique_pairs(lists[s], counts[s]);
    }
    int *per_rank = calloc((size_t)p->size * 2 + 2, sizeof *per_rank);
    if (!per_rank)
        return -1;
    for (int s = 0; s < 2; s++)
        for (int k = 0; k < counts[s]; k++)
            per_rank[2 * lists[s][2 * k] + s]++;
    for (int r = 0; r < p->size; r++)
        h->nlinks += per_rank[2 * r] + per_rank[2 * r + 1] > 0;
    h->link = calloc((size_t)h->nlinks + 1, sizeof *h->link);
    if (!h->link) {
        free(per_rank);
        return -1;
    }
    int l = 0, at[2] = {0, 0};
    for (int r = 0; r < p->size; r++) {
        if (per_rank[2 * r] + per_rank[2 * r + 1] == 0)
            continue;
        cs_halo_link *link = h->link + l++;
        link->rank = r;
        link->nsend = per_rank[2 * r];
        link->nrecv = per_rank[2 * r + 1];
        link->send = malloc(sizeof(int) * ((size_t)link->nsend + 1));
        link->recv = malloc(sizeof(int) * ((size_t)link->nrecv + 1));
        if (!link->send || !link->recv) {
            free(per_rank);
            cs_halo_free(h);
            return -1;
        }
        for (int k = 0; k < link->nsend; k++)
            link->send[k] = lists[0][2 * at[0]++ + 1];
        for (int k = 0; k < link->nrecv; k++)
            link->recv[k] = lists[1][2 * at[1]++ + 1];
    }
    free(per_rank);
    return 0;
}

void cs_halo_free(cs_halo *h)
{
    for (int l = 0; l < h->nlinks && h->link; l++) {
        free(h->link[l].send);
        free(h->link[l].recv);
    }
    free(h->link);
    memset(h, 0, sizeof *h);
}

int cs_halo_from_needs(const cs_par *p, int nneeds, const int *user, const int *particle,
                       cs_halo *h)
{
    int *send = malloc(sizeof(int) * (2 * (size_t)nneeds + 2));
    int *recv = malloc(sizeof(int) * (2 * (size_t)nneeds + 2));
    int ns = 0, nr = 0, rc = -1;
    if (send && recv) {
        for (int k = 0; k < nneeds; k++) {
            int i = particle[k], owner = p->owner[i];
            if (owner == user[k])
                continue;
            if (owner == p->rank) {
                send[2 * ns] = user[k];
                send[2 * ns++ + 1] = i;
            } else if (user[k] == p->rank) {
                recv[2 * nr] = owner;
                recv[2 * nr++ + 1] = i;
            }
        }
        rc = halo_build(p, ns, send, nr, recv, h);
    }
    free(send);
    free(recv);
    return rc;
}

/* The MPI communicator a cs_comm names (MPI initialised). */
static MPI_Comm mpi_comm(cs_comm comm)
{
    switch (comm) {
    case CS_COMM_WORLD:
        return MPI_COMM_WORLD;
    case CS_COMM_SELF:
        return MPI_COMM_SELF;
    case CS_COMM_NONE:
        return MPI_COMM_NULL;
    default:
        return comm >= 0 ? MPI_Comm_f2c(comm) : MPI_COMM_NULL;
    }
}

cs_par *cs_par_create(cs_comm handle, int n, const double *x, int nsprings, const int *ends)
{
    cs_par *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    p->n = n;
    p->size = 1;
    int initialised = 0, finalised = 0;
    MPI_Initialized(&initialised);
    MPI_Finalized(&finalised);
    p->comm = MPI_COMM_NULL;
    p->sum_max = MPI_OP_NULL;
    MPI_Comm comm = initialised && !finalised ? mpi_comm(handle) : MPI_COMM_NULL;
    if (comm != MPI_COMM_NULL) {
        /* our own communicator: the simulation's messages never match the
         * caller's */
        if (MPI_Comm_dup(comm, &p->comm) != MPI_SUCCESS) {
            free(p);
            return NULL;
        }
        p->mpi = true;
        MPI_Comm_rank(p->comm, &p->rank);
        MPI_Comm_size(p->comm, &p->size);
    }
    p->owner = calloc((size_t)n + 1, sizeof *p->owner);
    unsigned char *mark = calloc((size_t)n + 1, 1);
    int *send = NULL, *recv = NULL;
    if (!p->owner || !mark)
        goto fail;
    if (p->size > 1)
        cs_par_median_split(n, x, p->size, p->owner);
    for (int i = 0; i < n; i++)
        mark[i] = p->owner[i] == p->rank;
    if (!(p->own = ranges_of(mark, n, &p->nown)))
        goto fail;

    /* ghosts: the far ends of springs with one end here */
    send = malloc(sizeof(int) * (4 * (size_t)nsprings + 2));
    recv = malloc(sizeof(int) * (4 * (size_t)nsprings + 2));
    if (!send || !recv)
        goto fail;
    int ns = 0, nr = 0;
    for (int s = 0; s < nsprings && p->size > 1; s++) {
        int i = ends[2 * s], j = ends[2 * s + 1];
        int oi = p->owner[i], oj = p->owner[j];
        if (oi == oj || (oi != p->rank && oj != p->rank))
            continue;
        int mine = oi == p->rank ? i : j, theirs = oi == p->rank ? j : i;
        int other = oi == p->rank ? oj : oi;
        send[2 * ns] = other;
        send[2 * ns++ + 1] = mine;
        recv[2 * nr] = other;
        recv[2 * nr++ + 1] = theirs;
        mark[theirs] = 1;
    }
    if (halo_build(p, ns, send, nr, recv, &p->ghosts))
        goto fail;
    if (!(p->local = ranges_of(mark, n, &p->nlocal)))
        goto fail;

    p->order = malloc(sizeof *p->order * ((size_t)n + 1));
    p->counts = calloc((size_t)p->size + 1, sizeof *p->counts);
    p->displs = calloc((size_t)p->size + 1, sizeof *p->displs);
    p->buffer_size = 3 * (size_t)n + 3;
    p->buffer = malloc(sizeof *p->buffer * p->buffer_size);
    p->requests = malloc(sizeof *p->requests * (2 * (size_t)p->size + 2));
    if (!p->order || !p->counts || !p->displs || !p->buffer || !p->requests)
        goto fail;
    for (int i = 0; i < n; i++)
        p->counts[p->owner[i]]++;
    for (int r = 1; r < p->size; r++)
        p->displs[r] = p->displs[r - 1] + p->counts[r - 1];
    int *at = calloc((size_t)p->size + 1, sizeof *at);
    if (!at)
        goto fail;
    for (int i = 0; i < n; i++)
        p->order[p->displs[p->owner[i]] + at[p->owner[i]]++] = i;
    free(at);
    p->nowned = p->counts[p->rank];
    p->bytes = sizeof(int) * (3 * (size_t)n + 2 * (size_t)(p->nown + p->nlocal)) +
               sizeof(double) * p->buffer_size;
    for (int l = 0; l < p->ghosts.nlinks; l++)
        p->bytes += sizeof(int) * (size_t)(p->ghosts.link[l].nsend + p->ghosts.link[l].nrecv);
    free(mark);
    free(send);
    free(recv);
    return p;
fail:
    free(mark);
    free(send);
    free(recv);
    cs_par_destroy(p);
    return NULL;
}

void cs_par_destroy(cs_par *p)
{
    if (!p)
        return;
    cs_halo_free(&p->ghosts);
    if (p->mpi && p->comm != MPI_COMM_NULL) {
        int finalised = 0;
        MPI_Finalized(&finalised);
        if (!finalised) {
            MPI_Comm_free(&p->comm);
            if (p->sum_max != MPI_OP_NULL)
                MPI_Op_free(&p->sum_max);
        }
    }
    free(p->owner);
    free(p->own);
    free(p->local);
    free(p->order);
    free(p->counts);
    free(p->displs);
    free(p->buffer);
    free(p->requests);
    free(p);
}

/* ------------------------------------------------------------- exchange */

static double *buffer(cs_par *p, size_t count)
{
    if (count > p->buffer_size) {
        double *b = realloc(p->buffer, sizeof *b * count);
        if (!b)
            abort(); /* a halo larger than 3 n doubles: cannot happen */
        p->buffer = b;
        p->buffer_size = count;
    }
    return p->buffer;
}

/* Sends a[out[k]] to each link and writes what arrives into a[in[k]];
 * forward sends send[] and receives recv[], reverse the other way. */
static void exchange(cs_par *p, const cs_halo *h, double *a, int width, bool reverse)
{
    if (!p->mpi || h->nlinks == 0)
        return;
    double t0 = cs_now();
    size_t total = 0;
    for (int l = 0; l < h->nlinks; l++)
        total += (size_t)(h->link[l].nsend + h->link[l].nrecv) * (size_t)width;
    double *buf = buffer(p, total + 1);
    long bytes = 0, messages = 0;
    int nreq = 0;
    size_t at = 0;
    for (int l = 0; l < h->nlinks; l++) { /* receives first */
        const cs_halo_link *k = h->link + l;
        int count = (reverse ? k->nsend : k->nrecv) * width;
        if (count > 0)
            MPI_Irecv(buf + at, count, MPI_DOUBLE, k->rank, 7, p->comm, p->requests + nreq++);
        at += (size_t)count;
    }
    for (int l = 0; l < h->nlinks; l++) {
        const cs_halo_link *k = h->link + l;
        int nout = reverse ? k->nrecv : k->nsend;
        const int *out = reverse ? k->recv : k->send;
        for (int j = 0; j < nout; j++)
            memcpy(buf + at + (size_t)j * width, a + (size_t)width * out[j],
                   sizeof *a * (size_t)width);
        if (nout > 0) {
            MPI_Isend(buf + at, nout * width, MPI_DOUBLE, k->rank, 7, p->comm,
                      p->requests + nreq++);
            bytes += (long)sizeof(double) * nout * width;
            messages++;
        }
        at += (size_t)nout * width;
    }
    MPI_Waitall(nreq, p->requests, MPI_STATUSES_IGNORE);
    at = 0;
    for (int l = 0; l < h->nlinks; l++) {
        const cs_halo_link *k = h->link + l;
        int nin = reverse ? k->nsend : k->nrecv;
        const int *in = reverse ? k->send : k->recv;
        for (int j = 0; j < nin; j++)
            memcpy(a + (size_t)width * in[j], buf + at + (size_t)j * width,
                   sizeof *a * (size_t)width);
        at += (size_t)nin * width;
    }
    charge(p, t0, bytes, messages);
}

void cs_halo_forward(cs_par *p, const cs_halo *h, double *a, int width)
{
    exchange(p, h, a, width, false);
}

void cs_halo_reverse(cs_par *p, const cs_halo *h, double *a, int width)
{
    exchange(p, h, a, width, true);
}

/* Packs owned values in order; unpacks all into a. */
static void gather(cs_par *p, double *a, int width, bool to_all)
{
    if (!cs_par_distributed(p))
        return;
    double t0 = cs_now();
    double *buf = buffer(p, (size_t)width * (size_t)p->n + (size_t)width * p->nowned + 1);
    double *mine = buf + (size_t)width * (size_t)p->n;
    const int *ids = p->order + p->displs[p->rank];
    for (int k = 0; k < p->nowned; k++)
        memcpy(mine + (size_t)width * k, a + (size_t)width * ids[k], sizeof *a * (size_t)width);
    int *counts = malloc(sizeof *counts * 2 * ((size_t)p->size + 1));
    if (!counts)
        abort();
    int *displs = counts + p->size + 1;
    for (int r = 0; r < p->size; r++) {
        counts[r] = width * p->counts[r];
        displs[r] = width * p->displs[r];
    }
    if (to_all)
        MPI_Allgatherv(mine, width * p->nowned, MPI_DOUBLE, buf, counts, displs, MPI_DOUBLE,
                       p->comm);
    else
        MPI_Gatherv(mine, width * p->nowned, MPI_DOUBLE, buf, counts, displs, MPI_DOUBLE, 0,
                    p->comm);
    free(counts);
    if (to_all || p->rank == 0)
        for (int k = 0; k < p->n; k++)
            memcpy(a + (size_t)width * p->order[k], buf + (size_t)width * k,
                   sizeof *a * (size_t)width);
    /* counted as the sends this rank makes: its owned values to each other
     * rank (all) or to rank 0 */
    long out = to_all ? p->size - 1 : (p->rank != 0);
    charge(p, t0, out * (long)sizeof(double) * width * p->nowned, out);
}

void cs_par_allgather(cs_par *p, double *a, int width) { gather(p, a, width, true); }
void cs_par_gather_root(cs_par *p, double *a, int width) { gather(p, a, width, false); }

static void reduce(cs_par *p, void *a, int count, MPI_Datatype type, MPI_Op op, size_t size)
{
    if (!cs_par_distributed(p))
        return;
    double t0 = cs_now();
    MPI_Allreduce(MPI_IN_PLACE, a, count, type, op, p->comm);
    charge(p, t0, (long)size * count, 1);
}

void cs_par_sum(cs_par *p, double *a, int count)
{
    reduce(p, a, count, MPI_DOUBLE, MPI_SUM, sizeof *a);
}

void cs_par_sum_long(cs_par *p, long *a, int count)
{
    reduce(p, a, count, MPI_LONG, MPI_SUM, sizeof *a);
}

void cs_par_max(cs_par *p, double *a, int count)
{
    reduce(p, a, count, MPI_DOUBLE, MPI_MAX, sizeof *a);
}

int cs_par_allgather_items(cs_par *p, const void *items, int count, size_t size, void **out,
                           int *nout)
{
    *out = NULL;
    *nout = 0;
    if (!cs_par_distributed(p)) {
        void *copy = malloc(size * (size_t)count + 1);
        if (!copy)
            return -1;
        if (count > 0)
            memcpy(copy, items, size * (size_t)count);
        *out = copy;
        *nout = count;
        return 0;
    }
    double t0 = cs_now();
    int *counts = malloc(sizeof *counts * 2 * ((size_t)p->size + 1));
    if (!counts)
        return -1;
    int *displs = counts + p->size + 1;
    int bytes = (int)(size * (size_t)count);
    MPI_Allgather(&bytes, 1, MPI_INT, counts, 1, MPI_INT, p->comm);
    long total = 0;
    for (int r = 0; r < p->size; r++) {
        displs[r] = (int)total;
        total += counts[r];
    }
    char *all = malloc((size_t)total + 1);
    int ok = all != NULL, all_ok = 0;
    MPI_Allreduce(&ok, &all_ok, 1, MPI_INT, MPI_MIN, p->comm);
    if (!all_ok) {
        free(all);
        free(counts);
        return -1;
    }
    MPI_Allgatherv(items, bytes, MPI_BYTE, all, counts, displs, MPI_BYTE, p->comm);
    free(counts);
    *out = all;
    *nout = (int)(total / (long)size);
    charge(p, t0, (long)(p->size - 1) * (bytes + (long)sizeof(int)), 2L * (p->size - 1));
    return 0;
}

void cs_par_report(cs_par *p, const cs_stage_timing *timing, cs_stage_timing *timing_all,
                   cs_comm_stats *comm_all, cs_comm_stats *rank_comm)
{
    cs_comm_stats total = {0, 0, 0};
    for (int s = 0; s < CS_STAGE_COUNT; s++) {
        total.seconds += p->stats[s].seconds;
        total.bytes += p->stats[s].bytes;
        total.messages += p->stats[s].messages;
    }
    if (!cs_par_distributed(p)) {
        memcpy(timing_all, timing, sizeof *timing * CS_STAGE_COUNT);
        memcpy(comm_all, p->stats, sizeof *comm_all * CS_STAGE_COUNT);
        rank_comm[0] = total;
        return;
    }
    /* not charged to any stage: this is the report, not the simulation */
    double seconds[2 * CS_STAGE_COUNT], seconds_max[2 * CS_STAGE_COUNT];
    long counts[2 * CS_STAGE_COUNT], counts_sum[2 * CS_STAGE_COUNT];
    for (int s = 0; s < CS_STAGE_COUNT; s++) {
        seconds[s] = timing[s].seconds;
        seconds[CS_STAGE_COUNT + s] = p->stats[s].seconds;
        counts[s] = p->stats[s].bytes;
        counts[CS_STAGE_COUNT + s] = p->stats[s].messages;
    }
    MPI_Reduce(seconds, seconds_max, 2 * CS_STAGE_COUNT, MPI_DOUBLE, MPI_MAX, 0, p->comm);
    MPI_Reduce(counts, counts_sum, 2 * CS_STAGE_COUNT, MPI_LONG, MPI_SUM, 0, p->comm);
    double mine[3] = {total.seconds, (double)total.bytes, (double)total.messages};
    double *all = p->rank == 0 ? malloc(sizeof *all * 3 * (size_t)p->size) : NULL;
    MPI_Gather(mine, 3, MPI_DOUBLE, all, 3, MPI_DOUBLE, 0, p->comm);
    if (p->rank != 0)
        return;
    for (int s = 0; s < CS_STAGE_COUNT; s++) {
        timing_all[s].seconds = seconds_max[s];
        timing_all[s].calls = timing[s].calls;
        comm_all[s].seconds = seconds_max[CS_STAGE_COUNT + s];
        comm_all[s].bytes = counts_sum[s];
        comm_all[s].messages = counts_sum[CS_STAGE_COUNT + s];
    }
    for (int r = 0; all && r < p->size; r++) {
        rank_comm[r].seconds = all[3 * r];
        rank_comm[r].bytes = (long)all[3 * r + 1];
        rank_comm[r].messages = (long)all[3 * r + 2];
    }
    free(all);
}

int cs_par_bcast_int(cs_par *p, int value)
{
    if (cs_par_distributed(p))
        MPI_Bcast(&value, 1, MPI_INT, 0, p->comm);
    return value;
}

/* A launcher's variables: Open MPI's mpirun, PMI (MPICH, Slurm), PMIx. */
static bool launched_by_mpi(void)
{
    const char *force = getenv("CLOTHSIM_MPI");
    if (force && *force)
        return strcmp(force, "0") != 0;
    return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMI_SIZE") || getenv("PMIX_RANK");
}

bool cs_parallel_init(int *argc, char ***argv)
{
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (initialised)
        return true;
    if (!launched_by_mpi())
        return false;
    return MPI_Init(argc, argv) == MPI_SUCCESS;
}

void cs_parallel_finalize(void)
{
    int initialised = 0, finalised = 0;
    MPI_Initialized(&initialised);
    MPI_Finalized(&finalised);
    if (initialised && !finalised)
        MPI_Finalize();
}

int cs_parallel_set_threads(int n)
{
    if (n <= 0) {
        const char *env = getenv("OMP_NUM_THREADS");
        if (env && *env)
            return omp_get_max_threads(); /* the user's choice, read by libgomp */
        int local = 1, initialised = 0, finalised = 0;
        MPI_Initialized(&initialised);
        MPI_Finalized(&finalised);
        if (initialised && !finalised) { /* ranks sharing this machine */
            MPI_Comm node;
            if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL,
                                    &node) == MPI_SUCCESS) {
                MPI_Comm_size(node, &local);
                MPI_Comm_free(&node);
            }
        }
        /* omp_get_num_procs counts the cores of the affinity mask (a rank
         * mpirun bound to one core sees one); unbound ranks share them */
        n = omp_get_num_procs() / local;
        if (n < 1)
            n = 1;
    }
    omp_set_num_threads(n);
    return n;
}

int cs_parallel_threads(void) { return omp_get_max_threads(); }

int cs_parallel_rank(void)
{
    int initialised = 0, finalised = 0, rank = 0;
    MPI_Initialized(&initialised);
    MPI_Finalized(&finalised);
    if (initialised && !finalised)
        MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    return rank;
}

/* [sum, max] pairs: one reduction where CG needs both */
static void sum_max_op(void *in, void *inout, int *len, MPI_Datatype *type)
{
    (void)type;
    const double *a = in;
    double *b = inout;
    for (int k = 0; k + 1 < *len; k += 2) {
        b[k] += a[k];
        b[k + 1] = a[k + 1] > b[k + 1] ? a[k + 1] : b[k + 1];
    }
}

void cs_par_sum_max(cs_par *p, double *sum, double *max)
{
    if (!cs_par_distributed(p))
        return;
    double t0 = cs_now();
    if (p->sum_max == MPI_OP_NULL)
        MPI_Op_create(sum_max_op, 1, &p->sum_max);
    double pair[2] = {*sum, *max};
    MPI_Allreduce(MPI_IN_PLACE, pair, 2, MPI_DOUBLE, p->sum_max, p->comm);
    *sum = pair[0];
    *max = pair[1];
    charge(p, t0, (long)sizeof pair, 1);
}
