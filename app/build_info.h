/* build_info.h: the optional parts this build was made with (CMake's
 * CLOTHSIM_WITH_* options, docs/building.md). */
#ifndef CS_APP_BUILD_INFO_H
#define CS_APP_BUILD_INFO_H

#include <stdio.h>

/* Two lines: "with: MPI, assimp, ..." and "without: ..." ("none" for an
 * empty list), for `clothsim --version`. */
void cs_build_print_parts(FILE *out);

/* Before a command that can span ranks: 0, or in a build without MPI that
 * a launcher (mpirun, srun) started as one of several ranks, which it
 * cannot join into one run, says so on stderr and returns exit status 4. */
int cs_build_check_ranks(void);

#endif
