/* SPDX-License-Identifier: Apache-2.0 */
/* See subproc.h. */
#include "os/subproc.h"

#include <signal.h>

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

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
    w->guard = NULL;
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
    if (now >= w->start + 10.0 * w->timeout || !child_starved(w->pid, 0.5 * w->timeout)) return 0;
    w->deadline = now + 1.0;
    return 1;
}

int vp_subproc_read_all(int fd, void *buf, size_t n, vp_subproc_watch *w) {
    char *p = buf;
    const vp_subproc_guard *g = w->guard;
    while (n) {
        if (g && g->cancel && g->cancel(g->user)) return 3;
        double left = w->deadline - vp_subproc_now();
        if (left <= 0) {
            if (!extend(w)) return 2;
            continue;
        }
        /* a tenth of a second at a time while someone may cancel */
        if (g && g->cancel && left > 0.1) left = 0.1;
        struct pollfd pfd = {fd, POLLIN, 0};
        int pr = poll(&pfd, 1, (int)(left * 1000.0) + 1);
        if (pr < 0) {
            if (errno == EINTR) continue;
            return -1;
        }
        if (pr == 0) continue; /* the deadline or the cancel, checked above */
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

int vp_subproc_pipe(int fds[2]) {
    int p[2];
    if (pipe(p) != 0) return -1;
    int e = 0;
    fds[0] = fcntl(p[0], F_DUPFD_CLOEXEC, 3);
    if (fds[0] < 0) e = errno;
    fds[1] = e ? -1 : fcntl(p[1], F_DUPFD_CLOEXEC, 3);
    if (!e && fds[1] < 0) e = errno;
    close(p[0]);
    close(p[1]);
    if (e) {
        if (fds[0] >= 0) close(fds[0]);
        errno = e;
        return -1;
    }
    return 0;
}

/* The child's address space now (bytes), from /proc/self/statm; 0 when it
 * cannot be read. Async-signal-safe calls only (a child of a threaded
 * parent). */
static uint64_t address_space(void) {
    int fd = open("/proc/self/statm", O_RDONLY | O_CLOEXEC);
    if (fd < 0) return 0;
    char buf[64];
    ssize_t n = read(fd, buf, sizeof buf - 1);
    close(fd);
    uint64_t pages = 0;
    for (ssize_t i = 0; i < n && buf[i] >= '0' && buf[i] <= '9'; i++)
        pages = 10 * pages + (uint64_t)(buf[i] - '0');
    long psz = sysconf(_SC_PAGESIZE);
    return psz > 0 ? pages * (uint64_t)psz : 0;
}

static void child_setup(pid_t parent, const vp_subproc_guard *g) {
    setpgid(0, 0);
#ifdef __linux__
    prctl(PR_SET_PDEATHSIG, SIGKILL);
#endif
    /* the parent died before the line above: no one will read or end it */
    if (getppid() != parent) _exit(125);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sigemptyset(&sa.sa_mask);
    sa.sa_handler = SIG_DFL;
    for (int sig = 1; sig < 65; sig++)
        if (sig != SIGKILL && sig != SIGSTOP)
            sigaction(sig, &sa, NULL); /* (errors: not a signal) */
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, NULL);
    int null = open("/dev/null", O_RDWR);
    if (null >= 0) {
        for (int fd = 0; fd < 3; fd++)
            if (null != fd) dup2(null, fd);
        if (null > 2) close(null);
    }
    /* memory: what it has now (the parent's mappings, inherited) plus the
     * bound, never above the limit the caller already set */
    uint64_t budget = g ? g->max_bytes : 0;
    if (!budget) {
        long pages = sysconf(_SC_PHYS_PAGES), psz = sysconf(_SC_PAGESIZE);
        budget = pages > 0 && psz > 0 ? (uint64_t)pages * (uint64_t)psz : 0;
    }
    if (budget) {
        uint64_t want = address_space() + budget;
        struct rlimit rl;
        if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_max != RLIM_INFINITY &&
            (uint64_t)rl.rlim_max < want)
            want = (uint64_t)rl.rlim_max;
        rl.rlim_cur = rl.rlim_max = (rlim_t)want;
        setrlimit(RLIMIT_AS, &rl);
    }
}

pid_t vp_subproc_fork(const vp_subproc_guard *g) {
    pid_t parent = getpid();
    fflush(NULL); /* nothing buffered may be written twice */
    pid_t pid = fork();
    if (pid == 0) {
        child_setup(parent, g);
        return 0;
    }
    if (pid > 0) setpgid(pid, pid); /* also done by the child: whichever comes first */
    return pid;
}

int vp_subproc_wait(pid_t pid) {
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    return status;
}

void vp_subproc_kill(pid_t pid, int *status) {
    if (kill(-pid, SIGKILL) != 0) kill(pid, SIGKILL);
    int st = vp_subproc_wait(pid);
    if (status) *status = st;
}

vp_subproc_end vp_subproc_run(double timeout, const vp_subproc_guard *guard,
                              int (*child)(int fd, void *user),
                              int (*answer)(int fd, vp_subproc_watch *w, void *user), void *user,
                              int *status) {
    *status = 0;
    int fds[2];
    if (vp_subproc_pipe(fds) != 0) return VP_SUBPROC_NO_PIPE;
    pid_t pid = vp_subproc_fork(guard);
    if (pid < 0) {
        int e = errno;
        close(fds[0]);
        close(fds[1]);
        errno = e;
        return VP_SUBPROC_NO_FORK;
    }
    if (pid == 0) {
        close(fds[0]);
        _exit(child(fds[1], user));
    }
    close(fds[1]);
    vp_subproc_watch watch;
    vp_subproc_watch_start(&watch, pid, timeout);
    watch.guard = guard;
    int rr = answer(fds[0], &watch, user);
    close(fds[0]);
    if (rr == 3 || rr == 2) {
        vp_subproc_kill(pid, status);
        return rr == 3 ? VP_SUBPROC_CANCELLED : VP_SUBPROC_TIMEOUT;
    }
    *status = vp_subproc_wait(pid);
    return rr == 0 ? VP_SUBPROC_ANSWERED : VP_SUBPROC_FAILED;
}
