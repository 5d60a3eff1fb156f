/* lock.c: flock(2) on DIR/.lock, one run per output folder. */
#include "app/lock.h"

#include "common/util.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <time.h>
#include <unistd.h>

/* The holder's line, without its newline; "" when it wrote none yet. */
static void read_holder(int fd, char *buf, size_t len)
{
    ssize_t got = pread(fd, buf, len - 1, 0);
    buf[got > 0 ? got : 0] = '\0';
    buf[strcspn(buf, "\n")] = '\0';
}

int cs_dir_lock_take(cs_dir_lock *lock, const char *dir, char *err, size_t errlen)
{
    lock->fd = -1;
    char *path = cs_path_join(dir, ".lock");
    if (!path) {
        snprintf(err, errlen, "cannot lock %s: out of memory", dir);
        return -1;
    }
    int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) {
        snprintf(err, errlen, "cannot lock the output folder: %s: %s", path, strerror(errno));
        free(path);
        return -1;
    }
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        int e = errno;
        char holder[256];
        read_holder(fd, holder, sizeof holder);
        if (e == EWOULDBLOCK)
            snprintf(err, errlen,
                     "%s is in use by another clothsim run (%s, holding %s); wait for it to "
                     "end or choose another folder with -o",
                     dir, holder[0] ? holder : "it has not written who it is yet", path);
        else
            snprintf(err, errlen, "cannot lock the output folder: %s: %s", path, strerror(e));
        close(fd);
        free(path);
        return -1;
    }
    char host[128] = "unknown host", when[64] = "";
    gethostname(host, sizeof host);
    host[sizeof host - 1] = '\0';
    time_t now = time(NULL);
    struct tm tm;
    if (localtime_r(&now, &tm))
        strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S %z", &tm);
    char line[512];
    int len = snprintf(line, sizeof line, "pid %ld on host %s since %s\n", (long)getpid(), host,
                       when);
    if (len < 0 || (size_t)len >= sizeof line)
        len = (int)strlen(line);
    /* the text is for the message of a run refused; the lock is the flock */
    if (ftruncate(fd, 0) != 0 || pwrite(fd, line, (size_t)len, 0) != len) {
        snprintf(err, errlen, "cannot write %s: %s", path, strerror(errno ? errno : EIO));
        close(fd);
        free(path);
        return -1;
    }
    free(path);
    lock->fd = fd;
    return 0;
}

void cs_dir_lock_release(cs_dir_lock *lock)
{
    if (lock->fd >= 0)
        close(lock->fd); /* drops the flock; the file stays, harmless */
    lock->fd = -1;
}
