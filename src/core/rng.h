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
/* Uniform random rotation as a unit quaternion (x, y, z, w) (Shoemake). */
static inline void vp_rng_quat(uint64_t *s, double q[4]) {
    double u1 = vp_rng_uniform(s), u2 = vp_rng_uniform(s) * 2 * M_PI,
           u3 = vp_rng_uniform(s) * 2 * M_PI;
    double a = sqrt(1 - u1), b = sqrt(u1);
    q[0] = a * sin(u2); q[1] = a * cos(u2); q[2] = b * sin(u3); q[3] = b * cos(u3);
}
#endif
