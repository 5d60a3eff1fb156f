/* main.c: the clothsim command line: `clothsim COMMAND [options]`.
 *
 * Only dispatch lives here; each command has its own file (run.c).
 */
#include "app/run.h"
#include "sim/sim.h"
#include "app/mesh_cmds.h"
#include "app/render_cmd.h"
#include "app/intersections_cmd.h"

#include <stdio.h>
#include <string.h>

#ifndef CS_VERSION
#define CS_VERSION "unknown"
#endif

static void usage(FILE *out)
{
    fputs("usage: clothsim COMMAND [options]\n"
          "\n"
          "commands:\n"
          "  run SCENE        simulate a scene file and write a mesh file per frame\n"
          "  render TARGET    render a run's frames (or a scene's start) to PNG images\n"
          "  intersections MESHFILE  count intersecting triangle pairs (exact)\n"
          "  mesh-info FILE   what import sees in a mesh file\n"
          "  levelset FILE -o OUT.vdb  convert a mesh to a signed distance grid (OpenVDB)\n"
          "  help [COMMAND]   show help, for a command if one is named\n"
          "\n"
          "options:\n"
          "  -h, --help       show this help\n"
          "  -V, --version    show the version\n"
          "\n"
          "'clothsim help run' (or 'clothsim run --help') explains the run command.\n",
          out);
}

static int help_main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stdout);
        return CS_EXIT_OK;
    }
    if (argc > 2) {
        fprintf(stderr, "clothsim help: one command at a time\n");
        usage(stderr);
        return CS_EXIT_USAGE;
    }
    if (strcmp(argv[1], "run") == 0) {
        cs_run_help(stdout);
        return CS_EXIT_OK;
    }
    if (strcmp(argv[1], "intersections") == 0) {
        cs_intersections_help(stdout);
        return CS_EXIT_OK;
    }
    if (strcmp(argv[1], "render") == 0) {
        cs_render_help(stdout);
        return CS_EXIT_OK;
    }
    if (strcmp(argv[1], "mesh-info") == 0 || strcmp(argv[1], "levelset") == 0) {
        (argv[1][0] == 'm' ? cs_mesh_info_help : cs_levelset_help)(stdout);
        return CS_EXIT_OK;
    }
    if (strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return CS_EXIT_OK;
    }
    fprintf(stderr, "clothsim help: unknown command '%s'\n", argv[1]);
    usage(stderr);
    return CS_EXIT_USAGE;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "clothsim: no command given\n");
        usage(stderr);
        return CS_EXIT_USAGE;
    }
    const char *cmd = argv[1];
    if (strcmp(cmd, "-h") == 0 || strcmp(cmd, "--help") == 0) {
        usage(stdout);
        return CS_EXIT_OK;
    }
    if (strcmp(cmd, "-V") == 0 || strcmp(cmd, "--version") == 0) {
        printf("clothsim %s\n", CS_VERSION);
        return CS_EXIT_OK;
    }
    if (strcmp(cmd, "run") == 0) { /* the one command that can span ranks */
        cs_parallel_init(&argc, &argv);
        int status = cs_run_main(argc - 1, argv + 1);
        cs_parallel_finalize();
        return status;
    }
    if (strcmp(cmd, "intersections") == 0)
        return cs_intersections_main(argc - 1, argv + 1);
    if (strcmp(cmd, "render") == 0)
        return cs_render_main(argc - 1, argv + 1);
    if (strcmp(cmd, "mesh-info") == 0)
        return cs_mesh_info_main(argc - 1, argv + 1);
    if (strcmp(cmd, "levelset") == 0)
        return cs_levelset_main(argc - 1, argv + 1);
    if (strcmp(cmd, "help") == 0)
        return help_main(argc - 1, argv + 1);

    if (cmd[0] == '-')
        fprintf(stderr, "clothsim: unknown option '%s'\n", cmd);
    else
        fprintf(stderr, "clothsim: unknown command '%s'\n", cmd);
    usage(stderr);
    return CS_EXIT_USAGE;
}
