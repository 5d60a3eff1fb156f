/* lock.h: one run per output folder.
 *
 * A run holds flock(2) on DIR/.lock for its whole life, with "pid PID on
 * host HOST since TIME" written in it. The kernel drops the lock when the
 * process ends however it ends (kill -9 included), so a stale file never
 * blocks a later run; the text only names the holder for the message. */
#ifndef CS_APP_LOCK_H
#define CS_APP_LOCK_H

#include <stddef.h>

typedef struct cs_dir_lock {
    int fd;   /* -1: not held */
} cs_dir_lock;

#define CS_DIR_LOCK_NONE ((cs_dir_lock){-1})

/* Takes the lock of dir (which exists). Returns 0, or -1 with a message in
 * err: who holds it, or why the lock file cannot be used. */
int cs_dir_lock_take(cs_dir_lock *lock, const char *dir, char *err, size_t errlen);
void cs_dir_lock_release(cs_dir_lock *lock);

#endif
