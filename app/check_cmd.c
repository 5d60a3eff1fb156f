/* check_cmd.c: `clothsim check SCENE [--fix -o DIR]`: the scene loaded,
 * its initial state checked (input_check.c) and listed (input_report.c),
 * and with --fix lifted out of the bodies (input_fix.c). */
#include "app/check_cmd.h"
#include "app/input_check_internal.h"

#include "app/cli.h"
#include "app/run.h"
#include "import/import.h"

#include <getopt.h>
#include <stdlib.h>
#include <string.h>

#define ERRLEN 1024

void cs_check_help(FILE *out)
{
    fputs("usage: clothsim check SCENE [options]\n"
          "\n"
          "Checks the initial state of the scene file SCENE, as 'clothsim run' starts it,\n"
          "and lists what it finds, grouped by kind, the first 20 of each with a count:\n"
          "  errors (run refuses them, exit 2, unless the scene sets\n"
          "  check: {allow_intersecting_start: true}):\n"
          "    triangles of two cloths, or of one cloth, that intersect (the exact\n"
          "    verifier 'clothsim intersections' uses: every pair it counts)\n"
          "    cloth vertices inside a body (negative signed distance)\n"
          "  warnings:\n"
          "    cloth edges through a body with both ends outside it\n"
          "    cloth vertices closer to a body than the larger of\n"
          "    self_collision.thickness and the body's collision_offset\n"
          "    vertex-triangle pairs of cloth closer than self_collision.thickness\n"
          "    (the vertex not a corner of the triangle; with self-collision on)\n"
          "    degenerate triangles and non-manifold edges\n"
          "A selection (pin or script) that selects no vertex is an error of the scene\n"
          "file itself, reported with its file and line like any other.\n"
          "\n"
          "options:\n"
          "      --set KEY=VALUE  override a scene setting, as for 'clothsim run'\n"
          "      --fix            lift cloth vertices inside or too close to a body out\n"
          "                       along the body's gradient to the threshold, say how\n"
          "                       many moved and how far, and check again\n"
          "  -o, --output DIR     with --fix: write the fixed cloths as DIR/NAME.ply (world\n"
          "                       positions, the vertex numbering kept) and DIR/cloths.yaml,\n"
          "                       the scene lines that use them\n"
          "  -h, --help           show this help\n"
          "\n"
          "exit status:\n"
          "  0    no error (warnings may be listed)\n"
          "  1    errors found (after --fix: errors left)\n"
          "  2    bad command line, or the scene is invalid\n"
          "  4    out of memory, or a fixed file could not be written\n"
          "\n"
          "docs/input-check.md explains each finding.\n",
          out);
}

static const cs_cli CLI = {"check", NULL, cs_check_help, CS_EXIT_INPUT};

static void print_clean(FILE *out, const report *r)
{
    fprintf(out, "checked: intersections (verifier: %ld pairs)%s%s, degenerate triangles, "
                 "non-manifold edges\n",
            r->verifier_pairs,
            r->bodies_checked ? ", bodies (inside, edges through, closer than the threshold)"
                              : ", no bodies (none, or effects.bodies off)",
            r->self_checked ? ", cloth closer than the thickness"
                            : ", not closeness to itself (self-collision off)");
}

int cs_check_main(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"set", required_argument, NULL, 's'},
        {"fix", no_argument, NULL, 'f'},
        {"output", required_argument, NULL, 'o'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    char **overrides = calloc((size_t)argc + 1, sizeof *overrides);
    int noverrides = 0;
    bool fix = false;
    const char *out_dir = NULL;
    if (!overrides) {
        fprintf(stderr, "clothsim check: out of memory\n");
        return CS_EXIT_OUTPUT;
    }
    optind = 1;
    opterr = 0;
    int c, status = 0;
    while ((c = getopt_long(argc, argv, ":o:h", longopts, NULL)) != -1) {
        switch (c) {
        case 's':
            if (!strchr(optarg, '=') || optarg[0] == '=') {
                free(overrides);
                return cs_cli_error(&CLI, "--set needs KEY=VALUE, got '%s'", optarg);
            }
            overrides[noverrides++] = optarg;
            break;
        case 'f':
            fix = true;
            break;
        case 'o':
            out_dir = optarg;
            break;
        case 'h':
            free(overrides);
            cs_check_help(stdout);
            return CS_EXIT_OK;
        default:
            free(overrides);
            return cs_cli_option_error(&CLI, c, argv);
        }
    }
    const char *path = cs_cli_operand(&CLI, argc, argv, optind, "scene file", &status);
    if (!path) {
        free(overrides);
        return status;
    }
    if (fix != (out_dir != NULL)) {
        free(overrides);
        return cs_cli_error(&CLI, "%s", "--fix and -o DIR go together");
    }
    char err[ERRLEN] = "";
    cs_scene *scene = NULL;
    int rc = cs_scene_load(path, noverrides, (const char *const *)overrides, &scene, err,
                           sizeof err);
    free(overrides);
    if (rc != CS_OK) {
        fprintf(stderr, "clothsim check: %s\n", err[0] ? err : "cannot load the scene");
        return cs_exit_status(rc);
    }
    for (int i = 0; i < scene->nnotes; i++)
        fprintf(stderr, "clothsim check: %s\n", scene->notes[i]);

    cloth_set s;
    report r;
    if (cs_cloth_set_init(&s, scene) != 0 || cs_input_analyse(&s, &r) != 0) {
        fprintf(stderr, "clothsim check: out of memory\n");
        cs_cloth_set_free(&s);
        cs_scene_destroy(scene);
        return CS_EXIT_OUTPUT;
    }
    printf("%s: %d cloth%s, %d vertices, %d triangles, %d bod%s%s; self-collision %s, "
           "thickness %.4g m\n",
           scene->path, s.ncloths, s.ncloths == 1 ? "" : "s", s.nv, s.nt, scene->def.nbodies,
           scene->def.nbodies == 1 ? "y" : "ies",
           cs_input_bodies_on(scene) || !scene->def.nbodies ? "" : " (off)",
           scene->def.self_collision ? "on" : "off", scene->def.self.thickness);
    print_clean(stdout, &r);
    cs_input_print_report(stdout, &s, &r, "");
    long errors = cs_input_errors(&r);
    status = errors > 0 ? 1 : CS_EXIT_OK;
    if (fix) {
        fix_result fr;
        cs_input_fix_bodies(&s, &fr);
        printf("--fix: moved %ld vertices out of bodies, at most %.4g m", fr.moved, fr.max_move);
        if (fr.stuck > 0)
            printf("; %ld vertices could not be moved clear (no gradient, or between bodies)",
                   fr.stuck);
        printf("\n");
        if (cs_input_write_fixed(&s, out_dir, err, sizeof err) != 0) {
            fprintf(stderr, "clothsim check: %s\n", err);
            status = CS_EXIT_OUTPUT;
        } else {
            printf("--fix: wrote the fixed cloths to %s/ (one NAME.ply a cloth) and the scene "
                   "lines that use them to %s/cloths.yaml\n",
                   out_dir, out_dir);
            report after;
            if (cs_input_analyse(&s, &after) != 0) {
                fprintf(stderr, "clothsim check: out of memory\n");
                status = CS_EXIT_OUTPUT;
            } else {
                printf("after --fix:\n");
                cs_input_print_report(stdout, &s, &after, "");
                long left = cs_input_errors(&after);
                long pairs0 = r.k[K_CROSS].count + r.k[K_SELF].count;
                long pairs1 = after.k[K_CROSS].count + after.k[K_SELF].count;
                printf("after --fix: %ld error%s left\n", left, left == 1 ? "" : "s");
                if (pairs1 > pairs0)
                    printf("after --fix: the moved vertices made %ld more intersecting triangle "
                           "pairs: lifting along the gradient folds a cloth that lies deep in "
                           "a body; move that cloth by hand\n",
                           pairs1 - pairs0);
                errors = left;
                status = left > 0 ? 1 : CS_EXIT_OK;
            }
        }
    }
    const char *state = fix ? "the fixed state" : "this start";
    if (status == CS_EXIT_OUTPUT)
        printf("result: the fixed cloths were not written\n");
    else if (errors > 0 && !scene->allow_intersecting_start)
        printf("result: %ld error%s: 'clothsim run' refuses %s (exit 2) unless the "
               "scene sets check: {allow_intersecting_start: true}\n",
               errors, errors == 1 ? "" : "s", state);
    else if (errors > 0)
        printf("result: %ld error%s, accepted by check.allow_intersecting_start\n", errors,
               errors == 1 ? "" : "s");
    else
        printf("result: no error; 'clothsim run' starts from %s\n", state);
    cs_cloth_set_free(&s);
    cs_scene_destroy(scene);
    return status;
}
