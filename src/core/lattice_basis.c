/* SPDX-License-Identifier: Apache-2.0 */
/* Lattice bases at bounding-sphere (circum) radius 1. Every basis is at
 * contact: the particle at the origin touches, but does not overlap, its
 * lattice translates. Derivations, sources and the corrections to the seed
 * report are in docs/lattices.md; tests/test_lattice_basis.c re-checks the
 * contact and the packing fraction of every (shape, lattice) pair. */
#include "core/lattice_basis.h"
#include "core/geom.h"
#include "core/shape.h"
#include "core/superball.h"

#include <math.h>
#include <string.h>

#define VP_PI 3.14159265358979323846

static void set_rows(vp_lattice_basis *b, double k, const double r[3][3]) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) b->a[i][j] = k * r[i][j];
}

/* Sphere lattices (sphere radius 1: nearest neighbours at distance 2). */
static void sphere_basis(vp_lattice l, vp_lattice_basis *b) {
    switch (l) {
    case VP_LATTICE_SC: {
        static const double r[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        set_rows(b, 2.0, r);
        b->fraction = VP_PI / 6.0;
        b->name = "simple cubic";
        b->source = "SC, a = 2r";
        break;
    }
    case VP_LATTICE_BCC: {
        /* conventional cube a = 4r/sqrt(3); primitive vectors a/2 (-1,1,1)...:
         * the nearest neighbours touch along the body diagonals */
        static const double r[3][3] = {{-1, 1, 1}, {1, -1, 1}, {1, 1, -1}};
        set_rows(b, 2.0 / sqrt(3.0), r);
        b->fraction = VP_PI * sqrt(3.0) / 8.0;
        b->name = "BCC";
        b->source = "BCC primitive vectors, a = 4r/sqrt(3)";
        break;
    }
    case VP_LATTICE_HCP: {
        /* hexagonal primitive cell a1 = (2,0,0), a2 = (1,sqrt3,0),
         * a3 = (0,0,c), c = 4 sqrt(2/3) r, second site a1/3 + a2/3 + a3/2
         * (AB stacking) */
        const double c = 4.0 * sqrt(2.0 / 3.0);
        const double r[3][3] = {{2, 0, 0}, {1, sqrt(3.0), 0}, {0, 0, c}};
        set_rows(b, 1.0, r);
        b->nsites = 2;
        b->sites[1][0] = 1.0;
        b->sites[1][1] = 1.0 / sqrt(3.0);
        b->sites[1][2] = 0.5 * c;
        b->fraction = VP_PI / (3.0 * sqrt(2.0));
        b->name = "HCP (AB)";
        b->source = "hexagonal cell a = 2r, c = 4 sqrt(2/3) r, sites 0 and a1/3+a2/3+a3/2";
        break;
    }
    default: { /* FCC (also DEFAULT and DENSEST for spheres) */
        static const double r[3][3] = {{0, 1, 1}, {1, 0, 1}, {1, 1, 0}};
        set_rows(b, sqrt(2.0), r);
        b->fraction = VP_PI / (3.0 * sqrt(2.0));
        b->name = "FCC (ABC)";
        b->source = "FCC primitive vectors, a = 2 sqrt(2) r; Hales 2005 (Kepler)";
        break;
    }
    }
}

/* Densest known lattice packings of the platonic solids, in the canonical
 * orientations of shape.c, at circumradius 1. */
static void solid_basis(vp_shape s, vp_lattice_basis *b) {
    const double phi = 0.5 * (1.0 + sqrt(5.0));
    switch (s) {
    case VP_SHAPE_TETRAHEDRON: {
        /* Hoylman 1970: a lattice packs T iff it packs (T - T)/2, the
         * cuboctahedron; its critical lattice is invariant under the cyclic
         * permutation of the axes: (2,-1/3,-1/3) and its cyclic shifts for
         * the tetrahedron (+-1,+-1,+-1)-alternate (circumradius sqrt 3). */
        static const double r[3][3] = {{6, -1, -1}, {-1, 6, -1}, {-1, -1, 6}};
        set_rows(b, 1.0 / (3.0 * sqrt(3.0)), r);
        b->fraction = 18.0 / 49.0;
        b->name = "Hoylman tetrahedron lattice";
        b->source = "Hoylman 1970 (densest lattice packing of tetrahedra, 18/49)";
        break;
    }
    case VP_SHAPE_CUBE: {
        static const double r[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        set_rows(b, 2.0 / sqrt(3.0), r);
        b->fraction = 1.0;
        b->name = "cubic tiling";
        b->source = "cubes tile space (edge 2/sqrt(3) at circumradius 1)";
        break;
    }
    case VP_SHAPE_OCTAHEDRON: {
        /* Minkowski 1904, for |x|+|y|+|z| <= 1 exactly as in the seed report
         * (a2 and a3 swapped to make the basis right-handed) */
        static const double r[3][3] = {{2, 2, -2}, {1, -1, -4}, {-1, 4, -1}};
        set_rows(b, 1.0 / 3.0, r);
        b->fraction = 18.0 / 19.0;
        b->name = "Minkowski octahedron lattice";
        b->source = "Minkowski 1904; Betke & Henk 2000 (18/19)";
        break;
    }
    case VP_SHAPE_DODECAHEDRON: {
        /* Torquato & Jiao 2009 / Betke & Henk 2000: (1,1,0), (1,0,1),
         * (0,1,1) scaled to contact: 2/sqrt(3) at circumradius 1 (the seed
         * report's 2/(1+phi) is for a dodecahedron phi^2 times smaller). */
        static const double r[3][3] = {{1, 1, 0}, {0, 1, 1}, {1, 0, 1}};
        set_rows(b, 2.0 / sqrt(3.0), r);
        b->fraction = (2.0 + phi) / 4.0;
        b->name = "densest dodecahedron lattice";
        b->source = "Betke & Henk 2000; Torquato & Jiao 2009 ((2+phi)/4)";
        break;
    }
    case VP_SHAPE_ICOSAHEDRON: {
        /* Betke & Henk 2000 / Torquato & Jiao 2009: the seed report's
         * closed forms a_i(x) at x = 1.5916030137021390852723..., the root
         * in (1.5, 1.7) of 1629x^6 - 4809x^5 + 3590x^4 + 139x^3 - 382x^2 + 3x
         * + 1 (where d det(a1,a2,a3)/dx = 0), mirrored y <-> z to our
         * (0,+-1,+-phi) orientation and scaled by 1/sin(72 deg) from edge 1
         * to circumradius 1. Evaluated with 40-digit arithmetic. */
        static const double r[3][3] = {
            {0.748412331422600858332, 1.13121717087780024891, 0.87313433864194596917},
            {-0.916483126059056060943, 1.03590460863365653572, 0.800376106249634479755},
            {-0.0727582323923114894146, 0.0, 1.67351044489158044893}};
        set_rows(b, 1.0, r);
        b->fraction = 0.83635744537971105245;
        b->name = "densest icosahedron lattice";
        b->source = "Betke & Henk 2000; Torquato & Jiao 2009 (0.8363574...)";
        break;
    }
    default: break;
    }
}

/* Dense lattice packings of the Archimedean solids, at circumradius 1 in
 * the orientations of shape.c, found by scripts/archimedean_lattices.py (a
 * numeric search for the critical lattice of the difference body, polished
 * on its contact set; docs/lattices.md) and rescaled there to contact. The
 * fraction is computed from the basis; tests/test_archimedean.c checks it
 * against Betke & Henk 2000 and the absence of overlaps. */
typedef struct arch_basis {
    vp_shape shape;
    double a[3][3];
} arch_basis;

static const arch_basis arch_bases[] = {
#include "core/lattice_archimedean.inc"
};

static int archimedean_basis(vp_shape s, vp_lattice_basis *b) {
    for (size_t i = 0; i < sizeof arch_bases / sizeof arch_bases[0]; ++i)
        if (arch_bases[i].shape == s) {
            set_rows(b, 1.0, arch_bases[i].a);
            b->fraction = vp_shape_unit_volume(s) / fabs(vp_det3(b->a[0], b->a[1], b->a[2]));
            b->name = "dense Archimedean lattice";
            b->source = "numeric critical-lattice search (scripts/archimedean_lattices.py); "
                        "Betke & Henk 2000 densities";
            return 0;
        }
    return -1;
}

int vp_lattice_basis_get(vp_shape shape, vp_lattice lattice, vp_lattice_basis *out) {
    if (!out || (int)shape < 0 || (int)shape >= VP_SHAPE_COUNT) return -1;
    if ((int)lattice < (int)VP_LATTICE_DEFAULT || (int)lattice > (int)VP_LATTICE_DENSEST) return -1;
    vp_lattice_basis b;
    memset(&b, 0, sizeof b);
    b.nsites = 1;
    if (shape == VP_SHAPE_SPHERE) {
        sphere_basis(lattice, &b);
    } else {
        if (lattice != VP_LATTICE_DEFAULT && lattice != VP_LATTICE_DENSEST) return -1;
        if ((int)shape > (int)VP_SHAPE_ICOSAHEDRON) {
            if (archimedean_basis(shape, &b) != 0) return -1;
        } else {
            solid_basis(shape, &b);
        }
    }
    /* all bases are stored right-handed; keep it that way */
    if (vp_det3(b.a[0], b.a[1], b.a[2]) < 0) {
        double t[3];
        memcpy(t, b.a[1], sizeof t);
        memcpy(b.a[1], b.a[2], sizeof t);
        memcpy(b.a[2], t, sizeof t);
    }
    *out = b;
    return 0;
}

int vp_lattice_basis_get_param(vp_shape shape, double param, vp_lattice lattice,
                               vp_lattice_basis *out) {
    if (shape != VP_SHAPE_SUPERBALL) return vp_lattice_basis_get(shape, lattice, out);
    if (!out || (lattice != VP_LATTICE_DEFAULT && lattice != VP_LATTICE_DENSEST)) return -1;
    vp_superball_family f = vp_superball_best_family(param);
    vp_lattice_basis b;
    memset(&b, 0, sizeof b);
    b.nsites = 1;
    if (vp_superball_family_basis(f, param, b.a) != 0) return -1;
    const double R = vp_superball_circumradius(param);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) b.a[i][j] /= R;
    if (vp_det3(b.a[0], b.a[1], b.a[2]) < 0) {
        double t[3];
        memcpy(t, b.a[1], sizeof t);
        memcpy(b.a[1], b.a[2], sizeof t);
        memcpy(b.a[2], t, sizeof t);
    }
    b.fraction = vp_superball_unit_volume(param) / fabs(vp_det3(b.a[0], b.a[1], b.a[2]));
    static const char *const names[] = {"superball C0 lattice", "superball C1 lattice",
                                        "superball O0 lattice", "superball O1 lattice"};
    b.name = names[f];
    b.source = "Jiao, Stillinger & Torquato 2009 (Phys. Rev. E 79, 041309), parameters solved "
               "numerically";
    *out = b;
    return 0;
}

double vp_lattice_fraction_param(vp_shape shape, double param, vp_lattice lattice) {
    vp_lattice_basis lb;
    return vp_lattice_basis_get_param(shape, param, lattice, &lb) == 0 ? lb.fraction : 0.0;
}

double vp_lattice_fraction(vp_shape shape, vp_lattice lattice) {
    vp_lattice_basis lb;
    return vp_lattice_basis_get(shape, lattice, &lb) == 0 ? lb.fraction : 0.0;
}
