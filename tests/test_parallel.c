/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of src/core/parallel.c (vp_parallel_for over a pool of
 * workers kept between calls): every index runs exactly once, whatever
 * the thread count and however calls follow each other (back to back,
 * with varying thread counts, after the workers have gone to sleep);
 * the pool's worker really takes part; a nested call and calls from two
 * threads at once (the pool busy: threads of their own) are exact too;
 * and a child forked after the pool was used can use it. A deadlock
 * fails the test by alarm() instead of hanging it. */
#include "core/parallel.h"
#include "vp_test.h"

#include <pthread.h>
#include <stdatomic.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define NMAX 4096

typedef struct count_job {
    atomic_int hits[NMAX];
    atomic_int calls;
    pthread_t who[NMAX];
    int sleep_us; /* per index, so that a worker gets some of them */
} count_job;

static void count_fn(void *user, size_t i) {
    count_job *c = user;
    atomic_fetch_add(&c->hits[i], 1);
    atomic_fetch_add(&c->calls, 1);
    c->who[i] = pthread_self();
    if (c->sleep_us) {
        struct timespec t = {0, 1000L * c->sleep_us};
        nanosleep(&t, NULL);
    }
}

static count_job *new_job(void) {
    count_job *c = calloc(1, sizeof *c);
    ASSERT_TRUE(c != NULL);
    return c;
}

/* Runs one call and checks that each of the n indices ran once. */
static void exact(int threads, size_t n, count_job *c) {
    for (size_t i = 0; i < n; i++) atomic_store(&c->hits[i], 0);
    atomic_store(&c->calls, 0);
    ASSERT_EQ_INT(vp_parallel_for(threads, n, count_fn, c), 0);
    ASSERT_EQ_INT(atomic_load(&c->calls), n);
    for (size_t i = 0; i < n; i++) ASSERT_EQ_INT(atomic_load(&c->hits[i]), 1);
}

static void test_every_index_once(void) {
    count_job *c = new_job();
    int threads[] = {1, 2, 3, 8, 64, 100};
    size_t ns[] = {0, 1, 2, 5, 64, 1000, NMAX};
    for (size_t t = 0; t < sizeof threads / sizeof *threads; t++)
        for (size_t k = 0; k < sizeof ns / sizeof *ns; k++) exact(threads[t], ns[k], c);
    free(c);
}

/* Back-to-back calls, the thread count changing from call to call (a
 * worker that sat one call out must not take part in the next one twice). */
static void test_many_calls(void) {
    count_job *c = new_job();
    vp_parallel_pool_cap(7); /* calls that leave workers out */
    int threads[] = {2, 8, 3, 2, 1, 5, 2, 4};
    for (int k = 0; k < 20000; k++) exact(threads[k % 8], (size_t)(k % 97), c);
    vp_parallel_pool_cap(1);
    free(c);
}

/* Items that sleep: the pool's worker must have run some of them. */
static void test_worker_takes_part(void) {
    count_job *c = new_job();
    c->sleep_us = 2000;
    for (int rep = 0; rep < 3; rep++) {
        exact(2, 16, c);
        int other = 0;
        for (int i = 0; i < 16; i++) other += !pthread_equal(c->who[i], pthread_self());
        ASSERT_TRUE(other > 0);
        ASSERT_TRUE(other < 16);
    }
    free(c);
}

/* Calls far apart: the workers have gone to sleep on the condition
 * variable between them. */
static void test_after_sleep(void) {
    count_job *c = new_job();
    for (int k = 0; k < 3; k++) {
        struct timespec t = {0, 150 * 1000000L};
        nanosleep(&t, NULL);
        exact(2, 500, c);
    }
    free(c);
}

typedef struct nest {
    count_job *inner[8];
} nest;

static void nest_fn(void *user, size_t i) {
    nest *n = user;
    exact(2, 300, n->inner[i]); /* the pool is busy: threads of its own */
}

static void test_nested(void) {
    nest n;
    for (int i = 0; i < 8; i++) n.inner[i] = new_job();
    ASSERT_EQ_INT(vp_parallel_for(2, 8, nest_fn, &n), 0);
    for (int i = 0; i < 8; i++) {
        ASSERT_EQ_INT(atomic_load(&n.inner[i]->calls), 300);
        free(n.inner[i]);
    }
}

static void *caller(void *arg) {
    count_job *c = arg;
    for (int k = 0; k < 2000; k++) exact(2, (size_t)(k % 61) + 1, c);
    return NULL;
}

static void test_two_callers(void) {
    count_job *a = new_job(), *b = new_job();
    pthread_t t;
    ASSERT_EQ_INT(pthread_create(&t, NULL, caller, a), 0);
    caller(b);
    pthread_join(t, NULL);
    free(a);
    free(b);
}

static void test_fork(void) {
    count_job *c = new_job();
    exact(2, 200, c); /* the pool exists */
    pid_t pid = fork();
    ASSERT_TRUE(pid >= 0);
    if (pid == 0) {
        alarm(300);
        for (int k = 0; k < 100; k++) exact(2, 200, c); /* exits 1 on a failed check */
        _exit(0);
    }
    int st = 0;
    ASSERT_EQ_INT(waitpid(pid, &st, 0), pid);
    ASSERT_TRUE(WIFEXITED(st));
    ASSERT_EQ_INT(WEXITSTATUS(st), 0);
    exact(2, 200, c); /* and the parent's pool still works */
    free(c);
}

int main(void) {
    alarm(300); /* a deadlock fails instead of hanging */
    RUN_TEST(test_every_index_once);
    RUN_TEST(test_many_calls);
    RUN_TEST(test_worker_takes_part);
    RUN_TEST(test_after_sleep);
    RUN_TEST(test_nested);
    RUN_TEST(test_two_callers);
    RUN_TEST(test_fork);
    fprintf(stderr, "test_parallel: all passed\n");
    return 0;
}
