/* SPDX-License-Identifier: Apache-2.0 */
/* The extern "C" interface of the only C++ layer: everything that touches
 * OpenVDB goes through these functions. No C++ exception crosses this
 * boundary: every function catches everything and returns a code with a
 * message (one line, no trailing newline, naming the file where there is
 * one) written to err[errlen].
 * Return codes are vp_result values (see include/vdbpack/vdbpack.h). */
#ifndef VDBPACK_VDB_BRIDGE_H
#define VDBPACK_VDB_BRIDGE_H

#include <stddef.h>
#include <stdint.h>
#include "vdbpack/vdbpack.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Initialises OpenVDB (idempotent, thread-safe). */
void vpv_init(void);

/* Ends TBB's worker threads (tbb::finalize), waiting for them to exit, so
 * that a fork() that follows leaves the child no TBB state made by threads
 * it does not have: a child forked while OpenVDB's TBB workers exist hangs
 * in its first parallel OpenVDB call (seen: Grid::activeVoxelCount waiting
 * forever for workers after a points read). TBB starts new workers when it
 * is next used. 0: no TBB worker thread is left; -1: TBB refused (another
 * thread is inside a parallel algorithm), workers may remain. */
int vpv_quiesce_threads(void);

/* An owned openvdb::FloatGrid level set (negative inside). */
typedef struct vpv_levelset vpv_levelset;

typedef struct vpv_levelset_info {
    double voxel_size;       /* smallest voxel edge (world) */
    double bmin[3], bmax[3]; /* world bbox of the active voxels */
    double background;       /* exterior background value (world units, > 0) */
    double interior_band;    /* depth inside to which values are distances:
                              the grid's -(most negative value), inactive
                              values included (they hold the band) */
    size_t active_voxels;
    size_t inside_voxels; /* active voxels < 0 (tiles counted by voxel) */
    double volume;        /* world volume inside (OpenVDB level-set measure, or
                              the inside voxels' when larger) */
    int leaked;           /* 1: some voxel on a face of the active bbox is < 0,
                              i.e. the inside reaches the grid's boundary */
    char name[128];
} vpv_levelset_info;

/* Voxelizes a closed triangle mesh with openvdb::tools::meshToVolume.
 * verts: 3*nverts world coordinates (double, so far-from-origin meshes keep
 * their precision: the transform is centred on the mesh); tris: 3*ntris
 * indices. voxel: world voxel size. ex_band/in_band: exterior/interior
 * half-widths in voxels (in_band sized for the largest particle).
 * renormalize: run OpenVDB's renormalization pass, which smooths bumps from
 * self-intersecting or overlapping parts; 0 keeps the exact closest-point
 * distances (closed meshes) and saves about a fifth of the time.
 * keep_going (may be NULL): polled with user (from worker threads, one call
 * at a time) while OpenVDB voxelizes; once it returns 0 the work stops and
 * the call returns VP_ERR_CANCELLED with nothing in *out.
 * *out is owned by the caller (vpv_levelset_destroy). */
int vpv_levelset_from_mesh(const double *verts, size_t nverts, const uint32_t *tris, size_t ntris,
                           double voxel, double ex_band, double in_band, int renormalize,
                           int (*keep_going)(void *user), void *user, vpv_levelset **out, char *err,
                           size_t errlen);

/* The winding numbers of a mesh, for vpv_levelset_from_mesh_winding.
 * Both calls come from several threads at once. */
typedef struct vpv_winding_ops {
    void *user;
    /* w[i] at the n world points pts[3i..3i+2] */
    void (*points)(void *user, const double *pts, size_t n, double *w);
    /* w[64 i + 8 j + k] at the world points lo + h * (i, j, k), i, j, k in
     * 0..7 (a leaf node's voxels in OpenVDB's order) */
    void (*block)(void *user, const double lo[3], double h, double *w);
} vpv_winding_ops;

/* As vpv_levelset_from_mesh, with the inside where the winding number is
 * at least 0.5 instead of OpenVDB's closed-surface sign: the unsigned
 * distance to the triangles (meshToVolume, max(ex_band, in_band) voxels on
 * both sides), each voxel's sign from winding; where the mesh has holes
 * (holes: nholes boxes of 6 doubles, world min and max, around them) the
 * film where the winding number crosses 0.5 away from the triangles is
 * found on a grid of 8-voxel blocks, made leaves, and the distances to it
 * and to the triangles are solved again together (OpenVDB's fast
 * sweeping); tiles beyond the leaves take the sign of the winding number at
 * their centres. */
int vpv_levelset_from_mesh_winding(const double *verts, size_t nverts, const uint32_t *tris,
                                   size_t ntris, double voxel, double ex_band, double in_band,
                                   const vpv_winding_ops *winding, const double *holes,
                                   size_t nholes, int (*keep_going)(void *user), void *user,
                                   vpv_levelset **out, char *err, size_t errlen);

/* Reads a level set from a .vdb. grid_name NULL: the first float level set
 * (GRID_LEVEL_SET class, float or double values; double is converted);
 * otherwise the grid with that name ("" = unnamed). A file without such a
 * grid gives VP_ERR_NOT_LEVEL_SET with a message listing every grid as
 * name [class, value type]. Truncated/corrupt files give VP_ERR_FORMAT,
 * missing ones VP_ERR_IO. */
int vpv_levelset_read(const char *path, const char *grid_name, vpv_levelset **out, char *err,
                      size_t errlen);

/* A fog or density grid as a level set (vp_container_params.has_iso):
 * grid_name NULL picks the first float grid that is not a level set; the
 * inside is where the grid's value is at least iso, converted by OpenVDB's
 * fast sweeping (fogToSdf) at the grid's voxel size. A level set named
 * here, an iso outside the grid's values (no surface), a grid of another
 * type: VP_ERR_INVALID_ARGUMENT or VP_ERR_NOT_LEVEL_SET, one line. */
int vpv_levelset_read_fog(const char *path, const char *grid_name, double iso, vpv_levelset **out,
                          char *err, size_t errlen);

/* Makes sure values are distances to at least in_depth (world) inside; if
 * the grid's interior band is narrower, it is widened inward by fast
 * sweeping from the band it has (OpenVDB's dilateSdf), keeping the signs
 * the grid has (a cavity stays outside). */
int vpv_levelset_ensure_interior(vpv_levelset *ls, double in_depth, char *err, size_t errlen);

/* About how many voxels the rebuild of vpv_levelset_ensure_interior(ls,
 * in_depth) makes: 0 when none is needed; otherwise the surface's voxels
 * (64 a leaf, plus the faces of inside tiles that meet the outside) times
 * the band widths, at most inside_voxels plus the outer band. Never fails
 * (0 on error). */
double vpv_levelset_rebuild_voxels(const vpv_levelset *ls, double in_depth, double inside_voxels);

void vpv_levelset_get_info(const vpv_levelset *ls, vpv_levelset_info *info);

/* The level set's 8^3-voxel blocks (its leaf nodes' footprint) over the
 * leaves' bounding box plus one block on each side, x fastest: value[i] is
 * NaN where the block holds a leaf node, else the value of the tile that
 * covers it (the background's magnitude; negative inside). Block (0,0,0)
 * starts at world origin[] and spans block = 8 voxels on each axis; a world
 * point p lies in block floor((p - origin) / block). Only for axis-aligned
 * uniform-scale transforms (VP_ERR_NOT_LEVEL_SET otherwise), and at most
 * max_blocks blocks (VP_ERR_OUT_OF_MEMORY otherwise). out->value is
 * malloc'd and owned by the caller (free). */
typedef struct vpv_blocks {
    double origin[3];
    double block, voxel;
    double background; /* |the grid's background| (the exterior band) */
    int64_t dims[3];
    float *value;
} vpv_blocks;
int vpv_levelset_blocks(const vpv_levelset *ls, size_t max_blocks, vpv_blocks *out, char *err,
                        size_t errlen);

/* Trilinear sample of the signed distance at world point p. Outside the
 * narrow band the background (+ outside, - inside) is returned.
 * Safe to call from several threads at once. */
double vpv_levelset_sample(const vpv_levelset *ls, const double p[3]);
/* Gradient (outward, normalised) by central differences at half a voxel. */
void vpv_levelset_gradient(const vpv_levelset *ls, const double p[3], double g[3]);

/* Writes the level set alone to path (not atomic: the caller passes a
 * temporary path and renames). meta may be NULL. */
int vpv_levelset_write(const vpv_levelset *ls, const char *path, const vp_meta *meta,
                       size_t meta_count, char *err, size_t errlen);

void vpv_levelset_destroy(vpv_levelset *ls);

/* The position error of P stored in a points grid of voxel size voxel
 * (as vpv_points_read reports it): sqrt(3) x the codec's step x voxel. */
static inline double vpv_points_error(double voxel, int full_precision)
{
    return 1.7320508075688772 *
           (full_precision ? 5.9604644775390625e-8 /* 2^-24 */
                           : 1.0 / 65535.0) *
           voxel;
}
/* The smallest voxel the writer uses for positions up to maxabs from the
 * origin: OpenVDB's smallest scale, or what keeps index coordinates within
 * 2^29. */
static inline double vpv_points_min_voxel(double maxabs)
{
    const double lim = maxabs / 536870912.0; /* 2^29 */
    return lim > VP_POINTS_MIN_VOXEL ? lim : VP_POINTS_MIN_VOXEL;
}

/* Writes particles as a PointDataGrid named "points" (see vp_write_points
 * for the attribute layout) to path (not atomic: caller renames). File
 * metadata from params->meta, also copied onto the grid. The voxel size and
 * the codec follow VP_POSITION_ERROR_LIMIT (vdbpack.h): 16-bit fixed point
 * becomes float where it would be too coarse for the smallest radius; a set
 * that even float P cannot hold is refused (VP_ERR_INVALID_ARGUMENT, before
 * anything is written); params->report, if set, is filled on success. */
int vpv_points_write(const char *path, const vp_particles *p, const vp_write_params *params,
                     char *err, size_t errlen);

/* Reads the first PointDataGrid (preferring one named "points"): P,
 * pscale (else radius 0), orient (else none), groups (pass groups in the
 * order of the descriptor). *out allocated with vp_particles_alloc_raw
 * semantics: free with vp_particles_destroy. */
int vpv_points_read(const char *path, vp_particles **out, char *err, size_t errlen);

/* Describes every grid of a file (name, type, class, voxel size, active
 * voxels, bbox; for points: count, attributes with type and codec, groups)
 * and the file metadata. *out is malloc'd (free()). json != 0: one JSON
 * object. */
int vpv_describe_file(const char *path, int json, char **out, char *err, size_t errlen);

#ifdef __cplusplus
}
#endif
#endif
