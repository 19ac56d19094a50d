/* SPDX-License-Identifier: Apache-2.0 */
/* RSA figures of issue 5, each case in its own process:
 *  1. random-orientation cubes in a unit box, 100k x SCALE asked for
 *     (radius for a fraction of 0.25 once all are placed): accepted
 *     particles per second, fraction; then the same radius with count=max
 *     (which for solids ends by the retry limit);
 *  2. count=max for every solid: exact overlap with random orientations
 *     against bounding-box overlap (fixed orientation), same radius;
 *  3. reference in the same run: spheres of the same bounding radius and
 *     count (the sphere packer's rate on this machine now).
 * Usage: build/bench/bench_rsa_solids [SCALE]   (default 1)
 * No pass/fail: figures for the notes. */
#include "vdbpack/vdbpack.h"

#include <math.h>

#include "bench_random_common.h"

typedef struct scase {
    const char *label;
    vp_shape shape;
    vp_orient_mode orient;
    vp_overlap_mode overlap;
    double r;
    size_t count; /* 0 = max */
} scase;

static void run(void *arg) {
    scase *k = arg;
    vp_context *ctx = NULL;
    vp_context_create(&ctx);
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    vp_container *c = NULL;
    vp_container_create_box(ctx, lo, hi, &c);
    vp_rsa_pass ps;
    vp_rsa_pass_init(&ps);
    ps.count = k->count;
    ps.maximal = k->count == 0;
    vp_size_dist_constant(&ps.radius, k->r);
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.shape = k->shape;
    rp.orient = k->orient;
    rp.overlap = k->overlap;
    rp.passes = &ps;
    rp.npasses = 1;
    rp.seed = 1;
    vp_particles *p = NULL;
    double t0 = bench_now();
    if (vp_pack_rsa(ctx, c, &rp, &p, NULL) != VP_OK) {
        printf("%s: error: %s\n", k->label, vp_context_message(ctx));
        return;
    }
    double t = bench_now() - t0;
    printf("%-44s %8zu placed, fraction %.4f, %6.2f s, %7.0f particles/s\n", k->label, p->count,
           vp_particles_volume(p), t, p->count / t);
    vp_particles_destroy(p);
    vp_container_destroy(c);
    vp_context_destroy(ctx);
}

int main(int argc, char **argv) {
    double scale = argc > 1 ? atof(argv[1]) : 1.0;
    if (!(scale > 0)) scale = 1.0;
    size_t n = (size_t)(1e5 * scale);
    double rc = cbrt(0.25 / ((double)n * vp_shape_unit_volume(VP_SHAPE_CUBE)));
    printf("bench_rsa_solids: scale %g; cubes of bounding radius %.5f\n", scale, rc);
    scase a = {"cubes, random orientation, count",
               VP_SHAPE_CUBE,
               VP_ORIENT_RANDOM,
               VP_OVERLAP_EXACT,
               rc,
               n};
    bench_fork(run, &a);
    scase b = {"cubes, random orientation, count=max",
               VP_SHAPE_CUBE,
               VP_ORIENT_RANDOM,
               VP_OVERLAP_EXACT,
               rc,
               0};
    bench_fork(run, &b);
    scase ref = {"reference: spheres, same radius and count",
                 VP_SHAPE_SPHERE,
                 VP_ORIENT_RANDOM,
                 VP_OVERLAP_EXACT,
                 rc,
                 n};
    bench_fork(run, &ref);
    double r = 0.04 / cbrt(scale);
    for (int s = VP_SHAPE_TETRAHEDRON; s < VP_SHAPE_COUNT; s++) {
        char l1[64], l2[64];
        snprintf(l1, sizeof l1, "%s max, exact, random orientation", vp_shape_name((vp_shape)s));
        snprintf(l2, sizeof l2, "%s max, bbox, fixed orientation", vp_shape_name((vp_shape)s));
        scase e = {l1, (vp_shape)s, VP_ORIENT_RANDOM, VP_OVERLAP_EXACT, r, 0};
        scase f = {l2, (vp_shape)s, VP_ORIENT_FIXED, VP_OVERLAP_BBOX, r, 0};
        bench_fork(run, &e);
        bench_fork(run, &f);
    }
    printf("targets (issue 5): cubes count case >= 50k particles/s; exact packs more than bbox "
           "where the box is loose\n");
    return 0;
}
