/* SPDX-License-Identifier: Apache-2.0 */
/* The jammed packer (part of vdbpack.h): random close packing of spheres
 * in any container by soft-sphere energy minimisation (FIRE, Bitzek et al.
 * 2006) under a decompression to the jamming point (O'Hern et al. 2003).
 * docs/jam.md says how it works and what its figures mean. */
/* Self-contained: included first, it brings in vdbpack.h, which includes
 * this header where the declarations it needs are in place. */
#include "vdbpack/vdbpack.h"

#ifndef VDBPACK_JAM_H
#define VDBPACK_JAM_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vp_jam_params {
    vp_fit fit;
    vp_size_dist radius;    /* the radii's distribution; all radii are then
                                scaled by one factor until the packing jams.
                                With a spread of 0.1 of the mean or more,
                                neighbours may trade radii as they pack: the
                                radii drawn, not in the order drawn */
    size_t count;           /* spheres; 0: from target_fraction */
    double target_fraction; /* with count 0: count = this fraction of the
                                container's volume over the mean sphere
                                volume of `radius` (default 0.64) */
    double tolerance;       /* largest overlap / (r_i + r_j) at the end;
                                default 1e-6 */
    double contact_gap;     /* a contact: a gap below this much of r_i + r_j
                                (of 2 r_i at the wall); default 1e-4 */
    uint64_t seed;
    double margin; /* world distance each sphere keeps from the wall
                                (its surface with fit inside, its centre with
                                fit center); default 0 */
    double gap;    /* world distance kept between the surfaces of
                                any two (smaller than the radii); default 0 */
    /* Optional (field.h, docs/fields.md; not owned): each sphere's radius
     * times the field at its starting centre (VP_FIELD_SCALE) or the field
     * itself (VP_FIELD_ABSOLUTE); then, as always, all radii are scaled by
     * one factor (their ratios stay the field's) to the jamming point */
    const vp_field *radius_field;
    vp_field_mode radius_field_mode;
} vp_jam_params;
VP_API void vp_jam_params_init(vp_jam_params *p);

typedef struct vp_jam_report {
    size_t count;
    double fraction;         /* the spheres' volume / the container's */
    double core_fraction;    /* the same in the core: centres farther than 5
                                mean diameters from the wall (0: no core; a
                                level set: where its depth map vouches for
                                that depth, docs/jam.md) */
    size_t core_count;       /* spheres in the core */
    double core_volume;      /* the core's volume */
    double mean_contacts;    /* Z: contacts per sphere over non-rattlers
                                (wall contacts count) */
    double rattler_fraction; /* share of spheres with fewer than 4 contacts
                                with non-rattlers (removed repeatedly) */
    double max_overlap;      /* largest overlap / (r_i + r_j) at the end */
    double radius_scale;     /* final radius / the distribution's radius */
    double particle_volume;
    int minimizations; /* energy minimisations (compression steps) */
    long iterations;   /* FIRE steps over all of them */
    int list_builds;   /* neighbour lists built */
    double seconds;
} vp_jam_report;

/* *out is owned by the caller; report may be NULL. Deterministic in seed
 * whatever the thread count. Progress stage "jam". */
VP_API vp_result vp_pack_jam(vp_context *ctx, const vp_container *c, const vp_jam_params *params,
                             vp_particles **out, vp_jam_report *report);
/* The container's load parameters for this job (as
 * vp_container_params_for_lattice in vdbpack.h). */
VP_API void vp_container_params_for_jam(vp_container_params *cp, const vp_jam_params *params);
#ifdef __cplusplus
}
#endif
#endif
