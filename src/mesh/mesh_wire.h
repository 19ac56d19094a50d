/* SPDX-License-Identifier: Apache-2.0 */
/* The answer a mesh-import child writes to its pipe (src/mesh/isolate.c):
 * a fixed header (the result, the message's length, the mesh's counts and
 * bounds), the message, then on success the vertex and triangle arrays.
 * Both ends are this file's, so the format is in one place. Internal to
 * src/mesh. */
#ifndef VDBPACK_MESH_WIRE_H
#define VDBPACK_MESH_WIRE_H

#include "mesh/mesh.h"
#include "os/subproc.h"

/* Writes result r, its message err and, when r is VP_OK, the mesh m (may
 * be NULL) to fd. 0, or -1 when a write failed. */
int vp_mesh_wire_write(int fd, vp_result r, const char *err, const vp_mesh *m);

/* Reads what vp_mesh_wire_write wrote, under the watch w; returns as
 * vp_subproc_read_all (0: all of it). On 0, *res is the child's result,
 * with its message in err, or VP_OK with the mesh in *out (owned by the
 * caller), or VP_ERR_OUT_OF_MEMORY ("NAME: out of memory" in err) when
 * the mesh cannot be allocated here. On any other return *out is NULL and
 * *res VP_OK. */
int vp_mesh_wire_read(int fd, vp_subproc_watch *w, const char *name, vp_result *res, vp_mesh **out,
                      char *err, size_t errlen);

#endif
