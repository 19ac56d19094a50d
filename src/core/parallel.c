/* Fork-join over pthreads; see parallel.h. */
#include "core/parallel.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>

typedef struct job {
    void (*fn)(void *, size_t);
    void *user;
    size_t n;
    atomic_size_t next;
} job;

static void *worker(void *arg) {
    job *j = arg;
    for (;;) {
        size_t i = atomic_fetch_add(&j->next, 1);
        if (i >= j->n) break;
        j->fn(j->user, i);
    }
    return NULL;
}

int vp_parallel_for(int threads, size_t n, void (*fn)(void *, size_t), void *user) {
    job j;
    j.fn = fn;
    j.user = user;
    j.n = n;
    atomic_init(&j.next, 0);
    if (threads > (int)n) threads = (int)n;
    if (threads <= 1) {
        worker(&j);
        return 0;
    }
    pthread_t *tids = malloc(sizeof(pthread_t) * (size_t)(threads - 1));
    int started = 0, rc = 0;
    if (tids) {
        for (int t = 0; t < threads - 1; t++) {
            if (pthread_create(&tids[t], NULL, worker, &j) != 0) { rc = -1; break; }
            started++;
        }
    } else {
        rc = -1;
    }
    worker(&j);
    for (int t = 0; t < started; t++) pthread_join(tids[t], NULL);
    free(tids);
    return rc;
}
