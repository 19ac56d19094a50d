/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of src/core/rsa_top.h, the RSA packer's top-ball test:
 *  - sound: a point it says is in the ball is in the ball (exact centre,
 *    the smallest exclusion radius), for cells and balls of many scales,
 *    points in the cell, on its faces and just outside, and cells far
 *    from the origin, where the margin for the arithmetic matters;
 *  - useful: it holds for every point deeper than the rounding allows
 *    (a test that never held would pass the first check alone);
 *  - every ball that meets the cell is in range; codes are never NONE. */
#include "core/rng.h"
#include "core/rsa_top.h"
#include "vp_test.h"

#include <float.h>
#include <stdint.h>

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double urand(void) { return vp_rng_uniform(&rng_state); }

/* One scale: cells of side a around `where`, balls of exclusion radius in
 * [emin, emax]. */
static void run(double a, double emin, double emax, double where) {
    double hd = 0.5 * sqrt(3.0) * a;
    double eps = 64.0 * DBL_EPSILON * (fabs(where) + 1.0);
    vp_top_scale t = vp_top_scale_make(emin, emax, hd, eps);
    ASSERT_TRUE(t.u > 0 && t.lim2 > 0);
    double delta = 0.5 * sqrt(3.0) * t.u + eps; /* what the test gives up */
    long held = 0, deep = 0;
    for (int trial = 0; trial < 20000; trial++) {
        double m[3], c[3], off[3], dist = 0.0;
        /* a ball meeting the cell: centre within e + hd of the cell's centre */
        double e = emin + (emax - emin) * urand();
        for (int k = 0; k < 3; k++) m[k] = where + a * (urand() - 0.5) * 1000.0;
        do {
            dist = 0.0;
            for (int k = 0; k < 3; k++) {
                off[k] = (2.0 * urand() - 1.0) * (e + hd);
                dist += off[k] * off[k];
            }
        } while (dist >= (e + hd) * (e + hd));
        for (int k = 0; k < 3; k++) c[k] = m[k] + off[k];
        uint32_t code = vp_top_encode(&t, off);
        ASSERT_TRUE(code != VP_TOP_NONE);
        ASSERT_TRUE((code & 0xFFu) != 0); /* NONE is never a code */
        for (int n = 0; n < 16; n++) {
            double p[3], d2 = 0.0;
            for (int k = 0; k < 3; k++) {
                /* in the cell, on its faces (n even: one coordinate on a
                 * face), or up to a fifth of a side beyond them */
                double x = 1.4 * urand() - 0.7;
                if (!(n & 1) && k == n % 3) x = urand() < 0.5 ? -0.5 : 0.5;
                p[k] = m[k] + x * a;
                d2 += (p[k] - c[k]) * (p[k] - c[k]);
            }
            /* the point, seen by the exact test against the smallest radius */
            int in = d2 < emin * emin;
            int h = vp_top_holds(&t, code, m, p);
            if (h) ASSERT_TRUE(in); /* sound */
            held += h;
            if (sqrt(d2) < emin - 2.0 * delta) { /* deep inside: must hold */
                deep++;
                ASSERT_TRUE(h);
            }
        }
    }
    fprintf(stderr, "   a %.3g, e in [%.3g, %.3g] at %.3g: %ld held, %ld deep\n", a, emin, emax,
            where, held, deep);
    ASSERT_TRUE(deep > 1000);
    /* out of range: a ball whose centre is farther than emax + hd on an axis */
    double far[3] = {0.0, (emax + hd) * 1.02, 0.0};
    ASSERT_TRUE(vp_top_encode(&t, far) == VP_TOP_NONE);
    ASSERT_TRUE(!vp_top_holds(&t, VP_TOP_NONE, far, far));
}

int main(void) {
    /* level 1 of a one-radius pass: side 2r / sqrt 3, e = 2r */
    RUN_CASE(level_one, run(2.0 * 0.0043 / sqrt(3.0), 0.0086, 0.0086, 0.0));
    /* deep levels: cells small against the ball */
    RUN_CASE(deep_levels, run(0.0043 / 64.0, 0.0086, 0.0086, 0.3));
    /* several radii (binary packings): e from 2r to 5r */
    RUN_CASE(several_radii, run(0.005, 0.01, 0.025, -0.2));
    /* far from the origin: the rounding margin matters */
    RUN_CASE(far_from_origin, run(0.002, 0.004, 0.004, 5000.0));
    fprintf(stderr, "all rsa_top tests passed\n");
    return 0;
}
