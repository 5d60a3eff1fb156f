/* export_cmd.c: `clothsim export DIR --format usd|pc2`: the frames of an
 * existing run folder as one animated USD stage or as Blender point caches
 * (app/export.c does the work; `run` does the same at its end). The scene
 * is reloaded from summary.json with the run's overrides, as `render` and
 * `info` do, for its cloths' names and triangles, bodies and colours. */
#include "app/export_cmd.h"

#include "app/cli.h"
#include "app/exit.h"
#include "app/export.h"
#include "app/lock.h"
#include "app/outdir.h"
#include "app/run.h"
#include "import/import.h"

#include <errno.h>
#include <getopt.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#define ERRLEN 1024

void cs_export_help(FILE *out)
{
    fputs(
        "usage: clothsim export DIR [--format usd|pc2] [--scene FILE] [-q]\n"
        "\n"
        "Writes the frames of the run folder DIR (the output folder of 'clothsim run')\n"
        "as files other programs open as one animation. The frame files are read one\n"
        "at a time, so the output holds their float32 values exactly and memory holds\n"
        "one frame whatever the run's length. 'clothsim run' writes the same at its\n"
        "end (scene keys output.usd, on by default, and output.pc2, off by default).\n"
        "\n"
        "options:\n"
        "      --format FMT    usd (default): DIR/cloth.usda, a USD stage (text): a\n"
        "                      mesh per cloth, its points sampled at every frame (time\n"
        "                      code = frame number, timeCodesPerSecond = fps), its\n"
        "                      colour as displayColor; a mesh per body with its\n"
        "                      transform, sampled per frame when the body moves\n"
        "                      pc2: per cloth DIR/pc2/NAME.pc2, Blender's point cache\n"
        "                      (a sample per frame from frame 0, rate 1), beside its\n"
        "                      rest pose DIR/pc2/NAME.obj (frame 0's positions) to put a\n"
        "                      Mesh Cache modifier on; NAME is the cloth's name made an\n"
        "                      identifier\n"
        "      --scene FILE    the run's scene file, when it is no longer where\n"
        "                      summary.json says (the run's overrides still apply)\n"
        "  -q, --quiet         do not name the files written\n"
        "  -h, --help          show this help\n"
        "\n"
        "Every file appears whole (written beside itself, then renamed). A run that\n"
        "stopped early is exported up to its last frame written. A run writing into\n"
        "DIR at the same time is refused.\n"
        "\n"
        "exit status:\n"
        "  0    written\n"
        "  1    bad command line (an unknown format)\n"
        "  2    DIR is not a run folder, its scene does not load, or a frame file is\n"
        "       missing, unreadable or not the scene's\n"
        "  4    a file could not be written (the message names it and why), or DIR\n"
        "       is in use by a run\n",
        out);
}

static const cs_cli CLI = {"export",
                           "usage: clothsim export DIR [--format usd|pc2] [--scene FILE] [-q]\n"
                           "'clothsim export --help' explains every option.\n",
                           NULL, CS_EXIT_USAGE};

int cs_export_main(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"format", required_argument, NULL, 'f'},
        {"scene", required_argument, NULL, 's'},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    cs_export_what what = {.usd = true};
    const char *scene_path = NULL;
    bool quiet = false;
    optind = 1;
    opterr = 0;
    int c, status = 0;
    while ((c = getopt_long(argc, argv, ":qh", longopts, NULL)) != -1) {
        switch (c) {
        case 'f':
            if (strcasecmp(optarg, "usd") == 0 || strcasecmp(optarg, "usda") == 0)
                what = (cs_export_what){.usd = true};
            else if (strcasecmp(optarg, "pc2") == 0)
                what = (cs_export_what){.pc2 = true};
            else
                return cs_cli_error(&CLI, "--format: '%s' is not one of usd, pc2", optarg);
            break;
        case 's': scene_path = optarg; break;
        case 'q': quiet = true; break;
        case 'h': cs_export_help(stdout); return CS_EXIT_OK;
        default: return cs_cli_option_error(&CLI, c, argv);
        }
    }
    const char *dir = cs_cli_operand(&CLI, argc, argv, optind, "run folder", &status);
    if (!dir)
        return status;

    char err[ERRLEN] = "";
    struct stat st;
    if (stat(dir, &st) != 0) {
        fprintf(stderr, "clothsim export: cannot read %s: %s\n", dir, strerror(errno));
        return CS_EXIT_INPUT;
    }
    if (!S_ISDIR(st.st_mode)) {
        fprintf(stderr, "clothsim export: %s is not a folder: give the output folder of "
                        "'clothsim run'\n", dir);
        return CS_EXIT_INPUT;
    }
    cs_run_info info;
    if ((status = cs_run_info_read(dir, &info, err, sizeof err)) != CS_EXIT_OK) {
        fprintf(stderr, "clothsim export: %s\n", err);
        return status;
    }
    cs_scene *scene = NULL;
    cs_dir_lock lock = CS_DIR_LOCK_NONE;
    const char *path = scene_path ? scene_path : info.scene_file;
    int rc = cs_scene_load(path, info.noverrides, (const char *const *)info.overrides, &scene,
                           err, sizeof err);
    if (rc != CS_OK) {
        fprintf(stderr, "clothsim export: %s\n", err[0] ? err : "cannot load the scene");
        if (access(path, R_OK) != 0)
            fprintf(stderr, "clothsim export: %s/summary.json names the scene file '%s'; run "
                            "from where the run was started, or give it with --scene FILE\n",
                    dir, path);
        status = cs_exit_status(rc);
        goto done;
    }
    /* a run writing frames now would be exported half done */
    if (cs_dir_lock_take(&lock, dir, err, sizeof err) != 0) {
        fprintf(stderr, "clothsim export: %s\n", err);
        status = CS_EXIT_OUTPUT;
        goto done;
    }
    status = cs_export_run(scene, info.format, dir, info.frames_written, info.fps, what,
                           quiet ? NULL : stdout, err, sizeof err);
    if (status != CS_EXIT_OK)
        fprintf(stderr, "clothsim export: %s\n", err);
done:
    cs_dir_lock_release(&lock);
    if (scene)
        cs_scene_destroy(scene);
    cs_run_info_free(&info);
    return status;
}
