/* SPDX-License-Identifier: Apache-2.0 */
/* Fork-join over a pool of pthreads; see parallel.h.
 *
 * The random packer calls vp_parallel_for thousands of times per pass (a
 * batch of darts, a round of a split: each a fraction of a millisecond),
 * and creating and joining a thread per call cost about 45 us of it
 * (bench in docs/design.md), so workers are kept between calls. One pool
 * per process, used by one call at a time: a call that finds it busy
 * (another thread's, or a nested one) starts threads of its own as
 * before. Between calls a worker spins briefly on the call counter (the
 * next batch usually follows within microseconds), then sleeps on a
 * condition variable. fork() is made safe by pthread_atfork handlers: the
 * child starts with an empty pool. */
#include "core/parallel.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

#define POOL_MAX 63 /* workers beyond the calling thread */
#define SPIN 2000   /* polls of the counter before sleeping (about 50 us) */

#if defined(__x86_64__) || defined(__i386__)
#define CPU_RELAX() __builtin_ia32_pause()
#else
#define CPU_RELAX() ((void)0)
#endif

typedef struct job {
    void (*fn)(void *, size_t);
    void *user;
    size_t n;
    atomic_size_t next;
} job;

static void run(job *j) {
    for (;;) {
        size_t i = atomic_fetch_add(&j->next, 1);
        if (i >= j->n) break;
        j->fn(j->user, i);
    }
}

static void *thread_main(void *arg) {
    run(arg);
    return NULL;
}

/* The pool. call holds the call counter and, in its low byte, how many
 * workers take part (one load reads both consistently); it is published
 * under mu once per call, after cur and pending are set. pending counts
 * the workers of the call still running: the next call cannot begin
 * before they are done, so a worker taking part reads its call's cur. */
static struct {
    pthread_mutex_t mu;
    pthread_cond_t work, done;
    pthread_once_t once;
    int cap;           /* most workers: the other cores (more would only
                              take turns on them, spinning) */
    int nworkers;      /* under mu */
    int busy;          /* under mu: a call holds the pool */
    atomic_ulong call; /* counter << 8 | workers taking part */
    job *_Atomic cur;
    atomic_int pending;
    unsigned long born[POOL_MAX]; /* call when worker i was created */
} P = {.mu = PTHREAD_MUTEX_INITIALIZER,
       .work = PTHREAD_COND_INITIALIZER,
       .done = PTHREAD_COND_INITIALIZER,
       .once = PTHREAD_ONCE_INIT};

static void *pool_main(void *arg) {
    int id = (int)(size_t)arg;
    pthread_mutex_lock(&P.mu);
    unsigned long seen = P.born[id] >> 8; /* its first call may have begun already */
    pthread_mutex_unlock(&P.mu);
    for (;;) {
        unsigned long c = atomic_load(&P.call);
        for (int k = 0; c >> 8 == seen && k < SPIN; k++) {
            CPU_RELAX();
            c = atomic_load(&P.call);
        }
        if (c >> 8 == seen) {
            pthread_mutex_lock(&P.mu);
            while ((c = atomic_load(&P.call)) >> 8 == seen) pthread_cond_wait(&P.work, &P.mu);
            pthread_mutex_unlock(&P.mu);
        }
        seen = c >> 8;
        if (id >= (int)(c & 0xFF)) continue;
        run(atomic_load(&P.cur));
        if (atomic_fetch_sub(&P.pending, 1) == 1) {
            pthread_mutex_lock(&P.mu);
            pthread_cond_signal(&P.done);
            pthread_mutex_unlock(&P.mu);
        }
    }
    return NULL;
}

static void atfork_prepare(void) { pthread_mutex_lock(&P.mu); }
static void atfork_parent(void) { pthread_mutex_unlock(&P.mu); }
static void atfork_child(void) { /* the workers do not exist in the child */
    pthread_mutex_init(&P.mu, NULL);
    pthread_cond_init(&P.work, NULL);
    pthread_cond_init(&P.done, NULL);
    P.nworkers = 0;
    P.busy = 0;
}
static void pool_once(void) {
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    P.cap = cores > 1 ? (cores - 1 < POOL_MAX ? (int)cores - 1 : POOL_MAX) : 1;
    pthread_atfork(atfork_prepare, atfork_parent, atfork_child);
}

void vp_parallel_pool_cap(int workers) {
    pthread_once(&P.once, pool_once);
    pthread_mutex_lock(&P.mu);
    P.cap = workers < 1 ? 1 : workers > POOL_MAX ? POOL_MAX : workers;
    pthread_mutex_unlock(&P.mu);
}

/* Threads of its own, created and joined: when the pool is busy. */
static int spawn_for(int threads, job *j) {
    pthread_t *tids = malloc(sizeof(pthread_t) * (size_t)(threads - 1));
    int started = 0, rc = 0;
    if (tids) {
        for (int t = 0; t < threads - 1; t++) {
            if (pthread_create(&tids[t], NULL, thread_main, j) != 0) {
                rc = -1;
                break;
            }
            started++;
        }
    } else {
        rc = -1;
    }
    run(j);
    for (int t = 0; t < started; t++) pthread_join(tids[t], NULL);
    free(tids);
    return rc;
}

int vp_parallel_for(int threads, size_t n, void (*fn)(void *, size_t), void *user) {
    job j;
    j.fn = fn;
    j.user = user;
    j.n = n;
    atomic_init(&j.next, 0);
    if (threads > (int)n) threads = (int)n;
    if (threads <= 1) {
        run(&j);
        return 0;
    }
    pthread_once(&P.once, pool_once);
    pthread_mutex_lock(&P.mu);
    int want = threads - 1 < P.cap ? threads - 1 : P.cap;
    if (P.busy) {
        pthread_mutex_unlock(&P.mu);
        return spawn_for(threads, &j);
    }
    P.busy = 1;
    while (P.nworkers < want) {
        pthread_t t;
        pthread_attr_t a;
        if (pthread_attr_init(&a) != 0) break;
        pthread_attr_setdetachstate(&a, PTHREAD_CREATE_DETACHED);
        P.born[P.nworkers] = atomic_load(&P.call);
        int ok = pthread_create(&t, &a, pool_main, (void *)(size_t)P.nworkers) == 0;
        pthread_attr_destroy(&a);
        if (!ok) break;
        P.nworkers++;
    }
    int rc = 0;
    if (want > P.nworkers) { /* some could not be created: fewer take part */
        want = P.nworkers;
        rc = -1;
    }
    atomic_store(&P.cur, &j);
    atomic_store(&P.pending, want);
    atomic_store(&P.call, ((atomic_load(&P.call) >> 8) + 1) << 8 | (unsigned long)want);
    pthread_cond_broadcast(&P.work);
    pthread_mutex_unlock(&P.mu);
    run(&j);
    for (int k = 0; atomic_load(&P.pending) && k < SPIN; k++) CPU_RELAX();
    pthread_mutex_lock(&P.mu);
    while (atomic_load(&P.pending)) pthread_cond_wait(&P.done, &P.mu);
    P.busy = 0;
    pthread_mutex_unlock(&P.mu);
    return rc;
}
