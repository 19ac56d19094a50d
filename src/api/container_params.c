/* SPDX-License-Identifier: Apache-2.0 */
/* What a mesh or level-set container needs to know of the job before it is
 * loaded (vp_container_params_for_*): the largest particle radius sizes the
 * level set's interior band and the automatic voxel size, and a count with
 * the space one particle takes gives that radius when the job has none. The
 * command line and the Python module both go through these, so that a job
 * gives the same container, and the same particles, either way. */
#include "vdbpack/vdbpack.h"

#include <math.h>

void vp_container_params_for_lattice(vp_container_params *cp, const vp_lattice_params *lp) {
    if (!cp || !lp) return;
    cp->particle_radius = lp->radius;
    cp->particle_count = lp->radius > 0 ? 0 : lp->count;
    /* space one particle of bounding radius 1 takes: its volume over the
     * lattice's packing fraction */
    double f = vp_lattice_fraction_param(lp->shape, lp->shape_param, lp->lattice);
    cp->space_per_particle =
        f > 0 ? vp_shape_unit_volume_param(lp->shape, lp->shape_param) / f : 0.0;
    /* the lattice packer reads no deeper than a particle's radius and the
     * margin */
    cp->narrow_band = 1;
    cp->extra_depth = lp->margin;
}

void vp_container_params_for_rsa(vp_container_params *cp, const vp_rsa_params *rp) {
    if (!cp || !rp) return;
    double rmax = 0;
    size_t count = 0;
    for (size_t i = 0; i < rp->npasses && rp->passes; i++) {
        rmax = fmax(rmax, vp_size_dist_max(&rp->passes[i].radius));
        if (!rp->passes[i].maximal) count += rp->passes[i].count;
    }
    /* a radius field: its largest value, or that times the passes' */
    if (rp->radius_field) {
        vp_field_info fi;
        vp_field_get_info(rp->radius_field, &fi);
        rmax = rp->radius_field_mode == VP_FIELD_ABSOLUTE ? fi.max : rmax * fi.max;
        if (!(rmax > 0)) rmax = 0; /* (refused by the packer) */
    }
    cp->particle_radius = rmax;
    cp->particle_count = count;
    cp->space_per_particle = 0;
    cp->narrow_band = 0;          /* room for growth */
    cp->extra_depth = rp->margin; /* distances are clamped past the band */
}

void vp_container_params_for_relax(vp_container_params *cp, const vp_relax_params *xp) {
    if (!cp || !xp) return;
    cp->particle_count = xp->count;
    cp->narrow_band = 0;
    cp->extra_depth = xp->margin;
    if (xp->target_fraction > 0) {
        /* the radii are scaled so that count spheres fill target_fraction:
         * the largest is rmax, the mean cube E[r^3] */
        double rmax = vp_size_dist_max(&xp->radius), m3 = vp_size_dist_mean_cube(&xp->radius);
        cp->particle_radius = 0;
        cp->space_per_particle =
            4.0 / 3.0 * M_PI * (m3 / (rmax * rmax * rmax)) / xp->target_fraction;
    } else {
        cp->particle_radius = vp_size_dist_max(&xp->radius);
        cp->space_per_particle = 0;
    }
}
