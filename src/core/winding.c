/* SPDX-License-Identifier: Apache-2.0 */
/* Generalized winding numbers, hierarchically (see winding.h).
 *
 * The tree: a binary bounding-volume hierarchy over the triangles' centroids
 * (median split on the longest axis, at most LEAF_TRIS a leaf). Each node
 * keeps the sum of its triangles' vector areas N = sum(a_i n_i) and their
 * area-weighted centre p, and the radius r of the ball about p holding all
 * their corners. Seen from a point q with |p - q| > BETA r, the node's
 * triangles subtend about the solid angle of one dipole, (p - q).N / |p - q|^3
 * (Barill et al. 2018), corrected by the second-order term of their
 * expansion; nearer, its children are visited, and a leaf sums its
 * triangles' exact solid angles. The far-field error falls as
 * (r / |p - q|)^3 relative to the node's own contribution; vdbpack only
 * compares the result with 0.5 (and looks closer near it), and
 * every point near the surface is evaluated exactly by the leaves around it
 * (tests/test_winding.c compares with the exact sum). */
#include "core/winding.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LEAF_TRIS 8
#define BETA 2.0
#define INV_4PI 0.079577471545947667884 /* 1 / (4 pi) */

typedef struct wnode {
    double c[3];    /* area-weighted centre of the node's triangles */
    double n[3];    /* sum of their vector areas (outward) */
    double m[9];    /* second moment: sum of vector area (row) times the
                         triangle's centroid less c (column) */
    double r;       /* radius about c of the ball holding their corners */
    uint32_t left;  /* first child (the second is left + 1); 0: a leaf */
    uint32_t first; /* leaf: its triangles are tri[first .. first + count) */
    uint32_t count;
    uint32_t rims; /* triangles with a boundary edge in the subtree */
} wnode;

struct vp_winding {
    wnode *node;
    size_t nnodes;
    double *tri;  /* 9 doubles a triangle (its corners), in tree order */
    uint8_t *rim; /* 1: the triangle has a boundary edge (tree order) */
    size_t ntris;
};

/* ---- exact solid angles ------------------------------------------------- */

/* The solid angle of triangle (A, B, C) seen from q over 4 pi: Van Oosterom
 * & Strackee's formula, positive when q is on the side the
 * counter-clockwise normal points away from. */
static double tri_winding(const double *A, const double *B, const double *C, const double q[3]) {
    double a[3] = {A[0] - q[0], A[1] - q[1], A[2] - q[2]};
    double b[3] = {B[0] - q[0], B[1] - q[1], B[2] - q[2]};
    double c[3] = {C[0] - q[0], C[1] - q[1], C[2] - q[2]};
    double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                 a[2] * (b[0] * c[1] - b[1] * c[0]);
    double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    double ac = a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
    double bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
    double den = la * lb * lc + ab * lc + ac * lb + bc * la;
    return 2.0 * atan2(det, den) * INV_4PI;
}

double vp_winding_exact(const double *verts, const uint32_t *tris, size_t ntris,
                        const double q[3]) {
    double w = 0;
    for (size_t t = 0; t < ntris; t++)
        w += tri_winding(verts + 3 * (size_t)tris[3 * t], verts + 3 * (size_t)tris[3 * t + 1],
                         verts + 3 * (size_t)tris[3 * t + 2], q);
    return w;
}

/* A far node's winding number at q: the first two terms of the expansion
 * of its triangles' flux about c (Barill et al. 2018): with r = c - q,
 * r.N / |r|^3 + sum_jk M_jk (delta_jk |r|^2 - 3 r_j r_k) / |r|^5, over 4 pi. */
static double dipole(const wnode *nd, const double q[3]) {
    double d[3] = {nd->c[0] - q[0], nd->c[1] - q[1], nd->c[2] - q[2]};
    double l2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    double l3 = l2 * sqrt(l2);
    double first = d[0] * nd->n[0] + d[1] * nd->n[1] + d[2] * nd->n[2];
    const double *m = nd->m;
    double trace = m[0] + m[4] + m[8];
    double rmr = 0;
    for (int j = 0; j < 3; j++)
        rmr += d[j] * (m[3 * j] * d[0] + m[3 * j + 1] * d[1] + m[3 * j + 2] * d[2]);
    return (first + (trace * l2 - 3.0 * rmr) / l2) * INV_4PI / l3;
}

static double leaf_winding(const vp_winding *w, const wnode *nd, const double q[3]) {
    double s = 0;
    const double *t = w->tri + 9 * (size_t)nd->first;
    for (uint32_t i = 0; i < nd->count; i++, t += 9) s += tri_winding(t, t + 3, t + 6, q);
    return s;
}

/* ---- building ----------------------------------------------------------- */

typedef struct builder {
    const double *cen; /* 3 a triangle: centroids */
    uint32_t *idx;     /* triangle order, permuted in place */
    wnode *node;
    size_t nnodes, cap;
} builder;

/* Puts the k-th smallest of idx[lo..hi) by cen[3 * idx + axis] at k, the
 * smaller before it and the larger after (quickselect with a three-way
 * partition about the median of three, so equal keys cannot stall it). */
static void select_kth(builder *b, size_t lo, size_t hi, size_t k, int axis) {
    uint32_t *v = b->idx;
#define KEY(i) (b->cen[3 * (size_t)v[i] + axis])
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        double x0 = KEY(lo), x1 = KEY(mid), x2 = KEY(hi - 1);
        double pivot =
            x0 < x1 ? (x1 < x2 ? x1 : (x0 < x2 ? x2 : x0)) : (x0 < x2 ? x0 : (x1 < x2 ? x2 : x1));
        size_t lt = lo, i = lo, gt = hi; /* [lo,lt) <, [lt,i) ==, [gt,hi) > */
        while (i < gt) {
            double x = KEY(i);
            if (x < pivot) {
                uint32_t s = v[lt];
                v[lt] = v[i];
                v[i] = s;
                lt++;
                i++;
            } else if (x > pivot) {
                gt--;
                uint32_t s = v[gt];
                v[gt] = v[i];
                v[i] = s;
            } else {
                i++;
            }
        }
        if (k < lt) hi = lt;
        else if (k >= gt) lo = gt;
        else break;
    }
#undef KEY
}

/* The tree is built without recursion: a task makes the node in its slot
 * and, for more than LEAF_TRIS triangles, reserves two adjacent slots for
 * its children. */
typedef struct task {
    uint32_t slot;
    uint32_t lo, hi;
} task;

static int build_tree(builder *b, size_t ntris) {
    /* at most 2 * ntris / (LEAF_TRIS / 2) + 1 nodes: every split halves */
    b->cap = 2 * ntris + 1;
    b->node = malloc(b->cap * sizeof *b->node);
    task *stack = malloc((64 + 2 * 64) * sizeof *stack);
    if (!b->node || !stack) {
        free(stack);
        return -1;
    }
    size_t top = 0;
    b->nnodes = 1;
    stack[top++] = (task){0, 0, (uint32_t)ntris};
    while (top) {
        task t = stack[--top];
        wnode *nd = &b->node[t.slot];
        memset(nd, 0, sizeof *nd);
        nd->first = t.lo;
        nd->count = t.hi - t.lo;
        if (t.hi - t.lo <= LEAF_TRIS) continue;
        double lo3[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi3[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
        for (size_t i = t.lo; i < t.hi; i++)
            for (int k = 0; k < 3; k++) {
                double x = b->cen[3 * (size_t)b->idx[i] + k];
                if (x < lo3[k]) lo3[k] = x;
                if (x > hi3[k]) hi3[k] = x;
            }
        int axis = 0;
        for (int k = 1; k < 3; k++)
            if (hi3[k] - lo3[k] > hi3[axis] - lo3[axis]) axis = k;
        uint32_t mid = t.lo + (t.hi - t.lo) / 2;
        select_kth(b, t.lo, t.hi, mid, axis);
        uint32_t l = (uint32_t)b->nnodes;
        b->nnodes += 2;
        nd->left = l;
        /* depth is at most log2(ntris) + 1 < 64: two pushes a level */
        stack[top++] = (task){l + 1, mid, t.hi};
        stack[top++] = (task){l, t.lo, mid};
    }
    free(stack);
    return 0;
}

/* Fills each node's dipole and radius, children before parents (children
 * always have larger indices). */
static void fill_moments(vp_winding *w) {
    for (size_t k = w->nnodes; k-- > 0;) {
        wnode *nd = &w->node[k];
        double area = 0, c[3] = {0, 0, 0}, n[3] = {0, 0, 0};
        const double *t = w->tri + 9 * (size_t)nd->first;
        for (uint32_t i = 0; i < nd->count; i++, t += 9) {
            double e1[3] = {t[3] - t[0], t[4] - t[1], t[5] - t[2]};
            double e2[3] = {t[6] - t[0], t[7] - t[1], t[8] - t[2]};
            double x[3] = {0.5 * (e1[1] * e2[2] - e1[2] * e2[1]),
                           0.5 * (e1[2] * e2[0] - e1[0] * e2[2]),
                           0.5 * (e1[0] * e2[1] - e1[1] * e2[0])};
            double a = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
            for (int j = 0; j < 3; j++) {
                n[j] += x[j];
                c[j] += a * (t[j] + t[3 + j] + t[6 + j]) / 3.0;
            }
            area += a;
        }
        if (area > 0) {
            for (int j = 0; j < 3; j++) c[j] /= area;
        } else { /* degenerate triangles only: their corners' mean */
            t = w->tri + 9 * (size_t)nd->first;
            for (uint32_t i = 0; i < nd->count; i++, t += 9)
                for (int j = 0; j < 3; j++)
                    c[j] += (t[j] + t[3 + j] + t[6 + j]) / (3.0 * nd->count);
        }
        double mm[9] = {0};
        t = w->tri + 9 * (size_t)nd->first;
        for (uint32_t i = 0; i < nd->count; i++, t += 9) {
            double e1[3] = {t[3] - t[0], t[4] - t[1], t[5] - t[2]};
            double e2[3] = {t[6] - t[0], t[7] - t[1], t[8] - t[2]};
            double x[3] = {0.5 * (e1[1] * e2[2] - e1[2] * e2[1]),
                           0.5 * (e1[2] * e2[0] - e1[0] * e2[2]),
                           0.5 * (e1[0] * e2[1] - e1[1] * e2[0])};
            double dc[3];
            for (int j = 0; j < 3; j++) dc[j] = (t[j] + t[3 + j] + t[6 + j]) / 3.0 - c[j];
            for (int j = 0; j < 3; j++)
                for (int q = 0; q < 3; q++) mm[3 * j + q] += x[j] * dc[q];
        }
        memcpy(nd->m, mm, sizeof mm);
        double r2 = 0;
        t = w->tri + 9 * (size_t)nd->first;
        for (uint32_t i = 0; i < 3 * nd->count; i++, t += 3) {
            double d[3] = {t[0] - c[0], t[1] - c[1], t[2] - c[2]};
            double l2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if (l2 > r2) r2 = l2;
        }
        memcpy(nd->c, c, sizeof c);
        memcpy(nd->n, n, sizeof n);
        nd->r = sqrt(r2);
        nd->rims = 0;
        for (uint32_t i = 0; i < nd->count; i++) nd->rims += w->rim[nd->first + i];
    }
}

vp_winding *vp_winding_build(const double *verts, size_t nverts, const uint32_t *tris, size_t ntris,
                             const uint8_t *rim) {
    if (!verts || !tris || ntris == 0 || ntris >= UINT32_MAX / 4) return NULL;
    (void)nverts;
    vp_winding *w = calloc(1, sizeof *w);
    builder b;
    memset(&b, 0, sizeof b);
    double *cen = malloc(3 * ntris * sizeof *cen);
    b.idx = malloc(ntris * sizeof *b.idx);
    if (!w || !cen || !b.idx) goto fail;
    for (size_t t = 0; t < ntris; t++) {
        b.idx[t] = (uint32_t)t;
        for (int k = 0; k < 3; k++)
            cen[3 * t + k] =
                (verts[3 * (size_t)tris[3 * t] + k] + verts[3 * (size_t)tris[3 * t + 1] + k] +
                 verts[3 * (size_t)tris[3 * t + 2] + k]) /
                3.0;
    }
    b.cen = cen;
    if (build_tree(&b, ntris) != 0) goto fail;
    w->node = b.node;
    w->nnodes = b.nnodes;
    b.node = NULL;
    w->ntris = ntris;
    w->tri = malloc(9 * ntris * sizeof *w->tri);
    w->rim = calloc(ntris, 1);
    if (!w->tri || !w->rim) goto fail;
    for (size_t i = 0; i < ntris; i++) {
        size_t t = b.idx[i];
        for (int j = 0; j < 3; j++)
            memcpy(w->tri + 9 * i + 3 * j, verts + 3 * (size_t)tris[3 * t + j], 3 * sizeof(double));
        w->rim[i] = rim ? rim[t] : 0;
    }
    fill_moments(w);
    free(cen);
    free(b.idx);
    return w;
fail:
    free(cen);
    free(b.idx);
    free(b.node);
    vp_winding_destroy(w);
    return NULL;
}

void vp_winding_destroy(vp_winding *w) {
    if (!w) return;
    free(w->node);
    free(w->tri);
    free(w->rim);
    free(w);
}

/* ---- evaluation --------------------------------------------------------- */

#define STACK_MAX 128

static double winding_at(const vp_winding *w, const double q[3], double beta) {
    uint32_t stack[STACK_MAX];
    int top = 0;
    double s = 0;
    stack[top++] = 0;
    while (top) {
        const wnode *nd = &w->node[stack[--top]];
        double d[3] = {nd->c[0] - q[0], nd->c[1] - q[1], nd->c[2] - q[2]};
        double l2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (l2 > beta * beta * nd->r * nd->r) {
            s += dipole(nd, q);
        } else if (!nd->left) {
            s += leaf_winding(w, nd, q);
        } else {
            stack[top++] = nd->left + 1;
            stack[top++] = nd->left;
        }
    }
    return s;
}

/* Near 0.5, where vdbpack draws the line, the dipoles' error (a few
 * hundredths at BETA) could move it: there the tree is opened further. */
#define BETA_NEAR_HALF 4.0
#define NEAR_HALF 0.1

double vp_winding_at(const vp_winding *w, const double q[3]) {
    double s = winding_at(w, q, BETA);
    return fabs(s - 0.5) < NEAR_HALF ? winding_at(w, q, BETA_NEAR_HALF) : s;
}

/* The nodes far from every point within R of bc (their dipoles) and the
 * leaves near any of them (their triangles), for a batch. */
typedef struct lists {
    uint32_t *far, *near;
    size_t nfar, nnear, cap_far, cap_near;
} lists;

static int push(uint32_t **v, size_t *n, size_t *cap, uint32_t x) {
    if (*n == *cap) {
        size_t nc = *cap ? 2 * *cap : 256;
        uint32_t *nv = realloc(*v, nc * sizeof *nv);
        if (!nv) return -1;
        *v = nv;
        *cap = nc;
    }
    (*v)[(*n)++] = x;
    return 0;
}

static int gather(const vp_winding *w, const double bc[3], double R, lists *L) {
    uint32_t stack[STACK_MAX];
    int top = 0;
    stack[top++] = 0;
    while (top) {
        uint32_t k = stack[--top];
        const wnode *nd = &w->node[k];
        double d[3] = {nd->c[0] - bc[0], nd->c[1] - bc[1], nd->c[2] - bc[2]};
        double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        /* every point q of the batch has |c - q| >= l - R */
        if (l - R > BETA * nd->r) {
            if (push(&L->far, &L->nfar, &L->cap_far, k)) return -1;
        } else if (!nd->left) {
            if (push(&L->near, &L->nnear, &L->cap_near, k)) return -1;
        } else {
            stack[top++] = nd->left + 1;
            stack[top++] = nd->left;
        }
    }
    return 0;
}

void vp_winding_batch(const vp_winding *w, const double *pts, size_t n, double *out) {
    if (n == 0) return;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            if (pts[3 * i + k] < lo[k]) lo[k] = pts[3 * i + k];
            if (pts[3 * i + k] > hi[k]) hi[k] = pts[3 * i + k];
        }
    double bc[3], R2 = 0;
    for (int k = 0; k < 3; k++) bc[k] = 0.5 * (lo[k] + hi[k]);
    for (size_t i = 0; i < n; i++) {
        double d[3] = {pts[3 * i] - bc[0], pts[3 * i + 1] - bc[1], pts[3 * i + 2] - bc[2]};
        double l2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (l2 > R2) R2 = l2;
    }
    /* a spread-out batch (more than a sixteenth of the mesh's extent) would
     * find little far from all of its points: each point on its own */
    lists L;
    memset(&L, 0, sizeof L);
    if (n < 4 || sqrt(R2) > w->node[0].r / 16 || gather(w, bc, sqrt(R2), &L) != 0) {
        for (size_t i = 0; i < n; i++) out[i] = vp_winding_at(w, pts + 3 * i);
        free(L.far);
        free(L.near);
        return;
    }
    for (size_t i = 0; i < n; i++) {
        const double *q = pts + 3 * i;
        double s = 0;
        for (size_t j = 0; j < L.nfar; j++) s += dipole(&w->node[L.far[j]], q);
        /* a leaf near the batch may still be far from this point */
        for (size_t j = 0; j < L.nnear; j++) {
            const wnode *nd = &w->node[L.near[j]];
            double d[3] = {nd->c[0] - q[0], nd->c[1] - q[1], nd->c[2] - q[2]};
            double l2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            s += l2 > BETA * BETA * nd->r * nd->r ? dipole(nd, q) : leaf_winding(w, nd, q);
        }
        out[i] = fabs(s - 0.5) < NEAR_HALF ? winding_at(w, q, BETA_NEAR_HALF) : s;
    }
    free(L.far);
    free(L.near);
}

/* ---- blocks of voxels: crossings ------------------------------------------
 *
 * Within a block the winding number changes by exactly 1 where a segment
 * between neighbouring voxel centres crosses a triangle (down when it
 * leaves through the triangle's front), and smoothly elsewhere (not at all
 * for closed pieces; near a hole, the film's slope). So the block takes
 * the winding number at its first voxel and adds the crossings along x (at
 * j = k = 0), then y (at k = 0), then z: a scan of the triangles near the
 * block, without solid angles. Crossings are counted in the style of a
 * rasterizer: a line through an edge belongs to one of the edge's two
 * triangles (the edge's points in a triangle's projection follow the
 * top-left rule, with the edge's ends taken in a fixed order so that both
 * triangles compute it alike), a point on a triangle's plane to the segment
 * that starts there. Where a line passes through an edge or a corner, or
 * meets a triangle at a voxel centre, to rounding, the block is evaluated
 * point by point instead (a vertex on a voxel centre would otherwise hand
 * rounding's choice of side on to every voxel after it). Within a block's
 * width of a hole's rim (a triangle with
 * a boundary edge) the number also turns around the rim without crossings:
 * such blocks are evaluated point by point. The scan's answer is checked against the hierarchical
 * evaluation at the block's far corners; where they disagree by more than
 * BLOCK_SLACK (the film's slope, or a crossing the scan cannot count) the
 * whole block is evaluated point by point, and so is every voxel whose
 * scanned value lies within BLOCK_MARGIN of 0.5. */
#define BLOCK_SLACK 0.15
#define BLOCK_MARGIN 0.2
#define BETA_CHECK BETA

/* 1 when a precedes b (lexicographically): the fixed order of an edge's
 * ends. */
static int before(const double *a, const double *b, int u, int v) {
    return a[u] < b[u] || (a[u] == b[u] && a[v] < b[v]);
}

/* The edge function of (A, B) at p in the (u, v) plane, computed from the
 * ends in their fixed order so that the two triangles of an edge get
 * exactly opposite values. */
static double edge_fn(const double *A, const double *B, double pu, double pv, int u, int v) {
    if (before(B, A, u, v)) return -((A[u] - B[u]) * (pv - B[v]) - (A[v] - B[v]) * (pu - B[u]));
    return (B[u] - A[u]) * (pv - A[v]) - (B[v] - A[v]) * (pu - A[u]);
}

/* Whether (pu, pv) lies in the projection of triangle T on the (u, v)
 * plane (counter-clockwise when s > 0; s = the sign of its normal's third
 * axis), edges included by the top-left rule. *close is set when the
 * point lies on an edge or at a corner, to rounding: there, which triangle
 * the line meets, and on which side, is rounding's choice. */
static int covers(const double *T, double s, double pu, double pv, int u, int v, int *close) {
    int inside = 1;
    for (int e = 0; e < 3; e++) {
        const double *A = T + 3 * e, *B = T + 3 * ((e + 1) % 3);
        double f = s * edge_fn(A, B, pu, pv, u, v);
        double len = fabs(B[u] - A[u]) + fabs(B[v] - A[v]);
        double span = fabs(pu - A[u]) + fabs(pv - A[v]);
        if (fabs(f) <= 1e-9 * len * span) *close = 1;
        if (f < 0) inside = 0;
    }
    if (!inside) return 0;
    for (int e = 0; e < 3; e++) {
        const double *A = T + 3 * e, *B = T + 3 * ((e + 1) % 3);
        double f = s * edge_fn(A, B, pu, pv, u, v);
        if (f == 0) {
            /* the edge as the counter-clockwise triangle runs it */
            double du = s * (B[u] - A[u]), dv = s * (B[v] - A[v]);
            if (!(dv > 0 || (dv == 0 && du < 0))) return 0;
        }
    }
    return 1;
}

/* Adds to cross[] the crossings of triangle T with the lines along axis a
 * through the block's voxel centres lo + h * (i, j, k) that the mask
 * lines[] selects (lines[l] for line l = i0 * 8 + i1 over the two other
 * axes, in axis order): cross[l * 8 + m] counts the change from voxel m to
 * m + 1 along the line. */
static void cross_triangle(const double *T, int a, const double lo[3], double h,
                           const unsigned char *lines, int *cross, int *degenerate) {
    int u = (a + 1) % 3, v = (a + 2) % 3;
    if (u > v) {
        int t = u;
        u = v;
        v = t;
    } /* the other axes, in axis order */
    double e1[3] = {T[3] - T[0], T[4] - T[1], T[5] - T[2]};
    double e2[3] = {T[6] - T[0], T[7] - T[1], T[8] - T[2]};
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                   e1[0] * e2[1] - e1[1] * e2[0]};
    if (!(n[a] != 0)) return; /* parallel to the lines */
    /* (u, v, a) is a right-handed frame when u, v, a cycle as x, y, z */
    double s = n[a] > 0 ? 1.0 : -1.0;
    if (!((u + 1) % 3 == v)) s = -s;
    double umin = fmin(T[u], fmin(T[3 + u], T[6 + u])), umax = fmax(T[u], fmax(T[3 + u], T[6 + u]));
    double vmin = fmin(T[v], fmin(T[3 + v], T[6 + v])), vmax = fmax(T[v], fmax(T[3 + v], T[6 + v]));
    int i0 = (int)ceil((umin - lo[u]) / h), i1 = (int)floor((umax - lo[u]) / h);
    int j0 = (int)ceil((vmin - lo[v]) / h), j1 = (int)floor((vmax - lo[v]) / h);
    if (i0 < 0) i0 = 0;
    if (j0 < 0) j0 = 0;
    if (i1 > 7) i1 = 7;
    if (j1 > 7) j1 = 7;
    /* leaving through the front (the normal's side) takes 1 away */
    int step = n[a] > 0 ? -1 : 1;
    for (int i = i0; i <= i1; i++)
        for (int j = j0; j <= j1; j++) {
            int l = i * 8 + j;
            if (!lines[l]) continue;
            double pu = lo[u] + h * i, pv = lo[v] + h * j;
            int close = 0;
            int in = covers(T, s, pu, pv, u, v, &close);
            /* where the line meets the triangle's plane */
            double t = T[a] - (n[u] * (pu - T[u]) + n[v] * (pv - T[v])) / n[a];
            double x = (t - lo[a]) / h, m = floor(x);
            if (close && x > -1e-6 && x < 7 + 1e-6) *degenerate = 1;
            if (!in) continue;
            /* on a voxel centre, to rounding: which side it is on is too */
            if (x > -1e-6 && x < 7 + 1e-6 && fabs(x - floor(x + 0.5)) <= 1e-9 * (1 + fabs(x)))
                *degenerate = 1;
            if (m >= 0 && m <= 6) cross[l * 8 + (int)m] += step;
        }
}

/* 1 when a tree node's bounding ball meets the box [lo, hi]. */
static int ball_meets_box(const wnode *nd, const double lo[3], const double hi[3]) {
    double d2 = 0;
    for (int k = 0; k < 3; k++) {
        double x = nd->c[k] < lo[k] ? lo[k] - nd->c[k] : nd->c[k] > hi[k] ? nd->c[k] - hi[k] : 0;
        d2 += x * x;
    }
    return d2 <= nd->r * nd->r;
}

/* 1 when the box of triangle T's corners meets the box [lo, hi]. */
static int tri_box_meets_box(const double *T, const double lo[3], const double hi[3]) {
    for (int k = 0; k < 3; k++)
        if (!(fmin(T[k], fmin(T[3 + k], T[6 + k])) <= hi[k] &&
              fmax(T[k], fmax(T[3 + k], T[6 + k])) >= lo[k]))
            return 0;
    return 1;
}

/* The triangles whose corners' box meets the box [lo, hi]: their indices
 * (in tree order) into *out, grown as needed. Returns the count, or -1
 * when out of memory. */
static long near_box(const vp_winding *w, const double lo[3], const double hi[3], uint32_t **out,
                     size_t *cap) {
    uint32_t stack[STACK_MAX];
    int top = 0;
    size_t n = 0;
    stack[top++] = 0;
    while (top) {
        const wnode *nd = &w->node[stack[--top]];
        if (!ball_meets_box(nd, lo, hi)) continue;
        if (nd->left) {
            stack[top++] = nd->left + 1;
            stack[top++] = nd->left;
            continue;
        }
        for (uint32_t i = 0; i < nd->count; i++) {
            if (!tri_box_meets_box(w->tri + 9 * (size_t)(nd->first + i), lo, hi)) continue;
            if (n == *cap) {
                size_t nc = *cap ? 2 * *cap : 256;
                uint32_t *nv = realloc(*out, nc * sizeof *nv);
                if (!nv) return -1;
                *out = nv;
                *cap = nc;
            }
            (*out)[n++] = nd->first + i;
        }
    }
    return (long)n;
}

/* Every point of the block, as one batch (vp_winding_batch). */
static void block_points(const vp_winding *w, const double lo[3], double h, double *out) {
    double pts[3 * 512];
    for (int i = 0; i < 512; i++) {
        pts[3 * i] = lo[0] + h * (i >> 6);
        pts[3 * i + 1] = lo[1] + h * ((i >> 3) & 7);
        pts[3 * i + 2] = lo[2] + h * (i & 7);
    }
    vp_winding_batch(w, pts, 512, out);
}

/* 1 when a triangle with a boundary edge meets the box [lo, hi]: near a
 * hole's rim the winding number turns around the rim by a whole unit
 * without any segment crossing a triangle. */
static int rim_near(const vp_winding *w, const double lo[3], const double hi[3]) {
    if (!w->node[0].rims) return 0;
    uint32_t stack[STACK_MAX];
    int top = 0;
    stack[top++] = 0;
    while (top) {
        const wnode *nd = &w->node[stack[--top]];
        if (!nd->rims || !ball_meets_box(nd, lo, hi)) continue;
        if (nd->left) {
            stack[top++] = nd->left + 1;
            stack[top++] = nd->left;
            continue;
        }
        for (uint32_t i = 0; i < nd->count; i++) {
            if (!w->rim[nd->first + i]) continue;
            if (tri_box_meets_box(w->tri + 9 * (size_t)(nd->first + i), lo, hi)) return 1;
        }
    }
    return 0;
}

void vp_winding_block(const vp_winding *w, const double lo[3], double h, double *out) {
    double hi[3] = {lo[0] + 7 * h, lo[1] + 7 * h, lo[2] + 7 * h};
    /* within a block's width of a rim: point by point */
    double rlo[3] = {lo[0] - 8 * h, lo[1] - 8 * h, lo[2] - 8 * h};
    double rhi[3] = {hi[0] + 8 * h, hi[1] + 8 * h, hi[2] + 8 * h};
    if (rim_near(w, rlo, rhi)) {
        block_points(w, lo, h, out);
        return;
    }
    uint32_t *tris = NULL;
    size_t cap = 0;
    long nt = near_box(w, lo, hi, &tris, &cap);
    /* crossings: x at (j, k) = (0, 0), y at k = 0, z everywhere */
    int cx[64] = {0}, cy[512] = {0}, cz[512] = {0};
    unsigned char line_x[64] = {0}, line_y[64] = {0}, line_z[64];
    line_x[0] = 1;                                 /* (y, z) = (0, 0) */
    for (int i = 0; i < 8; i++) line_y[i * 8] = 1; /* (x, z) = (i, 0) */
    memset(line_z, 1, sizeof line_z);              /* every (x, y) */
    int degenerate = 0;
    for (long t = 0; t < nt; t++) {
        const double *T = w->tri + 9 * (size_t)tris[t];
        cross_triangle(T, 0, lo, h, line_x, cx, &degenerate);
        cross_triangle(T, 1, lo, h, line_y, cy, &degenerate);
        cross_triangle(T, 2, lo, h, line_z, cz, &degenerate);
    }
    free(tris);
    /* a line through an edge, a corner or a voxel on a triangle (meshes on
     * the voxel grid: boxes, CAD parts): point by point */
    if (degenerate) {
        block_points(w, lo, h, out);
        return;
    }
    double w0 = winding_at(w, lo, BETA_CHECK);
    /* out[64 i + 8 j + k] at lo + h * (i, j, k) */
    double along_x = w0;
    for (int i = 0; i < 8; i++) {
        if (i) along_x += cx[i - 1];
        double along_y = along_x;
        for (int j = 0; j < 8; j++) {
            if (j) along_y += cy[i * 64 + (j - 1)];
            double along_z = along_y;
            for (int k = 0; k < 8; k++) {
                if (k) along_z += cz[(i * 8 + j) * 8 + (k - 1)];
                out[64 * i + 8 * j + k] = along_z;
            }
        }
    }
    if (nt < 0) { /* out of memory for the list: point by point */
        block_points(w, lo, h, out);
        return;
    }
    /* the check at the far corners */
    static const int far[3] = {511, 64 * 7 + 7, 8 * 7 + 7};
    int ok = 1;
    for (int c = 0; c < 3 && ok; c++) {
        int i = far[c];
        double q[3] = {lo[0] + h * (i >> 6), lo[1] + h * ((i >> 3) & 7), lo[2] + h * (i & 7)};
        ok = fabs(winding_at(w, q, BETA_CHECK) - out[i]) <= BLOCK_SLACK;
    }
    if (!ok) {
        block_points(w, lo, h, out);
        return;
    }
    for (int i = 0; i < 512; i++)
        if (fabs(out[i] - 0.5) < BLOCK_MARGIN) {
            double q[3] = {lo[0] + h * (i >> 6), lo[1] + h * ((i >> 3) & 7), lo[2] + h * (i & 7)};
            out[i] = vp_winding_at(w, q);
        }
}
