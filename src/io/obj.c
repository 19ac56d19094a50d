/* SPDX-License-Identifier: Apache-2.0 */
/* OBJ: every particle's surface as a mesh (write only): the unit shape of
 * core/shape.h (spheres: an icosphere, each icosahedron edge split in n),
 * scaled by pscale, rotated by orient and moved to P. One object (o/g) per
 * group; inside one, particles in id order, each with its vertices then its
 * faces (counter-clockwise seen from outside). */
#include "io/io_internal.h"
#include "core/context.h"
#include "core/geom.h"
#include "core/mesh_shape.h"
#include "core/shape.h"
#include "core/superball.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct unit_mesh {
    int nv, nf;
    double (*v)[3];
    int (*f)[VP_POLY_MAX_FACE_VERTS];
    int *fsize;
} unit_mesh;

static void unit_free(unit_mesh *m) {
    free(m->v);
    free(m->f);
    free(m->fsize);
}

static int clamp_subdiv(int n) { return n <= 0 ? 2 : n > 16 ? 16 : n; }

int vp_export_obj_counts(vp_shape s, int n, int *verts, int *faces) {
    if (!vp_shape_name(s)) return -1;
    if (s == VP_SHAPE_SPHERE) {
        n = clamp_subdiv(n);
        *verts = 10 * n * n + 2;
        *faces = 20 * n * n;
        return 0;
    }
    const vp_polyhedron *p = vp_shape_polyhedron(s);
    if (!p) return -1;
    *verts = p->nverts;
    *faces = p->nfaces;
    return 0;
}

/* Room for nv vertices and nf faces (freed with the mesh, also on failure). */
static int unit_alloc(unit_mesh *m, int nv, int nf) {
    m->nv = nv;
    m->nf = nf;
    m->v = malloc(sizeof *m->v * (size_t)nv);
    m->f = malloc(sizeof *m->f * (size_t)nf);
    m->fsize = malloc(sizeof *m->fsize * (size_t)nf);
    return m->v && m->f && m->fsize ? 0 : -1;
}

/* Welded icosphere: each icosahedron face on a barycentric grid of n
 * steps, points projected to the unit sphere, shared edge points merged. */
static int build_sphere(unit_mesh *m, int n) {
    const vp_polyhedron *ico = vp_shape_polyhedron(VP_SHAPE_ICOSAHEDRON);
    int maxv = 10 * n * n + 2, maxf = 20 * n * n;
    int room = unit_alloc(m, maxv, maxf);
    int *idx = malloc(sizeof(int) * (size_t)((n + 1) * (n + 1)));
    if (!ico || room != 0 || !idx) {
        free(idx);
        return -1;
    }
    m->nv = m->nf = 0; /* counted up as points and faces are added */
    for (int fi = 0; fi < ico->nfaces; fi++) {
        const double *a = ico->verts[ico->faces[fi][0]], *b = ico->verts[ico->faces[fi][1]],
                     *c = ico->verts[ico->faces[fi][2]];
        for (int i = 0; i <= n; i++)
            for (int j = 0; j <= n - i; j++) {
                double u = (double)i / n, v = (double)j / n, w = 1 - u - v, p[3];
                for (int k = 0; k < 3; k++) p[k] = w * a[k] + u * b[k] + v * c[k];
                double l = vp_norm3(p);
                for (int k = 0; k < 3; k++) p[k] /= l;
                int found = -1;
                for (int e = 0; e < m->nv && found < 0; e++) {
                    double d[3] = {m->v[e][0] - p[0], m->v[e][1] - p[1], m->v[e][2] - p[2]};
                    if (vp_dot3(d, d) < 1e-18) found = e;
                }
                if (found < 0) {
                    if (m->nv == maxv) {
                        free(idx);
                        return -1;
                    }
                    memcpy(m->v[m->nv], p, sizeof p);
                    found = m->nv++;
                }
                idx[i * (n + 1) + j] = found;
            }
#define AT(i, j) idx[(i) * (n + 1) + (j)]
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n - i; j++) {
                int *t = m->f[m->nf];
                m->fsize[m->nf++] = 3;
                t[0] = AT(i, j), t[1] = AT(i + 1, j), t[2] = AT(i, j + 1);
                if (j + 1 < n - i) {
                    t = m->f[m->nf];
                    m->fsize[m->nf++] = 3;
                    t[0] = AT(i + 1, j), t[1] = AT(i + 1, j + 1), t[2] = AT(i, j + 1);
                }
            }
#undef AT
    }
    free(idx);
    return m->nv == maxv && m->nf == maxf ? 0 : -1;
}

static int build_unit(unit_mesh *m, vp_shape s, const vp_mesh_shape *mesh, int n) {
    memset(m, 0, sizeof *m);
    if (s == VP_SHAPE_SPHERE) return build_sphere(m, n);
    if (s == VP_SHAPE_MESH) { /* the normalised mesh, as --shape-out writes it */
        if (!mesh || mesh->nverts > INT32_MAX || mesh->ntris > INT32_MAX) return -1;
        if (unit_alloc(m, (int)mesh->nverts, (int)mesh->ntris) != 0) return -1;
        memcpy(m->v, mesh->verts, sizeof *m->v * (size_t)m->nv);
        for (int i = 0; i < m->nf; i++) {
            m->fsize[i] = 3;
            for (int k = 0; k < 3; k++) m->f[i][k] = (int)mesh->tris[3 * (size_t)i + k];
        }
        return 0;
    }
    const vp_polyhedron *p = vp_shape_polyhedron(s);
    if (!p) return -1;
    if (unit_alloc(m, p->nverts, p->nfaces) != 0) return -1;
    memcpy(m->v, p->verts, sizeof *m->v * (size_t)m->nv);
    for (int i = 0; i < m->nf; i++) {
        m->fsize[i] = p->face_size[i];
        memcpy(m->f[i], p->faces[i], sizeof m->f[i]);
    }
    return 0;
}

/* The unit mesh of a shape (superballs: their tessellation); a message
 * in ctx and an error on failure. */
static vp_result unit_for(vp_context *ctx, const char *path, unit_mesh *m, vp_shape_ref ref,
                          int n) {
    memset(m, 0, sizeof *m);
    if (!vp_shape_name(ref.shape) || ref.shape == VP_SHAPE_MIXED)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: unknown particle shape", path);
    if (ref.shape == VP_SHAPE_MESH && !ref.mesh)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "%s: the particles are of a mesh shape and the mesh is not loaded", path);
    const vp_mesh_shape *um =
        ref.shape == VP_SHAPE_SUPERBALL ? vp_superball_mesh(ref.param, NULL) : ref.mesh;
    if (ref.shape == VP_SHAPE_SUPERBALL && !um)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "%s: a superball's exponent must be in [0.5, 1000], not %g", path,
                       ref.param);
    if (build_unit(m, ref.shape == VP_SHAPE_SUPERBALL ? VP_SHAPE_MESH : ref.shape, um, n) != 0) {
        unit_free(m);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "%s: out of memory for the unit shape", path);
    }
    return VP_OK;
}

/* The unit meshes of a set's shapes: one, or one per shape of a mixed set
 * (units[shape_index]). *nunits of them to free with units_free. */
static vp_result units_for(vp_context *ctx, const char *path, const vp_particles *p, int n,
                           unit_mesh *units, unsigned *nunits) {
    unsigned nk = p->shape == VP_SHAPE_MIXED ? p->shape_count : 1;
    *nunits = 0;
    if (p->shape == VP_SHAPE_MIXED && (!p->shape_index || nk < 1 || nk > VP_MAX_SHAPES))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: a mixed set without its shapes", path);
    for (unsigned k = 0; k < nk; k++) {
        vp_shape_ref ref = p->shape == VP_SHAPE_MIXED ? p->shapes[k] : vp_particles_shape_of(p, 0);
        vp_result r = unit_for(ctx, path, &units[k], ref, n);
        if (r != VP_OK) return r;
        *nunits = k + 1;
    }
    return VP_OK;
}

static void units_free(unit_mesh *units, unsigned n) {
    for (unsigned k = 0; k < n; k++) unit_free(&units[k]);
}

vp_result vpio_write_obj(vp_context *ctx, const char *path, const vp_particles *p,
                         const vp_export_params *params) {
    vp_result r = vpio_check_particles(ctx, path, p);
    if (r == VP_OK) r = vpio_check_writable(ctx, path, p, 2, "OBJ");
    if (r != VP_OK) return r;
    int n = clamp_subdiv(params->sphere_subdivisions);
    unit_mesh units[VP_MAX_SHAPES];
    unsigned nunits = 0;
    if ((r = units_for(ctx, path, p, n, units, &nunits)) != VP_OK) {
        units_free(units, nunits);
        return r;
    }
    unit_mesh m = units[0];
    vpio_out o;
    if ((r = vpio_open(ctx, path, &o)) != VP_OK) {
        units_free(units, nunits);
        return r;
    }
    FILE *f = o.f;
    if (p->shape == VP_SHAPE_MIXED) {
        char list[4096];
        fprintf(f,
                "# vdbpack %s: %zu particles of %u shapes (%s), one object per group;\n"
                "# in each object, particles in id order, each its vertices then its faces\n",
                VP_VERSION_STRING, p->count, nunits, vp_particles_shape_list(p, list, sizeof list));
    } else {
        fprintf(f,
                "# vdbpack %s: %zu %s%s, each %d vertices and %d faces, one object per group;\n"
                "# in each object, particles in id order, each its vertices then its faces\n",
                VP_VERSION_STRING, p->count, vp_shape_name(p->shape), p->count == 1 ? "" : "s",
                m.nv, m.nf);
    }
    for (size_t i = 0; i < params->vdb.meta_count; i++) {
        const vp_meta *mt = &params->vdb.meta[i];
        fprintf(f, "# %s: ", mt->key ? mt->key : "");
        if (mt->type == VP_META_STRING) {
            for (const char *c = mt->s ? mt->s : ""; *c; c++)
                fputc((*c == '\n' || *c == '\r') ? ' ' : *c, f);
        } else if (mt->type == VP_META_INT) {
            fprintf(f, "%lld", (long long)mt->i);
        } else {
            fprintf(f, "%.17g", mt->d);
        }
        fputc('\n', f);
    }
    unsigned long long base = 1; /* OBJ indices are 1-based and global */
    int cancelled = 0;
    for (unsigned g = 0; g < p->group_count && !ferror(f) && !cancelled; g++) {
        int any = 0;
        for (size_t i = 0; i < p->count && !ferror(f); i++) {
            if (vpio_group(p, i) != g) continue;
            if (!any) {
                fprintf(f, "o %s\ng %s\n", p->group_names[g], p->group_names[g]);
                any = 1;
            }
            if ((i & 0xffff) == 0 &&
                !vp_report_progress(ctx, (double)i / (double)p->count, "writing OBJ")) {
                cancelled = 1;
                break;
            }
            if (p->shape == VP_SHAPE_MIXED) m = units[p->shape_index[i]];
            double q[4] = {0, 0, 0, 1}, s = vpio_radius(p, i);
            if (p->has_orient) vp_quat_from_float(vpio_orient(p, i), q);
            const double *c = p->positions + 3 * i;
            for (int k = 0; k < m.nv; k++) {
                double w[3];
                vp_quat_rotate(q, m.v[k], w);
                fprintf(f, "v %.9g %.9g %.9g\n", c[0] + s * w[0], c[1] + s * w[1], c[2] + s * w[2]);
            }
            for (int k = 0; k < m.nf; k++) {
                fputc('f', f);
                for (int e = 0; e < m.fsize[k]; e++)
                    fprintf(f, " %llu", base + (unsigned long long)m.f[k][e]);
                fputc('\n', f);
            }
            base += (unsigned long long)m.nv;
        }
    }
    units_free(units, nunits);
    if (cancelled) {
        vpio_close(ctx, &o, 1);
        return vp_fail(ctx, VP_ERR_CANCELLED, "%s: cancelled", path);
    }
    return vpio_close(ctx, &o, 0);
}

vp_result vp_mesh_shape_write_obj(vp_context *ctx, const vp_mesh_shape *s, const char *path) {
    if (!s) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "no mesh shape");
    vpio_out o;
    vp_result r = vpio_open(ctx, path, &o);
    if (r != VP_OK) return r;
    fprintf(o.f,
            "# vdbpack %s unit shape from %s: bounding-sphere radius 1 about the centroid\n"
            "# of its volume, which is at the origin. Instance it at each point scaled by\n"
            "# pscale and rotated by orient.\n",
            VP_VERSION_STRING, s->name);
    fprintf(o.f, "o %s\n", s->name);
    for (size_t v = 0; v < s->nverts; v++)
        fprintf(o.f, "v %.17g %.17g %.17g\n", s->verts[3 * v], s->verts[3 * v + 1],
                s->verts[3 * v + 2]);
    for (size_t t = 0; t < s->ntris; t++)
        fprintf(o.f, "f %u %u %u\n", s->tris[3 * t] + 1, s->tris[3 * t + 1] + 1,
                s->tris[3 * t + 2] + 1);
    return vpio_close(ctx, &o, 0);
}

vp_result vp_particles_write_shapes_obj(vp_context *ctx, const vp_particles *p, const char *path) {
    if (!p) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "no particles");
    unit_mesh units[VP_MAX_SHAPES];
    unsigned nunits = 0;
    vp_result r = units_for(ctx, path, p, clamp_subdiv(0), units, &nunits);
    vpio_out o;
    if (r == VP_OK) r = vpio_open(ctx, path, &o);
    if (r != VP_OK) {
        units_free(units, nunits);
        return r;
    }
    char list[4096];
    fprintf(o.f,
            "# vdbpack %s unit shapes (%s): bounding-sphere radius 1, centroid at the\n"
            "# origin. Group shapeK is the shape of the points whose shape attribute is K;\n"
            "# instance it at each such point scaled by pscale and rotated by orient.\n",
            VP_VERSION_STRING, vp_particles_shape_list(p, list, sizeof list));
    unsigned long long base = 1;
    for (unsigned k = 0; k < nunits; k++) {
        const unit_mesh *m = &units[k];
        fprintf(o.f, "o shape%u\ng shape%u\n", k, k);
        for (int v = 0; v < m->nv; v++)
            fprintf(o.f, "v %.17g %.17g %.17g\n", m->v[v][0], m->v[v][1], m->v[v][2]);
        for (int t = 0; t < m->nf; t++) {
            fputc('f', o.f);
            for (int e = 0; e < m->fsize[t]; e++)
                fprintf(o.f, " %llu", base + (unsigned long long)m->f[t][e]);
            fputc('\n', o.f);
        }
        base += (unsigned long long)m->nv;
    }
    units_free(units, nunits);
    return vpio_close(ctx, &o, 0);
}
