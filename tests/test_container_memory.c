/* SPDX-License-Identifier: Apache-2.0 */
/* Containers and particle shapes from meshes in memory
 * (vp_container_from_mesh, vp_mesh_shape_from_mesh): the same level set and
 * the same packing as the same mesh read from a file, the same checks, and
 * one clear error for every bad array. Also the container parameters of a
 * job (vp_container_params_for_*), vp_container_distances and the
 * version calls. */
#include "vdbpack/vdbpack.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "vp_test.h"

/* A cube of side 1 about the origin, outward (counter-clockwise seen from
 * outside); coordinates exact in float, as Assimp reads a file. */
static const double CUBE_V[8 * 3] = {-0.5, -0.5, -0.5, 0.5,  -0.5, -0.5, 0.5, 0.5,
                                     -0.5, -0.5, 0.5,  -0.5, -0.5, -0.5, 0.5, 0.5,
                                     -0.5, 0.5,  0.5,  0.5,  0.5,  -0.5, 0.5, 0.5};
static const uint32_t CUBE_T[12 * 3] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                        2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};

static char g_dir[256];

static void write_obj(const char *path, const double *v, size_t nv, const uint32_t *t, size_t nt) {
    FILE *f = fopen(path, "w");
    ASSERT_TRUE(f != NULL);
    for (size_t i = 0; i < nv; i++)
        fprintf(f, "v %.17g %.17g %.17g\n", v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    for (size_t i = 0; i < nt; i++)
        fprintf(f, "f %u %u %u\n", t[3 * i] + 1, t[3 * i + 1] + 1, t[3 * i + 2] + 1);
    ASSERT_TRUE(fclose(f) == 0);
}

/* The arrays give exactly the file's level set: info and distances. */
static void test_same_level_set_as_file(void) {
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    char path[300];
    snprintf(path, sizeof path, "%s/cube.obj", g_dir);
    write_obj(path, CUBE_V, 8, CUBE_T, 12);
    vp_container_params cp;
    vp_container_params_init(&cp);
    cp.particle_radius = 0.05;
    vp_container *cf = NULL, *cm = NULL;
    ASSERT_OK(ctx, vp_container_load(ctx, path, &cp, &cf));
    cp.name = "my cube";
    ASSERT_OK(ctx, vp_container_from_mesh(ctx, CUBE_V, 8, CUBE_T, 12, &cp, &cm));
    vp_container_info a, b;
    vp_container_get_info(cf, &a);
    vp_container_get_info(cm, &b);
    ASSERT_EQ_INT(b.kind, VP_CONTAINER_MESH);
    ASSERT_EQ_INT(a.active_voxels, b.active_voxels);
    ASSERT_NEAR(a.voxel_size, b.voxel_size, 0);
    ASSERT_NEAR(a.volume, b.volume, 0);
    ASSERT_NEAR(b.mesh_volume, 1.0, 1e-12);
    ASSERT_EQ_INT(b.mesh_triangles, 12);
    ASSERT_EQ_INT(b.mesh_vertices, 8);
    ASSERT_NEAR(b.volume, 1.0, 0.02);
    /* distances, one by one and in a batch */
    enum { N = 2000 };
    double *pts = malloc(3 * N * sizeof *pts), *d = malloc(N * sizeof *d);
    uint64_t s = 12345;
    for (int i = 0; i < 3 * N; i++) {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        pts[i] = ((double)(s >> 11) / 9007199254740992.0 - 0.5) * 1.4;
    }
    vp_container_distances(cm, pts, N, d);
    int inside = 0;
    for (int i = 0; i < N; i++) {
        double df = vp_container_distance(cf, pts + 3 * i);
        ASSERT_NEAR(df, d[i], 0);
        ASSERT_NEAR(vp_container_distance(cm, pts + 3 * i), d[i], 0);
        inside += d[i] < 0;
    }
    /* the cube holds about (1 / 1.4)^3 of the sampled box */
    ASSERT_NEAR((double)inside / N, 1.0 / (1.4 * 1.4 * 1.4), 0.04);
    /* and the same packing */
    vp_lattice_params lp;
    vp_lattice_params_init(&lp);
    lp.radius = 0.05;
    vp_particles *pf = NULL, *pm = NULL;
    ASSERT_OK(ctx, vp_pack_lattice(ctx, cf, &lp, &pf, NULL));
    ASSERT_OK(ctx, vp_pack_lattice(ctx, cm, &lp, &pm, NULL));
    ASSERT_TRUE(pf->count > 500);
    ASSERT_EQ_INT(pf->count, pm->count);
    ASSERT_TRUE(memcmp(pf->positions, pm->positions, 3 * pf->count * sizeof(double)) == 0);
    vp_particles_destroy(pf);
    vp_particles_destroy(pm);
    free(pts);
    free(d);
    vp_container_destroy(cf);
    vp_container_destroy(cm);
    vp_context_destroy(ctx);
}

/* Vertices given twice (a triangle soup, as exported per face) weld into
 * the closed mesh. */
static void test_soup_welds(void) {
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    double v[36 * 3];
    uint32_t t[36];
    for (int i = 0; i < 36; i++) {
        memcpy(v + 3 * i, CUBE_V + 3 * CUBE_T[i], 3 * sizeof(double));
        t[i] = (uint32_t)i;
    }
    /* -0.0 and +0.0 are one position */
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_from_mesh(ctx, v, 36, t, 12, NULL, &c));
    vp_container_info in;
    vp_container_get_info(c, &in);
    ASSERT_EQ_INT(in.mesh_vertices_raw, 36);
    ASSERT_EQ_INT(in.mesh_vertices, 8);
    ASSERT_EQ_INT(in.boundary_edges, 0);
    vp_container_destroy(c);
    vp_context_destroy(ctx);
}

static void expect_error(vp_context *ctx, vp_result want, const char *needle, vp_result got,
                         vp_container *c) {
    if (got != want || !strstr(vp_context_message(ctx), needle)) {
        fprintf(stderr, "wanted %s with '%s', got %s: '%s'\n", vp_result_name(want), needle,
                vp_result_name(got), vp_context_message(ctx));
        exit(1);
    }
    ASSERT_TRUE(c == NULL);
    ASSERT_TRUE(strchr(vp_context_message(ctx), '\n') == NULL);
}

static void test_bad_arrays(void) {
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_container *c = (vp_container *)1;
    vp_container_params cp;
    vp_container_params_init(&cp);
    cp.name = "host";
    vp_result r = vp_container_from_mesh(ctx, NULL, 8, CUBE_T, 12, &cp, &c);
    expect_error(ctx, VP_ERR_INVALID_ARGUMENT, "host: vertices is NULL", r, c);
    r = vp_container_from_mesh(ctx, CUBE_V, 8, NULL, 12, &cp, &c);
    expect_error(ctx, VP_ERR_INVALID_ARGUMENT, "triangles is NULL", r, c);
    r = vp_container_from_mesh(ctx, CUBE_V, 0, CUBE_T, 12, &cp, &c);
    expect_error(ctx, VP_ERR_FORMAT, "no triangles", r, c);
    r = vp_container_from_mesh(ctx, CUBE_V, 8, CUBE_T, 0, &cp, &c);
    expect_error(ctx, VP_ERR_FORMAT, "no triangles", r, c);
    /* misaligned: a double array starting one byte in */
    unsigned char *buf = malloc(8 * 3 * sizeof(double) + 8);
    memcpy(buf + 1, CUBE_V, sizeof CUBE_V);
    r = vp_container_from_mesh(ctx, (const double *)(const void *)(buf + 1), 8, CUBE_T, 12, &cp,
                               &c);
    expect_error(ctx, VP_ERR_INVALID_ARGUMENT, "not aligned", r, c);
    free(buf);
    uint32_t bad_t[12 * 3];
    memcpy(bad_t, CUBE_T, sizeof bad_t);
    bad_t[3 * 5 + 1] = 8;
    r = vp_container_from_mesh(ctx, CUBE_V, 8, bad_t, 12, &cp, &c);
    expect_error(ctx, VP_ERR_INVALID_ARGUMENT, "triangle 5 has vertex index 8, out of range", r, c);
    double bad_v[8 * 3];
    memcpy(bad_v, CUBE_V, sizeof bad_v);
    bad_v[3 * 6 + 2] = NAN;
    r = vp_container_from_mesh(ctx, bad_v, 8, CUBE_T, 12, &cp, &c);
    expect_error(ctx, VP_ERR_INVALID_ARGUMENT, "vertex 6 has a non-finite coordinate (nan)", r, c);
    bad_v[3 * 6 + 2] = -INFINITY;
    r = vp_container_from_mesh(ctx, bad_v, 8, CUBE_T, 12, &cp, &c);
    expect_error(ctx, VP_ERR_INVALID_ARGUMENT, "(-inf)", r, c);
    /* every triangle collapsed */
    uint32_t degen[6] = {0, 0, 1, 2, 2, 2};
    r = vp_container_from_mesh(ctx, CUBE_V, 8, degen, 2, &cp, &c);
    expect_error(ctx, VP_ERR_FORMAT, "degenerate", r, c);
    /* open: one face missing; VP_INSIDE_CLOSED refuses it, naming the
     * parameter; the default takes it by winding number */
    cp.inside = VP_INSIDE_CLOSED;
    r = vp_container_from_mesh(ctx, CUBE_V, 8, CUBE_T, 10, &cp, &c);
    expect_error(ctx, VP_ERR_OPEN_MESH, "host: the mesh is not closed: 4 boundary edges", r, c);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "set inside to VP_INSIDE_AUTO") != NULL);
    cp.inside = VP_INSIDE_AUTO;
    ASSERT_OK(ctx, vp_container_from_mesh(ctx, CUBE_V, 8, CUBE_T, 10, &cp, &c));
    vp_container_info oi;
    vp_container_get_info(c, &oi);
    ASSERT_EQ_INT(oi.inside, VP_INSIDE_WINDING);
    ASSERT_NEAR(oi.volume, 1.0, 0.05);
    vp_container_destroy(c);
    /* flat: a closed, manifold mesh (a tetrahedron's topology) of four
     * coplanar points, which encloses no volume */
    double flat_v[4 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    uint32_t flat_t[12] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};
    c = (vp_container *)1;
    r = vp_container_from_mesh(ctx, flat_v, 4, flat_t, 4, &cp, &c);
    expect_error(ctx, VP_ERR_BAD_CONTAINER, "encloses no volume", r, c);
    /* a negative voxel size */
    cp.voxel_size = -1;
    r = vp_container_from_mesh(ctx, CUBE_V, 8, CUBE_T, 12, &cp, &c);
    expect_error(ctx, VP_ERR_INVALID_ARGUMENT, "voxel size", r, c);
    ASSERT_EQ_INT(vp_container_from_mesh(ctx, CUBE_V, 8, CUBE_T, 12, NULL, NULL),
                  VP_ERR_INVALID_ARGUMENT);
    vp_context_destroy(ctx);
}

/* A particle shape from arrays equals the same mesh read from a file. */
static void test_shape_from_mesh(void) {
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    char path[300];
    snprintf(path, sizeof path, "%s/cube_shape.obj", g_dir);
    write_obj(path, CUBE_V, 8, CUBE_T, 12);
    vp_mesh_shape *a = NULL, *b = NULL;
    ASSERT_OK(ctx, vp_mesh_shape_load(ctx, path, &a));
    ASSERT_OK(ctx, vp_mesh_shape_from_mesh(ctx, "brick", CUBE_V, 8, CUBE_T, 12, &b));
    ASSERT_TRUE(strcmp(vp_mesh_shape_name(b), "brick") == 0);
    ASSERT_EQ_INT(vp_mesh_shape_triangles(b), 12);
    /* a cube of circumradius 1 has side 2 / sqrt(3) */
    double side = 2.0 / sqrt(3.0);
    ASSERT_NEAR(vp_mesh_shape_volume(b), side * side * side, 1e-12);
    ASSERT_NEAR(vp_mesh_shape_volume(a), vp_mesh_shape_volume(b), 0);
    ASSERT_NEAR(vp_mesh_shape_inradius(a), vp_mesh_shape_inradius(b), 0);
    ASSERT_NEAR(vp_mesh_shape_inradius(b), side / 2, 1e-12);
    vp_mesh_shape *c = (vp_mesh_shape *)1;
    vp_result r = vp_mesh_shape_from_mesh(ctx, "open", CUBE_V, 8, CUBE_T, 11, &c);
    ASSERT_EQ_INT(r, VP_ERR_OPEN_MESH);
    ASSERT_TRUE(c == NULL);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "open: the particle mesh is not closed") != NULL);
    r = vp_mesh_shape_from_mesh(ctx, NULL, NULL, 8, CUBE_T, 12, &c);
    ASSERT_EQ_INT(r, VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "mesh: vertices is NULL") != NULL);
    vp_mesh_shape_destroy(a);
    vp_mesh_shape_destroy(b);
    vp_context_destroy(ctx);
}

/* The container parameters of each job, as the command line sets them. */
static void test_params_for_jobs(void) {
    vp_container_params cp;
    vp_container_params_init(&cp);
    cp.voxel_size = 0.25; /* left alone */
    vp_lattice_params lp;
    vp_lattice_params_init(&lp);
    lp.count = 1000;
    vp_container_params_for_lattice(&cp, &lp);
    ASSERT_NEAR(cp.voxel_size, 0.25, 0);
    ASSERT_NEAR(cp.particle_radius, 0, 0);
    ASSERT_EQ_INT(cp.particle_count, 1000);
    ASSERT_EQ_INT(cp.narrow_band, 1);
    /* spheres on FCC: 4/3 pi / 0.74048 */
    ASSERT_NEAR(cp.space_per_particle, 4.0 / 3.0 * M_PI / (M_PI / sqrt(18.0)), 1e-9);
    lp.radius = 0.1;
    lp.shape = VP_SHAPE_CUBE;
    vp_container_params_for_lattice(&cp, &lp);
    ASSERT_NEAR(cp.particle_radius, 0.1, 0);
    ASSERT_EQ_INT(cp.particle_count, 0);
    ASSERT_NEAR(cp.space_per_particle, vp_shape_unit_volume(VP_SHAPE_CUBE), 1e-12);

    vp_rsa_pass ps[2];
    vp_rsa_pass_init(&ps[0]);
    vp_rsa_pass_init(&ps[1]);
    ps[0].count = 100;
    vp_size_dist_constant(&ps[0].radius, 0.2);
    ps[1].maximal = 1;
    ASSERT_OK(NULL, vp_size_dist_parse(NULL, "uniform:0.01:0.05", &ps[1].radius));
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.passes = ps;
    rp.npasses = 2;
    vp_container_params_for_rsa(&cp, &rp);
    ASSERT_NEAR(cp.particle_radius, 0.2, 0);
    ASSERT_EQ_INT(cp.particle_count, 100);
    ASSERT_EQ_INT(cp.narrow_band, 0);

    vp_relax_params xp;
    vp_relax_params_init(&xp);
    xp.count = 500;
    vp_size_dist_constant(&xp.radius, 0.03);
    vp_container_params_for_relax(&cp, &xp);
    ASSERT_NEAR(cp.particle_radius, 0.03, 0);
    ASSERT_EQ_INT(cp.particle_count, 500);
    xp.target_fraction = 0.5;
    vp_container_params_for_relax(&cp, &xp);
    ASSERT_NEAR(cp.particle_radius, 0, 0);
    ASSERT_NEAR(cp.space_per_particle, 4.0 / 3.0 * M_PI / 0.5, 1e-12);
}

static void test_version(void) {
    ASSERT_TRUE(strcmp(vp_version(), VP_VERSION_STRING) == 0);
    ASSERT_EQ_INT(vp_version_number(), VP_VERSION_NUMBER);
    char buf[64];
    snprintf(buf, sizeof buf, "%d.%d.%d", VP_VERSION_MAJOR, VP_VERSION_MINOR, VP_VERSION_PATCH);
    ASSERT_TRUE(strcmp(buf, vp_version()) == 0);
}

int main(void) {
    snprintf(g_dir, sizeof g_dir, "/tmp/vp_test_memory.XXXXXX");
    ASSERT_TRUE(mkdtemp(g_dir) != NULL);
    RUN_TEST(test_same_level_set_as_file);
    RUN_TEST(test_soup_welds);
    RUN_TEST(test_bad_arrays);
    RUN_TEST(test_shape_from_mesh);
    RUN_TEST(test_params_for_jobs);
    RUN_TEST(test_version);
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_dir);
    if (system(cmd) != 0) return 1;
    return 0;
}
