/* fsutil.h: file-system helpers shared by the command's subcommands.
 *
 * Files appear atomically: written as NAME.tmp, every write checked
 * (fwrite, fflush, fclose), then renamed, so a full disk or a killed
 * process never leaves a truncated file under its final name. Local file
 * systems report a full disk at write (they reserve blocks then), NFS at
 * close. Reaching the disk itself (against a power cut) is cs_dir_sync's,
 * once in a while rather than an fsync per file (milliseconds each). */
#ifndef CS_APP_FSUTIL_H
#define CS_APP_FSUTIL_H

#include <stddef.h>
#include <stdio.h>

/* mkdir -p: creates path and its missing parents; returns 0, or -1 with
 * errno set (ENOTDIR when a part exists and is not a folder). */
int cs_make_dirs(const char *path);

/* "a/b" and "path.tmp", malloc'd; NULL when memory runs out. */
char *cs_path_join(const char *a, const char *b);
char *cs_path_tmp(const char *path);

/* Ends a file written through fp as tmp: fflush and fclose, each
 * checked, then renames it to path. Returns 0, or -1 with "cannot write
 * PATH: why" in err and tmp removed. */
int cs_file_commit(FILE *fp, const char *tmp, const char *path, char *err, size_t errlen);

/* Writes len bytes as path atomically (path.tmp, checked, renamed). */
int cs_file_write_atomic(const char *path, const void *data, size_t len, char *err,
                         size_t errlen);

/* syncfs(2) on the file system of dir: everything written so far reaches
 * the disk, and a write-back error (EIO, ENOSPC) shows. Returns 0, or -1
 * with err. */
int cs_dir_sync(const char *dir, char *err, size_t errlen);

/* The whole of a file, NUL-terminated after its *len bytes (malloc'd);
 * NULL with errno set when it cannot be read. */
char *cs_file_read_all(const char *path, size_t *len);

#endif
