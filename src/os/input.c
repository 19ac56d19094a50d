/* SPDX-License-Identifier: Apache-2.0 */
/* See input.h. */
#include "os/input.h"
#include "os/text.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *kind(mode_t m) {
    if (S_ISDIR(m)) return "a directory";
    if (S_ISFIFO(m)) return "a FIFO (named pipe)";
    if (S_ISCHR(m)) return "a character device";
    if (S_ISBLK(m)) return "a block device";
    if (S_ISSOCK(m)) return "a socket";
    return "not a regular file";
}

int vp_os_open_input(const char *path, char *msg, size_t msglen) {
    if (!path || !*path) {
        vp_os_format(msg, msglen, "no input file given");
        return -1;
    }
    /* named first (a socket cannot even be opened: ENXIO), then checked
     * again on what open() gave, in case the name changed between */
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        vp_os_format(msg, msglen,
                     "%s: not a regular file but %s: vdbpack reads its inputs from "
                     "regular files only",
                     path, kind(st.st_mode));
        return -1;
    }
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        int e = errno;
        vp_os_format(msg, msglen, "%s: cannot open file (%s)", path, strerror(e));
        return -1;
    }
    if (fstat(fd, &st) != 0) {
        int e = errno;
        close(fd);
        vp_os_format(msg, msglen, "%s: cannot open file (%s)", path, strerror(e));
        return -1;
    }
    if (!S_ISREG(st.st_mode)) {
        close(fd);
        vp_os_format(msg, msglen,
                     "%s: not a regular file but %s: vdbpack reads its inputs from "
                     "regular files only",
                     path, kind(st.st_mode));
        return -1;
    }
    int fl = fcntl(fd, F_GETFL);
    if (fl >= 0) fcntl(fd, F_SETFL, fl & ~O_NONBLOCK);
    return fd;
}

int vp_os_check_input(const char *path, char *msg, size_t msglen) {
    int fd = vp_os_open_input(path, msg, msglen);
    if (fd < 0) return -1;
    close(fd);
    return 0;
}
