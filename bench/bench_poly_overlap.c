/* SPDX-License-Identifier: Apache-2.0 */
/* Cost of one exact overlap test of two solids, SAT (vp_poly_posed_overlap,
 * posed once per pair) against GJK (vp_convex_overlap), on random pairs
 * whose centres are between the inradius and circumradius sums apart: why
 * the packers test the Archimedean solids by GJK (shape.h,
 * vp_shape_overlap_by_gjk). Usage: build/bench/bench_poly_overlap [PAIRS]
 * No pass/fail: figures for docs/lattices.md. */
#include "core/shape.h"
#include "core/superball.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static uint64_t rng = 0x2545F4914F6CDD1Dull;
static double urand(void) {
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}
static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

int main(int argc, char **argv) {
    int n = argc > 1 ? atoi(argv[1]) : 2000;
    if (n < 1) n = 2000;
    double(*q)[4] = malloc(sizeof *q * 2 * n), (*t)[3] = malloc(sizeof *t * n);
    printf("%-28s %5s %10s %10s  %s\n", "solid", "verts", "SAT us", "GJK us",
           "overlapping (SAT/GJK)");
    for (int s = VP_SHAPE_TETRAHEDRON; s < VP_SHAPE_COUNT; s++) {
        const vp_polyhedron *p = vp_shape_polyhedron((vp_shape)s);
        for (int i = 0; i < n; i++) {
            for (int k = 0; k < 2; k++) {
                double l = 0;
                for (int m = 0; m < 4; m++) {
                    q[2 * i + k][m] = 2 * urand() - 1;
                    l += q[2 * i + k][m] * q[2 * i + k][m];
                }
                for (int m = 0; m < 4; m++) q[2 * i + k][m] /= sqrt(l);
            }
            double d[3], l = 0;
            for (int m = 0; m < 3; m++) {
                d[m] = 2 * urand() - 1;
                l += d[m] * d[m];
            }
            double r = 2 * (p->inradius + urand() * (1 - p->inradius));
            for (int m = 0; m < 3; m++) t[i][m] = d[m] / sqrt(l) * r;
        }
        static const double o[3] = {0, 0, 0};
        int sat_ov = 0, gjk_ov = 0;
        double t0 = now();
        for (int i = 0; i < n; i++) {
            vp_poly_posed a, b;
            vp_poly_pose(p, 1, q[2 * i], o, o, &a);
            vp_poly_pose(p, 1, q[2 * i + 1], t[i], o, &b);
            sat_ov += vp_poly_posed_overlap(&a, &b);
        }
        double t1 = now();
        for (int i = 0; i < n; i++) {
            vp_convex a, b;
            vp_convex_set(&a, (vp_shape)s, 0, 1, q[2 * i], o, o);
            vp_convex_set(&b, (vp_shape)s, 0, 1, q[2 * i + 1], t[i], o);
            gjk_ov += vp_convex_overlap(&a, &b);
        }
        double t2 = now();
        printf("%-28s %5d %10.2f %10.2f   %d/%d of %d\n", vp_shape_name((vp_shape)s), p->nverts,
               1e6 * (t1 - t0) / n, 1e6 * (t2 - t1) / n, sat_ov, gjk_ov, n);
    }
    free(q);
    free(t);
    return 0;
}
