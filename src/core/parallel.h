/* SPDX-License-Identifier: Apache-2.0 */
/* A minimal fork-join helper over a pool of pthreads kept between calls.
 * Work is split by the caller into a fixed number of chunks so results
 * never depend on thread timing. */
#ifndef VDBPACK_CORE_PARALLEL_H
#define VDBPACK_CORE_PARALLEL_H

#include <stddef.h>

/* Calls fn(user, i) for every i in [0, n) on up to `threads` threads
 * (an atomic counter hands out indices; at most one per core from the
 * pool). Returns 0, or -1 if some threads could not be created (then the
 * others, or the calling thread alone, ran everything). */
int vp_parallel_for(int threads, size_t n, void (*fn)(void *user, size_t i), void *user);

/* Sets the most pool workers a call uses (default: one per other
 * core; more take part in a call only when it asks for more threads). For
 * tests: the pool's bookkeeping of calls with fewer threads than workers
 * cannot be exercised on a machine with two cores otherwise. */
void vp_parallel_pool_cap(int workers);
#endif
