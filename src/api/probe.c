/* SPDX-License-Identifier: Apache-2.0 */
/* OpenVDB 10's reader trusts the sizes and offsets stored in a .vdb: on a
 * corrupt file it can read past its buffers, copy gigabytes, loop for
 * minutes or die (see docs/hardening.md for what fuzzing found). vdbpack
 * cannot mend OpenVDB, so every .vdb is first read in a forked child that
 * runs the very same read and then exits: a crash or hang there becomes
 * one error line here, and only a file the child read cleanly is read again
 * in-process. The cost is a second read of the file. OpenVDB's TBB worker
 * threads are ended before each fork: a child forked while they exist
 * hangs in its first parallel call. */
#include "api/probe.h"
#include "core/context.h"
#include "os/subproc.h"
#include "vdb/vdb_bridge.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef VP_SUBPROC_IN_PROCESS

/* What the child answers: fn's result and message. */
typedef struct probe_call {
    vp_probe_fn fn;
    const void *arg;
    int32_t rc;
    uint32_t n;
    char msg[1024];
} probe_call;

/* In the child: runs the read, writes its result and message. */
static int probe_child(int fd, void *user) {
    probe_call *c = user;
    char err[1024] = "";
    int32_t rc = c->fn(c->arg, err, sizeof err);
    uint32_t n = (uint32_t)strlen(err);
    int bad = vp_subproc_write_all(fd, &rc, sizeof rc) || vp_subproc_write_all(fd, &n, sizeof n) ||
              vp_subproc_write_all(fd, err, n);
    return bad ? 3 : 0;
}

/* In the parent: reads what probe_child wrote. */
static int probe_answer(int fd, vp_subproc_watch *w, void *user) {
    probe_call *c = user;
    int rr = vp_subproc_read_all(fd, &c->rc, sizeof c->rc, w);
    if (rr == 0) rr = vp_subproc_read_all(fd, &c->n, sizeof c->n, w);
    if (rr == 0 && c->n >= sizeof c->msg) rr = -1;
    if (rr == 0) rr = vp_subproc_read_all(fd, c->msg, c->n, w);
    return rr;
}
#endif

vp_result vp_probe_read(vp_context *ctx, const char *path, vp_probe_fn fn, const void *arg) {
#ifdef VP_SUBPROC_IN_PROCESS
    (void)path;
    (void)fn;
    (void)arg;
    return VP_OK;
#else
    const char *env = getenv("VDBPACK_VDB_PROBE");
    if (env && !strcmp(env, "0")) return VP_OK;
    struct stat st;
    if (stat(path, &st) != 0) return VP_OK; /* the in-process read names the error */
    double timeout = vp_subproc_timeout("VDBPACK_READ_TIMEOUT", 30.0, 1.0, (size_t)st.st_size);
    /* no TBB worker may exist at the fork (see vpv_quiesce_threads); if TBB
     * cannot end them (another thread of the caller is inside a parallel
     * algorithm), a forked read could hang on a sound file, so the file is
     * read in-process only, without this guard */
    if (vpv_quiesce_threads() != 0) return VP_OK;
    /* its own process group, dies with this thread, default signal
     * actions, stdio on /dev/null (glibc's and OpenVDB's own messages on a
     * crash would make a second error line), and a runaway allocation ends
     * the child, not the machine: the context's memory limit */
    vp_subproc_guard guard;
    vp_context_child_guard(ctx, &guard);
    probe_call call = {fn, arg, 0, 0, ""};
    int status = 0;
    switch (vp_subproc_run(timeout, &guard, probe_child, probe_answer, &call, &status)) {
    case VP_SUBPROC_NO_PIPE:
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot start the file check (pipe: %s)",
                       vp_path_base(path), strerror(errno));
    case VP_SUBPROC_NO_FORK:
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "%s: cannot start the file check (fork: %s)",
                       vp_path_base(path), strerror(errno));
    case VP_SUBPROC_CANCELLED: return vp_fail(ctx, VP_ERR_CANCELLED, "cancelled");
    case VP_SUBPROC_TIMEOUT:
        return vp_fail(ctx, VP_ERR_FORMAT,
                       "%s: OpenVDB's reader did not finish within %.0f s; the file is probably "
                       "corrupt (set VDBPACK_READ_TIMEOUT to allow longer)",
                       vp_path_base(path), timeout);
    case VP_SUBPROC_FAILED:
        if (WIFSIGNALED(status))
            return vp_fail(ctx, VP_ERR_FORMAT,
                           "%s: OpenVDB's reader crashed on this file (signal %d); the file is "
                           "probably corrupt",
                           vp_path_base(path), WTERMSIG(status));
        return vp_fail(ctx, VP_ERR_FORMAT,
                       "%s: OpenVDB's reader failed on this file (exit status %d); the file is "
                       "probably corrupt",
                       vp_path_base(path), WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    case VP_SUBPROC_ANSWERED: break;
    }
    call.msg[call.n] = '\0';
    if (call.rc != VP_OK) return vp_fail(ctx, (vp_result)call.rc, "%s", call.msg);
    return VP_OK;
#endif
}
