/* SPDX-License-Identifier: Apache-2.0 */
/* Lattice bases, at bounding-sphere radius 1, for packing spheres on SC,
 * BCC, FCC and HCP, and each platonic solid (in the canonical orientation of
 * shape.h) on its densest known lattice. Sources and derivations are in
 * docs/lattices.md. */
#ifndef VDBPACK_CORE_LATTICE_BASIS_H
#define VDBPACK_CORE_LATTICE_BASIS_H

#include "vdbpack/vdbpack.h"

typedef struct vp_lattice_basis {
    double a[3][3];     /* primitive vectors a1, a2, a3 (rows) */
    int nsites;         /* points per primitive cell: 1 (Bravais) or 2 (HCP) */
    double sites[2][3]; /* their offsets inside the cell (sites[0] = 0) */
    double fraction;    /* literature packing fraction (volume fraction) */
    const char *name;   /* e.g. "FCC (ABC)", "Minkowski octahedron lattice" */
    const char *source; /* reference */
} vp_lattice_basis;

/* Resolves VP_LATTICE_DEFAULT (FCC for spheres, DENSEST for solids).
 * Returns 0 and fills *out, or -1 when the combination is not offered
 * (SC/BCC/FCC/HCP are for spheres only; DENSEST for spheres means FCC). */
int vp_lattice_basis_get(vp_shape shape, vp_lattice lattice, vp_lattice_basis *out);
/* The same for shapes with a parameter: superballs (DEFAULT or DENSEST
 * only) on the densest lattice family of Jiao et al. 2009 at p, its
 * fraction the superball's volume over the cell's. */
int vp_lattice_basis_get_param(vp_shape shape, double param, vp_lattice lattice,
                               vp_lattice_basis *out);
#endif
