/* SPDX-License-Identifier: Apache-2.0 */
/* Runs a mesh import in a child process so that a bug in Assimp (an endless
 * loop, a crash, an abort() from one of its assertions, a runaway
 * allocation) on hostile input becomes one clear error instead of a hung or
 * dead vdbpack. The child imports and welds, then streams the finished
 * vp_mesh back through a pipe; the parent enforces a deadline and reports
 * how the child ended. */
#include "mesh/isolate.h"
#include "core/context.h"
#include "os/subproc.h"

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

/* Fixed-size header the child sends first; arrays follow. */
typedef struct wire_header {
    int32_t result;
    uint32_t errlen;
    uint64_t nverts, nverts_raw, ntris, boundary, nonmanifold, zero_area, components;
    double signed_volume, bmin[3], bmax[3];
} wire_header;

double vp_mesh_import_timeout(size_t file_bytes)
{
    /* Generous: Assimp reads well over 10 MB/s of OBJ on this class of
     * machine, so 2 s per MB is a hang, not a slow parse. */
    return vp_subproc_timeout("VDBPACK_IMPORT_TIMEOUT", 10.0, 2.0, file_bytes);
}

int vp_readers_isolated(void)
{
#ifdef VP_SUBPROC_IN_PROCESS
    return 0;
#else
    return 1;
#endif
}

/* The child's memory bound, for messages: "4.0 GB". */
static void bound_text(const vp_subproc_guard *g, char *out, size_t len)
{
    vp_format_bytes((double)(g && g->max_bytes ? g->max_bytes : 0), out, len);
}

/* Runs in the child (vp_subproc_fork has set its signals, process group,
 * standard descriptors and memory bound): imports, then streams the mesh
 * or the error back. */
static void child_main(int fd, vp_mesh_import_fn fn, const void *arg, const char *name,
                       const vp_subproc_guard *g)
{
    char err[512] = "";
    vp_mesh *m = NULL;
    vp_result r = fn(arg, &m, err, sizeof err);
    /* Assimp reports a failed allocation as its message: under the bound
     * that is the bound's doing, and a user can raise it */
    size_t el = strlen(err);
    if (r != VP_OK && (strstr(err, "bad_alloc") ||
                       (el >= 13 && !strcmp(err + el - 13, "out of memory")))) {
        r = VP_ERR_OUT_OF_MEMORY;
        if (g && g->max_bytes) {
            char b[32];
            bound_text(g, b, sizeof b);
            snprintf(err, sizeof err, "%s: reading the mesh needs more than the memory limit "
                     "of %s (--max-memory): the file is malformed, or too large for the limit",
                     name, b);
        } else {
            snprintf(err, sizeof err, "%s: the mesh reader (Assimp) ran out of memory; the "
                     "file is probably malformed", name);
        }
    }
    wire_header h;
    memset(&h, 0, sizeof h);
    h.result = (int32_t)r;
    h.errlen = (uint32_t)strlen(err);
    if (r == VP_OK && m) {
        h.nverts = m->nverts;
        h.nverts_raw = m->nverts_raw;
        h.ntris = m->ntris;
        h.boundary = m->boundary_edges;
        h.nonmanifold = m->nonmanifold_edges;
        h.zero_area = m->zero_area_tris;
        h.components = m->components;
        h.signed_volume = m->signed_volume;
        memcpy(h.bmin, m->bmin, sizeof h.bmin);
        memcpy(h.bmax, m->bmax, sizeof h.bmax);
    }
    int bad = vp_subproc_write_all(fd, &h, sizeof h) || vp_subproc_write_all(fd, err, h.errlen);
    if (!bad && r == VP_OK && m)
        bad = vp_subproc_write_all(fd, m->verts, 3 * m->nverts * sizeof *m->verts) ||
              vp_subproc_write_all(fd, m->tris, 3 * m->ntris * sizeof *m->tris);
    _exit(bad ? 3 : 0);
}

vp_result vp_mesh_import_isolated(vp_mesh_import_fn fn, const void *arg, const char *name,
                                  double timeout, const vp_subproc_guard *guard, vp_mesh **out,
                                  char *err, size_t errlen)
{
    *out = NULL;
#ifdef VP_SUBPROC_IN_PROCESS
    (void)name;
    (void)timeout;
    (void)guard;
    return fn(arg, out, err, errlen);
#endif
    int fds[2];
    if (vp_subproc_pipe(fds) != 0) {
        snprintf(err, errlen, "%s: cannot start the mesh reader (pipe: %s)", name,
                 strerror(errno));
        return VP_ERR_IO;
    }
    pid_t pid = vp_subproc_fork(guard);
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        snprintf(err, errlen, "%s: cannot start the mesh reader (fork: %s)", name,
                 strerror(errno));
        return VP_ERR_OUT_OF_MEMORY;
    }
    if (pid == 0) {
        close(fds[0]);
        child_main(fds[1], fn, arg, name, guard);
    }
    close(fds[1]);

    vp_subproc_watch watch;
    vp_subproc_watch_start(&watch, pid, timeout);
    watch.guard = guard;
    vp_result res = VP_OK;
    vp_mesh *m = NULL;
    wire_header h;
    int rr = vp_subproc_read_all(fds[0], &h, sizeof h, &watch);
    if (rr == 0) {
        char msg[512];
        size_t el = h.errlen < sizeof msg ? h.errlen : sizeof msg - 1;
        rr = vp_subproc_read_all(fds[0], msg, el, &watch);
        msg[rr == 0 ? el : 0] = '\0';
        if (rr == 0 && h.result != VP_OK) {
            res = (vp_result)h.result;
            snprintf(err, errlen, "%s", msg);
        } else if (rr == 0) {
            m = calloc(1, sizeof *m);
            if (m && h.nverts <= SIZE_MAX / 24 && h.ntris <= SIZE_MAX / 12) {
                m->verts = malloc(3 * h.nverts * sizeof *m->verts + 1);
                m->tris = malloc(3 * h.ntris * sizeof *m->tris + 1);
            }
            if (!m || !m->verts || !m->tris) {
                res = VP_ERR_OUT_OF_MEMORY;
                snprintf(err, errlen, "%s: out of memory", name);
            } else {
                m->nverts = h.nverts;
                m->nverts_raw = h.nverts_raw;
                m->ntris = h.ntris;
                m->boundary_edges = h.boundary;
                m->nonmanifold_edges = h.nonmanifold;
                m->zero_area_tris = h.zero_area;
                m->components = h.components;
                m->signed_volume = h.signed_volume;
                memcpy(m->bmin, h.bmin, sizeof h.bmin);
                memcpy(m->bmax, h.bmax, sizeof h.bmax);
                rr = vp_subproc_read_all(fds[0], m->verts, 3 * h.nverts * sizeof *m->verts, &watch);
                if (rr == 0)
                    rr = vp_subproc_read_all(fds[0], m->tris, 3 * h.ntris * sizeof *m->tris, &watch);
            }
        }
    }
    close(fds[0]);
    int status = 0;
    if (rr == 3) { /* the caller cancelled (SIGINT in the command-line tool) */
        vp_subproc_kill(pid, &status);
        snprintf(err, errlen, "cancelled");
        res = VP_ERR_CANCELLED;
    } else if (rr == 2) {
        vp_subproc_kill(pid, &status);
        snprintf(err, errlen,
                 "%s: the mesh reader (Assimp) did not finish within %.0f s; the file is "
                 "probably malformed (set VDBPACK_IMPORT_TIMEOUT to allow longer)",
                 name, timeout);
        res = VP_ERR_FORMAT;
    } else {
        status = vp_subproc_wait(pid);
        if (rr != 0 && res == VP_OK && guard && guard->max_bytes &&
            (WIFSIGNALED(status) || (WIFEXITED(status) && WEXITSTATUS(status) != 0))) {
            /* a crash under the bound is most likely a failed allocation
             * that the reader did not check */
            char b[32];
            bound_text(guard, b, sizeof b);
            snprintf(err, errlen, "%s: the mesh reader (Assimp) failed (%s %d) under the "
                                  "memory limit of %s (--max-memory): the file is malformed, "
                                  "or too large for the limit",
                     name, WIFSIGNALED(status) ? "signal" : "exit status",
                     WIFSIGNALED(status) ? WTERMSIG(status) : WEXITSTATUS(status), b);
            res = VP_ERR_FORMAT;
        } else if (rr != 0 && res == VP_OK) {
            if (WIFSIGNALED(status))
                snprintf(err, errlen, "%s: the mesh reader (Assimp) crashed on this file "
                                      "(signal %d); the file is probably malformed",
                         name, WTERMSIG(status));
            else
                snprintf(err, errlen, "%s: the mesh reader (Assimp) failed on this file "
                                      "(exit status %d); the file is probably malformed",
                         name, WIFEXITED(status) ? WEXITSTATUS(status) : -1);
            res = VP_ERR_FORMAT;
        }
    }
    if (res != VP_OK) {
        vp_mesh_destroy(m);
        m = NULL;
    }
    *out = m;
    return res;
}
