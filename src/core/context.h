/* SPDX-License-Identifier: Apache-2.0 */
/* The library context (opaque in the public API): last error message,
 * thread count, progress callback and memory limit. */
#ifndef VDBPACK_CORE_CONTEXT_H
#define VDBPACK_CORE_CONTEXT_H

#include "vdbpack/vdbpack.h"

struct vp_context {
    char message[1024];
    int threads; /* 0 = all cores */
    vp_progress_fn progress;
    void *progress_user;
    uint64_t max_memory; /* 0 = physical memory */
    /* during a progress call from vp_report_progress_counts: its counts */
    int has_counts;
    uint64_t count_done, count_total;
};

/* Records a failure on ctx (printf-style message) and returns r. */
vp_result vp_fail(vp_context *ctx, vp_result r, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* Threads to use for ctx (resolves 0 to the number of online cores). */
int vp_threads_for(const vp_context *ctx);
/* Reports progress; returns 0 when the caller asked to cancel. */
int vp_report_progress(vp_context *ctx, double fraction, const char *stage);
/* The same, with the particles the stage has placed so far and the number
 * it aims at (0: none fixed), which the callback reads through
 * vp_context_progress_counts. */
int vp_report_progress_counts(vp_context *ctx, double fraction, const char *stage, uint64_t done,
                              uint64_t total);
/* Memory limit in bytes: max_memory, else physical memory. */
uint64_t vp_memory_limit(const vp_context *ctx);
/* The part of path after its last '/' (a pointer into path). */
const char *vp_path_base(const char *path);
/* Whether the environment variable name is set to anything but "" or
 * "0" (the switches tests use: VDBPACK_NO_SIMD and the like). */
int vp_env_flag(const char *name);
/* "1.5 GB"-style text for a byte count. */
void vp_format_bytes(double bytes, char *out, size_t outlen);
/* Monotonic seconds. */
double vp_seconds(void);
/* The bounds of a reader child (os/subproc.h) from ctx: its progress
 * callback as the cancel, polled while the child reads (stage `stage`,
 * fraction 0), and its memory limit (max_memory; 0, the machine's memory,
 * when unset). ctx may be NULL. */
struct vp_subproc_guard;
void vp_context_child_guard(vp_context *ctx, struct vp_subproc_guard *g);
#endif
