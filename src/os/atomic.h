/* SPDX-License-Identifier: Apache-2.0 */
/* Atomic file output: write to a temporary file beside the target, then
 * rename over it, so that no partial file is ever left at the target.
 * A symbolic link is followed (the file it names is replaced, the link
 * stays); a target that exists and is not a regular file (a device such
 * as /dev/null, a FIFO) is written through instead: the finished
 * temporary file is copied into it, and it is never replaced.
 * Operating-system layer: no library context; a failure's one-line
 * message is left in vp_atomic.err (api/atomic.h passes it on to a
 * context). */
#ifndef VDBPACK_OS_ATOMIC_H
#define VDBPACK_OS_ATOMIC_H

#include "vdbpack/vdbpack.h"

typedef struct vp_atomic {
    char final_path[4096];
    char tmp_path[4096];
    int slot;    /* in the registry of vp_remove_partial_outputs(), or -1 */
    int through; /* the target is not a regular file: copy into it */
    int dirfd;   /* the target's directory, when tmp_path names the
                      temporary through /proc/self/fd (a target path within
                      14 bytes of PATH_MAX) and dir_open is 1 */
    int dir_open;
    char err[1024]; /* the last failure's message */
} vp_atomic;

/* Checks that path can be written (not a directory, parent exists and is
 * writable) and creates an empty temporary file beside it, named
 * .vp-XXXXXX.tmp (14 bytes, whatever the target's name: a name of 255
 * bytes, the most a directory entry takes, had no room for a temporary
 * name built from it). Any path shorter than PATH_MAX (4096) can be
 * written: where the temporary's own path would be longer, it is named
 * through /proc/self/fd and a descriptor of the directory. */
vp_result vp_os_atomic_begin(vp_atomic *a, const char *path);
/* Renames the temporary file onto the target. On failure the temporary
 * file is removed. */
vp_result vp_os_atomic_commit(vp_atomic *a);
/* Removes the temporary file (after a failed write). */
void vp_os_atomic_abort(vp_atomic *a);
#endif
