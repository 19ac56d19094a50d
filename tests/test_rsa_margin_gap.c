/* SPDX-License-Identifier: Apache-2.0 */
/* --margin and --gap of the random packer (issue 31), by brute force on
 * exact analytic containers: every sphere keeps the margin from the wall
 * (its surface with fit inside, its centre with fit center) and every pair
 * the gap between surfaces; with grow the gap is reached (the limit is not
 * merely kept far off); a maximal pass leaves no probe centre with room
 * for one more sphere under the same rule, where one without a gap would
 * place more; vp_check_particles with the same margin and gap finds no
 * violation, and with 1 % more finds one; a gap not below the radius is
 * refused. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "vp_test.h"

static vp_context *ctx;

/* Signed room to the wall at x: box of half side h or sphere of radius h. */
static double wall_dist(int sphere, double h, const double x[3]) {
    if (sphere) return h - sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    double d = HUGE_VAL;
    for (int k = 0; k < 3; k++) d = fmin(d, h - fabs(x[k]));
    return d;
}

static double min_gap(const vp_particles *p) {
    double best = HUGE_VAL;
    for (size_t i = 0; i < p->count; i++)
        for (size_t j = i + 1; j < p->count; j++) {
            const double *a = p->positions + 3 * i, *b = p->positions + 3 * j;
            double d = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                            (a[2] - b[2]) * (a[2] - b[2]));
            best = fmin(best, d - p->radii[i] - p->radii[j]);
        }
    return best;
}

static double min_wall(const vp_particles *p, int sphere, double h, vp_fit fit) {
    double best = HUGE_VAL;
    for (size_t i = 0; i < p->count; i++)
        best = fmin(best, wall_dist(sphere, h, p->positions + 3 * i) -
                              (fit == VP_FIT_INSIDE ? p->radii[i] : 0.0));
    return best;
}

static vp_result pack(const vp_container *c, const char *law, size_t count, int grow, vp_fit fit,
                      double margin, double gap, vp_particles **p) {
    vp_rsa_pass ps;
    vp_rsa_pass_init(&ps);
    ps.maximal = count == 0;
    ps.count = count;
    ps.grow = grow;
    ASSERT_OK(ctx, vp_size_dist_parse(ctx, law, &ps.radius));
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.passes = &ps;
    rp.npasses = 1;
    rp.fit = fit;
    rp.seed = 3;
    rp.margin = margin;
    rp.gap = gap;
    return vp_pack_rsa(ctx, c, &rp, p, NULL);
}

static void check_with(const vp_container *c, const vp_particles *p, vp_fit fit, double margin,
                       double gap, size_t *pairs, size_t *outside) {
    vp_check_params cp;
    vp_check_params_init(&cp);
    cp.fit = fit;
    cp.margin = margin;
    cp.gap = gap;
    vp_check_report rep;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &rep));
    *pairs = rep.overlapping_pairs;
    *outside = rep.outside;
}

static void run_case(int sphere, vp_fit fit, const char *law, size_t count, int grow) {
    const double h = 0.5, margin = 0.07, gap = 0.012;
    vp_container *c = NULL;
    double ctr[3] = {0, 0, 0}, lo[3] = {-h, -h, -h}, hi[3] = {h, h, h};
    ASSERT_OK(ctx, sphere ? vp_container_create_sphere(ctx, ctr, h, &c)
                          : vp_container_create_box(ctx, lo, hi, &c));
    vp_particles *p = NULL;
    ASSERT_OK(ctx, pack(c, law, count, grow, fit, margin, gap, &p));
    double g = min_gap(p), w = min_wall(p, sphere, h, fit);
    /* (radii are floats: a relative 1e-6 of them) */
    double tol = 1e-6 * 0.1;
    size_t pairs, outside, pairs2, outside2;
    check_with(c, p, fit, margin, gap, &pairs, &outside);
    check_with(c, p, fit, 1.01 * margin, 1.01 * gap, &pairs2, &outside2);
    fprintf(stderr,
            "   %s fit %s %s %s%s: %zu spheres; smallest gap %.7f (asked %.3f), smallest "
            "wall distance %.7f (asked %.3f); check: %zu pairs, %zu outside; with 1 %% "
            "more: %zu, %zu\n",
            sphere ? "sphere" : "box", fit == VP_FIT_INSIDE ? "inside" : "center", law,
            count ? "count" : "max", grow ? " grow" : "", p->count, g, gap, w, margin, pairs,
            outside, pairs2, outside2);
    ASSERT_GE(g, gap - tol);
    ASSERT_GE(w, margin - tol);
    ASSERT_EQ_INT(pairs, 0);
    ASSERT_EQ_INT(outside, 0);
    if (grow) ASSERT_LE(g, gap * 1.001); /* grown until the gap: some pair reaches it */
    if (!count) {
        /* maximal: no probe centre has room under the same rule */
        ASSERT_TRUE(pairs2 + outside2 > 0);
        vp_size_dist d;
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, law, &d));
        double rmin = (float)vp_size_dist_min(&d);
        uint64_t st = 77;
        size_t adm = 0, fr = 0;
        for (int k = 0; k < 40000; k++) {
            double x[3];
            for (int m = 0; m < 3; m++) x[m] = h * (2 * vp_rng_uniform(&st) - 1);
            if (wall_dist(sphere, h, x) - (fit == VP_FIT_INSIDE ? rmin : 0.0) < margin) continue;
            adm++;
            double room = HUGE_VAL;
            for (size_t i = 0; i < p->count; i++) {
                const double *q = p->positions + 3 * i;
                double dx = x[0] - q[0], dy = x[1] - q[1], dz = x[2] - q[2];
                room = fmin(room, sqrt(dx * dx + dy * dy + dz * dz) - p->radii[i] - gap);
            }
            fr += room >= rmin;
        }
        fprintf(stderr, "     probes: %zu admissible with the margin, %zu with room\n", adm, fr);
        ASSERT_GE(adm, 5000);
        ASSERT_EQ_INT(fr, 0);
        /* the same pass without the gap and margin places more */
        vp_particles *q = NULL;
        ASSERT_OK(ctx, pack(c, law, 0, 0, fit, 0.0, 0.0, &q));
        ASSERT_GE(q->count, p->count + 1);
        vp_particles_destroy(q);
    }
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

static void test_margin_gap(void) {
    run_case(0, VP_FIT_INSIDE, "0.04", 300, 0);
    run_case(0, VP_FIT_INSIDE, "0.04", 200, 1);
    run_case(1, VP_FIT_INSIDE, "uniform:0.03:0.05", 200, 1);
    run_case(0, VP_FIT_CENTER, "0.04", 200, 1);
    run_case(0, VP_FIT_INSIDE, "0.04", 0, 0);
    run_case(1, VP_FIT_CENTER, "uniform:0.03:0.05", 0, 0);
}

static void test_refused(void) {
    double lo[3] = {-0.5, -0.5, -0.5}, hi[3] = {0.5, 0.5, 0.5};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, hi, &c));
    vp_particles *p = NULL;
    ASSERT_EQ_INT(pack(c, "0.04", 10, 0, VP_FIT_INSIDE, 0.0, 0.04, &p), VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "smaller than the smallest radius") != NULL);
    ASSERT_EQ_INT(pack(c, "0.04", 10, 0, VP_FIT_INSIDE, -0.1, 0.0, &p), VP_ERR_INVALID_ARGUMENT);
    ASSERT_EQ_INT(pack(c, "0.04", 10, 0, VP_FIT_INSIDE, NAN, 0.0, &p), VP_ERR_INVALID_ARGUMENT);
    /* a margin past the inradius: no room, said so */
    ASSERT_EQ_INT(pack(c, "0.04", 10, 0, VP_FIT_INSIDE, 0.47, 0.0, &p), VP_ERR_NO_FIT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "margin") != NULL);
    ASSERT_TRUE(p == NULL);
    vp_container_destroy(c);
}

int main(void) {
    ASSERT_OK(NULL, vp_context_create(&ctx));
    RUN_TEST(test_margin_gap);
    RUN_TEST(test_refused);
    vp_context_destroy(ctx);
    fprintf(stderr, "PASS\n");
    return 0;
}
