/* SPDX-License-Identifier: Apache-2.0 */
/* Particle size distributions (part of vdbpack.h): a constant radius,
 * uniform:A:B, lognormal:MEAN:SD (mean and standard deviation of the radius
 * itself) or list:R1:R2:... with equal weights. */
/* Self-contained: included first, it brings in vdbpack.h, which includes
 * this header where the declarations it needs are in place. */
#include "vdbpack/vdbpack.h"

#ifndef VDBPACK_SIZE_DIST_H
#define VDBPACK_SIZE_DIST_H

#ifdef __cplusplus
extern "C" {
#endif


#define VP_SIZE_LIST_MAX 64

typedef enum vp_size_kind {
    VP_SIZE_CONSTANT = 0, /* a */
    VP_SIZE_UNIFORM,      /* uniform in [a, b] */
    VP_SIZE_LOGNORMAL,    /* mean a, standard deviation b; truncated, see below */
    VP_SIZE_LIST          /* values[0..n), equal weights */
} vp_size_kind;

typedef struct vp_size_dist {
    vp_size_kind kind;
    double a, b;
    unsigned n;
    double values[VP_SIZE_LIST_MAX];
} vp_size_dist;

/* A constant radius r. */
VP_API void vp_size_dist_constant(vp_size_dist *d, double r);
/* Parses "0.1", "uniform:A:B", "lognormal:MEAN:SD", "list:R1:R2:...". On
 * failure returns VP_ERR_INVALID_ARGUMENT with a one-line message on ctx
 * (ctx may be NULL). Sizes must be finite and > 0, A <= B, SD >= 0. */
VP_API vp_result vp_size_dist_parse(vp_context *ctx, const char *text, vp_size_dist *out);
/* Smallest and largest radius it can produce. The lognormal is truncated
 * to its central 1 - 2e-4 (mean +- 3.72 sigma in log space), so that it has
 * a largest radius to size neighbour grids and the container's band. */
VP_API double vp_size_dist_min(const vp_size_dist *d);
VP_API double vp_size_dist_max(const vp_size_dist *d);
/* Expected radius and expected radius cubed (of the truncated law). */
VP_API double vp_size_dist_mean(const vp_size_dist *d);
VP_API double vp_size_dist_mean_cube(const vp_size_dist *d);
/* Multiplies every size by k > 0. */
VP_API void vp_size_dist_scale(vp_size_dist *d, double k);
/* Canonical text ("uniform:0.1:0.2"), for metadata. */
VP_API void vp_size_dist_format(const vp_size_dist *d, char *out, size_t outlen);

#ifdef __cplusplus
}
#endif
#endif
