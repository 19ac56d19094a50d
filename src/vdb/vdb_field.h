/* SPDX-License-Identifier: Apache-2.0 */
/* The extern "C" interface of the field sampler (src/vdb/vdb_field.cpp):
 * a float grid read from a .vdb, sampled trilinearly (OpenVDB's
 * BoxSampler). As vdb_bridge.h: no exception crosses it, every failure is
 * a vp_result code with a one-line message in err[errlen]. */
#ifndef VDBPACK_VDB_FIELD_H
#define VDBPACK_VDB_FIELD_H

#include <stddef.h>
#include "vdb/vdb_bridge.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vpv_field vpv_field;

typedef struct vpv_field_info {
    double bmin[3], bmax[3]; /* world box of the active voxels (centres
                                +- half a voxel) */
    double voxel_size;       /* smallest voxel edge (world) */
    double min, max;         /* over every value of the grid, background
                                included */
    char name[128];
} vpv_field_info;

/* Reads a float grid from a .vdb: grid_name NULL picks the first grid of
 * float values (any class), else the grid of that name. Refused with one
 * line: a missing file (VP_ERR_IO), a corrupt one (VP_ERR_FORMAT), no
 * such grid, a grid of another value type (points, vec3s, double, ...),
 * a grid without active voxels, a NaN or infinite value anywhere
 * (VP_ERR_INVALID_ARGUMENT). *out is owned by the caller. */
int vpv_field_read(const char *path, const char *grid_name, vpv_field **out, char *err,
                   size_t errlen);
void vpv_field_get_info(const vpv_field *f, vpv_field_info *info);
/* Trilinear sample at world point p, the point first clamped to the box of
 * the active voxels' centres (so the half voxel at the box's faces takes
 * the face's values, not a blend with the background). Thread-safe. */
double vpv_field_sample(const vpv_field *f, const double p[3]);
/* The smallest and largest value a sample in the world box [lo, hi] can
 * return: every value (voxel or tile, active or not) within one voxel of
 * it, and the background where the grid holds no node there. */
int vpv_field_range(const vpv_field *f, const double lo[3], const double hi[3], double *vmin,
                    double *vmax, char *err, size_t errlen);
void vpv_field_destroy(vpv_field *f);

/* The world box of a level set's inside: its voxels and tiles below zero
 * (active or not), grown by one voxel (the trilinear sample is negative up
 * to a voxel beyond a negative voxel's centre). 0, or -1 (no inside). */
int vpv_levelset_inside_box(const vpv_levelset *ls, double lo[3], double hi[3]);

#ifdef __cplusplus
}
#endif
#endif
