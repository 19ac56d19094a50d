/* Atomic file output; see atomic.h. */
#include "api/atomic.h"
#include "core/context.h"

#include <errno.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Temporary files of writes in progress, for vp_remove_partial_outputs()
 * in a signal handler: fixed slots, claimed and released atomically, so the
 * handler never sees a half-written name (a slot is published only once its
 * name is complete). */
#define VP_TEMP_SLOTS 16
static char g_temp[VP_TEMP_SLOTS][4096];
static atomic_int g_temp_used[VP_TEMP_SLOTS]; /* 0 free, 1 being filled, 2 live */

static void temp_register(vp_atomic *a) {
    a->slot = -1;
    for (int i = 0; i < VP_TEMP_SLOTS; i++) {
        int expect = 0;
        if (atomic_compare_exchange_strong(&g_temp_used[i], &expect, 1)) {
            memcpy(g_temp[i], a->tmp_path, sizeof g_temp[i]);
            atomic_store(&g_temp_used[i], 2);
            a->slot = i;
            return;
        }
    }
}

static void temp_release(vp_atomic *a) {
    if (a->slot >= 0) atomic_store(&g_temp_used[a->slot], 0);
    a->slot = -1;
}

void vp_remove_partial_outputs(void) {
    for (int i = 0; i < VP_TEMP_SLOTS; i++)
        if (atomic_load(&g_temp_used[i]) == 2) unlink(g_temp[i]);
}

vp_result vp_atomic_begin(vp_context *ctx, const char *path, vp_atomic *a) {
    memset(a, 0, sizeof *a);
    a->slot = -1;
    if (!path || !*path) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "no output path given");
    size_t n = strlen(path);
    if (n >= sizeof a->final_path - 32)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: output path too long", path);
    struct stat st;
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot write output: it is a directory", path);
    memcpy(a->final_path, path, n + 1);
    const char *slash = strrchr(path, '/');
    char dir[4096];
    if (slash) {
        size_t dl = (size_t)(slash - path);
        if (dl == 0) dl = 1; /* "/file" */
        memcpy(dir, path, dl);
        dir[dl] = 0;
    } else {
        strcpy(dir, ".");
    }
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot write output: directory %s does not exist",
                       path, dir);
    snprintf(a->tmp_path, sizeof a->tmp_path, "%s/.%s.tmp-XXXXXX", dir, slash ? slash + 1 : path);
    int fd = mkstemp(a->tmp_path);
    if (fd < 0) {
        int e = errno;
        a->tmp_path[0] = 0;
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot write output (%s)", path, strerror(e));
    }
    close(fd);
    temp_register(a);
    return VP_OK;
}

vp_result vp_atomic_commit(vp_context *ctx, vp_atomic *a) {
    struct stat st;
    if (stat(a->tmp_path, &st) != 0 || st.st_size == 0) {
        vp_atomic_abort(a);
        return vp_fail(ctx, VP_ERR_IO, "%s: writing failed (nothing was written)", a->final_path);
    }
    /* mkstemp makes 0600 files; outputs should follow the umask like any file */
    mode_t um = umask(0);
    umask(um);
    chmod(a->tmp_path, 0666 & ~um);
    temp_release(a);
    if (rename(a->tmp_path, a->final_path) != 0) {
        int e = errno;
        vp_atomic_abort(a);
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot write output (%s)", a->final_path, strerror(e));
    }
    a->tmp_path[0] = 0;
    return VP_OK;
}

void vp_atomic_abort(vp_atomic *a) {
    if (a) temp_release(a);
    if (a && a->tmp_path[0]) {
        unlink(a->tmp_path);
        a->tmp_path[0] = 0;
    }
}
