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
    int fds[2];
    if (vp_subproc_pipe(fds) != 0)
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot start the file check (pipe: %s)",
                       vp_path_base(path), strerror(errno));
    /* its own process group, dies with this thread, default signal
     * actions, stdio on /dev/null (glibc's and OpenVDB's own messages on a
     * crash would make a second error line), and a runaway allocation ends
     * the child, not the machine: the context's memory limit */
    vp_subproc_guard guard;
    vp_context_child_guard(ctx, &guard);
    pid_t pid = vp_subproc_fork(&guard);
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "%s: cannot start the file check (fork: %s)",
                       vp_path_base(path), strerror(errno));
    }
    if (pid == 0) {
        close(fds[0]);
        char err[1024] = "";
        int32_t rc = fn(arg, err, sizeof err);
        uint32_t n = (uint32_t)strlen(err);
        int bad = vp_subproc_write_all(fds[1], &rc, sizeof rc) ||
                  vp_subproc_write_all(fds[1], &n, sizeof n) ||
                  vp_subproc_write_all(fds[1], err, n);
        _exit(bad ? 3 : 0);
    }
    close(fds[1]);
    vp_subproc_watch watch;
    vp_subproc_watch_start(&watch, pid, timeout);
    watch.guard = &guard;
    int32_t rc = 0;
    uint32_t n = 0;
    char msg[1024];
    int rr = vp_subproc_read_all(fds[0], &rc, sizeof rc, &watch);
    if (rr == 0) rr = vp_subproc_read_all(fds[0], &n, sizeof n, &watch);
    if (rr == 0 && n >= sizeof msg) rr = -1;
    if (rr == 0) rr = vp_subproc_read_all(fds[0], msg, n, &watch);
    close(fds[0]);
    int status = 0;
    if (rr == 3) {
        vp_subproc_kill(pid, NULL);
        return vp_fail(ctx, VP_ERR_CANCELLED, "cancelled");
    }
    if (rr == 2) {
        vp_subproc_kill(pid, NULL);
        return vp_fail(ctx, VP_ERR_FORMAT,
                       "%s: OpenVDB's reader did not finish within %.0f s; the file is probably "
                       "corrupt (set VDBPACK_READ_TIMEOUT to allow longer)",
                       vp_path_base(path), timeout);
    }
    status = vp_subproc_wait(pid);
    if (rr != 0) {
        if (WIFSIGNALED(status))
            return vp_fail(ctx, VP_ERR_FORMAT,
                           "%s: OpenVDB's reader crashed on this file (signal %d); the file is "
                           "probably corrupt",
                           vp_path_base(path), WTERMSIG(status));
        return vp_fail(ctx, VP_ERR_FORMAT,
                       "%s: OpenVDB's reader failed on this file (exit status %d); the file is "
                       "probably corrupt",
                       vp_path_base(path), WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    }
    msg[n] = '\0';
    if (rc != VP_OK) return vp_fail(ctx, (vp_result)rc, "%s", msg);
    return VP_OK;
#endif
}
