/* SPDX-License-Identifier: Apache-2.0 */
/* The 13 Archimedean solids: their polyhedra against closed forms (counts
 * of vertices, edges and faces by size, equal edges, volume), their lattice
 * bases against the literature densities with an overlap test of this
 * file's own (the critical-lattice criterion on the difference body,
 * from edges found here, not the SAT of shape.c), and the packers' GJK overlap test
 * against the SAT on random pairs. */
#include "core/geom.h"
#include "core/lattice_basis.h"
#include "core/shape.h"
#include "core/superball.h"
#include "vp_test.h"

#include <string.h>

typedef struct solid {
    vp_shape s;
    int V, E, f3, f4, f5, f6, f8, f10;
    double vol_a3; /* volume at edge 1 */
    /* the densest lattice's fraction: Betke & Henk 2000; the snub cube's
     * from scripts/lattice_enum.c's enumeration (docs/lattices.md) */
    double lit;
    int symmetric; /* K = -K */
} solid;

static solid solids[13];

static void fill(void) {
    const double r2 = sqrt(2.0), r5 = sqrt(5.0);
    const solid t[13] = {
        {VP_SHAPE_TRUNCATED_TETRAHEDRON, 12, 18, 4, 0, 0, 4, 0, 0, 23 * r2 / 12, 0.680921, 0},
        {VP_SHAPE_CUBOCTAHEDRON, 12, 24, 8, 6, 0, 0, 0, 0, 5 * r2 / 3, 0.918367, 1},
        {VP_SHAPE_TRUNCATED_CUBE, 24, 36, 8, 0, 0, 0, 6, 0, (21 + 14 * r2) / 3, 0.973747, 1},
        {VP_SHAPE_TRUNCATED_OCTAHEDRON, 24, 36, 0, 6, 0, 8, 0, 0, 8 * r2, 1.0, 1},
        {VP_SHAPE_RHOMBICUBOCTAHEDRON, 24, 48, 8, 18, 0, 0, 0, 0, (12 + 10 * r2) / 3, 0.875805, 1},
        {VP_SHAPE_TRUNCATED_CUBOCTAHEDRON, 48, 72, 0, 12, 0, 8, 6, 0, 22 + 14 * r2, 0.849373, 1},
        {VP_SHAPE_SNUB_CUBE, 24, 60, 32, 6, 0, 0, 0, 0, 7.8894774, 0.787680, 0},
        {VP_SHAPE_ICOSIDODECAHEDRON, 30, 60, 20, 0, 12, 0, 0, 0, (45 + 17 * r5) / 6, 0.864720, 1},
        {VP_SHAPE_TRUNCATED_DODECAHEDRON, 60, 90, 20, 0, 0, 0, 0, 12, 5 * (99 + 47 * r5) / 12,
         0.897787, 1},
        {VP_SHAPE_TRUNCATED_ICOSAHEDRON, 60, 90, 0, 0, 12, 20, 0, 0, (125 + 43 * r5) / 4, 0.784987,
         1},
        {VP_SHAPE_RHOMBICOSIDODECAHEDRON, 60, 120, 20, 30, 12, 0, 0, 0, (60 + 29 * r5) / 3,
         0.804708, 1},
        {VP_SHAPE_TRUNCATED_ICOSIDODECAHEDRON, 120, 180, 0, 30, 0, 20, 0, 12, 95 + 50 * r5,
         0.827213, 1},
        {VP_SHAPE_SNUB_DODECAHEDRON, 60, 150, 80, 0, 12, 0, 0, 0, 37.61664996, 0.788640, 0},
    };
    memcpy(solids, t, sizeof t);
}

static double edge_length(const vp_polyhedron *p) {
    double e = HUGE_VAL;
    for (int i = 0; i < p->nverts; i++)
        for (int j = i + 1; j < p->nverts; j++) {
            double d[3] = {p->verts[i][0] - p->verts[j][0], p->verts[i][1] - p->verts[j][1],
                           p->verts[i][2] - p->verts[j][2]};
            if (vp_norm3(d) < e) e = vp_norm3(d);
        }
    return e;
}

static void test_polyhedra(void) {
    for (int k = 0; k < 13; k++) {
        const solid *S = &solids[k];
        const vp_polyhedron *p = vp_shape_polyhedron(S->s);
        ASSERT_TRUE(p != NULL);
        vp_shape back;
        ASSERT_EQ_INT(vp_shape_parse(vp_shape_name(S->s), &back), 0);
        ASSERT_EQ_INT(back, S->s);
        int cnt[11] = {0};
        for (int f = 0; f < p->nfaces; f++) {
            ASSERT_TRUE(p->face_size[f] >= 3 && p->face_size[f] <= 10);
            cnt[p->face_size[f]]++;
        }
        double a = edge_length(p);
        fprintf(stderr,
                "   %-28s V=%d E=%d F=%d (3:%d 4:%d 5:%d 6:%d 8:%d 10:%d) edge %.6f vol %.12f\n",
                vp_shape_name(S->s), p->nverts, p->nedges, p->nfaces, cnt[3], cnt[4], cnt[5],
                cnt[6], cnt[8], cnt[10], a, p->volume);
        ASSERT_EQ_INT(p->nverts, S->V);
        ASSERT_EQ_INT(p->nedges, S->E);
        ASSERT_EQ_INT(cnt[3], S->f3);
        ASSERT_EQ_INT(cnt[4], S->f4);
        ASSERT_EQ_INT(cnt[5], S->f5);
        ASSERT_EQ_INT(cnt[6], S->f6);
        ASSERT_EQ_INT(cnt[8], S->f8);
        ASSERT_EQ_INT(cnt[10], S->f10);
        /* vertices on the unit sphere, every edge of the same length */
        for (int i = 0; i < p->nverts; i++) ASSERT_NEAR(vp_norm3(p->verts[i]), 1.0, 1e-14);
        for (int e = 0; e < p->nedges; e++) {
            const double *u = p->verts[p->edges[e][0]], *w = p->verts[p->edges[e][1]];
            double d[3] = {u[0] - w[0], u[1] - w[1], u[2] - w[2]};
            ASSERT_NEAR(vp_norm3(d), a, 1e-12);
        }
        /* the volume of the closed form at that edge (the snubs: 8 digits) */
        ASSERT_NEAR(p->volume / (S->vol_a3 * a * a * a), 1.0, 1e-7);
        /* central symmetry as expected */
        int sym = 1;
        for (int i = 0; i < p->nverts && sym; i++) {
            int found = 0;
            for (int j = 0; j < p->nverts; j++)
                if (fabs(p->verts[i][0] + p->verts[j][0]) + fabs(p->verts[i][1] + p->verts[j][1]) +
                        fabs(p->verts[i][2] + p->verts[j][2]) <
                    1e-12)
                    found = 1;
            sym = found;
        }
        ASSERT_EQ_INT(sym, S->symmetric);
        ASSERT_EQ_INT(vp_shape_overlap_by_gjk(S->s), 1);
    }
    ASSERT_EQ_INT(vp_shape_overlap_by_gjk(VP_SHAPE_ICOSAHEDRON), 0);
    /* names: '_' for '-', any case; unknown ones refused */
    vp_shape s;
    ASSERT_EQ_INT(vp_shape_parse("Truncated_Octahedron", &s), 0);
    ASSERT_EQ_INT(s, VP_SHAPE_TRUNCATED_OCTAHEDRON);
    ASSERT_EQ_INT(vp_shape_parse("truncated-octahedra", &s), -1);
    ASSERT_EQ_INT(vp_shape_parse("snub-tetrahedron", &s), -1);
}

/* The difference body D = K - K, seen through its support function
 * w(n) = max_K n.x - min_K n.x: its facet normals are cross products of
 * two edge directions of K (a face normal of K is one too, of two edges of
 * that face), so the gauge of D is max |n.v| / w(n) over all those n. The
 * lattice translates of K overlap iff a non-zero lattice vector has gauge
 * < 1 (Minkowski). Edges are found here (the vertex pairs at the least
 * distance), not taken from shape.c. Returns the number of axes. */
#define MAXAX 20000
static int diff_axes(const vp_polyhedron *p, double (*ax)[3], double *w) {
    static double dirs[200][3];
    double a = edge_length(p);
    int nd = 0, m = 0;
    for (int i = 0; i < p->nverts; i++)
        for (int j = i + 1; j < p->nverts; j++) {
            double d[3] = {p->verts[j][0] - p->verts[i][0], p->verts[j][1] - p->verts[i][1],
                           p->verts[j][2] - p->verts[i][2]};
            if (fabs(vp_norm3(d) - a) > 1e-9 || nd >= 200) continue;
            for (int c = 0; c < 3; c++) dirs[nd][c] = d[c] / a;
            nd++;
        }
    for (int i = 0; i < nd; i++)
        for (int j = i + 1; j < nd && m < MAXAX; j++) {
            double c[3];
            vp_cross3(dirs[i], dirs[j], c);
            double l = vp_norm3(c);
            if (l < 1e-6) continue;
            double lo = HUGE_VAL, hi = -HUGE_VAL;
            for (int k = 0; k < 3; k++) c[k] /= l;
            for (int v = 0; v < p->nverts; v++) {
                double t = vp_dot3(c, p->verts[v]);
                if (t < lo) lo = t;
                if (t > hi) hi = t;
            }
            memcpy(ax[m], c, sizeof c);
            w[m++] = hi - lo;
        }
    return m;
}

static double gauge(const double (*ax)[3], const double *w, int m, const double v[3]) {
    double g = 0;
    for (int f = 0; f < m; f++) {
        double t = fabs(vp_dot3(ax[f], v)) / w[f];
        if (t > g) g = t;
    }
    return g;
}

static void test_lattices(void) {
    static double nf[MAXAX][3], hf[MAXAX];
    for (int k = 0; k < 13; k++) {
        const solid *S = &solids[k];
        const vp_polyhedron *p = vp_shape_polyhedron(S->s);
        int m = diff_axes(p, nf, hf);
        ASSERT_TRUE(m < MAXAX);
        vp_lattice_basis b;
        ASSERT_EQ_INT(vp_lattice_basis_get(S->s, VP_LATTICE_DENSEST, &b), 0);
        ASSERT_EQ_INT(vp_lattice_basis_get(S->s, VP_LATTICE_FCC, &b), -1);
        ASSERT_EQ_INT(vp_lattice_basis_get(S->s, VP_LATTICE_DEFAULT, &b), 0);
        double det = vp_det3(b.a[0], b.a[1], b.a[2]);
        ASSERT_TRUE(det > 0);
        double lam = HUGE_VAL;
        int touch = 0;
        for (int i = -3; i <= 3; i++)
            for (int j = -3; j <= 3; j++)
                for (int l = -3; l <= 3; l++) {
                    if (!i && !j && !l) continue;
                    double v[3];
                    for (int q = 0; q < 3; q++)
                        v[q] = i * b.a[0][q] + j * b.a[1][q] + l * b.a[2][q];
                    double g = gauge((const double(*)[3])nf, hf, m, v);
                    if (g < lam) lam = g;
                    if (fabs(g - 1) < 1e-7) touch++;
                }
        double a = edge_length(p);
        double frac = S->vol_a3 * a * a * a / det;
        fprintf(stderr,
                "   %-28s %5d axes; least gauge %.15f, %2d contacts, fraction %.9f "
                "(densest known %.6f, %+.2g)\n",
                vp_shape_name(S->s), m, lam, touch, frac, S->lit, frac - S->lit);
        /* no overlap (to rounding), and at contact */
        ASSERT_GE(lam, 1 - 1e-12);
        ASSERT_LE(lam, 1 + 1e-9);
        ASSERT_TRUE(touch >= 6 && touch % 2 == 0);
        /* the stored fraction is the basis's, and that of the densest lattice */
        ASSERT_NEAR(b.fraction, p->volume / det, 1e-12);
        ASSERT_LE(frac, S->lit + 1e-6);
        ASSERT_GE(frac, S->lit - 1e-6);
        /* the SAT of shape.c agrees on the nearest translates: apart or touching */
        static const double qid[4] = {0, 0, 0, 1}, o[3] = {0, 0, 0};
        for (int i = -1; i <= 1; i++)
            for (int j = -1; j <= 1; j++)
                for (int l = -1; l <= 1; l++) {
                    if (!i && !j && !l) continue;
                    double v[3];
                    for (int q = 0; q < 3; q++)
                        v[q] = i * b.a[0][q] + j * b.a[1][q] + l * b.a[2][q];
                    ASSERT_GE(vp_poly_separation(p, 1, qid, o, p, 1, qid, v), -1e-9);
                }
    }
}

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double urand(void) {
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}
static void rand_quat(double q[4]) {
    double n = 0;
    for (int k = 0; k < 4; k++) {
        q[k] = 2 * urand() - 1;
        n += q[k] * q[k];
    }
    n = sqrt(n);
    for (int k = 0; k < 4; k++) q[k] /= n;
}

/* The packers' GJK (vp_convex_overlap) against the SAT on random pairs near
 * contact: every pair farther than 1e-9 from touching gets the same answer. */
static void test_gjk_against_sat(void) {
    for (int k = 0; k < 13; k++) {
        vp_shape s = solids[k].s;
        const vp_polyhedron *p = vp_shape_polyhedron(s);
        int agree = 0, overl = 0;
        for (int t = 0; t < 300; t++) {
            double qa[4], qb[4], ta[3] = {0, 0, 0}, tb[3], d[3];
            rand_quat(qa);
            rand_quat(qb);
            double n = 0;
            for (int c = 0; c < 3; c++) {
                d[c] = 2 * urand() - 1;
                n += d[c] * d[c];
            }
            n = sqrt(n);
            double rb = 0.5 + urand(),
                   dist = (p->inradius * (1 + rb)) + urand() * (1 - p->inradius) * (1 + rb);
            for (int c = 0; c < 3; c++) tb[c] = d[c] / n * dist;
            double sep = vp_poly_separation(p, 1, qa, ta, p, rb, qb, tb);
            vp_convex A, B;
            vp_convex_set(&A, s, 0, 1, qa, ta, ta);
            vp_convex_set(&B, s, 0, rb, qb, tb, ta);
            int ov = vp_convex_overlap(&A, &B);
            if (fabs(sep) < 1e-9) continue;
            ASSERT_EQ_INT(ov, sep < 0);
            agree++;
            overl += ov;
        }
        fprintf(stderr, "   %-28s GJK = SAT on %d pairs (%d overlapping)\n", vp_shape_name(s),
                agree, overl);
        ASSERT_TRUE(agree > 250 && overl > 20 && overl < agree - 20);
    }
}

int main(void) {
    fill();
    RUN_TEST(test_polyhedra);
    RUN_TEST(test_lattices);
    RUN_TEST(test_gjk_against_sat);
    return 0;
}
