/* util.c: the helpers every folder shares (util.h). */
#define _GNU_SOURCE /* syncfs */
#include "common/util.h"

#include <errno.h>
#include <stdarg.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

double cs_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int cs_make_dirs(const char *path)
{
    if (!*path) {
        errno = ENOENT;
        return -1;
    }
    char *p = strdup(path);
    if (!p)
        return -1;
    int rc = 0;
    for (char *s = p + 1;; s++) {
        if (*s == '/' || *s == '\0') {
            char keep = *s;
            *s = '\0';
            struct stat st;
            if (mkdir(p, 0777) != 0 && errno != EEXIST)
                rc = -1;
            else if (stat(p, &st) != 0)
                rc = -1;
            else if (!S_ISDIR(st.st_mode)) {
                errno = ENOTDIR;
                rc = -1;
            }
            *s = keep;
            if (rc != 0 || keep == '\0')
                break;
        }
    }
    free(p);
    return rc;
}

char *cs_path_join(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    char *p = malloc(la + lb + 2);
    if (p) {
        memcpy(p, a, la);
        p[la] = '/';
        memcpy(p + la + 1, b, lb + 1);
    }
    return p;
}

char *cs_path_tmp(const char *path)
{
    size_t len = strlen(path);
    char *tmp = malloc(len + 5);
    if (tmp) {
        memcpy(tmp, path, len);
        memcpy(tmp + len, ".tmp", 5);
    }
    return tmp;
}

int cs_write_atomic(const char *path, bool unique_tmp, cs_file_filler fill, void *ctx,
                    char *err, size_t errlen)
{
    size_t len = strlen(path);
    char *tmp = malloc(len + 32);
    if (!tmp) {
        snprintf(err, errlen, "cannot write %s: out of memory", path);
        return -1;
    }
    if (unique_tmp) /* a name of this process's own */
        snprintf(tmp, len + 32, "%s.tmp%ld", path, (long)getpid());
    else
        snprintf(tmp, len + 32, "%s.tmp", path);
    char why[1024] = "";
    int rc = 0;
    if (fill(tmp, ctx, why, sizeof why) != 0) {
        snprintf(err, errlen, "cannot write %s: %s", path, why[0] ? why : strerror(EIO));
        rc = -1;
    } else if (rename(tmp, path) != 0) {
        snprintf(err, errlen, "cannot rename %s to %s: %s", tmp, path, strerror(errno));
        rc = -1;
    }
    if (rc != 0)
        remove(tmp);
    free(tmp);
    return rc;
}

typedef struct bytes {
    const void *data;
    size_t len;
} bytes;

FILE *cs_file_open_checked(const char *path, const char *mode, char *why, size_t whylen)
{
    errno = 0;
    FILE *fp = fopen(path, mode);
    if (!fp && why)
        snprintf(why, whylen, "%s", strerror(errno ? errno : EIO));
    return fp;
}

int cs_file_close_checked(FILE *fp, char *why, size_t whylen)
{
    int failed = fflush(fp) != 0 || ferror(fp);
    int saved = errno;
    if (fclose(fp) != 0 && !failed) {
        failed = 1;
        saved = errno;
    }
    if (failed && why)
        snprintf(why, whylen, "%s", strerror(saved ? saved : EIO));
    return failed ? -1 : 0;
}

/* The bytes as tmp, every write checked (fwrite, fflush, fclose). */
static int fill_bytes(const char *tmp, void *ctx, char *why, size_t whylen)
{
    const bytes *b = ctx;
    FILE *fp = cs_file_open_checked(tmp, "wb", why, whylen);
    if (!fp)
        return -1;
    fwrite(b->data, 1, b->len, fp); /* a short write sets the error indicator */
    return cs_file_close_checked(fp, why, whylen);
}

int cs_file_write_atomic(const char *path, const void *data, size_t len, char *err,
                         size_t errlen)
{
    bytes b = {data, len};
    return cs_write_atomic(path, false, fill_bytes, &b, err, errlen);
}

char *cs_file_read_all(const char *path, size_t *len)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return NULL;
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap);
    while (buf) {
        n += fread(buf + n, 1, cap - 1 - n, fp);
        if (ferror(fp) || feof(fp))
            break;
        char *grown = realloc(buf, 2 * cap);
        if (!grown) {
            free(buf);
            errno = ENOMEM;
        }
        buf = grown;
        cap *= 2;
    }
    bool failed = !buf || ferror(fp);
    int saved = errno;
    fclose(fp);
    if (failed) {
        free(buf);
        errno = saved ? saved : EIO;
        return NULL;
    }
    buf[n] = '\0';
    *len = n;
    return buf;
}

int cs_dir_sync(const char *dir, char *err, size_t errlen)
{
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0 || syncfs(fd) != 0) {
        snprintf(err, errlen, "cannot write %s to the disk: %s", dir, strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    close(fd);
    return 0;
}

void cs_errorf(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}
