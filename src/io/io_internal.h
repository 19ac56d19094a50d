/* SPDX-License-Identifier: Apache-2.0 */
/* Shared pieces of the export formats (src/io): atomic text/binary output
 * through stdio, per-particle accessors over vp_particles' uniform-or-array
 * fields, and the checks every reader applies. Private to src/io. */
#ifndef VDBPACK_IO_INTERNAL_H
#define VDBPACK_IO_INTERNAL_H

#include "vdbpack/vdbpack.h"
#include "api/atomic.h"

#include <stdio.h>

/* Per-particle values (uniform fields resolved). */
static inline float vpio_radius(const vp_particles *p, size_t i) {
    return p->radii ? p->radii[i] : p->uniform_radius;
}
static inline const float *vpio_orient(const vp_particles *p, size_t i) {
    return p->orients ? p->orients + 4 * i : p->uniform_orient;
}
static inline unsigned vpio_group(const vp_particles *p, size_t i) {
    return p->groups ? p->groups[i] : 0u;
}

/* An output file: the atomic temporary opened with stdio ("wb"), with a
 * 1 MiB buffer. On failure nothing is open and nothing is left. */
typedef struct vpio_out {
    vp_atomic a;
    FILE *f;
    char *buf;
    const char *path;
} vpio_out;
vp_result vpio_open(vp_context *ctx, const char *path, vpio_out *o);
/* Closes and renames into place, or (bad != 0, a write error, a failed
 * fclose) removes the temporary and reports "PATH: writing failed (...)". */
vp_result vpio_close(vp_context *ctx, vpio_out *o, int bad);

/* Opens path for reading ("rb"); refuses anything but a regular file.
 * VP_OK with *f (the caller closes it), or VP_ERR_IO with a message. */
vp_result vpio_open_read(vp_context *ctx, const char *path, FILE **f);

/* The checks shared by the writers: group indices in range, at most
 * VP_MAX_GROUPS groups, arrays present for count > 0. */
vp_result vpio_check_particles(vp_context *ctx, const char *path, const vp_particles *p);

/* What every reader refuses, refused before writing (a writer must not
 * make a file its readers refuse): per particle, a position that is not
 * finite or, with floats 1 (PLY's 32-bit floats) or 2 (OBJ, whose
 * readers take floats: the position and the particle's radius), beyond
 * the largest float; a radius that is not a positive finite number; an
 * orient that is not a finite unit quaternion (within 1e-3, as the readers
 * check). VP_ERR_INVALID_ARGUMENT with one line naming the particle;
 * format names the format in it. */
vp_result vpio_check_writable(vp_context *ctx, const char *path, const vp_particles *p, int floats,
                              const char *format);

/* Group names are what OpenVDB accepts (letters, digits, _ | :), 1 to
 * VP_GROUP_NAME_MAX - 1 characters. */
int vpio_valid_group_name(const char *s, size_t n);

/* Validates one particle read from path (row/vertex k, 0-based) and returns
 * VP_OK or VP_ERR_FORMAT with a message: finite position, finite pscale > 0,
 * finite quaternion of length within 1e-3 of 1 (q may be NULL). */
vp_result vpio_check_values(vp_context *ctx, const char *path, const char *what, size_t k,
                            const double x[3], double pscale, const double *q);

/* Allocates a set for n particles read from a file: positions, radii,
 * groups, and orients if with_orient. Returns NULL on failure. Owned by
 * the caller (vp_particles_destroy). */
vp_particles *vpio_alloc(size_t n, int with_orient);

/* Places particle k (file order) at index id, so that the set comes out in
 * id order: fails (VP_ERR_FORMAT) unless every id is in 0..n-1 and new.
 * seen: n bytes, zeroed by the caller. */
vp_result vpio_place_id(vp_context *ctx, const char *path, const char *what, size_t k, long long id,
                        size_t n, unsigned char *seen);

vp_result vpio_write_ply(vp_context *ctx, const char *path, const vp_particles *p,
                         const vp_export_params *params);
vp_result vpio_write_csv(vp_context *ctx, const char *path, const vp_particles *p,
                         const vp_export_params *params);
vp_result vpio_write_obj(vp_context *ctx, const char *path, const vp_particles *p,
                         const vp_export_params *params);
vp_result vpio_read_ply(vp_context *ctx, const char *path, vp_particles **out, int *needs_shape);
vp_result vpio_read_csv(vp_context *ctx, const char *path, vp_particles **out, int *has_orient);
#endif
