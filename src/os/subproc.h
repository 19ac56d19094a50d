/* SPDX-License-Identifier: Apache-2.0 */
/* Small pieces for running third-party readers in a forked child (Assimp's
 * importer in src/mesh/isolate.c, OpenVDB's file reader in src/api/probe.c):
 * whole-buffer pipe I/O with a deadline. Internal. */
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

#include <sys/types.h>

/* Monotonic clock, seconds. */
double vp_subproc_now(void);
/* In a forked child, before it runs a reader: the default action for
 * SIGPIPE and for the crash signals (SEGV, BUS, FPE, ILL, ABRT), which the
 * command line tool catches to clean up its outputs; the parent learns a
 * reader's crash from the child's death by that signal. */
void vp_subproc_child_signals(void);
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
    double timeout;  /* seconds */
    double start;    /* vp_subproc_now() when the child started */
    double deadline; /* moves while the child is starved */
} vp_subproc_watch;
/* Starts the watch of child pid with the given timeout. */
void vp_subproc_watch_start(vp_subproc_watch *w, pid_t pid, double timeout);
/* Reads exactly n bytes before the watch's deadline: 0 on success, 1 on
 * EOF first, -1 on error, 2 on timeout. */
int vp_subproc_read_all(int fd, void *buf, size_t n, vp_subproc_watch *w);
/* A deadline from the environment variable env (seconds, > 0) when set,
 * otherwise base + per_mb seconds per MB of file_bytes. */
double vp_subproc_timeout(const char *env, double base, double per_mb, size_t file_bytes);
#endif
