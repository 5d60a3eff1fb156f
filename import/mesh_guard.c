/* mesh_guard.c: assimp in a child process with limits.
 *
 * Checking a file before assimp reads it (mesh_check.c) stops the corrupt
 * files we know of, but not all that assimp 5.2 does to itself: a corrupt
 * binary FBX is known to double-free inside its importer, and any
 * reader may loop, crash or allocate what a file claims. So every mesh file is read in a
 * forked child: RLIMIT_CPU bounds its CPU time, RLIMIT_DATA its memory
 * (counted from what the process already maps: AddressSanitizer reserves
 * terabytes of shadow, which rules RLIMIT_AS out but not a limit on top of
 * it), no core files, and the parent enforces a wall-clock deadline. The
 * result comes back through a pipe as plain bytes; a child that crashes, is
 * killed or answers nonsense means a bad file, never a crash of clothsim.
 * What it costs is measured at the top of mesh_import.c.
 */
#include "import/mesh_internal.h"
#include "common/util.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* ------------------------------------------------------- byte buffers */

void cs_bytes_put(cs_bytes *b, const void *p, size_t n)
{
    if (b->nomem || n == 0)
        return;
    if (b->len + n > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->len + n)
            cap *= 2;
        unsigned char *d = realloc(b->data, cap);
        if (!d) {
            b->nomem = true;
            return;
        }
        b->data = d;
        b->cap = cap;
    }
    memcpy(b->data + b->len, p, n);
    b->len += n;
}

void cs_bytes_put_str(cs_bytes *b, const char *s)
{
    uint32_t n = s ? (uint32_t)strlen(s) : 0;
    cs_bytes_put(b, &n, sizeof n);
    cs_bytes_put(b, s, n);
}

void cs_bytes_free(cs_bytes *b)
{
    free(b->data);
    memset(b, 0, sizeof *b);
}

const void *cs_bytes_take(cs_bytes_reader *r, size_t n)
{
    if (r->bad || n > r->left) {
        r->bad = true;
        return NULL;
    }
    const void *p = r->p;
    r->p += n;
    r->left -= n;
    return p;
}

void cs_bytes_get(cs_bytes_reader *r, void *out, size_t n)
{
    const void *p = cs_bytes_take(r, n);
    if (p)
        memcpy(out, p, n);
    else
        memset(out, 0, n);
}

void cs_bytes_get_str(cs_bytes_reader *r, char *out, size_t len)
{
    uint32_t n;
    cs_bytes_get(r, &n, sizeof n);
    const char *s = cs_bytes_take(r, n);
    size_t k = s ? (n < len ? n : len - 1) : 0;
    if (k)
        memcpy(out, s, k);
    out[k] = '\0';
}

char *cs_bytes_get_strdup(cs_bytes_reader *r)
{
    uint32_t n;
    cs_bytes_get(r, &n, sizeof n);
    const char *s = cs_bytes_take(r, n);
    char *d = s ? malloc((size_t)n + 1) : NULL;
    if (d) {
        memcpy(d, s, n);
        d[n] = '\0';
    }
    return d;
}

/* ------------------------------------------------------------- limits */

typedef struct limits {
    double cpu_seconds;      /* RLIMIT_CPU */
    double wall_seconds;     /* the parent's deadline */
    double memory_mb;        /* RLIMIT_DATA above what is mapped at the fork */
} limits;

/* A positive number from the environment, else 0. */
static double env_number(const char *name)
{
    const char *s = getenv(name);
    char *end;
    double v = s ? strtod(s, &end) : 0;
    return s && end != s && *end == '\0' && v > 0 && v < 1e9 ? v : 0;
}

/* Generous for any real file (assimp reads tens of MB a second and needs a
 * few times a file's size in memory, more for compressed FBX), tight
 * enough that a file which lies costs seconds, not the machine: 30 s of CPU
 * plus 1 s per MB, 1 GiB plus 64 times the file. The environment's
 * CLOTHSIM_IMPORT_SECONDS and CLOTHSIM_IMPORT_MEMORY (MB) replace them. */
static limits limits_for(const char *path)
{
    struct stat st;
    double mb = stat(path, &st) == 0 ? (double)st.st_size / 1048576.0 : 0;
    limits l = {30 + mb, 0, 1024 + 64 * mb};
    double s = env_number("CLOTHSIM_IMPORT_SECONDS"), m = env_number("CLOTHSIM_IMPORT_MEMORY");
    if (s > 0)
        l.cpu_seconds = s;
    if (m > 0)
        l.memory_mb = m;
    /* a busy machine gives the child less than a core */
    l.wall_seconds = 2 * l.cpu_seconds + 5;
    return l;
}

/* Bytes of data segment (VmData) mapped now, 0 if unknown. */
static double mapped_data_bytes(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    double kb = 0;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "VmData: %lf kB", &kb) == 1)
            break;
    if (f)
        fclose(f);
    return kb * 1024;
}

/* Lowers a limit to soft (and hard, where the kernel kills), never raises it. */
static void set_limit(int resource, double soft, double hard)
{
    struct rlimit cur, lim;
    if (getrlimit(resource, &cur) != 0)
        return;
    lim.rlim_cur = soft >= 1.8e19 ? RLIM_INFINITY : (rlim_t)soft;
    lim.rlim_max = hard >= 1.8e19 ? RLIM_INFINITY : (rlim_t)hard;
    if (cur.rlim_max != RLIM_INFINITY && cur.rlim_max < lim.rlim_max)
        lim.rlim_max = cur.rlim_max;
    if (lim.rlim_cur > lim.rlim_max)
        lim.rlim_cur = lim.rlim_max;
    setrlimit(resource, &lim);
}

/* ------------------------------------------------------------ child */

#define GUARD_MAGIC 0x31475343u   /* "CSG1" */

static bool write_all(int fd, const unsigned char *p, size_t n)
{
    while (n > 0) {
        ssize_t w = write(fd, p, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return false;
        p += w;
        n -= (size_t)w;
    }
    return true;
}

static _Noreturn void child_main(int fd, const limits *l, cs_guarded_fn fn, void *ctx)
{
    /* the parent's handlers (a test framework's, which would carry on
     * after a crash here; the command's for Ctrl-C) are not the child's */
    static const int sigs[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGXCPU,
                               SIGPIPE, SIGINT, SIGTERM};
    for (size_t i = 0; i < sizeof sigs / sizeof *sigs; i++)
        signal(sigs[i], SIG_DFL);
    set_limit(RLIMIT_CORE, 0, 0);
    /* SIGXCPU at the limit, SIGKILL two seconds later if it is ignored */
    set_limit(RLIMIT_CPU, l->cpu_seconds, l->cpu_seconds + 2);
    double mapped = mapped_data_bytes();
    if (mapped > 0)
        set_limit(RLIMIT_DATA, mapped + l->memory_mb * 1048576.0,
                  mapped + l->memory_mb * 1048576.0);

    cs_bytes payload = {0}, msg = {0};
    char err[1024] = "";
    int32_t rc = fn(ctx, &payload, err, sizeof err);
    if (payload.nomem && rc == CS_OK) {
        rc = CS_ERR_NOMEM;
        snprintf(err, sizeof err, "out of memory");
    }
    uint32_t magic = GUARD_MAGIC;
    uint64_t n = payload.nomem ? 0 : payload.len;
    cs_bytes_put(&msg, &magic, sizeof magic);
    cs_bytes_put(&msg, &rc, sizeof rc);
    cs_bytes_put_str(&msg, err);
    cs_bytes_put(&msg, &n, sizeof n);
    bool ok = !msg.nomem && write_all(fd, msg.data, msg.len) && write_all(fd, payload.data, n);
    /* _exit: no atexit handlers, no stdio flushed twice, no leak check of
     * a process that is about to vanish */
    _exit(ok ? 0 : 3);
}

/* ----------------------------------------------------------- parent */

/* A child stuck on a lock it inherited uses no CPU, while one reading a
 * file always does: fork copies only the calling thread, so a lock another
 * thread held at that moment stays held in the child for ever. That
 * happens: under AddressSanitizer, whose allocator has no fork handler, a
 * fork while OpenVDB's log4cplus starts its thread pool (at load) left
 * about one test run in four waiting for the whole deadline. Such a child
 * is started again, a few times, before the file is blamed. */
static const double STALL_SECONDS = 3;
enum { GUARD_STARTS = 3 };

/* CPU clock ticks process pid has used, -1 if unknown. */
static long long process_ticks(pid_t pid)
{
    char path[64], buf[1024];
    snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    const char *p = strrchr(buf, ')'); /* the command name may hold anything */
    unsigned long long user, sys;
    if (!p || sscanf(p + 1, " %*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu", &user,
                     &sys) != 2)
        return -1;
    return (long long)(user + sys);
}

typedef enum { ANSWERED, TIMED_OUT, STALLED } answer;

/* Reads the child's answer until it closes the pipe, the deadline, or the
 * child's CPU time stands still for STALL_SECONDS. */
static answer read_answer(int fd, pid_t pid, double deadline, cs_bytes *buf)
{
    unsigned char chunk[65536];
    long long ticks = process_ticks(pid);
    double moved = cs_now();
    for (;;) {
        double now = cs_now(), left = deadline - now;
        if (left <= 0)
            return TIMED_OUT;
        long long t = process_ticks(pid);
        if (t != ticks) {
            ticks = t;
            moved = now;
        } else if (t >= 0 && now - moved > STALL_SECONDS) {
            return STALLED;
        }
        struct pollfd p = {.fd = fd, .events = POLLIN};
        int r = poll(&p, 1, left > 0.5 ? 500 : (int)(left * 1000) + 1);
        if (r <= 0)
            continue; /* EINTR or a quiet half second: the clocks are checked above */
        ssize_t n = read(fd, chunk, sizeof chunk);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return ANSWERED;
        cs_bytes_put(buf, chunk, (size_t)n);
    }
}

/* CPU seconds of the children reaped so far. */
static double children_cpu(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_CHILDREN, &ru) != 0)
        return 0;
    return (double)ru.ru_utime.tv_sec + (double)ru.ru_stime.tv_sec +
           1e-6 * (double)(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

/* Why a child gave no answer, as the end of "cannot read FILE: ...". */
static void describe_death(int status, answer got, double cpu, const limits *l, char *why,
                           size_t len)
{
    if (got == STALLED)
        snprintf(why, len, "the reading process stopped using the CPU, %d times (stuck, not "
                 "reading: a lock held at the fork; not the file's fault)", GUARD_STARTS);
    else if (got == TIMED_OUT || (WIFSIGNALED(status) && (WTERMSIG(status) == SIGXCPU ||
                                                        cpu >= l->cpu_seconds)))
        snprintf(why, len, "reading it took longer than %g s, so it is probably malformed "
                 "(CLOTHSIM_IMPORT_SECONDS sets the limit)",
                 got == TIMED_OUT ? l->wall_seconds : l->cpu_seconds);
    else if (WIFSIGNALED(status))
        snprintf(why, len, "assimp crashed reading it (%s): the file is corrupt or not what its "
                 "name says", strsignal(WTERMSIG(status)));
    else
        snprintf(why, len, "assimp stopped reading it without an answer (exit status %d): the "
                 "file is probably corrupt, or needs more than %g MB of memory "
                 "(CLOTHSIM_IMPORT_MEMORY sets the limit)",
                 WIFEXITED(status) ? WEXITSTATUS(status) : -1, l->memory_mb);
}

/* CLOTHSIM_IMPORT_ISOLATION=0 runs fn in this process, unprotected: for a
 * debugger, and for tests that read thousands of files they wrote. */
static int run_here(cs_guarded_fn fn, void *ctx, cs_bytes *result, char *err, size_t errlen)
{
    int rc = fn(ctx, result, err, errlen);
    if (result->nomem || rc == CS_ERR_NOMEM) {
        cs_bytes_free(result);
        cs_mesh_set_err(err, errlen, "out of memory");
        return CS_ERR_NOMEM;
    }
    return rc;
}

int cs_guard_run(const char *path, cs_guarded_fn fn, void *ctx, cs_bytes *result, char *err,
                 size_t errlen)
{
    memset(result, 0, sizeof *result);
    const char *iso = getenv("CLOTHSIM_IMPORT_ISOLATION");
    if (iso && !strcmp(iso, "0"))
        return run_here(fn, ctx, result, err, errlen);
    limits l = limits_for(path);
    int fds[2];
    if (pipe(fds) != 0) {
        cs_mesh_set_err(err, errlen, "cannot read %s: no pipe to a reading process: %s", path,
                        strerror(errno));
        return CS_ERR_NOMEM;
    }
    fflush(NULL);   /* nothing buffered is written twice */
    cs_bytes buf = {0};
    answer got = STALLED;
    int status = 0;
    double cpu = 0;
    for (int start = 0; start < GUARD_STARTS && got == STALLED; start++) {
        if (start > 0 && pipe(fds) != 0) {
            cs_mesh_set_err(err, errlen, "cannot read %s: no pipe to a reading process: %s",
                            path, strerror(errno));
            return CS_ERR_NOMEM;
        }
        double cpu_before = children_cpu();
        pid_t pid = fork();
        if (pid < 0) {
            int e = errno;
            close(fds[0]);
            close(fds[1]);
            cs_mesh_set_err(err, errlen, "cannot read %s: cannot start a reading process: %s",
                            path, strerror(e));
            return CS_ERR_NOMEM;
        }
        if (pid == 0) {
            close(fds[0]);
            child_main(fds[1], &l, fn, ctx);
        }
        close(fds[1]);
        cs_bytes_free(&buf);
        got = read_answer(fds[0], pid, cs_now() + l.wall_seconds, &buf);
        close(fds[0]);
        if (got != ANSWERED)
            kill(pid, SIGKILL);
        while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
        }
        cpu = children_cpu() - cpu_before; /* this child's, once reaped */
    }
    bool answered = got == ANSWERED;

    int rc = CS_ERR_BAD_INPUT;
    cs_bytes_reader r = {buf.data, buf.len, buf.nomem};
    uint32_t magic = 0;
    int32_t crc = 0;
    uint64_t n = 0;
    char msg[1024];
    cs_bytes_get(&r, &magic, sizeof magic);
    cs_bytes_get(&r, &crc, sizeof crc);
    cs_bytes_get_str(&r, msg, sizeof msg);
    cs_bytes_get(&r, &n, sizeof n);
    if (buf.nomem) {
        cs_mesh_set_err(err, errlen, "cannot read %s: out of memory", path);
        rc = CS_ERR_NOMEM;
    } else if (!answered || !WIFEXITED(status) || WEXITSTATUS(status) != 0 || r.bad ||
               magic != GUARD_MAGIC || n != r.left) {
        char why[512];
        describe_death(status, got, cpu, &l, why, sizeof why);
        cs_mesh_set_err(err, errlen, "cannot read %s: %s", path, why);
    } else if (crc == CS_ERR_NOMEM) {
        /* in the child, most likely the limit: the file asked for more */
        cs_mesh_set_err(err, errlen, "cannot read %s: reading it needs more than %g MB of memory "
                        "(CLOTHSIM_IMPORT_MEMORY sets the limit); the file may claim more than it "
                        "holds", path, l.memory_mb);
    } else {
        /* the payload is what follows the header; it comes with a failure
         * too (the import's report) */
        if (crc != CS_OK)
            cs_mesh_set_err(err, errlen, "%s", msg);
        memmove(buf.data, r.p, r.left);
        buf.len = r.left;
        *result = buf;
        return crc == CS_OK ? CS_OK : CS_ERR_BAD_INPUT;
    }
    cs_bytes_free(&buf);
    return rc;
}
