/* render_cmd.h: the `clothsim render` command. */
#ifndef CS_APP_RENDER_CMD_H
#define CS_APP_RENDER_CMD_H

#include <stdio.h>

/* argv[0] is "render"; returns the exit status (see app/run.h). */
int cs_render_main(int argc, char **argv);

void cs_render_help(FILE *out);

#endif
