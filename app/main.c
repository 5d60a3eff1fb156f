/* main.c: the clothsim command line: `clothsim COMMAND [options]`.
 *
 * Only dispatch lives here, on one table of commands; each command has its
 * own file (run.c, render_cmd.c, ...). A new command, or a help topic
 * (`clothsim help scene`: a row with topic set), is a new row. */
#include "app/build_info.h"
#include "app/check_cmd.h"
#include "app/cli.h"
#include "app/export_cmd.h"
#include "app/info_cmd.h"
#include "app/intersections_cmd.h"
#include "app/help_cmd.h"
#include "app/mesh_cmds.h"
#include "app/render_cmd.h"
#include "app/run.h"
#include "app/sweep_cmd.h"
#include "sim/sim.h"

#include <stdio.h>
#include <string.h>

#ifndef CS_VERSION
#define CS_VERSION "unknown"
#endif

static int help_main(int argc, char **argv);
static void usage(FILE *out);

static const cs_command COMMANDS[] = {
    {.name = "run", .synopsis = "run SCENE",
     .summary = "simulate a scene file and write a mesh file per frame", .main = cs_run_main,
     .help = cs_run_help, .parallel = 1}, /* the one command that can span ranks */
    {.name = "sweep", .synopsis = "sweep SCENE",
     .summary = "run a scene over settings; cost and error against a reference",
     .main = cs_sweep_main, .help = cs_sweep_help},
    {.name = "check", .synopsis = "check SCENE",
     .summary = "find intersections and other problems of a scene's start",
     .main = cs_check_main, .help = cs_check_help},
    {.name = "info", .synopsis = "info DIR",
     .summary = "a run's frames as a table (pairs, energy, speed) and DIR/info.png",
     .main = cs_info_main, .help = cs_info_help},
    {.name = "export", .synopsis = "export DIR",
     .summary = "a run's frames as one animated USD stage or Blender point caches",
     .main = cs_export_main, .help = cs_export_help},
    {.name = "render", .synopsis = "render TARGET",
     .summary = "render a run's frames (or a scene's start) to PNG images",
     .main = cs_render_main, .help = cs_render_help},
    {.name = "intersections", .synopsis = "intersections MESHFILE",
     .summary = "count intersecting triangle pairs (exact)", .main = cs_intersections_main,
     .help = cs_intersections_help},
    {.name = "mesh-info", .synopsis = "mesh-info FILE",
     .summary = "what import sees in a mesh file", .main = cs_mesh_info_main,
     .help = cs_mesh_info_help},
    {.name = "levelset", .synopsis = "levelset FILE -o OUT.vdb",
     .summary = "convert a mesh to a signed distance grid (OpenVDB)", .main = cs_levelset_main,
     .help = cs_levelset_help},
    {.name = "scene", .main = cs_help_scene_main, .topic = 1}, /* `help scene` */
    {.name = "help", .synopsis = "help [COMMAND]",
     .summary = "show help, for a command if one is named", .main = help_main, .help = usage},
};
#define NCOMMANDS ((int)(sizeof COMMANDS / sizeof COMMANDS[0]))

static const cs_command *find_command(const char *name)
{
    for (int i = 0; i < NCOMMANDS; i++)
        if (strcmp(COMMANDS[i].name, name) == 0)
            return &COMMANDS[i];
    return NULL;
}

static void usage(FILE *out)
{
    fputs("usage: clothsim COMMAND [options]\n\ncommands:\n", out);
    for (int i = 0; i < NCOMMANDS; i++) {
        const cs_command *c = &COMMANDS[i];
        if (c->summary) /* the synopsis in 16 columns, or two spaces after */
            fprintf(out, "  %-16s%s%s\n", c->synopsis, strlen(c->synopsis) < 16 ? " " : "  ",
                    c->summary);
    }
    fputs("\n"
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
    const cs_command *c = find_command(argv[1]);
    if (c && c->topic)
        return c->main(argc - 1, argv + 1);
    if (argc > 2) {
        fprintf(stderr, "clothsim help: one command at a time\n");
        usage(stderr);
        return CS_EXIT_USAGE;
    }
    if (!c || !c->help) {
        fprintf(stderr, "clothsim help: unknown command '%s'\n", argv[1]);
        usage(stderr);
        return CS_EXIT_USAGE;
    }
    c->help(stdout);
    return CS_EXIT_OK;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "clothsim: no command given\n");
        usage(stderr);
        return CS_EXIT_USAGE;
    }
    const char *name = argv[1];
    if (strcmp(name, "-h") == 0 || strcmp(name, "--help") == 0) {
        usage(stdout);
        return CS_EXIT_OK;
    }
    if (strcmp(name, "-V") == 0 || strcmp(name, "--version") == 0) {
        printf("clothsim %s\n", CS_VERSION);
        cs_build_print_parts(stdout);
        return CS_EXIT_OK;
    }
    const cs_command *c = find_command(name);
    if (c && !c->topic) {
        if (!c->parallel)
            return c->main(argc - 1, argv + 1);
        int refused = cs_build_check_ranks();
        if (refused)
            return refused;
        cs_parallel_init(&argc, &argv);
        int status = c->main(argc - 1, argv + 1);
        cs_parallel_finalize();
        return status;
    }
    if (name[0] == '-')
        fprintf(stderr, "clothsim: unknown option '%s'\n", name);
    else
        fprintf(stderr, "clothsim: unknown command '%s'\n", name);
    usage(stderr);
    return CS_EXIT_USAGE;
}
