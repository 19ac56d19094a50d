/* SPDX-License-Identifier: Apache-2.0 */
/* The wall test of a placed polyhedron, shared by the packers and the
 * checker so that both decide "inside" the same way; see shape.h and
 * docs/rsa.md ("Solids", its item "Wall"). */
#include "core/container.h"
#include "core/geom.h"
#include "core/shape.h"

#include <math.h>

int vp_wall_sample(vp_wall_acc *a, const double x[3]) {
    double d = vp_container_distance(a->c, x);
    if (!(d <= a->worst)) a->worst = isnan(d) ? HUGE_VAL : d;
    return a->worst > a->stop;
}

static double dist3(const double a[3], const double b[3]) {
    double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return vp_norm3(d);
}

int vp_wall_segment(vp_wall_acc *a, const double p[3], const double q[3], int n) {
    for (int k = 1; k < n; k++) {
        double t = (double)k / n, x[3];
        for (int m = 0; m < 3; m++) x[m] = (1.0 - t) * p[m] + t * q[m];
        if (vp_wall_sample(a, x)) return 1;
    }
    return 0;
}

int vp_wall_triangle(vp_wall_acc *a, const double p0[3], const double p1[3], const double p2[3],
                     int n) {
    for (int u = 1; u < n; u++)
        for (int v = 1; u + v < n; v++) {
            double b1 = (double)u / n, b2 = (double)v / n, b0 = 1.0 - b1 - b2, x[3];
            for (int m = 0; m < 3; m++) x[m] = b0 * p0[m] + b1 * p1[m] + b2 * p2[m];
            if (vp_wall_sample(a, x)) return 1;
        }
    return 0;
}

double vp_poly_wall_distance(const vp_container *c, const vp_polyhedron *poly, double scale,
                             const double q[4], const double t[3], double stop) {
    static const double qid[4] = {0, 0, 0, 1};
    if (!q) q = qid;
    vp_wall_acc a = {c, -HUGE_VAL, stop};
    double w[VP_POLY_MAX_VERTS][3];
    for (int k = 0; k < poly->nverts; k++) {
        double v[3] = {poly->verts[k][0] * scale, poly->verts[k][1] * scale,
                       poly->verts[k][2] * scale};
        vp_quat_rotate(q, v, w[k]);
        for (int m = 0; m < 3; m++) w[k][m] += t[m];
        if (vp_wall_sample(&a, w[k])) return a.worst;
    }
    double h = c->info.voxel_size;
    if (!(h > 0)) return a.worst; /* analytic containers are convex: vertices decide */
    /* Edges and faces, at most h apart: each face is a fan of triangles
     * (v0, vi, vi+1) on a barycentric grid of n steps per side, n from the
     * longest side of any of them (a diagonal for squares and pentagons).
     * Each point once: the edges, the fans' diagonals, then the triangles'
     * interiors. */
    double L = 0.0;
    for (int f = 0; f < poly->nfaces; f++)
        for (int i = 1; i < poly->face_size[f]; i++) {
            const int *fv = poly->faces[f];
            double a0 = dist3(w[fv[0]], w[fv[i]]), a1 = dist3(w[fv[i - 1]], w[fv[i]]);
            if (a0 > L) L = a0;
            if (a1 > L) L = a1;
        }
    int n = (int)ceil(L / h);
    if (n < 2) return a.worst; /* the vertices are already h apart */
    if (n > 4096) n = 4096;
    for (int e = 0; e < poly->nedges; e++)
        if (vp_wall_segment(&a, w[poly->edges[e][0]], w[poly->edges[e][1]], n)) return a.worst;
    for (int f = 0; f < poly->nfaces; f++)
        for (int i = 2; i + 1 < poly->face_size[f]; i++)
            if (vp_wall_segment(&a, w[poly->faces[f][0]], w[poly->faces[f][i]], n)) return a.worst;
    for (int f = 0; f < poly->nfaces; f++) {
        const int *fv = poly->faces[f];
        for (int i = 1; i + 1 < poly->face_size[f]; i++) {
            if (vp_wall_triangle(&a, w[fv[0]], w[fv[i]], w[fv[i + 1]], n)) return a.worst;
        }
    }
    return a.worst;
}
