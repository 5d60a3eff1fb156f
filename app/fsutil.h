/* fsutil.h: file-system helpers shared by the command's subcommands. */
#ifndef CS_APP_FSUTIL_H
#define CS_APP_FSUTIL_H

/* mkdir -p: creates path and its missing parents; returns 0, or -1 with
 * errno set (ENOTDIR when a part exists and is not a folder). */
int cs_make_dirs(const char *path);

#endif
