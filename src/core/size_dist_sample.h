/* SPDX-License-Identifier: Apache-2.0 */
/* Sampling a vp_size_dist (internal to the core). */
#ifndef VDBPACK_CORE_SIZE_DIST_SAMPLE_H
#define VDBPACK_CORE_SIZE_DIST_SAMPLE_H

#include <stdint.h>
#include "vdbpack/vdbpack.h"

/* One radius drawn with the rng state s (see rng.h); deterministic. */
double vp_size_dist_sample(const vp_size_dist *d, uint64_t *s);
/* One radius drawn from d conditioned on being at most c (the room a
 * maximal pass has at a centre): the law of d truncated to [min, c]; the
 * smallest radius when c is below it. */
double vp_size_dist_sample_below(const vp_size_dist *d, double c, uint64_t *s);
/* The standard deviation of the radius over its mean (0 for one radius;
 * the lognormal's as truncated). */
double vp_size_dist_rel_sd(const vp_size_dist *d);
#endif
