/* SPDX-License-Identifier: Apache-2.0 */
/* Small pieces for running third-party readers in a forked child (Assimp's
 * importer in src/mesh/isolate.c, OpenVDB's file reader in src/api/probe.c):
 * the fork, whole-buffer pipe I/O with a deadline, and vp_subproc_run, which
 * puts them together. Internal. */
#ifndef VDBPACK_CORE_SUBPROC_H
#define VDBPACK_CORE_SUBPROC_H

#include <stddef.h>

/* Builds that run third-party readers in-process instead of in a child:
 * - fuzz builds (VP_FUZZING), so that the sanitizers see our own code
 *   (welding, topology) and the fuzzer sees Assimp's and OpenVDB's failures;
 * - AddressSanitizer builds: clang 14's ASan allocator is not fork-safe (a
 *   child forked while another thread holds an allocator lock waits on it
 *   forever: seen as 6 of 75 imports of vdb_samples/torus.obj hanging under
 *   load), and its shadow memory cannot live under RLIMIT_AS anyway.
 * gcc says __SANITIZE_ADDRESS__, clang 14 only __has_feature. */
#if defined(VP_FUZZING) || defined(__SANITIZE_ADDRESS__)
#define VP_SUBPROC_IN_PROCESS 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define VP_SUBPROC_IN_PROCESS 1
#endif
#endif

#include <stdint.h>
#include <sys/types.h>

/* Monotonic clock, seconds. */
double vp_subproc_now(void);

/* What bounds a reader child besides its deadline. */
typedef struct vp_subproc_guard {
    /* polled about ten times a second (on the waiting thread) while the
     * parent waits for the child; nonzero: the wait ends at once
     * (vp_subproc_read_all returns 3) and the caller kills the child. NULL:
     * never. The library passes its progress callback (a SIGINT in the
     * command-line tool cancels through it). */
    int (*cancel)(void *user);
    void *user;
    /* bytes the child may map beyond what it has at the fork (RLIMIT_AS,
     * in the child): a runaway allocation fails there, not the machine.
     * 0: the machine's physical memory. */
    uint64_t max_bytes;
} vp_subproc_guard;

/* A pipe for a child's answer: both ends close-on-exec and numbered above
 * 2, so that a child whose standard descriptors are replaced by /dev/null
 * keeps its end even when the caller had 0, 1 or 2 closed (pipe() then
 * hands out those numbers). 0, or -1 with errno set. */
int vp_subproc_pipe(int fds[2]);
/* fork() for a reader child, after fflush(NULL). In the child (0 is
 * returned): its own process group (a Ctrl-C to the terminal's group
 * reaches the parent only, which ends the child), killed by SIGKILL when
 * the thread that forked it dies (PR_SET_PDEATHSIG; a child whose parent
 * is already gone exits), every signal's default action and none blocked
 * (the parent's handlers, such as the command-line tool's SIGINT handler
 * that removes outputs, must not run in it; the parent learns a reader's
 * crash from its death by that signal), stdin, stdout and stderr on
 * /dev/null (a reader's own messages would make a second error line, or
 * mix into an output written to stdout), and g's memory bound (g may be
 * NULL). In the parent: the child's pid, or -1 with errno set. */
pid_t vp_subproc_fork(const vp_subproc_guard *g);
/* Kills a child started by vp_subproc_fork (its process group) with
 * SIGKILL and waits for it; the status in *status if not NULL. */
void vp_subproc_kill(pid_t pid, int *status);
/* Waits for a child (retrying on EINTR); its status. */
int vp_subproc_wait(pid_t pid);
/* Writes all n bytes (retrying on EINTR): 0, or -1 on error. */
int vp_subproc_write_all(int fd, const void *buf, size_t n);

/* The deadline of a child. A child that is still runnable at its deadline
 * but has had less than half of it in CPU time (the machine was starved:
 * other processes, or a hypervisor that did not run this machine, which
 * Linux counts as steal time and charges to no process) gets more wall
 * time, one second at a time, up to 10 times the timeout: a timeout is
 * meant for a reader that loops or blocks on a bad file, not for a slow
 * machine. A child whose threads all sleep (a reader blocked on a FIFO,
 * a deadlock) or that has used its CPU time ends at the deadline. */
typedef struct vp_subproc_watch {
    pid_t pid;
    double timeout;                /* seconds */
    double start;                  /* vp_subproc_now() when the child started */
    double deadline;               /* moves while the child is starved */
    const vp_subproc_guard *guard; /* its cancel is polled; may be NULL */
} vp_subproc_watch;
/* Starts the watch of child pid with the given timeout (guard NULL). */
void vp_subproc_watch_start(vp_subproc_watch *w, pid_t pid, double timeout);
/* Reads exactly n bytes before the watch's deadline: 0 on success, 1 on
 * EOF first, -1 on error, 2 on timeout, 3 when the guard's cancel asked to
 * stop. */
int vp_subproc_read_all(int fd, void *buf, size_t n, vp_subproc_watch *w);
/* How vp_subproc_run ended. */
typedef enum vp_subproc_end {
    VP_SUBPROC_ANSWERED = 0, /* the answer was read; the child was waited for */
    VP_SUBPROC_NO_PIPE,      /* pipe() failed (errno set); no child */
    VP_SUBPROC_NO_FORK,      /* fork() failed (errno set); no child */
    VP_SUBPROC_TIMEOUT,      /* the deadline passed: the child was killed */
    VP_SUBPROC_CANCELLED,    /* the guard's cancel asked: the child was killed */
    VP_SUBPROC_FAILED        /* the answer ended early or could not be read
                              * (the child died, or wrote too little); the
                              * child was waited for: its status says how */
} vp_subproc_end;
/* Runs a reader child end to end: a pipe (vp_subproc_pipe), a child
 * (vp_subproc_fork(guard)) that runs child(fd, user), writing its answer
 * to fd, and exits with child's return value; in the parent,
 * answer(fd, w, user) reads that answer through vp_subproc_read_all under
 * the watch w (timeout seconds, guard's cancel polled) and returns as
 * vp_subproc_read_all does. Then the child is killed (timeout, cancel) or
 * waited for; its wait status in *status (0 when there was no child). The
 * pipe is closed in both processes. guard may be NULL. */
vp_subproc_end vp_subproc_run(double timeout, const vp_subproc_guard *guard,
                              int (*child)(int fd, void *user),
                              int (*answer)(int fd, vp_subproc_watch *w, void *user), void *user,
                              int *status);
/* A deadline from the environment variable env (seconds, > 0) when set,
 * otherwise base + per_mb seconds per MB of file_bytes. */
double vp_subproc_timeout(const char *env, double base, double per_mb, size_t file_bytes);
#endif
