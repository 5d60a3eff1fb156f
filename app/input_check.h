/* input_check.h: problems of a scene's initial state, found before a run
 * (`clothsim check SCENE`, and the start of every `clothsim run`):
 * intersecting cloth (the verifier of sim/verify.c, the counter `clothsim
 * intersections` uses), cloth inside a body, cloth closer than the
 * repulsion thickness to itself or to a body, degenerate triangles and
 * non-manifold edges. docs/input-check.md says what is looked at and how.
 * The checks are in input_check.c, their listing and the start of `run` in
 * input_report.c, the `check` command in check_cmd.c (check_cmd.h).
 */
#ifndef CS_APP_INPUT_CHECK_H
#define CS_APP_INPUT_CHECK_H

#include <stdbool.h>
#include <stdio.h>

#include "import/import.h"

/* The start of `run` (rank 0): checks the scene's initial state. An
 * intersecting start (cloth with cloth, or a cloth vertex inside a body) is
 * listed on err and refused, CS_EXIT_INPUT, unless the scene sets
 * check.allow_intersecting_start (then a warning); warnings are one line
 * each unless quiet. Returns CS_EXIT_OK to go on, or an exit status. */
int cs_input_check_start(const cs_scene *scene, bool quiet, FILE *err);

#endif
