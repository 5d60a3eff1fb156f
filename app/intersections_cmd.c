/* intersections_cmd.c: `clothsim intersections MESHFILE [--list]`: the
 * exact self-intersection verifier (cs_count_intersections) on a mesh file,
 * all its meshes merged into one. Exit status like cmp(1): 0 clean,
 * 1 intersecting, 2 trouble, so scripts can test it directly.
 */
#include "app/intersections_cmd.h"

#include "app/cli.h"
#include "app/exit.h"

#include "import/import.h"
#include "sim/sim.h"

#include <getopt.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>

#define ERRLEN 1024
#define LIST_MAX 20   /* pairs shown by --list */

enum { EXIT_INTERSECTING = 1 }; /* its own: 0 clean, 2 bad input, 4 no memory */

void cs_intersections_help(FILE *out)
{
    fputs("usage: clothsim intersections MESHFILE [options]\n"
          "\n"
          "Counts the pairs of triangles of MESHFILE (any format assimp reads; all its\n"
          "meshes merged, identical vertices joined) that share no vertex and intersect,\n"
          "touching included, with exact arithmetic, and prints\n"
          "'N intersecting triangle pairs'.\n"
          "\n"
          "options:\n"
          "      --list       also print the first 20 pairs, one 'I J' (triangle\n"
          "                   indices, from 0) per line\n"
          "  -h, --help       show this help\n"
          "\n"
          "exit status:\n"
          "  0    no intersecting pair\n"
          "  1    some pairs intersect\n"
          "  2    bad command line, or the file is missing, unreadable or invalid\n"
          "  4    out of memory\n",
          out);
}

/* A bad command line is exit status 2 here, with the whole help. */
static const cs_cli CLI = {"intersections", NULL, cs_intersections_help, CS_EXIT_INPUT};

int cs_intersections_main(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"list", no_argument, NULL, 'l'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    bool list = false;
    optind = 1;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
        switch (c) {
        case 'l':
            list = true;
            break;
        case 'h':
            cs_intersections_help(stdout);
            return CS_EXIT_OK;
        default:
            return cs_cli_option_error(&CLI, c, argv);
        }
    }
    int status = 0;
    const char *path = cs_cli_operand(&CLI, argc, argv, optind, "mesh file", &status);
    if (!path)
        return status;

    char err[ERRLEN];
    cs_trimesh *mesh = cs_mesh_read(path, err, sizeof err);
    if (!mesh) {
        fprintf(stderr, "clothsim intersections: %s\n", err);
        return CS_EXIT_INPUT;
    }
    int pairs[2 * LIST_MAX];
    long n = cs_find_intersections(mesh->nv, mesh->x, mesh->nt, mesh->tri,
                                   list ? LIST_MAX : 0, pairs);
    int nt = mesh->nt;
    cs_trimesh_destroy(mesh);
    if (n == CS_ERR_NOMEM) {
        fprintf(stderr, "clothsim intersections: out of memory for %d triangles\n", nt);
        return CS_EXIT_OUTPUT;
    }
    if (n < 0) {
        fprintf(stderr, "clothsim intersections: %s: invalid mesh\n", path);
        return CS_EXIT_INPUT;
    }
    printf("%ld intersecting triangle pairs\n", n);
    if (list) {
        for (long k = 0; k < n && k < LIST_MAX; k++)
            printf("%d %d\n", pairs[2 * k], pairs[2 * k + 1]);
        if (n > LIST_MAX)
            printf("(first %d of %ld shown)\n", LIST_MAX, n);
    }
    return n == 0 ? CS_EXIT_OK : EXIT_INTERSECTING;
}
