/* Mesh input through Assimp's C API: every mesh of the scene flattened into
 * one triangle soup in world space, vertices welded by exact position, and
 * the topology counts that decide whether the mesh encloses a volume. */
#ifndef VDBPACK_MESH_MESH_H
#define VDBPACK_MESH_MESH_H

#include <stddef.h>
#include <stdint.h>
#include "vdbpack/vdbpack.h"

typedef struct vp_mesh {
    size_t nverts;        /* after welding */
    size_t nverts_raw;    /* as read (after Assimp's triangulation) */
    size_t ntris;         /* triangles kept (degenerate index triples dropped) */
    double *verts;        /* 3*nverts, owned */
    uint32_t *tris;       /* 3*ntris, owned */
    size_t boundary_edges;     /* edges used by exactly one triangle */
    size_t nonmanifold_edges;  /* edges used by three or more triangles */
    size_t zero_area_tris;
    size_t components;         /* connected components (by shared edges) */
    double signed_volume;      /* divergence theorem; > 0: outward normals */
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

/* Same, from an in-memory buffer; hint is the format extension ("obj"). */
vp_result vp_mesh_load_memory(const void *data, size_t size, const char *hint,
                              vp_mesh **out, char *err, size_t errlen);

void vp_mesh_destroy(vp_mesh *m);
#endif
