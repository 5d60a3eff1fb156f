/* par_one_rank.h: the part of MPI's interface par.c uses, for a build
 * without MPI (-DCLOTHSIM_WITH_MPI=OFF), which par.h includes instead of
 * <mpi.h>.
 *
 * Why a header and not a second par.c: par.c already runs one rank without
 * a single message whenever MPI is not initialised (a plain `clothsim run`),
 * so the same file, compiled against this header, is the build without MPI:
 * the partition, the loops over ranges and the reports stay one code, and
 * one rank behaves alike in both builds.
 *
 * Here MPI is never initialised: MPI_Initialized and MPI_Finalized say no,
 * and MPI_Init fails (there is nothing to start), so cs_parallel_init
 * returns false and every simulation is one rank; par.c makes no other MPI
 * call then. Should it, each call below does what it does for one process
 * alone: a reduction, gather or broadcast copies its own contribution, and
 * there is no other rank to send to. */
#ifndef CS_PAR_ONE_RANK_H
#define CS_PAR_ONE_RANK_H

#include <stddef.h>
#include <string.h>

typedef int MPI_Comm;
typedef int MPI_Op;
typedef int MPI_Request;
typedef int MPI_Info;
typedef size_t MPI_Datatype; /* the bytes of one item */
typedef struct MPI_Status {
    int unused;
} MPI_Status;
typedef void MPI_User_function(void *in, void *inout, int *len, MPI_Datatype *type);

enum { MPI_SUCCESS = 0, MPI_ERR_OTHER = 16 };
#define MPI_COMM_NULL 0
#define MPI_COMM_WORLD 1
#define MPI_COMM_SELF 2
#define MPI_OP_NULL 0
#define MPI_SUM 1
#define MPI_MAX 2
#define MPI_MIN 3
#define MPI_INFO_NULL 0
#define MPI_COMM_TYPE_SHARED 1
#define MPI_DOUBLE sizeof(double)
#define MPI_LONG sizeof(long)
#define MPI_INT sizeof(int)
#define MPI_BYTE ((size_t)1)
#define MPI_IN_PLACE ((void *)-1)
#define MPI_STATUSES_IGNORE ((MPI_Status *)0)

static inline int MPI_Initialized(int *flag)
{
    *flag = 0;
    return MPI_SUCCESS;
}

static inline int MPI_Finalized(int *flag)
{
    *flag = 0;
    return MPI_SUCCESS;
}

static inline int MPI_Init(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    return MPI_ERR_OTHER;
}

static inline int MPI_Finalize(void) { return MPI_SUCCESS; }

/* ------------------------------------------ one process alone, unused */

static inline MPI_Comm MPI_Comm_f2c(int handle) { return handle; }

static inline int MPI_Comm_dup(MPI_Comm comm, MPI_Comm *copy)
{
    *copy = comm;
    return MPI_SUCCESS;
}

static inline int MPI_Comm_split_type(MPI_Comm comm, int type, int key, MPI_Info info,
                                      MPI_Comm *part)
{
    (void)type, (void)key, (void)info;
    *part = comm;
    return MPI_SUCCESS;
}

static inline int MPI_Comm_free(MPI_Comm *comm)
{
    *comm = MPI_COMM_NULL;
    return MPI_SUCCESS;
}

static inline int MPI_Comm_rank(MPI_Comm comm, int *rank)
{
    (void)comm;
    *rank = 0;
    return MPI_SUCCESS;
}

static inline int MPI_Comm_size(MPI_Comm comm, int *size)
{
    (void)comm;
    *size = 1;
    return MPI_SUCCESS;
}

static inline int MPI_Op_create(MPI_User_function *fn, int commute, MPI_Op *op)
{
    (void)fn, (void)commute;
    *op = 1;
    return MPI_SUCCESS;
}

static inline int MPI_Op_free(MPI_Op *op)
{
    *op = MPI_OP_NULL;
    return MPI_SUCCESS;
}

/* One process's contribution to a collective: its own items, at offset
 * items of out. */
static inline int cs_one_rank_copy(const void *in, void *out, int offset, int count,
                                   MPI_Datatype type)
{
    char *to = (char *)out + (size_t)offset * type;
    if (in != MPI_IN_PLACE && in != to && count > 0)
        memcpy(to, in, (size_t)count * type);
    return MPI_SUCCESS;
}

static inline int MPI_Allreduce(const void *in, void *out, int count, MPI_Datatype type,
                                MPI_Op op, MPI_Comm comm)
{
    (void)op, (void)comm;
    return cs_one_rank_copy(in, out, 0, count, type);
}

static inline int MPI_Reduce(const void *in, void *out, int count, MPI_Datatype type, MPI_Op op,
                             int root, MPI_Comm comm)
{
    (void)op, (void)root, (void)comm;
    return cs_one_rank_copy(in, out, 0, count, type);
}

static inline int MPI_Bcast(void *buf, int count, MPI_Datatype type, int root, MPI_Comm comm)
{
    (void)buf, (void)count, (void)type, (void)root, (void)comm;
    return MPI_SUCCESS;
}

static inline int MPI_Allgather(const void *in, int count, MPI_Datatype type, void *out,
                                int out_count, MPI_Datatype out_type, MPI_Comm comm)
{
    (void)out_count, (void)out_type, (void)comm;
    return cs_one_rank_copy(in, out, 0, count, type);
}

static inline int MPI_Gather(const void *in, int count, MPI_Datatype type, void *out,
                             int out_count, MPI_Datatype out_type, int root, MPI_Comm comm)
{
    (void)out_count, (void)out_type, (void)root, (void)comm;
    return cs_one_rank_copy(in, out, 0, count, type);
}

static inline int MPI_Allgatherv(const void *in, int count, MPI_Datatype type, void *out,
                                 const int *counts, const int *displs, MPI_Datatype out_type,
                                 MPI_Comm comm)
{
    (void)counts, (void)out_type, (void)comm;
    return cs_one_rank_copy(in, out, displs[0], count, type);
}

static inline int MPI_Gatherv(const void *in, int count, MPI_Datatype type, void *out,
                              const int *counts, const int *displs, MPI_Datatype out_type,
                              int root, MPI_Comm comm)
{
    (void)counts, (void)out_type, (void)root, (void)comm;
    return cs_one_rank_copy(in, out, displs[0], count, type);
}

/* No other rank to send to or hear from. */
static inline int MPI_Isend(const void *buf, int count, MPI_Datatype type, int dest, int tag,
                            MPI_Comm comm, MPI_Request *request)
{
    (void)buf, (void)count, (void)type, (void)dest, (void)tag, (void)comm;
    *request = 0;
    return MPI_ERR_OTHER;
}

static inline int MPI_Irecv(void *buf, int count, MPI_Datatype type, int source, int tag,
                            MPI_Comm comm, MPI_Request *request)
{
    (void)buf, (void)count, (void)type, (void)source, (void)tag, (void)comm;
    *request = 0;
    return MPI_ERR_OTHER;
}

static inline int MPI_Waitall(int count, MPI_Request *requests, MPI_Status *statuses)
{
    (void)count, (void)requests, (void)statuses;
    return MPI_SUCCESS;
}

#endif
