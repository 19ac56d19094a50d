/* SPDX-License-Identifier: Apache-2.0 */
/* The generalized winding number (core/winding.c) against the exact sum
 * of solid angles: the tree's point and batch evaluations, and the block
 * evaluation by crossings, on closed, open, nested and flipped meshes
 * built here; every answer on the right side of 0.5. */
#include "core/winding.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vp_test.h"

/* An icosphere of radius r about c, subdivided n times (20 * 4^n
 * triangles), outward. */
typedef struct mesh {
    double *v;
    uint32_t *t;
    size_t nv, nt;
} mesh;

static uint32_t add_vertex(mesh *m, double x, double y, double z) {
    m->v = realloc(m->v, 3 * (m->nv + 1) * sizeof *m->v);
    m->v[3 * m->nv] = x;
    m->v[3 * m->nv + 1] = y;
    m->v[3 * m->nv + 2] = z;
    return (uint32_t)m->nv++;
}

static void add_tri(mesh *m, uint32_t a, uint32_t b, uint32_t c) {
    m->t = realloc(m->t, 3 * (m->nt + 1) * sizeof *m->t);
    m->t[3 * m->nt] = a;
    m->t[3 * m->nt + 1] = b;
    m->t[3 * m->nt + 2] = c;
    m->nt++;
}

static uint32_t midpoint(mesh *m, uint32_t a, uint32_t b) {
    double p[3];
    for (int k = 0; k < 3; k++) p[k] = 0.5 * (m->v[3 * a + k] + m->v[3 * b + k]);
    double l = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    return add_vertex(m, p[0] / l, p[1] / l, p[2] / l);
}

static void icosphere(mesh *m, int n, double r, const double c[3]) {
    mesh u = {0};
    double t = (1 + sqrt(5.0)) / 2;
    double base[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                          {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                          {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (int i = 0; i < 12; i++) {
        double l =
            sqrt(base[i][0] * base[i][0] + base[i][1] * base[i][1] + base[i][2] * base[i][2]);
        add_vertex(&u, base[i][0] / l, base[i][1] / l, base[i][2] / l);
    }
    static const uint32_t f[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                      {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                      {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                      {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (int i = 0; i < 20; i++) add_tri(&u, f[i][0], f[i][1], f[i][2]);
    for (int s = 0; s < n; s++) {
        mesh d = {0};
        d.v = malloc(3 * u.nv * sizeof *d.v);
        memcpy(d.v, u.v, 3 * u.nv * sizeof *d.v);
        d.nv = u.nv;
        for (size_t i = 0; i < u.nt; i++) {
            uint32_t a = u.t[3 * i], b = u.t[3 * i + 1], cc = u.t[3 * i + 2];
            uint32_t ab = midpoint(&d, a, b), bc = midpoint(&d, b, cc), ca = midpoint(&d, cc, a);
            add_tri(&d, a, ab, ca);
            add_tri(&d, b, bc, ab);
            add_tri(&d, cc, ca, bc);
            add_tri(&d, ab, bc, ca);
        }
        free(u.v);
        free(u.t);
        u = d;
    }
    /* append, scaled and moved (midpoints repeat vertices: harmless here) */
    size_t base_v = m->nv;
    for (size_t i = 0; i < u.nv; i++)
        add_vertex(m, c[0] + r * u.v[3 * i], c[1] + r * u.v[3 * i + 1], c[2] + r * u.v[3 * i + 2]);
    for (size_t i = 0; i < u.nt; i++)
        add_tri(m, (uint32_t)(base_v + u.t[3 * i]), (uint32_t)(base_v + u.t[3 * i + 1]),
                (uint32_t)(base_v + u.t[3 * i + 2]));
    free(u.v);
    free(u.t);
}

static uint64_t g_rng = 88172645463325252ULL;
static double urand(void) {
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return (double)(g_rng >> 11) / 9007199254740992.0;
}

/* The tree's point, batch and block answers against the exact sum at
 * random points in [-span, span]^3 and in 8^3 blocks: the same side of
 * 0.5 wherever the exact value is more than `margin` from it, and within
 * tol of it everywhere. */
static void compare(const mesh *m, const uint8_t *rim, double span, double h, double tol,
                    double margin) {
    vp_winding *w = vp_winding_build(m->v, m->nv, m->t, m->nt, rim);
    ASSERT_TRUE(w != NULL);
    double worst = 0;
    int wrong = 0;
    for (int i = 0; i < 400; i++) {
        double q[3] = {span * (2 * urand() - 1), span * (2 * urand() - 1),
                       span * (2 * urand() - 1)};
        double e = vp_winding_exact(m->v, m->t, m->nt, q), a = vp_winding_at(w, q), b;
        vp_winding_batch(w, q, 1, &b);
        worst = fmax(worst, fmax(fabs(a - e), fabs(b - e)));
        if (fabs(e - 0.5) > margin)
            wrong += ((a >= 0.5) != (e >= 0.5)) + ((b >= 0.5) != (e >= 0.5));
    }
    double out[512], pts[3 * 512], batch[512];
    for (int blk = 0; blk < 12; blk++) {
        double lo[3] = {span * (2 * urand() - 1) - 4 * h, span * (2 * urand() - 1) - 4 * h,
                        span * (2 * urand() - 1) - 4 * h};
        vp_winding_block(w, lo, h, out);
        for (int i = 0; i < 512; i++) {
            pts[3 * i] = lo[0] + h * (i >> 6);
            pts[3 * i + 1] = lo[1] + h * ((i >> 3) & 7);
            pts[3 * i + 2] = lo[2] + h * (i & 7);
        }
        vp_winding_batch(w, pts, 512, batch);
        for (int i = 0; i < 512; i += 5) {
            double e = vp_winding_exact(m->v, m->t, m->nt, pts + 3 * i);
            if (getenv("VP_DEBUG_WINDING") && fmax(fabs(out[i] - e), fabs(batch[i] - e)) > tol)
                fprintf(stderr,
                        "   block %d point %d: block %.4f batch %.4f exact %.4f at (%g %g %g)\n",
                        blk, i, out[i], batch[i], e, pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
            worst = fmax(worst, fmax(fabs(out[i] - e), fabs(batch[i] - e)));
            if (fabs(e - 0.5) > margin)
                wrong += ((out[i] >= 0.5) != (e >= 0.5)) + ((batch[i] >= 0.5) != (e >= 0.5));
        }
    }
    fprintf(stderr, "   %zu triangles: largest error %.3g, %d on the wrong side of 0.5\n", m->nt,
            worst, wrong);
    ASSERT_LE(worst, tol);
    ASSERT_EQ_INT(wrong, 0);
    vp_winding_destroy(w);
}

static void test_closed_sphere(void) {
    mesh m = {0};
    double c[3] = {0, 0, 0};
    icosphere(&m, 3, 1.0, c);
    /* exact values: 1 inside, 0 outside */
    double in[3] = {0.1, -0.2, 0.3}, out[3] = {1.5, 0, 0};
    ASSERT_NEAR(vp_winding_exact(m.v, m.t, m.nt, in), 1.0, 1e-9);
    ASSERT_NEAR(vp_winding_exact(m.v, m.t, m.nt, out), 0.0, 1e-9);
    compare(&m, NULL, 1.3, 0.02, 0.1, 0.02);
    free(m.v);
    free(m.t);
}

/* A sphere with a cap of triangles removed (an open mesh): the winding
 * number is between 0 and 1 near the hole. */
static void test_open_sphere(void) {
    mesh m = {0};
    double c[3] = {0, 0, 0};
    icosphere(&m, 3, 1.0, c);
    size_t w = 0;
    uint8_t *rim = calloc(m.nt, 1);
    for (size_t t = 0; t < m.nt; t++) {
        double z =
            (m.v[3 * m.t[3 * t] + 2] + m.v[3 * m.t[3 * t + 1] + 2] + m.v[3 * m.t[3 * t + 2] + 2]) /
            3;
        if (z > 0.8) continue; /* the cap */
        memmove(m.t + 3 * w, m.t + 3 * t, 3 * sizeof *m.t);
        rim[w] = z > 0.6; /* the triangles along the hole's rim, and a few more */
        w++;
    }
    m.nt = w;
    double mid[3] = {0, 0, 0.5};
    double e = vp_winding_exact(m.v, m.t, m.nt, mid);
    ASSERT_TRUE(e > 0.5 && e < 0.99);
    compare(&m, rim, 1.3, 0.02, 0.15, 0.02);
    free(rim);
    free(m.v);
    free(m.t);
}

/* Two overlapping spheres (w = 2 where they overlap) and a reversed inner
 * shell (w = 0 in the cavity). */
static void test_overlap_and_cavity(void) {
    mesh m = {0};
    double a[3] = {-0.4, 0, 0}, b[3] = {0.4, 0, 0};
    icosphere(&m, 3, 0.8, a);
    icosphere(&m, 3, 0.8, b);
    double mid[3] = {0, 0, 0};
    ASSERT_NEAR(vp_winding_exact(m.v, m.t, m.nt, mid), 2.0, 1e-9);
    compare(&m, NULL, 1.4, 0.03, 0.1, 0.02);
    free(m.v);
    free(m.t);
    memset(&m, 0, sizeof m);
    double o[3] = {0, 0, 0};
    icosphere(&m, 3, 1.0, o);
    size_t first = m.nt;
    icosphere(&m, 3, 0.5, o);
    for (size_t t = first; t < m.nt; t++) { /* reverse the inner shell */
        uint32_t s = m.t[3 * t + 1];
        m.t[3 * t + 1] = m.t[3 * t + 2];
        m.t[3 * t + 2] = s;
    }
    ASSERT_NEAR(vp_winding_exact(m.v, m.t, m.nt, mid), 0.0, 1e-9);
    double shell[3] = {0.75, 0, 0};
    ASSERT_NEAR(vp_winding_exact(m.v, m.t, m.nt, shell), 1.0, 1e-9);
    compare(&m, NULL, 1.2, 0.02, 0.1, 0.02);
    free(m.v);
    free(m.t);
}

int main(void) {
    RUN_TEST(test_closed_sphere);
    RUN_TEST(test_open_sphere);
    RUN_TEST(test_overlap_and_cavity);
    return 0;
}
