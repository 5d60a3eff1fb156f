/* exit.c: a status's exit code. */
#include "app/exit.h"

int cs_exit_status(int status)
{
    switch ((cs_status)status) {
    case CS_OK: return CS_EXIT_OK;
    case CS_ERR_INVALID:
    case CS_ERR_BAD_INPUT: return CS_EXIT_INPUT;
    case CS_ERR_UNSTABLE:
    case CS_ERR_SCRIPT: return CS_EXIT_UNSTABLE;
    case CS_ERR_NOMEM:
    case CS_ERR_FAILED: return CS_EXIT_OUTPUT;
    }
    return CS_EXIT_OUTPUT;
}
