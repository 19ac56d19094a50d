/* SPDX-License-Identifier: Apache-2.0 */
/* Issue 27: the reader children (Assimp's importer, OpenVDB's reader) and
 * their parent.
 * - a child starts in its own process group, with every signal's default
 *   action and none blocked, stdio on /dev/null, a parent-death signal and
 *   its memory bound; it dies when the thread that forked it dies;
 * - its pipe never takes descriptors 0, 1 or 2, even when they are closed,
 *   and reading a file with them closed works;
 * - the caller's cancel ends the wait at once, the child killed and reaped;
 * - the deadline ends a reader blocked on a FIFO (vp_probe_read);
 * - a PLY whose header claims more data than the file holds is refused
 *   before Assimp allocates it; a sound PLY still loads;
 * - the context's memory limit binds the importer. */
#define _GNU_SOURCE /* prctl, setenv */
#include "vdbpack/vdbpack.h"
#include "api/probe.h"
#include "core/context.h"
#include "mesh/mesh.h"
#include "os/subproc.h"
#include "vp_test.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static char g_dir[256];

static const char *tmp(const char *name) {
    static char buf[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", g_dir, name);
    return buf[k];
}

static void on_sig(int sig) { (void)sig; }

/* What a child reports about itself. */
typedef struct child_report {
    int own_group; /* getpgid(0) == getpid() */
    int pdeathsig; /* PR_GET_PDEATHSIG */
    int int_default, term_default, pipe_default, usr1_blocked;
    int stdout_null, stderr_null, stdin_null;
    int big_alloc_failed; /* 256 MB more than its 64 MB bound */
} child_report;

static int is_devnull(int fd) {
    struct stat a, b;
    return fstat(fd, &a) == 0 && stat("/dev/null", &b) == 0 && a.st_rdev == b.st_rdev &&
           S_ISCHR(a.st_mode);
}

static int handler_is_default(int sig) {
    struct sigaction sa;
    return sigaction(sig, NULL, &sa) == 0 && sa.sa_handler == SIG_DFL;
}

static void test_child_starts_clean(void) {
    /* the parent as the command-line tool sets itself up: handlers that
     * remove outputs, SIGPIPE ignored, and here a blocked signal too */
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sig;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
    sigset_t usr1;
    sigemptyset(&usr1);
    sigaddset(&usr1, SIGUSR1);
    sigprocmask(SIG_BLOCK, &usr1, NULL);
    int fds[2];
    ASSERT_EQ_INT(vp_subproc_pipe(fds), 0);
    vp_subproc_guard g = {NULL, NULL, (uint64_t)64 << 20};
    pid_t pid = vp_subproc_fork(&g);
    ASSERT_TRUE(pid >= 0);
    if (pid == 0) {
        child_report r;
        memset(&r, 0, sizeof r);
        r.own_group = getpgid(0) == getpid();
        int ds = 0;
        prctl(PR_GET_PDEATHSIG, &ds);
        r.pdeathsig = ds;
        r.int_default = handler_is_default(SIGINT);
        r.term_default = handler_is_default(SIGTERM);
        r.pipe_default = handler_is_default(SIGPIPE);
        sigset_t now;
        sigprocmask(SIG_BLOCK, NULL, &now);
        r.usr1_blocked = sigismember(&now, SIGUSR1);
        r.stdin_null = is_devnull(0);
        r.stdout_null = is_devnull(1);
        r.stderr_null = is_devnull(2);
        if (!VP_TEST_SANITIZED) {
            char *big = malloc((size_t)256 << 20);
            r.big_alloc_failed = big == NULL;
            free(big);
        }
        vp_subproc_write_all(fds[1], &r, sizeof r);
        _exit(0);
    }
    close(fds[1]);
    child_report r;
    vp_subproc_watch w;
    vp_subproc_watch_start(&w, pid, 10.0);
    ASSERT_EQ_INT(vp_subproc_read_all(fds[0], &r, sizeof r, &w), 0);
    close(fds[0]);
    int st = vp_subproc_wait(pid);
    ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    fprintf(stderr,
            "   own group %d, death signal %d, SIGINT/SIGTERM/SIGPIPE default %d%d%d, "
            "SIGUSR1 blocked %d, stdio on /dev/null %d%d%d, 256 MB refused %d\n",
            r.own_group, r.pdeathsig, r.int_default, r.term_default, r.pipe_default, r.usr1_blocked,
            r.stdin_null, r.stdout_null, r.stderr_null, r.big_alloc_failed);
    ASSERT_EQ_INT(r.own_group, 1);
    ASSERT_EQ_INT(r.pdeathsig, SIGKILL);
    ASSERT_EQ_INT(r.int_default + r.term_default + r.pipe_default, 3);
    ASSERT_EQ_INT(r.usr1_blocked, 0);
    ASSERT_EQ_INT(r.stdin_null + r.stdout_null + r.stderr_null, 3);
    if (!VP_TEST_SANITIZED) ASSERT_EQ_INT(r.big_alloc_failed, 1);
    sigprocmask(SIG_UNBLOCK, &usr1, NULL);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    signal(SIGPIPE, SIG_DFL);
}

/* A child whose parent is SIGKILLed dies too (this process is made the
 * subreaper, so that it can wait for the orphan). */
static void test_child_dies_with_parent(void) {
    ASSERT_EQ_INT(prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
    int fds[2];
    ASSERT_EQ_INT(pipe(fds), 0);
    pid_t mid = fork();
    ASSERT_TRUE(mid >= 0);
    if (mid == 0) {
        close(fds[0]);
        pid_t g = vp_subproc_fork(NULL);
        if (g == 0) { /* its setup done (the death signal set): says so */
            pid_t me = getpid();
            vp_subproc_write_all(fds[1], &me, sizeof me);
            for (;;) pause();
        }
        for (;;) pause();
    }
    close(fds[1]);
    pid_t grand = 0;
    ASSERT_EQ_INT(read(fds[0], &grand, sizeof grand), (long long)sizeof grand);
    close(fds[0]);
    ASSERT_TRUE(grand > 0);
    ASSERT_EQ_INT(kill(grand, 0), 0);
    kill(mid, SIGKILL);
    waitpid(mid, NULL, 0);
    double t0 = vp_subproc_now();
    int st = 0;
    pid_t got = 0;
    while ((got = waitpid(grand, &st, WNOHANG)) == 0 && vp_subproc_now() - t0 < 5.0) usleep(10000);
    if (got == 0) kill(grand, SIGKILL), waitpid(grand, NULL, 0);
    fprintf(stderr, "   the orphan ended after %.3f s: %s %d\n", vp_subproc_now() - t0,
            got > 0 && WIFSIGNALED(st) ? "signal" : "still running, or", WTERMSIG(st));
    ASSERT_EQ_INT(got, grand);
    ASSERT_TRUE(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL);
    ASSERT_EQ_INT(prctl(PR_SET_CHILD_SUBREAPER, 0), 0);
}

/* The pipe's ends are above 2 even with 0, 1 and 2 closed. */
static void test_pipe_above_std(void) {
    int keep[3];
    for (int fd = 0; fd < 3; fd++) keep[fd] = dup(fd);
    for (int fd = 0; fd < 3; fd++) close(fd);
    int fds[2] = {-1, -1};
    int rc = vp_subproc_pipe(fds);
    for (int fd = 0; fd < 3; fd++) dup2(keep[fd], fd), close(keep[fd]);
    fprintf(stderr, "   with 0, 1, 2 closed: pipe %d %d\n", fds[0], fds[1]);
    ASSERT_EQ_INT(rc, 0);
    ASSERT_GE(fds[0], 3);
    ASSERT_GE(fds[1], 3);
    ASSERT_TRUE(fcntl(fds[0], F_GETFD) & FD_CLOEXEC);
    close(fds[0]);
    close(fds[1]);
}

/* vdbpack check FILE >&- 2>&-: the probe's pipe took 1 and 2, and the
 * child's stderr redirection overwrote it. Reads with 1 and 2 closed. */
static void test_reads_with_std_closed(void) {
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_particles *p = NULL;
    ASSERT_OK(ctx, vp_particles_create(ctx, 2, &p));
    p->count = 2;
    p->uniform_radius = 0.1f;
    memset(p->positions, 0, 6 * sizeof(double));
    p->positions[3] = 0.5;
    ASSERT_OK(ctx, vp_write_points(ctx, tmp("two.vdb"), p, NULL));
    vp_particles_destroy(p);
    p = NULL;
    fflush(stdout);
    fflush(stderr);
    int k1 = dup(1), k2 = dup(2);
    close(1);
    close(2);
    vp_result r1 = vp_read_points(ctx, tmp("two.vdb"), &p);
    vp_container *c = NULL;
    vp_result r2 = vp_container_load(ctx, VP_SAMPLES "/box.obj", NULL, &c);
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", vp_context_message(ctx));
    dup2(k1, 1);
    dup2(k2, 2);
    close(k1);
    close(k2);
    fprintf(stderr, "   with 1 and 2 closed: read %s, container %s %s\n", vp_result_name(r1),
            vp_result_name(r2), msg);
    ASSERT_OK(NULL, r1);
    ASSERT_EQ_INT(p->count, 2);
    ASSERT_OK_MSG(msg, r2);
    vp_particles_destroy(p);
    vp_container_destroy(c);
    unlink(tmp("two.vdb"));
    vp_context_destroy(ctx);
}

static double g_cancel_at;
static int cancel_after(void *user) {
    (void)user;
    return vp_subproc_now() >= g_cancel_at;
}
static int progress_cancel(void *user, double f, const char *stage) {
    (void)user, (void)f, (void)stage;
    return vp_subproc_now() < g_cancel_at;
}

/* The guard's cancel ends a wait on a child that never answers. */
static void test_cancel_ends_wait(void) {
    int fds[2];
    ASSERT_EQ_INT(vp_subproc_pipe(fds), 0);
    vp_subproc_guard g = {cancel_after, NULL, 0};
    pid_t pid = vp_subproc_fork(&g);
    ASSERT_TRUE(pid >= 0);
    if (pid == 0)
        for (;;) pause();
    close(fds[1]);
    g_cancel_at = vp_subproc_now() + 0.3;
    vp_subproc_watch w;
    vp_subproc_watch_start(&w, pid, 30.0);
    w.guard = &g;
    char c;
    int rr = vp_subproc_read_all(fds[0], &c, 1, &w);
    double dt = vp_subproc_now() - w.start;
    int st = 0;
    vp_subproc_kill(pid, &st);
    close(fds[0]);
    fprintf(stderr, "   cancelled after %.3f s: result %d\n", dt, rr);
    ASSERT_EQ_INT(rr, 3);
    ASSERT_LE(dt, 1.0);
    ASSERT_TRUE(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL);
}

static int open_and_read(const void *arg, char *err, size_t errlen) {
    int fd = open((const char *)arg, O_RDONLY); /* blocks: a FIFO without a writer */
    char b[4];
    ssize_t n = fd >= 0 ? read(fd, b, sizeof b) : -1;
    snprintf(err, errlen, "read %zd", n);
    return VP_ERR_FORMAT;
}

/* OpenVDB's reader blocked on a FIFO: the deadline ends it (this was
 * tested through `vdbpack info fifo.vdb`, which now refuses a FIFO before
 * reading); a cancel ends it sooner. */
static void test_probe_deadline_and_cancel(void) {
    if (!vp_readers_isolated()) {
        fprintf(stderr, "   skipped: readers run in-process in this build\n");
        return;
    }
    const char *fifo = tmp("blocked.vdb");
    ASSERT_EQ_INT(mkfifo(fifo, 0600), 0);
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    setenv("VDBPACK_READ_TIMEOUT", "1", 1);
    double t0 = vp_subproc_now();
    vp_result r = vp_probe_read(ctx, fifo, open_and_read, fifo);
    double dt = vp_subproc_now() - t0;
    fprintf(stderr, "   deadline: %s after %.2f s: %s\n", vp_result_name(r), dt,
            vp_context_message(ctx));
    ASSERT_EQ_INT(r, VP_ERR_FORMAT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "did not finish within 1 s") != NULL);
    ASSERT_GE(dt, 1.0);
    ASSERT_LE(dt, 4.0);
    setenv("VDBPACK_READ_TIMEOUT", "30", 1);
    g_cancel_at = vp_subproc_now() + 0.3;
    vp_context_set_progress(ctx, progress_cancel, NULL);
    t0 = vp_subproc_now();
    r = vp_probe_read(ctx, fifo, open_and_read, fifo);
    dt = vp_subproc_now() - t0;
    fprintf(stderr, "   cancel: %s after %.2f s\n", vp_result_name(r), dt);
    ASSERT_EQ_INT(r, VP_ERR_CANCELLED);
    ASSERT_LE(dt, 1.5);
    unsetenv("VDBPACK_READ_TIMEOUT");
    ASSERT_TRUE(waitpid(-1, NULL, WNOHANG) <= 0); /* no child left unreaped */
    unlink(fifo);
    vp_context_destroy(ctx);
}

/* Assimp looping on a malformed PLY (tests/data/assimp_hang.ply) until the
 * deadline: a cancel ends it at once. */
static void test_import_cancel(void) {
    if (!vp_readers_isolated()) {
        fprintf(stderr, "   skipped: readers run in-process in this build\n");
        return;
    }
    vp_subproc_guard g = {cancel_after, NULL, 0};
    g_cancel_at = vp_subproc_now() + 0.3;
    vp_mesh *m = NULL;
    char err[512];
    double t0 = vp_subproc_now();
    vp_result r = vp_mesh_load_guarded(VP_TEST_DATA "/assimp_hang.ply", &g, &m, err, sizeof err);
    double dt = vp_subproc_now() - t0;
    fprintf(stderr, "   %s after %.2f s: %s\n", vp_result_name(r), dt, err);
    ASSERT_EQ_INT(r, VP_ERR_CANCELLED);
    ASSERT_LE(dt, 1.5);
    ASSERT_TRUE(m == NULL);
    ASSERT_TRUE(waitpid(-1, NULL, WNOHANG) <= 0);
}

static void write_file(const char *path, const void *data, size_t n) {
    FILE *f = fopen(path, "wb");
    ASSERT_TRUE(f != NULL);
    ASSERT_EQ_INT(fwrite(data, 1, n, f), n);
    ASSERT_EQ_INT(fclose(f), 0);
}

/* A cube as PLY, binary or ASCII, with `extra` vertices more claimed than
 * written (0: a sound file). */
static size_t cube_ply(char *buf, size_t cap, int ascii, long extra) {
    static const float v[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                  {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    static const int f[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                                 {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
    size_t n = (size_t)snprintf(buf, cap,
                                "ply\nformat %s 1.0\nelement vertex %ld\nproperty float x\n"
                                "property float y\nproperty float z\nelement face 12\n"
                                "property list uchar int vertex_indices\nend_header\n",
                                ascii ? "ascii" : "binary_little_endian", 8 + extra);
    for (int i = 0; i < 8; i++) {
        if (ascii) {
            n += (size_t)snprintf(buf + n, cap - n, "%g %g %g\n", v[i][0], v[i][1], v[i][2]);
        } else {
            memcpy(buf + n, v[i], 12);
            n += 12;
        }
    }
    for (int i = 0; i < 12; i++) {
        if (ascii) {
            n += (size_t)snprintf(buf + n, cap - n, "3 %d %d %d\n", f[i][0], f[i][1], f[i][2]);
        } else {
            buf[n++] = 3;
            memcpy(buf + n, f[i], 12);
            n += 12;
        }
    }
    return n;
}

/* The 360-byte PLY claiming 2e8 vertices made Assimp grow to 2.3 GB
 * before the deadline: refused at once from its header, with or without a
 * memory limit; sound PLYs (binary, ASCII, exact sizes) still load. */
static void test_ply_claims(void) {
    char buf[4096];
    for (int ascii = 0; ascii < 2; ascii++) {
        size_t n = cube_ply(buf, sizeof buf, ascii, 0);
        const char *ok = tmp(ascii ? "cube_a.ply" : "cube_b.ply");
        write_file(ok, buf, n);
        vp_mesh *m = NULL;
        char err[512] = "";
        ASSERT_OK_MSG(err, vp_mesh_load(ok, &m, err, sizeof err));
        ASSERT_EQ_INT(m->ntris, 12);
        vp_mesh_destroy(m);
        m = NULL;
        ASSERT_OK_MSG(err, vp_mesh_load_memory(buf, n, "ply", &m, err, sizeof err));
        vp_mesh_destroy(m);
        m = NULL;
        /* 100 vertices more than the file holds (the check is a lower
         * bound: a list counts as its count alone) */
        if (!ascii) {
            n = cube_ply(buf, sizeof buf, ascii, 100);
            write_file(ok, buf, n);
            ASSERT_EQ_INT(vp_mesh_load(ok, &m, err, sizeof err), VP_ERR_FORMAT);
            fprintf(stderr, "   100 vertices short: %s\n", err);
            ASSERT_TRUE(strstr(err, "truncated or corrupt") != NULL);
        }
        /* the hostile file: 200000000 vertices claimed, 360 bytes */
        n = cube_ply(buf, sizeof buf, ascii, 200000000 - 8);
        if (n < 360) {
            memset(buf + n, ascii ? '\n' : 0, 360 - n);
            n = 360;
        }
        const char *bad = tmp(ascii ? "claims_a.ply" : "claims_b.ply");
        write_file(bad, buf, n);
        vp_context *ctx;
        ASSERT_OK(NULL, vp_context_create(&ctx));
        for (int lim = 0; lim < 2; lim++) {
            vp_context_set_max_memory(ctx, lim ? (uint64_t)256 << 20 : 0);
            vp_container *c = NULL;
            double t0 = vp_subproc_now();
            vp_result r = vp_container_load(ctx, bad, NULL, &c);
            double dt = vp_subproc_now() - t0;
            fprintf(stderr, "   %s, %s: %s in %.3f s: %s\n", ascii ? "ASCII" : "binary",
                    lim ? "--max-memory 256M" : "no limit", vp_result_name(r), dt,
                    vp_context_message(ctx));
            ASSERT_EQ_INT(r, VP_ERR_FORMAT);
            ASSERT_TRUE(strstr(vp_context_message(ctx), "200000000 'vertex'") != NULL);
            ASSERT_LE(dt, 1.0);
        }
        vp_context_destroy(ctx);
        unlink(ok);
        unlink(bad);
    }
}

/* A sound but large PLY (1.5 million vertices, 500 000 triangles, 25 MB)
 * under a memory limit of 8 MB: the importer's child fails with one line
 * naming the limit; without the limit it imports. */
static void test_memory_limit_binds_importer(void) {
    if (!vp_readers_isolated() || VP_TEST_SANITIZED) {
        fprintf(stderr, "   skipped: readers run in-process in this build\n");
        return;
    }
    const long nv = 1500000, nf = nv / 3;
    const char *path = tmp("large.ply");
    FILE *f = fopen(path, "wb");
    ASSERT_TRUE(f != NULL);
    fprintf(f,
            "ply\nformat binary_little_endian 1.0\nelement vertex %ld\nproperty float x\n"
            "property float y\nproperty float z\nelement face %ld\n"
            "property list uchar int vertex_indices\nend_header\n",
            nv, nf);
    for (long i = 0; i < nv; i++) {
        float v[3] = {(float)(i % 97), (float)((i / 97) % 89), (float)(i % 3)};
        fwrite(v, sizeof v, 1, f);
    }
    for (long i = 0; i < nf; i++) {
        unsigned char k = 3;
        int32_t t[3] = {(int32_t)(3 * i), (int32_t)(3 * i + 1), (int32_t)(3 * i + 2)};
        fwrite(&k, 1, 1, f);
        fwrite(t, sizeof t, 1, f);
    }
    ASSERT_EQ_INT(fclose(f), 0);
    vp_subproc_guard g = {NULL, NULL, (uint64_t)8 << 20};
    vp_mesh *m = NULL;
    char err[512] = "";
    double t0 = vp_subproc_now();
    vp_result r = vp_mesh_load_guarded(path, &g, &m, err, sizeof err);
    fprintf(stderr, "   8 MB: %s in %.2f s: %s\n", vp_result_name(r), vp_subproc_now() - t0, err);
    ASSERT_TRUE(r != VP_OK);
    ASSERT_TRUE(strstr(err, "memory limit of 8.4 MB") != NULL);
    ASSERT_TRUE(strchr(err, '\n') == NULL);
    g.max_bytes = 0;
    ASSERT_OK_MSG(err, vp_mesh_load_guarded(path, &g, &m, err, sizeof err));
    ASSERT_EQ_INT(m->nverts_raw, nv);
    vp_mesh_destroy(m);
    unlink(path);
}

int main(void) {
    snprintf(g_dir, sizeof g_dir, "/tmp/vp_hostile_children_%d", (int)getpid());
    ASSERT_EQ_INT(mkdir(g_dir, 0700), 0);
    RUN_TEST(test_child_starts_clean);
    RUN_TEST(test_child_dies_with_parent);
    RUN_TEST(test_pipe_above_std);
    RUN_TEST(test_reads_with_std_closed);
    RUN_TEST(test_cancel_ends_wait);
    RUN_TEST(test_probe_deadline_and_cancel);
    RUN_TEST(test_import_cancel);
    RUN_TEST(test_ply_claims);
    RUN_TEST(test_memory_limit_binds_importer);
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_dir);
    if (system(cmd) != 0) return 1;
    fprintf(stderr, "all hostile children tests passed\n");
    return 0;
}
