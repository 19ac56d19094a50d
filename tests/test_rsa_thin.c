/* SPDX-License-Identifier: Apache-2.0 */
/* RSA in slabs and needles far thinner than a level-0 cell: all placed,
 * no overlap, inside (brute force), in bounded time and memory. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "random_util.h"
#include "vp_test.h"

/* Largest |x_k| + r - h_k over the particles (fit inside the box of
 * half sides h: must be <= 0), relative to the radius r0. */
static double worst_wall_aabb(const vp_particles *p, const double h[3], double r0) {
    double worst = -HUGE_VAL;
    for (size_t i = 0; i < p->count; i++)
        for (int k = 0; k < 3; k++) {
            double v = (fabs(p->positions[3 * i + k]) + rad(p, i) - h[k]) / r0;
            if (v > worst) worst = v;
        }
    return worst;
}

/* n spheres of radius 0.4 t in the box t x 1 x 1 (or t x t x 1, a
 * needle): every one placed (stop count), no overlap, inside, in a child
 * bounded to 30 s and 1.5 GB. Before the fix, the level-0 cells were sized
 * from the volume and tiled the slab with cubes far thicker than it:
 * t = 1e-20 made 1e16 cells (24 GB, killed), t = 1e-8 placed none, t =
 * 1e-6 placed 3 of 50 (5000 tries in a row failed: a dart fell in the
 * slab once in 10^4). */
static double thin_t;
static size_t thin_n;
static int thin_needle;
static vp_shape thin_shape;

static void thin_case(void) {
    double t = thin_t, r = 0.4 * t;
    double h[3] = {0.5 * t, thin_needle ? 0.5 * t : 0.5, 0.5};
    double lo[3] = {-h[0], -h[1], -h[2]};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, h, &c));
    vp_rsa_pass ps;
    vp_rsa_params rp;
    one_pass(&ps, &rp, r, thin_n, 7);
    rp.shape = thin_shape;
    vp_particles *p = NULL;
    vp_rsa_report rep;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    fprintf(stderr, "   %s%s %g, r %g: placed %zu of %zu, stop %d, %llu tries, peak %ld MB\n",
            thin_shape == VP_SHAPE_CUBE ? "cubes, " : "", thin_needle ? "needle" : "slab", t, r,
            rep.passes[0].placed, thin_n, (int)rep.passes[0].stop,
            (unsigned long long)rep.passes[0].tries, ru.ru_maxrss / 1024);
    ASSERT_EQ_INT(rep.passes[0].stop, VP_RSA_STOP_COUNT);
    ASSERT_EQ_INT(p->count, thin_n);
    if (thin_shape == VP_SHAPE_SPHERE) ASSERT_LE(worst_overlap(p), 0.0);
    ASSERT_LE(worst_wall_aabb(p, h, r), 1e-9);
    /* the darts are drawn in the slab: few fail (each fails with the
     * chance that it lands within 2r of a placed centre, or, for a
     * solid, too near the wall for its orientation) */
    ASSERT_LE((double)rep.passes[0].tries, 4.0 * (double)thin_n + 100.0);
    /* 10 particles: the memory of the packer, not of a grid (the test's
     * own baseline is about 40 MB; the 1e-7 slab took 690 MB before) */
    if (!VP_TEST_SANITIZED) ASSERT_LE((double)ru.ru_maxrss, 200.0 * 1024);
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

static void test_rsa_thin_containers(void) {
    const double ts[] = {1e-20, 1e-10, 1e-8, 1e-7, 1e-6, 1e-3};
    for (size_t i = 0; i < sizeof ts / sizeof ts[0]; i++) {
        thin_t = ts[i];
        thin_n = ts[i] == 1e-6 ? 50 : 10;
        thin_needle = 0;
        thin_shape = VP_SHAPE_SPHERE;
        vp_test_bounded(thin_case, 30, 1500ull << 20);
    }
    thin_t = 1e-8; /* a needle: two thin axes */
    thin_n = 10;
    thin_needle = 1;
    vp_test_bounded(thin_case, 30, 1500ull << 20);
    thin_t = 1e-6; /* a solid in a slab */
    thin_n = 50;
    thin_needle = 0;
    thin_shape = VP_SHAPE_CUBE;
    vp_test_bounded(thin_case, 30, 1500ull << 20);
}

/* A maximal pass in a slab 2.5 radii thick (one layer): no overlap,
 * inside, stop maximal, and denser than a quarter of the slab's area in
 * disks of the radius (2D RSA saturates at 0.547 of the area for disks
 * that must not overlap; here the centres may also move across the
 * slab, so disks of radius r*sqrt(1 - (0.25)^2) bound it from below). */
static void test_rsa_thin_maximal(void) {
    double t = 1e-6, r = 0.4 * t, w = 2e-5;
    double h[3] = {0.5 * t, 0.5 * w, 0.5 * w}, lo[3] = {-h[0], -h[1], -h[2]};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, h, &c));
    vp_rsa_pass ps;
    vp_rsa_params rp;
    one_pass(&ps, &rp, r, 0, 3);
    vp_particles *p = NULL;
    vp_rsa_report rep;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
    double area = (w - 2 * r) * (w - 2 * r), disk = 3.14159265358979 * r * r;
    fprintf(stderr, "   slab %g x %g x %g, r %g, maximal: %zu spheres, %.3f of the area in disks\n",
            t, w, w, r, p->count, (double)p->count * disk / area);
    ASSERT_EQ_INT(rep.passes[0].stop, VP_RSA_STOP_MAXIMAL);
    ASSERT_LE(worst_overlap(p), 0.0);
    ASSERT_LE(worst_wall_aabb(p, h, r), 1e-9);
    ASSERT_GE((double)p->count * disk / area, 0.25);
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

int main(void) {
    ASSERT_OK(NULL, vp_context_create(&ctx));
    RUN_TEST(test_rsa_thin_containers);
    RUN_TEST(test_rsa_thin_maximal);
    vp_context_destroy(ctx);
    fprintf(stderr, "PASS\n");
    return 0;
}
