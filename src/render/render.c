/* SPDX-License-Identifier: Apache-2.0 */
/* Preview renderer: one primary ray a pixel through a uniform grid (3D-DDA)
 * over the particles, spheres solved in closed form and polyhedra by
 * clipping the ray against their face planes (and the cut plane), lit by a
 * key light with hard shadows and a few ambient-occlusion rays. Every
 * pixel's random numbers come from its own index, so the image does not
 * depend on the thread count. See docs/render.md. */
#include "vdbpack/vdbpack.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/context.h"
#include "core/geom.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/mesh_shape.h"
#include "core/sgrid.h"
#include "core/shape.h"
#include "core/superball.h"

void vp_render_params_init(vp_render_params *p) {
    if (!p) return;
    memset(p, 0, sizeof *p);
    p->width = 960;
    p->height = 540;
    p->view = VP_VIEW_ISO;
    p->fov_degrees = 30.0;
    p->colour = VP_COLOUR_PASS;
    p->cut_axis = -1;
    p->ao_samples = 8;
    p->shadows = 1;
}

void vp_image_destroy(vp_image *img) {
    if (!img) return;
    free(img->rgba);
    free(img->z);
    free(img->id);
    free(img);
}

/* --- the scene: particles behind a uniform grid -------------------------- */

/* One shape as the ray tests see it. */
typedef struct render_kind {
    const vp_polyhedron *poly; /* NULL: spheres (or a mesh) */
    const vp_mesh_shape *mesh; /* a mesh shape (superballs: their tessellation), or NULL */
    double inradius;
} render_kind;

typedef struct scene {
    const vp_particles *p;
    render_kind kind[VP_MAX_SHAPES]; /* kind[0]; a mixed set: kind[shape_index] */
    int mixed;
    int cut_axis;
    double cut_value;
    double bmin[3], bmax[3]; /* grid bounds */
    double h, inv_h;         /* cell edge */
    int n[3];
    uint32_t *cell_start; /* n0*n1*n2 + 1 offsets into refs */
    uint32_t *refs;       /* particle indices, by cell */
    double rmin, rmax, rmean;
    uint8_t *contacts; /* per particle, VP_COLOUR_CONTACTS only */
} scene;

typedef struct hit {
    double t;
    double n[3];  /* outward unit normal at the hit */
    uint32_t idx; /* particle index */
} hit;

static double radius_of(const vp_particles *p, size_t i) {
    return p->radii ? (double)p->radii[i] : (double)p->uniform_radius;
}

/* Particles that draw anything: a finite centre, a positive finite radius,
 * and not wholly on the + side of the cut. */
static int particle_kept(const scene *S, size_t i) {
    const double *c = S->p->positions + 3 * i;
    double r = radius_of(S->p, i);
    if (!(r > 0) || !isfinite(r) || !isfinite(c[0]) || !isfinite(c[1]) || !isfinite(c[2])) return 0;
    if (S->cut_axis >= 0) {
        /* a solid's nearest point to the plane lies at most r and at least
         * its inradius below the centre; r is the safe bound */
        if (c[S->cut_axis] - r > S->cut_value) return 0;
    }
    return 1;
}

static void cell_range(const scene *S, const double *c, double r, int lo[3], int hi[3]) {
    for (int k = 0; k < 3; k++) {
        double a = (c[k] - r - S->bmin[k]) * S->inv_h, b = (c[k] + r - S->bmin[k]) * S->inv_h;
        int ia = (int)floor(a), ib = (int)floor(b);
        if (ia < 0) ia = 0;
        if (ib > S->n[k] - 1) ib = S->n[k] - 1;
        if (ia > ib) ia = ib; /* cut-clamped bounds */
        lo[k] = ia;
        hi[k] = ib;
    }
}

/* One pass over every kept particle's cell range, in index order (so the
 * grid is deterministic): fill NULL counts the references of each cell
 * (into cell_start[c + 1]); otherwise each reference is stored at fill[c]++. */
static void grid_pass(scene *S, const vp_particles *p, uint32_t *fill) {
    for (size_t i = 0; i < p->count; i++) {
        if (!particle_kept(S, i)) continue;
        int lo[3], hi[3];
        cell_range(S, p->positions + 3 * i, radius_of(p, i), lo, hi);
        for (int z = lo[2]; z <= hi[2]; z++)
            for (int y = lo[1]; y <= hi[1]; y++)
                for (int x = lo[0]; x <= hi[0]; x++) {
                    size_t c = ((size_t)z * S->n[1] + y) * S->n[0] + x;
                    if (fill) S->refs[fill[c]++] = (uint32_t)i;
                    else S->cell_start[c + 1]++;
                }
    }
}

uint64_t vp_render_grid_bytes(size_t count, double refs_per_particle) {
    /* refs (4 B each) + at most ~1 cell a particle (4 B) + the per-image
     * bookkeeping, which is small */
    return (uint64_t)((double)count * (refs_per_particle * 4.0 + 4.0)) + 4096;
}

static vp_result scene_build(vp_context *ctx, scene *S, uint64_t budget) {
    const vp_particles *p = S->p;
    size_t kept = 0;
    double rsum = 0;
    S->rmin = HUGE_VAL;
    S->rmax = 0;
    for (int k = 0; k < 3; k++) S->bmin[k] = HUGE_VAL, S->bmax[k] = -HUGE_VAL;
    for (size_t i = 0; i < p->count; i++) {
        if (!particle_kept(S, i)) continue;
        const double *c = p->positions + 3 * i;
        double r = radius_of(p, i);
        for (int k = 0; k < 3; k++) {
            if (c[k] - r < S->bmin[k]) S->bmin[k] = c[k] - r;
            if (c[k] + r > S->bmax[k]) S->bmax[k] = c[k] + r;
        }
        if (r < S->rmin) S->rmin = r;
        if (r > S->rmax) S->rmax = r;
        rsum += r;
        kept++;
    }
    if (kept == 0 && S->cut_axis >= 0)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "nothing to render: the cut removes every particle (all lie where %c > %g)",
                       "xyz"[S->cut_axis], S -> cut_value);
    if (kept == 0)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "nothing to render: no particle with a positive radius");
    if (kept > UINT32_MAX - 1)
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "too many particles to render (%zu)", kept);
    if (S->cut_axis >= 0 && S->bmax[S->cut_axis] > S->cut_value)
        S->bmax[S->cut_axis] = S->cut_value;
    S->rmean = rsum / (double)kept;
    /* Cell edge: about one particle a cell for sparse sets, at least a mean
     * diameter for dense ones (each particle then overlaps about 8 cells). */
    double ext[3], vol = 1;
    for (int k = 0; k < 3; k++) {
        ext[k] = S->bmax[k] - S->bmin[k];
        if (!(ext[k] > 0)) ext[k] = S->rmean;
        vol *= ext[k];
    }
    double h = fmax(cbrt(vol / (double)kept), 2.0 * S->rmean);
    for (;;) {
        double cells = 1;
        for (int k = 0; k < 3; k++) {
            double nk = ceil(ext[k] / h);
            S->n[k] = nk < 1 ? 1 : (int)nk;
            cells *= S->n[k];
        }
        if (cells <= 2.0 * (double)kept + 64 && cells < 1e9) break;
        h *= 1.25;
    }
    S->h = h;
    S->inv_h = 1.0 / h;
    size_t ncells = (size_t)S->n[0] * (size_t)S->n[1] * (size_t)S->n[2];

    /* counting sort of (cell, particle) references */
    uint64_t total = 0;
    for (size_t i = 0; i < p->count; i++) {
        if (!particle_kept(S, i)) continue;
        int lo[3], hi[3];
        cell_range(S, p->positions + 3 * i, radius_of(p, i), lo, hi);
        total += (uint64_t)(hi[0] - lo[0] + 1) * (uint64_t)(hi[1] - lo[1] + 1) *
                 (uint64_t)(hi[2] - lo[2] + 1);
    }
    uint64_t bytes = total * 4 + (uint64_t)(ncells + 1) * 4;
    if (total >= UINT32_MAX || bytes > budget) {
        char b[32];
        vp_format_bytes((double)bytes, b, sizeof b);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY,
                       "render: the acceleration grid would need %s (%llu cell references), "
                       "more than the memory left",
                       b, (unsigned long long)total);
    }
    S->cell_start = calloc(ncells + 1, sizeof(uint32_t));
    S->refs = malloc((size_t)(total ? total : 1) * sizeof(uint32_t));
    if (!S->cell_start || !S->refs)
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "render: out of memory for the grid");
    grid_pass(S, p, NULL);
    for (size_t c = 0; c < ncells; c++) S->cell_start[c + 1] += S->cell_start[c];
    uint32_t *fill = malloc(ncells * sizeof(uint32_t));
    if (!fill) return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "render: out of memory for the grid");
    memcpy(fill, S->cell_start, ncells * sizeof(uint32_t));
    grid_pass(S, p, fill);
    free(fill);
    return VP_OK;
}

/* --- ray / particle ------------------------------------------------------ */

/* Clips [*t0, *t1] by the cut half-space; *entered = 1 when the cut plane
 * becomes the entry face. Returns 0 when nothing is left. */
static int clip_cut(const scene *S, const double o[3], const double d[3], double *t0, double *t1,
                    int *entered) {
    *entered = 0;
    if (S->cut_axis < 0) return 1;
    int a = S->cut_axis;
    double da = d[a], num = S->cut_value - o[a];
    if (da == 0) return num >= 0;
    double tp = num / da;
    if (da > 0) {
        if (tp < *t1) *t1 = tp;
    } else if (tp > *t0) {
        *t0 = tp;
        *entered = 1;
    }
    return *t0 <= *t1;
}

/* Nearest entry of the ray into particle i with tmin < t < h->t; updates h. */
static void intersect(const scene *S, uint32_t i, const double o[3], const double d[3], double tmin,
                      hit *h) {
    const double *c = S->p->positions + 3 * (size_t)i;
    double r = radius_of(S->p, i);
    double oc[3] = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
    /* bounding sphere (d is unit length) */
    double b = vp_dot3(oc, d), cc = vp_dot3(oc, oc) - r * r;
    double disc = b * b - cc;
    if (disc < 0) return;
    double sq = sqrt(disc);
    double t0 = -b - sq, t1 = -b + sq;
    if (t1 <= tmin || t0 >= h->t) return;
    double n[3];
    const render_kind *K = &S->kind[S->mixed ? S->p->shape_index[i] : 0];
    if (K->mesh) {
        /* in the shape's frame; a particle crossing the cut plane shows its
         * surface up to the plane, open (no cut face: a concave shape has
         * no single interval along the ray) */
        double q[4], m[3][3];
        if (S->p->orients) vp_quat_from_float(S->p->orients + 4 * (size_t)i, q);
        else vp_quat_from_float(S->p->uniform_orient, q);
        vp_quat_to_matrix(q, m);
        double lo[3], ld[3], ln[3], th;
        for (int k = 0; k < 3; k++) {
            lo[k] = (m[0][k] * oc[0] + m[1][k] * oc[1] + m[2][k] * oc[2]) / r;
            ld[k] = (m[0][k] * d[0] + m[1][k] * d[1] + m[2][k] * d[2]) / r;
        }
        double ta = t0 > tmin ? t0 : tmin, tb = t1 < h->t ? t1 : h->t;
        int cut;
        if (!clip_cut(S, o, d, &ta, &tb, &cut)) return;
        if (!vp_mesh_shape_ray(K->mesh, lo, ld, ta, tb, &th, ln)) return;
        for (int k = 0; k < 3; k++) n[k] = m[k][0] * ln[0] + m[k][1] * ln[1] + m[k][2] * ln[2];
        h->t = th;
        h->idx = i;
        memcpy(h->n, n, sizeof n);
        return;
    }
    if (!K->poly) {
        int cut;
        if (!clip_cut(S, o, d, &t0, &t1, &cut)) return;
        if (!(t0 > tmin && t0 < h->t)) return;
        if (cut) {
            n[0] = n[1] = n[2] = 0;
            n[S->cut_axis] = 1;
        } else {
            for (int k = 0; k < 3; k++) n[k] = (oc[k] + t0 * d[k]) / r;
        }
    } else {
        double q[4], m[3][3];
        if (S->p->orients) vp_quat_from_float(S->p->orients + 4 * (size_t)i, q);
        else vp_quat_from_float(S->p->uniform_orient, q);
        vp_quat_to_matrix(q, m);
        /* local = R^T (x - c) / r */
        double lo[3], ld[3];
        for (int k = 0; k < 3; k++) {
            lo[k] = (m[0][k] * oc[0] + m[1][k] * oc[1] + m[2][k] * oc[2]) / r;
            ld[k] = (m[0][k] * d[0] + m[1][k] * d[1] + m[2][k] * d[2]) / r;
        }
        const vp_polyhedron *P = K->poly;
        int face = -1;
        t0 = -HUGE_VAL;
        t1 = HUGE_VAL;
        for (int f = 0; f < P->nfaces; f++) {
            double den = vp_dot3(P->normals[f], ld), num = K->inradius - vp_dot3(P->normals[f], lo);
            if (den == 0) {
                if (num < 0) return;
                continue;
            }
            double t = num / den;
            if (den < 0) {
                if (t > t0) t0 = t, face = f;
            } else if (t < t1) {
                t1 = t;
            }
            if (t0 > t1) return;
        }
        int cut;
        if (!clip_cut(S, o, d, &t0, &t1, &cut)) return;
        if (face < 0 && !cut) return;
        if (!(t0 > tmin && t0 < h->t)) return;
        if (cut) {
            n[0] = n[1] = n[2] = 0;
            n[S->cut_axis] = 1;
        } else {
            const double *ln = P->normals[face];
            for (int k = 0; k < 3; k++) n[k] = m[k][0] * ln[0] + m[k][1] * ln[1] + m[k][2] * ln[2];
        }
    }
    h->t = t0;
    h->idx = i;
    memcpy(h->n, n, sizeof n);
}

/* Walks the grid cells the ray crosses (Amanatides & Woo) and returns 1 with
 * the nearest hit in (tmin, tmax), skipping particle `skip`; with any = 1
 * it returns at the first hit found. */
static int trace(const scene *S, const double o[3], const double d[3], double tmin, double tmax,
                 uint32_t skip, int any, hit *h) {
    double t0 = tmin, t1 = tmax;
    double inv[3];
    for (int k = 0; k < 3; k++) {
        inv[k] = 1.0 / d[k]; /* +-inf for 0: the slab test below still works */
        double a = (S->bmin[k] - o[k]) * inv[k], b = (S->bmax[k] - o[k]) * inv[k];
        if (d[k] == 0) {
            if (o[k] < S->bmin[k] || o[k] > S->bmax[k]) return 0;
            continue;
        }
        if (a > b) {
            double x = a;
            a = b;
            b = x;
        }
        if (a > t0) t0 = a;
        if (b < t1) t1 = b;
        if (t0 > t1) return 0;
    }
    int cell[3], step[3];
    double tnext[3], tdelta[3];
    for (int k = 0; k < 3; k++) {
        double x = o[k] + t0 * d[k];
        int ck = (int)floor((x - S->bmin[k]) * S->inv_h);
        if (ck < 0) ck = 0;
        if (ck >= S->n[k]) ck = S->n[k] - 1;
        cell[k] = ck;
        if (d[k] > 0) {
            step[k] = 1;
            tnext[k] = (S->bmin[k] + (ck + 1) * S->h - o[k]) * inv[k];
            tdelta[k] = S->h * inv[k];
        } else if (d[k] < 0) {
            step[k] = -1;
            tnext[k] = (S->bmin[k] + ck * S->h - o[k]) * inv[k];
            tdelta[k] = -S->h * inv[k];
        } else {
            step[k] = 0;
            tnext[k] = HUGE_VAL;
            tdelta[k] = HUGE_VAL;
        }
    }
    h->t = tmax;
    int found = 0;
    for (;;) {
        size_t ci = ((size_t)cell[2] * S->n[1] + cell[1]) * S->n[0] + cell[0];
        for (uint32_t j = S->cell_start[ci]; j < S->cell_start[ci + 1]; j++) {
            uint32_t i = S->refs[j];
            if (i == skip) continue;
            double before = h->t;
            intersect(S, i, o, d, tmin, h);
            if (h->t < before) {
                found = 1;
                if (any) return 1;
            }
        }
        int k = tnext[0] < tnext[1] ? (tnext[0] < tnext[2] ? 0 : 2) : (tnext[1] < tnext[2] ? 1 : 2);
        double texit = tnext[k];
        if (found && h->t <= texit) return 1;
        if (texit > t1) return found;
        cell[k] += step[k];
        if (cell[k] < 0 || cell[k] >= S->n[k]) return found;
        tnext[k] += tdelta[k];
    }
}

/* --- camera and shading -------------------------------------------------- */

typedef struct camera {
    double eye[3], fwd[3], right[3], up[3];
    double focal; /* pixels */
    int w, h;
} camera;

static int normalize(double v[3]) {
    double n = vp_norm3(v);
    if (!(n > 0) || !isfinite(n)) return 0;
    v[0] /= n;
    v[1] /= n;
    v[2] /= n;
    return 1;
}

static int camera_basis(camera *C, const double up_hint[3]) {
    double up[3] = {up_hint[0], up_hint[1], up_hint[2]};
    if (!normalize(up)) up[0] = 0, up[1] = 1, up[2] = 0;
    vp_cross3(C->fwd, up, C->right);
    if (!normalize(C->right)) {
        /* looking along the up direction: take -Z (or +Y) as up instead */
        double alt[3] = {0, 0, -1};
        if (fabs(C->fwd[2]) > 0.9) alt[1] = 1, alt[2] = 0;
        vp_cross3(C->fwd, alt, C->right);
        if (!normalize(C->right)) return 0;
    }
    vp_cross3(C->right, C->fwd, C->up);
    return normalize(C->up);
}

static vp_result camera_setup(vp_context *ctx, const scene *S, const vp_render_params *rp,
                              camera *C) {
    C->w = rp->width;
    C->h = rp->height;
    double half = rp->fov_degrees * M_PI / 360.0;
    C->focal = 0.5 * rp->height / tan(half);
    if (rp->view == VP_VIEW_CAMERA) {
        for (int k = 0; k < 3; k++) {
            C->eye[k] = rp->eye[k];
            C->fwd[k] = rp->target[k] - rp->eye[k];
        }
        if (!isfinite(vp_norm3(C->eye)) || !normalize(C->fwd))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "render: the camera's eye and target must be distinct finite points");
        if (!camera_basis(C, rp->up))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "render: the camera's up direction is "
                           "parallel to its view direction");
        return VP_OK;
    }
    double up[3] = {0, 1, 0};
    if (rp->view == VP_VIEW_FRONT) {
        C->fwd[0] = 0, C->fwd[1] = 0, C->fwd[2] = -1;
    } else if (rp->view == VP_VIEW_TOP) {
        C->fwd[0] = 0, C->fwd[1] = -1, C->fwd[2] = 0;
        up[1] = 0, up[2] = -1;
    } else {
        C->fwd[0] = C->fwd[1] = C->fwd[2] = -1.0 / sqrt(3.0);
    }
    camera_basis(C, up);
    /* Distance from the centre of the bounds at which all 8 corners fall in
     * the frame (with a 4 % margin). */
    double c[3], dist = 0;
    for (int k = 0; k < 3; k++) c[k] = 0.5 * (S->bmin[k] + S->bmax[k]);
    double tx = tan(half) * rp->width / rp->height, ty = tan(half);
    for (int m = 0; m < 8; m++) {
        double v[3];
        for (int k = 0; k < 3; k++) v[k] = ((m >> k) & 1 ? S->bmax[k] : S->bmin[k]) - c[k];
        double x = fabs(vp_dot3(v, C->right)), y = fabs(vp_dot3(v, C->up)), z = vp_dot3(v, C->fwd);
        double need = fmax(x / (tx / 1.04), y / (ty / 1.04)) - z;
        if (need > dist) dist = need;
    }
    for (int k = 0; k < 3; k++) C->eye[k] = c[k] - dist * C->fwd[k];
    return VP_OK;
}

static void hsv(double hdeg, double s, double v, float out[3]) {
    double c = v * s, hp = fmod(hdeg, 360.0) / 60.0, x = c * (1 - fabs(fmod(hp, 2.0) - 1));
    double r = 0, g = 0, b = 0;
    if (hp < 1) r = c, g = x;
    else if (hp < 2) r = x, g = c;
    else if (hp < 3) g = c, b = x;
    else if (hp < 4) g = x, b = c;
    else if (hp < 5) r = x, b = c;
    else r = c, b = x;
    out[0] = (float)(r + v - c), out[1] = (float)(g + v - c), out[2] = (float)(b + v - c);
}

static void base_colour(const scene *S, vp_render_colour mode, uint32_t i, float out[3]) {
    /* linear RGB; the pass palette is 8 well separated hues */
    static const float pal[8][3] = {
        {0.80f, 0.33f, 0.10f}, {0.10f, 0.38f, 0.80f}, {0.25f, 0.65f, 0.15f}, {0.85f, 0.65f, 0.05f},
        {0.55f, 0.20f, 0.70f}, {0.05f, 0.60f, 0.60f}, {0.80f, 0.15f, 0.35f}, {0.55f, 0.55f, 0.55f}};
    if (mode == VP_COLOUR_PASS) {
        unsigned g = S->p->groups ? S->p->groups[i] : 0;
        memcpy(out, pal[g % 8], 3 * sizeof(float));
    } else if (mode == VP_COLOUR_SIZE) {
        double r = radius_of(S->p, i);
        double t = S->rmax > S->rmin ? (r - S->rmin) / (S->rmax - S->rmin) : 0.5;
        hsv(240.0 - 180.0 * t, 0.85, 0.85, out); /* blue (small) to yellow (large) */
    } else if (mode == VP_COLOUR_CONTACTS) {
        static const float zc[6][3] = {{0.45f, 0.45f, 0.45f}, {0.10f, 0.25f, 0.85f},
                                       {0.05f, 0.65f, 0.75f}, {0.20f, 0.70f, 0.15f},
                                       {0.90f, 0.75f, 0.05f}, {0.85f, 0.12f, 0.08f}};
        unsigned z = S->contacts ? S->contacts[i] : 0;
        memcpy(out, zc[z < 4 ? 0 : z > 8 ? 5 : z - 3], 3 * sizeof(float));
    } else {
        uint64_t x = vp_rng_mix(i);
        hsv((double)(x % 360), 0.55 + 0.3 * (double)((x >> 16) % 100) / 100.0, 0.85, out);
    }
}

typedef struct render_job {
    const scene *S;
    const camera *C;
    const vp_render_params *rp;
    vp_image *img;
    double light[3];
    double ao_dist;
    int rows_per_chunk;
    int first_chunk;
} render_job;

static void shade_pixel(const render_job *J, int px, int py) {
    const scene *S = J->S;
    const camera *C = J->C;
    size_t pi = (size_t)py * (size_t)C->w + (size_t)px;
    double u = (px + 0.5 - 0.5 * C->w), v = (0.5 * C->h - py - 0.5);
    double d[3];
    for (int k = 0; k < 3; k++) d[k] = C->fwd[k] * C->focal + C->right[k] * u + C->up[k] * v;
    normalize(d);
    hit h;
    float *rgba = J->img->rgba + 4 * pi;
    if (!trace(S, C->eye, d, 0.0, HUGE_VAL, UINT32_MAX, 0, &h)) {
        rgba[0] = rgba[1] = rgba[2] = rgba[3] = 0;
        J->img->z[pi] = INFINITY;
        J->img->id[pi] = VP_RENDER_BACKGROUND_ID;
        return;
    }
    /* facing the camera (a cut face seen from behind stays lit the same) */
    if (vp_dot3(h.n, d) > 0)
        for (int k = 0; k < 3; k++) h.n[k] = -h.n[k];
    double x[3];
    double r = radius_of(S->p, h.idx);
    double eps = 1e-6 * fmax(r, h.t * 1e-3);
    for (int k = 0; k < 3; k++) x[k] = C->eye[k] + h.t * d[k] + eps * h.n[k];
    double diffuse = vp_dot3(h.n, J->light);
    if (diffuse < 0) diffuse = 0;
    if (diffuse > 0 && J->rp->shadows) {
        hit sh;
        if (trace(S, x, J->light, 0.0, HUGE_VAL, h.idx, 1, &sh)) diffuse = 0;
    }
    double ao = 1.0;
    int na = J->rp->ao_samples;
    if (na > 0) {
        /* cosine-weighted directions around n, at most ao_dist away */
        double t1[3], t2[3], a[3] = {1, 0, 0};
        if (fabs(h.n[0]) > 0.9) a[0] = 0, a[1] = 1;
        vp_cross3(h.n, a, t1);
        normalize(t1);
        vp_cross3(h.n, t1, t2);
        /* the same directions (in the frame of the normal) for every pixel
         * of a particle: smooth shading instead of per-pixel noise */
        uint64_t s = vp_rng_mix((uint64_t)h.idx * 0x2545F4914F6CDD1Dull + 1);
        double open = 0;
        for (int j = 0; j < na; j++) {
            /* stratified in the azimuth so 4 rays cover the hemisphere */
            double e1 = vp_rng_chain_uniform(&s), e2 = (j + vp_rng_chain_uniform(&s)) / na;
            double sr = sqrt(e1), phi = 2 * M_PI * e2, z = sqrt(1 - e1);
            double dir[3];
            for (int k = 0; k < 3; k++)
                dir[k] = t1[k] * sr * cos(phi) + t2[k] * sr * sin(phi) + h.n[k] * z;
            /* obscurance: a near occluder darkens more than a far one */
            hit ah;
            if (!trace(S, x, dir, 0.0, J->ao_dist, h.idx, 0, &ah)) open += 1;
            else open += ah.t / J->ao_dist;
        }
        ao = open / na;
    }
    float base[3];
    base_colour(S, J->rp->colour, h.idx, base);
    double light = 0.40 * (0.2 + 0.8 * ao) + 0.75 * diffuse;
    for (int k = 0; k < 3; k++) rgba[k] = (float)(base[k] * light);
    rgba[3] = 1.0f;
    J->img->z[pi] = (float)h.t;
    J->img->id[pi] = h.idx;
}

static void render_chunk(void *user, size_t i) {
    const render_job *J = user;
    int y0 = (J->first_chunk + (int)i) * J->rows_per_chunk;
    int y1 = y0 + J->rows_per_chunk;
    if (y1 > J->C->h) y1 = J->C->h;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < J->C->w; x++) shade_pixel(J, x, y);
}

/* ---- contacts (VP_COLOUR_CONTACTS) -------------------------------------- */

#define CONTACT_GAP 1e-4 /* of r_i + r_j: the jam packer's contact */

typedef struct contact_q {
    const vp_particles *p;
    uint8_t *z;
    size_t i;
} contact_q;

static int contact_visit(void *user, uint32_t j) {
    contact_q *q = user;
    if (j <= q->i) return 0; /* each pair once */
    const double *a = q->p->positions + 3 * q->i, *b = q->p->positions + 3 * (size_t)j;
    double e = radius_of(q->p, q->i) + radius_of(q->p, j);
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    if (sqrt(dx * dx + dy * dy + dz * dz) - e < CONTACT_GAP * e) {
        if (q->z[q->i] < 255) q->z[q->i]++;
        if (q->z[j] < 255) q->z[j]++;
    }
    return 0;
}

/* S->contacts: each sphere's count of touching neighbours, over the whole
 * set (a cut does not change them). Owned by S. */
static vp_result count_contacts(vp_context *ctx, scene *S) {
    const vp_particles *p = S->p;
    size_t n = p->count;
    if (p->shape != VP_SHAPE_SPHERE)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "render: --colour contacts is for sphere packings only");
    S->contacts = calloc(n ? n : 1, 1);
    if (!S->contacts) return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "render: out of memory");
    if (n < 2) return VP_OK;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    double rmin = HUGE_VAL, rmax = 0;
    for (size_t i = 0; i < n; i++) {
        double r = radius_of(p, i);
        if (r < rmin) rmin = r;
        if (r > rmax) rmax = r;
        for (int k = 0; k < 3; k++) {
            double c = p->positions[3 * i + k];
            if (c < lo[k]) lo[k] = c;
            if (c > hi[k]) hi[k] = c;
        }
    }
    vp_sgrid g;
    if (!(rmin > 0) || vp_sgrid_init(&g, lo, hi, rmin, rmax, 2 * n + 4096) != 0)
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "render: out of memory for the contacts");
    vp_result res = VP_OK;
    for (size_t i = 0; i < n && res == VP_OK; i++)
        if (vp_sgrid_insert(&g, (uint32_t)i, p->positions + 3 * i, radius_of(p, i)) != 0)
            res = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "render: out of memory for the contacts");
    contact_q q = {p, S->contacts, 0};
    for (size_t i = 0; i < n && res == VP_OK; i++) {
        q.i = i;
        double reach = radius_of(p, i) * (1.0 + CONTACT_GAP) + rmax * CONTACT_GAP;
        vp_sgrid_query(&g, p->positions + 3 * i, reach, contact_visit, &q);
    }
    vp_sgrid_free(&g);
    return res;
}

vp_result vp_render(vp_context *ctx, const vp_particles *p, const vp_render_params *params,
                    vp_image **out) {
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "vp_render: out is NULL");
    *out = NULL;
    if (!p) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "vp_render: no particle set");
    vp_render_params rp;
    if (params) rp = *params;
    else vp_render_params_init(&rp);
    if (rp.width < 1 || rp.height < 1 || rp.width > VP_RENDER_MAX_SIDE ||
        rp.height > VP_RENDER_MAX_SIDE ||
        (uint64_t)rp.width * (uint64_t)rp.height > VP_RENDER_MAX_PIXELS)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "render: image size %dx%d out of range (each side 1..%d, at most %u "
                       "pixels)",
                       rp.width, rp.height, VP_RENDER_MAX_SIDE, VP_RENDER_MAX_PIXELS);
    if (!(rp.fov_degrees > 0.1 && rp.fov_degrees < 179))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "render: field of view %g degrees out of range (0.1..179)", rp.fov_degrees);
    if (rp.view < VP_VIEW_ISO || rp.view > VP_VIEW_CAMERA || rp.colour < VP_COLOUR_PASS ||
        rp.colour > VP_COLOUR_CONTACTS || rp.cut_axis < -1 || rp.cut_axis > 2 ||
        (rp.cut_axis >= 0 && !isfinite(rp.cut_value)) || rp.ao_samples < 0 || rp.ao_samples > 64)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "render: invalid view, colour, cut or "
                       "ambient-occlusion setting");
    if (p->count == 0)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "nothing to render: the set has no particles");
    if (p->count > UINT32_MAX - 1)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "render: at most %u particles (ids are 32-bit)", UINT32_MAX - 1);

    uint64_t npix = (uint64_t)rp.width * (uint64_t)rp.height;
    uint64_t img_bytes = npix * 24;
    uint64_t limit = vp_memory_limit(ctx);
    if (img_bytes > limit)
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY,
                       "render: a %dx%d image needs more memory than "
                       "the limit",
                       rp.width, rp.height);

    scene S;
    memset(&S, 0, sizeof S);
    S.p = p;
    S.mixed = p->shape == VP_SHAPE_MIXED;
    if (S.mixed && (!p->shape_index || p->shape_count < 1 || p->shape_count > VP_MAX_SHAPES))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "render: a mixed set without its shapes");
    for (size_t i = 0; S.mixed && i < p->count; i++)
        if (p->shape_index[i] >= p->shape_count)
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "render: particle %zu has shape %u of %u",
                           i, (unsigned)p->shape_index[i], p->shape_count);
    for (unsigned k = 0; k < (S.mixed ? p->shape_count : 1); k++) {
        vp_shape_ref ref = S.mixed ? p->shapes[k] : vp_particles_shape_of(p, 0);
        render_kind *K = &S.kind[k];
        if (ref.shape == VP_SHAPE_MESH && !ref.mesh)
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "render: the particles are of a mesh shape: give the mesh (vdbpack "
                           "render --shape FILE)");
        K->poly =
            p->has_orient || ref.shape != VP_SHAPE_SPHERE ? vp_shape_polyhedron(ref.shape) : NULL;
        K->mesh = ref.shape == VP_SHAPE_MESH        ? ref.mesh
                  : ref.shape == VP_SHAPE_SUPERBALL ? vp_superball_mesh(ref.param, NULL)
                                                    : NULL;
        if (ref.shape == VP_SHAPE_SUPERBALL && !K->mesh)
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "render: a superball's exponent must be in [0.5, 1000], not %g",
                           ref.param);
        K->inradius = K->poly ? K->poly->inradius : 1.0;
    }
    S.cut_axis = rp.cut_axis;
    S.cut_value = rp.cut_value;
    vp_result r = scene_build(ctx, &S, limit - img_bytes);
    vp_image *img = NULL;
    if (r != VP_OK) goto done;
    if (rp.colour == VP_COLOUR_CONTACTS && (r = count_contacts(ctx, &S)) != VP_OK) goto done;

    camera C;
    if ((r = camera_setup(ctx, &S, &rp, &C)) != VP_OK) goto done;

    img = calloc(1, sizeof *img);
    if (img) {
        img->width = rp.width;
        img->height = rp.height;
        img->rgba = malloc((size_t)npix * 4 * sizeof(float));
        img->z = malloc((size_t)npix * sizeof(float));
        img->id = malloc((size_t)npix * sizeof(uint32_t));
    }
    if (!img || !img->rgba || !img->z || !img->id) {
        r = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "render: out of memory for a %dx%d image", rp.width,
                    rp.height);
        goto done;
    }

    render_job J;
    J.S = &S;
    J.C = &C;
    J.rp = &rp;
    J.img = img;
    /* key light from the upper left, a little behind the camera */
    for (int k = 0; k < 3; k++) J.light[k] = -0.55 * C.right[k] + 0.80 * C.up[k] - 0.25 * C.fwd[k];
    normalize(J.light);
    J.ao_dist = 2.5 * S.rmean;
    J.rows_per_chunk = 8;
    int nchunks = (rp.height + J.rows_per_chunk - 1) / J.rows_per_chunk;
    int threads = vp_threads_for(ctx);
    /* batches between progress reports (and the chance to cancel) */
    const int batch = 16;
    for (int c0 = 0; c0 < nchunks; c0 += batch) {
        int n = nchunks - c0 < batch ? nchunks - c0 : batch;
        J.first_chunk = c0;
        vp_parallel_for(threads, (size_t)n, render_chunk, &J);
        if (!vp_report_progress(ctx, (double)(c0 + n) / nchunks, "rendering")) {
            r = vp_fail(ctx, VP_ERR_CANCELLED, "render: cancelled");
            goto done;
        }
    }
    *out = img;
    img = NULL;
    r = VP_OK;
done:
    vp_image_destroy(img);
    free(S.cell_start);
    free(S.refs);
    free(S.contacts);
    return r;
}
