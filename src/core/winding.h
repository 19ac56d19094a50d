/* SPDX-License-Identifier: Apache-2.0 */
/* Generalized winding numbers of triangle meshes (Jacobson, Kavan &
 * Sorkine-Hornung 2013), evaluated hierarchically after Barill, Dickson,
 * Schmidt, Levin & Jacobson 2018 ("Fast Winding Numbers for Soups and
 * Clouds"): a bounding-volume tree over the triangles whose far nodes
 * count as a dipole (their area-weighted normal at their area-weighted
 * centre), and whose near leaves sum the triangles' exact solid angles
 * (Van Oosterom & Strackee 1983). For a closed, outward mesh the winding
 * number is 1 inside and 0 outside; for an open or broken one it varies
 * smoothly across holes, and "inside" is where it is at least 0.5.
 * Internal to the library (docs/design.md, "Inside of a mesh"). */
#ifndef VDBPACK_CORE_WINDING_H
#define VDBPACK_CORE_WINDING_H

#include <stddef.h>
#include <stdint.h>

typedef struct vp_winding vp_winding;

/* Builds the tree over ntris triangles (tris: 3 * ntris indices into verts,
 * 3 * nverts doubles; counter-clockwise seen from outside). rim (may be
 * NULL: none) marks the triangles with a boundary edge (one a triangle),
 * for vp_winding_block. The arrays are copied: the tree owns what it needs.
 * NULL when out of memory. Immutable once built: evaluation is safe from
 * several threads at once. */
vp_winding *vp_winding_build(const double *verts, size_t nverts, const uint32_t *tris, size_t ntris,
                             const uint8_t *rim);
void vp_winding_destroy(vp_winding *w); /* NULL: no-op */

/* The winding number at q. */
double vp_winding_at(const vp_winding *w, const double q[3]);
/* The winding numbers at n points (3 * n doubles) into out (n doubles).
 * Points that lie close together (a leaf of voxels) share one traversal of
 * the tree: the nodes far from all of them are found once. */
void vp_winding_batch(const vp_winding *w, const double *pts, size_t n, double *out);
/* The winding numbers at the 8 x 8 x 8 points lo + h * (i, j, k) into
 * out[64 i + 8 j + k] (OpenVDB's order within a leaf node): one evaluation
 * at lo, then the crossings of the segments between neighbouring points
 * with the triangles (each one changes the number by exactly 1), checked
 * against evaluations at far corners of the block; points where the counts
 * and the check disagree, or whose value is near 0.5, are evaluated one by
 * one. Much cheaper than 512 evaluations where the block holds few
 * triangles. */
void vp_winding_block(const vp_winding *w, const double lo[3], double h, double *out);
/* The same by the exact sum over every triangle (tests, and small meshes). */
double vp_winding_exact(const double *verts, const uint32_t *tris, size_t ntris, const double q[3]);
#endif
