/* SPDX-License-Identifier: Apache-2.0 */
/* Atomic file output for the library's writers (os/atomic.h), with a
 * failure's message passed on to the caller's context. */
#ifndef VDBPACK_API_ATOMIC_H
#define VDBPACK_API_ATOMIC_H

#include "core/context.h"
#include "os/atomic.h"

/* vp_os_atomic_begin, its message left on ctx. */
static inline vp_result vp_atomic_begin(vp_context *ctx, const char *path, vp_atomic *a) {
    vp_result r = vp_os_atomic_begin(a, path);
    return r == VP_OK ? r : vp_fail(ctx, r, "%s", a->err);
}
/* vp_os_atomic_commit, its message left on ctx. */
static inline vp_result vp_atomic_commit(vp_context *ctx, vp_atomic *a) {
    vp_result r = vp_os_atomic_commit(a);
    return r == VP_OK ? r : vp_fail(ctx, r, "%s", a->err);
}
static inline void vp_atomic_abort(vp_atomic *a) { vp_os_atomic_abort(a); }
#endif
