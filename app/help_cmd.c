/* help_cmd.c: `clothsim help scene [--markdown]`: every key of a scene file,
 * printed from the table the loader is made from (import/scene_keys.def). */
#include "app/help_cmd.h"

#include <stdio.h>
#include <string.h>

#include "app/run.h"
#include "import/import.h"

int cs_help_scene_main(int argc, char **argv)
{
    bool markdown = argc == 2 && strcmp(argv[1], "--markdown") == 0;
    if (argc > 2 || (argc == 2 && !markdown)) {
        fprintf(stderr,
                "clothsim help scene: unknown option '%s'\n"
                "usage: clothsim help scene [--markdown]\n",
                argv[1]);
        return CS_EXIT_USAGE;
    }
    cs_scene_reference(stdout, markdown);
    return fflush(stdout) == 0 ? CS_EXIT_OK : CS_EXIT_OUTPUT;
}
