/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of src/core/shape.c: names, the unit polyhedra (closed-form
 * volumes and inradii, topology, orientation), the separating-axis test
 * against an independent brute-force overlap check, and the cube's quick
 * centre tests against the separating-axis test. */
#include "core/geom.h"
#include "core/shape.h"
#include "vp_test.h"

#include <string.h>

#define PI_ 3.14159265358979323846

/* ------------------------------------------------------------------ */
static void test_names(void) {
    vp_shape s;
    for (int i = 0; i < VP_SHAPE_COUNT; ++i) {
        const char *n = vp_shape_name((vp_shape)i);
        ASSERT_TRUE(n != NULL);
        ASSERT_EQ_INT(vp_shape_parse(n, &s), 0);
        ASSERT_EQ_INT(s, i);
    }
    ASSERT_TRUE(strcmp(vp_shape_name(VP_SHAPE_DODECAHEDRON), "dodecahedron") == 0);
    ASSERT_EQ_INT(vp_shape_parse("ICOSAHEDRON", &s), 0);
    ASSERT_EQ_INT(s, VP_SHAPE_ICOSAHEDRON);
    ASSERT_EQ_INT(vp_shape_parse("Cube", &s), 0);
    ASSERT_EQ_INT(s, VP_SHAPE_CUBE);
    ASSERT_TRUE(vp_shape_parse("cubes", &s) != 0);
    ASSERT_TRUE(vp_shape_parse("", &s) != 0);
    ASSERT_TRUE(vp_shape_parse(NULL, &s) != 0);
    ASSERT_TRUE(vp_shape_name(VP_SHAPE_COUNT) == NULL);
    ASSERT_TRUE(vp_shape_name((vp_shape)-1) == NULL);

    static const char *const ln[] = {"default", "sc", "bcc", "fcc", "hcp", "densest"};
    vp_lattice l;
    for (int i = 0; i < 6; ++i) {
        ASSERT_TRUE(strcmp(vp_lattice_name((vp_lattice)i), ln[i]) == 0);
        ASSERT_EQ_INT(vp_lattice_parse(ln[i], &l), 0);
        ASSERT_EQ_INT(l, i);
    }
    ASSERT_EQ_INT(vp_lattice_parse("HCP", &l), 0);
    ASSERT_EQ_INT(l, VP_LATTICE_HCP);
    ASSERT_TRUE(vp_lattice_parse("diamond", &l) != 0);
    ASSERT_TRUE(vp_lattice_name((vp_lattice)6) == NULL);
    ASSERT_TRUE(vp_shape_polyhedron(VP_SHAPE_SPHERE) == NULL);
    ASSERT_NEAR(vp_shape_unit_volume(VP_SHAPE_SPHERE), 4.0 * PI_ / 3.0, 1e-15);
}

/* ------------------------------------------------------------------ */
/* Closed forms at circumradius 1: edge a, volume, inradius. */
static void closed_form(vp_shape s, int *v, int *e, int *f, double *vol, double *inr) {
    const double r5 = sqrt(5.0), phi = 0.5 * (1 + r5);
    double a;
    switch (s) {
    case VP_SHAPE_TETRAHEDRON:
        a = sqrt(8.0 / 3.0);
        *v = 4;
        *e = 6;
        *f = 4;
        *vol = a * a * a / (6 * sqrt(2.0));
        *inr = a / sqrt(24.0);
        break;
    case VP_SHAPE_CUBE:
        a = 2 / sqrt(3.0);
        *v = 8;
        *e = 12;
        *f = 6;
        *vol = a * a * a;
        *inr = a / 2;
        break;
    case VP_SHAPE_OCTAHEDRON:
        a = sqrt(2.0);
        *v = 6;
        *e = 12;
        *f = 8;
        *vol = sqrt(2.0) / 3 * a * a * a;
        *inr = a / sqrt(6.0);
        break;
    case VP_SHAPE_DODECAHEDRON:
        a = 4 / (sqrt(3.0) * (1 + r5));
        *v = 20;
        *e = 30;
        *f = 12;
        *vol = (15 + 7 * r5) / 4 * a * a * a;
        *inr = a / 2 * sqrt((25 + 11 * r5) / 10);
        break;
    default: /* icosahedron */
        a = 1 / sin(2 * PI_ / 5);
        *v = 12;
        *e = 30;
        *f = 20;
        *vol = 5 * (3 + r5) / 12 * a * a * a;
        *inr = phi * phi * a / (2 * sqrt(3.0));
        break;
    }
}

static int has_vertex(const vp_polyhedron *p, double x, double y, double z) {
    double n = sqrt(x * x + y * y + z * z);
    for (int i = 0; i < p->nverts; ++i)
        if (fabs(p->verts[i][0] - x / n) < 1e-14 && fabs(p->verts[i][1] - y / n) < 1e-14 &&
            fabs(p->verts[i][2] - z / n) < 1e-14)
            return 1;
    return 0;
}

static void test_polyhedra(void) {
    const double phi = 0.5 * (1 + sqrt(5.0));
    for (int s = VP_SHAPE_TETRAHEDRON; s <= VP_SHAPE_ICOSAHEDRON;
         ++s) { /* the Archimedean: test_archimedean.c */
        const vp_polyhedron *p = vp_shape_polyhedron((vp_shape)s);
        ASSERT_TRUE(p != NULL);
        ASSERT_TRUE(p == vp_shape_polyhedron((vp_shape)s));
        int V, E, F;
        double vol, inr;
        closed_form((vp_shape)s, &V, &E, &F, &vol, &inr);
        fprintf(stderr, "   %-12s V=%d E=%d F=%d vol=%.17g inr=%.17g\n", vp_shape_name((vp_shape)s),
                p->nverts, p->nedges, p->nfaces, p->volume, p->inradius);
        ASSERT_EQ_INT(p->nverts, V);
        ASSERT_EQ_INT(p->nedges, E);
        ASSERT_EQ_INT(p->nfaces, F);
        ASSERT_EQ_INT(p->nverts - p->nedges + p->nfaces, 2);
        ASSERT_NEAR(p->volume, vol, 1e-13);
        ASSERT_NEAR(vp_shape_unit_volume((vp_shape)s), vol, 1e-13);
        ASSERT_NEAR(p->inradius, inr, 1e-13);

        double cen[3] = {0, 0, 0};
        for (int i = 0; i < p->nverts; ++i) {
            ASSERT_NEAR(vp_norm3(p->verts[i]), 1.0, 1e-15);
            for (int c = 0; c < 3; ++c) cen[c] += p->verts[i][c] / p->nverts;
        }
        ASSERT_NEAR(vp_norm3(cen), 0.0, 1e-15);

        /* edge length: all edges equal to the closed-form edge */
        double a0 = -1;
        for (int e = 0; e < p->nedges; ++e) {
            double d[3];
            for (int c = 0; c < 3; ++c)
                d[c] = p->verts[p->edges[e][0]][c] - p->verts[p->edges[e][1]][c];
            if (a0 < 0) a0 = vp_norm3(d);
            ASSERT_NEAR(vp_norm3(d), a0, 1e-14);
            for (int f = 0; f < e; ++f) /* unique */
                ASSERT_TRUE(
                    !((p->edges[f][0] == p->edges[e][0] && p->edges[f][1] == p->edges[e][1]) ||
                      (p->edges[f][0] == p->edges[e][1] && p->edges[f][1] == p->edges[e][0])));
        }

        /* faces: unit outward normals, planar, CCW seen from outside; every
         * directed edge used exactly once (closed 2-manifold); divergence
         * volume from the triangle fans. */
        double vol2 = 0;
        int used[VP_POLY_MAX_VERTS][VP_POLY_MAX_VERTS];
        memset(used, 0, sizeof used);
        for (int f = 0; f < p->nfaces; ++f) {
            const double *n = p->normals[f];
            int k = p->face_size[f];
            ASSERT_TRUE(k >= 3 && k <= VP_POLY_MAX_FACE_VERTS);
            ASSERT_NEAR(vp_norm3(n), 1.0, 1e-15);
            double h = vp_dot3(n, p->verts[p->faces[f][0]]);
            ASSERT_NEAR(h, p->inradius, 1e-14); /* regular solid: all faces at the inradius */
            for (int i = 0; i < p->nverts; ++i) ASSERT_LE(vp_dot3(n, p->verts[i]), h + 1e-14);
            for (int m = 0; m < k; ++m) {
                const double *v0 = p->verts[p->faces[f][m]],
                             *v1 = p->verts[p->faces[f][(m + 1) % k]],
                             *v2 = p->verts[p->faces[f][(m + 2) % k]];
                ASSERT_NEAR(vp_dot3(n, v0), h, 1e-14);
                double e1[3], e2[3], c[3];
                for (int q = 0; q < 3; ++q) {
                    e1[q] = v1[q] - v0[q];
                    e2[q] = v2[q] - v1[q];
                }
                vp_cross3(e1, e2, c);
                ASSERT_TRUE(vp_dot3(c, n) > 1e-6); /* convex CCW turn about the outward normal */
                used[p->faces[f][m]][p->faces[f][(m + 1) % k]]++;
            }
            for (int m = 1; m + 1 < k; ++m)
                vol2 += vp_det3(p->verts[p->faces[f][0]], p->verts[p->faces[f][m]],
                                p->verts[p->faces[f][m + 1]]) /
                        6.0;
        }
        ASSERT_NEAR(vol2, vol, 1e-13);
        int directed = 0;
        for (int i = 0; i < p->nverts; ++i)
            for (int j = 0; j < p->nverts; ++j) {
                ASSERT_TRUE(used[i][j] <= 1);
                if (used[i][j]) {
                    ASSERT_EQ_INT(used[j][i], 1);
                    ++directed;
                }
            }
        ASSERT_EQ_INT(directed, 2 * p->nedges);
    }
    /* canonical orientations (docs/lattices.md) */
    ASSERT_TRUE(has_vertex(vp_shape_polyhedron(VP_SHAPE_TETRAHEDRON), 1, 1, 1));
    ASSERT_TRUE(has_vertex(vp_shape_polyhedron(VP_SHAPE_TETRAHEDRON), -1, -1, 1));
    ASSERT_TRUE(!has_vertex(vp_shape_polyhedron(VP_SHAPE_TETRAHEDRON), -1, -1, -1));
    ASSERT_TRUE(has_vertex(vp_shape_polyhedron(VP_SHAPE_CUBE), 1, -1, 1));
    ASSERT_TRUE(has_vertex(vp_shape_polyhedron(VP_SHAPE_OCTAHEDRON), 0, 0, -1));
    ASSERT_TRUE(has_vertex(vp_shape_polyhedron(VP_SHAPE_DODECAHEDRON), 1, 1, 1));
    ASSERT_TRUE(has_vertex(vp_shape_polyhedron(VP_SHAPE_DODECAHEDRON), 0, 1 / phi, phi));
    ASSERT_TRUE(has_vertex(vp_shape_polyhedron(VP_SHAPE_DODECAHEDRON), phi, 0, -1 / phi));
    ASSERT_TRUE(has_vertex(vp_shape_polyhedron(VP_SHAPE_ICOSAHEDRON), 0, 1, phi));
    ASSERT_TRUE(has_vertex(vp_shape_polyhedron(VP_SHAPE_ICOSAHEDRON), -1, phi, 0));
    ASSERT_TRUE(has_vertex(vp_shape_polyhedron(VP_SHAPE_ICOSAHEDRON), phi, 0, 1));
    ASSERT_TRUE(!has_vertex(vp_shape_polyhedron(VP_SHAPE_ICOSAHEDRON), 0, phi, 1));
}

/* ------------------------------------------------------------------ */
/* Separating-axis test                                                */

static void test_sat_simple(void) {
    const vp_polyhedron *cube = vp_shape_polyhedron(VP_SHAPE_CUBE);
    const vp_polyhedron *oct = vp_shape_polyhedron(VP_SHAPE_OCTAHEDRON);
    const double q0[4] = {0, 0, 0, 1}, o[3] = {0, 0, 0};
    const double edge = 2 / sqrt(3.0);
    /* face to face along x: touching at distance edge */
    for (int axis = 0; axis < 3; ++axis) {
        double t[3] = {0, 0, 0};
        t[axis] = edge;
        ASSERT_NEAR(vp_poly_separation(cube, 1, q0, o, cube, 1, q0, t), 0.0, 1e-14);
        t[axis] = edge - 0.01;
        ASSERT_NEAR(vp_poly_separation(cube, 1, q0, o, cube, 1, q0, t), -0.01, 1e-14);
        t[axis] = edge + 0.25;
        ASSERT_NEAR(vp_poly_separation(cube, 1, q0, o, cube, 1, q0, t), 0.25, 1e-14);
        t[axis] = -(edge + 0.25);
        ASSERT_NEAR(vp_poly_separation(cube, 1, q0, o, cube, 1, q0, t), 0.25, 1e-14);
    }
    /* scales: cube of scale 2 next to cube of scale 0.5 */
    {
        double t[3] = {edge * (2 + 0.5) / 2 + 0.125, 0.1, -0.2};
        ASSERT_NEAR(vp_poly_separation(cube, 2, q0, o, cube, 0.5, q0, t), 0.125, 1e-14);
        double ta[3] = {5, 5, 5}, tb[3] = {5 + t[0], 5 + t[1], 5 + t[2]};
        ASSERT_NEAR(vp_poly_separation(cube, 2, q0, ta, cube, 0.5, q0, tb), 0.125, 1e-13);
    }
    /* octahedra vertex to vertex along z */
    {
        double t[3] = {0, 0, 2};
        ASSERT_NEAR(vp_poly_separation(oct, 1, q0, o, oct, 1, q0, t), 0.0, 1e-14);
        t[2] = 2.5;
        ASSERT_NEAR(vp_poly_separation(oct, 1, q0, o, oct, 1, q0, t), 0.5, 1e-14);
        /* face to face along (1,1,1): touching at 2*inradius */
        double d = 2 / sqrt(3.0) / sqrt(3.0);
        double u[3] = {d, d, d};
        ASSERT_NEAR(vp_poly_separation(oct, 1, q0, o, oct, 1, q0, u), 0.0, 1e-14);
    }
    /* a cube turned 45 degrees about z, edge first towards an axis-aligned
     * cube: touching at x = edge/2 + edge/sqrt(2) */
    {
        double q45[4] = {0, 0, sin(PI_ / 8), cos(PI_ / 8)};
        double t[3] = {edge / 2 + edge / sqrt(2.0), 0.05, 0};
        ASSERT_NEAR(vp_poly_separation(cube, 1, q0, o, cube, 1, q45, t), 0.0, 1e-14);
        t[0] += 0.1;
        ASSERT_NEAR(vp_poly_separation(cube, 1, q0, o, cube, 1, q45, t), 0.1, 1e-14);
    }
    /* edge-edge contact that no face normal detects: two cubes turned 45
     * degrees about perpendicular axes (z and x), crossing edges along
     * (1,1,1)/sqrt(3)-free directions: the gap along x is only found via
     * the cross product of the two edge directions. */
    {
        double qz[4] = {0, 0, sin(PI_ / 8), cos(PI_ / 8)},
               qx[4] = {sin(PI_ / 8), 0, 0, cos(PI_ / 8)};
        /* A's edge along z sits at y = edge/sqrt(2); B's edge along x at
         * y = -edge/sqrt(2) relative to B. Touch when B is at y = 2*edge/sqrt(2). */
        double t[3] = {0, 2 * edge / sqrt(2.0) + 0.01, 0};
        double s = vp_poly_separation(cube, 1, qz, o, cube, 1, qx, t);
        ASSERT_NEAR(s, 0.01, 1e-14);
        t[1] -= 0.02;
        s = vp_poly_separation(cube, 1, qz, o, cube, 1, qx, t);
        ASSERT_NEAR(s, -0.01, 1e-14);
    }
    /* NULL pose pointers mean identity / origin */
    {
        double t[3] = {edge + 0.5, 0, 0};
        ASSERT_NEAR(vp_poly_separation(cube, 1, NULL, NULL, cube, 1, NULL, t), 0.5, 1e-14);
    }
}

/* World face planes of a posed polyhedron: n.x <= d. */
static void posed(const vp_polyhedron *p, double s, const double q[4], const double t[3],
                  double verts[][3], double nrm[][3], double d[]) {
    for (int i = 0; i < p->nverts; ++i) {
        double r[3];
        vp_quat_rotate(q, p->verts[i], r);
        for (int c = 0; c < 3; ++c) verts[i][c] = s * r[c] + t[c];
    }
    for (int f = 0; f < p->nfaces; ++f) {
        vp_quat_rotate(q, p->normals[f], nrm[f]);
        d[f] = vp_dot3(nrm[f], t) + s * vp_dot3(p->normals[f], p->verts[p->faces[f][0]]);
    }
}

/* Does some edge of (va, a) meet the polyhedron given by planes (nb, db)? */
static int edges_hit(const vp_polyhedron *a, double va[][3], const vp_polyhedron *b, double nb[][3],
                     const double db[]) {
    for (int e = 0; e < a->nedges; ++e) {
        const double *p0 = va[a->edges[e][0]], *p1 = va[a->edges[e][1]];
        double lo = 0, hi = 1, dir[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        for (int f = 0; f < b->nfaces && lo <= hi; ++f) {
            double num = db[f] - vp_dot3(nb[f], p0), den = vp_dot3(nb[f], dir);
            if (fabs(den) < 1e-300) {
                if (num < 0) hi = -1;
                continue;
            }
            double t = num / den;
            if (den > 0) {
                if (t < hi) hi = t;
            } else {
                if (t > lo) lo = t;
            }
        }
        if (lo <= hi) return 1;
    }
    return 0;
}

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double urand(void) {
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) * (1.0 / 9007199254740992.0);
}
static void rand_quat(double q[4]) {
    double n;
    do {
        for (int i = 0; i < 4; ++i) q[i] = 2 * urand() - 1;
        n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    } while (n < 0.1 || n > 1);
    for (int i = 0; i < 4; ++i) q[i] /= n;
}

/* Face-normal-only separation (what a SAT without edge axes would say). */
static double face_only(const vp_polyhedron *a, double va[][3], double na[][3],
                        const vp_polyhedron *b, double vb[][3], double nb[][3]) {
    double best = -HUGE_VAL;
    for (int pass = 0; pass < 2; ++pass) {
        const vp_polyhedron *p = pass ? b : a;
        double(*n)[3] = pass ? nb : na;
        for (int f = 0; f < p->nfaces; ++f) {
            double alo = HUGE_VAL, ahi = -HUGE_VAL, blo = HUGE_VAL, bhi = -HUGE_VAL;
            for (int i = 0; i < a->nverts; ++i) {
                double x = vp_dot3(n[f], va[i]);
                if (x < alo) alo = x;
                if (x > ahi) ahi = x;
            }
            for (int i = 0; i < b->nverts; ++i) {
                double x = vp_dot3(n[f], vb[i]);
                if (x < blo) blo = x;
                if (x > bhi) bhi = x;
            }
            double g = blo - ahi > alo - bhi ? blo - ahi : alo - bhi;
            if (g > best) best = g;
        }
    }
    return best;
}

static void test_sat_random(void) {
    int checked = 0, overl = 0, sep = 0, edge_only = 0, posed_checked = 0;
    for (int it = 0; it < 6000; ++it) {
        vp_shape sa = (vp_shape)(1 + it % 5), sb = (vp_shape)(1 + (it / 5) % 5);
        const vp_polyhedron *a = vp_shape_polyhedron(sa), *b = vp_shape_polyhedron(sb);
        double qa[4], qb[4], ta[3], tb[3], dir[3];
        rand_quat(qa);
        rand_quat(qb);
        double ka = 0.5 + urand(), kb = 0.5 + urand();
        for (int c = 0; c < 3; ++c) ta[c] = 4 * urand() - 2;
        do {
            for (int c = 0; c < 3; ++c) dir[c] = 2 * urand() - 1;
        } while (vp_norm3(dir) < 0.1 || vp_norm3(dir) > 1);
        double dn = vp_norm3(dir);
        /* distance between the inscribed and the bounding sphere sums */
        double lo = ka * a->inradius + kb * b->inradius, hi = ka + kb;
        double dist = lo + (hi - lo) * (1.2 * urand() - 0.1);
        for (int c = 0; c < 3; ++c) tb[c] = ta[c] + dist * dir[c] / dn;

        double s = vp_poly_separation(a, ka, qa, ta, b, kb, qb, tb);
        /* symmetric in its arguments */
        ASSERT_NEAR(vp_poly_separation(b, kb, qb, tb, a, ka, qa, ta), s, 1e-12);
        /* never more than the centre gap minus the inscribed radii, never
         * less than minus the bounding radii */
        ASSERT_LE(s, dist - lo + 1e-12);
        /* the posed test (the packers' early-exit form) gives the same
         * answer on every pair, near-contact ones included, and posing
         * relative to another origin gives the same separation */
        vp_poly_posed pa, pb;
        vp_poly_pose(a, ka, qa, ta, ta, &pa);
        vp_poly_pose(b, kb, qb, tb, ta, &pb);
        ASSERT_EQ_INT(vp_poly_posed_overlap(&pa, &pb), s < 0);
        ASSERT_TRUE(vp_poly_posed_separation(&pa, &pb) == s);
        posed_checked++;
        if (fabs(s) <= 1e-3) continue;
        double va[VP_POLY_MAX_VERTS][3], vb[VP_POLY_MAX_VERTS][3];
        double na[VP_POLY_MAX_FACES][3], nb[VP_POLY_MAX_FACES][3], da[VP_POLY_MAX_FACES],
            db[VP_POLY_MAX_FACES];
        posed(a, ka, qa, ta, va, na, da);
        posed(b, kb, qb, tb, vb, nb, db);
        int ref = edges_hit(a, va, b, nb, db) || edges_hit(b, vb, a, na, da);
        if (ref != (s < 0)) {
            fprintf(stderr, "   mismatch it=%d %s/%s sep=%.6g ref overlap=%d\n", it,
                    vp_shape_name(sa), vp_shape_name(sb), s, ref);
        }
        ASSERT_EQ_INT(ref, s < 0);
        if (s > 0) {
            /* count the pairs that only an edge-edge axis separates */
            ++sep;
            if (face_only(a, va, na, b, vb, nb) < 0) ++edge_only;
        } else {
            ++overl;
        }
        ++checked;
    }
    fprintf(stderr,
            "   random SAT pairs checked: %d (overlapping %d, separated %d, of which %d "
            "only by an edge-edge axis)\n",
            checked, overl, sep, edge_only);
    ASSERT_TRUE(checked > 3000);
    ASSERT_EQ_INT(posed_checked, 6000);
    ASSERT_TRUE(overl > 500);
    ASSERT_TRUE(sep > 500);
    ASSERT_TRUE(edge_only > 20);
}

/* Touching pairs found by bisection on the reference: the SAT value at the
 * reference's contact distance must be ~0. */
static void test_sat_contact(void) {
    int n = 0;
    for (int it = 0; it < 300; ++it) {
        vp_shape sa = (vp_shape)(1 + it % 5), sb = (vp_shape)(1 + (it / 5) % 5);
        const vp_polyhedron *a = vp_shape_polyhedron(sa), *b = vp_shape_polyhedron(sb);
        double qa[4], qb[4], ta[3] = {0.3, -0.2, 0.1}, dir[3];
        rand_quat(qa);
        rand_quat(qb);
        do {
            for (int c = 0; c < 3; ++c) dir[c] = 2 * urand() - 1;
        } while (vp_norm3(dir) < 0.1 || vp_norm3(dir) > 1);
        double dn = vp_norm3(dir);
        double lo = 0, hi = 2.5; /* reference overlaps at lo, not at hi */
        for (int k = 0; k < 60; ++k) {
            double mid = 0.5 * (lo + hi), tb[3];
            for (int c = 0; c < 3; ++c) tb[c] = ta[c] + mid * dir[c] / dn;
            double va[VP_POLY_MAX_VERTS][3], vb[VP_POLY_MAX_VERTS][3];
            double na[VP_POLY_MAX_FACES][3], nb[VP_POLY_MAX_FACES][3], da[VP_POLY_MAX_FACES],
                db[VP_POLY_MAX_FACES];
            posed(a, 1, qa, ta, va, na, da);
            posed(b, 1, qb, tb, vb, nb, db);
            if (edges_hit(a, va, b, nb, db) || edges_hit(b, vb, a, na, da)) lo = mid;
            else hi = mid;
        }
        double tb[3];
        for (int c = 0; c < 3; ++c) tb[c] = ta[c] + hi * dir[c] / dn;
        double s = vp_poly_separation(a, 1, qa, ta, b, 1, qb, tb);
        ASSERT_NEAR(s, 0.0, 1e-9);
        vp_poly_posed pa, pb;
        vp_poly_pose(a, 1, qa, ta, ta, &pa);
        vp_poly_pose(b, 1, qb, tb, ta, &pb);
        ASSERT_EQ_INT(vp_poly_posed_overlap(&pa, &pb), s < 0);
        ++n;
    }
    ASSERT_EQ_INT(n, 300);
}

/* The cube's quick cases (vp_cube_center_test, used by the RSA packer
 * before the SAT) against the SAT: a random cube A and solid B of every
 * shape, B's centre at random offsets and at offsets bisected onto the
 * two thresholds (its distance to A equal to B's inradius or to its
 * radius, times 1 -+ 1e-7); every pair the quick test decides must get
 * the SAT's answer, and both answers must occur. */
static double cube_point_dist(const double R[3][3], double h, const double d[3]) {
    double f = 0.0;
    for (int k = 0; k < 3; ++k) {
        double u = fabs(R[0][k] * d[0] + R[1][k] * d[1] + R[2][k] * d[2]) - h;
        if (u > 0) f += u * u;
    }
    return sqrt(f);
}

static void test_cube_center(void) {
    const vp_polyhedron *cube = vp_shape_polyhedron(VP_SHAPE_CUBE);
    int decided[2] = {0, 0}, n = 0;
    for (int it = 0; it < 20000; ++it) {
        vp_shape sb = (vp_shape)(1 + it % 5);
        const vp_polyhedron *b = vp_shape_polyhedron(sb);
        double qa[4], qb[4], ta[3] = {0.3, -0.7, 0.2}, tb[3], dir[3], R[3][3];
        rand_quat(qa);
        rand_quat(qb);
        vp_quat_to_matrix(qa, R);
        double ka = 0.5 + urand(), kb = 0.5 + urand(), h = ka * cube->inradius;
        do {
            for (int c = 0; c < 3; ++c) dir[c] = 2 * urand() - 1;
        } while (vp_norm3(dir) < 0.1 || vp_norm3(dir) > 1);
        double dn = vp_norm3(dir), dist;
        int mode = it % 3;
        if (mode == 0) {
            dist = 3.0 * urand() * (ka + kb);
        } else { /* the distance to the cube along dir grows: bisect onto a threshold */
            double target =
                (mode == 1 ? kb * b->inradius : kb) * (1.0 + ((it / 3) % 2 ? 1e-7 : -1e-7));
            double lo = 0.0, hi = 4.0 * (ka + kb);
            for (int k = 0; k < 200; ++k) {
                double mid = 0.5 * (lo + hi), d[3];
                for (int c = 0; c < 3; ++c) d[c] = mid * dir[c] / dn;
                if (cube_point_dist((const double(*)[3])R, h, d) < target) lo = mid;
                else hi = mid;
            }
            dist = 0.5 * (lo + hi);
        }
        double d[3];
        for (int c = 0; c < 3; ++c) {
            tb[c] = ta[c] + dist * dir[c] / dn;
            d[c] = tb[c] - ta[c];
        }
        int v = vp_cube_center_test((const double(*)[3])R, h, d, kb * b->inradius, kb, 1e-14);
        ++n;
        if (v < 0) continue;
        double s = vp_poly_separation(cube, ka, qa, ta, b, kb, qb, tb);
        if (v != (s < 0))
            fprintf(stderr, "   mismatch it=%d cube/%s quick=%d sep=%.6g\n", it, vp_shape_name(sb),
                    v, s);
        ASSERT_EQ_INT(v, s < 0);
        ++decided[v];
    }
    fprintf(stderr, "   cube centre tests: %d pairs, %d decided overlapping, %d decided apart\n", n,
            decided[1], decided[0]);
    ASSERT_TRUE(decided[0] > 3000);
    ASSERT_TRUE(decided[1] > 3000);
}

int main(void) {
    RUN_TEST(test_names);
    RUN_TEST(test_polyhedra);
    RUN_TEST(test_sat_simple);
    RUN_TEST(test_sat_random);
    RUN_TEST(test_sat_contact);
    RUN_TEST(test_cube_center);
    fprintf(stderr, "all shape tests passed\n");
    return 0;
}
