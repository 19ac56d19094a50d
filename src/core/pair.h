/* SPDX-License-Identifier: Apache-2.0 */
/* The exact overlap test of two particles of any shapes: the one place
 * that knows every pairing of kinds (sphere, platonic and Archimedean
 * solid, superball, mesh shape). The packers keep faster paths for two
 * particles of one shape and call this for the others (mixed packings,
 * docs/shapes.md "Several shapes in one packing"); vdbpack check calls it
 * for every pair of two shapes. Internal. */
#ifndef VDBPACK_CORE_PAIR_H
#define VDBPACK_CORE_PAIR_H

#include "vdbpack/vdbpack.h"

struct vp_polyhedron;

/* One shape with what its tests need, resolved once. */
typedef struct vp_kind {
    vp_shape shape;
    double param;                     /* superball exponent, else 0 */
    const struct vp_polyhedron *poly; /* solids, else NULL */
    const vp_mesh_shape *mesh;        /* mesh shapes, else NULL */
    double rin;                       /* insphere / bounding radius (1 for spheres) */
    double unit_volume;               /* at bounding radius 1 */
} vp_kind;

/* Fills k from a shape; returns 0, or -1 for an invalid one (unknown
 * shape, superball exponent outside [0.5, 1000], mesh shape without its
 * mesh, VP_SHAPE_MIXED). */
int vp_kind_set(vp_kind *k, vp_shape_ref ref);

/* 1 if the interiors of particle a (kind ka, bounding radius sa,
 * orientation qa, centre ta) and particle b overlap. Spheres by distance,
 * two platonic solids of one kind by the separating-axis test, two meshes
 * by their faces and containment, a mesh and a convex shape by GJK on
 * each face, any two convex shapes by GJK (undecided counts as overlap:
 * the packers never let one through). Touching is not overlapping. */
int vp_kind_overlap(const vp_kind *ka, double sa, const double qa[4], const double ta[3],
                    const vp_kind *kb, double sb, const double qb[4], const double tb[3]);

/* 1 if the two come closer than gap (>= 0; 0: vp_kind_overlap): the
 * overlap of both grown by gap / 2 (Minkowski sums with a ball, by GJK on
 * the grown support functions). Convex shapes only: a mesh shape with
 * gap > 0 answers 1 (the packers refuse gaps for mesh shapes). */
int vp_kind_overlap_gap(const vp_kind *ka, double sa, const double qa[4], const double ta[3],
                        const vp_kind *kb, double sb, const double qb[4], const double tb[3],
                        double gap);

/* vp_kind_overlap_gap with GJK's undecided case apart (-1; 1 overlap, 0
 * apart): for vdbpack check, which counts it as a contact, where the
 * packers refuse it. */
int vp_kind_overlap_state(const vp_kind *ka, double sa, const double qa[4], const double ta[3],
                          const vp_kind *kb, double sb, const double qb[4], const double tb[3],
                          double gap);
#endif
