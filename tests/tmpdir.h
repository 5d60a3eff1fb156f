/* tmpdir.h: a test program's temporary folder, made before its tests and
 * removed after them (cmocka group setup and teardown). */
#ifndef CS_TEST_TMPDIR_H
#define CS_TEST_TMPDIR_H

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

static char tmpdir[256];

static int tmpdir_make(void **state)
{
    (void)state;
    snprintf(tmpdir, sizeof tmpdir, "/tmp/cs_test_XXXXXX");
    return mkdtemp(tmpdir) ? 0 : -1;
}

static int tmpdir_remove(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    return system(cmd) == 0 ? 0 : -1;
}

#endif
