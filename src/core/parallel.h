/* A minimal fork-join helper over pthreads. Work is split by the caller
 * into a fixed number of chunks so results never depend on thread timing. */
#ifndef VDBPACK_CORE_PARALLEL_H
#define VDBPACK_CORE_PARALLEL_H

#include <stddef.h>

/* Calls fn(user, i) for every i in [0, n) on up to `threads` threads
 * (an atomic counter hands out indices). Returns 0, or -1 if threads could
 * not be created (then everything ran on the calling thread). */
int vp_parallel_for(int threads, size_t n, void (*fn)(void *user, size_t i), void *user);
#endif
