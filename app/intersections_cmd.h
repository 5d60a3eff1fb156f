/* intersections_cmd.h: the `clothsim intersections MESHFILE` command. */
#ifndef CS_APP_INTERSECTIONS_CMD_H
#define CS_APP_INTERSECTIONS_CMD_H

#include <stdio.h>

/* argv[0] is "intersections"; returns the exit status: 0 no intersecting
 * pair, 1 some, 2 bad input or command line, 4 out of memory. */
int cs_intersections_main(int argc, char **argv);

void cs_intersections_help(FILE *out);

#endif
