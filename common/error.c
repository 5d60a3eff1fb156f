/* error.c: what each status means, in words. */
#include "common/error.h"

const char *cs_status_message(int status)
{
    switch ((cs_status)status) {
    case CS_OK: return "ok";
    case CS_ERR_INVALID: return "invalid definition";
    case CS_ERR_NOMEM: return "out of memory";
    case CS_ERR_UNSTABLE: return "simulation unstable";
    case CS_ERR_SCRIPT: return "no collision-free state follows the scripts";
    case CS_ERR_BAD_INPUT: return "bad input";
    case CS_ERR_FAILED: return "failed";
    }
    return "unknown status";
}
