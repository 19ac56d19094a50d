/* See subproc.h. */
#include "core/subproc.h"

#include <errno.h>
#include <poll.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

double vp_subproc_now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int vp_subproc_write_all(int fd, const void *buf, size_t n) {
    const char *p = buf;
    while (n) {
        ssize_t w = write(fd, p, n);
        if (w < 0) {
            if (errno == EINTR) continue;
            return -1;
        }
        p += w;
        n -= (size_t)w;
    }
    return 0;
}

int vp_subproc_read_all(int fd, void *buf, size_t n, double deadline) {
    char *p = buf;
    while (n) {
        double left = deadline - vp_subproc_now();
        if (left <= 0) return 2;
        struct pollfd pfd = {fd, POLLIN, 0};
        int pr = poll(&pfd, 1, (int)(left * 1000.0) + 1);
        if (pr < 0) {
            if (errno == EINTR) continue;
            return -1;
        }
        if (pr == 0) return 2;
        ssize_t r = read(fd, p, n);
        if (r < 0) {
            if (errno == EINTR || errno == EAGAIN) continue;
            return -1;
        }
        if (r == 0) return 1;
        p += r;
        n -= (size_t)r;
    }
    return 0;
}

double vp_subproc_timeout(const char *env, double base, double per_mb, size_t file_bytes) {
    const char *v = getenv(env);
    if (v && *v) {
        char *end = NULL;
        double t = strtod(v, &end);
        if (end && *end == '\0' && t > 0) return t;
    }
    return base + per_mb * (double)file_bytes / 1e6;
}
