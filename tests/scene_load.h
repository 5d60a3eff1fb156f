/* scene_load.h: the scene tests' loads from text (as if read from
 * scenes/a.yaml, with --set overrides), expecting success or exactly one
 * error message. Include after cmocka.h. */
#ifndef CS_TESTS_SCENE_LOAD_H
#define CS_TESTS_SCENE_LOAD_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "import/import.h"

static inline cs_scene *load_ok(const char *text, int nov, const char *const *ov)
{
    char err[1024] = "";
    cs_scene *s = NULL;
    int rc = cs_scene_load_string(text, "scenes/a.yaml", nov, ov, &s, err, sizeof err);
    if (rc != CS_OK)
        print_error("unexpected error: %s\n", err);
    assert_int_equal(rc, CS_OK);
    assert_non_null(s);
    return s;
}

/* The load fails with exactly this one-line message, and leaves no scene. */
static inline void expect_error(const char *text, int nov, const char *const *ov,
                                const char *want)
{
    char err[1024] = "";
    cs_scene *s = (cs_scene *)&err; /* must be reset to NULL */
    int rc = cs_scene_load_string(text, "scenes/a.yaml", nov, ov, &s, err, sizeof err);
    if (rc != CS_ERR_BAD_INPUT || strcmp(err, want) != 0)
        print_error("got:  %s\nwant: %s\n", err, want);
    assert_int_equal(rc, CS_ERR_BAD_INPUT);
    assert_null(s);
    assert_null(strchr(err, '\n'));
    assert_string_equal(err, want);
}

static inline void assert_vec(const double *got, double x, double y, double z)
{
    assert_true(fabs(got[0] - x) < 1e-9);
    assert_true(fabs(got[1] - y) < 1e-9);
    assert_true(fabs(got[2] - z) < 1e-9);
}

#endif
