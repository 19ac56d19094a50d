/* SPDX-License-Identifier: Apache-2.0 */
/* Mesh import in a child process (see isolate.c): Assimp's hangs and crashes
 * on hostile files become errors. Internal to src/mesh. */
#ifndef VDBPACK_MESH_ISOLATE_H
#define VDBPACK_MESH_ISOLATE_H

#include "mesh/mesh.h"
#include "os/subproc.h"

/* Imports in the current process; arg is the importer's own argument. */
typedef vp_result (*vp_mesh_import_fn)(const void *arg, vp_mesh **out, char *err, size_t errlen);

/* Runs fn(arg) in a forked child (vp_subproc_fork: its own process group,
 * dies with its parent, default signal actions, guard's memory bound) and
 * returns its mesh (owned by the caller) or its error. A child that runs
 * past timeout seconds is killed; one that dies is reported by signal;
 * guard's cancel (may be NULL) is polled while waiting, and kills the
 * child (VP_ERR_CANCELLED, "cancelled"). Errors are one line naming
 * `name`. */
vp_result vp_mesh_import_isolated(vp_mesh_import_fn fn, const void *arg, const char *name,
                                  double timeout, const vp_subproc_guard *guard, vp_mesh **out,
                                  char *err, size_t errlen);

/* Whether imports run in a child process (the product) or in-process
 * (fuzz and AddressSanitizer builds, where a hang or crash of Assimp is not
 * contained): vp_readers_isolated() in vdbpack.h. */

/* Deadline for a file of that size: $VDBPACK_IMPORT_TIMEOUT seconds when
 * set, otherwise 10 s plus 2 s per MB. */
double vp_mesh_import_timeout(size_t file_bytes);

#endif
