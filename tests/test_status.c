/* Unit tests of the one status enumeration (common/error.h): every status
 * has its own message, and a value outside it says so. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <string.h>

#include "common/error.h"

static void test_every_status_has_its_message(void **state)
{
    (void)state;
    const int all[] = {CS_OK,           CS_ERR_INVALID,   CS_ERR_NOMEM, CS_ERR_UNSTABLE,
                       CS_ERR_SCRIPT,   CS_ERR_BAD_INPUT, CS_ERR_FAILED};
    const int n = (int)(sizeof all / sizeof *all);
    for (int i = 0; i < n; i++) {
        const char *m = cs_status_message(all[i]);
        assert_true(strlen(m) > 0);
        assert_string_not_equal(m, "unknown status");
        for (int j = 0; j < i; j++) {
            assert_int_not_equal(all[i], all[j]);
            assert_string_not_equal(m, cs_status_message(all[j]));
        }
    }
    assert_string_equal(cs_status_message(CS_ERR_NOMEM), "out of memory");
    assert_string_equal(cs_status_message(-1000), "unknown status");
    assert_string_equal(cs_status_message(1), "unknown status");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_status_has_its_message),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
