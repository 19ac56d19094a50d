/* SPDX-License-Identifier: Apache-2.0 */
/* Particle sets in formats other than OpenVDB points: binary PLY and CSV
 * (written and read back), and OBJ (every particle's full geometry, write
 * only). The formats, their property names and limits: docs/export.md.
 * Part of vdbpack.h; conventions as there (vp_result + context message,
 * ownership stated at each function, every write atomic). */
/* Self-contained: included first, it brings in vdbpack.h, which includes
 * this header where the declarations it needs are in place. */
#include "vdbpack/vdbpack.h"

#ifndef VDBPACK_EXPORT_H
#define VDBPACK_EXPORT_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum vp_format {
    VP_FORMAT_UNKNOWN = 0,
    VP_FORMAT_VDB, /* PointDataGrid "points" (vp_write_points / vp_read_points) */
    VP_FORMAT_PLY, /* binary little-endian PLY, one vertex per particle */
    VP_FORMAT_CSV, /* header row, one row per particle */
    VP_FORMAT_OBJ  /* Wavefront OBJ: each particle's surface (write only) */
} vp_format;

/* "vdb", "ply", "csv", "obj"; NULL for VP_FORMAT_UNKNOWN or an invalid value. */
VP_API const char *vp_format_name(vp_format f);
/* Parses a format name (as vp_format_name gives); returns 0 on success. */
VP_API int vp_format_parse(const char *name, vp_format *out);
/* The format a path's extension names (case-insensitive: .vdb, .ply, .csv,
 * .obj), else VP_FORMAT_UNKNOWN. path may be NULL. */
VP_API vp_format vp_format_from_path(const char *path);

typedef struct vp_export_params {
    vp_format format;        /* VP_FORMAT_UNKNOWN (default): from the path's extension */
    vp_write_params vdb;     /* .vdb: precision and metadata; .ply/.obj: the
                                  metadata becomes comment lines (CSV has none) */
    int sphere_subdivisions; /* .obj spheres: each icosahedron edge split in
                                  n (1..16, default 2: 42 vertices, 80 triangles) */
} vp_export_params;
/* Fills defaults (vp_write_params_init for vdb). */
VP_API void vp_export_params_init(vp_export_params *p);

/* Writes p to path in params->format (or by extension) atomically: on any
 * failure nothing is left at path (an existing file there is untouched).
 * p is only read; params NULL means defaults. Unknown formats give
 * VP_ERR_INVALID_ARGUMENT, and so does a particle that the format's
 * readers would refuse, before any file is made (the message names it): a
 * position, radius or orient that is not finite (every format); a radius
 * <= 0 or an orient that is not a unit quaternion within 1e-3 (PLY, CSV,
 * OBJ); a coordinate beyond FLT_MAX (PLY; OBJ with the radius added). */
VP_API vp_result vp_export(vp_context *ctx, const char *path, const vp_particles *p,
                           const vp_export_params *params);

/* Estimated size in bytes of p written in format (exact layout for PLY,
 * typical text widths for CSV and OBJ); for the CLI's size warning. */
VP_API double vp_export_estimate_bytes(const vp_particles *p, vp_format format,
                                       const vp_export_params *params);
/* Vertices and faces one particle of shape s has in an OBJ export with
 * sphere_subdivisions n (0 = default). Returns 0, or -1 for a bad shape. */
VP_API int vp_export_obj_counts(vp_shape s, int sphere_subdivisions, int *verts, int *faces);

/* Reads a particle set from a .vdb (its points grid, as vp_read_points), or
 * a .ply or .csv as vdbpack writes them; format VP_FORMAT_UNKNOWN = by
 * extension. A path that is not a regular file (a FIFO, a device, a
 * directory) gives VP_ERR_IO at once. PLY and CSV input is checked strictly: a wrong header, a
 * truncated or over-long file, non-finite values, pscale <= 0, ids that
 * are not 0..N-1 once each, or bad quaternions give VP_ERR_FORMAT with a
 * message naming the file and the first problem. Particles come back in id
 * order. A CSV does not record the shape (nor may a foreign PLY): *out
 * then has shape VP_SHAPE_SPHERE, and if it has orientations the caller
 * must set the shape; *needs_shape (if not NULL) says so: 1 for such a
 * file, else 0.
 * *out is owned by the caller (vp_particles_destroy). */
VP_API vp_result vp_import(vp_context *ctx, const char *path, vp_format format, vp_particles **out,
                           int *needs_shape);

#ifdef __cplusplus
}
#endif
#endif
