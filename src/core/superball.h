// SPDX-License-Identifier: Apache-2.0
/* Superballs |x|^2p + |y|^2p + |z|^2p <= 1 (p >= 0.5, convex) as particle
 * shapes: scaled to bounding radius 1 like every shape, their support
 * function, volume, the exact overlap test of convex shapes by GJK on
 * support functions, a tessellation for rendering, export and the wall
 * test, and the four lattice families of Jiao, Stillinger & Torquato 2009.
 * Internal; docs/lattices.md ("Superballs") has the sources. */
#ifndef VDBPACK_CORE_SUPERBALL_H
#define VDBPACK_CORE_SUPERBALL_H

#include "vdbpack/vdbpack.h"
#include "core/shape.h"

/* The exponents offered: convex superballs, up to where they are cubes to
 * double precision for every purpose here. */
#define VP_SUPERBALL_P_MIN 0.5
#define VP_SUPERBALL_P_MAX 1000.0

/* Radius of the superball of exponent p before scaling: 1 for p <= 1
 * (the axis points), 3^(1/2 - 1/2p) for p >= 1 (the corners). */
double vp_superball_circumradius(double p);
/* Volume of the unscaled superball: (2/p^2) B(1/2p, (2p+1)/2p) B(1/2p, (p+1)/p). */
double vp_superball_raw_volume(double p);
/* At bounding radius 1. */
double vp_superball_unit_volume(double p);
double vp_superball_inradius(double p); /* at bounding radius 1 */

/* Support point of the unit shape (bounding radius 1) in direction d (any
 * length, not zero): the point x of the shape with the largest x . d. */
void vp_superball_support(double p, const double d[3], double x[3]);

/* A convex shape seen through its support function, posed at (scale, q,
 * t) relative to an origin chosen by the caller. */
typedef struct vp_convex {
    int kind; /* 0 sphere, 1 superball, 2 polyhedron (vertex hull),
                             3 triangle (vp_convex_set_triangle) */
    double p; /* superball exponent */
    const vp_polyhedron *poly;
    double scale;
    double m[3][3];   /* rotation, local to world */
    double t[3];      /* the centre (a triangle: its centroid) */
    double tri[3][3]; /* kind 3: the corners, relative to the origin */
    double inflate;   /* the shape grown by this distance (its Minkowski sum
                             with a ball): a gap kept between two shapes is
                             their overlap grown by half of it each; 0 after
                             vp_convex_set */
} vp_convex;
void vp_convex_set(vp_convex *c, vp_shape shape, double p, double scale, const double q[4],
                   const double t[3], const double origin[3]);
void vp_convex_support(const vp_convex *c, const double d[3], double x[3]);
/* A triangle (world corners a, b, c) relative to origin (NULL: 0): the
 * mesh shapes' faces against the convex shapes (pair.c). */
void vp_convex_set_triangle(vp_convex *c, const double a[3], const double b[3], const double cc[3],
                            const double origin[3]);

/* GJK on the Minkowski difference. Returns 1 when the shapes intersect
 * (the origin was enclosed by a simplex of support points), 0 when a
 * separating direction was found. Undecided after the iteration limit: 1
 * (the packers then refuse the candidate; never an overlap let through). */
int vp_convex_overlap(const vp_convex *a, const vp_convex *b);
/* The same with the undecided case apart: 1 overlap (proven), 0 apart
 * (proven), -1 undecided after the iteration limit, which happens only
 * within a hair of touching (smooth shapes converge slowly there): the
 * packers count it as an overlap, vdbpack check as a contact. */
int vp_convex_overlap_state(const vp_convex *a, const vp_convex *b);

/* The same for two shapes placed at (scale, q, t) each (unit superballs of
 * exponent p, or polyhedra of vp_shape_polyhedron). */
int vp_superball_overlap(double p, double sa, const double qa[4], const double ta[3], double sb,
                         const double qb[4], const double tb[3]);

/* A closed triangle mesh whose surface lies within a relative gap of the
 * unit superball's (vertices on the surface): the cube-sphere grid of n
 * cells per cube face edge, built once per p and kept for the process
 * (thread-safe). *inflate: the factor by which the mesh, scaled about the
 * centre, encloses the superball (measured on every triangle, with a
 * margin): the wall test uses the mesh so scaled. NULL on failure. */
const vp_mesh_shape *vp_superball_mesh(double p, double *inflate);

/* Largest signed container distance over the superball of exponent p
 * placed at (scale, q, t): as vp_poly_wall_distance, on the enclosing mesh
 * (vp_superball_mesh scaled by its inflate factor), so <= 0 proves the
 * superball inside. */
struct vp_container;
double vp_superball_wall_distance(const struct vp_container *c, double p, double scale,
                                  const double q[4], const double t[3], double stop);

/* The lattice families of Jiao, Stillinger & Torquato 2009 (Phys. Rev. E
 * 79, 041309): C0, C1 (cubic regime), O0, O1 (octahedral regime). */
typedef enum vp_superball_family { VP_SB_C0 = 0, VP_SB_C1, VP_SB_O0, VP_SB_O1 } vp_superball_family;
const char *vp_superball_family_name(vp_superball_family f);
/* The family that is densest at p: O1 (0.5 <= p < ln3/ln4), O0 (below 1),
 * C0 (1 <= p < 1.1509...), C1. */
vp_superball_family vp_superball_best_family(double p);
/* The family's lattice vectors (rows) for the unscaled superball of
 * exponent p (the paper's units), with the parameters solved numerically
 * from the paper's equations. Returns 0, or -1 when the family does not
 * exist at p (O1 above ln3/ln4, O0 at or below it, C0/C1 below 1). */
int vp_superball_family_basis(vp_superball_family f, double p, double a[3][3]);
/* The switch point between C0 and C1 (where their densities are equal),
 * solved numerically: 1.1509... */
double vp_superball_pc(void);

/* Parses "superball:P" (case-insensitive name) into *p; 0 on success,
 * -1 when the text is not a superball, -2 when P is not a number in
 * [VP_SUPERBALL_P_MIN, VP_SUPERBALL_P_MAX]. */
int vp_superball_parse(const char *text, double *p);
/* "superball:P" with the fewest digits (15 to 17) that read back as p. */
void vp_superball_format(double p, char *buf, size_t n);
#endif
