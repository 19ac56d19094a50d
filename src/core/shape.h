/* SPDX-License-Identifier: Apache-2.0 */
/* Particle shapes: the sphere, the five platonic and the 13 Archimedean
 * solids, each scaled to bounding-sphere (circum) radius 1 with its centroid
 * at the origin, in the canonical orientation that the lattice bases of
 * lattice_basis.h assume. A particle with pscale s and orient q occupies
 * { s * rotate(q, x) + P }. */
#ifndef VDBPACK_CORE_SHAPE_H
#define VDBPACK_CORE_SHAPE_H

#include "vdbpack/vdbpack.h"

/* Sized for the largest solids: 120 vertices and 180 edges (truncated
 * icosidodecahedron), 92 faces (snub dodecahedron), decagons (truncated
 * dodecahedron). The posed copy (vp_poly_posed) is the only per-test
 * buffer; the loops run over the actual counts, not these caps. */
#define VP_POLY_MAX_VERTS 120
#define VP_POLY_MAX_FACES 92
#define VP_POLY_MAX_FACE_VERTS 10
#define VP_POLY_MAX_EDGES 180

typedef struct vp_polyhedron {
    int nverts, nfaces;
    double verts[VP_POLY_MAX_VERTS][3];
    int face_size[VP_POLY_MAX_FACES];
    int faces[VP_POLY_MAX_FACES][VP_POLY_MAX_FACE_VERTS]; /* counter-clockwise seen from outside */
    double normals[VP_POLY_MAX_FACES][3];                 /* outward unit face normals */
    int nedges;
    int edges[VP_POLY_MAX_EDGES][2]; /* unique undirected edges */
    double volume;                   /* at circumradius 1 */
    double inradius;                 /* at circumradius 1 */
    /* Helpers for the separating-axis test: face normals and edge
     * directions, unit length and unique up to sign (centrally symmetric
     * solids have half as many as faces/edges). */
    int nface_dirs, nedge_dirs;
    double face_dirs[VP_POLY_MAX_FACES][3];
    double edge_dirs[VP_POLY_MAX_EDGES][3];
} vp_polyhedron;

/* The unit polyhedron of a solid; NULL for VP_SHAPE_SPHERE. Static storage,
 * built on the first call for that solid; thread-safe. */
const vp_polyhedron *vp_shape_polyhedron(vp_shape s);

/* 1 for the solids whose overlap the packers test by GJK on support
 * functions (vp_convex_overlap, superball.h): the Archimedean solids, whose
 * SAT would test up to 90 x 90 edge-pair axes (docs/lattices.md has the
 * timings); 0 for the platonic ones, which keep the SAT. */
int vp_shape_overlap_by_gjk(vp_shape s);

/* Separating-axis test of two convex polyhedra placed at (scale, q, t):
 * returns the largest separation over the SAT axes (face normals of both,
 * cross products of edge pairs). > 0: separated by at least that gap;
 * 0: touching; < 0: overlapping, and -value is the penetration depth along
 * the best axis. Double precision. */
double vp_poly_separation(const vp_polyhedron *a, double sa, const double qa[4], const double ta[3],
                          const vp_polyhedron *b, double sb, const double qb[4],
                          const double tb[3]);

/* A polyhedron placed at (scale, q, t) (q, t NULL: identity, origin),
 * relative to origin o (NULL: 0; use one centre for both solids of a test
 * to keep the numbers small): its vertices and rotated SAT directions.
 * Posing a solid once serves all its tests against neighbours. */
typedef struct vp_poly_posed {
    int nverts, nface, nedge;
    double w[VP_POLY_MAX_VERTS][3];
    double f[VP_POLY_MAX_FACES][3];
    double e[VP_POLY_MAX_EDGES][3];
} vp_poly_posed;
void vp_poly_pose(const vp_polyhedron *p, double scale, const double q[4], const double t[3],
                  const double o[3], vp_poly_posed *out);
/* vp_poly_separation of two posed solids (same origin). */
double vp_poly_posed_separation(const vp_poly_posed *a, const vp_poly_posed *b);
/* 1 when they overlap: the same answer as vp_poly_separation(...) < 0 (no
 * SAT axis with a gap >= 0), but returns at the first separating axis. */
int vp_poly_posed_overlap(const vp_poly_posed *a, const vp_poly_posed *b);

/* Cheap exact cases of the overlap of a cube with another solid, from the
 * other solid's centre alone: the cube has rotation R (local to world, as
 * vp_quat_to_matrix) and half side h; the other solid's centre is at
 * offset d from the cube's, and it holds the ball of radius rin about its
 * centre and lies in the ball of radius r. Returns 1 when that centre is
 * closer than rin to the cube (the interiors meet: an overlap), 0 when it
 * is farther than r (apart), -1 when neither. eps: the absolute rounding
 * of d. The margins (1e-9 relative, eps) are far above the rounding of
 * vp_poly_separation, which so gives the same answer where this decides. */
int vp_cube_center_test(const double R[3][3], double h, const double d[3], double rin, double r,
                        double eps);

/* Largest signed container distance (negative inside) over the surface of
 * the polyhedron placed at (scale, q, t) (q NULL: identity): its vertices
 * and, when the container is a level set of voxel size h, points of every
 * face (edges included) on a grid no coarser than h; analytic containers
 * are convex, so there the vertices decide. Returns as soon as the running
 * maximum exceeds stop (then the value is only a lower bound). The packers
 * and vdbpack check share this test; <= 0 means wholly inside. */
struct vp_container;
double vp_poly_wall_distance(const struct vp_container *c, const vp_polyhedron *poly, double scale,
                             const double q[4], const double t[3], double stop);

/* The samplers behind the wall tests (poly_wall.c, mesh_shape.c): each
 * returns 1 once the running maximum of the container distance is above
 * stop (the caller can stop). segment: the n - 1 points strictly between p
 * and q; triangle: the interior points of a barycentric grid of n steps. */
typedef struct vp_wall_acc {
    const struct vp_container *c;
    double worst, stop;
} vp_wall_acc;
int vp_wall_sample(vp_wall_acc *a, const double x[3]);
int vp_wall_segment(vp_wall_acc *a, const double p[3], const double q[3], int n);
int vp_wall_triangle(vp_wall_acc *a, const double p0[3], const double p1[3], const double p2[3],
                     int n);

/* A list as vp_particles_shape_list writes it ("sphere;cube;mesh:rock.obj")
 * into shapes (at most VP_MAX_SHAPES; mesh shapes without their mesh, the
 * names after "mesh:" in names, cut to VP_SHAPE_NAME_MAX - 1, when names is
 * not NULL) and *count. 0, or -1 for an empty entry, an
 * unknown name or too many. */
int vp_shape_list_parse(const char *text, vp_shape_ref *shapes, unsigned *count,
                        char (*names)[VP_SHAPE_NAME_MAX]);
#endif
