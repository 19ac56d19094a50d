/* SPDX-License-Identifier: Apache-2.0 */
/* Triangle-mesh topology shared by the mesh importer (src/mesh) and the
 * particle shapes (core/mesh_shape.c): the sides of the triangles sorted
 * into edges, and union-find over indices. Internal. */
#ifndef VDBPACK_CORE_MESH_TOPO_H
#define VDBPACK_CORE_MESH_TOPO_H

#include <stddef.h>
#include <stdint.h>

/* One side of a triangle: the edge it lies on (key: its two vertices,
 * smaller first, as (uint64)a << 32 | b), the triangle, and whether the
 * triangle runs along it from the smaller vertex to the larger. */
typedef struct vp_edge_side {
    uint64_t key;
    uint32_t tri;
    uint8_t side;    /* 0, 1, 2: from corner side to corner side + 1 */
    uint8_t forward; /* 1: the triangle goes a -> b (a < b) */
} vp_edge_side;

/* The 3 * ntris sides of the triangles, sorted by edge and then triangle:
 * the sides of one edge are adjacent. malloc'd (free()); NULL when out of
 * memory. */
vp_edge_side *vp_edge_sides(const uint32_t *tris, size_t ntris);

/* Union-find over 0..n-1: parent[i] = i to start. */
uint32_t vp_uf_find(uint32_t *parent, uint32_t x);
/* Joins the sets of a and b (the smaller root becomes the root). */
void vp_uf_union(uint32_t *parent, uint32_t a, uint32_t b);
#endif
