/* SPDX-License-Identifier: Apache-2.0 */
/* Atomic file output; see atomic.h. */
#define _DEFAULT_SOURCE /* mkstemps */
#include "os/atomic.h"
#include "os/text.h"

#include <stdarg.h>

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Records a failure's message in a->err and returns r. */
static vp_result fail(vp_atomic *a, vp_result r, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static vp_result fail(vp_atomic *a, vp_result r, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vp_os_vformat(a->err, sizeof a->err, fmt, ap);
    va_end(ap);
    return r;
}

/* Closes the directory descriptor a temporary was named through. */
static void close_dir(vp_atomic *a) {
    if (a->dir_open) close(a->dirfd);
    a->dir_open = 0;
}

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

/* The file a symbolic link at path names (links followed up to 40 deep,
 * as the kernel does), in out; 0, or the errno of the failure: ELOOP for a
 * chain too long, ENAMETOOLONG for a name too long, readlink's own. A
 * dangling link names the file it would create. */
static int follow_links(const char *path, char *out, size_t outlen) {
    char cur[4096];
    if (strlen(path) >= sizeof cur) return ENAMETOOLONG;
    strcpy(cur, path);
    for (int depth = 0; depth < 40; depth++) {
        struct stat st;
        if (lstat(cur, &st) != 0 || !S_ISLNK(st.st_mode)) {
            if (strlen(cur) >= outlen) return ENAMETOOLONG;
            strcpy(out, cur);
            return 0;
        }
        char link[4096];
        ssize_t n = readlink(cur, link, sizeof link - 1);
        if (n < 0) return errno ? errno : EIO;
        link[n] = 0;
        char next[4096];
        const char *slash = strrchr(cur, '/');
        if (link[0] == '/' || !slash) {
            if ((size_t)n >= sizeof next) return ENAMETOOLONG;
            strcpy(next, link);
        } else {
            int w = snprintf(next, sizeof next, "%.*s/%s", (int)(slash - cur), cur, link);
            if (w < 0 || (size_t)w >= sizeof next) return ENAMETOOLONG;
        }
        strcpy(cur, next);
    }
    return ELOOP;
}

int vp_output_file(const char *path, char *out, size_t outlen) {
    struct stat st;
    if (!path || !*path || !out || !outlen) return 0;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode)) return 0; /* absent, device, FIFO, ... */
    return follow_links(path, out, outlen) == 0;
}

void vp_remove_output(const char *path) {
    char file[4096];
    if (vp_output_file(path, file, sizeof file)) unlink(file);
}

vp_result vp_os_atomic_begin(vp_atomic *a, const char *path) {
    memset(a, 0, sizeof *a);
    a->slot = -1;
    if (!path || !*path) return fail(a, VP_ERR_INVALID_ARGUMENT, "no output path given");
    size_t n = strlen(path);
    if (n >= sizeof a->final_path)
        return fail(a, VP_ERR_INVALID_ARGUMENT, "%s: cannot write output (%s)", path,
                    strerror(ENAMETOOLONG));
    struct stat st;
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return fail(a, VP_ERR_IO, "%s: cannot write output: it is a directory", path);
    char target[4096];
    /* a device or FIFO (the kernel follows any links: /dev/stdout names a
     * pipe through /proc) is written through: -o /dev/null must not
     * replace the system's /dev/null with a file */
    a->through = stat(path, &st) == 0 && !S_ISREG(st.st_mode);
    if (a->through) {
        memcpy(target, path, n + 1);
    } else {
        /* a link is followed: renaming onto it would replace the link */
        int e = follow_links(path, target, sizeof a->final_path);
        if (e) return fail(a, VP_ERR_IO, "%s: cannot write output (%s)", path, strerror(e));
    }
    n = strlen(target);
    memcpy(a->final_path, target, n + 1);
    path = a->final_path;
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
        return fail(a, VP_ERR_IO, "%s: cannot write output: directory %s does not exist", path,
                    dir);
    int w, suffix = 0;
    if (a->through) { /* not beside a device: /dev may not take files */
        const char *tmpdir = getenv("TMPDIR");
        w = snprintf(a->tmp_path, sizeof a->tmp_path, "%s/vdbpack-out.tmp-XXXXXX",
                     tmpdir && *tmpdir ? tmpdir : "/tmp");
    } else {
        /* a short name of its own, not the target's name with more added */
        suffix = 4;
        w = snprintf(a->tmp_path, sizeof a->tmp_path, "%s/.vp-XXXXXX.tmp", dir);
        if (w >= 0 && (size_t)w >= sizeof a->tmp_path) {
            /* the directory's path leaves no room for it: through a
             * descriptor of the directory (Linux's /proc/self/fd) */
            a->dirfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
#ifdef O_PATH
            if (a->dirfd < 0) a->dirfd = open(dir, O_PATH | O_DIRECTORY | O_CLOEXEC);
#endif
            if (a->dirfd < 0) {
                int e = errno;
                return fail(a, VP_ERR_IO, "%s: cannot write output (%s)", path, strerror(e));
            }
            a->dir_open = 1;
            w = snprintf(a->tmp_path, sizeof a->tmp_path, "/proc/self/fd/%d/.vp-XXXXXX.tmp",
                         a->dirfd);
        }
    }
    if (w < 0 || (size_t)w >= sizeof a->tmp_path) {
        a->tmp_path[0] = 0;
        close_dir(a);
        return fail(a, VP_ERR_INVALID_ARGUMENT, "%s: cannot write output (%s)", path,
                    strerror(ENAMETOOLONG));
    }
    int fd = mkstemps(a->tmp_path, suffix);
    if (fd < 0) {
        int e = errno;
        a->tmp_path[0] = 0;
        close_dir(a);
        return fail(a, VP_ERR_IO, "%s: cannot write output (%s)", path, strerror(e));
    }
    close(fd);
    temp_register(a);
    return VP_OK;
}

/* Copies the finished temporary file into a target that is not a regular
 * file, then removes it. A short write (ENOSPC from /dev/full) is an error. */
static vp_result copy_through(vp_atomic *a) {
    int in = open(a->tmp_path, O_RDONLY);
    int out = in < 0 ? -1 : open(a->final_path, O_WRONLY);
    int e = errno;
    vp_result r = VP_OK;
    if (in < 0 || out < 0) {
        r = fail(a, VP_ERR_IO, "%s: cannot write output (%s)", a->final_path, strerror(e));
    } else {
        char buf[1 << 16];
        ssize_t got;
        while (r == VP_OK && (got = read(in, buf, sizeof buf)) != 0) {
            if (got < 0) {
                if (errno == EINTR) continue;
                r = fail(a, VP_ERR_IO, "%s: cannot write output (%s)", a->final_path,
                         strerror(errno));
                break;
            }
            for (ssize_t off = 0; off < got && r == VP_OK;) {
                ssize_t w = write(out, buf + off, (size_t)(got - off));
                if (w < 0 && errno == EINTR) continue;
                if (w <= 0)
                    r = fail(a, VP_ERR_IO, "%s: cannot write output (%s)", a->final_path,
                             strerror(w < 0 ? errno : ENOSPC));
                else off += w;
            }
        }
    }
    if (out >= 0 && close(out) != 0 && r == VP_OK)
        r = fail(a, VP_ERR_IO, "%s: cannot write output (%s)", a->final_path, strerror(errno));
    if (in >= 0) close(in);
    vp_os_atomic_abort(a);
    return r;
}

vp_result vp_os_atomic_commit(vp_atomic *a) {
    struct stat st;
    if (stat(a->tmp_path, &st) != 0 || st.st_size == 0) {
        vp_os_atomic_abort(a);
        return fail(a, VP_ERR_IO, "%s: writing failed (nothing was written)", a->final_path);
    }
    if (a->through) return copy_through(a);
    /* mkstemp makes 0600 files; outputs should follow the umask like any file */
    mode_t um = umask(0);
    umask(um);
    chmod(a->tmp_path, 0666 & ~um);
    temp_release(a);
    if (rename(a->tmp_path, a->final_path) != 0) {
        int e = errno;
        vp_os_atomic_abort(a);
        return fail(a, VP_ERR_IO, "%s: cannot write output (%s)", a->final_path, strerror(e));
    }
    a->tmp_path[0] = 0;
    close_dir(a);
    return VP_OK;
}

void vp_os_atomic_abort(vp_atomic *a) {
    if (a) temp_release(a);
    if (a && a->tmp_path[0]) {
        unlink(a->tmp_path);
        a->tmp_path[0] = 0;
    }
    if (a) close_dir(a);
}
