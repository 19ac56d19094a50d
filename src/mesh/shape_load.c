/* SPDX-License-Identifier: Apache-2.0 */
/* Mesh particle shapes from files (Assimp's import, in a child process:
 * see isolate.c) or arrays in memory: the topology check, then
 * core/mesh_shape.c. */
#include "core/context.h"
#include "core/mesh_shape.h"
#include "mesh/mesh.h"
#include "os/subproc.h"

#include <string.h>

/* A welded mesh (owned: destroyed here) into a shape named bn, once it is
 * known to be closed. */
static vp_result shape_from_welded(vp_context *ctx, const char *bn, vp_mesh *mesh,
                                   vp_mesh_shape **out)
{
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

vp_result vp_mesh_shape_load(vp_context *ctx, const char *path, vp_mesh_shape **out)
{
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "shape: out is NULL");
    *out = NULL;
    if (!path || !*path) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "shape: no mesh file given");
    char err[1024];
    vp_mesh *mesh = NULL;
    vp_subproc_guard guard; /* cancel and --max-memory reach the reader */
    vp_context_child_guard(ctx, &guard);
    vp_result r = vp_mesh_load_guarded(path, &guard, &mesh, err, sizeof err);
    if (r == VP_ERR_CANCELLED) return vp_fail(ctx, r, "cancelled");
    if (r != VP_OK) return vp_fail(ctx, r, "shape %s", err);
    return shape_from_welded(ctx, vp_path_base(path), mesh, out);
}

vp_result vp_mesh_shape_from_mesh(vp_context *ctx, const char *name, const double *vertices,
                                  size_t vertex_count, const uint32_t *triangles,
                                  size_t triangle_count, vp_mesh_shape **out)
{
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "shape: out is NULL");
    *out = NULL;
    if (!name || !*name) name = "mesh";
    char err[1024];
    vp_mesh *mesh = NULL;
    vp_result r = vp_mesh_from_arrays(vertices, vertex_count, triangles, triangle_count, name,
                                      &mesh, err, sizeof err);
    if (r != VP_OK) return vp_fail(ctx, r, "shape %s", err);
    return shape_from_welded(ctx, name, mesh, out);
}
