/* cli.c: reporting a bad command line, the same way in every command. */
#include "app/cli.h"

#include <getopt.h>
#include <stdio.h>
#include <string.h>

int cs_cli_error(const cs_cli *cli, const char *fmt, const char *arg)
{
    fprintf(stderr, "clothsim %s: ", cli->name);
    fprintf(stderr, fmt, arg);
    fputc('\n', stderr);
    if (cli->usage)
        fputs(cli->usage, stderr);
    else if (cli->help)
        cli->help(stderr);
    return cli->status;
}

int cs_cli_option_error(const cs_cli *cli, int c, char **argv)
{
    const char *arg = argv[optind - 1];
    if (c == ':')
        return cs_cli_error(cli, "option '%s' needs a value", arg);
    char shortopt[3] = {'-', (char)optopt, '\0'};
    if (strncmp(arg, "--", 2) != 0 && optopt > ' ' && optopt < 127)
        arg = shortopt; /* e.g. the x of -qx */
    return cs_cli_error(cli, "unknown option '%s'", arg);
}

const char *cs_cli_operand(const cs_cli *cli, int argc, char **argv, int optind,
                           const char *what, int *status)
{
    char msg[256];
    if (optind >= argc)
        snprintf(msg, sizeof msg, "no %s given", what);
    else if (argc - optind > 1)
        snprintf(msg, sizeof msg, "one %s only; '%s' is one too many", what, argv[optind + 1]);
    else
        return argv[optind];
    *status = cs_cli_error(cli, "%s", msg);
    return NULL;
}
