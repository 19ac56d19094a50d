/* SPDX-License-Identifier: Apache-2.0 */
/* Export formats: names, choosing one by extension, the vp_export /
 * vp_import dispatch, and the helpers the writers and readers share. */
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
    const vp_mesh_shape *um = ref.shape == VP_SHAPE_SUPERBALL ? vp_superball_mesh(ref.param, NULL)
                                                              : ref.mesh;
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
    case VP_FORMAT_PLY: return 1024 + n * (4 * 3 + 4 + 4 + (o ? 16 : 0) + 1 + (p->shape_index ? 1 : 0));
    case VP_FORMAT_CSV: return 64 + n * (10 + 3 * 24 + 15 + (o ? 4 * 15 : 0) + 8 + (p->shape_index ? 40 : 0));
    case VP_FORMAT_VDB: return n * (o ? 40 : 24);
    case VP_FORMAT_OBJ: { /* a mixed set: as if every particle were its largest shape */
        double most = 0.0;
        unsigned nk = p->shape == VP_SHAPE_MIXED ? p->shape_count : 1;
        for (unsigned k = 0; k < nk && k < VP_MAX_SHAPES; k++) {
            vp_shape_ref ref = p->shape == VP_SHAPE_MIXED ? p->shapes[k] : vp_particles_shape_of(p, 0);
            double b = obj_bytes_per_particle(ref, n, params);
            if (!(b > 0)) return 0;
            if (b > most) most = b;
        }
        return 1024 + n * most;
    }
    default: return 0;
    }
}

/* --- shared helpers ------------------------------------------------------- */

vp_result vpio_open(vp_context *ctx, const char *path, vpio_out *o) {
    memset(o, 0, sizeof *o);
    o->path = path;
    vp_result r = vp_atomic_begin(ctx, path, &o->a);
    if (r != VP_OK) return r;
    o->f = fopen(o->a.tmp_path, "wb");
    if (!o->f) {
        int e = errno;
        vp_atomic_abort(&o->a);
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot write (%s)", path, strerror(e));
    }
    o->buf = malloc(1 << 20);
    if (o->buf) setvbuf(o->f, o->buf, _IOFBF, 1 << 20);
    return VP_OK;
}

vp_result vpio_open_read(vp_context *ctx, const char *path, FILE **f) {
    /* without blocking: fopen() of a FIFO waits for its writer */
    char msg[1024];
    int fd = vp_os_open_input(path, msg, sizeof msg);
    if (fd < 0) {
        *f = NULL;
        return vp_fail(ctx, VP_ERR_IO, "%s", msg);
    }
    *f = fdopen(fd, "rb");
    if (!*f) {
        int e = errno;
        close(fd);
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot open (%s)", path, strerror(e));
    }
    return VP_OK;
}

vp_result vpio_close(vp_context *ctx, vpio_out *o, int bad) {
    int e = 0;
    if (ferror(o->f)) bad = 1, e = errno;
    if (fclose(o->f) != 0 && !bad) bad = 1, e = errno;
    o->f = NULL;
    free(o->buf);
    o->buf = NULL;
    if (bad) {
        vp_atomic_abort(&o->a);
        if (e) return vp_fail(ctx, VP_ERR_IO, "%s: writing failed (%s)", o->path, strerror(e));
        return vp_fail(ctx, VP_ERR_IO, "%s: writing failed", o->path);
    }
    return vp_atomic_commit(ctx, &o->a);
}

vp_result vpio_check_particles(vp_context *ctx, const char *path, const vp_particles *p) {
    if (p->group_count < 1 || p->group_count > VP_MAX_GROUPS)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: %u groups (1 to %d)", path,
                       p->group_count, VP_MAX_GROUPS);
    if (p->count && !p->positions)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: particles without positions", path);
    if (p->groups)
        for (size_t i = 0; i < p->count; i++)
            if (p->groups[i] >= p->group_count)
                return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: particle %zu is in group %u of %u",
                               path, i, (unsigned)p->groups[i], p->group_count);
    if (p->count > 2147483647u)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: %zu particles (ids are int32: at most "
                       "2147483647)", path, p->count);
    return VP_OK;
}

vp_result vpio_check_writable(vp_context *ctx, const char *path, const vp_particles *p,
                              int floats, const char *format) {
    for (size_t i = 0; i < p->count; i++) {
        const double *x = p->positions + 3 * i;
        double r = (double)vpio_radius(p, i);
        if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2]))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "%s: particle %zu: its position (%g %g %g) is not finite; nothing "
                           "written", path, i, x[0], x[1], x[2]);
        if (!isfinite(r) || !(r > 0))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "%s: particle %zu: its radius %g is not a positive number; nothing "
                           "written", path, i, r);
        for (int k = 0; floats && k < 3; k++)
            if (!(fabs(x[k]) + (floats == 2 ? r : 0.0) <= FLT_MAX))
                return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                               "%s: particle %zu: its coordinate %g is beyond the 32-bit floats "
                               "%s holds (at most %.3g); nothing written (.csv keeps it)",
                               path, i, x[k], format, (double)FLT_MAX);
        if (p->has_orient) {
            const float *q = vpio_orient(p, i);
            double n = 0;
            for (int c = 0; c < 4; c++) n += (double)q[c] * (double)q[c];
            if (!(fabs(sqrt(n) - 1) <= 1e-3))
                return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                               "%s: particle %zu: its orient (%g %g %g %g) is not a finite unit "
                               "quaternion; nothing written", path, i, (double)q[0],
                               (double)q[1], (double)q[2], (double)q[3]);
        }
    }
    return VP_OK;
}

int vpio_valid_group_name(const char *s, size_t n) {
    if (n == 0 || n >= VP_GROUP_NAME_MAX) return 0;
    for (size_t i = 0; i < n; i++) {
        char c = s[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
              c == '_' || c == '|' || c == ':'))
            return 0;
    }
    return 1;
}

vp_result vpio_check_values(vp_context *ctx, const char *path, const char *what, size_t k,
                            const double x[3], double pscale, const double *q) {
    if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2]))
        return vp_fail(ctx, VP_ERR_FORMAT, "%s: %s %zu: position is not finite (%g %g %g)", path,
                       what, k, x[0], x[1], x[2]);
    if (!isfinite(pscale) || !(pscale > 0))
        return vp_fail(ctx, VP_ERR_FORMAT, "%s: %s %zu: pscale %g is not a positive number", path,
                       what, k, pscale);
    if (q) {
        double n = 0;
        for (int c = 0; c < 4; c++) {
            if (!isfinite(q[c]))
                return vp_fail(ctx, VP_ERR_FORMAT, "%s: %s %zu: orient is not finite", path, what, k);
            n += q[c] * q[c];
        }
        if (!(fabs(sqrt(n) - 1) <= 1e-3))
            return vp_fail(ctx, VP_ERR_FORMAT, "%s: %s %zu: orient (%g %g %g %g) is not a unit "
                           "quaternion", path, what, k, q[0], q[1], q[2], q[3]);
    }
    return VP_OK;
}

vp_particles *vpio_alloc(size_t n, int with_orient) {
    vp_particles *p = calloc(1, sizeof *p);
    if (!p) return NULL;
    size_t m = n ? n : 1;
    p->positions = malloc(m * 3 * sizeof(double));
    p->radii = malloc(m * sizeof(float));
    p->groups = calloc(m, sizeof(uint16_t));
    if (with_orient) p->orients = malloc(m * 4 * sizeof(float));
    if (!p->positions || !p->radii || !p->groups || (with_orient && !p->orients)) {
        vp_particles_destroy(p);
        return NULL;
    }
    p->count = p->capacity = n;
    p->has_orient = with_orient;
    p->uniform_orient[3] = 1.0f;
    p->shape = VP_SHAPE_SPHERE;
    p->group_count = 1;
    strcpy(p->group_names[0], "pass1");
    return p;
}

vp_result vpio_place_id(vp_context *ctx, const char *path, const char *what, size_t k,
                        long long id, size_t n, unsigned char *seen) {
    if (id < 0 || (unsigned long long)id >= n)
        return vp_fail(ctx, VP_ERR_FORMAT, "%s: %s %zu: id %lld is not in 0..%zu (ids must be "
                       "0..N-1 once each)", path, what, k, id, n ? n - 1 : 0);
    if (seen[id])
        return vp_fail(ctx, VP_ERR_FORMAT, "%s: %s %zu: id %lld appears twice", path, what, k, id);
    seen[id] = 1;
    return VP_OK;
}
