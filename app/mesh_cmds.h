/* mesh_cmds.h: `clothsim mesh-info` and `clothsim levelset`, the mesh
 * import and level-set conversion outside any scene. */
#ifndef CS_APP_MESH_CMDS_H
#define CS_APP_MESH_CMDS_H

#include <stdio.h>

/* argv[0] is the command's name; return the exit status (app/run.h). */
int cs_mesh_info_main(int argc, char **argv);
void cs_mesh_info_help(FILE *out);
int cs_levelset_main(int argc, char **argv);
void cs_levelset_help(FILE *out);

#endif
