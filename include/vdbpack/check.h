/* SPDX-License-Identifier: Apache-2.0 */
/* Independent verification of a packing (part of vdbpack.h): overlaps,
 * particles crossing the wall, packing fraction and contacts, recomputed
 * from positions, radii, orientations and the shape alone. */
/* Self-contained: included first, it brings in vdbpack.h, which includes
 * this header where the declarations it needs are in place. */
#include "vdbpack/vdbpack.h"

#ifndef VDBPACK_CHECK_H
#define VDBPACK_CHECK_H

#ifdef __cplusplus
extern "C" {
#endif


typedef struct vp_check_params {
    vp_fit fit;
    double overlap_tolerance;  /* overlaps up to this fraction of r_i + r_j
                                 (spheres; of the smaller bounding radius for
                                 solids) are not violations; default 1e-6 */
    double contact_tolerance;  /* gaps up to this fraction of r_i + r_j count
                                 as contacts; default 1e-3 */
    double wall_tolerance;     /* world distance a particle may cross the wall
                                 by; < 0 = automatic (a tenth of the container's
                                 voxel size, 1e-9 for analytic containers) */
    double position_tolerance; /* particles read from a file whose
                                 position_error exceeds this fraction of the
                                 smallest radius are a violation
                                 ("imprecise": the file cannot show that they
                                 do not overlap); default
                                 VP_POSITION_ERROR_LIMIT (1e-3) */
    double margin;             /* world distance each particle must keep from the
                                 wall (its surface with fit inside, its centre
                                 with fit center); default 0 */
    double gap;                /* spheres: world distance between any two
                                 surfaces (pairs closer overlap); default 0 */
} vp_check_params;
VP_API void vp_check_params_init(vp_check_params *p);

typedef struct vp_check_report {
    size_t count;
    size_t overlapping_pairs; /* beyond overlap_tolerance */
    double max_overlap;       /* largest overlap / (r_i + r_j); 0 if none */
    double max_overlap_world; /* the same in world units (penetration depth) */
    size_t outside;           /* particles violating fit beyond wall_tolerance */
    double max_outside;       /* largest violation, world units; 0 if none */
    double particle_volume;
    double container_volume;
    double fraction;
    double mean_contacts; /* contacts per particle (pairs * 2 / count) */
    size_t contact_pairs;
    double position_error_ratio; /* the particles' position_error / the
                                    smallest radius; 0 for exact positions */
    int imprecise;               /* 1: position_error_ratio exceeds
                                   position_tolerance (a violation) */
    double seconds;
} vp_check_report;

/* Returns VP_OK when the check ran (violations are in the report, not in the
 * result: overlapping_pairs, outside, imprecise). */
VP_API vp_result vp_check_particles(vp_context *ctx, const vp_container *c, const vp_particles *p,
                                    const vp_check_params *params, vp_check_report *report);
#ifdef __cplusplus
}
#endif
#endif
