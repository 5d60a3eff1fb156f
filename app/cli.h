/* cli.h: what every `clothsim COMMAND` shares: the table of commands that
 * main.c dispatches on, and the one way to report a bad command line. */
#ifndef CS_APP_CLI_H
#define CS_APP_CLI_H

#include <stdio.h>

/* A row of the command table (main.c): a command, `clothsim NAME ...`, or
 * a help topic, `clothsim help NAME ...` (topic set: main gets argv from
 * NAME on, e.g. `help scene --markdown`). */
typedef struct cs_command {
    const char *name;
    const char *synopsis;          /* the usage's left column, e.g. "run SCENE" */
    const char *summary;           /* its right column; NULL: not listed */
    int (*main)(int argc, char **argv); /* argv[0] is the name; an exit status */
    void (*help)(FILE *out);       /* `clothsim help NAME` for a command */
    int parallel;                  /* runs between cs_parallel_init and _finalize */
    int topic;                     /* a help topic, not a command */
} cs_command;

/* How a command reports a bad command line: "clothsim NAME: what", then
 * usage (text) or help (the command's help, when usage is NULL), on stderr;
 * the command then exits with status. */
typedef struct cs_cli {
    const char *name;
    const char *usage;
    void (*help)(FILE *out);
    int status;
} cs_cli;

/* Prints "clothsim NAME: " fmt (with arg), a newline and the usage; returns
 * cli->status. */
int cs_cli_error(const cs_cli *cli, const char *fmt, const char *arg);

/* After getopt_long returned c for a bad option (':' a value missing, '?'
 * unknown): says which option, as cs_cli_error. */
int cs_cli_option_error(const cs_cli *cli, int c, char **argv);

/* The command's one operand (a scene file, a run folder): argv[optind],
 * or NULL after reporting "no WHAT given" or "one WHAT only; 'X' is one too
 * many" (then *status is the exit status). */
const char *cs_cli_operand(const cs_cli *cli, int argc, char **argv, int optind,
                           const char *what, int *status);

#endif
