/* SPDX-License-Identifier: Apache-2.0 */
/* The random draws of the packers: uniform rotations (moments on the
 * 3-sphere) and size distributions (sample moments of each law). */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "core/size_dist_sample.h"
#include "random_util.h"
#include "vp_test.h"

/* vp_rng_quat is uniform on the 3-sphere: unit length, and the moments of
 * the uniform law, E[q_i^2] = 1/4, E[q_i^4] = 1/8, E[q_i^2 q_j^2] = 1/24
 * and E[q_i] = 0, within 5 standard errors over 400 000 draws. */
static void test_rng_quat(void) {
    const int n = 400000;
    double m1[4] = {0}, m2[4] = {0}, m4[4] = {0}, m22 = 0;
    uint64_t st = vp_rng_stream(7, 3);
    for (int k = 0; k < n; k++) {
        double q[4];
        vp_rng_quat(&st, q);
        ASSERT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1.0, 1e-12);
        for (int i = 0; i < 4; i++) {
            m1[i] += q[i];
            m2[i] += q[i] * q[i];
            m4[i] += q[i] * q[i] * q[i] * q[i];
        }
        m22 += q[0] * q[0] * q[3] * q[3];
    }
    /* standard deviations of one draw: q_i 1/2, q_i^2 sqrt(1/8 - 1/16),
     * q_i^4 sqrt(E q^8 - 1/64) with E q^8 = 105/(4 6 8 10) = 7/128,
     * q_0^2 q_3^2 at most 1/4 */
    double se = 1.0 / sqrt((double)n);
    for (int i = 0; i < 4; i++) {
        ASSERT_NEAR(m1[i] / n, 0.0, 5 * 0.5 * se);
        ASSERT_NEAR(m2[i] / n, 0.25, 5 * sqrt(1.0 / 16) * se);
        ASSERT_NEAR(m4[i] / n, 0.125, 5 * sqrt(7.0 / 128 - 1.0 / 64) * se);
    }
    ASSERT_NEAR(m22 / n, 1.0 / 24, 5 * 0.25 * se);
    fprintf(stderr,
            "   E q^2 %.4f %.4f %.4f %.4f (1/4), E q^4 %.4f (1/8), E q0^2 q3^2 %.4f (1/24)\n",
            m2[0] / n, m2[1] / n, m2[2] / n, m2[3] / n, m4[0] / n, m22 / n);
}

static void test_size_dist(void) {
    const char *specs[] = {"0.25", "uniform:0.1:0.3", "lognormal:0.2:0.05", "list:0.1:0.2:0.6"};
    for (int s = 0; s < 4; s++) {
        vp_size_dist d;
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, specs[s], &d));
        uint64_t st = 12345;
        double m1 = 0, m3 = 0, lo = HUGE_VAL, hi = 0;
        const int n = 400000;
        double sum2 = 0;
        for (int i = 0; i < n; i++) {
            double r = vp_size_dist_sample(&d, &st);
            m1 += r;
            sum2 += r * r;
            m3 += r * r * r;
            if (r < lo) lo = r;
            if (r > hi) hi = r;
        }
        m1 /= n;
        m3 /= n;
        double sd = sqrt(sum2 / n - m1 * m1);
        fprintf(stderr,
                "   %s: mean %.5f (expected %.5f), E[r^3] %.6f (%.6f), sd %.5f, range "
                "[%.4f, %.4f]\n",
                specs[s], m1, vp_size_dist_mean(&d), m3, vp_size_dist_mean_cube(&d), sd, lo, hi);
        ASSERT_NEAR(m1, vp_size_dist_mean(&d), 0.005 * vp_size_dist_mean(&d));
        ASSERT_NEAR(m3, vp_size_dist_mean_cube(&d), 0.01 * vp_size_dist_mean_cube(&d));
        ASSERT_GE(lo, vp_size_dist_min(&d));
        ASSERT_LE(hi, vp_size_dist_max(&d));
        if (s == 1) ASSERT_NEAR(sd, 0.2 / sqrt(12.0), 0.002); /* uniform */
        if (s == 2) ASSERT_NEAR(sd, 0.05, 0.05 * 0.03);       /* lognormal SD */
        if (s == 3) ASSERT_NEAR(m1, 0.3, 0.003);
    }
    /* formatted as written (shortest text that reads back exactly), and
     * parsed back to the same values */
    const char *fmt[] = {"0.004493",
                         "uniform:0.1:0.3",
                         "lognormal:0.2:0.05",
                         "list:0.1:0.2:0.6",
                         "0.1000000000000000055511151231257827",
                         "1e-30"};
    const char *want[] = {
        "0.004493", "uniform:0.1:0.3", "lognormal:0.2:0.05", "list:0.1:0.2:0.6", "0.1", "1e-30"};
    for (int s = 0; s < 6; s++) {
        vp_size_dist d, e;
        char buf[256];
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, fmt[s], &d));
        vp_size_dist_format(&d, buf, sizeof buf);
        fprintf(stderr, "   format(%s) = %s\n", fmt[s], buf);
        ASSERT_TRUE(!strcmp(buf, want[s]));
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, buf, &e));
        ASSERT_TRUE(e.kind == d.kind && e.a == d.a && e.b == d.b && e.n == d.n);
        for (unsigned i = 0; i < d.n; i++) ASSERT_TRUE(e.values[i] == d.values[i]);
    }
    { /* radii are stored as float: every size a law draws must be a normal float */
        vp_size_dist d;
        const char *ok[] = {"1.2e-38", "3.4e38", "uniform:1.2e-38:1", "lognormal:1:0.5"};
        const char *no[] = {"1e-38",           "1e-300",       "3.5e38",
                            "uniform:1e-39:1", "list:1:1e-40", "lognormal:1e-37:1e-36",
                            "uniform:1:1e39"};
        for (int i = 0; i < 4; i++) ASSERT_OK(ctx, vp_size_dist_parse(ctx, ok[i], &d));
        for (int i = 0; i < 7; i++) {
            ASSERT_EQ_INT(vp_size_dist_parse(ctx, no[i], &d), VP_ERR_INVALID_ARGUMENT);
            ASSERT_TRUE(strstr(vp_context_message(ctx), "float") != NULL);
        }
    }
    { /* a value that needs 17 digits keeps them */
        vp_size_dist d, e;
        char buf[64];
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, "0.30000000000000004", &d));
        vp_size_dist_format(&d, buf, sizeof buf);
        ASSERT_TRUE(!strcmp(buf, "0.30000000000000004"));
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, buf, &e));
        ASSERT_TRUE(e.a == d.a);
    }
    const char *bad[] = {
        "-1",    "0",   "uniform:0.3:0.1", "gamma:1:2", "lognormal:0.1", "list:", "uniform:0.1:nan",
        "1e400", "0.1x"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        vp_size_dist d;
        ASSERT_EQ_INT(vp_size_dist_parse(ctx, bad[i], &d), VP_ERR_INVALID_ARGUMENT);
        ASSERT_TRUE(strlen(vp_context_message(ctx)) > 0);
    }
}

int main(void) {
    ASSERT_OK(NULL, vp_context_create(&ctx));
    RUN_TEST(test_rng_quat);
    RUN_TEST(test_size_dist);
    vp_context_destroy(ctx);
    fprintf(stderr, "PASS\n");
    return 0;
}
