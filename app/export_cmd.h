/* export_cmd.h: `clothsim export DIR`: a run folder's frames as
 * DIR/cloth.usda or Blender point caches (app/export.h). */
#ifndef CS_APP_EXPORT_CMD_H
#define CS_APP_EXPORT_CMD_H

#include <stdio.h>

int cs_export_main(int argc, char **argv);
void cs_export_help(FILE *out);

#endif
