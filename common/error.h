/* error.h: the one status enumeration of import, sim, render and app.
 * Every fallible call returns CS_OK or a negative cs_status and, where a
 * message buffer is given, a sentence that says what was wrong; the
 * command turns a status into its documented exit code (app/cli.h). C and
 * C++ include it. */
#ifndef CS_COMMON_ERROR_H
#define CS_COMMON_ERROR_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum cs_status {
    CS_OK = 0,
    CS_ERR_INVALID = -1,   /* a definition or argument that makes no sense */
    CS_ERR_NOMEM = -2,
    CS_ERR_UNSTABLE = -3,  /* NaN or runaway velocity detected */
    CS_ERR_SCRIPT = -4,    /* step C found no collision-free state that
                              follows the scripts (cs_sim_script_conflict) */
    CS_ERR_BAD_INPUT = -5, /* an input file or value that is unreadable,
                              malformed or invalid */
    CS_ERR_FAILED = -6,    /* an engine, a file or a program failed */
} cs_status;

/* A few words for the status ("out of memory"); "unknown status" for a
 * value that is none of the above. */
const char *cs_status_message(int status);

/* The sentence of a build without an optional part, where the part is
 * needed (the stand-ins of docs/building.md): PART the library, WHAT what
 * needs it ("--resume and checkpoints need it"), OPTION its CMake option;
 * all three string literals. */
#define CS_MISSING_PART(part, what, option) \
    "this build has no " part ": " what "; rebuild with -D" option "=ON"

#ifdef __cplusplus
}
#endif
#endif
