/* util.h: the few helpers every folder shares (import, sim, render, app):
 * a monotonic clock, mkdir -p, reading a whole file, and files that appear
 * atomically. Depends on nothing but the C library and POSIX; C and C++
 * (import/levelset.cpp) include it.
 *
 * Files appear atomically: written as NAME.tmp, every write checked
 * (fwrite, fflush, fclose), then renamed, so a full disk or a killed
 * process never leaves a truncated file under its final name. Local file
 * systems report a full disk at write (they reserve blocks then), NFS at
 * close. Reaching the disk itself (against a power cut) is cs_dir_sync's,
 * once in a while rather than an fsync per file (milliseconds each). */
#ifndef CS_COMMON_UTIL_H
#define CS_COMMON_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Seconds on the monotonic clock (CLOCK_MONOTONIC): for durations only. */
double cs_now(void);

/* printf into err (errlen bytes) when err is not NULL: the one way import,
 * render and app fill an error buffer. */
void cs_errorf(char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* mkdir -p: creates path and its missing parents; returns 0, or -1 with
 * errno set (ENOTDIR when a part exists and is not a folder). */
int cs_make_dirs(const char *path);

/* "a/b" and "path.tmp", malloc'd; NULL when memory runs out. */
char *cs_path_join(const char *a, const char *b);
char *cs_path_tmp(const char *path);

/* Fills the temporary file tmp (by its name: libraries that open files
 * themselves); returns 0, or -1 with the reason in why. */
typedef int (*cs_file_filler)(const char *tmp, void *ctx, char *why, size_t whylen);

/* Writes path atomically: fill writes path.tmp (with unique_tmp,
 * path.tmp<pid>, for a file other processes may write at the same time),
 * which is then renamed to path. Returns 0, or -1 with "cannot write PATH:
 * why" in err and the temporary file removed. */
int cs_write_atomic(const char *path, bool unique_tmp, cs_file_filler fill, void *ctx,
                    char *err, size_t errlen);

/* fopen(path, mode), or NULL with the reason in why (when not NULL). */
FILE *cs_file_open_checked(const char *path, const char *mode, char *why, size_t whylen);

/* Flushes and closes fp, every step checked: returns 0, or -1 with the
 * reason (the first error of the stream's writes, the flush or the close)
 * in why (when not NULL). fp is closed either way. */
int cs_file_close_checked(FILE *fp, char *why, size_t whylen);

/* Writes len bytes as path atomically (cs_write_atomic). */
int cs_file_write_atomic(const char *path, const void *data, size_t len, char *err,
                         size_t errlen);

/* The whole of a file, NUL-terminated after its *len bytes (malloc'd);
 * NULL with errno set when it cannot be read. */
char *cs_file_read_all(const char *path, size_t *len);

/* syncfs(2) on the file system of dir: everything written so far reaches
 * the disk, and a write-back error (EIO, ENOSPC) shows. Returns 0, or -1
 * with err. */
int cs_dir_sync(const char *dir, char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif
