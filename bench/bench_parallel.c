/* SPDX-License-Identifier: Apache-2.0 */
/* Cost of one vp_parallel_for call (src/core/parallel.c: a pool of
 * workers kept between calls) against the reference it replaced, timed in
 * the same run: threads created and joined at every call. The random
 * packer makes thousands of such calls per pass (a batch of darts, a
 * round of a split), each a fraction of a millisecond of work.
 * Workloads: 64 chunks of W multiply-adds each (W = 0, 2000, 20000).
 * Usage: build/bench/bench_parallel [CALLS] [THREADS]   (default 20000, 2)
 * No pass/fail: microseconds per call and ratios are printed. */
#include "core/parallel.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

typedef struct work {
    int w;
    double out[64];
} work;

static void chunk(void *user, size_t i) {
    work *k = user;
    double x = (double)i;
    for (int m = 0; m < k->w; m++) x = x * 0.999999 + 1e-9;
    k->out[i] = x;
}

/* The reference: the code before the pool, threads made per call. */
typedef struct ref_job {
    work *k;
    size_t n;
    atomic_size_t next;
} ref_job;

static void *ref_worker(void *arg) {
    ref_job *j = arg;
    for (size_t i; (i = atomic_fetch_add(&j->next, 1)) < j->n;) chunk(j->k, i);
    return NULL;
}

static void ref_for(int threads, size_t n, work *k) {
    ref_job j = {k, n, 0};
    pthread_t t[64];
    int started = 0;
    for (int i = 0; i < threads - 1 && i < 64; i++)
        if (pthread_create(&t[i], NULL, ref_worker, &j) == 0) started++;
    ref_worker(&j);
    for (int i = 0; i < started; i++) pthread_join(t[i], NULL);
}

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv) {
    int calls = argc > 1 ? atoi(argv[1]) : 20000, threads = argc > 2 ? atoi(argv[2]) : 2;
    if (calls < 1 || threads < 1) {
        fprintf(stderr, "usage: bench_parallel [CALLS >= 1] [THREADS >= 1]\n");
        return 2;
    }
    printf("bench_parallel: %d calls of 64 chunks on %d threads\n", calls, threads);
    printf("%8s %14s %14s %14s %8s\n", "W", "1 thread us", "pool us", "reference us", "ratio");
    int ws[] = {0, 2000, 20000};
    for (int a = 0; a < 3; a++) {
        work k = {ws[a], {0}};
        double t0 = now();
        for (int c = 0; c < calls; c++) vp_parallel_for(1, 64, chunk, &k);
        double t1 = now();
        for (int c = 0; c < calls; c++) vp_parallel_for(threads, 64, chunk, &k);
        double t2 = now();
        for (int c = 0; c < calls; c++) ref_for(threads, 64, &k);
        double t3 = now();
        double one = (t1 - t0) / calls * 1e6, pool = (t2 - t1) / calls * 1e6,
               ref = (t3 - t2) / calls * 1e6;
        printf("%8d %14.2f %14.2f %14.2f %8.2f\n", ws[a], one, pool, ref, pool / ref);
    }
    return 0;
}
