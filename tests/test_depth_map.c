/* SPDX-License-Identifier: Apache-2.0 */
/* The coarse depth map of level-set containers (src/core/depth_map.c):
 * the block distance transform and sign rule on hand-made block grids, the
 * bound's promise checked against the level set's own samples on a real
 * voxelized mesh, and the lattice packer giving the same particles with
 * and without the map. */
#include "vp_test.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/container.h"
#include "core/depth_map.h"
#include "core/geom.h"
#include "core/rng.h"
#include "vdbpack/vdbpack.h"

static vp_context *ctx;

/* A 7^3 block grid of interior tiles with one leaf block in the middle:
 * the 26 blocks around it stay undecided (k = 1), the shell at k = 2 gets
 * band + 8 - 3.75 voxels and k = 3 16 voxels more; a block next to a tile
 * of the other sign is never decided. */
static void test_distance_transform_and_sign_rule(void) {
    const int64_t dims[3] = {7, 7, 7};
    const double v = 0.5, band = 3 * v, origin[3] = {0, 0, 0};
    float *val = malloc(7 * 7 * 7 * sizeof *val);
    ASSERT_TRUE(val);
    for (int i = 0; i < 343; i++) val[i] = (float)-band;
#define AT(x, y, z) ((size_t)(((z)*7 + (y)) * 7 + (x)))
    val[AT(3, 3, 3)] = NAN;
    /* an exterior tile in a corner: it and its neighbours are undecided */
    val[AT(0, 0, 0)] = (float)band;
    vp_depth_map m;
    ASSERT_EQ_INT(vp_depth_map_build(&m, origin, 8 * v, v, dims, val, band, band), 0);
    const float *b = m.bound;
    ASSERT_TRUE(isnan(b[AT(3, 3, 3)]));
    for (int dz = -1; dz <= 1; dz++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) ASSERT_TRUE(isnan(b[AT(3 + dx, 3 + dy, 3 + dz)]));
    double k2 = -(band + 8 * v - 3.75 * v), k3 = -(band + 16 * v - 3.75 * v);
    ASSERT_NEAR(b[AT(5, 3, 3)], k2, 1e-6);
    ASSERT_NEAR(b[AT(1, 5, 2)], k2, 1e-6); /* Chebyshev: max(2, 2, 1) */
    ASSERT_NEAR(b[AT(6, 3, 3)], k3, 1e-6);
    ASSERT_NEAR(b[AT(6, 0, 6)], k3, 1e-6);
    ASSERT_LE(b[AT(6, 3, 3)], k3);      /* never deeper than derived */
    ASSERT_TRUE(isnan(b[AT(0, 0, 0)])); /* the exterior tile */
    ASSERT_TRUE(isnan(b[AT(1, 1, 0)])); /* next to it: sign changes */
    ASSERT_TRUE(isnan(b[AT(1, 1, 1)]));
    ASSERT_NEAR(b[AT(2, 0, 0)], k3, 1e-6); /* two away: k = 3 from the leaf */
    /* every decided block is counted */
    size_t n = 0;
    for (int i = 0; i < 343; i++) n += !isnan(b[i]);
    ASSERT_EQ_INT(n, m.decided);
    /* lookups: the block of a point, NaN outside the grid */
    double p[3] = {5.5 * 8 * v, 3.5 * 8 * v, 3.5 * 8 * v};
    ASSERT_NEAR(vp_depth_map_at(&m, p), k2, 1e-6);
    double q[3] = {-0.1, 1, 1};
    ASSERT_TRUE(isnan(vp_depth_map_at(&m, q)));
    ASSERT_TRUE(isnan(vp_depth_map_at(NULL, p)));
#undef AT
    vp_depth_map_free(&m);
    ASSERT_TRUE(m.bound == NULL);
}

static vp_container *load(const char *name, double radius, int narrow) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", VP_SAMPLES, name);
    vp_container_params cp;
    vp_container_params_init(&cp);
    cp.particle_radius = radius;
    cp.narrow_band = narrow;
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_load(ctx, path, &cp, &c));
    return c;
}

/* The promise of depth_map.h, checked on the level set itself: for a point
 * x in a decided block and any y within s of x, the sample at y is at most
 * max(b + s, -interior band) inside and at least min(b - s, background)
 * outside. Points y are drawn up to 3 blocks away. (The box's outside
 * lies within a block of its leaves everywhere: nothing decided there.) */
static void test_bound_holds_against_samples(const char *name, size_t min_outside) {
    vp_container *c = load(name, 0.02, 1);
    ASSERT_TRUE(c->depth_map != NULL);
    vp_depth_map m;
    ASSERT_EQ_INT(c->depth_map(c, &m), 0);
    const vp_container_info *in = &c->info;
    double far[3] = {in->bmax[0] + 1e3, in->bmax[1] + 1e3, in->bmax[2] + 1e3};
    double background = vp_container_distance(c, far);
    ASSERT_GE(background, in->voxel_size);
    uint64_t rng = 12345;
    size_t inside = 0, outside = 0, tight = 0;
    double block = 1.0 / m.inv_block;
    for (int i = 0; i < 400000; i++) {
        double x[3];
        for (int a = 0; a < 3; a++) {
            double lo = in->bmin[a] - block, hi = in->bmax[a] + block;
            x[a] = lo + (hi - lo) * vp_rng_uniform(&rng);
        }
        double b = vp_depth_map_at(&m, x);
        if (isnan(b)) continue;
        double dir[3], s = 3.0 * block * vp_rng_uniform(&rng);
        do {
            for (int a = 0; a < 3; a++) dir[a] = vp_rng_normal(&rng);
        } while (vp_norm3(dir) < 1e-9);
        double dn = vp_norm3(dir);
        for (int a = 0; a < 3; a++) dir[a] /= dn;
        double y[3] = {x[0] + s * dir[0], x[1] + s * dir[1], x[2] + s * dir[2]};
        double d = vp_container_distance(c, y);
        if (b < 0) {
            double lim = fmax(b + s, -in->interior_band);
            ASSERT_LE(d, lim + 1e-6);
            tight += d > lim - in->voxel_size;
            inside++;
        } else {
            ASSERT_GE(d, fmin(b - s, background) - 1e-6);
            outside++;
        }
    }
    fprintf(stderr,
            "   %s: %zu of %lld blocks decided; %zu inside and %zu outside checks "
            "(%zu within a voxel of the bound)\n",
            name, m.decided, (long long)(m.dims[0] * m.dims[1] * m.dims[2]), inside, outside,
            tight);
    ASSERT_GE(inside, 10000);
    ASSERT_GE(outside, min_outside);
    vp_depth_map_free(&m);
    vp_container_destroy(c);
}

/* The map only saves samples: with one placement (no search) the lattice
 * packer must place exactly the same particles with and without it. */
static void test_lattice_same_with_and_without_map(void) {
    vp_container *c = load("peanut.obj", 0.02, 1);
    vp_lattice_params lp;
    vp_lattice_params_init(&lp);
    lp.radius = 0.02;
    lp.offsets = 1;
    vp_particles *a = NULL, *b = NULL;
    ASSERT_OK(ctx, vp_pack_lattice(ctx, c, &lp, &a, NULL));
    int (*saved)(const struct vp_container *, vp_depth_map *) = c->depth_map;
    c->depth_map = NULL;
    ASSERT_OK(ctx, vp_pack_lattice(ctx, c, &lp, &b, NULL));
    c->depth_map = saved;
    fprintf(stderr, "   %zu particles with the map, %zu without\n", a->count, b->count);
    ASSERT_GE(a->count, 1000);
    ASSERT_EQ_INT(a->count, b->count);
    ASSERT_TRUE(memcmp(a->positions, b->positions, 3 * a->count * sizeof(double)) == 0);
    vp_particles_destroy(a);
    vp_particles_destroy(b);
    /* the same for a polyhedron, whose wall test reads vertices */
    lp.shape = VP_SHAPE_OCTAHEDRON;
    ASSERT_OK(ctx, vp_pack_lattice(ctx, c, &lp, &a, NULL));
    c->depth_map = NULL;
    ASSERT_OK(ctx, vp_pack_lattice(ctx, c, &lp, &b, NULL));
    c->depth_map = saved;
    ASSERT_EQ_INT(a->count, b->count);
    ASSERT_TRUE(memcmp(a->positions, b->positions, 3 * a->count * sizeof(double)) == 0);
    vp_particles_destroy(a);
    vp_particles_destroy(b);
    vp_container_destroy(c);
}

/* The narrow band: just past the radius (at least 3 voxels), against the
 * wide one (1.25 r + 2 voxels) that the random packers get. */
static void test_narrow_band_depth(void) {
    vp_container *n = load("peanut.obj", 0.02, 1), *w = load("peanut.obj", 0.02, 0);
    fprintf(stderr, "   interior band: narrow %g, wide %g (voxel %g)\n", n->info.interior_band,
            w->info.interior_band, n->info.voxel_size);
    ASSERT_GE(n->info.interior_band, 0.02);
    ASSERT_LE(n->info.interior_band, 0.02 + 2 * n->info.voxel_size);
    ASSERT_GE(w->info.interior_band, 1.25 * 0.02 + n->info.voxel_size);
    vp_container_destroy(n);
    vp_container_destroy(w);
}

int main(void) {
    vp_context_create(&ctx);
    RUN_TEST(test_distance_transform_and_sign_rule);
    RUN_CASE(bound_peanut, test_bound_holds_against_samples("peanut.obj", 10000));
    RUN_CASE(bound_torus, test_bound_holds_against_samples("torus.obj", 10000));
    RUN_CASE(bound_box, test_bound_holds_against_samples("box.obj", 0));
    RUN_TEST(test_lattice_same_with_and_without_map);
    RUN_TEST(test_narrow_band_depth);
    vp_context_destroy(ctx);
    return 0;
}
