/* SPDX-License-Identifier: Apache-2.0 */
/* The coarse depth map of a level-set container (see depth_map.h).
 *
 * Why the bound holds. Let x lie in a block whose nearest leaf block is k
 * >= 2 blocks away (Chebyshev), so every voxel of every leaf is at least
 * 8 (k - 1) voxels from x. In a narrow-band level set every voxel whose
 * distance magnitude is below the band B is active, and active voxels live
 * in leaves. On the segment from x to its closest surface point s the
 * distance magnitude falls linearly to 0, so the segment holds a point p
 * at |d| = B - 1 voxel; p's nearest voxel (within 0.87 voxel) has |d| < B,
 * lies in a leaf, and therefore |x - p| >= 8 (k - 1) - 0.87 voxels. Hence
 * |d(x)| = |x - p| + |p - s| >= B + 8 (k - 1) - 2 voxels =: D.
 * The packers test the trilinear sample, not d: each of the 8 corners is
 * within sqrt(3) voxels of the sample point y and stores max(d, -B) inside
 * (min(d, B) outside), so sample(y) <= max(d(y) + 1.75 voxels, -B), and
 * d(y) <= -D + |y - x|. With b = -D + 1.75 voxels this is the bound of
 * depth_map.h; outside it is mirrored. A block is only decided when its 26
 * neighbours are tiles of the same sign (a well-formed level set has no
 * sign change without a leaf, but a file may be anything). */
#include "core/depth_map.h"

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

void vp_depth_map_free(vp_depth_map *m) {
    if (!m) return;
    free(m->bound);
    memset(m, 0, sizeof *m);
}

int vp_depth_map_build(vp_depth_map *m, const double origin[3], double block, double voxel,
                       const int64_t dims[3], float *value, double in_band, double ex_band) {
    memset(m, 0, sizeof *m);
    const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
    if (!value || nx <= 0 || ny <= 0 || nz <= 0 || !(block > 0) || !(voxel > 0)) {
        free(value);
        return -1;
    }
    /* Work on a copy padded by one block on every side, so that neighbour
     * reads need no bounds checks: k (Chebyshev distance in blocks to the
     * nearest leaf block; the padding is never a leaf) and the sign of
     * each block (+1/-1 tiles, 0 leaf or zero tile; the padding matches
     * any sign, as blocks outside the grid were never looked at). */
    const int64_t px = nx + 2, py = ny + 2, pz = nz + 2;
    const size_t pn = (size_t)px * (size_t)py * (size_t)pz;
    uint16_t *k = malloc(pn * sizeof *k);
    int8_t *sg = malloc(pn);
    if (!k || !sg) {
        free(k);
        free(sg);
        free(value);
        return -1;
    }
    for (size_t i = 0; i < pn; i++) {
        k[i] = UINT16_MAX;
        sg[i] = 2; /* padding */
    }
#define PAD(x, y, z) ((size_t)((((z) + 1) * py + ((y) + 1)) * px + ((x) + 1)))
    for (int64_t z = 0; z < nz; z++)
        for (int64_t y = 0; y < ny; y++)
            for (int64_t x = 0; x < nx; x++) {
                float t = value[(size_t)((z * ny + y) * nx + x)];
                size_t i = PAD(x, y, z);
                if (isnan(t)) k[i] = 0;
                sg[i] = isnan(t) || t == 0.0f ? 0 : t < 0 ? -1 : 1;
            }
    /* neighbour offsets in the padded grid: the 13 before a block in
     * raster order (the forward pass reads these; the backward pass reads
     * their negatives) */
    ptrdiff_t half[13];
    int nh = 0;
    for (int dz = -1; dz <= 0; dz++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                if (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0))) continue;
                half[nh++] = (ptrdiff_t)((dz * py + dy) * px + dx);
            }
    /* a two-pass chamfer with unit weights over the 26-neighbourhood is
     * exact for the Chebyshev distance */
    for (int pass = 0; pass < 2; pass++) {
        ptrdiff_t sgn = pass ? -1 : 1;
        for (int64_t zz = 0; zz < nz; zz++) {
            int64_t z = pass ? nz - 1 - zz : zz;
            for (int64_t yy = 0; yy < ny; yy++) {
                int64_t y = pass ? ny - 1 - yy : yy;
                for (int64_t xx = 0; xx < nx; xx++) {
                    int64_t x = pass ? nx - 1 - xx : xx;
                    size_t i = PAD(x, y, z);
                    unsigned best = k[i];
                    if (best == 0) continue;
                    for (int h = 0; h < 13; h++) {
                        unsigned v = k[(size_t)((ptrdiff_t)i + sgn * half[h])] + 1u;
                        if (v < best) best = v;
                    }
                    k[i] = (uint16_t)best;
                }
            }
        }
    }
    /* decided: k >= 2 and all 26 neighbours tiles of the same sign */
    for (int64_t z = 0; z < nz; z++)
        for (int64_t y = 0; y < ny; y++)
            for (int64_t x = 0; x < nx; x++) {
                size_t i = PAD(x, y, z);
                if (k[i] < 2 || sg[i] == 0) {
                    k[i] = 0;
                    continue;
                }
                int same = 1;
                for (int h = 0; h < 13 && same; h++) {
                    int8_t u = sg[(size_t)((ptrdiff_t)i + half[h])],
                           w = sg[(size_t)((ptrdiff_t)i - half[h])];
                    if ((u != 2 && u != sg[i]) || (w != 2 && w != sg[i])) same = 0;
                }
                if (!same) k[i] = 0;
            }
    free(sg);
    size_t decided = 0;
    for (int64_t z = 0; z < nz; z++)
        for (int64_t y = 0; y < ny; y++)
            for (int64_t x = 0; x < nx; x++) {
                size_t i = (size_t)((z * ny + y) * nx + x);
                unsigned kk = k[PAD(x, y, z)];
                if (kk == 0) {
                    value[i] = NAN;
                    continue;
                }
                double t = value[i];
                double band = t < 0 ? fmin(-t, in_band) : fmin(t, ex_band);
                double d = band + 8.0 * voxel * (double)(kk - 1) - 2.0 * voxel - 1.75 * voxel;
                if (!(d > 0)) {
                    value[i] = NAN;
                    continue;
                }
                /* float must not overstate the depth */
                float f = (float)d;
                if ((double)f > d) f = nextafterf(f, 0.0f);
                value[i] = t < 0 ? -f : f;
                decided++;
            }
#undef PAD
    free(k);
    memcpy(m->origin, origin, sizeof m->origin);
    m->inv_block = 1.0 / block;
    memcpy(m->dims, dims, sizeof m->dims);
    m->bound = value;
    m->decided = decided;
    return 0;
}
