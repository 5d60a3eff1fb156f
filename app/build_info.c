/* build_info.c: which optional parts this build has. CMake defines
 * CS_WITH_<PART> as 1 or 0 for this file alone (the top CMakeLists.txt),
 * the one place of app/ that asks; elsewhere a part that is off is a
 * stand-in file that says so where the part is needed. */
#include "app/build_info.h"

#include "app/exit.h"
#include "common/error.h"

#include <stdbool.h>
#include <stdlib.h>

static const struct {
    const char *name;
    bool have;
} PARTS[] = {
    {"MPI", CS_WITH_MPI},         {"assimp", CS_WITH_ASSIMP}, {"OpenVDB", CS_WITH_OPENVDB},
    {"Embree", CS_WITH_EMBREE},   {"OSMesa", CS_WITH_OSMESA}, {"HDF5", CS_WITH_HDF5},
    {"PLplot", CS_WITH_PLPLOT},
};
#define NPARTS ((int)(sizeof PARTS / sizeof PARTS[0]))

void cs_build_print_parts(FILE *out)
{
    for (int have = 1; have >= 0; have--) {
        fputs(have ? "with:" : "without:", out);
        int n = 0;
        for (int i = 0; i < NPARTS; i++)
            if (PARTS[i].have == have)
                fprintf(out, "%s %s", n++ ? "," : "", PARTS[i].name);
        fputs(n ? "\n" : " none\n", out);
    }
}

/* The ranks a launcher started: Open MPI's mpirun, PMI (MPICH, Slurm). */
static long launched_ranks(void)
{
    const char *names[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"};
    for (int i = 0; i < 2; i++) {
        const char *v = getenv(names[i]);
        if (v && *v)
            return strtol(v, NULL, 10);
    }
    return 1;
}

int cs_build_check_ranks(void)
{
    long ranks = launched_ranks();
    if (CS_WITH_MPI || ranks <= 1)
        return 0;
    fprintf(stderr, "clothsim: started as one of %ld ranks, but %s\n", ranks,
            CS_MISSING_PART("MPI", "a run on several ranks needs it", "CLOTHSIM_WITH_MPI"));
    return CS_EXIT_OUTPUT;
}
