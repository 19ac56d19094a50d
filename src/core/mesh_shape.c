/* SPDX-License-Identifier: Apache-2.0 */
/* Mesh-shaped particles: a closed mesh read through Assimp (src/mesh),
 * normalised to its volume centroid and bounding radius 1, with a BVH over
 * its triangles. Two placed copies overlap when a pair of their triangles
 * crosses or one holds a component of the other; both tests are exact up
 * to double rounding (no bounding spheres, no sampling). See mesh_shape.h. */
#include "core/mesh_shape.h"
#include "core/container.h"
#include "core/context.h"
#include "core/geom.h"
#include "core/mesh_topo.h"
#include "core/shape.h"
#include "core/superball.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* --- BVH ----------------------------------------------------------------------- */

typedef struct bvh_build {
    vp_mesh_shape *m;
    double *cent; /* 3*ntris triangle centroids */
    struct bvh_key {
        double key;
        uint32_t tri;
    } * keys; /* ntris, scratch for the median splits */
} bvh_build;

static int cmp_key(const void *a, const void *b) {
    double x = ((const struct bvh_key *)a)->key, y = ((const struct bvh_key *)b)->key;
    return (x > y) - (x < y);
}

static void tri_bounds(const vp_mesh_shape *m, uint32_t t, double lo[3], double hi[3]) {
    for (int v = 0; v < 3; v++) {
        const double *p = m->verts + 3 * (size_t)m->tris[3 * (size_t)t + v];
        for (int k = 0; k < 3; k++) {
            if (p[k] < lo[k]) lo[k] = p[k];
            if (p[k] > hi[k]) hi[k] = p[k];
        }
    }
}

/* Builds node ni over order[b, e): median split on the longest axis of the
 * centroids, leaves of at most 4 triangles. */
static void build_node(bvh_build *bb, size_t ni, size_t b, size_t e) {
    vp_mesh_shape *m = bb->m;
    vp_bvh_node *n = &m->nodes[ni];
    double clo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, chi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (int k = 0; k < 3; k++) {
        n->lo[k] = HUGE_VAL;
        n->hi[k] = -HUGE_VAL;
    }
    for (size_t i = b; i < e; i++) {
        tri_bounds(m, m->order[i], n->lo, n->hi);
        const double *c = bb->cent + 3 * (size_t)m->order[i];
        for (int k = 0; k < 3; k++) {
            if (c[k] < clo[k]) clo[k] = c[k];
            if (c[k] > chi[k]) chi[k] = c[k];
        }
    }
    if (e - b <= 4) {
        n->first = (uint32_t)b;
        n->count = (uint32_t)(e - b);
        return;
    }
    int axis = 0;
    for (int k = 1; k < 3; k++)
        if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
    for (size_t i = b; i < e; i++)
        bb->keys[i] = (struct bvh_key){bb->cent[3 * (size_t)m->order[i] + axis], m->order[i]};
    qsort(bb->keys + b, e - b, sizeof *bb->keys, cmp_key);
    for (size_t i = b; i < e; i++) m->order[i] = bb->keys[i].tri;
    size_t mid = b + (e - b) / 2;
    size_t left = m->nnodes;
    m->nnodes += 2;
    n->first = (uint32_t)left;
    n->count = 0;
    build_node(bb, left, b, mid);
    build_node(bb, left + 1, mid, e);
}

static int build_bvh(vp_mesh_shape *m) {
    m->order = malloc(m->ntris * sizeof *m->order);
    m->nodes = malloc(2 * m->ntris * sizeof *m->nodes + sizeof *m->nodes);
    double *cent = malloc(3 * m->ntris * sizeof *cent);
    struct bvh_key *keys = malloc(m->ntris * sizeof *keys);
    if (!m->order || !m->nodes || !cent || !keys) {
        free(cent);
        free(keys);
        return -1;
    }
    for (size_t t = 0; t < m->ntris; t++) {
        m->order[t] = (uint32_t)t;
        for (int k = 0; k < 3; k++) {
            double s = 0;
            for (int v = 0; v < 3; v++) s += m->verts[3 * (size_t)m->tris[3 * t + v] + k];
            cent[3 * t + k] = s / 3.0;
        }
    }
    bvh_build bb = {m, cent, keys};
    m->nnodes = 1;
    build_node(&bb, 0, 0, m->ntris);
    free(cent);
    free(keys);
    return 0;
}

/* --- triangle pair: separating axes ------------------------------------------------- */

static void sub3(const double a[3], const double b[3], double o[3]) {
    o[0] = a[0] - b[0];
    o[1] = a[1] - b[1];
    o[2] = a[2] - b[2];
}

/* Largest gap over the separating-axis candidates of two triangles (both
 * normals, the nine edge-edge cross products and the six in-plane edge
 * normals that settle the coplanar case); >= 0: apart or touching, < 0:
 * crossing, -value the penetration depth along the best axis. Axes too
 * short to normalise reliably (parallel edges, degenerate triangles) are
 * skipped: every remaining axis is a valid candidate, so a gap >= 0 on any
 * of them still proves the triangles disjoint. */
static double tri_tri_gap(const double a[3][3], const double b[3][3]) {
    double ea[3][3], eb[3][3], na[3], nb[3];
    for (int i = 0; i < 3; i++) {
        sub3(a[(i + 1) % 3], a[i], ea[i]);
        sub3(b[(i + 1) % 3], b[i], eb[i]);
    }
    vp_cross3(ea[0], ea[1], na);
    vp_cross3(eb[0], eb[1], nb);
    double axes[17][3], len2[17];
    int n = 0;
    memcpy(axes[n++], na, sizeof na);
    memcpy(axes[n++], nb, sizeof nb);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) vp_cross3(ea[i], eb[j], axes[n++]);
    for (int i = 0; i < 3; i++) vp_cross3(na, ea[i], axes[n++]);
    for (int j = 0; j < 3; j++) vp_cross3(nb, eb[j], axes[n++]);
    double la = 0, lb = 0;
    for (int i = 0; i < 3; i++) {
        double x = vp_dot3(ea[i], ea[i]), y = vp_dot3(eb[i], eb[i]);
        if (x > la) la = x;
        if (y > lb) lb = y;
    }
    /* reference squared lengths of each axis family, for the cut-off */
    double ref[17];
    ref[0] = la * la;
    ref[1] = lb * lb;
    for (int i = 2; i < 11; i++) ref[i] = la * lb;
    for (int i = 11; i < 14; i++) ref[i] = la * la * la;
    for (int i = 14; i < 17; i++) ref[i] = lb * lb * lb;
    /* coplanar triangles: faces of two solids lying in one plane. With
     * opposite normals the solids are on opposite sides (face-to-face
     * contact); with equal normals they are on the same side and their
     * interiors overlap where the faces do, by the in-plane axes alone. */
    double nn[3], d0[3];
    vp_cross3(na, nb, nn);
    sub3(b[0], a[0], d0);
    double dn = vp_dot3(na, d0), lna2 = vp_dot3(na, na);
    int coplanar = vp_dot3(nn, nn) <= 1e-24 * lna2 * vp_dot3(nb, nb) &&
                   dn * dn <= 1e-24 * lna2 * (la > lb ? la : lb);
    if (coplanar) {
        for (int v = 1; v < 3; v++) {
            sub3(b[v], a[0], d0);
            dn = vp_dot3(na, d0);
            if (!(dn * dn <= 1e-24 * lna2 * (la > lb ? la : lb))) coplanar = 0;
        }
    }
    if (coplanar && vp_dot3(na, nb) < 0) return 0.0;
    double best = -HUGE_VAL;
    for (int k = coplanar ? 11 : 0; k < n; k++) {
        len2[k] = vp_dot3(axes[k], axes[k]);
        if (!(len2[k] > 1e-24 * ref[k])) continue;
        double amin = HUGE_VAL, amax = -HUGE_VAL, bmin = HUGE_VAL, bmax = -HUGE_VAL;
        for (int v = 0; v < 3; v++) {
            double x = vp_dot3(axes[k], a[v]), y = vp_dot3(axes[k], b[v]);
            if (x < amin) amin = x;
            if (x > amax) amax = x;
            if (y < bmin) bmin = y;
            if (y > bmax) bmax = y;
        }
        /* the push that separates them along this axis (not the length of
         * the common interval: a triangle projects to a point on its own
         * normal, and a crossing one must still move to clear it) */
        double over = fmin(amax - bmin, bmax - amin);
        double gap = -over / sqrt(len2[k]);
        if (gap > best) {
            best = gap;
            if (best >= 0) return best;
        }
    }
    return best == -HUGE_VAL ? 0.0 : best;
}

/* Distance from p to triangle (a, b, c): the closest point by Voronoi
 * regions (Ericson, Real-Time Collision Detection, 5.1.5). */
static double point_triangle_distance(const double p[3], const double a[3], const double b[3],
                                      const double c[3]) {
    double ab[3], ac[3], ap[3], q[3];
    sub3(b, a, ab);
    sub3(c, a, ac);
    sub3(p, a, ap);
    double d1 = vp_dot3(ab, ap), d2 = vp_dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        memcpy(q, a, sizeof q);
    } else {
        double bp[3], cp[3];
        sub3(p, b, bp);
        sub3(p, c, cp);
        double d3 = vp_dot3(ab, bp), d4 = vp_dot3(ac, bp);
        double d5 = vp_dot3(ab, cp), d6 = vp_dot3(ac, cp);
        double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
        if (d3 >= 0 && d4 <= d3) {
            memcpy(q, b, sizeof q);
        } else if (d6 >= 0 && d5 <= d6) {
            memcpy(q, c, sizeof q);
        } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
            double v = d1 / (d1 - d3);
            for (int k = 0; k < 3; k++) q[k] = a[k] + v * ab[k];
        } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
            double w = d2 / (d2 - d6);
            for (int k = 0; k < 3; k++) q[k] = a[k] + w * ac[k];
        } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
            double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            for (int k = 0; k < 3; k++) q[k] = b[k] + w * (c[k] - b[k]);
        } else {
            double den = 1.0 / (va + vb + vc), v = vb * den, w = vc * den;
            for (int k = 0; k < 3; k++) q[k] = a[k] + ab[k] * v + ac[k] * w;
        }
    }
    double d[3];
    sub3(p, q, d);
    return vp_norm3(d);
}

/* --- point in mesh ----------------------------------------------------------------- */

/* Moller-Trumbore: 1 with *t when the ray o + t d meets triangle tri (any
 * t; the caller bounds it), and the triangle's edges e1, e2 for its normal. */
static int ray_tri(const vp_mesh_shape *m, const uint32_t *tri, const double o[3],
                   const double d[3], double *t, double e1[3], double e2[3]) {
    const double *p0 = m->verts + 3 * (size_t)tri[0], *p1 = m->verts + 3 * (size_t)tri[1],
                 *p2 = m->verts + 3 * (size_t)tri[2];
    double pv[3], tv[3], qv[3];
    sub3(p1, p0, e1);
    sub3(p2, p0, e2);
    vp_cross3(d, e2, pv);
    double det = vp_dot3(e1, pv);
    if (det == 0.0) return 0;
    double id = 1.0 / det;
    sub3(o, p0, tv);
    double u = vp_dot3(tv, pv) * id;
    if (u < 0.0 || u > 1.0) return 0;
    vp_cross3(tv, e1, qv);
    double v = vp_dot3(d, qv) * id;
    if (v < 0.0 || u + v > 1.0) return 0;
    *t = vp_dot3(e2, qv) * id;
    return 1;
}

/* Walks the BVH along the ray o + t d for tmin < t < *tmax. nearest: each
 * hit shrinks *tmax and leaves its triangle's (unnormalised) normal in n;
 * otherwise *tmax stays and every hit is counted. Returns the hits. */
static unsigned ray_walk(const vp_mesh_shape *m, const double o[3], const double d[3], double tmin,
                         double *tmax, int nearest, double n[3]) {
    double inv[3];
    for (int k = 0; k < 3; k++) inv[k] = 1.0 / d[k];
    uint32_t stack[128];
    int sp = 0;
    stack[sp++] = 0;
    unsigned hits = 0;
    while (sp) {
        const vp_bvh_node *nd = &m->nodes[stack[--sp]];
        double t0 = tmin, t1 = *tmax;
        int miss = 0;
        for (int k = 0; k < 3 && !miss; k++) {
            double a = (nd->lo[k] - o[k]) * inv[k], b = (nd->hi[k] - o[k]) * inv[k];
            if (a > b) {
                double x = a;
                a = b;
                b = x;
            }
            if (a > t0) t0 = a;
            if (b < t1) t1 = b;
            miss = t0 > t1;
        }
        if (miss) continue;
        if (nd->count == 0) {
            if (sp + 2 > 128) continue; /* cannot happen for a median-split tree */
            stack[sp++] = nd->first;
            stack[sp++] = nd->first + 1;
            continue;
        }
        for (uint32_t i = 0; i < nd->count; i++) {
            double t, e1[3], e2[3];
            if (!ray_tri(m, m->tris + 3 * (size_t)m->order[nd->first + i], o, d, &t, e1, e2) ||
                !(t > tmin && t < *tmax))
                continue;
            hits++;
            if (nearest) {
                *tmax = t;
                vp_cross3(e1, e2, n);
            }
        }
    }
    return hits;
}

int vp_mesh_shape_contains(const vp_mesh_shape *m, const double p[3]) {
    for (int k = 0; k < 3; k++)
        if (!(p[k] >= m->bb_lo[k] && p[k] <= m->bb_hi[k])) return 0;
    /* three fixed directions in general position (not along any axis or
     * diagonal, where meshes keep their edges): a ray through an edge or a
     * vertex can miscount, two of three cannot both do so but by chance */
    static const double dirs[3][3] = {
        {0.5378939618809205, 0.3915411878002461, 0.7465692091347053},
        {-0.6230881925906245, 0.7044866501044696, 0.3397935609730288},
        {0.2119123866410093, -0.8430492776704618, 0.4943288943683384}};
    int in = 0;
    for (int r = 0; r < 3; r++) {
        double tmax = HUGE_VAL;
        in += (int)(ray_walk(m, p, dirs[r], 0.0, &tmax, 0, NULL) & 1u);
    }
    return in >= 2;
}

int vp_mesh_shape_ray(const vp_mesh_shape *m, const double o[3], const double d[3], double tmin,
                      double tmax, double *t_hit, double n_out[3]) {
    if (!ray_walk(m, o, d, tmin, &tmax, 1, n_out)) return 0;
    double l = vp_norm3(n_out);
    for (int k = 0; k < 3; k++) n_out[k] /= l;
    *t_hit = tmax;
    return 1;
}

static void place(const vp_mesh_shape *m, const double R[3][3], double scale, const double t[3],
                  uint32_t v, double x[3]);

/* --- overlap of two placed copies ---------------------------------------------------- */

typedef struct pair_frame {
    double M[3][3]; /* B's unit coordinates -> A's unit coordinates */
    double c[3];
    double absM[3][3];
    double scale; /* sb / sa */
} pair_frame;

static void to_a(const pair_frame *f, const double x[3], double out[3]) {
    for (int k = 0; k < 3; k++)
        out[k] = f->M[k][0] * x[0] + f->M[k][1] * x[1] + f->M[k][2] * x[2] + f->c[k];
}

static void make_frame(double sa, const double qa[4], const double ta[3], double sb,
                       const double qb[4], const double tb[3], pair_frame *f) {
    double ra[3][3], rb[3][3];
    vp_quat_to_matrix(qa, ra);
    vp_quat_to_matrix(qb, rb);
    double d[3] = {tb[0] - ta[0], tb[1] - ta[1], tb[2] - ta[2]};
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            double s = 0;
            for (int k = 0; k < 3; k++) s += ra[k][i] * rb[k][j];
            f->M[i][j] = s * sb / sa;
            f->absM[i][j] = fabs(f->M[i][j]);
        }
        f->c[i] = (ra[0][i] * d[0] + ra[1][i] * d[1] + ra[2][i] * d[2]) / sa;
    }
    f->scale = sb / sa;
}

/* 1 if some triangle pair crosses; with depth, the deepest (A units). */
static int crossing(const vp_mesh_shape *ma, const vp_mesh_shape *mb, const pair_frame *f,
                    double *depth) {
    struct {
        uint32_t a, b;
    } stack[256];
    int sp = 0;
    stack[sp].a = 0;
    stack[sp++].b = 0;
    int found = 0;
    while (sp) {
        sp--;
        const vp_bvh_node *A = &ma->nodes[stack[sp].a], *B = &mb->nodes[stack[sp].b];
        uint32_t ia = stack[sp].a, ib = stack[sp].b;
        double cb[3], hb[3], c2[3];
        for (int k = 0; k < 3; k++) {
            cb[k] = 0.5 * (B->lo[k] + B->hi[k]);
            hb[k] = 0.5 * (B->hi[k] - B->lo[k]);
        }
        to_a(f, cb, c2);
        int apart = 0;
        for (int k = 0; k < 3 && !apart; k++) {
            double h2 = f->absM[k][0] * hb[0] + f->absM[k][1] * hb[1] + f->absM[k][2] * hb[2];
            double ca = 0.5 * (A->lo[k] + A->hi[k]), ha = 0.5 * (A->hi[k] - A->lo[k]);
            /* a relative hair of slack: the boxes are a broad phase only */
            if (fabs(c2[k] - ca) > (ha + h2) * (1.0 + 1e-12) + 1e-15) apart = 1;
        }
        if (apart) continue;
        if (A->count && B->count) {
            double at[4][3][3]; /* A's leaf triangles (at most 4), once per leaf pair */
            for (uint32_t i = 0; i < A->count; i++) {
                const uint32_t *ta = ma->tris + 3 * (size_t)ma->order[A->first + i];
                for (int v = 0; v < 3; v++)
                    memcpy(at[i][v], ma->verts + 3 * (size_t)ta[v], sizeof at[i][v]);
            }
            for (uint32_t j = 0; j < B->count; j++) {
                const uint32_t *tb = mb->tris + 3 * (size_t)mb->order[B->first + j];
                double bt[3][3];
                for (int v = 0; v < 3; v++) to_a(f, mb->verts + 3 * (size_t)tb[v], bt[v]);
                for (uint32_t i = 0; i < A->count; i++) {
                    double g = tri_tri_gap((const double(*)[3])at[i], (const double(*)[3])bt);
                    if (g < 0) {
                        if (!depth) return 1;
                        found = 1;
                        if (-g > *depth) *depth = -g;
                    }
                }
            }
            continue;
        }
        if (sp + 2 > 256) continue; /* depth of two median-split trees: cannot happen */
        double va = (A->hi[0] - A->lo[0]) + (A->hi[1] - A->lo[1]) + (A->hi[2] - A->lo[2]);
        double vb = (B->hi[0] - B->lo[0]) + (B->hi[1] - B->lo[1]) + (B->hi[2] - B->lo[2]);
        if (B->count || (!A->count && va >= vb * f->scale)) {
            /* descend A (the larger, or the only inner node) */
            stack[sp].a = A->first;
            stack[sp++].b = ib;
            stack[sp].a = A->first + 1;
            stack[sp++].b = ib;
        } else {
            stack[sp].a = ia;
            stack[sp++].b = B->first;
            stack[sp].a = ia;
            stack[sp++].b = B->first + 1;
        }
    }
    return found;
}

int vp_mesh_shape_overlap(const vp_mesh_shape *m, double sa, const double qa[4], const double ta[3],
                          double sb, const double qb[4], const double tb[3], double *depth) {
    return vp_mesh_shape_overlap2(m, sa, qa, ta, m, sb, qb, tb, depth);
}

int vp_mesh_shape_overlap2(const vp_mesh_shape *ma, double sa, const double qa[4],
                           const double ta[3], const vp_mesh_shape *mb, double sb,
                           const double qb[4], const double tb[3], double *depth) {
    if (depth) *depth = 0.0;
    pair_frame f;
    make_frame(sa, qa, ta, sb, qb, tb, &f);
    double dep = 0.0;
    if (crossing(ma, mb, &f, depth ? &dep : NULL)) {
        if (depth) *depth = dep * sa;
        return 1;
    }
    /* no surfaces cross: overlap only if one holds a component of the other */
    double ia = sa * (ma->inradius > 0 ? ma->inradius : 1e-3),
           ib = sb * (mb->inradius > 0 ? mb->inradius : 1e-3), inner = ia < ib ? ia : ib;
    pair_frame g; /* A in B's frame */
    make_frame(sb, qb, tb, sa, qa, ta, &g);
    /* B's components in A, then A's in B */
    const pair_frame *frames[2] = {&f, &g};
    const vp_mesh_shape *held[2] = {mb, ma}, *holder[2] = {ma, mb};
    for (int k = 0; k < 2; k++)
        for (size_t r = 0; r < held[k]->nreps; r++) {
            double p[3];
            to_a(frames[k], held[k]->verts + 3 * (size_t)held[k]->reps[r], p);
            if (vp_mesh_shape_contains(holder[k], p)) {
                if (depth) *depth = inner;
                return 1;
            }
        }
    return 0;
}

int vp_mesh_shape_overlap_convex(const vp_mesh_shape *m, double s, const double q[4],
                                 const double t[3], const vp_convex *c, const double c_centre[3],
                                 double c_radius) {
    double R[3][3];
    vp_quat_to_matrix(q, R);
    /* the convex's bounding ball in the mesh's unit frame: R^T (x - t) / s */
    double u[3], d[3] = {c_centre[0] - t[0], c_centre[1] - t[1], c_centre[2] - t[2]};
    for (int k = 0; k < 3; k++) u[k] = (R[0][k] * d[0] + R[1][k] * d[1] + R[2][k] * d[2]) / s;
    double ru = c_radius / s * (1.0 + 1e-12) + 1e-15;
    uint32_t stack[128];
    int sp = 0;
    stack[sp++] = 0;
    while (sp) {
        const vp_bvh_node *n = &m->nodes[stack[--sp]];
        double e2 = 0.0; /* the ball against the node's box */
        for (int k = 0; k < 3; k++) {
            double e = u[k] < n->lo[k] ? n->lo[k] - u[k] : u[k] > n->hi[k] ? u[k] - n->hi[k] : 0.0;
            e2 += e * e;
        }
        if (e2 > ru * ru) continue;
        if (!n->count) {
            if (sp + 2 > 128) continue; /* depth of a median-split tree: cannot happen */
            stack[sp++] = n->first;
            stack[sp++] = n->first + 1;
            continue;
        }
        for (uint32_t i = 0; i < n->count; i++) {
            const uint32_t *tri = m->tris + 3 * (size_t)m->order[n->first + i];
            double w[3][3];
            for (int v = 0; v < 3; v++) place(m, (const double(*)[3])R, s, t, tri[v], w[v]);
            /* relative to the convex's own origin: c->t is c_centre there */
            double o[3] = {c_centre[0] - c->t[0], c_centre[1] - c->t[1], c_centre[2] - c->t[2]};
            vp_convex T;
            vp_convex_set_triangle(&T, w[0], w[1], w[2], o);
            if (vp_convex_overlap(c, &T)) return 1;
        }
    }
    /* no face meets it: it overlaps only if it lies inside the mesh (a
     * mesh wholly inside the convex has faces inside it, found above) */
    return vp_mesh_shape_contains(m, u);
}

/* --- the wall ------------------------------------------------------------------------ */

/* Vertex v of m placed by (R, scale, t). */
static void place(const vp_mesh_shape *m, const double R[3][3], double scale, const double t[3],
                  uint32_t v, double x[3]) {
    const double *p = m->verts + 3 * (size_t)v;
    for (int k = 0; k < 3; k++)
        x[k] = scale * (R[k][0] * p[0] + R[k][1] * p[1] + R[k][2] * p[2]) + t[k];
}

double vp_mesh_shape_wall_distance(const vp_container *c, const vp_mesh_shape *m, double scale,
                                   const double q[4], const double t[3], double stop) {
    static const double qid[4] = {0, 0, 0, 1};
    if (!q) q = qid;
    double R[3][3];
    vp_quat_to_matrix(q, R);
    vp_wall_acc a = {c, -HUGE_VAL, stop};
    for (size_t v = 0; v < m->nverts; v++) {
        double x[3];
        place(m, R, scale, t, (uint32_t)v, x);
        if (vp_wall_sample(&a, x)) return a.worst;
    }
    double h = c->info.voxel_size;
    if (!(h > 0 && m->max_edge * scale > h)) return a.worst; /* the vertices are h apart */
    /* edges and triangles with their vertices placed again as needed (a
     * rotation keeps lengths: the unit edge times scale) */
    for (size_t e = 0; e < m->nedges; e++) {
        const uint32_t *ev = m->edges + 2 * e;
        double p[3], r[3], d[3];
        sub3(m->verts + 3 * (size_t)ev[0], m->verts + 3 * (size_t)ev[1], d);
        int n = (int)ceil(scale * vp_norm3(d) / h);
        if (n < 2) continue;
        if (n > 4096) n = 4096;
        place(m, R, scale, t, ev[0], p);
        place(m, R, scale, t, ev[1], r);
        if (vp_wall_segment(&a, p, r, n)) return a.worst;
    }
    for (size_t ti = 0; ti < m->ntris; ti++) {
        const uint32_t *tr = m->tris + 3 * ti;
        double L = 0, w[3][3], d[3];
        for (int i = 0; i < 3; i++) {
            sub3(m->verts + 3 * (size_t)tr[i], m->verts + 3 * (size_t)tr[(i + 1) % 3], d);
            L = fmax(L, scale * vp_norm3(d));
        }
        int n = (int)ceil(L / h);
        if (n < 3) continue;
        if (n > 4096) n = 4096;
        for (int i = 0; i < 3; i++) place(m, R, scale, t, tr[i], w[i]);
        if (vp_wall_triangle(&a, w[0], w[1], w[2], n)) return a.worst;
    }
    return a.worst;
}

/* --- loading ------------------------------------------------------------------------- */

void vp_mesh_shape_destroy(vp_mesh_shape *s) {
    if (!s) return;
    free(s->verts);
    free(s->tris);
    free(s->edges);
    free(s->order);
    free(s->nodes);
    free(s->reps);
    free(s);
}

vp_result vp_mesh_shape_create(vp_context *ctx, const char *name, double *verts, size_t nverts,
                               uint32_t *tris, size_t ntris, vp_mesh_shape **out) {
    *out = NULL;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (size_t v = 0; v < nverts; v++)
        for (int k = 0; k < 3; k++) {
            double x = verts[3 * v + k];
            if (!isfinite(x)) {
                free(verts);
                free(tris);
                return vp_fail(ctx, VP_ERR_FORMAT, "shape %s: vertex %zu is not finite", name, v);
            }
            if (x < lo[k]) lo[k] = x;
            if (x > hi[k]) hi[k] = x;
        }
    double ext = 0, vol = 0;
    for (int k = 0; k < 3; k++) ext = fmax(ext, hi[k] - lo[k]);
    for (size_t t = 0; t < ntris; t++) {
        const double *a = verts + 3 * (size_t)tris[3 * t], *b = verts + 3 * (size_t)tris[3 * t + 1],
                     *c = verts + 3 * (size_t)tris[3 * t + 2];
        double da[3], db[3], dc[3];
        sub3(a, verts, da);
        sub3(b, verts, db);
        sub3(c, verts, dc);
        vol += vp_det3(da, db, dc) / 6.0;
    }
    if (!(nverts >= 4 && ntris >= 4 && fabs(vol) > 1e-9 * ext * ext * ext)) {
        free(verts);
        free(tris);
        return vp_fail(ctx, VP_ERR_FORMAT,
                       "shape %s: the particle mesh encloses no volume (%.3g); it is flat or "
                       "its parts cancel",
                       name, vol);
    }
    vp_mesh_shape *s = calloc(1, sizeof *s);
    if (!s) {
        free(verts);
        free(tris);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "shape %s: out of memory", name);
    }
    snprintf(s->name, sizeof s->name, "%s", name);
    s->nverts = nverts;
    s->ntris = ntris;
    s->verts = verts;
    s->tris = tris;
    const char *bn = s->name;
    if (vol < 0) /* inward normals: make them outward */
        for (size_t t = 0; t < s->ntris; t++) {
            uint32_t x = s->tris[3 * t + 1];
            s->tris[3 * t + 1] = s->tris[3 * t + 2];
            s->tris[3 * t + 2] = x;
        }
    /* volume centroid (tetrahedra from the first vertex, which keeps the
     * sums well conditioned far from the origin) */
    const double *o = s->verts;
    double cen[3] = {0, 0, 0};
    vol = 0;
    for (size_t t = 0; t < s->ntris; t++) {
        const double *a = s->verts + 3 * (size_t)s->tris[3 * t],
                     *b = s->verts + 3 * (size_t)s->tris[3 * t + 1],
                     *c = s->verts + 3 * (size_t)s->tris[3 * t + 2];
        double da[3], db[3], dc[3];
        sub3(a, o, da);
        sub3(b, o, db);
        sub3(c, o, dc);
        double v6 = vp_det3(da, db, dc);
        vol += v6;
        for (int k = 0; k < 3; k++) cen[k] += v6 * (da[k] + db[k] + dc[k]) / 4.0;
    }
    double c0[3];
    for (int k = 0; k < 3; k++) c0[k] = o[k] + cen[k] / vol;
    double rmax = 0;
    for (size_t v = 0; v < s->nverts; v++) {
        double *p = s->verts + 3 * v;
        sub3(p, c0, p);
        double l = vp_norm3(p);
        if (l > rmax) rmax = l;
    }
    for (size_t v = 0; v < 3 * s->nverts; v++) s->verts[v] /= rmax;
    s->volume = fabs(vol) / 6.0 / (rmax * rmax * rmax);
    for (int k = 0; k < 3; k++) {
        s->bb_lo[k] = HUGE_VAL;
        s->bb_hi[k] = -HUGE_VAL;
    }
    for (size_t v = 0; v < s->nverts; v++)
        for (int k = 0; k < 3; k++) {
            double x = s->verts[3 * v + k];
            if (x < s->bb_lo[k]) s->bb_lo[k] = x;
            if (x > s->bb_hi[k]) s->bb_hi[k] = x;
        }
    /* unique edges, components */
    uint32_t *parent = malloc((s->nverts ? s->nverts : 1) * sizeof *parent);
    s->edges = malloc(6 * s->ntris * sizeof *s->edges);
    vp_edge_side *sides = vp_edge_sides(s->tris, s->ntris); /* (core/mesh_topo.h) */
    if (!parent || !s->edges || !sides || build_bvh(s) != 0) {
        free(parent);
        free(sides);
        vp_mesh_shape_destroy(s);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "shape %s: out of memory", bn);
    }
    for (size_t v = 0; v < s->nverts; v++) parent[v] = (uint32_t)v;
    for (size_t t = 0; t < s->ntris; t++)
        for (int i = 0; i < 3; i++) {
            uint32_t a = s->tris[3 * t + i], b = s->tris[3 * t + (i + 1) % 3];
            uint32_t ra = vp_uf_find(parent, a), rb = vp_uf_find(parent, b);
            if (ra != rb) parent[ra] = rb;
        }
    /* each edge once, in the order of its vertices (smaller first) */
    size_t ne = 0;
    for (size_t e = 0; e < 3 * s->ntris; e++) {
        if (e && sides[e].key == sides[e - 1].key) continue;
        s->edges[2 * ne] = (uint32_t)(sides[e].key >> 32);
        s->edges[2 * ne + 1] = (uint32_t)sides[e].key;
        ne++;
    }
    free(sides);
    s->nedges = ne;
    for (size_t e = 0; e < ne; e++) {
        double d[3];
        sub3(s->verts + 3 * (size_t)s->edges[2 * e], s->verts + 3 * (size_t)s->edges[2 * e + 1], d);
        double l = vp_norm3(d);
        if (l > s->max_edge) s->max_edge = l;
    }
    /* one vertex per component: a vertex used by a triangle whose root is new */
    size_t nrep = 0;
    s->reps = malloc(64 * sizeof *s->reps);
    size_t cap = 64;
    for (size_t v = 0; v < s->nverts && s->reps; v++) {
        if (vp_uf_find(parent, (uint32_t)v) != v) continue;
        if (nrep == cap) {
            uint32_t *n = realloc(s->reps, 2 * cap * sizeof *n);
            if (!n) break;
            s->reps = n;
            cap *= 2;
        }
        s->reps[nrep++] = (uint32_t)v;
    }
    free(parent);
    if (!s->reps) {
        vp_mesh_shape_destroy(s);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "shape %s: out of memory", bn);
    }
    s->nreps = nrep;
    /* inradius about the centroid: the nearest surface point, when the
     * centroid is inside at all (a ring's is not) */
    static const double zero[3] = {0, 0, 0};
    s->inradius = 0;
    if (vp_mesh_shape_contains(s, zero)) {
        double best = HUGE_VAL;
        for (size_t t = 0; t < s->ntris; t++) {
            double d = point_triangle_distance(zero, s->verts + 3 * (size_t)s->tris[3 * t],
                                               s->verts + 3 * (size_t)s->tris[3 * t + 1],
                                               s->verts + 3 * (size_t)s->tris[3 * t + 2]);
            if (d < best) best = d;
        }
        s->inradius = best;
    }
    *out = s;
    return VP_OK;
}

double vp_mesh_shape_volume(const vp_mesh_shape *s) { return s ? s->volume : 0.0; }
size_t vp_mesh_shape_triangles(const vp_mesh_shape *s) { return s ? s->ntris : 0; }
const char *vp_mesh_shape_name(const vp_mesh_shape *s) { return s ? s->name : ""; }
double vp_mesh_shape_inradius(const vp_mesh_shape *s) { return s ? s->inradius : 0.0; }
