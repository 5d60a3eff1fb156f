/* exit.h: the exit statuses the command line documents (README.md,
 * docs/reliability.md) and the one mapping from a cs_status to them. */
#ifndef CS_APP_EXIT_H
#define CS_APP_EXIT_H

#include "common/error.h"

enum {
    CS_EXIT_OK = 0,
    CS_EXIT_USAGE = 1,        /* bad command line */
    CS_EXIT_INPUT = 2,        /* the scene file or its definition is invalid */
    CS_EXIT_UNSTABLE = 3,     /* the simulation blew up; earlier frames kept */
    CS_EXIT_OUTPUT = 4,       /* output could not be written, out of memory, or a
                                 part this build is without (docs/building.md) */
    CS_EXIT_INTERRUPTED = 130 /* SIGINT or SIGTERM; earlier frames kept */
};

/* What a command that failed with status exits with: bad input or an
 * invalid definition 2, a simulation that blew up or could not follow its
 * scripts 3, no memory or a failed engine or file 4 (CS_ERR_FAILED: also
 * a library this build is without). */
int cs_exit_status(int status);

#endif
