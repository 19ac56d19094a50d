/* SPDX-License-Identifier: Apache-2.0 */
/* Particle shapes from closed meshes (any format Assimp reads), convex or
 * not: the unit shape, a bounding-volume hierarchy over its triangles, and
 * the exact tests the packers and the checker share (see mesh_shape.c and
 * docs/rsa.md, "Mesh shapes"). Internal. */
#ifndef VDBPACK_CORE_MESH_SHAPE_H
#define VDBPACK_CORE_MESH_SHAPE_H

#include <stddef.h>
#include <stdint.h>

#include "vdbpack/vdbpack.h"

typedef struct vp_bvh_node {
    double lo[3], hi[3];
    uint32_t first; /* leaf: first index into order; inner: left child (right = first + 1) */
    uint32_t count; /* leaf: triangles; 0 for inner nodes */
} vp_bvh_node;

struct vp_mesh_shape {
    char name[256]; /* the file's base name */
    size_t nverts, ntris, nedges;
    double *verts;   /* 3*nverts, centroid at the origin, bounding radius 1 */
    uint32_t *tris;  /* 3*ntris, counter-clockwise seen from outside */
    uint32_t *edges; /* 2*nedges, each undirected edge once */
    uint32_t *order; /* ntris triangle indices in BVH leaf order */
    vp_bvh_node *nodes;
    size_t nnodes;
    uint32_t *reps; /* one vertex of each connected component */
    size_t nreps;
    double volume;   /* at bounding radius 1 */
    double inradius; /* distance from the origin to the surface when the
                              origin is inside, else 0 */
    double bb_lo[3], bb_hi[3];
    double max_edge; /* longest edge, unit shape */
};

/* Builds a shape from a closed, consistently oriented triangle mesh (the
 * caller has checked the topology; either orientation): normalises it,
 * builds the BVH. Takes ownership of verts (3*nverts) and tris (3*ntris),
 * also on failure. name: for messages and metadata. Refuses non-finite
 * vertices and meshes that enclose no volume. */
vp_result vp_mesh_shape_create(vp_context *ctx, const char *name, double *verts, size_t nverts,
                               uint32_t *tris, size_t ntris, vp_mesh_shape **out);

/* 1 if the interiors of two copies of m, placed at (scale, q, t) each,
 * intersect: some pair of triangles crosses (separating-axis test on the
 * triangle pair in double; touching is not crossing), or one copy holds a
 * vertex of some connected component of the other (containment, by ray
 * parity).
 * depth NULL: stops at the first crossing. Otherwise *depth is a world
 * measure of how deep the overlap is (0 when apart): the largest
 * penetration depth over crossing triangle pairs, or the smaller scale
 * times the inradius when one copy lies inside the other. */
int vp_mesh_shape_overlap(const vp_mesh_shape *m, double sa, const double qa[4], const double ta[3],
                          double sb, const double qb[4], const double tb[3], double *depth);

/* The same for copies of two meshes (ma at (sa, qa, ta), mb at (sb, qb,
 * tb)); vp_mesh_shape_overlap is this with ma == mb. */
int vp_mesh_shape_overlap2(const vp_mesh_shape *ma, double sa, const double qa[4],
                           const double ta[3], const vp_mesh_shape *mb, double sb,
                           const double qb[4], const double tb[3], double *depth);

/* 1 if the mesh m placed at (s, q, t) and the convex shape c (superball.h:
 * a sphere, superball or polyhedron, posed with its centre at c_centre in
 * world coordinates and lying in the ball of radius c_radius about it)
 * overlap: a face of m meets c (GJK, triangle against c), or c's centre
 * lies inside m. */
struct vp_convex;
int vp_mesh_shape_overlap_convex(const vp_mesh_shape *m, double s, const double q[4],
                                 const double t[3], const struct vp_convex *c,
                                 const double c_centre[3], double c_radius);

/* Nearest crossing of the ray o + t d (unit-shape coordinates, d of any
 * length) with the surface for tmin < t < tmax: 1 with *t_hit and the
 * triangle's outward unit normal (unit-shape frame), or 0. */
int vp_mesh_shape_ray(const vp_mesh_shape *m, const double o[3], const double d[3], double tmin,
                      double tmax, double *t_hit, double n_out[3]);

/* 1 if unit-shape point p is inside the mesh (ray parity, the majority of
 * three directions). */
int vp_mesh_shape_contains(const vp_mesh_shape *m, const double p[3]);

/* As vp_poly_wall_distance (shape.h) for a mesh shape: its vertices and, for
 * level sets, points of its edges and faces no more than a voxel apart. */
struct vp_container;
double vp_mesh_shape_wall_distance(const struct vp_container *c, const vp_mesh_shape *m,
                                   double scale, const double q[4], const double t[3], double stop);
#endif
