/* SPDX-License-Identifier: Apache-2.0 */
/* Export formats: names, choosing one by extension, and the vp_export /
 * vp_import dispatch; the helpers the writers and readers share are in
 * vpio.c. */
#include "io/io_internal.h"
#include "core/context.h"
#include "core/superball.h"
#include "os/input.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *const k_names[] = {NULL, "vdb", "ply", "csv", "obj"};

const char *vp_format_name(vp_format f) {
    return (f > VP_FORMAT_UNKNOWN && f <= VP_FORMAT_OBJ) ? k_names[f] : NULL;
}

int vp_format_parse(const char *name, vp_format *out) {
    if (!name || !out) return -1;
    for (int f = VP_FORMAT_VDB; f <= VP_FORMAT_OBJ; f++)
        if (!strcmp(name, k_names[f])) {
            *out = (vp_format)f;
            return 0;
        }
    return -1;
}

vp_format vp_format_from_path(const char *path) {
    if (!path) return VP_FORMAT_UNKNOWN;
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(slash ? slash + 1 : path, '.');
    if (!dot) return VP_FORMAT_UNKNOWN;
    for (int f = VP_FORMAT_VDB; f <= VP_FORMAT_OBJ; f++)
        if (!strcasecmp(dot + 1, k_names[f])) return (vp_format)f;
    return VP_FORMAT_UNKNOWN;
}

void vp_export_params_init(vp_export_params *p) {
    if (!p) return;
    memset(p, 0, sizeof *p);
    vp_write_params_init(&p->vdb);
    p->sphere_subdivisions = 2;
}

static vp_format resolve(const char *path, vp_format f) {
    return f != VP_FORMAT_UNKNOWN ? f : vp_format_from_path(path);
}

vp_result vp_export(vp_context *ctx, const char *path, const vp_particles *p,
                    const vp_export_params *params) {
    vp_export_params def;
    if (!params) {
        vp_export_params_init(&def);
        params = &def;
    }
    if (!p) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "no particles to write");
    vp_format f = resolve(path, params->format);
    switch (f) {
    case VP_FORMAT_VDB: return vp_write_points(ctx, path, p, &params->vdb);
    case VP_FORMAT_PLY: return vpio_write_ply(ctx, path, p, params);
    case VP_FORMAT_CSV: return vpio_write_csv(ctx, path, p, params);
    case VP_FORMAT_OBJ: return vpio_write_obj(ctx, path, p, params);
    default:
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "%s: unknown output format (the extension is not .vdb, .ply, .csv or .obj)",
                       path ? path : "(null)");
    }
}

vp_result vp_import(vp_context *ctx, const char *path, vp_format format, vp_particles **out,
                    int *needs_shape) {
    if (needs_shape) *needs_shape = 0;
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    vp_format f = resolve(path, format);
    int unknown_shape = 0;
    vp_result r;
    switch (f) {
    case VP_FORMAT_VDB: return vp_read_points(ctx, path, out);
    case VP_FORMAT_PLY:
        r = vpio_read_ply(ctx, path, out, &unknown_shape);
        if (r == VP_OK && needs_shape) *needs_shape = unknown_shape;
        return r;
    case VP_FORMAT_CSV:
        r = vpio_read_csv(ctx, path, out, &unknown_shape);
        if (r == VP_OK && needs_shape) *needs_shape = unknown_shape;
        return r;
    case VP_FORMAT_OBJ:
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "%s: OBJ is written, not read (an input is .vdb, .ply or .csv)", path);
    default:
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "%s: unknown input format (the extension is not .vdb, .ply or .csv)",
                       path ? path : "(null)");
    }
}

/* The OBJ bytes of one particle of shape ref among n: "v x y z" with %.9g
 * (about 40 bytes), "f a b c" with indices of about log10(n * v) digits,
 * as many as the largest face has; 0 for an unknown shape. */
static double obj_bytes_per_particle(vp_shape_ref ref, double n, const vp_export_params *params) {
    int v = 0, f = 0;
    const vp_mesh_shape *um =
        ref.shape == VP_SHAPE_SUPERBALL ? vp_superball_mesh(ref.param, NULL) : ref.mesh;
    if ((ref.shape == VP_SHAPE_MESH || ref.shape == VP_SHAPE_SUPERBALL) && um) {
        v = (int)vp_mesh_shape_triangles(um) / 2 + 2; /* closed genus-0 estimate */
        f = (int)vp_mesh_shape_triangles(um);
    } else if (vp_export_obj_counts(ref.shape, params ? params->sphere_subdivisions : 0, &v, &f) !=
               0) {
        return 0;
    }
    double digits = ceil(log10(n * v + 10)) + 1;
    const vp_polyhedron *poly = vp_shape_polyhedron(ref.shape);
    int fmax = 3;
    for (int k = 0; poly && k < poly->nfaces; k++)
        if (poly->face_size[k] > fmax) fmax = poly->face_size[k];
    return v * 40.0 + f * (2 + fmax * digits);
}

double vp_export_estimate_bytes(const vp_particles *p, vp_format format,
                                const vp_export_params *params) {
    if (!p) return 0;
    double n = (double)p->count;
    int o = p->has_orient;
    switch (format) {
    case VP_FORMAT_PLY:
        return 1024 + n * (4 * 3 + 4 + 4 + (o ? 16 : 0) + 1 + (p->shape_index ? 1 : 0));
    case VP_FORMAT_CSV:
        return 64 + n * (10 + 3 * 24 + 15 + (o ? 4 * 15 : 0) + 8 + (p->shape_index ? 40 : 0));
    case VP_FORMAT_VDB: return n * (o ? 40 : 24);
    case VP_FORMAT_OBJ: { /* a mixed set: as if every particle were its largest shape */
        double most = 0.0;
        unsigned nk = p->shape == VP_SHAPE_MIXED ? p->shape_count : 1;
        for (unsigned k = 0; k < nk && k < VP_MAX_SHAPES; k++) {
            vp_shape_ref ref =
                p->shape == VP_SHAPE_MIXED ? p->shapes[k] : vp_particles_shape_of(p, 0);
            double b = obj_bytes_per_particle(ref, n, params);
            if (!(b > 0)) return 0;
            if (b > most) most = b;
        }
        return 1024 + n * most;
    }
    default: return 0;
    }
}
