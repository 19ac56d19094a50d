/* SPDX-License-Identifier: Apache-2.0 */
/* The container as packers see it: a signed distance (negative inside),
 * its gradient, bounds and volume, behind callbacks. Packers include only
 * this; OpenVDB level sets and analytic shapes both sit behind it. */
#ifndef VDBPACK_CORE_CONTAINER_H
#define VDBPACK_CORE_CONTAINER_H

#include "core/depth_map.h"
#include "vdbpack/vdbpack.h"

struct vp_container {
    vp_container_ops ops;
    void *user;
    vp_container_info info;
    void *levelset; /* the vpv_levelset behind a level-set container, else NULL */
    /* Optional (NULL for analytic containers, which are cheap to sample
     * anyway): builds the coarse depth map of depth_map.h into *out (owned
     * by the caller). Returns 0, or -1 when there is none (the caller then
     * samples everything). */
    int (*depth_map)(const struct vp_container *c, vp_depth_map *out);
    /* Optional (NULL: the bounds in info): the box of the inside, tighter
     * than info's bounds for a level set (whose active voxels reach past
     * the surface). Returns 0, or -1 when unknown. */
    int (*inside_box)(const struct vp_container *c, double lo[3], double hi[3]);
};

/* Wraps ops/user into a new container with the given info (copied).
 * On failure user is NOT freed. */
vp_result vp_container_wrap(vp_context *ctx, const vp_container_ops *ops, void *user,
                            const vp_container_info *info, vp_container **out);
#endif
