/* SPDX-License-Identifier: Apache-2.0 */
/* Export formats through the C API: PLY and CSV written and read back
 * (CSV positions exact, PLY positions float-exact, ids, pscale, orient,
 * groups, shape), the PLY also read by Assimp (a PLY reader that is not
 * vdbpack's), strict readers on small malformed files, failed writes that
 * leave nothing, and the OBJ counts and size estimate behind the CLI's
 * warning. */
#include "vdbpack/vdbpack.h"
#include "vp_test.h"

#include <assimp/cimport.h>
#include <assimp/scene.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char g_dir[256];

static const char *tmp(const char *name) {
    static char buf[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", g_dir, name);
    return buf[k];
}

static uint64_t g_rng = 88172645463325252ull;
static double rnd(void) { /* xorshift64, uniform in [0,1) */
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return (double)(g_rng >> 11) / 9007199254740992.0;
}

/* n particles: random positions in [-10,10]^3, radii, unit orients, three groups. */
static vp_particles *make_set(vp_context *ctx, size_t n) {
    vp_particles *p = NULL;
    ASSERT_OK(ctx, vp_particles_create(ctx, n, &p));
    p->count = n;
    p->radii = malloc(n * sizeof(float));
    p->orients = malloc(4 * n * sizeof(float));
    p->groups = malloc(n * sizeof(uint16_t));
    ASSERT_TRUE(p->radii && p->orients && p->groups);
    p->has_orient = 1;
    p->shape = VP_SHAPE_OCTAHEDRON;
    p->group_count = 3;
    strcpy(p->group_names[0], "pass1");
    strcpy(p->group_names[1], "big_ones");
    strcpy(p->group_names[2], "g:3");
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++) p->positions[3 * i + c] = 20 * rnd() - 10;
        p->radii[i] = (float)(0.01 + rnd());
        double q[4], l = 0;
        for (int c = 0; c < 4; c++) q[c] = rnd() - 0.5, l += q[c] * q[c];
        for (int c = 0; c < 4; c++) p->orients[4 * i + c] = (float)(q[c] / sqrt(l));
        p->groups[i] = (uint16_t)(i * 3 / n);
    }
    return p;
}

static void same_set(const vp_particles *a, const vp_particles *b, int float_positions) {
    ASSERT_EQ_INT(b->count, a->count);
    ASSERT_EQ_INT(b->group_count, a->group_count);
    for (unsigned g = 0; g < a->group_count; g++)
        ASSERT_TRUE(!strcmp(a->group_names[g], b->group_names[g]));
    ASSERT_EQ_INT(b->has_orient, a->has_orient);
    for (size_t i = 0; i < a->count; i++) {
        for (int c = 0; c < 3; c++) {
            double want = a->positions[3 * i + c];
            if (float_positions) want = (double)(float)want;
            if (b->positions[3 * i + c] != want) {
                fprintf(stderr, "particle %zu: %.17g != %.17g\n", i, b->positions[3 * i + c], want);
                exit(1);
            }
        }
        ASSERT_TRUE(b->radii[i] == a->radii[i]);
        for (int c = 0; c < 4; c++) ASSERT_TRUE(b->orients[4 * i + c] == a->orients[4 * i + c]);
        ASSERT_EQ_INT(b->groups[i], a->groups[i]);
    }
}

static void test_format_from_path(void) {
    ASSERT_EQ_INT(vp_format_from_path("a/b.vdb"), VP_FORMAT_VDB);
    ASSERT_EQ_INT(vp_format_from_path("x.PLY"), VP_FORMAT_PLY);
    ASSERT_EQ_INT(vp_format_from_path("x.tar.csv"), VP_FORMAT_CSV);
    ASSERT_EQ_INT(vp_format_from_path("x.obj"), VP_FORMAT_OBJ);
    ASSERT_EQ_INT(vp_format_from_path("x.vdb.bak"), VP_FORMAT_UNKNOWN);
    ASSERT_EQ_INT(vp_format_from_path("dir.ply/file"), VP_FORMAT_UNKNOWN);
    ASSERT_EQ_INT(vp_format_from_path(NULL), VP_FORMAT_UNKNOWN);
    vp_format f;
    ASSERT_EQ_INT(vp_format_parse("csv", &f), 0);
    ASSERT_EQ_INT(f, VP_FORMAT_CSV);
    ASSERT_TRUE(vp_format_parse("CSV", &f) != 0);
    ASSERT_TRUE(vp_format_name(VP_FORMAT_UNKNOWN) == NULL);
}

static void test_ply_csv_round_trip(void) {
    vp_context *ctx = NULL;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_particles *p = make_set(ctx, 3000), *q = NULL;
    int needs = -1;
    ASSERT_OK(ctx, vp_export(ctx, tmp("a.csv"), p, NULL));
    ASSERT_OK(ctx, vp_import(ctx, tmp("a.csv"), VP_FORMAT_UNKNOWN, &q, &needs));
    ASSERT_EQ_INT(needs, 1); /* orient columns, no shape in a CSV */
    same_set(p, q, 0);       /* %.17g: the doubles exactly */
    vp_particles_destroy(q);
    ASSERT_OK(ctx, vp_export(ctx, tmp("a.ply"), p, NULL));
    ASSERT_OK(ctx, vp_import(ctx, tmp("a.ply"), VP_FORMAT_UNKNOWN, &q, &needs));
    ASSERT_EQ_INT(needs, 0);
    ASSERT_EQ_INT(q->shape, VP_SHAPE_OCTAHEDRON);
    same_set(p, q, 1); /* float x y z */
    vp_particles_destroy(q);
    /* a PLY reader that is not vdbpack's: Assimp sees the same vertices */
    const struct aiScene *sc = aiImportFile(tmp("a.ply"), 0);
    ASSERT_TRUE(sc != NULL);
    size_t nv = 0;
    for (unsigned m = 0; m < sc->mNumMeshes; m++) nv += sc->mMeshes[m]->mNumVertices;
    ASSERT_EQ_INT(nv, 3000);
    const struct aiMesh *m0 = sc->mMeshes[0];
    for (unsigned i = 0; i < m0->mNumVertices; i++) {
        ASSERT_TRUE(m0->mVertices[i].x == (float)p->positions[3 * i]);
        ASSERT_TRUE(m0->mVertices[i].z == (float)p->positions[3 * i + 2]);
    }
    aiReleaseImport(sc);
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
}

static void write_file(const char *path, const char *text, size_t n) {
    FILE *f = fopen(path, "wb");
    ASSERT_TRUE(f != NULL);
    fwrite(text, 1, n, f);
    fclose(f);
}

static vp_result import_text(vp_context *ctx, const char *name, const char *text, size_t *count) {
    write_file(tmp(name), text, strlen(text));
    vp_particles *p = NULL;
    vp_result r = vp_import(ctx, tmp(name), VP_FORMAT_UNKNOWN, &p, NULL);
    if (count) *count = p ? p->count : (size_t)-1;
    if (r != VP_OK) ASSERT_TRUE(p == NULL && strlen(vp_context_message(ctx)) > 0);
    vp_particles_destroy(p);
    return r;
}

static void test_readers_strict(void) {
    vp_context *ctx = NULL;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    size_t n;
    ASSERT_OK(ctx, import_text(ctx, "h.csv", "id,x,y,z,pscale,group\n", &n));
    ASSERT_EQ_INT(n, 0); /* well formed; convert refuses it, the reader does not */
    ASSERT_OK(ctx, import_text(ctx, "one.csv", "id,x,y,z,pscale,group\n0,1,2,3,0.5,a\n", &n));
    ASSERT_EQ_INT(n, 1);
    ASSERT_OK(ctx, import_text(ctx, "crlf.csv", "id,x,y,z,pscale,group\r\n0,1,2,3,0.5,a\r\n", &n));
    ASSERT_EQ_INT(import_text(ctx, "sp.csv", "id,x,y,z,pscale,group\n0, 1,2,3,0.5,a\n", NULL),
                  VP_ERR_FORMAT);
    ASSERT_EQ_INT(import_text(ctx, "nan.csv", "id,x,y,z,pscale,group\n0,1,NaN,3,0.5,a\n", NULL),
                  VP_ERR_FORMAT);
    ASSERT_EQ_INT(import_text(ctx, "big.csv", "id,x,y,z,pscale,group\n0,1,2,3,1e39,a\n", NULL),
                  VP_ERR_FORMAT);
    ASSERT_EQ_INT(import_text(ctx, "gap.csv", "id,x,y,z,pscale,group\n1,1,2,3,0.5,a\n", NULL),
                  VP_ERR_FORMAT);
    ASSERT_EQ_INT(import_text(ctx, "blank.csv", "id,x,y,z,pscale,group\n\n", NULL), VP_ERR_FORMAT);
    const char *ply0 =
        "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n"
        "property float y\nproperty float z\nproperty float pscale\nproperty int id\n"
        "end_header\n";
    ASSERT_OK(ctx, import_text(ctx, "e.ply", ply0, &n));
    ASSERT_EQ_INT(n, 0);
    const char *ply3q =
        "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n"
        "property float y\nproperty float z\nproperty float pscale\nproperty int id\n"
        "property float orient_x\nproperty float orient_y\nproperty float orient_w\n"
        "end_header\n";
    ASSERT_EQ_INT(import_text(ctx, "q3.ply", ply3q, NULL), VP_ERR_FORMAT);
    ASSERT_EQ_INT(import_text(ctx, "neg.ply",
                              "ply\nformat binary_little_endian 1.0\nelement vertex -1\n"
                              "end_header\n",
                              NULL),
                  VP_ERR_FORMAT);
    ASSERT_EQ_INT(import_text(ctx, "x.ply", "", NULL), VP_ERR_FORMAT);
    /* every prefix of a good PLY is refused, never read past its end */
    vp_particles *p = make_set(ctx, 5);
    ASSERT_OK(ctx, vp_export(ctx, tmp("g.ply"), p, NULL));
    FILE *f = fopen(tmp("g.ply"), "rb");
    char buf[4096];
    size_t len = fread(buf, 1, sizeof buf, f);
    fclose(f);
    for (size_t cut = 0; cut < len; cut += 7) {
        write_file(tmp("cut.ply"), buf, cut);
        vp_particles *q = NULL;
        ASSERT_TRUE(vp_import(ctx, tmp("cut.ply"), VP_FORMAT_UNKNOWN, &q, NULL) != VP_OK);
        ASSERT_TRUE(q == NULL);
    }
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
}

/* Random byte flips in a good PLY and CSV (deterministic): the readers
 * either refuse the file or return a set that passes their own checks;
 * never a crash (run under valgrind/ASan by the CI's hardening stages). */
static void test_mutated_files(void) {
    vp_context *ctx = NULL;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_particles *p = make_set(ctx, 12);
    const char *names[2] = {"m.ply", "m.csv"};
    int refused = 0, accepted = 0;
    for (int k = 0; k < 2; k++) {
        ASSERT_OK(ctx, vp_export(ctx, tmp(names[k]), p, NULL));
        FILE *f = fopen(tmp(names[k]), "rb");
        static char good[8192], bad[8192];
        size_t len = fread(good, 1, sizeof good, f);
        fclose(f);
        ASSERT_TRUE(len > 0 && len < sizeof good);
        for (int t = 0; t < 1500; t++) {
            memcpy(bad, good, len);
            int flips = 1 + (int)(rnd() * 4);
            for (int j = 0; j < flips; j++)
                bad[(size_t)(rnd() * (double)len)] = (char)(unsigned char)(rnd() * 256);
            write_file(tmp("mut.bin"), bad, len - (t % 5 == 0 ? (size_t)(rnd() * 40) : 0));
            vp_particles *q = NULL;
            vp_result r =
                vp_import(ctx, tmp("mut.bin"), k ? VP_FORMAT_CSV : VP_FORMAT_PLY, &q, NULL);
            if (r != VP_OK) {
                ASSERT_TRUE(q == NULL);
                refused++;
                continue;
            }
            accepted++;
            for (size_t i = 0; i < q->count; i++) {
                ASSERT_TRUE(isfinite(q->positions[3 * i]) && q->radii[i] > 0);
                ASSERT_TRUE(q->groups[i] < q->group_count);
            }
            vp_particles_destroy(q);
        }
    }
    fprintf(stderr, "   %d mutated files refused, %d accepted (valid)\n", refused, accepted);
    ASSERT_GE(refused, 1000);
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
}

static void test_failed_writes_leave_nothing(void) {
    vp_context *ctx = NULL;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_particles *p = make_set(ctx, 10);
    ASSERT_EQ_INT(vp_export(ctx, "/nonexistent-dir/x.ply", p, NULL), VP_ERR_IO);
    ASSERT_EQ_INT(vp_export(ctx, tmp("x.xyz"), p, NULL), VP_ERR_INVALID_ARGUMENT);
    struct stat st;
    ASSERT_TRUE(stat(tmp("x.xyz"), &st) != 0);
    /* a particle in a group that does not exist: refused before writing */
    p->groups[3] = 7;
    write_file(tmp("keep.csv"), "keep\n", 5);
    ASSERT_EQ_INT(vp_export(ctx, tmp("keep.csv"), p, NULL), VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(stat(tmp("keep.csv"), &st) == 0 && st.st_size == 5);
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
}

static void test_obj_counts_and_estimate(void) {
    int v, f;
    ASSERT_EQ_INT(vp_export_obj_counts(VP_SHAPE_SPHERE, 0, &v, &f), 0);
    ASSERT_EQ_INT(v, 42);
    ASSERT_EQ_INT(f, 80);
    ASSERT_EQ_INT(vp_export_obj_counts(VP_SHAPE_SPHERE, 3, &v, &f), 0);
    ASSERT_EQ_INT(v, 92);
    ASSERT_EQ_INT(f, 180);
    ASSERT_EQ_INT(vp_export_obj_counts(VP_SHAPE_DODECAHEDRON, 0, &v, &f), 0);
    ASSERT_EQ_INT(v, 20);
    ASSERT_EQ_INT(f, 12);
    vp_context *ctx = NULL;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    for (int s = 0; s < 2; s++) {
        vp_particles *p = make_set(ctx, 2000);
        if (s == 0) p->shape = VP_SHAPE_SPHERE;
        vp_export_params ep;
        vp_export_params_init(&ep);
        ASSERT_OK(ctx, vp_export(ctx, tmp("e.obj"), p, &ep));
        struct stat st;
        ASSERT_EQ_INT(stat(tmp("e.obj"), &st), 0);
        double est = vp_export_estimate_bytes(p, VP_FORMAT_OBJ, &ep);
        fprintf(stderr, "   %s: OBJ %lld bytes, estimated %.0f\n", vp_shape_name(p->shape),
                (long long)st.st_size, est);
        ASSERT_LE(fabs(est - (double)st.st_size), 0.15 * (double)st.st_size);
        ASSERT_OK(ctx, vp_export(ctx, tmp("e.ply"), p, &ep));
        ASSERT_EQ_INT(stat(tmp("e.ply"), &st), 0);
        ASSERT_LE(fabs(vp_export_estimate_bytes(p, VP_FORMAT_PLY, &ep) - (double)st.st_size), 1024);
        /* a million spheres cross the CLI's 2 GB warning line */
        p->count = 1000000;
        if (s == 0) ASSERT_GE(vp_export_estimate_bytes(p, VP_FORMAT_OBJ, &ep), 2e9);
        p->count = 2000;
        vp_particles_destroy(p);
    }
    vp_context_destroy(ctx);
}

int main(void) {
    snprintf(g_dir, sizeof g_dir, "/tmp/vp_test_export_XXXXXX");
    ASSERT_TRUE(mkdtemp(g_dir) != NULL);
    RUN_TEST(test_format_from_path);
    RUN_TEST(test_ply_csv_round_trip);
    RUN_TEST(test_readers_strict);
    RUN_TEST(test_mutated_files);
    RUN_TEST(test_failed_writes_leave_nothing);
    RUN_TEST(test_obj_counts_and_estimate);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_dir);
    if (system(cmd) != 0) return 1;
    fprintf(stderr, "PASS: test_export\n");
    return 0;
}
