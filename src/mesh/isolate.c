/* SPDX-License-Identifier: Apache-2.0 */
/* Runs a mesh import in a child process so that a bug in Assimp (an endless
 * loop, a crash, an abort() from one of its assertions, a runaway
 * allocation) on hostile input becomes one clear error instead of a hung or
 * dead vdbpack. The child imports and welds, then streams the finished
 * vp_mesh back through a pipe; the parent enforces a deadline and reports
 * how the child ended. */
#include "mesh/isolate.h"
#include "core/context.h"
#include "mesh/mesh_wire.h"
#include "os/subproc.h"

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

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

/* One import: the importer and its argument, the file's name for
 * messages, the bound; and in the parent, what the child answered. */
typedef struct import_call {
    vp_mesh_import_fn fn;
    const void *arg;
    const char *name;
    const vp_subproc_guard *guard;
    vp_result res;
    vp_mesh *mesh;
    char *err;
    size_t errlen;
} import_call;

/* Runs in the child (vp_subproc_fork has set its signals, process group,
 * standard descriptors and memory bound): imports, then streams the mesh
 * or the error back (mesh_wire.h). */
static int import_child(int fd, void *user)
{
    const import_call *c = user;
    const vp_subproc_guard *g = c->guard;
    const char *name = c->name;
    char err[512] = "";
    vp_mesh *m = NULL;
    vp_result r = c->fn(c->arg, &m, err, sizeof err);
    /* Assimp reports a failed allocation as its message: under the bound
     * that is the bound's doing, and a user can raise it */
    size_t el = strlen(err);
    if (r != VP_OK &&
        (strstr(err, "bad_alloc") || (el >= 13 && !strcmp(err + el - 13, "out of memory")))) {
        r = VP_ERR_OUT_OF_MEMORY;
        if (g && g->max_bytes) {
            char b[32];
            bound_text(g, b, sizeof b);
            snprintf(err, sizeof err,
                     "%s: reading the mesh needs more than the memory limit "
                     "of %s (--max-memory): the file is malformed, or too large for the limit",
                     name, b);
        } else {
            snprintf(err, sizeof err,
                     "%s: the mesh reader (Assimp) ran out of memory; the "
                     "file is probably malformed",
                     name);
        }
    }
    int rc = vp_mesh_wire_write(fd, r, err, m) ? 3 : 0;
    vp_mesh_destroy(m); /* (the child exits after this: freed, not lost) */
    return rc;
}

/* In the parent: reads the child's answer. */
static int import_answer(int fd, vp_subproc_watch *w, void *user)
{
    import_call *c = user;
    return vp_mesh_wire_read(fd, w, c->name, &c->res, &c->mesh, c->err, c->errlen);
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
    import_call call = {fn, arg, name, guard, VP_OK, NULL, err, errlen};
    int status = 0;
    vp_result res = VP_OK;
    switch (vp_subproc_run(timeout, guard, import_child, import_answer, &call, &status)) {
    case VP_SUBPROC_NO_PIPE:
        snprintf(err, errlen, "%s: cannot start the mesh reader (pipe: %s)", name, strerror(errno));
        return VP_ERR_IO;
    case VP_SUBPROC_NO_FORK:
        snprintf(err, errlen, "%s: cannot start the mesh reader (fork: %s)", name, strerror(errno));
        return VP_ERR_OUT_OF_MEMORY;
    case VP_SUBPROC_CANCELLED: /* the caller cancelled (SIGINT in the command-line tool) */
        snprintf(err, errlen, "cancelled");
        res = VP_ERR_CANCELLED;
        break;
    case VP_SUBPROC_TIMEOUT:
        snprintf(err, errlen,
                 "%s: the mesh reader (Assimp) did not finish within %.0f s; the file is "
                 "probably malformed (set VDBPACK_IMPORT_TIMEOUT to allow longer)",
                 name, timeout);
        res = VP_ERR_FORMAT;
        break;
    case VP_SUBPROC_FAILED:
        if (guard && guard->max_bytes &&
            (WIFSIGNALED(status) || (WIFEXITED(status) && WEXITSTATUS(status) != 0))) {
            /* a crash under the bound is most likely a failed allocation
             * that the reader did not check */
            char b[32];
            bound_text(guard, b, sizeof b);
            snprintf(err, errlen,
                     "%s: the mesh reader (Assimp) failed (%s %d) under the "
                     "memory limit of %s (--max-memory): the file is malformed, "
                     "or too large for the limit",
                     name, WIFSIGNALED(status) ? "signal" : "exit status",
                     WIFSIGNALED(status) ? WTERMSIG(status) : WEXITSTATUS(status), b);
        } else if (WIFSIGNALED(status)) {
            snprintf(err, errlen,
                     "%s: the mesh reader (Assimp) crashed on this file "
                     "(signal %d); the file is probably malformed",
                     name, WTERMSIG(status));
        } else {
            snprintf(err, errlen,
                     "%s: the mesh reader (Assimp) failed on this file "
                     "(exit status %d); the file is probably malformed",
                     name, WIFEXITED(status) ? WEXITSTATUS(status) : -1);
        }
        res = VP_ERR_FORMAT;
        break;
    case VP_SUBPROC_ANSWERED: res = call.res; break;
    }
    vp_mesh *m = call.mesh;
    if (res != VP_OK) {
        vp_mesh_destroy(m);
        m = NULL;
    }
    *out = m;
    return res;
}
