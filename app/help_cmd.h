/* help_cmd.h: `clothsim help scene [--markdown]`. */
#ifndef CS_HELP_CMD_H
#define CS_HELP_CMD_H

/* argv[0] is "scene". Prints the scene file reference (import.h's
 * cs_scene_reference); --markdown: docs/scene-reference.md's tables. Exit
 * status. */
int cs_help_scene_main(int argc, char **argv);

#endif
