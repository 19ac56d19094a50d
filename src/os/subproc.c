/* SPDX-License-Identifier: Apache-2.0 */
/* See subproc.h. */
#include "os/subproc.h"

#include <signal.h>

#include <dirent.h>
#include <errno.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
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

void vp_subproc_watch_start(vp_subproc_watch *w, pid_t pid, double timeout) {
    w->pid = pid;
    w->timeout = timeout;
    w->start = vp_subproc_now();
    w->deadline = w->start + timeout;
}

/* The fields of /proc/<path> after the command name (which may hold
 * spaces), in buf; NULL when it cannot be read. */
static const char *proc_stat_fields(const char *path, char *buf, size_t size) {
    FILE *f = fopen(path, "r");
    if (!f) return NULL;
    size_t n = fread(buf, 1, size - 1, f);
    fclose(f);
    buf[n] = '\0';
    const char *p = strrchr(buf, ')');
    return p && p[1] == ' ' ? p + 2 : NULL;
}

/* 1 when some thread of the child is runnable (state R) and the child has
 * used less than `cpu` seconds of CPU time; 0 otherwise or when /proc
 * cannot tell (then the deadline stands). */
static int child_starved(pid_t pid, double cpu) {
    char path[64], buf[1024];
    snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
    const char *p = proc_stat_fields(path, buf, sizeof buf);
    unsigned long long ut = 0, st = 0;
    if (!p || sscanf(p, "%*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu", &ut, &st) != 2)
        return 0;
    long hz = sysconf(_SC_CLK_TCK);
    if (hz <= 0 || (double)(ut + st) / (double)hz >= cpu) return 0;
    snprintf(path, sizeof path, "/proc/%d/task", (int)pid);
    DIR *d = opendir(path);
    if (!d) return 0;
    int runnable = 0;
    for (struct dirent *e; !runnable && (e = readdir(d));) {
        if (e->d_name[0] == '.') continue;
        char tp[128];
        snprintf(tp, sizeof tp, "/proc/%d/task/%.32s/stat", (int)pid, e->d_name);
        p = proc_stat_fields(tp, buf, sizeof buf);
        runnable = p && p[0] == 'R';
    }
    closedir(d);
    return runnable;
}

/* 1 when the watch's deadline was moved on (see vp_subproc_watch). */
static int extend(vp_subproc_watch *w) {
    double now = vp_subproc_now();
    if (now >= w->start + 10.0 * w->timeout || !child_starved(w->pid, 0.5 * w->timeout))
        return 0;
    w->deadline = now + 1.0;
    return 1;
}

int vp_subproc_read_all(int fd, void *buf, size_t n, vp_subproc_watch *w) {
    char *p = buf;
    while (n) {
        double left = w->deadline - vp_subproc_now();
        if (left <= 0) {
            if (!extend(w)) return 2;
            continue;
        }
        struct pollfd pfd = {fd, POLLIN, 0};
        int pr = poll(&pfd, 1, (int)(left * 1000.0) + 1);
        if (pr < 0) {
            if (errno == EINTR) continue;
            return -1;
        }
        if (pr == 0) continue; /* the deadline, checked above */
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

void vp_subproc_child_signals(void) {
    const int sigs[] = {SIGPIPE, SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) signal(sigs[i], SIG_DFL);
}
