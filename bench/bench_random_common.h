/* SPDX-License-Identifier: Apache-2.0 */
/* Shared helpers of bench_rsa.c and bench_relax.c: each case runs in a
 * forked child, so its peak resident memory (VmHWM) is its own. */
#ifndef VDBPACK_BENCH_RANDOM_COMMON_H
#define VDBPACK_BENCH_RANDOM_COMMON_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static long bench_status_kb(const char *key) {
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    long v = -1;
    size_t k = strlen(key);
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, key, k)) v = strtol(line + k + 1, NULL, 10);
    if (f) fclose(f);
    return v;
}

static double bench_now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Runs fn(arg) in a child and waits; returns the child's exit status. */
static int bench_fork(void (*fn)(void *), void *arg) {
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        fn(arg);
        fflush(stdout);
        _exit(0);
    }
    int st = 0;
    if (pid < 0 || waitpid(pid, &st, 0) < 0) return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}
#endif
