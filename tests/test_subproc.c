/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of src/core/subproc.c: the deadline of a child reader.
 * - a child blocked for ever (a pipe nobody writes: all threads asleep)
 *   ends at its deadline;
 * - a child that loops on the CPU ends near its deadline too;
 * - a child that is runnable but starved (nice 19 against one busy
 *   process per CPU, as on a machine whose hypervisor or other jobs take
 *   the CPU) is given the time to finish: it needs 0.03 s of CPU time,
 *   which it cannot get within the 1 s deadline (about 1.4 % of a CPU),
 *   and gets within the 10 s the watch allows. A plain wall-clock
 *   deadline fails this case. */
#define _DEFAULT_SOURCE /* nice */
#include "os/subproc.h"
#include "vp_test.h"

#include <signal.h>
#include <stdint.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static double cpu_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Forks a child running fn with the pipe's write end; returns its pid. */
static pid_t spawn(void (*fn)(int), int fds[2]) {
    ASSERT_EQ_INT(pipe(fds), 0);
    pid_t pid = fork();
    ASSERT_TRUE(pid >= 0);
    if (pid == 0) {
        close(fds[0]);
        fn(fds[1]);
        _exit(0);
    }
    close(fds[1]);
    return pid;
}

static void sleep_forever(int fd) {
    (void)fd;
    for (;;) pause();
}

static void spin_forever(int fd) {
    (void)fd;
    volatile uint64_t x = 0;
    for (;;) x++;
}

static void work_then_answer(int fd) {
    if (nice(19) == -1) { /* -1 is also a valid result; nothing to do either way */
    }
    volatile uint64_t x = 0;
    while (cpu_seconds() < 0.03) x++;
    uint32_t v = 0xC0FFEEu;
    vp_subproc_write_all(fd, &v, sizeof v);
}

/* Reads 4 bytes from a child under a watch of `timeout` seconds: the
 * read's result, the answer, and the wall time taken. */
static int watch_read(void (*fn)(int), double timeout, uint32_t *v, double *dt) {
    int fds[2];
    pid_t pid = spawn(fn, fds);
    vp_subproc_watch w;
    vp_subproc_watch_start(&w, pid, timeout);
    int rr = vp_subproc_read_all(fds[0], v, sizeof *v, &w);
    *dt = vp_subproc_now() - w.start;
    close(fds[0]);
    kill(pid, SIGKILL);
    waitpid(pid, NULL, 0);
    return rr;
}

/* A child that never answers, under a 0.5 s watch: a timeout after 0.5
 * to 3 s (well before the watch's cap of 10 x 0.5 s). */
static void expect_timeout(void (*fn)(int), const char *what) {
    uint32_t v = 0;
    double dt;
    int rr = watch_read(fn, 0.5, &v, &dt);
    fprintf(stderr, "   %s child: result %d after %.2f s\n", what, rr, dt);
    ASSERT_EQ_INT(rr, 2);
    ASSERT_GE(dt, 0.5);
    ASSERT_LE(dt, 3.0);
}

/* all its threads asleep */
static void test_blocked_child_ends_at_deadline(void) { expect_timeout(sleep_forever, "blocked"); }

/* it used its CPU time */
static void test_spinning_child_ends_near_deadline(void) {
    expect_timeout(spin_forever, "spinning");
}

static void test_starved_child_gets_time(void) {
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    if (ncpu < 1) ncpu = 1;
    if (ncpu > 64) ncpu = 64;
    pid_t hogs[64];
    int hfds[64][2];
    for (long i = 0; i < ncpu; i++) hogs[i] = spawn(spin_forever, hfds[i]);
    uint32_t v = 0;
    double dt;
    int rr = watch_read(work_then_answer, 1.0, &v, &dt);
    for (long i = 0; i < ncpu; i++) {
        kill(hogs[i], SIGKILL);
        waitpid(hogs[i], NULL, 0);
        close(hfds[i][0]);
    }
    fprintf(stderr, "   starved child (%ld busy processes): result %d after %.2f s\n", ncpu, rr,
            dt);
    ASSERT_EQ_INT(rr, 0);
    ASSERT_EQ_INT(v, 0xC0FFEEu);
}

int main(void) {
    RUN_TEST(test_blocked_child_ends_at_deadline);
    RUN_TEST(test_spinning_child_ends_near_deadline);
    RUN_TEST(test_starved_child_gets_time);
    fprintf(stderr, "all subproc tests passed\n");
    return 0;
}
