/* test_mesh_guard.c: the child process that reads mesh files
 * (import/mesh_guard.c): what a reader does to itself stays in the child
 * and comes back as a sentence, in bounded time and memory. The
 * readers are stand-ins that crash, double-free, spin, allocate without
 * end or vanish, as assimp 5.2 did on corrupt files. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <signal.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "import/mesh_internal.h"

static char path[256];

static int setup(void **state)
{
    (void)state;
    snprintf(path, sizeof path, "/tmp/cs_test_mesh_guard_XXXXXX");
    int fd = mkstemp(path);
    if (fd < 0)
        return -1;
    close(fd);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    return unlink(path);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int answers(void *ctx, cs_bytes *out, char *err, size_t errlen)
{
    (void)err;
    (void)errlen;
    cs_bytes_put_str(out, ctx);
    return CS_OK;
}

static int refuses(void *ctx, cs_bytes *out, char *err, size_t errlen)
{
    (void)ctx;
    cs_bytes_put_str(out, "report");
    snprintf(err, errlen, "the file is bad");
    return CS_ERR_BAD_INPUT;
}

/* What a stand-in reader does wrong. */
typedef enum misdeed { SEGFAULT, DOUBLE_FREE, SPIN, SLEEP, ALLOCATE, VANISH } misdeed;

static int misbehaves(void *ctx, cs_bytes *out, char *err, size_t errlen)
{
    (void)out;
    switch (*(const misdeed *)ctx) {
    case SEGFAULT:
        raise(SIGSEGV);
        break;
    case DOUBLE_FREE: {
        char *volatile p = malloc(64);
        free(p);
        free(p);
        break;
    }
    case SPIN:
        for (volatile unsigned long i = 0;; i++) {
        }
    case SLEEP:
        for (;;)
            pause();   /* stuck without using CPU, e.g. on a lock held at the fork */
    case ALLOCATE:
        /* 64 MB at a time, touched, until malloc says no (as a reader
         * reports it) or the sanitizer's allocator stops the child */
        for (int i = 0; i < 1024; i++) {
            char *p = malloc(64 << 20);
            if (!p) {
                snprintf(err, errlen, "out of memory");
                return CS_ERR_NOMEM;
            }
            memset(p, 1, 64 << 20);
        }
        break;
    case VANISH:
        _exit(7);
    }
    return CS_OK;
}

static void expect_failure(misdeed what, const char *want, double max_seconds)
{
    char err[1024] = "";
    cs_bytes res;
    double t0 = now();
    int rc = cs_guard_run(path, misbehaves, &what, &res, err, sizeof err);
    double took = now() - t0;
    cs_bytes_free(&res);
    print_message("%.2f s: %s\n", took, err);
    assert_int_equal(rc, CS_ERR_BAD_INPUT);
    assert_non_null(strstr(err, path));
    if (!strstr(err, want))
        fail_msg("'%s' lacks '%s'", err, want);
    assert_true(took < max_seconds);
}

static void test_answer_comes_back(void **state)
{
    (void)state;
    char err[256] = "";
    cs_bytes res;
    assert_int_equal(cs_guard_run(path, answers, "a mesh", &res, err, sizeof err), CS_OK);
    cs_bytes_reader r = {res.data, res.len, false};
    char got[32];
    cs_bytes_get_str(&r, got, sizeof got);
    assert_false(r.bad);
    assert_string_equal(got, "a mesh");
    cs_bytes_free(&res);

    /* a refusal brings its sentence and what was written (a report) */
    assert_int_equal(cs_guard_run(path, refuses, NULL, &res, err, sizeof err),
                     CS_ERR_BAD_INPUT);
    assert_string_equal(err, "the file is bad");
    r = (cs_bytes_reader){res.data, res.len, false};
    cs_bytes_get_str(&r, got, sizeof got);
    assert_string_equal(got, "report");
    cs_bytes_free(&res);
}

static void test_crashes_stay_in_the_child(void **state)
{
    (void)state;
    expect_failure(SEGFAULT, "crashed", 30);
    /* glibc aborts (a crash), AddressSanitizer reports and exits 1 */
    expect_failure(DOUBLE_FREE, "assimp", 30);
    expect_failure(VANISH, "without an answer (exit status 7)", 30);
}

static void test_time_is_bounded(void **state)
{
    (void)state;
    setenv("CLOTHSIM_IMPORT_SECONDS", "1", 1);
    expect_failure(SPIN, "took longer than 1 s", 10);
    /* a child whose CPU time stands still is stuck, not reading: started
     * again, then reported, well before the parent's 7 s deadline */
    expect_failure(SLEEP, "stopped using the CPU, 3 times", 15);
    unsetenv("CLOTHSIM_IMPORT_SECONDS");
}

/* Stuck the first time only (as on a lock held at the fork), then an
 * answer: the stuck child is started again and the file is read. */
static int stuck_once(void *ctx, cs_bytes *out, char *err, size_t errlen)
{
    (void)err;
    (void)errlen;
    int fd = open(ctx, O_CREAT | O_EXCL | O_WRONLY, 0600);
    if (fd >= 0) { /* the first child makes the marker and stops */
        close(fd);
        for (;;)
            pause();
    }
    cs_bytes_put_str(out, "read");
    return CS_OK;
}

static void test_stuck_child_starts_again(void **state)
{
    (void)state;
    char marker[] = "/tmp/clothsim-guard-XXXXXX";
    int fd = mkstemp(marker);
    assert_true(fd >= 0);
    close(fd);
    unlink(marker);
    char err[256] = "";
    cs_bytes res;
    double t0 = now();
    assert_int_equal(cs_guard_run(path, stuck_once, marker, &res, err, sizeof err),
                     CS_OK);
    double took = now() - t0;
    cs_bytes_reader r = {res.data, res.len, false};
    char got[32];
    cs_bytes_get_str(&r, got, sizeof got);
    assert_string_equal(got, "read");
    cs_bytes_free(&res);
    unlink(marker);
    print_message("%.2f s with one stuck start\n", took);
    assert_true(took > 3 && took < 10);
}

static void test_memory_is_bounded(void **state)
{
    (void)state;
    setenv("CLOTHSIM_IMPORT_MEMORY", "256", 1);
    expect_failure(ALLOCATE, "more than 256 MB of memory", 60);
    unsetenv("CLOTHSIM_IMPORT_MEMORY");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_answer_comes_back),
        cmocka_unit_test(test_crashes_stay_in_the_child),
        cmocka_unit_test(test_time_is_bounded),
        cmocka_unit_test(test_stuck_child_starts_again),
        cmocka_unit_test(test_memory_is_bounded),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
