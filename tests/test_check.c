/* SPDX-License-Identifier: Apache-2.0 */
/* vp_check_particles on packings with known overlaps, outsiders and
 * contacts, spheres and cubes. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "random_util.h"
#include "vp_test.h"

static void test_check_known_cases(void) {
    vp_container *c = unit_box();
    vp_particles *p = NULL;
    ASSERT_OK(ctx, vp_particles_create(ctx, 4, &p));
    p->radii = malloc(4 * sizeof(float));
    p->count = 4;
    double pos[4][3] = {{-0.2, 0, 0}, {0.0, 0, 0}, {0.3, 0, 0}, {0, 0.45, 0}};
    float r[4] = {0.1f, 0.1f, 0.1f, 0.1f};
    memcpy(p->positions, pos, sizeof pos);
    memcpy(p->radii, r, sizeof r);
    /* 0-1 touch exactly (d = 0.2); 1-2 gap 0.1; 3 crosses the wall by 0.05 */
    vp_check_report rep;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, NULL, &rep));
    ASSERT_EQ_INT(rep.overlapping_pairs, 0);
    ASSERT_EQ_INT(rep.contact_pairs, 1);
    ASSERT_EQ_INT(rep.outside, 1);
    ASSERT_NEAR(rep.max_outside, 0.05, 1e-7);
    ASSERT_NEAR(rep.mean_contacts, 0.5, 1e-12);
    ASSERT_NEAR(rep.fraction, 4 * 4.0 / 3.0 * M_PI * pow(0.1f, 3), 1e-9);
    /* centre fit: 3 is inside */
    vp_check_params cp;
    vp_check_params_init(&cp);
    cp.fit = VP_FIT_CENTER;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &rep));
    ASSERT_EQ_INT(rep.outside, 0);
    /* overlap 1 and 2 by 0.02 of r_i + r_j */
    p->positions[6] = 0.2 * (1 - 0.02);
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, NULL, &rep));
    ASSERT_EQ_INT(rep.overlapping_pairs, 1);
    ASSERT_NEAR(rep.max_overlap, 0.02, 1e-6);
    ASSERT_NEAR(rep.max_overlap_world, 0.004, 1e-7);
    cp.fit = VP_FIT_INSIDE;
    cp.overlap_tolerance = 0.03;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &rep));
    ASSERT_EQ_INT(rep.overlapping_pairs, 0);
    /* cubes: face to face touching is no overlap; turned 45 degrees about z,
     * the second one's edge enters the first */
    p->shape = VP_SHAPE_CUBE;
    p->has_orient = 1;
    double s = 0.1, half = s / sqrt(3.0); /* circumradius 0.1: half edge 0.1/sqrt(3) */
    double cpos[4][3] = {{0, 0, 0}, {2 * half, 0, 0}, {-0.3, -0.3, -0.3}, {0.3, 0.3, 0.3}};
    memcpy(p->positions, cpos, sizeof cpos);
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, NULL, &rep));
    ASSERT_EQ_INT(rep.overlapping_pairs, 0);
    ASSERT_EQ_INT(rep.contact_pairs, 1);
    ASSERT_EQ_INT(rep.outside, 0);
    p->orients = malloc(16 * sizeof(float));
    for (int i = 0; i < 4; i++) {
        float q[4] = {0, 0, 0, 1};
        if (i == 1) q[2] = (float)sin(M_PI / 8), q[3] = (float)cos(M_PI / 8);
        memcpy(p->orients + 4 * i, q, sizeof q);
    }
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, NULL, &rep));
    fprintf(stderr, "   turned cube: overlap %.4f of the radius\n", rep.max_overlap);
    ASSERT_EQ_INT(rep.overlapping_pairs, 1);
    /* penetration: the edge reaches half * sqrt(2) - half beyond the face */
    ASSERT_NEAR(rep.max_overlap_world, half * (sqrt(2.0) - 1), 1e-6);
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

int main(void) {
    ASSERT_OK(NULL, vp_context_create(&ctx));
    RUN_TEST(test_check_known_cases);
    vp_context_destroy(ctx);
    fprintf(stderr, "PASS\n");
    return 0;
}
