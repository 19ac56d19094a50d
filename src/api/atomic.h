/* Atomic file output: write to a temporary file beside the target, then
 * rename over it, so that no partial file is ever left at the target.
 * A symbolic link is followed (the file it names is replaced, the link
 * stays); a target that exists and is not a regular file (a device such
 * as /dev/null, a FIFO) is written through instead: the finished
 * temporary file is copied into it, and it is never replaced. */
#ifndef VDBPACK_API_ATOMIC_H
#define VDBPACK_API_ATOMIC_H

#include "vdbpack/vdbpack.h"

typedef struct vp_atomic {
    char final_path[4096];
    char tmp_path[4096];
    int slot;    /* in the registry of vp_remove_partial_outputs(), or -1 */
    int through; /* the target is not a regular file: copy into it */
} vp_atomic;

/* Checks that path can be written (not a directory, parent exists and is
 * writable) and creates an empty temporary file beside it. */
vp_result vp_atomic_begin(vp_context *ctx, const char *path, vp_atomic *a);
/* Renames the temporary file onto the target. On failure the temporary
 * file is removed. */
vp_result vp_atomic_commit(vp_context *ctx, vp_atomic *a);
/* Removes the temporary file (after a failed write). */
void vp_atomic_abort(vp_atomic *a);
#endif
