/* SPDX-License-Identifier: Apache-2.0 */
/* Unit tests of src/core/lattice_basis.c. For every (shape, lattice)
 * combination offered: the neighbours touch but do not overlap, and the
 * packing fraction computed from the basis equals the literature value.
 * The solids' bases are also checked to be local optima: no small random
 * deformation of the basis, rescaled back to contact, packs denser. */
#include "core/geom.h"
#include "core/lattice_basis.h"
#include "core/shape.h"
#include "vp_test.h"

#include <string.h>

#define PI_ 3.14159265358979323846

/* Literature packing fractions, written independently of the library. */
static double literature_fraction(vp_shape s, vp_lattice l) {
    const double phi = 0.5 * (1 + sqrt(5.0));
    switch (s) {
    case VP_SHAPE_SPHERE:
        switch (l) {
        case VP_LATTICE_SC: return PI_ / 6;              /* 0.5235987755982988 */
        case VP_LATTICE_BCC: return PI_ * sqrt(3.0) / 8; /* 0.6801747615878317 */
        default: return PI_ / (3 * sqrt(2.0));           /* 0.7404804896930610: FCC, HCP */
        }
    case VP_SHAPE_TETRAHEDRON: return 18.0 / 49.0; /* Hoylman 1970 */
    case VP_SHAPE_CUBE: return 1.0;
    case VP_SHAPE_OCTAHEDRON: return 18.0 / 19.0;     /* Minkowski 1904 */
    case VP_SHAPE_DODECAHEDRON: return (2 + phi) / 4; /* 0.904508...; Betke & Henk 2000 */
    case VP_SHAPE_ICOSAHEDRON: return 0.8363574;      /* Betke & Henk 2000: 0.8363574... */
    default: return -1;
    }
}

static int offered(vp_shape s, vp_lattice l) {
    if (s == VP_SHAPE_SPHERE) return 1;
    return l == VP_LATTICE_DEFAULT || l == VP_LATTICE_DENSEST;
}

static void lattice_vec(const double a[3][3], int i, int j, int k, double s, double v[3]) {
    for (int c = 0; c < 3; ++c) v[c] = s * (i * a[0][c] + j * a[1][c] + k * a[2][c]);
}

static double fraction_of(vp_shape s, const vp_lattice_basis *b) {
    return vp_shape_unit_volume(s) * b->nsites / fabs(vp_det3(b->a[0], b->a[1], b->a[2]));
}

static void test_availability(void) {
    vp_lattice_basis b;
    for (int s = 0; s < VP_SHAPE_COUNT; ++s)
        for (int l = 0; l <= VP_LATTICE_DENSEST; ++l) {
            memset(&b, 0xAB, sizeof b);
            int rc = vp_lattice_basis_get((vp_shape)s, (vp_lattice)l, &b);
            ASSERT_EQ_INT(rc, offered((vp_shape)s, (vp_lattice)l) ? 0 : -1);
            if (rc) continue;
            ASSERT_TRUE(b.nsites == 1 || b.nsites == 2);
            ASSERT_TRUE(b.name != NULL && b.name[0] != 0);
            ASSERT_TRUE(b.source != NULL && b.source[0] != 0);
            for (int c = 0; c < 3; ++c) ASSERT_EQ_INT(b.sites[0][c] == 0.0, 1);
            ASSERT_TRUE(vp_det3(b.a[0], b.a[1], b.a[2]) > 0); /* right-handed */
        }
    ASSERT_EQ_INT(vp_lattice_basis_get(VP_SHAPE_COUNT, VP_LATTICE_FCC, &b), -1);
    ASSERT_EQ_INT(vp_lattice_basis_get(VP_SHAPE_SPHERE, (vp_lattice)(VP_LATTICE_DENSEST + 1), &b),
                  -1);
    ASSERT_EQ_INT(vp_lattice_basis_get(VP_SHAPE_SPHERE, VP_LATTICE_FCC, NULL), -1);

    /* DEFAULT and DENSEST for spheres are FCC; DEFAULT for solids is DENSEST */
    vp_lattice_basis f, d;
    ASSERT_EQ_INT(vp_lattice_basis_get(VP_SHAPE_SPHERE, VP_LATTICE_FCC, &f), 0);
    ASSERT_EQ_INT(vp_lattice_basis_get(VP_SHAPE_SPHERE, VP_LATTICE_DEFAULT, &d), 0);
    ASSERT_TRUE(memcmp(f.a, d.a, sizeof f.a) == 0);
    ASSERT_EQ_INT(vp_lattice_basis_get(VP_SHAPE_SPHERE, VP_LATTICE_DENSEST, &d), 0);
    ASSERT_TRUE(memcmp(f.a, d.a, sizeof f.a) == 0);
    for (int s = 1; s < VP_SHAPE_COUNT; ++s) {
        ASSERT_EQ_INT(vp_lattice_basis_get((vp_shape)s, VP_LATTICE_DEFAULT, &f), 0);
        ASSERT_EQ_INT(vp_lattice_basis_get((vp_shape)s, VP_LATTICE_DENSEST, &d), 0);
        ASSERT_TRUE(memcmp(f.a, d.a, sizeof f.a) == 0);
    }
}

/* Spheres of radius 1: the closest pair of distinct sites is at distance 2. */
static void test_sphere_contact(void) {
    for (int l = 0; l <= VP_LATTICE_DENSEST; ++l) {
        vp_lattice_basis b;
        ASSERT_EQ_INT(vp_lattice_basis_get(VP_SHAPE_SPHERE, (vp_lattice)l, &b), 0);
        double dmin = HUGE_VAL;
        int touching = 0;
        for (int s0 = 0; s0 < b.nsites; ++s0)
            for (int s1 = 0; s1 < b.nsites; ++s1)
                for (int i = -3; i <= 3; ++i)
                    for (int j = -3; j <= 3; ++j)
                        for (int k = -3; k <= 3; ++k) {
                            if (s0 == s1 && !i && !j && !k) continue;
                            double v[3];
                            lattice_vec(b.a, i, j, k, 1.0, v);
                            for (int c = 0; c < 3; ++c) v[c] += b.sites[s1][c] - b.sites[s0][c];
                            double d = vp_norm3(v);
                            if (d < dmin) dmin = d;
                            if (fabs(d - 2) < 1e-12) ++touching;
                        }
        double frac = fraction_of(VP_SHAPE_SPHERE, &b);
        fprintf(stderr,
                "   sphere %-8s %-14s min distance %.17g, contacts/site %d, fraction %.17g\n",
                vp_lattice_name((vp_lattice)l), b.name, dmin, touching / b.nsites, frac);
        ASSERT_NEAR(dmin, 2.0, 1e-12);
        /* kissing numbers: SC 6, BCC 8, FCC and HCP 12 */
        int kiss = l == VP_LATTICE_SC ? 6 : l == VP_LATTICE_BCC ? 8 : 12;
        ASSERT_EQ_INT(touching / b.nsites, kiss);
        ASSERT_NEAR(frac, literature_fraction(VP_SHAPE_SPHERE, (vp_lattice)l), 1e-6);
        ASSERT_NEAR(frac, b.fraction, 1e-12);
    }
    /* HCP is not FCC: its second site sits half a cell up, over a hole */
    vp_lattice_basis h;
    ASSERT_EQ_INT(vp_lattice_basis_get(VP_SHAPE_SPHERE, VP_LATTICE_HCP, &h), 0);
    ASSERT_EQ_INT(h.nsites, 2);
    ASSERT_NEAR(h.sites[1][2], 0.5 * vp_norm3(h.a[2]), 1e-12);
    ASSERT_NEAR(vp_norm3(h.a[2]), 4 * sqrt(2.0 / 3.0), 1e-12);
}

static const double q_id[4] = {0, 0, 0, 1};
static const double t_zero[3] = {0, 0, 0};

/* Least separation between the solid at the origin and its translates by
 * the lattice vectors with |n_i| <= N, the basis scaled by sc. */
static double min_separation(const vp_polyhedron *p, const double a[3][3], double sc, int N,
                             int *ntouch) {
    double best = HUGE_VAL;
    int touch = 0;
    for (int i = -N; i <= N; ++i)
        for (int j = -N; j <= N; ++j)
            for (int k = -N; k <= N; ++k) {
                if (!i && !j && !k) continue;
                double v[3];
                lattice_vec(a, i, j, k, sc, v);
                double s = vp_poly_separation(p, 1, q_id, t_zero, p, 1, q_id, v);
                if (s < best) best = s;
                if (fabs(s) <= 1e-9) ++touch;
            }
    if (ntouch) *ntouch = touch;
    return best;
}

/* Smallest scale at which the translates by the lattice vectors |n_i| <= 2
 * do not overlap (bisection per vector on the SAT separation). */
static double contact_scale(const vp_polyhedron *p, const double a[3][3]) {
    double s = 0;
    for (int i = -2; i <= 2; ++i)
        for (int j = -2; j <= 2; ++j)
            for (int k = -2; k <= 2; ++k) {
                if (i < 0 || (i == 0 && (j < 0 || (j == 0 && k <= 0)))) continue; /* one of +-v */
                double v[3];
                lattice_vec(a, i, j, k, 1.0, v);
                if (vp_poly_separation(p, 1, q_id, t_zero, p, 1, q_id,
                                       (double[3]){s * v[0], s * v[1], s * v[2]}) >= 0)
                    continue;
                double lo = s,
                       hi = 2.0 / vp_norm3(v) * (1 + 1e-12); /* bounding spheres apart at hi */
                for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
                    double mid = 0.5 * (lo + hi), w[3] = {mid * v[0], mid * v[1], mid * v[2]};
                    if (vp_poly_separation(p, 1, q_id, t_zero, p, 1, q_id, w) < 0) lo = mid;
                    else hi = mid;
                }
                s = hi;
            }
    return s;
}

static void test_solid_contact(void) {
    for (int sh = 1; sh <= VP_SHAPE_ICOSAHEDRON; ++sh) { /* the Archimedean: test_archimedean.c */
        vp_lattice_basis b;
        ASSERT_EQ_INT(vp_lattice_basis_get((vp_shape)sh, VP_LATTICE_DENSEST, &b), 0);
        const vp_polyhedron *p = vp_shape_polyhedron((vp_shape)sh);
        int touch2 = 0, touch3 = 0;
        double m2 = min_separation(p, b.a, 1.0, 2, &touch2);
        double m3 = min_separation(p, b.a, 1.0, 3, &touch3);
        double sstar = contact_scale(p, b.a);
        double frac = fraction_of((vp_shape)sh, &b);
        fprintf(stderr,
                "   %-12s %-30s min sep %.3g (|n|<=3: %.3g), touching neighbours %d, contact scale "
                "1%+.2g, fraction %.17g\n",
                vp_shape_name((vp_shape)sh), b.name, m2, m3, touch2, sstar - 1, frac);
        ASSERT_GE(m2, -1e-9);
        ASSERT_LE(m2, 1e-9);
        ASSERT_GE(m3, -1e-9);
        ASSERT_EQ_INT(touch3, touch2); /* no new contacts beyond |n| <= 2 */
        ASSERT_TRUE(touch2 >= 6);      /* at least three pairs of neighbours touch */
        ASSERT_TRUE(touch2 % 2 == 0);
        /* stored at contact to 1e-12 relative */
        ASSERT_NEAR(sstar, 1.0, 1e-12);
        /* shrinking the lattice by 1e-9 makes neighbours overlap */
        ASSERT_LE(min_separation(p, b.a, 1 - 1e-9, 1, NULL), -1e-10);
        ASSERT_NEAR(frac, literature_fraction((vp_shape)sh, VP_LATTICE_DENSEST), 1e-6);
        ASSERT_NEAR(frac, b.fraction, 1e-12);
    }
}

/* Hand-made checks of the documented vectors. */
static void test_known_vectors(void) {
    vp_lattice_basis b;
    const double r3 = sqrt(3.0);
    ASSERT_EQ_INT(vp_lattice_basis_get(VP_SHAPE_OCTAHEDRON, VP_LATTICE_DENSEST, &b), 0);
    /* Minkowski's a1 = (2/3, 2/3, -2/3) for |x|+|y|+|z| <= 1 */
    ASSERT_NEAR(b.a[0][0], 2.0 / 3, 1e-15);
    ASSERT_NEAR(b.a[0][2], -2.0 / 3, 1e-15);
    ASSERT_NEAR(vp_det3(b.a[0], b.a[1], b.a[2]), 38.0 / 27, 1e-14);
    ASSERT_EQ_INT(vp_lattice_basis_get(VP_SHAPE_TETRAHEDRON, VP_LATTICE_DENSEST, &b), 0);
    ASSERT_NEAR(b.a[0][0], 2 / r3, 1e-15);
    ASSERT_NEAR(b.a[0][1], -1 / (3 * r3), 1e-15);
    ASSERT_NEAR(vp_det3(b.a[0], b.a[1], b.a[2]), 196.0 / 27 / (3 * r3), 1e-14);
    ASSERT_EQ_INT(vp_lattice_basis_get(VP_SHAPE_DODECAHEDRON, VP_LATTICE_DENSEST, &b), 0);
    ASSERT_NEAR(vp_norm3(b.a[0]), 2 * sqrt(2.0) / r3, 1e-15);
    ASSERT_EQ_INT(vp_lattice_basis_get(VP_SHAPE_ICOSAHEDRON, VP_LATTICE_DENSEST, &b), 0);
    /* x = 1.59160301370213908... is a root of the sextic of docs/lattices.md
     * and a3 = (phi^2 x - 2 - sqrt5, 0, x) / sin(72 deg) */
    const double x = 1.5916030137021390853, phi = 0.5 * (1 + sqrt(5.0));
    double px = ((((((1629 * x - 4809) * x + 3590) * x + 139) * x - 382) * x + 3) * x + 1);
    ASSERT_NEAR(px, 0.0, 1e-11);
    ASSERT_NEAR(b.a[2][2], x / sin(2 * PI_ / 5), 1e-15);
    ASSERT_NEAR(b.a[2][0], (phi * phi * x - 2 - sqrt(5.0)) / sin(2 * PI_ / 5), 1e-14);
    ASSERT_NEAR(b.a[2][1], 0.0, 0.0);
}

static uint64_t rng = 0x2545F4914F6CDD1Dull;
static double urand(void) {
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}

/* Local optimality: deform the basis by I + eps*G (G random), rescale to
 * contact; the fraction must not exceed the stored one. */
static void test_local_optimality(void) {
    for (int sh = 1; sh <= VP_SHAPE_ICOSAHEDRON; ++sh) { /* the Archimedean: test_archimedean.c */
        vp_lattice_basis b;
        ASSERT_EQ_INT(vp_lattice_basis_get((vp_shape)sh, VP_LATTICE_DENSEST, &b), 0);
        const vp_polyhedron *p = vp_shape_polyhedron((vp_shape)sh);
        double worst = -HUGE_VAL;
        for (int trial = 0; trial < 24; ++trial) {
            double eps = trial < 12 ? 1e-3 : 1e-5, g[3][3], a[3][3];
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) g[i][j] = (i == j) + eps * (2 * urand() - 1);
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c)
                    a[r][c] = g[c][0] * b.a[r][0] + g[c][1] * b.a[r][1] + g[c][2] * b.a[r][2];
            double s = contact_scale(p, a);
            double f = p->volume / (fabs(vp_det3(a[0], a[1], a[2])) * s * s * s);
            if (f - b.fraction > worst) worst = f - b.fraction;
            ASSERT_LE(f, b.fraction + 1e-10);
        }
        fprintf(stderr, "   %-12s deformed lattices: best fraction change %.3g\n",
                vp_shape_name((vp_shape)sh), worst);
    }
}

int main(void) {
    RUN_TEST(test_availability);
    RUN_TEST(test_sphere_contact);
    RUN_TEST(test_solid_contact);
    RUN_TEST(test_known_vectors);
    RUN_TEST(test_local_optimality);
    fprintf(stderr, "all lattice basis tests passed\n");
    return 0;
}
