/* run.h: the `clothsim run` command. */
#ifndef CS_APP_RUN_H
#define CS_APP_RUN_H

#include <stdio.h>

/* Exit statuses of the command line. */
enum {
    CS_EXIT_OK = 0,
    CS_EXIT_USAGE = 1,        /* bad command line */
    CS_EXIT_INPUT = 2,        /* the scene file or its definition is invalid */
    CS_EXIT_UNSTABLE = 3,     /* the simulation blew up; earlier frames kept */
    CS_EXIT_OUTPUT = 4,       /* output could not be written, or out of memory */
    CS_EXIT_INTERRUPTED = 130 /* SIGINT or SIGTERM; earlier frames kept */
};

/* argv[0] is "run"; returns the exit status. */
int cs_run_main(int argc, char **argv);

void cs_run_help(FILE *out);

#endif
