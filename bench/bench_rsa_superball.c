// SPDX-License-Identifier: Apache-2.0
/* RSA of superballs (issue 30), each case in its own process:
 *  1. 100k x SCALE superballs p = 2, random orientations, in a unit box
 *     (radius for a fraction of 0.25 once all are placed): accepted per
 *     second (target >= 30 000/s), fraction;
 *  2. count=max at radius 0.04 / cbrt(SCALE) for p = 0.6, 1 (sphere, by
 *     GJK), 2, 5: the fraction where the retry limit ends the pass;
 *  3. reference: spheres of the same bounding radius and count.
 * Usage: build/bench/bench_rsa_superball [SCALE]   (default 1)
 * No pass/fail: figures for the notes. */
#include "vdbpack/vdbpack.h"

#include <math.h>

#include "bench_random_common.h"

typedef struct scase {
    const char *label;
    vp_shape shape;
    double p, r;
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
    rp.shape_param = k->p;
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
    double rc = cbrt(0.25 / ((double)n * vp_shape_unit_volume_param(VP_SHAPE_SUPERBALL, 2.0)));
    printf("bench_rsa_superball: scale %g; superballs p = 2 of bounding radius %.5f\n", scale, rc);
    scase a = {"superballs p 2, random orientation, count", VP_SHAPE_SUPERBALL, 2.0, rc, n};
    bench_fork(run, &a);
    scase ref = {"reference: spheres, same radius and count", VP_SHAPE_SPHERE, 0, rc, n};
    bench_fork(run, &ref);
    double r = 0.04 / cbrt(scale);
    const double ps[] = {0.6, 1.0, 2.0, 5.0};
    for (int i = 0; i < 4; i++) {
        char l[64];
        snprintf(l, sizeof l, "superballs p %g, count=max", ps[i]);
        scase m = {l, VP_SHAPE_SUPERBALL, ps[i], r, 0};
        bench_fork(run, &m);
    }
    printf("target (issue 30): count case >= 30 000 particles/s\n");
    return 0;
}
