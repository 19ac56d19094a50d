/* SPDX-License-Identifier: Apache-2.0 */
/* Tests of the C++ OpenVDB bridge (src/vdb) through its extern "C" API. */
#include "vp_test.h"
#include "vdb/vdb_bridge.h"

#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#ifndef VP_SHARED_CONTAINERS
#define VP_SHARED_CONTAINERS "../shared/containers"
#endif

static char tmpdir[256];
static char err[512];

static void tmp_path(char *out, size_t n, const char *name) {
    snprintf(out, n, "%s/%s", tmpdir, name);
}

static int file_exists(const char *p) {
    FILE *f = fopen(p, "rb");
    if (f) fclose(f);
    return f != NULL;
}

static unsigned char *slurp(const char *p, size_t *n) {
    FILE *f = fopen(p, "rb");
    ASSERT_TRUE(f != NULL);
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc((size_t)len + 1);
    ASSERT_TRUE(b != NULL);
    ASSERT_EQ_INT(fread(b, 1, (size_t)len, f), len);
    fclose(f);
    *n = (size_t)len;
    return b;
}

static int same_bytes(const char *a, const char *b) {
    size_t na, nb;
    unsigned char *x = slurp(a, &na), *y = slurp(b, &nb);
    int same = na == nb && memcmp(x, y, na) == 0;
    free(x);
    free(y);
    return same;
}

/* Axis-aligned cube [c-h, c+h]^3 as 12 triangles (optionally missing the +z
 * face: 10 triangles). */
static size_t make_cube(const double c[3], double h, double v[24], uint32_t t[36], int open) {
    for (int i = 0; i < 8; ++i) {
        v[3 * i + 0] = c[0] + ((i & 1) ? h : -h);
        v[3 * i + 1] = c[1] + ((i & 2) ? h : -h);
        v[3 * i + 2] = c[2] + ((i & 4) ? h : -h);
    }
    static const uint32_t f[12][3] = {
        {0, 2, 1}, {1, 2, 3}, /* -z */
        {0, 1, 4}, {1, 5, 4}, /* -y */
        {0, 4, 2}, {2, 4, 6}, /* -x */
        {1, 3, 5}, {3, 7, 5}, /* +x */
        {2, 6, 3}, {3, 6, 7}, /* +y */
        {4, 5, 6}, {5, 7, 6}, /* +z */
    };
    size_t n = open ? 10 : 12;
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) t[3 * i + k] = f[i][k];
    return n;
}

/* Regular icosahedron of circumradius r centred at c. */
static void make_icosahedron(const double c[3], double r, double v[36], uint32_t t[60]) {
    const double phi = (1.0 + sqrt(5.0)) / 2.0, s = r / sqrt(1.0 + phi * phi);
    const double raw[12][3] = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0},
                               {0, -1, phi}, {0, 1, phi}, {0, -1, -phi}, {0, 1, -phi},
                               {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
    static const uint32_t f[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                      {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                      {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                      {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (int i = 0; i < 12; ++i)
        for (int k = 0; k < 3; ++k) v[3 * i + k] = c[k] + s * raw[i][k];
    for (int i = 0; i < 20; ++i)
        for (int k = 0; k < 3; ++k) t[3 * i + k] = f[i][k];
}

static double sample_at(const vpv_levelset *ls, const double c[3], double dx, double dy,
                        double dz) {
    double p[3] = {c[0] + dx, c[1] + dy, c[2] + dz};
    return vpv_levelset_sample(ls, p);
}

/* Closed cube far from the origin (Dutch RD-like coordinates). */
static void test_cube_levelset(void) {
    const double c[3] = {155000.25, 463000.5, 12.0};
    double v[24];
    uint32_t t[36];
    size_t nt = make_cube(c, 1.0, v, t, 0);
    vpv_levelset *ls = NULL;
    ASSERT_OK_MSG(err, vpv_levelset_from_mesh(v, 8, t, nt, 0.05, 3.0, 3.0, 1, NULL, NULL, &ls, err,
                                              sizeof err));
    ASSERT_TRUE(ls != NULL);

    vpv_levelset_info info;
    vpv_levelset_get_info(ls, &info);
    /* far from the origin the transform's round trip costs ~1e-11 */
    ASSERT_NEAR(info.voxel_size, 0.05, 1e-9);
    fprintf(stderr, "   cube: volume %g band %g active %zu inside %zu\n", info.volume,
            info.interior_band, info.active_voxels, info.inside_voxels);
    ASSERT_NEAR(info.volume, 8.0, 8.0 * 0.02);
    ASSERT_EQ_INT(info.leaked, 0);
    ASSERT_TRUE(strcmp(info.name, "container") == 0);
    ASSERT_NEAR(info.bmin[0], c[0] - 1.0, 0.3);
    ASSERT_NEAR(info.bmax[1], c[1] + 1.0, 0.3);
    ASSERT_TRUE(info.active_voxels > 0 && info.inside_voxels > 0);

    ASSERT_TRUE(sample_at(ls, c, 0, 0, 0) < 0);   /* deep inside: -background */
    ASSERT_TRUE(sample_at(ls, c, 1.5, 0, 0) > 0); /* outside */
    ASSERT_NEAR(sample_at(ls, c, 0.9, 0.1, -0.2), -0.1, 0.01);
    ASSERT_NEAR(sample_at(ls, c, 0.1, 1.05, 0.3), 0.05, 0.01);
    double p[3] = {c[0] + 0.93, c[1] + 0.1, c[2]}, g[3];
    vpv_levelset_gradient(ls, p, g);
    ASSERT_NEAR(g[0], 1.0, 0.02);
    ASSERT_NEAR(g[1], 0.0, 0.05);
    double far[3] = {c[0] + 50, c[1], c[2]};
    vpv_levelset_gradient(ls, far, g); /* flat background: degenerate */
    ASSERT_TRUE(g[0] == 0 && g[1] == 0 && g[2] == 0);

    /* Interior band widened to the requested depth. */
    ASSERT_TRUE(info.interior_band < 0.5);
    ASSERT_OK_MSG(err, vpv_levelset_ensure_interior(ls, 0.5, err, sizeof err));
    vpv_levelset_get_info(ls, &info);
    ASSERT_GE(info.interior_band, 0.5);
    ASSERT_NEAR(info.volume, 8.0, 8.0 * 0.02);
    ASSERT_EQ_INT(info.leaked, 0);
    ASSERT_NEAR(sample_at(ls, c, 0.5, 0.1, 0.0), -0.5, 0.01);
    ASSERT_TRUE(strcmp(info.name, "container") == 0);
    vpv_levelset_destroy(ls);
    vpv_levelset_destroy(NULL);
}

/* Icosahedron of circumradius r about c voxelized at 0.03 (band 3 voxels);
 * checks the volume against the exact one. v and t receive the mesh. */
static vpv_levelset *icosahedron_levelset(const double c[3], double r, int renormalize,
                                          double v[36], uint32_t t[60]) {
    make_icosahedron(c, r, v, t);
    vpv_levelset *ls = NULL;
    ASSERT_OK_MSG(err, vpv_levelset_from_mesh(v, 12, t, 20, 0.03, 3.0, 3.0, renormalize, NULL, NULL,
                                              &ls, err, sizeof err));
    return ls;
}

static double icosahedron_volume(double r) {
    const double a = r / sin(2.0 * M_PI / 5.0);
    return 5.0 / 12.0 * (3.0 + sqrt(5.0)) * a * a * a;
}

static void test_icosahedron_levelset(void) {
    const double c[3] = {1.0, -2.0, 0.5}, r = 1.0;
    double v[36];
    uint32_t t[60];
    vpv_levelset *ls = icosahedron_levelset(c, r, 1, v, t);
    ASSERT_OK_MSG(err, vpv_levelset_ensure_interior(ls, 0.3, err, sizeof err));
    vpv_levelset_info info;
    vpv_levelset_get_info(ls, &info);
    const double vol = icosahedron_volume(r);
    ASSERT_NEAR(info.volume, vol, vol * 0.02);
    ASSERT_GE(info.interior_band, 0.3);
    ASSERT_EQ_INT(info.leaked, 0);
    ASSERT_TRUE(sample_at(ls, c, 0, 0, 0) < -0.3 * 0.99);
    ASSERT_TRUE(sample_at(ls, c, 0, 0, 1.2) > 0);
    vpv_levelset_destroy(ls);
}

/* Without renormalization a closed mesh's level set holds exact distances:
 * near a face's centre the distance is the plane distance, which trilinear
 * interpolation reproduces, inside and outside. */
static void test_exact_distances_without_renormalization(void) {
    const double c[3] = {0.25, -0.5, 2.0}, r = 1.0;
    double v[36];
    uint32_t t[60];
    vpv_levelset *ls = icosahedron_levelset(c, r, 0, v, t);
    vpv_levelset_info info;
    vpv_levelset_get_info(ls, &info);
    ASSERT_NEAR(info.volume, icosahedron_volume(r), icosahedron_volume(r) * 0.02);
    double worst = 0;
    unsigned state = 12345;
    for (int f = 0; f < 20; f++) {
        const double *p0 = v + 3 * t[3 * f], *p1 = v + 3 * t[3 * f + 1], *p2 = v + 3 * t[3 * f + 2];
        double m[3], e1[3], e2[3], n[3];
        for (int k = 0; k < 3; k++) {
            m[k] = (p0[k] + p1[k] + p2[k]) / 3.0;
            e1[k] = p1[k] - p0[k];
            e2[k] = p2[k] - p0[k];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double out = (m[0] - c[0]) * n[0] + (m[1] - c[1]) * n[1] + (m[2] - c[2]) * n[2];
        for (int k = 0; k < 3; k++) n[k] /= out > 0 ? nl : -nl; /* outward unit normal */
        for (int s = 0; s < 10; s++) {
            double q[3], u[4];
            for (int k = 0; k < 4; k++) {
                state = state * 1664525u + 1013904223u;
                u[k] = (state >> 8) / 16777216.0 - 0.5;
            }
            for (int k = 0; k < 3; k++)
                q[k] = m[k] + 0.06 * u[0] * n[k] + 0.1 * (u[1] * e1[k] + u[2] * e2[k]);
            double want = (q[0] - p0[0]) * n[0] + (q[1] - p0[1]) * n[1] + (q[2] - p0[2]) * n[2];
            double got = vpv_levelset_sample(ls, q);
            if (fabs(got - want) > worst) worst = fabs(got - want);
        }
    }
    fprintf(stderr, "   largest error near faces: %.3g (voxel 0.03)\n", worst);
    ASSERT_TRUE(worst < 1e-5);
    vpv_levelset_destroy(ls);
}

/* Bad inputs are refused with a code and a message. */
static void test_mesh_bad_input(void) {
    const double c[3] = {0, 0, 0};
    double v[24];
    uint32_t t[36];
    size_t nt = make_cube(c, 1.0, v, t, 0);
    vpv_levelset *ls = (vpv_levelset *)1;
    ASSERT_EQ_INT(
        vpv_levelset_from_mesh(v, 8, t, nt, 0.0, 3, 3, 1, NULL, NULL, &ls, err, sizeof err),
        VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(ls == NULL && err[0] != 0);
    ASSERT_EQ_INT(
        vpv_levelset_from_mesh(v, 8, t, nt, NAN, 3, 3, 1, NULL, NULL, &ls, err, sizeof err),
        VP_ERR_INVALID_ARGUMENT);
    t[5] = 8;
    ASSERT_EQ_INT(
        vpv_levelset_from_mesh(v, 8, t, nt, 0.1, 3, 3, 1, NULL, NULL, &ls, err, sizeof err),
        VP_ERR_INVALID_ARGUMENT);
    t[5] = 3;
    ASSERT_EQ_INT(
        vpv_levelset_from_mesh(v, 8, t, nt, 1e-6, 3, 3, 1, NULL, NULL, &ls, err, sizeof err),
        VP_ERR_OUT_OF_MEMORY);
    ASSERT_TRUE(strstr(err, "2000000") != NULL);
    ASSERT_TRUE(strchr(err, '\n') == NULL);
}

static void test_open_mesh(void) {
    const double c[3] = {0, 0, 0};
    double v[24];
    uint32_t t[36];
    size_t nt = make_cube(c, 1.0, v, t, 1);
    vpv_levelset *ls = NULL;
    int rc =
        vpv_levelset_from_mesh(v, 8, t, nt, 0.05, 3.0, 3.0, 1, NULL, NULL, &ls, err, sizeof err);
    fprintf(stderr, "   open cube: rc %d\n", rc);
    if (rc == VP_OK) {
        vpv_levelset_info info;
        vpv_levelset_get_info(ls, &info);
        fprintf(stderr, "   open cube: volume %g leaked %d inside %zu\n", info.volume, info.leaked,
                info.inside_voxels);
        double o[3] = {0, 0, 0};
        (void)vpv_levelset_sample(ls, o);
        rc = vpv_levelset_ensure_interior(ls, 0.3, err, sizeof err);
        fprintf(stderr, "   open cube: ensure_interior rc %d\n", rc);
        vpv_levelset_destroy(ls);
    }
}

typedef struct {
    const vpv_levelset *ls;
    const double *pts;
    double *out;
    int n;
} sample_job;

static void *sample_thread(void *arg) {
    sample_job *j = arg;
    for (int rep = 0; rep < 20; ++rep)
        for (int i = 0; i < j->n; ++i) j->out[i] = vpv_levelset_sample(j->ls, j->pts + 3 * i);
    return NULL;
}

/* Write, read back (by name, by default), compare samples; determinism. */
/* Every cut of the file at path (40 lengths from the shortest complete
 * header to one byte short) is refused by all three readers as a format
 * error, and, once the cut lies past the grid list, named as truncated.
 * OpenVDB's own reader, given such a file, looped for minutes (a level set
 * cut at 5000 bytes) or described the grid as empty. */
static void check_cuts(const char *path, int points) {
    size_t n;
    unsigned char *bytes = slurp(path, &n);
    ASSERT_TRUE(bytes != NULL && n > 2000);
    char tr[300];
    tmp_path(tr, sizeof tr, "cut.vdb");
    for (int k = 0; k <= 40; ++k) {
        size_t len = k == 40 ? n - 1 : 65 + (n - 65) * (size_t)k / 40;
        FILE *f = fopen(tr, "wb");
        ASSERT_TRUE(f != NULL);
        fwrite(bytes, 1, len, f);
        fclose(f);
        int rc;
        if (points) {
            vp_particles *pp = NULL;
            rc = vpv_points_read(tr, &pp, err, sizeof err);
            ASSERT_TRUE(pp == NULL);
        } else {
            vpv_levelset *ls = NULL;
            rc = vpv_levelset_read(tr, NULL, &ls, err, sizeof err);
            ASSERT_TRUE(ls == NULL);
        }
        ASSERT_EQ_INT(rc, VP_ERR_FORMAT);
        if (len >= 1000) ASSERT_TRUE(strstr(err, "(truncated: grid '") != NULL);
        char *text = NULL;
        ASSERT_EQ_INT(vpv_describe_file(tr, 0, &text, err, sizeof err), VP_ERR_FORMAT);
        ASSERT_TRUE(text == NULL);
        if (len >= 1000) ASSERT_TRUE(strstr(err, "(truncated: grid '") != NULL);
    }
    fprintf(stderr, "   cut %s: %s\n", points ? "points" : "level set", err);
    free(bytes);
}

static void test_levelset_roundtrip(void) {
    const double c[3] = {3.0, 4.0, 5.0};
    double v[36];
    uint32_t t[60];
    make_icosahedron(c, 1.0, v, t);
    vpv_levelset *ls = NULL;
    ASSERT_OK_MSG(err, vpv_levelset_from_mesh(v, 12, t, 20, 0.05, 3.0, 3.0, 1, NULL, NULL, &ls, err,
                                              sizeof err));
    char a[300], b[300];
    tmp_path(a, sizeof a, "ls_a.vdb");
    tmp_path(b, sizeof b, "ls_b.vdb");
    vp_meta meta[3] = {{"generator", VP_META_STRING, "vdbpack test", 0, 0},
                       {"seed", VP_META_INT, NULL, 42, 0},
                       {"voxel", VP_META_DOUBLE, NULL, 0, 0.05}};
    ASSERT_OK_MSG(err, vpv_levelset_write(ls, a, meta, 3, err, sizeof err));
    ASSERT_OK_MSG(err, vpv_levelset_write(ls, b, meta, 3, err, sizeof err));
    ASSERT_TRUE(same_bytes(a, b));

    vpv_levelset *r1 = NULL, *r2 = NULL;
    ASSERT_OK_MSG(err, vpv_levelset_read(a, "container", &r1, err, sizeof err));
    ASSERT_OK_MSG(err, vpv_levelset_read(a, NULL, &r2, err, sizeof err));
    vpv_levelset *r3 = (vpv_levelset *)1;
    ASSERT_EQ_INT(vpv_levelset_read(a, "nope", &r3, err, sizeof err), VP_ERR_NOT_LEVEL_SET);
    ASSERT_TRUE(r3 == NULL);
    ASSERT_TRUE(strstr(err, "container") != NULL);

    enum { N = 2000 };
    static double pts[3 * N], s0[N], s1[N], s2[N];
    srand(7);
    for (int i = 0; i < N; ++i)
        for (int k = 0; k < 3; ++k) pts[3 * i + k] = c[k] + 2.6 * ((double)rand() / RAND_MAX - 0.5);
    for (int i = 0; i < N; ++i) {
        double x0 = vpv_levelset_sample(ls, pts + 3 * i);
        ASSERT_NEAR(vpv_levelset_sample(r1, pts + 3 * i), x0, 1e-6);
        ASSERT_NEAR(vpv_levelset_sample(r2, pts + 3 * i), x0, 1e-6);
        s0[i] = x0;
    }
    /* Concurrent sampling of two level sets from two threads. */
    pthread_t th[2];
    sample_job j1 = {r1, pts, s1, N}, j2 = {r2, pts, s2, N};
    pthread_create(&th[0], NULL, sample_thread, &j1);
    pthread_create(&th[1], NULL, sample_thread, &j2);
    pthread_join(th[0], NULL);
    pthread_join(th[1], NULL);
    for (int i = 0; i < N; ++i) {
        ASSERT_NEAR(s1[i], s0[i], 1e-6);
        ASSERT_NEAR(s2[i], s0[i], 1e-6);
    }
    /* Free one and create another (possibly at the same address). */
    vpv_levelset_destroy(r1);
    ASSERT_OK_MSG(err, vpv_levelset_read(a, NULL, &r1, err, sizeof err));
    for (int i = 0; i < N; i += 17) ASSERT_NEAR(vpv_levelset_sample(r1, pts + 3 * i), s0[i], 1e-6);

    /* describe: metadata shown. */
    char *text = NULL;
    ASSERT_OK_MSG(err, vpv_describe_file(a, 0, &text, err, sizeof err));
    ASSERT_TRUE(strstr(text, "generator = vdbpack test") != NULL);
    ASSERT_TRUE(strstr(text, "level set") != NULL);
    free(text);
    ASSERT_OK_MSG(err, vpv_describe_file(a, 1, &text, err, sizeof err));
    ASSERT_TRUE(strstr(text, "\"seed\":42") != NULL);
    ASSERT_TRUE(strstr(text, "\"name\":\"container\"") != NULL);
    free(text);

    check_cuts(a, 0);

    /* Truncated file -> FORMAT. */
    size_t n;
    unsigned char *bytes = slurp(a, &n);
    char tr[300];
    tmp_path(tr, sizeof tr, "truncated.vdb");
    FILE *f = fopen(tr, "wb");
    fwrite(bytes, 1, n / 2, f);
    fclose(f);
    free(bytes);
    r3 = NULL;
    int rc = vpv_levelset_read(tr, NULL, &r3, err, sizeof err);
    fprintf(stderr, "   truncated: %d %s\n", rc, err);
    ASSERT_TRUE(rc == VP_ERR_FORMAT || rc == VP_ERR_OUT_OF_MEMORY);
    ASSERT_TRUE(r3 == NULL);

    vpv_levelset_destroy(r1);
    vpv_levelset_destroy(r2);
    vpv_levelset_destroy(ls);
}

static void test_read_errors(void) {
    char p[300];
    vpv_levelset *ls = (vpv_levelset *)1;
    tmp_path(p, sizeof p, "missing.vdb");
    ASSERT_EQ_INT(vpv_levelset_read(p, NULL, &ls, err, sizeof err), VP_ERR_IO);
    ASSERT_TRUE(ls == NULL);
    ASSERT_TRUE(strstr(err, "missing.vdb: cannot open file (No such file or directory)") != NULL);

    tmp_path(p, sizeof p, "garbage.vdb");
    FILE *f = fopen(p, "wb");
    for (int i = 0; i < 1000; ++i) fputc((i * 37) & 0xff, f);
    fclose(f);
    ASSERT_EQ_INT(vpv_levelset_read(p, NULL, &ls, err, sizeof err), VP_ERR_FORMAT);
    ASSERT_TRUE(strstr(err, "garbage.vdb: not a readable .vdb file (") != NULL);
    fprintf(stderr, "   garbage: %s\n", err);
    vp_particles *pp = NULL;
    ASSERT_EQ_INT(vpv_points_read(p, &pp, err, sizeof err), VP_ERR_FORMAT);
    char *text = NULL;
    ASSERT_EQ_INT(vpv_describe_file(p, 0, &text, err, sizeof err), VP_ERR_FORMAT);
    ASSERT_TRUE(text == NULL);

    const char *fog = VP_SHARED_CONTAINERS "/gaffer_smoke_fog.vdb";
    if (file_exists(fog)) {
        ASSERT_EQ_INT(vpv_levelset_read(fog, NULL, &ls, err, sizeof err), VP_ERR_NOT_LEVEL_SET);
        fprintf(stderr, "   fog: %s\n", err);
        ASSERT_TRUE(strstr(err, "'density' [fog volume, float]") != NULL);
        ASSERT_TRUE(strstr(err, "gaffer_smoke_fog.vdb: ") != NULL);
        ASSERT_EQ_INT(vpv_levelset_read(fog, "density", &ls, err, sizeof err),
                      VP_ERR_NOT_LEVEL_SET);
        fprintf(stderr, "   fog by name: %s\n", err);
        ASSERT_EQ_INT(vpv_points_read(fog, &pp, err, sizeof err), VP_ERR_FORMAT);
    } else {
        fprintf(stderr, "   (skipped: %s absent)\n", fog);
    }
}

static void test_shared_levelsets(void) {
    const char *sph = VP_SHARED_CONTAINERS "/gaffer_ls_sphere.vdb";
    vpv_levelset *ls = NULL;
    vpv_levelset_info info;
    if (file_exists(sph)) {
        ASSERT_OK_MSG(err, vpv_levelset_read(sph, NULL, &ls, err, sizeof err));
        vpv_levelset_get_info(ls, &info);
        const double vol = 4.0 / 3.0 * M_PI * 27.0;
        fprintf(stderr, "   sphere: volume %g (%g) band %g\n", info.volume, vol,
                info.interior_band);
        ASSERT_NEAR(info.volume, vol, 0.03 * vol);
        ASSERT_EQ_INT(info.leaked, 0);
        ASSERT_TRUE(strcmp(info.name, "ls_sphere") == 0);
        double o[3] = {0, 0, 0};
        ASSERT_TRUE(vpv_levelset_sample(ls, o) < 0);
        ASSERT_OK_MSG(err, vpv_levelset_ensure_interior(ls, 1.0, err, sizeof err));
        vpv_levelset_get_info(ls, &info);
        ASSERT_GE(info.interior_band, 1.0);
        /* exact within the band (radius 3: 0.6 deep at r = 2.4), and beyond
         * it at least as deep as the band (the background value) */
        double q[3] = {2.4, 0, 0};
        ASSERT_NEAR(vpv_levelset_sample(ls, q), -0.6, 0.1);
        ASSERT_TRUE(vpv_levelset_sample(ls, o) <= -1.0);
        vpv_levelset_destroy(ls);
    } else {
        fprintf(stderr, "   (skipped: %s absent)\n", sph);
    }
    const char *zeno = VP_SHARED_CONTAINERS "/zeno_res.vdb";
    if (file_exists(zeno)) {
        ASSERT_OK_MSG(err, vpv_levelset_read(zeno, NULL, &ls, err, sizeof err));
        vpv_levelset_get_info(ls, &info);
        ASSERT_TRUE(info.name[0] == 0);
        ASSERT_TRUE(info.volume > 0);
        vpv_levelset_destroy(ls);
        ASSERT_OK_MSG(err, vpv_levelset_read(zeno, "", &ls, err, sizeof err));
        vpv_levelset_destroy(ls);
        char *text = NULL;
        ASSERT_OK_MSG(err, vpv_describe_file(zeno, 0, &text, err, sizeof err));
        ASSERT_TRUE(strstr(text, "(unnamed)") != NULL);
        free(text);
    }
}

static void free_particles(vp_particles *p) {
    if (!p) return;
    free(p->positions);
    free(p->radii);
    free(p->orients);
    free(p->groups);
    free(p);
}

static double json_number(const char *json, const char *key) {
    const char *s = strstr(json, key);
    ASSERT_TRUE(s != NULL);
    return strtod(s + strlen(key), NULL);
}

static void check_points_file(const char *path, const vp_particles *src, int full) {
    char *json = NULL;
    ASSERT_OK_MSG(err, vpv_describe_file(path, 1, &json, err, sizeof err));
    const double voxel = json_number(json, "\"voxel_size\":");
    ASSERT_TRUE(voxel > 0);
    ASSERT_TRUE(strstr(json, "\"points\":1000") != NULL);
    ASSERT_TRUE(strstr(json, "{\"name\":\"orient\",\"type\":\"quats\"") != NULL);
    ASSERT_TRUE(strstr(json, full ? "{\"name\":\"P\",\"type\":\"vec3s\",\"codec\":\"null\"}"
                                  : "{\"name\":\"P\",\"type\":\"vec3s\",\"codec\":\"fxpt16\"}") !=
                NULL);
    free(json);

    vp_particles *r = NULL;
    ASSERT_OK_MSG(err, vpv_points_read(path, &r, err, sizeof err));
    ASSERT_EQ_INT(r->count, src->count);
    ASSERT_EQ_INT(r->capacity, src->count);
    ASSERT_EQ_INT(r->group_count, src->group_count);
    for (unsigned g = 0; g < src->group_count; ++g)
        ASSERT_TRUE(strcmp(r->group_names[g], src->group_names[g]) == 0);
    ASSERT_TRUE(r->radii && r->orients && r->groups && r->has_orient);
    ASSERT_EQ_INT(r->shape, VP_SHAPE_CUBE);
    const double tol = full ? voxel * 1e-6 : voxel / 65535.0 * 2.0;
    double maxerr = 0;
    for (size_t i = 0; i < src->count; ++i) {
        for (int k = 0; k < 3; ++k) {
            double e = fabs(r->positions[3 * i + k] - src->positions[3 * i + k]);
            if (e > maxerr) maxerr = e;
            ASSERT_LE(e, tol);
        }
        ASSERT_TRUE(r->radii[i] == src->radii[i]);
        for (int k = 0; k < 4; ++k) ASSERT_TRUE(r->orients[4 * i + k] == src->orients[4 * i + k]);
        ASSERT_EQ_INT(r->groups[i], src->groups[i]);
    }
    /* the reader's stated bound holds for every position (as a vector) and
     * is the codec's: one 16-bit step per component, or float rounding */
    for (size_t i = 0; i < src->count; ++i) {
        double dx = r->positions[3 * i] - src->positions[3 * i],
               dy = r->positions[3 * i + 1] - src->positions[3 * i + 1],
               dz = r->positions[3 * i + 2] - src->positions[3 * i + 2];
        ASSERT_LE(sqrt(dx * dx + dy * dy + dz * dz),
                  r->position_error * (1 + 1e-9) + 1e-12 * voxel);
    }
    if (full) ASSERT_LE(r->position_error, voxel * 2e-7); /* float: 2^-24 per component */
    else ASSERT_NEAR(r->position_error, sqrt(3.0) * voxel / 65535.0, 1e-6 * voxel / 65535.0);
    fprintf(stderr, "   %s: voxel %g, max position error %g (tol %g)\n", full ? "full" : "fxpt16",
            voxel, maxerr, tol);
    free_particles(r);
}

/* A particle set of n particles with positions allocated (uninitialised);
 * the caller frees p->positions. */
static void particles_with_positions(vp_particles *p, size_t n) {
    memset(p, 0, sizeof *p);
    p->count = p->capacity = n;
    p->positions = malloc(sizeof(double) * 3 * n);
    ASSERT_TRUE(p->positions != NULL);
}

static void test_points(void) {
    enum { N = 1000 };
    vp_particles p;
    particles_with_positions(&p, N);
    p.radii = malloc(sizeof(float) * N);
    p.orients = malloc(sizeof(float) * 4 * N);
    p.groups = malloc(sizeof(uint16_t) * N);
    p.has_orient = 1;
    p.shape = VP_SHAPE_CUBE;
    p.group_count = 3;
    strcpy(p.group_names[0], "inner");
    strcpy(p.group_names[1], "outer");
    strcpy(p.group_names[2], "top_layer");
    srand(11);
    for (int i = 0; i < N; ++i) {
        p.positions[3 * i + 0] = 155000.0 + 10.0 * rand() / RAND_MAX;
        p.positions[3 * i + 1] = 463000.0 + 10.0 * rand() / RAND_MAX;
        p.positions[3 * i + 2] = -5.0 + 3.0 * rand() / RAND_MAX;
        p.radii[i] = 0.1f + 0.01f * (float)(i % 7);
        double q[4], n = 0;
        for (int k = 0; k < 4; ++k) {
            q[k] = (double)rand() / RAND_MAX - 0.5;
            n += q[k] * q[k];
        }
        for (int k = 0; k < 4; ++k) p.orients[4 * i + k] = (float)(q[k] / sqrt(n));
        p.groups[i] = (uint16_t)(i % 3 == 0 ? 0 : (i % 5 == 0 ? 2 : 1));
    }
    vp_meta meta[2] = {{"generator", VP_META_STRING, "vdbpack test", 0, 0},
                       {"particle_count", VP_META_INT, NULL, N, 0}};
    vp_write_params wp;
    memset(&wp, 0, sizeof wp);
    wp.meta = meta;
    wp.meta_count = 2;

    char a[300], b[300], f[300];
    tmp_path(a, sizeof a, "points_a.vdb");
    tmp_path(b, sizeof b, "points_b.vdb");
    tmp_path(f, sizeof f, "points_full.vdb");
    ASSERT_OK_MSG(err, vpv_points_write(a, &p, &wp, err, sizeof err));
    ASSERT_OK_MSG(err, vpv_points_write(b, &p, &wp, err, sizeof err));
    ASSERT_TRUE(same_bytes(a, b));
    check_points_file(a, &p, 0);
    check_cuts(a, 1);
    wp.full_precision = 1;
    ASSERT_OK_MSG(err, vpv_points_write(f, &p, &wp, err, sizeof err));
    check_points_file(f, &p, 1);

    /* Text description: quats, groups with counts. */
    char *text = NULL;
    ASSERT_OK_MSG(err, vpv_describe_file(a, 0, &text, err, sizeof err));
    ASSERT_TRUE(strstr(text, "orient: quats") != NULL);
    ASSERT_TRUE(strstr(text, "P: vec3s [fxpt16]") != NULL);
    ASSERT_TRUE(strstr(text, "inner: 334") != NULL);
    ASSERT_TRUE(strstr(text, "generator = vdbpack test") != NULL);
    ASSERT_TRUE(strstr(text, "points: 1000") != NULL);
    free(text);

    /* OpenVDB's own vdb_print sees the grid and its point count. */
    char cmd[400], line[512], all[8192] = "";
    snprintf(cmd, sizeof cmd, "vdb_print -l '%s' 2>&1", a);
    FILE *pipe = popen(cmd, "r");
    if (pipe) {
        size_t used = 0;
        while (fgets(line, sizeof line, pipe) && used + strlen(line) < sizeof all) {
            strcat(all, line);
            used += strlen(line);
        }
        int st = pclose(pipe);
        if (st == 0 && strstr(all, "not found") == NULL) {
            ASSERT_TRUE(strstr(all, "points") != NULL);
            ASSERT_TRUE(strstr(all, "1000") != NULL || strstr(all, "1,000") != NULL);
            ASSERT_TRUE(strstr(all, "vec4") == NULL);
        } else {
            fprintf(stderr, "   (vdb_print unavailable: %s)\n", all);
        }
    }

    /* Uniform radius/orient, no per-point groups. */
    free(p.radii);
    free(p.orients);
    free(p.groups);
    p.radii = NULL;
    p.orients = NULL;
    p.groups = NULL;
    p.uniform_radius = 0.25f;
    p.uniform_orient[0] = 0;
    p.uniform_orient[1] = 0;
    p.uniform_orient[2] = 0.6f;
    p.uniform_orient[3] = 0.8f;
    p.group_count = 1;
    strcpy(p.group_names[0], "all");
    p.shape = VP_SHAPE_SPHERE;
    wp.full_precision = 0;
    ASSERT_OK_MSG(err, vpv_points_write(a, &p, &wp, err, sizeof err));
    vp_particles *r = NULL;
    ASSERT_OK_MSG(err, vpv_points_read(a, &r, err, sizeof err));
    ASSERT_EQ_INT(r->count, N);
    ASSERT_TRUE(r->radii == NULL && r->uniform_radius == 0.25f);
    ASSERT_TRUE(r->orients == NULL && r->has_orient == 1 && r->uniform_orient[2] == 0.6f &&
                r->uniform_orient[3] == 0.8f);
    ASSERT_TRUE(r->groups == NULL && r->group_count == 1 && strcmp(r->group_names[0], "all") == 0);
    ASSERT_EQ_INT(r->shape, VP_SHAPE_SPHERE);
    free_particles(r);

    /* Invalid group name. */
    strcpy(p.group_names[0], "bad name");
    ASSERT_EQ_INT(vpv_points_write(a, &p, &wp, err, sizeof err), VP_ERR_INVALID_ARGUMENT);
    strcpy(p.group_names[0], "all");

    /* One particle, then none. */
    p.count = 1;
    p.has_orient = 0;
    ASSERT_OK_MSG(err, vpv_points_write(a, &p, &wp, err, sizeof err));
    ASSERT_OK_MSG(err, vpv_points_read(a, &r, err, sizeof err));
    ASSERT_EQ_INT(r->count, 1);
    ASSERT_TRUE(r->has_orient == 0 && r->orients == NULL);
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(r->positions[k], p.positions[k], 0.5 / 65535.0 * 2);
    free_particles(r);
    p.count = 0;
    ASSERT_OK_MSG(err, vpv_points_write(a, &p, &wp, err, sizeof err));
    ASSERT_OK_MSG(err, vpv_points_read(a, &r, err, sizeof err));
    ASSERT_EQ_INT(r->count, 0);
    ASSERT_TRUE(r->group_count >= 1);
    free_particles(r);

    /* Unwritable path -> IO. */
    ASSERT_EQ_INT(vpv_points_write("/nonexistent-dir/x.vdb", &p, &wp, err, sizeof err), VP_ERR_IO);
    fprintf(stderr, "   unwritable: %s\n", err);

    free(p.positions);
}

/* n^3 spheres of radius r on a simple cubic grid of spacing 2r (each
 * touching its neighbours), centred on c. */
static void touching_cubes(vp_particles *p, int n, float r, double c) {
    particles_with_positions(p, (size_t)n * n * n);
    p->uniform_radius = r;
    p->shape = VP_SHAPE_SPHERE;
    size_t k = 0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            for (int l = 0; l < n; ++l, ++k) {
                p->positions[3 * k] = c + 2.0 * r * (i - 0.5 * (n - 1));
                p->positions[3 * k + 1] = c + 2.0 * r * (j - 0.5 * (n - 1));
                p->positions[3 * k + 2] = c + 2.0 * r * (l - 0.5 * (n - 1));
            }
}

/* Writes p, reads it back, and returns the largest distance a position
 * moved; *pe gets the reader's position_error. */
static double roundtrip_error(const char *path, const vp_particles *p, const vp_write_params *wp,
                              double *pe) {
    ASSERT_OK_MSG(err, vpv_points_write(path, p, wp, err, sizeof err));
    vp_particles *r = NULL;
    ASSERT_OK_MSG(err, vpv_points_read(path, &r, err, sizeof err));
    ASSERT_EQ_INT(r->count, p->count);
    double worst = 0;
    for (size_t i = 0; i < p->count; ++i) {
        double d2 = 0;
        for (int k = 0; k < 3; ++k) {
            double d = r->positions[3 * i + k] - p->positions[3 * i + k];
            d2 += d * d;
        }
        if (sqrt(d2) > worst) worst = sqrt(d2);
    }
    *pe = r->position_error;
    free_particles(r);
    return worst;
}

/* Tiny particles: 16-bit fixed point in OpenVDB's smallest voxel
 * (1.44e-5) rounds positions by up to 3.8e-10, which was 2 % of a 2e-8
 * radius and put 55 spheres of radius 2e-11 on one point. The writer must
 * write float P instead, or refuse, and never store positions whose error
 * exceeds VP_POSITION_ERROR_LIMIT of the smallest radius. */
static void test_points_tiny_radii(void) {
    char path[300];
    tmp_path(path, sizeof path, "tiny.vdb");
    vp_write_report rep;
    vp_write_params wp;
    vp_write_params_init(&wp);
    wp.report = &rep;
    double pe;

    /* fixed16 asked for, too coarse: float P, said so */
    vp_particles p;
    touching_cubes(&p, 4, 2e-8f, 0.0);
    wp.full_precision = 0;
    memset(&rep, 0xff, sizeof rep);
    double moved = roundtrip_error(path, &p, &wp, &pe);
    fprintf(stderr, "   r 2e-8: moved %g, position error %g, voxel %g\n", moved, pe,
            rep.voxel_size);
    ASSERT_LE(moved, VP_POSITION_ERROR_LIMIT * 2e-8);
    ASSERT_LE(pe, VP_POSITION_ERROR_LIMIT * 2e-8);
    ASSERT_EQ_INT(rep.full_precision, 1);
    ASSERT_EQ_INT(rep.promoted, 1);
    ASSERT_NEAR(rep.position_error, pe, 1e-9 * pe);
    ASSERT_GE(rep.fixed16_error, VP_POSITION_ERROR_LIMIT * 2e-8);
    ASSERT_GE(rep.voxel_size, VP_POINTS_MIN_VOXEL);
    char *json = NULL;
    ASSERT_OK_MSG(err, vpv_describe_file(path, 1, &json, err, sizeof err));
    ASSERT_TRUE(strstr(json, "\"codec\":\"null\"") != NULL);
    ASSERT_TRUE(strstr(json, "\"position_precision_requested\":\"fixed16\"") != NULL);
    free(json);
    free(p.positions);

    /* the same at a normal size: fixed16 stays */
    touching_cubes(&p, 4, 0.05f, 0.0);
    moved = roundtrip_error(path, &p, &wp, &pe);
    ASSERT_EQ_INT(rep.full_precision, 0);
    ASSERT_EQ_INT(rep.promoted, 0);
    ASSERT_LE(pe, VP_POSITION_ERROR_LIMIT * 0.05);
    ASSERT_LE(moved, pe * (1 + 1e-9));
    free(p.positions);

    /* one small particle: the voxel was 2 r, below OpenVDB's smallest scale
     * ("ArithmeticError: Non-zero scale values required") */
    particles_with_positions(&p, 1);
    p.positions[0] = 1e-7;
    p.positions[1] = -2e-7;
    p.positions[2] = 3e-7;
    p.uniform_radius = 1e-6f;
    wp.full_precision = 1;
    moved = roundtrip_error(path, &p, &wp, &pe);
    ASSERT_LE(moved, VP_POSITION_ERROR_LIMIT * 1e-6);
    ASSERT_LE(pe, VP_POSITION_ERROR_LIMIT * 1e-6);
    free(p.positions);

    /* two sizes: 16-bit fixed point in a voxel sized for the large ones is
     * too coarse for the small ones (0.2 and 2e-5: a quarter of a radius) */
    particles_with_positions(&p, 200);
    p.radii = malloc(sizeof(float) * 200);
    ASSERT_TRUE(p.radii != NULL);
    p.shape = VP_SHAPE_SPHERE;
    srand(5);
    for (int i = 0; i < 200; ++i) {
        for (int k = 0; k < 3; ++k) p.positions[3 * i + k] = (double)rand() / RAND_MAX - 0.5;
        p.radii[i] = i < 4 ? 0.2f : 2e-5f;
    }
    wp.full_precision = 0;
    moved = roundtrip_error(path, &p, &wp, &pe);
    ASSERT_EQ_INT(rep.promoted, 1);
    ASSERT_LE(pe, VP_POSITION_ERROR_LIMIT * 2e-5);
    ASSERT_LE(moved, VP_POSITION_ERROR_LIMIT * 2e-5);
    free(p.radii);
    free(p.positions);

    /* too small for any .vdb: refused with one line, nothing written, no
     * OpenVDB exception text */
    touching_cubes(&p, 3, 2e-11f, 0.0);
    char bad[300];
    tmp_path(bad, sizeof bad, "tiny_refused.vdb");
    int rc = vpv_points_write(bad, &p, &wp, err, sizeof err);
    fprintf(stderr, "   r 2e-11: %s\n", err);
    ASSERT_EQ_INT(rc, VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(strstr(err, "radius 2e-11 is too small for a .vdb") != NULL);
    ASSERT_TRUE(strstr(err, "Error") == NULL && strchr(err, '\n') == NULL);
    ASSERT_TRUE(!file_exists(bad));
    free(p.positions);
    /* the bound the CLI uses before packing */
    ASSERT_NEAR(vp_points_min_radius(0.0), vpv_points_error(VP_POINTS_MIN_VOXEL, 1) / 1e-3, 1e-15);
    ASSERT_TRUE(vp_points_min_radius(0.0) > 2e-11 && vp_points_min_radius(0.0) < 2e-9);
    ASSERT_TRUE(vp_points_min_radius(1e6) > vp_points_min_radius(0.0));
}

/* vp_check_particles: a position error above position_tolerance of the
 * smallest radius is a violation (imprecise), not a pass with the overlap
 * tolerance widened by it. */
/* Sparse tiny particles: positions to 1e-3 of a radius of 1e-7 need
 * voxels of about 1e-3, a leaf node per particle spread over a unit box
 * (about 6 KB each): refused above max_memory before the grid is built,
 * written without a limit; dense particles under the same limit pass. */
static void test_points_memory_estimate(void) {
    enum { N = 3000 };
    char path[300];
    tmp_path(path, sizeof path, "sparse.vdb");
    vp_particles p;
    particles_with_positions(&p, N);
    p.uniform_radius = 1e-7f;
    p.shape = VP_SHAPE_SPHERE;
    srand(17);
    for (int i = 0; i < 3 * N; ++i) p.positions[i] = (double)rand() / RAND_MAX;
    vp_write_params wp;
    vp_write_params_init(&wp);
    wp.max_memory = 8000000; /* 8 MB: N leaves take about 18 */
    remove(path);
    int rc = vpv_points_write(path, &p, &wp, err, sizeof err);
    fprintf(stderr, "   sparse, 8 MB: %s\n", err);
    ASSERT_EQ_INT(rc, VP_ERR_OUT_OF_MEMORY);
    ASSERT_TRUE(strstr(err, "leaf nodes") != NULL);
    FILE *f = fopen(path, "rb");
    ASSERT_TRUE(f == NULL);   /* refused before anything was written */
    wp.max_memory = 40000000; /* 40 MB: passes */
    ASSERT_OK_MSG(err, vpv_points_write(path, &p, &wp, err, sizeof err));
    wp.max_memory = 0; /* no limit */
    ASSERT_OK_MSG(err, vpv_points_write(path, &p, &wp, err, sizeof err));
    /* the same count packed close (radius 1e-3, a grid of spacing 2e-3):
     * a few leaves, under 8 MB */
    p.uniform_radius = 1e-3f;
    for (int i = 0; i < N; ++i) {
        p.positions[3 * i + 0] = 2e-3 * (i % 15);
        p.positions[3 * i + 1] = 2e-3 * ((i / 15) % 15);
        p.positions[3 * i + 2] = 2e-3 * (i / 225);
    }
    wp.max_memory = 8000000;
    ASSERT_OK_MSG(err, vpv_points_write(path, &p, &wp, err, sizeof err));
    free(p.positions);
}

static void test_check_imprecise(void) {
    vp_context *ctx = NULL;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_container *c = NULL;
    const double o[3] = {0, 0, 0};
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, o, 1e-6, &c));
    vp_particles p;
    touching_cubes(&p, 3, 2e-8f, 0.0);
    /* overlap the first pair by 0.4 % of r_i + r_j */
    p.positions[2] += 0.004 * 4e-8;
    vp_check_params cp;
    vp_check_params_init(&cp);
    ASSERT_NEAR(cp.position_tolerance, VP_POSITION_ERROR_LIMIT, 0);
    vp_check_report rep;
    /* exact positions: the overlap is found */
    p.position_error = 0;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, &p, &cp, &rep));
    ASSERT_EQ_INT(rep.overlapping_pairs, 1);
    ASSERT_EQ_INT(rep.imprecise, 0);
    /* a file's 16-bit error in the smallest voxel (3.8e-10): the widened
     * tolerance hides the overlap, so the set is imprecise */
    p.position_error = vpv_points_error(VP_POINTS_MIN_VOXEL, 0);
    ASSERT_OK(ctx, vp_check_particles(ctx, c, &p, &cp, &rep));
    ASSERT_EQ_INT(rep.imprecise, 1);
    ASSERT_NEAR(rep.position_error_ratio, p.position_error / 2e-8, 1e-6);
    /* float P there (1.5e-12): fine, and the overlap is still found */
    p.position_error = vpv_points_error(VP_POINTS_MIN_VOXEL, 1);
    ASSERT_OK(ctx, vp_check_particles(ctx, c, &p, &cp, &rep));
    ASSERT_EQ_INT(rep.imprecise, 0);
    ASSERT_EQ_INT(rep.overlapping_pairs, 1);
    free(p.positions);
    vp_container_destroy(c);
    vp_context_destroy(ctx);
}

static int thread_count(void) {
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    int n = -1;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "Threads: %d", &n) == 1) break;
    if (f) fclose(f);
    return n;
}

/* A .vdb is read twice, first in a forked child (src/api/probe.c). A child
 * forked while OpenVDB's TBB workers exist hangs in its first parallel call:
 * seen as `vdbpack check` reporting a sound file as "did not finish within
 * 30 s" when describing it right after reading its points. Here: points
 * spread over many nodes, read (TBB workers start), then described with a
 * short deadline; and vpv_quiesce_threads leaves no TBB worker behind. */
enum { SPREAD_N = 20000 };

/* SPREAD_N points spread over many nodes, written to the temporary file
 * `name`; its path in f. */
static void write_spread_points(const char *name, char *f, size_t flen) {
    vp_particles p;
    particles_with_positions(&p, SPREAD_N);
    p.uniform_radius = 0.004f;
    p.group_count = 1;
    strcpy(p.group_names[0], "all");
    srand(5);
    for (int i = 0; i < 3 * SPREAD_N; ++i) p.positions[i] = 4.0 * rand() / RAND_MAX;
    vp_write_params wp;
    memset(&wp, 0, sizeof wp);
    tmp_path(f, flen, name);
    ASSERT_OK_MSG(err, vpv_points_write(f, &p, &wp, err, sizeof err));
    free(p.positions);
}

static void test_probe_after_tbb_work(void) {
    enum { N = SPREAD_N };
    char f[300];
    write_spread_points("probe_after_tbb.vdb", f, sizeof f);

    /* threads that are not TBB's: the main one and log4cplus's idle pool */
    ASSERT_EQ_INT(vpv_quiesce_threads(), 0);
    int base = thread_count();
    setenv("VDBPACK_READ_TIMEOUT", "8", 1);
    vp_context *ctx = NULL;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    for (int round = 0; round < 3; ++round) {
        vp_particles *r = NULL;
        ASSERT_OK(ctx, vp_read_points(ctx, f, &r));
        ASSERT_EQ_INT(r->count, N);
        vp_particles_destroy(r);
        fprintf(stderr, "   round %d: %d threads after the read\n", round, thread_count());
        char *text = NULL;
        ASSERT_OK(ctx, vp_describe_file(ctx, f, 0, &text));
        ASSERT_TRUE(strstr(text, "points: 20000") != NULL);
        free(text);
    }
    vp_context_destroy(ctx);
    unsetenv("VDBPACK_READ_TIMEOUT");
    ASSERT_EQ_INT(vpv_quiesce_threads(), 0);
    fprintf(stderr, "   %d threads after vpv_quiesce_threads, %d before the reads\n",
            thread_count(), base);
    ASSERT_EQ_INT(thread_count(), base);
}

/* Another thread of the caller inside a TBB algorithm (a voxelization held
 * in its progress callback): TBB cannot end its workers, vpv_quiesce_threads
 * says so at once instead of waiting, and a .vdb is still read (in-process,
 * without the forked check) rather than hanging in a child. */
static _Atomic int busy_started, busy_release;

static void nap_ms(long ms) {
    struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

static int busy_keep_going(void *user) {
    (void)user;
    busy_started = 1;
    while (!busy_release) nap_ms(1);
    return 1;
}

static void *busy_voxelize(void *arg) {
    double v[24], c[3] = {0, 0, 0};
    uint32_t t[36];
    make_cube(c, 1.0, v, t, 0);
    vpv_levelset *ls = NULL;
    char e[256];
    *(int *)arg =
        vpv_levelset_from_mesh(v, 8, t, 12, 0.02, 3, 3, 0, busy_keep_going, NULL, &ls, e, sizeof e);
    vpv_levelset_destroy(ls);
    return NULL;
}

static void test_quiesce_while_tbb_busy(void) {
    alarm(120); /* a hang here is the failure this test looks for */
    char f[300];
    write_spread_points("quiesce_busy.vdb", f, sizeof f);
    ASSERT_EQ_INT(vpv_quiesce_threads(), 0);
    int rc = -1;
    pthread_t th;
    ASSERT_EQ_INT(pthread_create(&th, NULL, busy_voxelize, &rc), 0);
    while (!busy_started) nap_ms(1);
    ASSERT_EQ_INT(vpv_quiesce_threads(), -1);
    vp_context *ctx = NULL;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    char *text = NULL;
    ASSERT_OK(ctx, vp_describe_file(ctx, f, 0, &text));
    ASSERT_TRUE(strstr(text, "points: 20000") != NULL);
    free(text);
    vp_context_destroy(ctx);
    busy_release = 1;
    ASSERT_EQ_INT(pthread_join(th, NULL), 0);
    ASSERT_OK(NULL, rc);
    ASSERT_EQ_INT(vpv_quiesce_threads(), 0);
    alarm(0);
}

int main(void) {
    snprintf(tmpdir, sizeof tmpdir, "/tmp/test_vdb_bridge.XXXXXX");
    ASSERT_TRUE(mkdtemp(tmpdir) != NULL);
    vpv_init();
    RUN_TEST(test_cube_levelset);
    RUN_TEST(test_icosahedron_levelset);
    RUN_TEST(test_exact_distances_without_renormalization);
    RUN_TEST(test_mesh_bad_input);
    RUN_TEST(test_open_mesh);
    RUN_TEST(test_levelset_roundtrip);
    RUN_TEST(test_read_errors);
    RUN_TEST(test_shared_levelsets);
    RUN_TEST(test_points);
    RUN_TEST(test_points_tiny_radii);
    RUN_TEST(test_points_memory_estimate);
    RUN_TEST(test_check_imprecise);
    RUN_TEST(test_probe_after_tbb_work);
    RUN_TEST(test_quiesce_while_tbb_busy);
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", tmpdir);
    fprintf(stderr, "all vdb bridge tests passed\n");
    return vp_test_failures;
}
