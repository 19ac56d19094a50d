/* SPDX-License-Identifier: Apache-2.0 */
/* Mesh input through Assimp's C API: every mesh of the scene flattened into
 * one triangle soup in world space, vertices welded by exact position, and
 * the topology counts that decide whether the mesh encloses a volume. */
#ifndef VDBPACK_MESH_MESH_H
#define VDBPACK_MESH_MESH_H

#include <stddef.h>
#include <stdint.h>
#include "vdbpack/vdbpack.h"

typedef struct vp_mesh {
    size_t nverts;             /* after welding */
    size_t nverts_raw;         /* as read (after Assimp's triangulation) */
    size_t ntris;              /* triangles kept (degenerate index triples dropped) */
    double *verts;             /* 3*nverts, owned */
    uint32_t *tris;            /* 3*ntris, owned */
    size_t boundary_edges;     /* edges used by exactly one triangle */
    size_t nonmanifold_edges;  /* edges used by three or more triangles */
    size_t inconsistent_edges; /* edges of two triangles that run along it the
                                  same way (the orientation flips there) */
    size_t zero_area_tris;
    size_t components;    /* connected components (by shared edges) */
    double signed_volume; /* divergence theorem; > 0: outward normals */
    double bmin[3], bmax[3];
} vp_mesh;

/* Loads path with Assimp (OBJ, PLY, STL, glTF, ... whatever it reads).
 * Errors (one line naming the file, written to err): missing/unreadable
 * file (VP_ERR_IO), a file Assimp cannot parse or with no triangles
 * (VP_ERR_FORMAT), a non-finite coordinate (VP_ERR_FORMAT, naming the
 * vertex and its coordinates; the number is Assimp's 0-based vertex index
 * counted over all meshes, and since Assimp's OBJ and STL readers give every
 * face corner its own vertex it is NOT the file's `v` line number).
 * Open meshes are NOT refused here: the caller reads the counts.
 * Assimp (as packaged) stores coordinates as float: they are widened to
 * double, so values that differ only beyond float precision weld together.
 * *out is owned by the caller (vp_mesh_destroy). */
vp_result vp_mesh_load(const char *path, vp_mesh **out, char *err, size_t errlen);
/* vp_mesh_load with the reader child bounded by guard (os/subproc.h: the
 * caller's cancel, polled while Assimp reads, and its memory limit; NULL:
 * neither). Anything but a regular file (a FIFO, a device) is refused at
 * once (VP_ERR_IO), and so is a PLY whose header declares more data than
 * the file holds (VP_ERR_FORMAT). */
struct vp_subproc_guard;
vp_result vp_mesh_load_guarded(const char *path, const struct vp_subproc_guard *guard,
                               vp_mesh **out, char *err, size_t errlen);

/* Same, from an in-memory buffer; hint is the format extension ("obj"). */
vp_result vp_mesh_load_memory(const void *data, size_t size, const char *hint, vp_mesh **out,
                              char *err, size_t errlen);

/* A mesh from arrays in memory (vp_container_from_mesh,
 * vp_mesh_shape_from_mesh): verts holds 3*nverts doubles, tris 3*ntris
 * indices into them (counter-clockwise seen from outside). Welded and
 * counted as an imported file is. Errors (one line naming `name`, "mesh"
 * if NULL, in err): NULL or misaligned arrays, an index out of range or a
 * non-finite coordinate (VP_ERR_INVALID_ARGUMENT), no triangles or all
 * degenerate (VP_ERR_FORMAT). The arrays are only read. *out is owned by
 * the caller. */
vp_result vp_mesh_from_arrays(const double *verts, size_t nverts, const uint32_t *tris,
                              size_t ntris, const char *name, vp_mesh **out, char *err,
                              size_t errlen);

void vp_mesh_destroy(vp_mesh *m);

/* ---- building blocks shared by the importer and vp_mesh_from_arrays ---- */

/* Welding by exact position: an open-addressing hash on the bit pattern of
 * (x, y, z), -0.0 counted as +0.0. */
typedef struct vp_weld {
    uint32_t *table; /* slots: welded id + 1, 0 = empty */
    size_t cap;      /* a power of two, at least twice the points */
    double *pos;     /* 3*n welded positions, in order of creation */
    size_t n;
} vp_weld;
/* Room for max_points points: 0, or -1 when out of memory. */
int vp_weld_init(vp_weld *w, size_t max_points);
/* The welded id of p (a new one, or that of an equal point added before). */
uint32_t vp_weld_add(vp_weld *w, const double p[3]);
void vp_weld_free(vp_weld *w);
/* The mesh of ntri triangles of welded ids (tris: 3*ntri, owned by the
 * result, or freed on failure) over w's points: keeps the points they use,
 * in order of first use, and counts the topology, bounds and signed volume.
 * nraw: vertices before welding; zero_area_tris: triangles dropped as
 * degenerate so far. VP_OK or VP_ERR_OUT_OF_MEMORY; w is left as it was. */
vp_result vp_mesh_finish(vp_weld *w, uint32_t *tris, size_t ntri, size_t nraw,
                         size_t zero_area_tris, vp_mesh **out);
/* What vp_mesh_prepare_winding changed. */
typedef struct vp_mesh_repair {
    size_t duplicate_triangles;  /* dropped: a second copy of a triangle */
    size_t opposite_triangles;   /* dropped: a triangle and its reverse, which cancel */
    size_t reoriented_triangles; /* turned to agree with their neighbours */
    size_t pieces;               /* connected pieces */
    size_t open_pieces;          /* pieces with boundary or non-manifold edges */
    size_t turned_pieces;        /* pieces turned inside out as a whole */
    size_t cavities;             /* closed reversed pieces kept as cavities */
    int pieces_overlap;          /* 1: the bounding boxes of two pieces overlap
                                    (they may cross or nest) */
} vp_mesh_repair;
/* Readies m's triangles for the winding-number inside (mesh_inside.c):
 * drops duplicates, orients each piece consistently, turns inside-out
 * pieces, keeps reversed closed pieces that lie inside the rest as
 * cavities; then counts again (vp_mesh_recount). rep may be NULL. VP_OK or
 * VP_ERR_OUT_OF_MEMORY. */
vp_result vp_mesh_prepare_winding(vp_mesh *m, vp_mesh_repair *rep);
/* Boxes around the mesh's holes, where the winding number's film may span
 * them: one a rim (boundary edges joined by their vertices), its bounds
 * grown by half its diagonal each way within the mesh's bounds grown by a
 * tenth of their diagonal; 6 doubles a
 * box (min, max). *boxes is malloc'd (free()), NULL when there are none.
 * VP_OK or VP_ERR_OUT_OF_MEMORY. */
vp_result vp_mesh_hole_boxes(const vp_mesh *m, double **boxes, size_t *nboxes);
/* One byte a triangle: 1 when one of its edges is a boundary edge (a
 * hole's rim). malloc'd (free()); NULL when out of memory. */
uint8_t *vp_mesh_rim_triangles(const vp_mesh *m);
/* Counts again what depends on the triangles (after they changed): bounds,
 * signed volume, boundary, non-manifold and inconsistent edges,
 * components. VP_OK or VP_ERR_OUT_OF_MEMORY. */
vp_result vp_mesh_recount(vp_mesh *m);
/* "nan", "inf" or "-inf". */
const char *vp_mesh_nonfinite_name(double v);
#endif
