/* levelset_cmd.c: `clothsim levelset FILE -o OUT.vdb`: a mesh file to a
 * signed distance grid outside any scene, as a mesh body would get it
 * (holes closed for the sign, interior filled), with what it costs. */
#include "app/cli.h"
#include "app/mesh_cmds.h"
#include "app/run.h"
#include "common/util.h"
#include "import/import.h"

#include <getopt.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

void cs_levelset_help(FILE *out)
{
    fputs("usage: clothsim levelset FILE -o OUT.vdb [--voxel V] [--band N] [options]\n"
          "\n"
          "Converts the mesh file FILE to a signed distance grid with OpenVDB and writes it\n"
          "as OUT.vdb (open it in vdb_view, Houdini or Blender), then prints its voxels,\n"
          "bounds, memory and the time taken. The mesh is read as `clothsim mesh-info`\n"
          "shows it; a mesh that is not closed gets its holes closed with fans first, so\n"
          "that the grid has an inside (as a scene's mesh body does).\n"
          "\n"
          "options:\n"
          "  -o, --output OUT.vdb  the file to write (required)\n"
          "      --voxel V         voxel size in metres (default: 1/100 of the mesh's\n"
          "                        largest extent)\n"
          "      --band N          narrow band in voxels (default 3)\n"
          "      --interior MODE   fill: distances all the way in; band: a band as wide as\n"
          "                        the outside one; auto (default): fill when the inside\n"
          "                        holds at most 2 million voxels\n"
          "      --node NAME       take only this node (with its subtree) or mesh\n"
          "      --units U         file units: m, cm, mm, km, in, ft (default: the file's)\n"
          "      --scale S         a uniform scale after the units\n"
          "      --keep-holes      do not close holes (the sign is then OpenVDB's flood\n"
          "                        fill, which leaks in through holes wider than a voxel)\n"
          "  -h, --help            show this help\n"
          "\n"
          "exit status: 0 written; 1 bad command line; 2 the mesh cannot be read, or the\n"
          "voxel size is absurd for it (the memory it needs is shown against what is\n"
          "available); 4 the grid could not be made or written.\n",
          out);
}

static const cs_cli CLI = {
    "levelset",
    "usage: clothsim levelset FILE -o OUT.vdb [--voxel V] [--band N] [--interior MODE] "
    "[--node NAME] [--units U] [--scale S]\n"
    "                          [--keep-holes]\n",
    NULL, CS_EXIT_USAGE};

static bool positive(const char *s, double *out)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end || !(v > 0) || v > 1e12)
        return false;
    *out = v;
    return true;
}

int cs_levelset_main(int argc, char **argv)
{
    enum { OPT_VOXEL = 256, OPT_BAND, OPT_NODE, OPT_UNITS, OPT_SCALE, OPT_KEEP, OPT_INTERIOR };
    static const struct option longopts[] = {
        {"output", required_argument, NULL, 'o'},
        {"voxel", required_argument, NULL, OPT_VOXEL},
        {"band", required_argument, NULL, OPT_BAND},
        {"node", required_argument, NULL, OPT_NODE},
        {"units", required_argument, NULL, OPT_UNITS},
        {"scale", required_argument, NULL, OPT_SCALE},
        {"keep-holes", no_argument, NULL, OPT_KEEP},
        {"interior", required_argument, NULL, OPT_INTERIOR},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    cs_mesh_placement place = cs_default_mesh_placement();
    const char *out = NULL;
    double voxel = 0, band = 3, scale;
    bool keep_holes = false;
    cs_interior_mode interior = CS_INTERIOR_AUTO;
    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, ":o:h", longopts, NULL)) != -1) {
        switch (c) {
        case 'o':
            if (!*optarg)
                return cs_cli_error(&CLI, "%s", "--output needs a file name");
            out = optarg;
            break;
        case OPT_VOXEL:
            if (!positive(optarg, &voxel))
                return cs_cli_error(&CLI, "--voxel: '%s' is not a number > 0", optarg);
            break;
        case OPT_BAND:
            if (!positive(optarg, &band) || band < 1 || band > 1000)
                return cs_cli_error(&CLI, "--band: '%s' is not a number of voxels in [1, 1000]", optarg);
            break;
        case OPT_NODE:
            place.node = optarg;
            break;
        case OPT_UNITS:
            if (!cs_mesh_units_from_name(optarg, &place.unit_scale))
                return cs_cli_error(&CLI, "--units: '%s' is not one of m, cm, mm, km, in, ft", optarg);
            break;
        case OPT_SCALE:
            if (!positive(optarg, &scale))
                return cs_cli_error(&CLI, "--scale: '%s' is not a number > 0", optarg);
            place.scale[0] = place.scale[1] = place.scale[2] = scale;
            break;
        case OPT_KEEP:
            keep_holes = true;
            break;
        case OPT_INTERIOR:
            if (!strcmp(optarg, "auto"))
                interior = CS_INTERIOR_AUTO;
            else if (!strcmp(optarg, "fill"))
                interior = CS_INTERIOR_FILL;
            else if (!strcmp(optarg, "band"))
                interior = CS_INTERIOR_BAND;
            else
                return cs_cli_error(&CLI, "--interior: '%s' is not one of auto, fill, band", optarg);
            break;
        case 'h':
            cs_levelset_help(stdout);
            return CS_EXIT_OK;
        default:
            return cs_cli_option_error(&CLI, c, argv);
        }
    }
    int status;
    const char *path = cs_cli_operand(&CLI, argc, argv, optind, "mesh file", &status);
    if (!path)
        return status;
    if (!out)
        return cs_cli_error(&CLI, "%s", "no output file given (-o OUT.vdb)");

    char err[1024];
    cs_trimesh *mesh = NULL;
    cs_mesh_report rep;
    int rc = cs_mesh_import(path, &place, &mesh, &rep, err, sizeof err);
    if (rc != CS_OK) {
        fprintf(stderr, "clothsim levelset: %s\n", err);
        return cs_exit_status(rc);
    }
    if (rep.size_warning[0])
        fprintf(stderr, "clothsim levelset: warning: %s: %s\n", path, rep.size_warning);
    printf("mesh:      %s: %d triangles, %d vertices, %s", path, rep.triangles, rep.vertices,
           rep.closed ? "closed\n" : "open");
    cs_mesh_report sign_rep;
    int closed = 0;
    cs_trimesh *sign = cs_mesh_body_sign_mesh(mesh, &rep, !keep_holes, &closed, &sign_rep);
    if (!sign) {
        fprintf(stderr, "clothsim levelset: out of memory\n");
        cs_trimesh_destroy(mesh);
        return CS_EXIT_OUTPUT;
    }
    if (sign != mesh) {
        cs_trimesh_destroy(mesh);
        mesh = sign;
    }
    if (!rep.closed) {
        printf(" (%d boundary edges in %d loops)", rep.boundary_edges, rep.boundary_loops);
        if (keep_holes)
            printf(": holes kept (--keep-holes); the sign may leak in through them\n");
        else
            printf(": closed %d hole%s with fans%s\n", closed, closed == 1 ? "" : "s",
                   sign_rep.closed ? "" : " (still open: the sign may be wrong near what is left)");
    }
    rep = sign_rep;
    bool given = voxel > 0, fill;
    char why[512];
    if (!cs_mesh_body_grid(&rep, &voxel, 0, 0, &band, interior, &fill, why, sizeof why)) {
        fprintf(stderr, "clothsim levelset: %s %g m: %s\n", given ? "--voxel" : "the default voxel",
                voxel, why);
        cs_trimesh_destroy(mesh);
        return CS_EXIT_INPUT;
    }
    printf("voxel:     %.4g m%s; band %g voxels, %s\n", voxel,
           given ? "" : " (default: 1/100 of the largest extent)", band,
           fill ? "the inside filled" : "inside too");
    printf("estimate:  %.3g voxels, %.3g MB at the peak of conversion\n",
           cs_levelset_estimate_voxels(&rep, voxel, band, fill),
           cs_levelset_estimate_bytes(&rep, voxel, band, fill) / 1e6);
    fflush(stdout);

    double t0 = cs_now();
    cs_levelset *ls = cs_levelset_create(mesh, voxel, band, fill, err, sizeof err);
    double convert = cs_now() - t0;
    cs_trimesh_destroy(mesh);
    if (!ls) {
        fprintf(stderr, "clothsim levelset: %s\n", err);
        return CS_EXIT_OUTPUT;
    }
    cs_levelset_info info;
    cs_levelset_get_info(ls, &info);
    printf("grid:      %d x %d x %d voxels, bounds (%.6g, %.6g, %.6g) - (%.6g, %.6g, %.6g) m\n",
           info.dim[0], info.dim[1], info.dim[2], info.min[0], info.min[1], info.min[2],
           info.max[0], info.max[1], info.max[2]);
    printf("active:    %lld voxels in %lld leaf nodes; %.3g MB in memory\n", info.active_voxels,
           info.leaf_nodes, info.memory_bytes / 1e6);
    printf("converted: %.3f s\n", convert);

    char voxel_text[32];
    snprintf(voxel_text, sizeof voxel_text, "%.17g", voxel);
    const char *keys[] = {"clothsim_source", "clothsim_voxel_size"};
    const char *values[] = {path, voxel_text};
    t0 = cs_now();
    rc = cs_levelset_write(ls, out, "phi", 2, keys, values, err, sizeof err);
    cs_levelset_destroy(ls);
    if (rc != 0) {
        fprintf(stderr, "clothsim levelset: %s\n", err);
        return CS_EXIT_OUTPUT;
    }
    struct stat st;
    printf("wrote:     %s (%.3g MB) in %.3f s\n", out,
           stat(out, &st) == 0 ? (double)st.st_size / 1e6 : 0.0, cs_now() - t0);
    return CS_EXIT_OK;
}
