/* SPDX-License-Identifier: Apache-2.0 */
/* Helpers of the random packers' tests (test_rng.c, test_rsa.c,
 * test_rsa_thin.c, test_relax.c, test_check.c): brute-force checks of a
 * packing on exact analytic containers, and one- and two-pass RSA
 * parameters. Each test file has its own context, ctx. */
#ifndef VP_TEST_RANDOM_UTIL_H
#define VP_TEST_RANDOM_UTIL_H
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdint.h>

#include "vp_test.h"

static vp_context *ctx;

static inline double rad(const vp_particles *p, size_t i) {
    return p->radii ? p->radii[i] : p->uniform_radius;
}

/* Worst pair overlap relative to r_i + r_j, by brute force. */
static inline double worst_overlap(const vp_particles *p) {
    double worst = -HUGE_VAL;
    for (size_t i = 0; i < p->count; i++)
        for (size_t j = i + 1; j < p->count; j++) {
            const double *a = p->positions + 3 * i, *b = p->positions + 3 * j;
            double d = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                            (a[2] - b[2]) * (a[2] - b[2]));
            double e = rad(p, i) + rad(p, j), o = (e - d) / e;
            if (o > worst) worst = o;
        }
    return worst;
}

/* Largest d(centre) + r over a box [-h, h]^3 (fit inside: must be <= 0). */
static inline double worst_wall_box(const vp_particles *p, double h) {
    double worst = -HUGE_VAL;
    for (size_t i = 0; i < p->count; i++)
        for (int k = 0; k < 3; k++) {
            double v = fabs(p->positions[3 * i + k]) + rad(p, i) - h;
            if (v > worst) worst = v;
        }
    return worst;
}

static inline vp_container *unit_box(void) {
    double lo[3] = {-0.5, -0.5, -0.5}, hi[3] = {0.5, 0.5, 0.5};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, hi, &c));
    return c;
}

/* One pass of radius r: count spheres, or maximal when count is 0. */
static inline void one_pass(vp_rsa_pass *ps, vp_rsa_params *rp, double r, size_t count,
                            uint64_t seed) {
    vp_rsa_pass_init(ps);
    ps->count = count;
    ps->maximal = count == 0;
    vp_size_dist_constant(&ps->radius, r);
    vp_rsa_params_init(rp);
    rp->passes = ps;
    rp->npasses = 1;
    rp->seed = seed;
}

/* Two passes: n0 spheres of radius law r0 (0: maximal), grown or not,
 * then n1 of law r1 (0: maximal). */
static inline void two_passes(vp_rsa_pass ps[2], vp_rsa_params *rp, const char *r0, size_t n0,
                              int grow0, const char *r1, size_t n1, uint64_t seed) {
    const char *law[2] = {r0, r1};
    size_t n[2] = {n0, n1};
    for (int k = 0; k < 2; k++) {
        vp_rsa_pass_init(&ps[k]);
        ps[k].count = n[k];
        ps[k].maximal = n[k] == 0;
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, law[k], &ps[k].radius));
    }
    ps[0].grow = grow0;
    vp_rsa_params_init(rp);
    rp->passes = ps;
    rp->npasses = 2;
    rp->seed = seed;
}
#endif
