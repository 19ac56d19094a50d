/* SPDX-License-Identifier: Apache-2.0 */
/* The lattice packer's margin and gap (issue 31, section 4): a simple
 * cubic lattice of spheres in a box, spaced for the gap and kept the margin
 * from the walls, has the count this file works out from the box's side
 * (the corner placement is among the offsets searched), every sphere the
 * margin from the wall and every pair the gap apart (brute force here);
 * cubes keep the margin (every corner, by this file's arithmetic); vdbpack
 * check holds both and flags more; bad values and a gap between solids are
 * refused. */
#include "vdbpack/vdbpack.h"
#include "vp_test.h"

#include <math.h>
#include <string.h>

static void test_sc_spheres_margin_gap(void) {
    vp_context *ctx;
    ASSERT_OK(ctx, vp_context_create(&ctx));
    vp_container *c;
    ASSERT_OK(ctx, vp_container_create_box(ctx, (double[3]){-0.5, -0.5, -0.5},
                                           (double[3]){0.5, 0.5, 0.5}, &c));
    const double r = 0.05, M = 0.03, G = 0.02;
    vp_lattice_params lp;
    vp_lattice_params_init(&lp);
    lp.lattice = VP_LATTICE_SC;
    lp.radius = r;
    lp.margin = M;
    lp.gap = G;
    vp_particles *p;
    vp_lattice_report rep;
    ASSERT_OK(ctx, vp_pack_lattice(ctx, c, &lp, &p, &rep));
    /* centres in [-0.5 + r + M, 0.5 - r - M] per axis, 2r + G apart */
    int n = (int)floor((1.0 - 2.0 * (r + M)) / (2.0 * r + G) + 1e-9) + 1;
    fprintf(stderr, "   %zu spheres (%d per axis expected)\n", p->count, n);
    ASSERT_EQ_INT(p->count, (size_t)n * n * n);
    double wall = HUGE_VAL, gap = HUGE_VAL;
    for (size_t i = 0; i < p->count; i++) {
        const double *x = p->positions + 3 * i;
        for (int k = 0; k < 3; k++) wall = fmin(wall, 0.5 - fabs(x[k]) - r);
        for (size_t j = i + 1; j < p->count; j++) {
            const double *y = p->positions + 3 * j;
            double d = sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                            (x[2] - y[2]) * (x[2] - y[2]));
            gap = fmin(gap, d - 2.0 * r);
        }
    }
    fprintf(stderr, "   least wall distance %.12f (margin %g), least gap %.12f (gap %g)\n", wall,
            M, gap, G);
    ASSERT_NEAR(gap, G, 1e-9);
    ASSERT_GE(wall, M - 1e-9);
    vp_check_params cp;
    vp_check_params_init(&cp);
    cp.margin = M;
    cp.gap = G;
    vp_check_report cr;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &cr));
    ASSERT_EQ_INT(cr.overlapping_pairs, 0);
    ASSERT_EQ_INT(cr.outside, 0);
    cp.gap = 1.5 * G;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &cr));
    ASSERT_GE(cr.overlapping_pairs, 1);
    vp_particles_destroy(p);
    /* without them: the plain lattice, which the margin and gap thin out */
    lp.margin = lp.gap = 0;
    ASSERT_OK(ctx, vp_pack_lattice(ctx, c, &lp, &p, NULL));
    ASSERT_EQ_INT(p->count, 1000);
    vp_particles_destroy(p);
    vp_container_destroy(c);
    vp_context_destroy(ctx);
}

static void test_cubes_margin_and_refusals(void) {
    vp_context *ctx;
    ASSERT_OK(ctx, vp_context_create(&ctx));
    vp_container *c;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, (double[3]){0, 0, 0}, 0.5, &c));
    const double M = 0.04;
    vp_lattice_params lp;
    vp_lattice_params_init(&lp);
    lp.shape = VP_SHAPE_CUBE;
    lp.radius = 0.05;
    lp.margin = M;
    vp_particles *p;
    ASSERT_OK(ctx, vp_pack_lattice(ctx, c, &lp, &p, NULL));
    ASSERT_GE(p->count, 100);
    double least = HUGE_VAL, h = lp.radius / sqrt(3.0);
    const float *q = p->orients ? p->orients : p->uniform_orient;
    for (size_t i = 0; i < p->count; i++) {
        const float *qi = p->orients ? q + 4 * i : q;
        double x = qi[0], y = qi[1], z = qi[2], w = qi[3];
        double m[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                          {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                          {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
        for (int v = 0; v < 8; v++) {
            double u[3] = {v & 1 ? h : -h, v & 2 ? h : -h, v & 4 ? h : -h}, pt[3];
            for (int k = 0; k < 3; k++)
                pt[k] = p->positions[3 * i + k] + m[k][0] * u[0] + m[k][1] * u[1] + m[k][2] * u[2];
            least = fmin(least, 0.5 - sqrt(pt[0] * pt[0] + pt[1] * pt[1] + pt[2] * pt[2]));
        }
    }
    fprintf(stderr, "   %zu cubes, least corner distance to the wall %.9f (margin %g)\n",
            p->count, least, M);
    ASSERT_GE(least, M - 1e-9);
    ASSERT_LE(least, M + 0.1); /* near the wall: the test can fail */
    vp_check_params cp;
    vp_check_params_init(&cp);
    cp.margin = M;
    vp_check_report cr;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &cr));
    ASSERT_EQ_INT(cr.outside, 0);
    cp.margin = least + 0.01;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &cr));
    ASSERT_GE(cr.outside, 1);
    vp_particles_destroy(p);
    /* refused: a gap between cubes, negative or NaN values */
    lp.gap = 0.01;
    p = (vp_particles *)1;
    ASSERT_FAILS(ctx, VP_ERR_INVALID_ARGUMENT, vp_pack_lattice(ctx, c, &lp, &p, NULL));
    ASSERT_TRUE(p == NULL && strstr(vp_context_message(ctx), "gap") != NULL);
    lp.gap = 0;
    lp.margin = -1;
    ASSERT_FAILS(ctx, VP_ERR_INVALID_ARGUMENT, vp_pack_lattice(ctx, c, &lp, &p, NULL));
    lp.margin = NAN;
    ASSERT_FAILS(ctx, VP_ERR_INVALID_ARGUMENT, vp_pack_lattice(ctx, c, &lp, &p, NULL));
    vp_container_destroy(c);
    vp_context_destroy(ctx);
}

int main(void) {
    RUN_TEST(test_sc_spheres_margin_gap);
    RUN_TEST(test_cubes_margin_and_refusals);
    return 0;
}
