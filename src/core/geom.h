/* SPDX-License-Identifier: Apache-2.0 */
/* Small vector and quaternion helpers and constants shared by the C core (header-only).
 * Quaternions are (x, y, z, w), as OpenVDB's math::Quat and Houdini's
 * orient store them. */
#ifndef VDBPACK_CORE_GEOM_H
#define VDBPACK_CORE_GEOM_H

#include <math.h>

#define VP_KEPLER 0.74048048969306104 /* densest packing of equal spheres: pi / sqrt 18 */

static inline double vp_dot3(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void vp_cross3(const double a[3], const double b[3], double out[3]) {
    double x = a[1] * b[2] - a[2] * b[1];
    double y = a[2] * b[0] - a[0] * b[2];
    double z = a[0] * b[1] - a[1] * b[0];
    out[0] = x;
    out[1] = y;
    out[2] = z;
}
static inline double vp_norm3(const double a[3]) { return sqrt(vp_dot3(a, a)); }
static inline double vp_det3(const double a[3], const double b[3], const double c[3]) {
    double t[3];
    vp_cross3(b, c, t);
    return vp_dot3(a, t);
}
/* Rotates v by unit quaternion q = (x,y,z,w). */
static inline void vp_quat_rotate(const double q[4], const double v[3], double out[3]) {
    double u[3] = {q[0], q[1], q[2]}, t[3], c[3];
    vp_cross3(u, v, t);
    t[0] *= 2;
    t[1] *= 2;
    t[2] *= 2;
    vp_cross3(u, t, c);
    out[0] = v[0] + q[3] * t[0] + c[0];
    out[1] = v[1] + q[3] * t[1] + c[1];
    out[2] = v[2] + q[3] * t[2] + c[2];
}
/* out = a * b (apply b first, then a). */
static inline void vp_quat_mul(const double a[4], const double b[4], double out[4]) {
    double x = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    double y = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    double z = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    double w = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
    out[0] = x;
    out[1] = y;
    out[2] = z;
    out[3] = w;
}
/* A stored float quaternion as the packers test it and vdbpack check reads
 * it back: widened to double and renormalised (identity if zero). */
static inline void vp_quat_from_float(const float f[4], double q[4]) {
    for (int k = 0; k < 4; k++) q[k] = f[k];
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (n > 0)
        for (int k = 0; k < 4; k++) q[k] /= n;
    else q[0] = q[1] = q[2] = 0, q[3] = 1;
}
/* Rotation matrix (row-major, out[i][j]) of unit quaternion q. */
static inline void vp_quat_to_matrix(const double q[4], double m[3][3]) {
    double x = q[0], y = q[1], z = q[2], w = q[3];
    m[0][0] = 1 - 2 * (y * y + z * z);
    m[0][1] = 2 * (x * y - z * w);
    m[0][2] = 2 * (x * z + y * w);
    m[1][0] = 2 * (x * y + z * w);
    m[1][1] = 1 - 2 * (x * x + z * z);
    m[1][2] = 2 * (y * z - x * w);
    m[2][0] = 2 * (x * z - y * w);
    m[2][1] = 2 * (y * z + x * w);
    m[2][2] = 1 - 2 * (x * x + y * y);
}
#endif
