/* checkpoint_none.c: checkpoint.h's state file in a build without HDF5
 * (-DCLOTHSIM_WITH_HDF5=OFF), in place of checkpoint.c: a run keeps no
 * state.h5 (summary.json names none) and --resume is refused with this
 * sentence, exit status 4. The hashes (run_identity.c) are as in any
 * build. */
#include "app/checkpoint.h"

#include "app/exit.h"
#include "common/error.h"

#include <stdio.h>
#include <string.h>

const char *cs_checkpoint_file_name(void) { return NULL; }

int cs_checkpoint_write(const char *path, const cs_run_identity *id, int frame,
                        const char *state_hash, cs_sim *sim, const double *totals, char *err,
                        size_t errlen)
{
    (void)path, (void)id, (void)frame, (void)state_hash, (void)sim, (void)totals;
    (void)err, (void)errlen;
    return 0;
}

int cs_checkpoint_read(const char *path, const cs_run_identity *id, cs_sim *sim, int *frame,
                       double *totals, char *err, size_t errlen)
{
    (void)path, (void)id, (void)sim, (void)totals;
    *frame = 0;
    snprintf(err, errlen, "%s",
             CS_MISSING_PART("HDF5", "--resume and checkpoints need it", "CLOTHSIM_WITH_HDF5"));
    return CS_EXIT_OUTPUT;
}

int cs_checkpoint_read_start(const char *path, cs_start_state *st, char *err, size_t errlen)
{
    (void)path;
    memset(st, 0, sizeof *st);
    snprintf(err, errlen, "%s",
             CS_MISSING_PART("HDF5", "--start-from reads a run's state.h5", "CLOTHSIM_WITH_HDF5"));
    return CS_EXIT_OUTPUT;
}

void cs_start_state_free(cs_start_state *st)
{
    (void)st;
}
