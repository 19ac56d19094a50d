/* SPDX-License-Identifier: Apache-2.0 */
/* Output: VDB points (through the C++ layer), reading them back, file
 * descriptions and the unit particle shape as OBJ. Every file is written to
 * a temporary path and renamed, so no partial file is ever left. */
#include "api/atomic.h"
#include "api/probe.h"
#include "core/context.h"
#include "core/mesh_shape.h"
#include "core/shape.h"
#include "core/superball.h"
#include "os/input.h"
#include "vdb/vdb_bridge.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void vp_write_params_init(vp_write_params *p) {
    if (!p) return;
    memset(p, 0, sizeof *p);
    p->points_per_voxel = 8;
}

double vp_points_min_radius(double max_coordinate) {
    double m = isfinite(max_coordinate) ? fabs(max_coordinate) : 0.0;
    return vpv_points_error(vpv_points_min_voxel(m), 1) / VP_POSITION_ERROR_LIMIT;
}

/* The first particle with a position, radius or orient that is not finite
 * (which vdbpack's readers refuse in every format), its part in *what; or
 * (size_t)-1. */
static size_t nonfinite_particle(const vp_particles *p, const char **what) {
    for (size_t i = 0; p->positions && i < p->count; i++) {
        const double *x = p->positions + 3 * i;
        const float *q = p->orients ? p->orients + 4 * i : p->uniform_orient;
        double r = p->radii ? (double)p->radii[i] : (double)p->uniform_radius;
        *what = !isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2]) ? "position"
                : !isfinite(r)                                        ? "radius (pscale)"
                : p->has_orient &&
                        !(isfinite(q[0]) && isfinite(q[1]) && isfinite(q[2]) && isfinite(q[3]))
                    ? "orient"
                    : NULL;
        if (*what) return i;
    }
    return (size_t)-1;
}

vp_result vp_write_points(vp_context *ctx, const char *path, const vp_particles *p,
                          const vp_write_params *params) {
    if (!p) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "no particles to write");
    const char *what = NULL;
    size_t bad = nonfinite_particle(p, &what);
    if (bad != (size_t)-1)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "%s: particle %zu: its %s is not finite; nothing written", path, bad, what);
    vp_write_params def;
    if (!params) {
        vp_write_params_init(&def);
        params = &def;
    }
    vp_write_params wp = *params;
    if (!wp.max_memory) wp.max_memory = vp_memory_limit(ctx);
    /* a mixed set names its shapes (what the "shape" attribute indexes)
     * unless the caller's metadata does */
    vp_meta *meta = NULL;
    char list[4096];
    if (p->shape == VP_SHAPE_MIXED) {
        int has_shape = 0, has_list = 0;
        for (size_t i = 0; i < wp.meta_count; i++) {
            has_shape |= !strcmp(wp.meta[i].key, "shape");
            has_list |= !strcmp(wp.meta[i].key, "shapes");
        }
        meta = malloc((wp.meta_count + 2) * sizeof *meta);
        if (!meta) return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
        if (wp.meta_count) memcpy(meta, wp.meta, wp.meta_count * sizeof *meta);
        size_t n = wp.meta_count;
        if (!has_shape) meta[n++] = (vp_meta){"shape", VP_META_STRING, "mixed", 0, 0};
        if (!has_list)
            meta[n++] = (vp_meta){"shapes", VP_META_STRING,
                                  vp_particles_shape_list(p, list, sizeof list), 0, 0};
        wp.meta = meta;
        wp.meta_count = n;
    }
    vpv_init();
    vp_atomic a;
    vp_result r = vp_atomic_begin(ctx, path, &a);
    if (r != VP_OK) {
        free(meta);
        return r;
    }
    char err[1024];
    int rc = vpv_points_write(a.tmp_path, p, &wp, err, sizeof err);
    free(meta);
    if (rc != VP_OK) {
        vp_atomic_abort(&a);
        return vp_fail(ctx, (vp_result)rc, "%s: %s", path, err);
    }
    return vp_atomic_commit(ctx, &a);
}

static int probe_points(const void *arg, char *err, size_t errlen) {
    vp_particles *p = NULL;
    int rc = vpv_points_read(arg, &p, err, errlen);
    vp_particles_destroy(p);
    return rc;
}

static int probe_describe(const void *arg, char *err, size_t errlen) {
    char *text = NULL;
    int rc = vpv_describe_file(arg, 0, &text, err, errlen);
    free(text);
    return rc;
}

/* A FIFO or device would block the reader until its writer comes: refused
 * with one line at once. */
static vp_result check_input(vp_context *ctx, const char *path) {
    char msg[1024];
    if (vp_os_check_input(path, msg, sizeof msg) != 0) return vp_fail(ctx, VP_ERR_IO, "%s", msg);
    return VP_OK;
}

vp_result vp_read_points(vp_context *ctx, const char *path, vp_particles **out) {
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if (check_input(ctx, path) != VP_OK) return VP_ERR_IO;
    vpv_init();
    vp_result pr = vp_probe_read(ctx, path, probe_points, path);
    if (pr != VP_OK) return pr;
    char err[1024];
    int rc = vpv_points_read(path, out, err, sizeof err);
    if (rc != VP_OK) return vp_fail(ctx, (vp_result)rc, "%s", err);
    /* refused as the CSV and PLY readers refuse it: check, render and
     * convert would work on NaN (convert wrote "-nan" into a CSV) */
    const char *what = NULL;
    size_t bad = nonfinite_particle(*out, &what);
    if (bad != (size_t)-1) {
        vp_particles_destroy(*out);
        *out = NULL;
        return vp_fail(ctx, VP_ERR_FORMAT, "%s: particle %zu: its %s is not finite", path, bad,
                       what);
    }
    return VP_OK;
}

vp_result vp_describe_file(vp_context *ctx, const char *path, int json, char **out) {
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    if (check_input(ctx, path) != VP_OK) return VP_ERR_IO;
    vpv_init();
    vp_result pr = vp_probe_read(ctx, path, probe_describe, path);
    if (pr != VP_OK) return pr;
    char err[1024];
    int rc = vpv_describe_file(path, json, out, err, sizeof err);
    return rc == VP_OK ? VP_OK : vp_fail(ctx, (vp_result)rc, "%s", err);
}

/* Unit sphere for instancing: an icosahedron subdivided twice, projected. */
static int write_sphere_obj(FILE *f) {
    const vp_polyhedron *ico = vp_shape_polyhedron(VP_SHAPE_ICOSAHEDRON);
    if (!ico) return -1;
    /* subdivide each face (triangles) into n^2 triangles on a barycentric
     * grid, projecting every vertex to the sphere; vertices are written per
     * face (the mesh is for rendering, welding is not needed) */
    const int n = 4;
    int base = 1;
    for (int fi = 0; fi < ico->nfaces; fi++) {
        const double *a = ico->verts[ico->faces[fi][0]], *b = ico->verts[ico->faces[fi][1]],
                     *c = ico->verts[ico->faces[fi][2]];
        for (int i = 0; i <= n; i++)
            for (int j = 0; j <= n - i; j++) {
                double u = (double)i / n, v = (double)j / n, w = 1 - u - v;
                double p[3] = {w * a[0] + u * b[0] + v * c[0], w * a[1] + u * b[1] + v * c[1],
                               w * a[2] + u * b[2] + v * c[2]};
                double l = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
                fprintf(f, "v %.9g %.9g %.9g\n", p[0] / l, p[1] / l, p[2] / l);
            }
            /* index of (i,j) within this face's block */
#define IDX(i, j) (base + (i) * (n + 1) - ((i) * ((i)-1)) / 2 + (j))
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n - i; j++) {
                fprintf(f, "f %d %d %d\n", IDX(i, j), IDX(i + 1, j), IDX(i, j + 1));
                if (j + 1 < n - i)
                    fprintf(f, "f %d %d %d\n", IDX(i + 1, j), IDX(i + 1, j + 1), IDX(i, j + 1));
            }
#undef IDX
        base += (n + 1) * (n + 2) / 2;
    }
    return 0;
}

vp_result vp_shape_write_obj_param(vp_context *ctx, vp_shape s, double param, const char *path) {
    if (s != VP_SHAPE_SUPERBALL) return vp_shape_write_obj(ctx, s, path);
    if (!(param >= VP_SUPERBALL_P_MIN && param <= VP_SUPERBALL_P_MAX))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "superball: the exponent must be in [%g, %g], not %g", VP_SUPERBALL_P_MIN,
                       VP_SUPERBALL_P_MAX, param);
    const vp_mesh_shape *m = vp_superball_mesh(param, NULL);
    if (!m) return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "superball: out of memory");
    return vp_mesh_shape_write_obj(ctx, m, path);
}

vp_result vp_shape_mesh(vp_context *ctx, vp_shape s, double param, const vp_mesh_shape *mesh,
                        double *vertices, size_t *nverts, uint32_t *face_sizes, size_t *nfaces,
                        uint32_t *indices, size_t *nindices) {
    if (!nverts || !nfaces || !nindices)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "shape mesh: a count pointer is NULL");
    const vp_polyhedron *poly = NULL;
    if (s == VP_SHAPE_SUPERBALL) {
        if (!(param >= VP_SUPERBALL_P_MIN && param <= VP_SUPERBALL_P_MAX))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "superball: the exponent must be in [%g, %g], not %g",
                           VP_SUPERBALL_P_MIN, VP_SUPERBALL_P_MAX, param);
        mesh = vp_superball_mesh(param, NULL);
        if (!mesh) return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "superball: out of memory");
    } else if (s == VP_SHAPE_MESH) {
        if (!mesh) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "shape mesh: no mesh shape");
    } else if (s == VP_SHAPE_SPHERE || !vp_shape_name(s)) {
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       s == VP_SHAPE_SPHERE ? "shape mesh: a sphere has no polygons (instance a "
                                              "sphere of radius 1)"
                                            : "shape mesh: unknown shape");
    } else {
        poly = vp_shape_polyhedron(s);
    }
    size_t nv = poly ? (size_t)poly->nverts : mesh->nverts;
    size_t nf = poly ? (size_t)poly->nfaces : mesh->ntris;
    size_t ni = 3 * nf;
    if (poly) {
        ni = 0;
        for (int f = 0; f < poly->nfaces; f++) ni += (size_t)poly->face_size[f];
    }
    if (!vertices && !face_sizes && !indices) {
        *nverts = nv, *nfaces = nf, *nindices = ni;
        return VP_OK;
    }
    if (!vertices || !face_sizes || !indices || *nverts < nv || *nfaces < nf || *nindices < ni)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "shape mesh: arrays for %zu vertices, %zu faces and %zu indices needed", nv,
                       nf, ni);
    if (poly) {
        size_t k = 0;
        for (int v = 0; v < poly->nverts; v++)
            for (int c = 0; c < 3; c++) vertices[3 * v + c] = poly->verts[v][c];
        for (int f = 0; f < poly->nfaces; f++) {
            face_sizes[f] = (uint32_t)poly->face_size[f];
            for (int i = 0; i < poly->face_size[f]; i++) indices[k++] = (uint32_t)poly->faces[f][i];
        }
    } else {
        memcpy(vertices, mesh->verts, 3 * nv * sizeof *vertices);
        for (size_t f = 0; f < nf; f++) face_sizes[f] = 3;
        memcpy(indices, mesh->tris, ni * sizeof *indices);
    }
    *nverts = nv, *nfaces = nf, *nindices = ni;
    return VP_OK;
}

vp_result vp_shape_write_obj(vp_context *ctx, vp_shape s, const char *path) {
    if (!vp_shape_name(s) || s == VP_SHAPE_MESH || s == VP_SHAPE_SUPERBALL)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       s == VP_SHAPE_SUPERBALL ? "a superball needs its exponent "
                                                 "(vp_shape_write_obj_param)"
                                               : "unknown shape");
    vp_atomic a;
    vp_result r = vp_atomic_begin(ctx, path, &a);
    if (r != VP_OK) return r;
    FILE *f = fopen(a.tmp_path, "w");
    if (!f) {
        int e = errno;
        vp_atomic_abort(&a);
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot write (%s)", path, strerror(e));
    }
    fprintf(f,
            "# vdbpack %s unit %s: bounding-sphere radius 1, centroid at the origin.\n"
            "# Instance it at each point scaled by pscale and rotated by orient.\n",
            VP_VERSION_STRING, vp_shape_name(s));
    fprintf(f, "o %s\n", vp_shape_name(s));
    int bad = 0;
    if (s == VP_SHAPE_SPHERE) {
        bad = write_sphere_obj(f);
    } else {
        const vp_polyhedron *p = vp_shape_polyhedron(s);
        for (int i = 0; i < p->nverts; i++)
            fprintf(f, "v %.17g %.17g %.17g\n", p->verts[i][0], p->verts[i][1], p->verts[i][2]);
        for (int i = 0; i < p->nfaces; i++) {
            fprintf(f, "f");
            for (int k = 0; k < p->face_size[i]; k++) fprintf(f, " %d", p->faces[i][k] + 1);
            fprintf(f, "\n");
        }
    }
    if (ferror(f)) bad = 1;
    if (fclose(f) != 0) bad = 1;
    if (bad) {
        vp_atomic_abort(&a);
        return vp_fail(ctx, VP_ERR_IO, "%s: writing failed", path);
    }
    return vp_atomic_commit(ctx, &a);
}
