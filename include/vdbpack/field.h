/* SPDX-License-Identifier: Apache-2.0 */
/* Fields and masks (part of vdbpack.h; docs/fields.md): a scalar field is
 * a value at every point of space, as packers see it: a sample callback
 * and the box it is defined on. A float grid from a .vdb is sampled
 * trilinearly (OpenVDB's BoxSampler) in the C++ layer. A mask is a second
 * container whose inside is taken out of the first. */
/* Self-contained: included first, it brings in vdbpack.h, which includes
 * this header where the declarations it needs are in place. */
#include "vdbpack/vdbpack.h"

#ifndef VDBPACK_FIELD_H
#define VDBPACK_FIELD_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vp_field vp_field;

typedef struct vp_field_ops {
    /* The value at world point p. Must be safe to call from several
     * threads at once. */
    double (*sample)(void *user, const double p[3]);
    /* Optional: frees user when the field is destroyed. */
    void (*destroy)(void *user);
} vp_field_ops;

typedef struct vp_field_info {
    double bmin[3], bmax[3]; /* the world box the field is defined on (a
                                grid: its active voxels, centres +- half a
                                voxel); it must cover the container's inside */
    double voxel_size;       /* a grid's voxel (world); 0 for custom fields */
    double min, max;         /* every value the field takes (a grid: every
                                voxel and tile, and the background) */
    char grid_name[128];     /* a grid's name */
} vp_field_info;

/* How a radius field gives radii. */
typedef enum vp_field_mode {
    VP_FIELD_SCALE = 0, /* the field multiplies the radius drawn for the
                           particle (its pass's radius or distribution) */
    VP_FIELD_ABSOLUTE   /* the field is the radius (world units) */
} vp_field_mode;
/* "scale", "absolute"; NULL for an invalid value. */
VP_API const char *vp_field_mode_name(vp_field_mode m);
/* Parses a mode's name; returns 0 on success. */
VP_API int vp_field_mode_parse(const char *name, vp_field_mode *out);

/* Reads a float grid from a .vdb as a field: grid_name NULL takes the
 * first grid of float values (any class), else the one of that name.
 * Refused with one line (VP_ERR_IO for a missing file, VP_ERR_FORMAT for
 * a corrupt one, else VP_ERR_INVALID_ARGUMENT): no such grid, a grid of
 * other values (points, vec3s, double, ...), no active voxels, a NaN or
 * infinite value. Sampled trilinearly at points clamped to the box of its
 * active voxels' centres: the half voxel at the faces of that box takes
 * the faces' values; inactive voxels inside it hold the background value
 * (they are sampled as they are). *out is owned by the caller. */
VP_API vp_result vp_field_load(vp_context *ctx, const char *path, const char *grid_name,
                               vp_field **out);
/* A caller-defined field on the box [bmin, bmax] whose values lie in
 * [vmin, vmax]. user is owned by the field if ops->destroy is set (also
 * when this fails). */
VP_API vp_result vp_field_create_custom(vp_context *ctx, const vp_field_ops *ops, void *user,
                                        const double bmin[3], const double bmax[3], double vmin,
                                        double vmax, vp_field **out);
VP_API void vp_field_destroy(vp_field *f); /* NULL: no-op */
VP_API double vp_field_sample(const vp_field *f, const double p[3]);
VP_API void vp_field_get_info(const vp_field *f, vp_field_info *info);
/* The smallest and largest value a sample in the world box [lo, hi] can
 * give (a grid: the values a trilinear sample there reads; a custom field:
 * its vmin and vmax). */
VP_API vp_result vp_field_range(vp_context *ctx, const vp_field *f, const double lo[3],
                                const double hi[3], double *vmin, double *vmax);
/* The box every particle centre of a packing of c lies in: the inside of
 * c (a level set: its voxels below zero, grown by a voxel; others: their
 * bounds). */
VP_API void vp_container_inside_box(const vp_container *c, double lo[3], double hi[3]);
/* Checks that field f can serve packing container c as `what` ("radius
 * field", "density field"): its box covers c's inside box (up to 1e-9 of
 * its size); for a radius field (positive != 0) every value it can give
 * there is positive; for a density field, none is negative and some is
 * positive. On failure: VP_ERR_INVALID_ARGUMENT, one line naming `name`
 * (the file) and both boxes or the bad value. vmin, vmax (may be NULL):
 * the field's range over c's inside box. */
VP_API vp_result vp_field_check(vp_context *ctx, const vp_field *f, const char *name,
                                const char *what, int positive, const vp_container *c, double *vmin,
                                double *vmax);

/* A container with a mask taken out: the inside of base where mask is
 * not inside, as a signed distance max(d_base, -d_mask) (exact where one
 * of the two is the nearer wall, a bound elsewhere, as any union of
 * level sets). base and mask are borrowed, not owned: they must outlive
 * the new container (destroy it first), which any binding can keep to. Its bounds are
 * base's; its volume, base's less the part of mask inside base (counted
 * on a grid of about 2^21 points over the box both share); its interior
 * band, the smaller of base's band and mask's exterior band (a level set
 * mask knows distances only that far outside it). */
VP_API vp_result vp_container_subtract(vp_context *ctx, const vp_container *base,
                                       const vp_container *mask, vp_container **out);

#ifdef __cplusplus
}
#endif
#endif
