/* Atomic file output; see atomic.h. */
#include "api/atomic.h"
#include "core/context.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

vp_result vp_atomic_begin(vp_context *ctx, const char *path, vp_atomic *a) {
    memset(a, 0, sizeof *a);
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
    if (rename(a->tmp_path, a->final_path) != 0) {
        int e = errno;
        vp_atomic_abort(a);
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot write output (%s)", a->final_path, strerror(e));
    }
    a->tmp_path[0] = 0;
    return VP_OK;
}

void vp_atomic_abort(vp_atomic *a) {
    if (a && a->tmp_path[0]) {
        unlink(a->tmp_path);
        a->tmp_path[0] = 0;
    }
}
