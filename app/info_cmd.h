/* info_cmd.h: `clothsim info DIR`: a run folder's frames as a table
 * (time, status, intersecting pairs, energy, speed) and DIR/info.png. */
#ifndef CS_APP_INFO_CMD_H
#define CS_APP_INFO_CMD_H

#include <stdio.h>

int cs_info_main(int argc, char **argv);
void cs_info_help(FILE *out);

#endif
