/* Mesh particle shapes from files: Assimp's import (in a child process,
 * see isolate.c), the topology check, then core/mesh_shape.c. */
#include "core/context.h"
#include "core/mesh_shape.h"
#include "mesh/mesh.h"

#include <string.h>

vp_result vp_mesh_shape_load(vp_context *ctx, const char *path, vp_mesh_shape **out) {
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "shape: out is NULL");
    *out = NULL;
    if (!path || !*path) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "shape: no mesh file given");
    char err[1024];
    vp_mesh *mesh = NULL;
    vp_result r = vp_mesh_load(path, &mesh, err, sizeof err);
    if (r != VP_OK) return vp_fail(ctx, r, "shape %s", err);
    const char *bn = vp_path_base(path);
    if (mesh->boundary_edges || mesh->nonmanifold_edges) {
        size_t b = mesh->boundary_edges, n = mesh->nonmanifold_edges;
        vp_mesh_destroy(mesh);
        return vp_fail(ctx, VP_ERR_OPEN_MESH,
                       "shape %s: the particle mesh is not closed (%zu boundary edges, %zu "
                       "non-manifold edges); a particle shape must enclose a volume",
                       bn, b, n);
    }
    double *verts = mesh->verts;
    uint32_t *tris = mesh->tris;
    size_t nv = mesh->nverts, nt = mesh->ntris;
    mesh->verts = NULL;
    mesh->tris = NULL;
    vp_mesh_destroy(mesh);
    return vp_mesh_shape_create(ctx, bn, verts, nv, tris, nt, out);
}
