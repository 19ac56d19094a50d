/* SPDX-License-Identifier: Apache-2.0 */
/* A coarse map of where a level-set container's sampled distance is known
 * without sampling: per block of 8^3 voxels, a bound that holds for every
 * point near the block, or NaN ("sample it"). It carries depth information
 * past the narrow band: a block k >= 2 blocks (Chebyshev) from every leaf
 * node lies at least band + 8 (k - 1) voxels from the surface, because
 * every point closer to the surface than the band lies in a leaf (see
 * depth_map.c). The lattice packer's placement search uses it to classify
 * the bulk of the lattice without touching the level set, which lets the
 * interior band be as narrow as the particle radius.
 *
 * Semantics of a finite bound b of the block holding point x, for a point y
 * with |y - x| <= s and a threshold t with -interior band <= t < exterior
 * band (every fit threshold is):
 *   b < 0: sampled distance at y <= t whenever b + s <= t;
 *   b > 0: sampled distance at y >  t whenever b - s >  t.
 *
 * Ownership: the map owns bound (vp_depth_map_free). Read-only after
 * construction, so lookups may run from several threads. */
#ifndef VDBPACK_CORE_DEPTH_MAP_H
#define VDBPACK_CORE_DEPTH_MAP_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

typedef struct vp_depth_map {
    double origin[3]; /* world position of block (0,0,0)'s low corner */
    double inv_block; /* 1 / block edge (world) */
    int64_t dims[3];
    float *bound;   /* dims[0]*dims[1]*dims[2], x fastest; NULL: no map */
    size_t decided; /* blocks with a finite bound */
} vp_depth_map;

/* Builds the map from the level set's block footprint: value[i] NaN for a
 * block holding a leaf node, else its tile value (negative inside). Takes
 * ownership of value (malloc'd; it becomes m->bound, or is freed on
 * failure). in_band / ex_band: the grid's interior and exterior band
 * (world); voxel: voxel edge (world). Returns 0, or -1 out of memory (m
 * then empty). */
int vp_depth_map_build(vp_depth_map *m, const double origin[3], double block, double voxel,
                       const int64_t dims[3], float *value, double in_band, double ex_band);
void vp_depth_map_free(vp_depth_map *m);

/* The bound of the block holding x; NaN without a map, outside it, or
 * where the level set must be sampled. */
static inline double vp_depth_map_at(const vp_depth_map *m, const double x[3]) {
    if (!m || !m->bound) return NAN;
    int64_t i[3];
    for (int a = 0; a < 3; a++) {
        double t = (x[a] - m->origin[a]) * m->inv_block;
        if (!(t >= 0.0) || !(t < (double)m->dims[a])) return NAN;
        i[a] = (int64_t)t;
    }
    return (double)m->bound[(i[2] * m->dims[1] + i[1]) * m->dims[0] + i[0]];
}
#endif
