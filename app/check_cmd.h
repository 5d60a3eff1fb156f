/* check_cmd.h: `clothsim check SCENE`: the problems of a scene's initial
 * state listed, and with --fix lifted out of the bodies (input_check.h). */
#ifndef CS_APP_CHECK_CMD_H
#define CS_APP_CHECK_CMD_H

#include <stdio.h>

/* argv[0] is "check"; returns the exit status (0 no error, 1 errors that
 * `run` refuses, 2 bad input, 4 out of memory or a file not written). */
int cs_check_main(int argc, char **argv);
void cs_check_help(FILE *out);

#endif
