/* SPDX-License-Identifier: Apache-2.0 */
/* Deterministic random numbers for the packers (header-only): splitmix64 for
 * seeding and streams, uniform doubles in [0,1), standard normals and
 * uniform random rotations. One state per stream; never global state, so
 * results depend only on the seed, not on threads. */
#ifndef VDBPACK_CORE_RNG_H
#define VDBPACK_CORE_RNG_H

#include <math.h>
#include <stdint.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static inline uint64_t vp_rng_next(uint64_t *s) {
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
/* Uniform in [0, 1). */
static inline double vp_rng_uniform(uint64_t *s) {
    return (double)(vp_rng_next(s) >> 11) * 0x1.0p-53;
}
/* splitmix64 of x alone, as a hash (vp_rng_next from the state x). */
static inline uint64_t vp_rng_mix(uint64_t x) { return vp_rng_next(&x); }
/* Uniform in [0, 1) from a hash chain: *s becomes vp_rng_mix(*s). The
 * renderer's per-pixel streams (src/render/render.c), whose images depend
 * on this very sequence. */
static inline double vp_rng_chain_uniform(uint64_t *s) {
    *s = vp_rng_mix(*s);
    return (double)(*s >> 11) * 0x1.0p-53;
}
/* A seed for sub-stream k of seed (independent streams for chunks/passes). */
static inline uint64_t vp_rng_stream(uint64_t seed, uint64_t k) {
    uint64_t s = seed ^ (0xD1B54A32D192ED03ull * (k + 1));
    return vp_rng_next(&s);
}
/* Standard normal (Box-Muller, one value per call). */
static inline double vp_rng_normal(uint64_t *s) {
    double u1 = vp_rng_uniform(s), u2 = vp_rng_uniform(s);
    return sqrt(-2.0 * log(1.0 - u1)) * cos(2.0 * M_PI * u2);
}
/* Uniform random rotation as a unit quaternion (x, y, z, w): a uniform
 * point of the 3-sphere by Marsaglia's method (Ann. Math. Stat. 43, 1972):
 * (x1, y1) and (x2, y2) uniform in the unit disc (by rejection: 4/pi pairs
 * drawn per point on average), then (x1, y1, x2 t, y2 t) with
 * t = sqrt((1 - s1) / s2), s the squared lengths. No trigonometry: a
 * random-orientation solid pass draws one for most darts, where
 * Shoemake's sin and cos took 5 % of the instructions. */
static inline void vp_rng_quat(uint64_t *s, double q[4]) {
    double x1, y1, s1, x2, y2, s2;
    do {
        x1 = 2.0 * vp_rng_uniform(s) - 1.0;
        y1 = 2.0 * vp_rng_uniform(s) - 1.0;
        s1 = x1 * x1 + y1 * y1;
    } while (s1 >= 1.0);
    do {
        x2 = 2.0 * vp_rng_uniform(s) - 1.0;
        y2 = 2.0 * vp_rng_uniform(s) - 1.0;
        s2 = x2 * x2 + y2 * y2;
    } while (s2 >= 1.0 || s2 == 0.0);
    double t = sqrt((1.0 - s1) / s2);
    q[0] = x1;
    q[1] = y1;
    q[2] = x2 * t;
    q[3] = y2 * t;
}
/* Uniform random rotation by Shoemake's method (three uniforms, sin and
 * cos): the lattice packer's rotation search (src/core/lattice_pack.c),
 * whose orientations depend on this very sequence. */
static inline void vp_rng_quat_shoemake(uint64_t *s, double q[4]) {
    double u1 = vp_rng_uniform(s), u2 = vp_rng_uniform(s) * 2 * M_PI,
           u3 = vp_rng_uniform(s) * 2 * M_PI;
    double a = sqrt(1 - u1), b = sqrt(u1);
    q[0] = a * sin(u2);
    q[1] = a * cos(u2);
    q[2] = b * sin(u3);
    q[3] = b * cos(u3);
}
#endif
