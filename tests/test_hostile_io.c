/* SPDX-License-Identifier: Apache-2.0 */
/* Issue 27 through the library: writers refuse what the readers refuse
 * (non-finite positions, radii and orients, coordinates past a float in
 * PLY and OBJ) and leave no file; .vdb reads refuse non-finite values;
 * messages longer than their buffer lose their middle, not their reason;
 * temporary names fit whatever the target's name fits (a 250-byte name, a
 * path of 4094 bytes); inputs that are not regular files are refused at
 * once, without blocking. */
#include "vdbpack/vdbpack.h"
#include "core/context.h"
#include "os/atomic.h"
#include "os/input.h"
#include "os/text.h"
#include "vdb/vdb_bridge.h"
#include "vp_test.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <time.h>
#include <unistd.h>

static char g_dir[256];

static const char *tmp(const char *name) {
    static char buf[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", g_dir, name);
    return buf[k];
}

/* The number of entries of dir besides . and .. (temporaries included). */
static int entries(const char *dir) {
    DIR *d = opendir(dir);
    ASSERT_TRUE(d != NULL);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
    closedir(d);
    return n;
}

/* Three spheres (or octahedra with orients) in a box of side 10. */
static vp_particles *make_set(vp_context *ctx, int solids) {
    vp_particles *p = NULL;
    ASSERT_OK(ctx, vp_particles_create(ctx, 3, &p));
    p->count = 3;
    p->radii = malloc(3 * sizeof(float));
    p->orients = malloc(12 * sizeof(float));
    ASSERT_TRUE(p->radii && p->orients);
    for (size_t i = 0; i < 3; i++) {
        for (int c = 0; c < 3; c++) p->positions[3 * i + c] = (double)i + 0.25 * c;
        p->radii[i] = 0.1f;
        p->orients[4 * i] = p->orients[4 * i + 1] = p->orients[4 * i + 2] = 0.0f;
        p->orients[4 * i + 3] = 1.0f;
    }
    p->has_orient = solids;
    p->shape = solids ? VP_SHAPE_OCTAHEDRON : VP_SHAPE_SPHERE;
    return p;
}

/* Every format refuses p (VP_ERR_INVALID_ARGUMENT, the message naming the
 * particle and `want`), and the directory stays empty. */
static void all_refuse(vp_context *ctx, const vp_particles *p, const char *want, int csv_keeps,
                       int vdb_refuses) {
    static const char *names[] = {"bad.vdb", "bad.ply", "bad.csv", "bad.obj"};
    for (int f = 0; f < 4; f++) {
        if (f == 2 && csv_keeps) continue;
        if (f == 0 && !vdb_refuses) continue;
        vp_result r = vp_export(ctx, tmp(names[f]), p, NULL);
        fprintf(stderr, "   %s: %s\n", names[f], vp_context_message(ctx));
        ASSERT_EQ_INT(r, VP_ERR_INVALID_ARGUMENT);
        ASSERT_TRUE(strstr(vp_context_message(ctx), "particle 1") != NULL);
        ASSERT_TRUE(strstr(vp_context_message(ctx), want) != NULL);
        ASSERT_TRUE(strstr(vp_context_message(ctx), names[f]) != NULL);
        ASSERT_EQ_INT(entries(g_dir), 0);
    }
}

static void test_writers_refuse_nonfinite(void) {
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_particles *p = make_set(ctx, 0);
    const double bad[] = {NAN, INFINITY, -INFINITY};
    for (int k = 0; k < 3; k++) {
        p->positions[3 * 1 + k] = bad[k];
        all_refuse(ctx, p, "position", 0, 1);
        p->positions[3 * 1 + k] = 1.0;
    }
    p->radii[1] = NAN;
    all_refuse(ctx, p, "radius", 0, 1);
    p->radii[1] = INFINITY;
    all_refuse(ctx, p, "radius", 0, 1);
    p->radii[1] = 0.0f; /* the text readers refuse pscale 0 (a .vdb may hold it) */
    for (int f = 1; f < 4; f++) {
        const char *n[] = {"", "r0.ply", "r0.csv", "r0.obj"};
        ASSERT_EQ_INT(vp_export(ctx, tmp(n[f]), p, NULL), VP_ERR_INVALID_ARGUMENT);
        ASSERT_TRUE(strstr(vp_context_message(ctx), "particle 1: its radius 0 ") != NULL);
    }
    ASSERT_EQ_INT(entries(g_dir), 0);
    vp_particles_destroy(p);
    /* orients: not finite, not unit */
    p = make_set(ctx, 1);
    p->orients[4 * 1 + 2] = NAN;
    all_refuse(ctx, p, "orient", 0, 1);
    p->orients[4 * 1 + 2] = 0.5f; /* |q| = 1.118 */
    all_refuse(ctx, p, "not a finite unit quaternion", 0, 0);
    p->orients[4 * 1 + 2] = 0.0f;
    /* and a sound set is written by all four */
    const char *ok[] = {"ok.vdb", "ok.ply", "ok.csv", "ok.obj"};
    for (int f = 0; f < 4; f++) ASSERT_OK(ctx, vp_export(ctx, tmp(ok[f]), p, NULL));
    ASSERT_EQ_INT(entries(g_dir), 4);
    for (int f = 0; f < 4; f++) unlink(tmp(ok[f]));
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
}

/* A coordinate past the largest float: PLY (float x, y, z) and OBJ (its
 * readers read floats) refuse it, CSV (%.17g) keeps it and reads it back. */
static void test_float_overflow(void) {
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_particles *p = make_set(ctx, 0);
    p->positions[3 * 1 + 1] = 1e300;
    all_refuse(ctx, p, "is beyond the 32-bit floats", 1, 0);
    ASSERT_OK(ctx, vp_export(ctx, tmp("big.csv"), p, NULL));
    vp_particles *q = NULL;
    ASSERT_OK(ctx, vp_import(ctx, tmp("big.csv"), VP_FORMAT_UNKNOWN, &q, NULL));
    ASSERT_TRUE(q->positions[3 * 1 + 1] == 1e300);
    vp_particles_destroy(q);
    unlink(tmp("big.csv"));
    /* at the largest float itself, PLY holds it; OBJ's vertices reach a
     * radius further */
    p->positions[3 * 1 + 1] = (double)FLT_MAX;
    ASSERT_OK(ctx, vp_export(ctx, tmp("edge.ply"), p, NULL));
    ASSERT_OK(ctx, vp_import(ctx, tmp("edge.ply"), VP_FORMAT_UNKNOWN, &q, NULL));
    ASSERT_TRUE(q->positions[3 * 1 + 1] == (double)FLT_MAX);
    vp_particles_destroy(q);
    p->positions[3 * 1 + 1] = -3e38;
    p->radii[1] = 1e38f;
    ASSERT_EQ_INT(vp_export(ctx, tmp("edge.obj"), p, NULL), VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "particle 1: its coordinate -3e+38") != NULL);
    p->radii[1] = 1e37f;
    ASSERT_OK(ctx, vp_export(ctx, tmp("edge.obj"), p, NULL));
    unlink(tmp("edge.ply"));
    unlink(tmp("edge.obj"));
    ASSERT_EQ_INT(entries(g_dir), 0);
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
}

/* A message longer than the context's 1024 bytes keeps its start and its
 * end (the reason), with "..." between, and no broken UTF-8 character. */
static void test_long_messages_keep_reason(void) {
    char path[3001];
    for (int i = 0; i < 3000; i++)
        path[i] = (char)(i % 3 == 0 ? 'a' : i % 3 == 1 ? '\xc3' : '\xa9');
    path[3000] = 0;
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_fail(ctx, VP_ERR_IO, "%s: cannot write output (%s)", path, strerror(ENAMETOOLONG));
    const char *m = vp_context_message(ctx);
    size_t n = strlen(m);
    fprintf(stderr, "   %zu bytes: ...%s\n", n, m + n - 40);
    ASSERT_LE(n, 1023);
    ASSERT_GE(n, 1000);
    ASSERT_TRUE(strstr(m, "...") != NULL);
    ASSERT_TRUE(strstr(m, ": cannot write output (File name too long)") != NULL);
    ASSERT_TRUE(!strncmp(m,
                         "a\xc3\xa9"
                         "a",
                         4));
    /* no lone continuation byte after the dots, none missing before */
    const char *d = strstr(m, "...");
    ASSERT_TRUE(((unsigned char)d[3] & 0xC0) != 0x80);
    ASSERT_TRUE((unsigned char)d[-1] != 0xc3);
    /* short ones are untouched */
    char out[64];
    vp_os_format(out, sizeof out, "%s: %d", "short", 7);
    ASSERT_TRUE(!strcmp(out, "short: 7"));
    /* in place, and at the boundary */
    char buf[32];
    strcpy(buf, "0123456789012345678901234567890"); /* 31 bytes: fits */
    vp_os_shorten(buf, sizeof buf, buf);
    ASSERT_TRUE(!strcmp(buf, "0123456789012345678901234567890"));
    char big[40] = "0123456789abcdefghijklmnopqrstuvwxyzABC";
    vp_os_shorten(big, 20, big);
    fprintf(stderr, "   in place: %s\n", big);
    ASSERT_EQ_INT(strlen(big), 19);
    ASSERT_TRUE(!strncmp(big, "01234", 5) && strstr(big, "...") && strstr(big, "xyzABC"));
    vp_context_destroy(ctx);
}

/* Temporary names: .vp-XXXXXX.tmp beside the target whatever its name
 * (250 bytes), and through /proc/self/fd when the directory's path leaves
 * no room (a target of 4094 bytes). */
static void test_temporary_names(void) {
    char name[251];
    memset(name, 'n', 246);
    strcpy(name + 246, ".csv");
    char path[600];
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    vp_atomic a;
    ASSERT_OK(NULL, vp_os_atomic_begin(&a, path));
    fprintf(stderr, "   beside a 250-byte name: %s\n", strrchr(a.tmp_path, '/') + 1);
    ASSERT_EQ_INT(strlen(strrchr(a.tmp_path, '/') + 1), 14);
    ASSERT_TRUE(!strncmp(strrchr(a.tmp_path, '/') + 1, ".vp-", 4));
    FILE *f = fopen(a.tmp_path, "w");
    ASSERT_TRUE(f != NULL);
    fputs("x\n", f);
    fclose(f);
    ASSERT_OK(NULL, vp_os_atomic_commit(&a));
    struct stat st;
    ASSERT_EQ_INT(stat(path, &st), 0);
    unlink(path);
    ASSERT_EQ_INT(entries(g_dir), 0);

    /* a directory path of about 4080 bytes (relative to g_dir, absolute
     * paths being longer than the tests need) */
    char cwd[4096];
    ASSERT_TRUE(getcwd(cwd, sizeof cwd) != NULL);
    ASSERT_EQ_INT(chdir(g_dir), 0);
    char deep[4096] = "";
    size_t at = 0;
    while (at + 251 < 4084) {
        memset(deep + at, 'd', 250);
        deep[at + 250] = 0;
        ASSERT_TRUE(mkdir(deep, 0755) == 0 || errno == EEXIST);
        deep[at + 250] = '/';
        at += 251;
    }
    memset(deep + at, 'e', 4084 - at);
    deep[4084] = 0;
    ASSERT_EQ_INT(mkdir(deep, 0755), 0);
    char target[4096];
    snprintf(target, sizeof target, "%s/a.csv", deep); /* 4090 bytes */
    ASSERT_EQ_INT(strlen(target), 4090);
    ASSERT_OK(NULL, vp_os_atomic_begin(&a, target));
    fprintf(stderr, "   beside a 4090-byte path: %s\n", a.tmp_path);
    ASSERT_TRUE(!strncmp(a.tmp_path, "/proc/self/fd/", 14));
    f = fopen(a.tmp_path, "w");
    ASSERT_TRUE(f != NULL);
    fputs("y\n", f);
    fclose(f);
    ASSERT_OK(NULL, vp_os_atomic_commit(&a));
    ASSERT_EQ_INT(stat(target, &st), 0);
    ASSERT_EQ_INT(entries(deep), 1);
    /* abort leaves nothing either */
    char target2[4096];
    snprintf(target2, sizeof target2, "%s/b.csv", deep);
    ASSERT_OK(NULL, vp_os_atomic_begin(&a, target2));
    ASSERT_EQ_INT(entries(deep), 2);
    vp_os_atomic_abort(&a);
    ASSERT_EQ_INT(entries(deep), 1);
    /* the library writes there too, and reads it back */
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_particles *p = make_set(ctx, 0), *q = NULL;
    snprintf(target2, sizeof target2, "%s/c.vdb", deep);
    ASSERT_OK(ctx, vp_write_points(ctx, target2, p, NULL));
    ASSERT_OK(ctx, vp_read_points(ctx, target2, &q));
    ASSERT_EQ_INT(q->count, 3);
    vp_particles_destroy(q);
    ASSERT_EQ_INT(entries(deep), 2);
    /* 4096 bytes: one past PATH_MAX, refused with its reason at the end */
    char over[4200];
    snprintf(over, sizeof over, "%s/abcdefghijk.csv", deep);
    ASSERT_EQ_INT(vp_export(ctx, over, p, NULL), VP_ERR_INVALID_ARGUMENT);
    fprintf(stderr, "   %zu-byte path: ...%s\n", strlen(over),
            vp_context_message(ctx) + strlen(vp_context_message(ctx)) - 50);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "(File name too long)") != NULL);
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
    ASSERT_EQ_INT(chdir(cwd), 0);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'/dddd*", g_dir);
    ASSERT_EQ_INT(system(cmd), 0);
}

/* Inputs that are not regular files: refused at once (a FIFO without a
 * writer blocked fopen() for ever). */
static void test_inputs_not_regular(void) {
    const char *fifo = tmp("in.csv");
    ASSERT_EQ_INT(mkfifo(fifo, 0600), 0);
    char msg[256];
    double t0 = vp_seconds();
    ASSERT_EQ_INT(vp_os_open_input(fifo, msg, sizeof msg), -1);
    ASSERT_TRUE(strstr(msg, "FIFO") != NULL);
    ASSERT_EQ_INT(vp_os_check_input(g_dir, msg, sizeof msg), -1);
    ASSERT_TRUE(strstr(msg, "a directory") != NULL);
    ASSERT_EQ_INT(vp_os_check_input("/dev/zero", msg, sizeof msg), -1);
    ASSERT_TRUE(strstr(msg, "character device") != NULL);
    ASSERT_EQ_INT(vp_os_check_input(tmp("missing.csv"), msg, sizeof msg), -1);
    ASSERT_TRUE(strstr(msg, "No such file") != NULL);
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_particles *p = NULL;
    ASSERT_EQ_INT(vp_import(ctx, fifo, VP_FORMAT_CSV, &p, NULL), VP_ERR_IO);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "FIFO") != NULL);
    ASSERT_EQ_INT(vp_read_points(ctx, fifo, &p), VP_ERR_IO);
    char *text = NULL;
    ASSERT_EQ_INT(vp_describe_file(ctx, fifo, 0, &text), VP_ERR_IO);
    vp_container *c = NULL;
    ASSERT_EQ_INT(vp_container_load(ctx, fifo, NULL, &c), VP_ERR_IO);
    vp_mesh_shape *m = NULL;
    ASSERT_EQ_INT(vp_mesh_shape_load(ctx, fifo, &m), VP_ERR_IO);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "FIFO") != NULL);
    double dt = vp_seconds() - t0;
    fprintf(stderr, "   every reader refused the FIFO in %.3f s\n", dt);
    ASSERT_LE(dt, 2.0);
    /* a regular file opens as usual: blocking */
    int fd = vp_os_open_input(VP_SAMPLES "/box.obj", msg, sizeof msg);
    ASSERT_TRUE(fd >= 0);
    ASSERT_EQ_INT(fcntl(fd, F_GETFL) & O_NONBLOCK, 0);
    close(fd);
    unlink(fifo);
    vp_context_destroy(ctx);
}

/* A .vdb holding a non-finite position (written past the checks, by
 * OpenVDB itself in the shell tests) cannot be made through the library:
 * the writer refuses; a finite one reads back. */
static void test_vdb_roundtrip_finite(void) {
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_particles *p = make_set(ctx, 1), *q = NULL;
    p->orients[4 * 2] = NAN;
    ASSERT_EQ_INT(vp_write_points(ctx, tmp("o.vdb"), p, NULL), VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "particle 2: its orient is not finite"));
    p->orients[4 * 2] = 0.0f;
    ASSERT_OK(ctx, vp_write_points(ctx, tmp("o.vdb"), p, NULL));
    ASSERT_OK(ctx, vp_read_points(ctx, tmp("o.vdb"), &q));
    ASSERT_EQ_INT(q->count, 3);
    vp_particles_destroy(q);
    q = NULL;
    unlink(tmp("o.vdb"));
    /* files with a NaN orient or radius, written by the C++ layer without
     * the library's checks (as another program could): every read refuses
     * them, naming the particle */
    char err[256];
    p->orients[4 * 2] = NAN;
    ASSERT_OK_MSG(err, vpv_points_write(tmp("nan_q.vdb"), p, NULL, err, sizeof err));
    ASSERT_EQ_INT(vp_read_points(ctx, tmp("nan_q.vdb"), &q), VP_ERR_FORMAT);
    fprintf(stderr, "   %s\n", vp_context_message(ctx));
    ASSERT_TRUE(strstr(vp_context_message(ctx), "particle 2: its orient is not finite") != NULL);
    ASSERT_TRUE(q == NULL);
    ASSERT_EQ_INT(vp_import(ctx, tmp("nan_q.vdb"), VP_FORMAT_UNKNOWN, &q, NULL), VP_ERR_FORMAT);
    p->orients[4 * 2] = 0.0f;
    p->radii[1] = INFINITY;
    ASSERT_OK_MSG(err, vpv_points_write(tmp("inf_r.vdb"), p, NULL, err, sizeof err));
    ASSERT_EQ_INT(vp_read_points(ctx, tmp("inf_r.vdb"), &q), VP_ERR_FORMAT);
    fprintf(stderr, "   %s\n", vp_context_message(ctx));
    ASSERT_TRUE(strstr(vp_context_message(ctx), "particle 1: its radius (pscale) is not finite"));
    unlink(tmp("nan_q.vdb"));
    unlink(tmp("inf_r.vdb"));
    ASSERT_EQ_INT(entries(g_dir), 0);
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
}

int main(void) {
    snprintf(g_dir, sizeof g_dir, "/tmp/vp_hostile_io_%d", (int)getpid());
    ASSERT_EQ_INT(mkdir(g_dir, 0700), 0);
    RUN_TEST(test_writers_refuse_nonfinite);
    RUN_TEST(test_float_overflow);
    RUN_TEST(test_long_messages_keep_reason);
    RUN_TEST(test_temporary_names);
    RUN_TEST(test_inputs_not_regular);
    RUN_TEST(test_vdb_roundtrip_finite);
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_dir);
    if (system(cmd) != 0) return 1;
    fprintf(stderr, "all hostile io tests passed\n");
    return 0;
}
