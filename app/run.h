/* run.h: the `clothsim run` command. */
#ifndef CS_APP_RUN_H
#define CS_APP_RUN_H

#include <stdio.h>

#include "app/exit.h"

/* argv[0] is "run"; returns the exit status. */
int cs_run_main(int argc, char **argv);

void cs_run_help(FILE *out);

#endif
