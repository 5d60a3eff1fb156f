/* mesh_info_cmd.c: `clothsim mesh-info FILE`: what import sees in a mesh
 * file: its nodes and meshes, and what a scene taking it (all of it, or one
 * node) gets: counts, bounds, units, repairs, topology, closedness. */
#include "app/mesh_cmds.h"

#include "app/cli.h"
#include "app/run.h"
#include "import/import.h"

#include <getopt.h>
#include <stdlib.h>
#include <string.h>

void cs_mesh_info_help(FILE *out)
{
    fputs("usage: clothsim mesh-info FILE [--node NAME] [--units U] [--scale S]\n"
          "\n"
          "Prints what import sees in a mesh file (OBJ, PLY, STL, glTF 2.0, FBX, Collada,\n"
          "...): its nodes and meshes, then the mesh a scene would get from it (every\n"
          "mesh merged, or the node or mesh NAME): vertices, triangles, parts, bounds,\n"
          "units, the repairs made (vertices joined, zero-area and duplicate triangles\n"
          "dropped) and the topology (boundary, non-manifold and inconsistently oriented\n"
          "edges; whether it is closed, which a body's level set needs for its sign).\n"
          "\n"
          "options:\n"
          "      --node NAME   take only this node (with its subtree) or mesh\n"
          "      --units U     file units: m, cm, mm, km, in, ft (default: from the file)\n"
          "      --scale S     a uniform scale after the units\n"
          "  -h, --help        show this help\n"
          "\n"
          "A file is read in a separate process with limits, so that no file can crash or\n"
          "hang the command: CLOTHSIM_IMPORT_SECONDS (CPU seconds, default 30 + 1 per MB)\n"
          "and CLOTHSIM_IMPORT_MEMORY (MB, default 1024 + 64 per MB of file) raise them.\n"
          "\n"
          "exit status: 0 read; 1 bad command line; 2 the file cannot be read, is corrupt\n"
          "or holds no usable triangles.\n",
          out);
}

static const cs_cli CLI = {
    "mesh-info", "usage: clothsim mesh-info FILE [--node NAME] [--units U] [--scale S]\n", NULL,
    CS_EXIT_USAGE};

/* --scale: a number > 0 */
static int parse_scale(const char *s, double *out)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end || !(v > 0) || v > 1e12)
        return -1;
    *out = v;
    return 0;
}

static void print_tree(const cs_mesh_catalog *c)
{
    printf("nodes (%d):\n", c->nnodes);
    for (int i = 0; i < c->nnodes && i < 200; i++) {
        const cs_mesh_catalog_node *n = &c->nodes[i];
        printf("  %*s'%s'", 2 * n->depth, "", n->name);
        for (int k = 0; k < n->nmeshes; k++)
            printf("%s mesh %d", k ? "," : ":", n->meshes[k]);
        printf("\n");
    }
    if (c->nnodes > 200)
        printf("  ... %d more\n", c->nnodes - 200);
    printf("meshes (%d):\n", c->nmeshes);
    for (int i = 0; i < c->nmeshes && i < 200; i++) {
        const cs_mesh_catalog_mesh *m = &c->meshes[i];
        printf("  %d '%s': %d vertices, %d triangles", i, m->name, m->vertices, m->triangles);
        if (m->other_primitives)
            printf(", %d points or lines (ignored)", m->other_primitives);
        printf("\n");
    }
    if (c->nmeshes > 200)
        printf("  ... %d more\n", c->nmeshes - 200);
}

static void print_report(const cs_mesh_placement *p, const cs_mesh_report *r)
{
    if (p->node)
        printf("selected:  node or mesh '%s': %d mesh instance%s\n", p->node, r->instances,
               r->instances == 1 ? "" : "s");
    else
        printf("selected:  every mesh, merged: %d mesh instance%s\n", r->instances,
               r->instances == 1 ? "" : "s");
    printf("units:     %s\n", r->units);
    printf("result:    %d vertices, %d triangles, %d part%s\n", r->vertices, r->triangles, r->parts,
           r->parts == 1 ? "" : "s");
    printf("bounds:    (%.6g, %.6g, %.6g) - (%.6g, %.6g, %.6g) m\n", r->min[0], r->min[1],
           r->min[2], r->max[0], r->max[1], r->max[2]);
    printf("size:      %.6g x %.6g x %.6g m; area %.6g m^2, enclosed volume %.6g m^3\n",
           r->max[0] - r->min[0], r->max[1] - r->min[1], r->max[2] - r->min[2], r->area,
           r->volume);
    printf("repairs:   %ld triangles read; joined %d vertices at identical positions; dropped "
           "%d zero-area and %d duplicate triangles and %d unused vertices; ignored %ld points "
           "or lines\n",
           r->triangles_read, r->welded_vertices, r->degenerate_triangles, r->duplicate_triangles,
           r->unreferenced_vertices, r->skipped_primitives);
    printf("topology:  %d boundary edge%s in %d loop%s, %d non-manifold edge%s, %d edge%s with "
           "inconsistent orientation\n",
           r->boundary_edges, r->boundary_edges == 1 ? "" : "s", r->boundary_loops,
           r->boundary_loops == 1 ? "" : "s", r->nonmanifold_edges,
           r->nonmanifold_edges == 1 ? "" : "s", r->inconsistent_edges,
           r->inconsistent_edges == 1 ? "" : "s");
    if (r->closed)
        printf("closed:    yes: a body's level set has a well-defined inside\n");
    else
        printf("closed:    no: as a body, its %d hole%s are closed with fans for the level "
               "set's sign (close_holes: true)\n",
               r->boundary_loops, r->boundary_loops == 1 ? "" : "s");
}

int cs_mesh_info_main(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"node", required_argument, NULL, 'n'},
        {"units", required_argument, NULL, 'u'},
        {"scale", required_argument, NULL, 's'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    cs_mesh_placement place = cs_default_mesh_placement();
    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, ":h", longopts, NULL)) != -1) {
        switch (c) {
        case 'n':
            place.node = optarg;
            break;
        case 'u':
            if (!cs_mesh_units_from_name(optarg, &place.unit_scale))
                return cs_cli_error(&CLI, "--units: '%s' is not one of m, cm, mm, km, in, ft",
                                    optarg);
            break;
        case 's': {
            double v;
            if (parse_scale(optarg, &v) != 0)
                return cs_cli_error(&CLI, "--scale: '%s' is not a number > 0", optarg);
            place.scale[0] = place.scale[1] = place.scale[2] = v;
            break;
        }
        case 'h':
            cs_mesh_info_help(stdout);
            return CS_EXIT_OK;
        default:
            return cs_cli_option_error(&CLI, c, argv);
        }
    }
    int status = 0;
    const char *path = cs_cli_operand(&CLI, argc, argv, optind, "mesh file", &status);
    if (!path)
        return status;
    char err[1024];
    cs_mesh_catalog *cat = NULL;
    int rc = cs_mesh_catalog_read(path, &cat, err, sizeof err);
    if (rc != CS_OK) {
        fprintf(stderr, "clothsim mesh-info: %s\n", err);
        return cs_exit_status(rc);
    }
    printf("file:      %s\n", path);
    printf("format:    %s\n", cat->format);
    print_tree(cat);
    cs_mesh_catalog_destroy(cat);

    cs_trimesh *mesh = NULL;
    cs_mesh_report rep;
    rc = cs_mesh_import(path, &place, &mesh, &rep, err, sizeof err);
    if (rc != CS_OK) {
        fflush(stdout);
        fprintf(stderr, "clothsim mesh-info: %s\n", err);
        return cs_exit_status(rc);
    }
    print_report(&place, &rep);
    if (rep.size_warning[0]) {
        fflush(stdout);
        fprintf(stderr, "clothsim mesh-info: warning: %s: %s\n", path, rep.size_warning);
    }
    cs_trimesh_destroy(mesh);
    return CS_EXIT_OK;
}
