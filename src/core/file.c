// Opening input files as regular files only (include/drift/file.h).
#include "drift/file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *file_kind(mode_t mode)
{
    return S_ISFIFO(mode)   ? "a FIFO"
           : S_ISCHR(mode)  ? "a character device"
           : S_ISBLK(mode)  ? "a block device"
           : S_ISDIR(mode)  ? "a folder"
           : S_ISSOCK(mode) ? "a socket"
                            : "not a plain file";
}

int drift_input_open(const char *path, char *why, size_t why_cap)
{
    if (why_cap > 0) {
        why[0] = '\0';
    }
    // O_NONBLOCK: opening a FIFO would otherwise wait for a writer; it is refused below.
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) {
        int err = errno;
        if (why_cap > 0 && strerror_r(err, why, why_cap) != 0) {
            snprintf(why, why_cap, "error %d", err);
        }
        errno = err;
        return -1;
    }
    struct stat st;
    if (fstat(fd, &st) != 0) {
        int err = errno;
        if (why_cap > 0 && strerror_r(err, why, why_cap) != 0) {
            snprintf(why, why_cap, "error %d", err);
        }
        close(fd);
        errno = err;
        return -1;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(why, why_cap, "not a regular file (%s)", file_kind(st.st_mode));
        close(fd);
        errno = EINVAL;
        return -1;
    }
    // Reads of a regular file do not block anyway; clear the flag for readers that check it.
    int flags = fcntl(fd, F_GETFL);
    if (flags >= 0) {
        fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
    }
    return fd;
}

FILE *drift_input_fopen(const char *path, char *why, size_t why_cap)
{
    int fd = drift_input_open(path, why, why_cap);
    if (fd < 0) {
        return NULL;
    }
    FILE *f = fdopen(fd, "rb");
    if (!f) {
        int err = errno;
        if (why_cap > 0 && strerror_r(err, why, why_cap) != 0) {
            snprintf(why, why_cap, "error %d", err);
        }
        close(fd);
        errno = err;
    }
    return f;
}
