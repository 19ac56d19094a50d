/* SPDX-License-Identifier: Apache-2.0 */
/* The relaxation packer (part of vdbpack.h), after He, Ekere & Cai (1999):
 * random centres with overlaps, then overlap relaxation (each overlapped
 * sphere moves to the mean of its non-overlapping positions against its
 * neighbours and the wall) alternating with a small radius relaxation
 * (shrinking only what still overlaps) until the largest overlap is at most
 * `tolerance` of r_i + r_j. */
/* Self-contained: included first, it brings in vdbpack.h, which includes
 * this header where the declarations it needs are in place. */
#include "vdbpack/vdbpack.h"

#ifndef VDBPACK_RELAX_H
#define VDBPACK_RELAX_H

#ifdef __cplusplus
extern "C" {
#endif


typedef struct vp_relax_params {
    vp_fit fit;
    vp_size_dist radius;    /* initial radii */
    size_t count;           /* spheres */
    double target_fraction; /* > 0: scale the radii so that the spheres'
                                volume is this fraction of the container's
                                before relaxation; 0 = radii as given */
    double tolerance;       /* largest overlap / (r_i + r_j) at the end;
                                default 1e-6 */
    int max_sweeps;         /* 0 = automatic */
    uint64_t seed;
    double margin; /* world distance each sphere keeps from the wall
                                (its surface with fit inside, its centre with
                                fit center); default 0 */
    double gap;    /* world distance kept between the surfaces of
                                any two (smaller than the radii); default 0 */
    /* Optional (field.h, docs/fields.md; not owned): each sphere's radius
     * times the field at its starting centre (VP_FIELD_SCALE) or the field
     * itself (VP_FIELD_ABSOLUTE); with target_fraction all are then scaled
     * by one factor to fill it. The radius relaxation then shrinks the
     * spheres that still overlap, one by one */
    const vp_field *radius_field;
    vp_field_mode radius_field_mode;
} vp_relax_params;
VP_API void vp_relax_params_init(vp_relax_params *p);

typedef struct vp_relax_report {
    size_t count;
    int sweeps;
    double radius_scale;     /* final radius / initial radius (<= 1) */
    double initial_fraction; /* spheres' volume / container volume, before */
    double max_overlap;      /* largest overlap / (r_i + r_j) at the end */
    double particle_volume;
    double seconds;
} vp_relax_report;

/* *out is owned by the caller; report may be NULL. Deterministic in seed
 * whatever the thread count. */
VP_API vp_result vp_pack_relax(vp_context *ctx, const vp_container *c,
                               const vp_relax_params *params, vp_particles **out,
                               vp_relax_report *report);
/* The container's load parameters for this job (as
 * vp_container_params_for_lattice in vdbpack.h). */
VP_API void vp_container_params_for_relax(vp_container_params *cp, const vp_relax_params *params);
#ifdef __cplusplus
}
#endif
#endif
