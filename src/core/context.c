/* SPDX-License-Identifier: Apache-2.0 */
/* Context, result names and small process-level helpers. */
#include "core/context.h"
#include "os/subproc.h"
#include "os/text.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

const char *vp_version(void) { return VP_VERSION_STRING; }

int vp_version_number(void) { return VP_VERSION_NUMBER; }

const char *vp_result_name(vp_result r) {
    switch (r) {
    case VP_OK: return "VP_OK";
    case VP_ERR_INVALID_ARGUMENT: return "VP_ERR_INVALID_ARGUMENT";
    case VP_ERR_IO: return "VP_ERR_IO";
    case VP_ERR_FORMAT: return "VP_ERR_FORMAT";
    case VP_ERR_OPEN_MESH: return "VP_ERR_OPEN_MESH";
    case VP_ERR_NOT_LEVEL_SET: return "VP_ERR_NOT_LEVEL_SET";
    case VP_ERR_BAD_CONTAINER: return "VP_ERR_BAD_CONTAINER";
    case VP_ERR_NO_FIT: return "VP_ERR_NO_FIT";
    case VP_ERR_OUT_OF_MEMORY: return "VP_ERR_OUT_OF_MEMORY";
    case VP_ERR_CANCELLED: return "VP_ERR_CANCELLED";
    case VP_ERR_INTERNAL: return "VP_ERR_INTERNAL";
    }
    return "VP_ERR_UNKNOWN";
}

vp_result vp_context_create(vp_context **out) {
    if (!out) return VP_ERR_INVALID_ARGUMENT;
    *out = calloc(1, sizeof(vp_context));
    return *out ? VP_OK : VP_ERR_OUT_OF_MEMORY;
}

void vp_context_destroy(vp_context *ctx) { free(ctx); }

const char *vp_context_message(const vp_context *ctx) { return ctx ? ctx->message : ""; }

void vp_context_set_threads(vp_context *ctx, int threads) {
    if (ctx) ctx->threads = threads < 0 ? 0 : threads;
}

int vp_context_threads(const vp_context *ctx) { return vp_threads_for(ctx); }

void vp_context_set_progress(vp_context *ctx, vp_progress_fn fn, void *user) {
    if (!ctx) return;
    ctx->progress = fn;
    ctx->progress_user = user;
}

void vp_context_set_max_memory(vp_context *ctx, uint64_t bytes) {
    if (ctx) ctx->max_memory = bytes;
}

uint64_t vp_context_max_memory(const vp_context *ctx) { return vp_memory_limit(ctx); }

vp_result vp_fail(vp_context *ctx, vp_result r, const char *fmt, ...) {
    if (ctx) {
        va_list ap;
        va_start(ap, fmt);
        /* a long path loses its middle, not the reason at the end */
        vp_os_vformat(ctx->message, sizeof ctx->message, fmt, ap);
        va_end(ap);
    }
    return r;
}

int vp_env_flag(const char *name) {
    const char *v = getenv(name);
    return v && *v && strcmp(v, "0") != 0;
}

int vp_threads_for(const vp_context *ctx) {
    if (ctx && ctx->threads > 0) return ctx->threads;
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : (n > 256 ? 256 : (int)n);
}

int vp_report_progress(vp_context *ctx, double fraction, const char *stage) {
    if (!ctx || !ctx->progress) return 1;
    return ctx->progress(ctx->progress_user, fraction, stage);
}

int vp_report_progress_counts(vp_context *ctx, double fraction, const char *stage, uint64_t done,
                              uint64_t total) {
    if (!ctx || !ctx->progress) return 1;
    ctx->has_counts = 1;
    ctx->count_done = done;
    ctx->count_total = total;
    int go = ctx->progress(ctx->progress_user, fraction, stage);
    ctx->has_counts = 0;
    return go;
}

int vp_context_progress_counts(const vp_context *ctx, uint64_t *done, uint64_t *total) {
    if (!ctx || !ctx->has_counts) return 0;
    if (done) *done = ctx->count_done;
    if (total) *total = ctx->count_total;
    return 1;
}

uint64_t vp_memory_limit(const vp_context *ctx) {
    if (ctx && ctx->max_memory) return ctx->max_memory;
    long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || size <= 0) return (uint64_t)1 << 34;
    return (uint64_t)pages * (uint64_t)size;
}

void vp_format_bytes(double bytes, char *out, size_t outlen) {
    const char *units[] = {"B", "KB", "MB", "GB", "TB", "PB", "EB"};
    int u = 0;
    while (bytes >= 1000.0 && u < 6) {
        bytes /= 1000.0;
        u++;
    }
    /* beyond 1000 EB (absurd requests): %g keeps it short */
    snprintf(out, outlen, bytes >= 1000.0 ? "%.3g %s" : u ? "%.1f %s" : "%.0f %s", bytes, units[u]);
}

double vp_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int child_cancelled(void *ctx) {
    return !vp_report_progress((vp_context *)ctx, 0.0, "reading");
}

void vp_context_child_guard(vp_context *ctx, vp_subproc_guard *g) {
    g->cancel = ctx && ctx->progress ? child_cancelled : NULL;
    g->user = ctx;
    g->max_bytes = ctx ? ctx->max_memory : 0;
}

const char *vp_path_base(const char *path) {
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}
