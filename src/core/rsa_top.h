/* SPDX-License-Identifier: Apache-2.0 */
/* The "top ball" of an active cell of the RSA packer (docs/rsa.md,
 * "Sampling: active cells", its item "Top ball"): one exclusion ball, among
 * those gathered when the cell was made, that holds much of it. It is stored
 * in 3 bytes as its centre's offset from the cell's centre, rounded per axis
 * to a multiple of a unit u (-127 to 127 units), so that a dart tests it
 * without reading the particle. A dart closer than lim to the rounded centre
 * lies in the ball itself: rounding moves the centre by at most (sqrt 3 / 2)
 * u, taken off the ball's radius together with a margin for the arithmetic.
 * The test only proves failures: a dart it does not settle gets the full
 * neighbour test, so the darts' outcomes are those of the full test.
 *
 * Internal to the packer (and its unit test); all functions are pure. */
#ifndef VP_CORE_RSA_TOP_H
#define VP_CORE_RSA_TOP_H

#include <math.h>
#include <stdint.h>

#define VP_TOP_NONE 0u /* no top ball (no valid encoding has a zero low byte) */

/* The encoding of one level of cells. */
typedef struct vp_top_scale {
    double u;    /* the unit of the offsets */
    double lim2; /* squared radius of the test around the rounded centre (0: never holds) */
} vp_top_scale;

/* For cells of half-diagonal hd and balls whose exclusion radius is at
 * most emax (so that every ball meeting a cell is in range) and at least
 * emin (the radius tested); eps bounds the rounding error of a
 * coordinate difference. */
static inline vp_top_scale vp_top_scale_make(double emin, double emax, double hd, double eps) {
    vp_top_scale t;
    t.u = (emax + hd) / 127.0;
    double lim = emin - 0.5 * sqrt(3.0) * t.u - eps;
    t.lim2 = lim > 0 ? lim * lim : 0.0;
    return t;
}

/* The code of the ball centred at `off` from the cell's centre, or
 * VP_TOP_NONE when out of range (such a ball does not meet the cell). */
static inline uint32_t vp_top_encode(const vp_top_scale *t, const double off[3]) {
    uint32_t code = 0;
    for (int k = 0; k < 3; k++) {
        double q = nearbyint(off[k] / t->u);
        if (!(q >= -127.0 && q <= 127.0)) return VP_TOP_NONE;
        code |= (uint32_t)((int)q + 128) << (8 * k);
    }
    return code;
}

/* 1 when point p (world) is proven inside the ball of `code` of the cell
 * centred at m; 0 when not proven (or no ball). */
static inline int vp_top_holds(const vp_top_scale *t, uint32_t code, const double m[3],
                               const double p[3]) {
    if (code == VP_TOP_NONE) return 0;
    double d2 = 0.0;
    for (int k = 0; k < 3; k++) {
        double c = m[k] + (double)((int)((code >> (8 * k)) & 0xFFu) - 128) * t->u;
        d2 += (p[k] - c) * (p[k] - c);
    }
    return d2 < t->lim2;
}

#endif
