/* SPDX-License-Identifier: Apache-2.0 */
/* Fields as packers see them (include/vdbpack/field.h): a sample callback,
 * the box the field is defined on and the range of its values. OpenVDB
 * grids sit behind it (src/api/field_load.c), as level sets sit behind
 * vp_container. */
#ifndef VDBPACK_CORE_FIELD_H
#define VDBPACK_CORE_FIELD_H

#include <stddef.h>

#include "vdbpack/vdbpack.h"

struct vp_field {
    vp_field_ops ops;
    void *user;
    vp_field_info info;
    /* Optional (NULL: info.min and info.max): the range of the samples in
     * a world box. Returns 0, or -1 on failure (message in err). */
    int (*range)(const struct vp_field *f, const double lo[3], const double hi[3], double *vmin,
                 double *vmax, char *err, size_t errlen);
};

/* Wraps ops/user into a new field with the given info (copied). On
 * failure user is NOT freed. */
vp_result vp_field_wrap(vp_context *ctx, const vp_field_ops *ops, void *user,
                        const vp_field_info *info, vp_field **out);

/* The dense packers' radius field (docs/fields.md): after vp_field_check
 * against c, radius i (at r[rstride * i]) becomes f(x_i) times it (scale)
 * or f(x_i) (absolute), x_i at x[xstride * i]; with keep_volume, then all
 * are scaled by one factor that keeps the sum of their cubes. rmin, rmax
 * (may be NULL): the new smallest and largest. */
vp_result vp_field_radii(vp_context *ctx, const vp_container *c, const vp_field *f,
                         vp_field_mode mode, const double *x, size_t xstride, double *r,
                         size_t rstride, size_t n, int keep_volume, double *rmin, double *rmax);

static inline double vp_field_at(const vp_field *f, const double p[3]) {
    return f->ops.sample(f->user, p);
}
#endif
