/* SPDX-License-Identifier: Apache-2.0 */
/* Relaxation through the public API on exact analytic containers,
 * verified by brute force: overlap bound, inside, radius scale, margin and
 * gap. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "random_util.h"
#include "vp_test.h"

static void test_relax(void) {
    double ctr[3] = {0, 0, 0};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, ctr, 1.0, &c));
    vp_relax_params xp;
    vp_relax_params_init(&xp);
    ASSERT_OK(ctx, vp_size_dist_parse(ctx, "uniform:0.5:1", &xp.radius));
    xp.count = 1500;
    xp.target_fraction = 0.55;
    xp.seed = 8;
    vp_particles *p = NULL;
    vp_relax_report rep;
    ASSERT_OK(ctx, vp_pack_relax(ctx, c, &xp, &p, &rep));
    double wo = worst_overlap(p), ww = -HUGE_VAL;
    for (size_t i = 0; i < p->count; i++) {
        const double *x = p->positions + 3 * i;
        double v = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) + rad(p, i) - 1.0;
        if (v > ww) ww = v;
    }
    double frac = vp_particles_volume(p) / (4.0 / 3.0 * M_PI);
    fprintf(stderr,
            "   relax: %d sweeps, worst overlap %.3g (reported %.3g), worst wall %.3g, "
            "fraction %.4f (%.4f before), radius scale %.4f\n",
            rep.sweeps, wo, rep.max_overlap, ww, frac, rep.initial_fraction, rep.radius_scale);
    ASSERT_LE(wo, 1e-6);
    ASSERT_LE(rep.max_overlap, 1e-6);
    ASSERT_LE(ww, 1e-12);
    ASSERT_NEAR(rep.initial_fraction, 0.55, 1e-9);
    ASSERT_TRUE(rep.radius_scale > 0.9 && rep.radius_scale <= 1.0);
    ASSERT_NEAR(frac, 0.55 * pow(rep.radius_scale, 3), 1e-4);
    vp_particles_destroy(p);
    /* centre fit: no centre outside, no overlap (a radius step alone cannot
     * bring a centre back: this caught that) */
    xp.fit = VP_FIT_CENTER;
    vp_size_dist_constant(&xp.radius, 0.1);
    xp.count = 600;
    xp.target_fraction = 0.6;
    ASSERT_OK(ctx, vp_pack_relax(ctx, c, &xp, &p, &rep));
    double cw = -HUGE_VAL;
    for (size_t i = 0; i < p->count; i++) {
        const double *x = p->positions + 3 * i;
        double v = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - 1.0;
        if (v > cw) cw = v;
    }
    fprintf(stderr, "   relax, centre fit: worst centre %.3g outside, worst overlap %.3g\n", cw,
            worst_overlap(p));
    ASSERT_LE(cw, 1e-12);
    ASSERT_LE(worst_overlap(p), 1e-6);
    vp_particles_destroy(p);
    xp.fit = VP_FIT_INSIDE;
    /* more volume than any packing can hold: refused */
    xp.target_fraction = 0;
    vp_size_dist_constant(&xp.radius, 0.5);
    xp.count = 100;
    ASSERT_EQ_INT(vp_pack_relax(ctx, c, &xp, &p, &rep), VP_ERR_NO_FIT);
    ASSERT_TRUE(p == NULL);
    xp.target_fraction = 1.0;
    ASSERT_EQ_INT(vp_pack_relax(ctx, c, &xp, &p, &rep), VP_ERR_INVALID_ARGUMENT);
    vp_container_destroy(c);
}

/* Relax with a margin and a gap: brute force over pairs and the analytic
 * wall finds both kept, for both fits; a gap as large as the radii and a
 * negative margin are refused. */
static void test_relax_margin_gap(void) {
    double ctr[3] = {0, 0, 0};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, ctr, 1.0, &c));
    for (int f = 0; f < 2; f++) {
        vp_relax_params xp;
        vp_relax_params_init(&xp);
        xp.fit = f ? VP_FIT_CENTER : VP_FIT_INSIDE;
        vp_size_dist_constant(&xp.radius, 0.08);
        xp.count = 800;
        xp.target_fraction = 0.45;
        xp.seed = 5;
        xp.margin = 0.06;
        xp.gap = 0.012;
        vp_particles *p = NULL;
        vp_relax_report rep;
        ASSERT_OK(ctx, vp_pack_relax(ctx, c, &xp, &p, &rep));
        double least_gap = HUGE_VAL, least_margin = HUGE_VAL;
        for (size_t i = 0; i < p->count; i++) {
            const double *x = p->positions + 3 * i;
            double d = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - 1.0;
            least_margin = fmin(least_margin, f ? -d : -d - rad(p, i));
            for (size_t j = i + 1; j < p->count; j++) {
                const double *y = p->positions + 3 * j;
                double e = sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                                (x[2] - y[2]) * (x[2] - y[2]));
                least_gap = fmin(least_gap, e - rad(p, i) - rad(p, j));
            }
        }
        fprintf(stderr,
                "   relax, fit %s, margin 0.06, gap 0.012: least margin %.9g, least gap "
                "%.9g, radius scale %.4f, %d sweeps\n",
                f ? "center" : "inside", least_margin, least_gap, rep.radius_scale, rep.sweeps);
        ASSERT_TRUE(least_margin >= 0.06 * (1 - 1e-9));
        ASSERT_TRUE(least_gap >= 0.012 * (1 - 1e-6));
        ASSERT_TRUE(least_gap < 0.012 * 1.05); /* some pair at the gap: it shaped the packing */
        vp_particles_destroy(p);
    }
    vp_relax_params xp;
    vp_relax_params_init(&xp);
    vp_size_dist_constant(&xp.radius, 0.08);
    xp.count = 100;
    xp.gap = 0.08;
    vp_particles *p = NULL;
    ASSERT_EQ_INT(vp_pack_relax(ctx, c, &xp, &p, NULL), VP_ERR_INVALID_ARGUMENT);
    xp.gap = 0;
    xp.margin = -1;
    ASSERT_EQ_INT(vp_pack_relax(ctx, c, &xp, &p, NULL), VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(p == NULL);
    vp_container_destroy(c);
}

int main(void) {
    ASSERT_OK(NULL, vp_context_create(&ctx));
    RUN_TEST(test_relax);
    RUN_TEST(test_relax_margin_gap);
    vp_context_destroy(ctx);
    fprintf(stderr, "PASS\n");
    return 0;
}
