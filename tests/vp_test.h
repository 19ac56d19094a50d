/* SPDX-License-Identifier: Apache-2.0 */
/* Tiny assertion macros for the C unit tests (libuv style: print both
 * values and the location, then fail the test). */
#ifndef VP_TEST_H
#define VP_TEST_H
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

#include "vdbpack/vdbpack.h"

/* Failure counter for tests that keep going after a failed check. */
static int vp_test_failures __attribute__((unused)) = 0;


#define ASSERT_TRUE(c)                                                                             \
    do {                                                                                           \
        if (!(c)) {                                                                                \
            fprintf(stderr, "%s:%d: assertion failed: %s\n", __FILE__, __LINE__, #c);              \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)
#define ASSERT_EQ_INT(a, b)                                                                        \
    do {                                                                                           \
        long long va_ = (long long)(a), vb_ = (long long)(b);                                      \
        if (va_ != vb_) {                                                                          \
            fprintf(stderr, "%s:%d: %s == %s failed: %lld != %lld\n", __FILE__, __LINE__, #a, #b,  \
                    va_, vb_);                                                                     \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)
#define ASSERT_NEAR(a, b, tol)                                                                     \
    do {                                                                                           \
        double va_ = (double)(a), vb_ = (double)(b);                                               \
        if (!(fabs(va_ - vb_) <= (tol))) {                                                         \
            fprintf(stderr, "%s:%d: |%s - %s| <= %s failed: %.17g vs %.17g (diff %.3g)\n",         \
                    __FILE__, __LINE__, #a, #b, #tol, va_, vb_, fabs(va_ - vb_));                  \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)
#define ASSERT_LE(a, b)                                                                            \
    do {                                                                                           \
        double va_ = (double)(a), vb_ = (double)(b);                                               \
        if (!(va_ <= vb_)) {                                                                       \
            fprintf(stderr, "%s:%d: %s <= %s failed: %.17g > %.17g\n", __FILE__, __LINE__, #a, #b, \
                    va_, vb_);                                                                     \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)
#define ASSERT_GE(a, b) ASSERT_LE(b, a)

/* Runs fn in a child process bounded by `seconds` (SIGALRM) and, outside
 * sanitizer builds (whose shadow memory needs terabytes of address space),
 * by `bytes` of address space, and fails the test unless the child exits
 * with 0: a runaway (a 24 GB allocation, an endless loop) then fails the
 * test instead of taking the machine down with it. */
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define VP_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) ||                         \
    __has_feature(memory_sanitizer)
#define VP_TEST_SANITIZED 1
#endif
#endif
#ifndef VP_TEST_SANITIZED
#define VP_TEST_SANITIZED 0
#endif
#if defined(__unix__) && !defined(__cplusplus)
#include <errno.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
static void vp_test_bounded(void (*fn)(void), unsigned seconds, unsigned long long bytes)
    __attribute__((unused));
static void vp_test_bounded(void (*fn)(void), unsigned seconds, unsigned long long bytes) {
    fflush(stderr);
    if (VP_TEST_SANITIZED) {
        /* no child under the sanitizers: a forked child that starts
         * threads (the packers' pool) can block for good in ASan's
         * allocator, whose lock the fork may copy held (seen in about 1
         * run in 6 of test_rsa_thin under load); the time bound stays,
         * SIGALRM ends the test, and the address-space bound is off for
         * them anyway */
        (void)bytes;
        alarm(seconds);
        fn();
        alarm(0);
        return;
    }
    pid_t pid = fork();
    if (pid < 0) {
        perror("fork");
        exit(1);
    }
    if (pid == 0) {
        if (!VP_TEST_SANITIZED) {
            struct rlimit rl = {(rlim_t)bytes, (rlim_t)bytes};
            setrlimit(RLIMIT_AS, &rl);
        }
        alarm(seconds);
        fn();
        fflush(stderr);
        _exit(0);
    }
    int st = 0;
    while (waitpid(pid, &st, 0) < 0) {
        if (errno != EINTR) {
            perror("waitpid");
            exit(1);
        }
    }
    if (WIFSIGNALED(st)) {
        fprintf(stderr, "   bounded run killed by signal %d (%s)\n", WTERMSIG(st),
                WTERMSIG(st) == SIGALRM ? "over its time limit" : "a crash or the memory limit");
        exit(1);
    }
    if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) exit(1);
}
#endif

/* A library call that must succeed: on failure prints the call, the
 * result's name and the context's message (ctx may be NULL: no message). */
#define ASSERT_OK(ctx, call)                                                                       \
    do {                                                                                           \
        vp_result r_ = (vp_result)(call);                                                          \
        if (r_ != VP_OK) {                                                                         \
            fprintf(stderr, "%s:%d: %s failed: %s: %s\n", __FILE__, __LINE__, #call,               \
                    vp_result_name(r_), vp_context_message(ctx));                                  \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)
/* The same for an internal call that reports into a message buffer (the
 * `char *err, size_t errlen` of src/vdb and src/mesh) instead of a context. */
#define ASSERT_OK_MSG(msg, call)                                                                   \
    do {                                                                                           \
        vp_result r_ = (vp_result)(call);                                                          \
        if (r_ != VP_OK) {                                                                         \
            fprintf(stderr, "%s:%d: %s failed: %s: %s\n", __FILE__, __LINE__, #call,               \
                    vp_result_name(r_), (const char *)(msg));                                      \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)
/* A library call that must fail with result `want`. */
#define ASSERT_FAILS(ctx, want, call)                                                              \
    do {                                                                                           \
        vp_result r_ = (vp_result)(call);                                                          \
        if (r_ != (want)) {                                                                        \
            fprintf(stderr, "%s:%d: %s gave %s, not %s (message: %s)\n", __FILE__, __LINE__,       \
                    #call, vp_result_name(r_), vp_result_name(want), vp_context_message(ctx));     \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)

/* Which cases run: with VP_TEST_CASE=NAME only the case named NAME (what
 * CTest sets: each case is its own CTest test, tests/CMakeLists.txt), and
 * a run in which no case has that name fails; with VP_TEST=NAME the cases
 * whose name contains NAME; otherwise all. */
static int vp_test_ran_ __attribute__((unused)) = 0;
static void vp_test_check_ran_(void) __attribute__((unused));
static void vp_test_check_ran_(void) {
    if (vp_test_ran_) return;
    fprintf(stderr, "VP_TEST_CASE=%s: no case of that name\n", getenv("VP_TEST_CASE"));
    fflush(stderr);
    _Exit(1);
}
static int vp_test_wanted(const char *name) __attribute__((unused));
static int vp_test_wanted(const char *name) {
    static int checked = 0;
    const char *one = getenv("VP_TEST_CASE");
    if (one && *one) {
        if (!checked) {
            checked = 1;
            atexit(vp_test_check_ran_);
        }
        if (strcmp(name, one) != 0) return 0;
        vp_test_ran_ = 1;
        return 1;
    }
    const char *part = getenv("VP_TEST");
    return !part || strstr(name, part) != NULL;
}
/* A case: RUN_TEST(fn) runs fn(); RUN_CASE(name, call) runs call under the
 * name `name` (an identifier: tests/CMakeLists.txt finds both forms in the
 * source and registers one CTest test per name). */
#define RUN_CASE(name, call)                                                                       \
    do {                                                                                           \
        if (vp_test_wanted(#name)) {                                                               \
            fprintf(stderr, "-- %s\n", #name);                                                     \
            call;                                                                                  \
        }                                                                                          \
    } while (0)
#define RUN_TEST(fn) RUN_CASE(fn, fn())
#endif
