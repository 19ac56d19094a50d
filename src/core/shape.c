/* SPDX-License-Identifier: Apache-2.0 */
/* Particle shapes: names, unit volumes, the five platonic and the 13
 * Archimedean solids as convex polyhedra (circumradius 1, centroid at the
 * origin) and the separating-axis test. See shape.h and docs/lattices.md for the canonical orientations. */
#include "core/shape.h"
#include "core/geom.h"
#include "core/mesh_shape.h"
#include "core/superball.h"

#include <stdio.h>

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <string.h>

/* ------------------------------------------------------------------ */
/* Names                                                               */

static const char *const vp_shape_names[VP_SHAPE_COUNT] = {"sphere",
                                                           "tetrahedron",
                                                           "cube",
                                                           "octahedron",
                                                           "dodecahedron",
                                                           "icosahedron",
                                                           "truncated-tetrahedron",
                                                           "cuboctahedron",
                                                           "truncated-cube",
                                                           "truncated-octahedron",
                                                           "rhombicuboctahedron",
                                                           "truncated-cuboctahedron",
                                                           "snub-cube",
                                                           "icosidodecahedron",
                                                           "truncated-dodecahedron",
                                                           "truncated-icosahedron",
                                                           "rhombicosidodecahedron",
                                                           "truncated-icosidodecahedron",
                                                           "snub-dodecahedron"};

static const char *const vp_lattice_names[] = {"default", "sc", "bcc", "fcc", "hcp", "densest"};
#define VP_LATTICE_NAME_COUNT ((int)(sizeof vp_lattice_names / sizeof vp_lattice_names[0]))

/* Case-insensitive, and '_' matches '-' (truncated_cube = truncated-cube). */
static int vp_streq_nocase(const char *a, const char *b) {
    for (;; ++a, ++b) {
        int ca = (unsigned char)*a, cb = (unsigned char)*b;
        if (ca >= 'A' && ca <= 'Z') ca += 'a' - 'A';
        if (cb >= 'A' && cb <= 'Z') cb += 'a' - 'A';
        if (ca == '_') ca = '-';
        if (cb == '_') cb = '-';
        if (ca != cb) return 0;
        if (ca == 0) return 1;
    }
}

const char *vp_shape_name(vp_shape s) {
    if (s == VP_SHAPE_MESH) return "mesh";
    if (s == VP_SHAPE_SUPERBALL) return "superball";
    if (s == VP_SHAPE_MIXED) return "mixed";
    if ((int)s < 0 || (int)s >= VP_SHAPE_COUNT) return NULL;
    return vp_shape_names[s];
}

int vp_shape_parse(const char *name, vp_shape *out) {
    if (!name || !out) return -1;
    for (int i = 0; i < VP_SHAPE_COUNT; ++i)
        if (vp_streq_nocase(name, vp_shape_names[i])) {
            *out = (vp_shape)i;
            return 0;
        }
    return -1;
}

int vp_shape_parse_param(const char *text, vp_shape *out, double *param) {
    if (!text || !out) return -1;
    double p = 0.0;
    int r = vp_superball_parse(text, &p);
    if (r == -2) return -2;
    if (r == 0) {
        *out = VP_SHAPE_SUPERBALL;
        if (param) *param = p;
        return 0;
    }
    if (vp_shape_parse(text, out) != 0) return -1;
    if (param) *param = 0.0;
    return 0;
}

const char *vp_shape_format(vp_shape s, double param, char *buf, size_t n) {
    if (!buf || n == 0) return buf;
    if (s == VP_SHAPE_SUPERBALL) vp_superball_format(param, buf, n);
    else snprintf(buf, n, "%s", vp_shape_name(s) ? vp_shape_name(s) : "");
    return buf;
}

double vp_shape_unit_volume_param(vp_shape s, double param) {
    if (s == VP_SHAPE_SUPERBALL)
        return param >= VP_SUPERBALL_P_MIN && param <= VP_SUPERBALL_P_MAX
                   ? vp_superball_unit_volume(param)
                   : 0.0;
    return vp_shape_unit_volume(s);
}

const char *vp_lattice_name(vp_lattice l) {
    if ((int)l < 0 || (int)l >= VP_LATTICE_NAME_COUNT) return NULL;
    return vp_lattice_names[l];
}

int vp_lattice_parse(const char *name, vp_lattice *out) {
    if (!name || !out) return -1;
    for (int i = 0; i < VP_LATTICE_NAME_COUNT; ++i)
        if (vp_streq_nocase(name, vp_lattice_names[i])) {
            *out = (vp_lattice)i;
            return 0;
        }
    return -1;
}

/* ------------------------------------------------------------------ */
/* Polyhedra                                                           */

static vp_polyhedron vp_polys[VP_SHAPE_COUNT];
static atomic_int vp_polys_built[VP_SHAPE_COUNT];
static pthread_mutex_t vp_polys_lock = PTHREAD_MUTEX_INITIALIZER;

/* The orbit of seed points under the permutations of the coordinates
 * (even ones only, or all) and the sign changes that keep(parity of the
 * permutation, number of plus signs) accepts (NULL: all); duplicates (from
 * zero coordinates) dropped. Appends to v[*n]; returns -1 past the cap. */
typedef int (*vp_sign_rule)(int parity, int plus);
static int rule_even_minus(int parity, int plus) {
    (void)parity;
    return (3 - plus) % 2 == 0;
}
static int rule_snub_cube(int parity, int plus) { return plus % 2 == parity; }
static int rule_even_plus(int parity, int plus) {
    (void)parity;
    return plus % 2 == 0;
}

static int vp_orbit(const double (*seeds)[3], int nseeds, int even_only, vp_sign_rule keep,
                    double v[VP_POLY_MAX_VERTS][3], int *n) {
    static const int perm[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                                   {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
    for (int s = 0; s < nseeds; ++s)
        for (int pi = 0; pi < (even_only ? 3 : 6); ++pi)
            for (int sg = 0; sg < 8; ++sg) {
                int plus = 3 - ((sg & 1) + ((sg >> 1) & 1) + ((sg >> 2) & 1));
                if (keep && !keep(pi >= 3, plus)) continue;
                double x[3];
                for (int k = 0; k < 3; ++k)
                    x[k] = ((sg >> k) & 1 ? -1.0 : 1.0) * seeds[s][perm[pi][k]];
                int dup = 0;
                for (int m = 0; m < *n && !dup; ++m)
                    dup = fabs(v[m][0] - x[0]) + fabs(v[m][1] - x[1]) + fabs(v[m][2] - x[2]) < 1e-9;
                if (dup) continue;
                if (*n >= VP_POLY_MAX_VERTS) return -1;
                memcpy(v[(*n)++], x, sizeof x);
            }
    return 0;
}

/* Canonical vertex sets (before scaling to circumradius 1); Φ = phi:
 *  tetrahedron  : alternate cube corners (1,1,1),(1,-1,-1),(-1,1,-1),(-1,-1,1)
 *  cube         : (+-1,+-1,+-1), axis aligned
 *  octahedron   : (+-1,0,0),(0,+-1,0),(0,0,+-1)
 *  dodecahedron : (+-1,+-1,+-1), (0,+-1/phi,+-phi) and its cyclic permutations
 *  icosahedron  : (0,+-1,+-phi) and its cyclic permutations
 * The Archimedean solids: the usual coordinates (docs/lattices.md has the
 * table), as orbits of seeds: all permutations and signs for the octahedral
 * family, even (cyclic) permutations and all signs for the icosahedral one,
 * with the sign rules of the truncated tetrahedron (even number of minus
 * signs) and the snub solids (one chirality). */
static int vp_make_verts(vp_shape s, double v[VP_POLY_MAX_VERTS][3]) {
    const double phi = 0.5 * (1.0 + sqrt(5.0)), p = phi, r2 = sqrt(2.0);
    int n = 0, rc = 0;
    switch (s) {
    case VP_SHAPE_TETRAHEDRON: {
        static const double t[4][3] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
        for (int i = 0; i < 4; ++i, ++n) memcpy(v[n], t[i], sizeof t[i]);
        break;
    }
    case VP_SHAPE_CUBE:
        for (int i = 0; i < 8; ++i, ++n) {
            v[n][0] = (i & 1) ? 1 : -1;
            v[n][1] = (i & 2) ? 1 : -1;
            v[n][2] = (i & 4) ? 1 : -1;
        }
        break;
    case VP_SHAPE_OCTAHEDRON:
        for (int ax = 0; ax < 3; ++ax)
            for (int sg = -1; sg <= 1; sg += 2, ++n) {
                v[n][0] = v[n][1] = v[n][2] = 0;
                v[n][ax] = sg;
            }
        break;
    case VP_SHAPE_DODECAHEDRON:
        for (int i = 0; i < 8; ++i, ++n) {
            v[n][0] = (i & 1) ? 1 : -1;
            v[n][1] = (i & 2) ? 1 : -1;
            v[n][2] = (i & 4) ? 1 : -1;
        }
        for (int c = 0; c < 3; ++c)
            for (int i = 0; i < 4; ++i, ++n) {
                double q[3] = {0, ((i & 1) ? 1 : -1) / phi, ((i & 2) ? 1 : -1) * phi};
                v[n][c] = q[0];
                v[n][(c + 1) % 3] = q[1];
                v[n][(c + 2) % 3] = q[2];
            }
        break;
    case VP_SHAPE_ICOSAHEDRON:
        for (int c = 0; c < 3; ++c)
            for (int i = 0; i < 4; ++i, ++n) {
                double q[3] = {0, (i & 1) ? 1 : -1, ((i & 2) ? 1 : -1) * phi};
                v[n][c] = q[0];
                v[n][(c + 1) % 3] = q[1];
                v[n][(c + 2) % 3] = q[2];
            }
        break;
    case VP_SHAPE_TRUNCATED_TETRAHEDRON: {
        const double sd[1][3] = {{3, 1, 1}};
        rc = vp_orbit(sd, 1, 0, rule_even_minus, v, &n);
        break;
    }
    case VP_SHAPE_CUBOCTAHEDRON: {
        const double sd[1][3] = {{1, 1, 0}};
        rc = vp_orbit(sd, 1, 0, NULL, v, &n);
        break;
    }
    case VP_SHAPE_TRUNCATED_CUBE: {
        const double sd[1][3] = {{r2 - 1, 1, 1}};
        rc = vp_orbit(sd, 1, 0, NULL, v, &n);
        break;
    }
    case VP_SHAPE_TRUNCATED_OCTAHEDRON: {
        const double sd[1][3] = {{0, 1, 2}};
        rc = vp_orbit(sd, 1, 0, NULL, v, &n);
        break;
    }
    case VP_SHAPE_RHOMBICUBOCTAHEDRON: {
        const double sd[1][3] = {{1, 1, 1 + r2}};
        rc = vp_orbit(sd, 1, 0, NULL, v, &n);
        break;
    }
    case VP_SHAPE_TRUNCATED_CUBOCTAHEDRON: {
        const double sd[1][3] = {{1, 1 + r2, 1 + 2 * r2}};
        rc = vp_orbit(sd, 1, 0, NULL, v, &n);
        break;
    }
    case VP_SHAPE_SNUB_CUBE: { /* t: the tribonacci constant */
        const double t =
            (1.0 + cbrt(19.0 + 3.0 * sqrt(33.0)) + cbrt(19.0 - 3.0 * sqrt(33.0))) / 3.0;
        const double sd[1][3] = {{1, 1 / t, t}};
        rc = vp_orbit(sd, 1, 0, rule_snub_cube, v, &n);
        break;
    }
    case VP_SHAPE_ICOSIDODECAHEDRON: {
        const double sd[2][3] = {{0, 0, p}, {0.5, p / 2, p * p / 2}};
        rc = vp_orbit(sd, 2, 1, NULL, v, &n);
        break;
    }
    case VP_SHAPE_TRUNCATED_DODECAHEDRON: {
        const double sd[3][3] = {{0, 1 / p, 2 + p}, {1 / p, p, 2 * p}, {p, 2, p + 1}};
        rc = vp_orbit(sd, 3, 1, NULL, v, &n);
        break;
    }
    case VP_SHAPE_TRUNCATED_ICOSAHEDRON: {
        const double sd[3][3] = {{0, 1, 3 * p}, {1, 2 + p, 2 * p}, {p, 2, p * p * p}};
        rc = vp_orbit(sd, 3, 1, NULL, v, &n);
        break;
    }
    case VP_SHAPE_RHOMBICOSIDODECAHEDRON: {
        const double sd[3][3] = {{1, 1, p * p * p}, {p * p, p, 2 * p}, {2 + p, 0, p * p}};
        rc = vp_orbit(sd, 3, 1, NULL, v, &n);
        break;
    }
    case VP_SHAPE_TRUNCATED_ICOSIDODECAHEDRON: {
        const double sd[5][3] = {{1 / p, 1 / p, 3 + p},
                                 {2 / p, p, 1 + 2 * p},
                                 {1 / p, p * p, 3 * p - 1},
                                 {2 * p - 1, 2, 2 + p},
                                 {p, 3, 2 * p}};
        rc = vp_orbit(sd, 5, 1, NULL, v, &n);
        break;
    }
    case VP_SHAPE_SNUB_DODECAHEDRON: { /* xi: the real root of xi^3 - 2 xi = phi */
        double xi = 1.0;
        for (int it = 0; it < 60; ++it) xi -= (xi * xi * xi - 2 * xi - p) / (3 * xi * xi - 2);
        const double a = xi - 1 / xi, b = xi * p + p * p + p / xi;
        const double sd[5][3] = {{2 * a, 2, 2 * b},
                                 {a + b / p + p, -a * p + b + 1 / p, a / p + b * p - 1},
                                 {a + b / p - p, a * p - b + 1 / p, a / p + b * p + 1},
                                 {-a / p + b * p + 1, -a + b / p - p, a * p + b - 1 / p},
                                 {-a / p + b * p - 1, a - b / p - p, a * p + b + 1 / p}};
        rc = vp_orbit(sd, 5, 1, rule_even_plus, v, &n);
        break;
    }
    default: return 0;
    }
    if (rc != 0) return 0;
    /* scale to circumradius 1 (all vertices are equidistant) */
    double r = vp_norm3(v[0]);
    for (int i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) v[i][k] /= r;
    return n;
}

static int vp_dir_known(double dirs[][3], int n, const double d[3]) {
    for (int i = 0; i < n; ++i)
        if (fabs(fabs(vp_dot3(dirs[i], d)) - 1.0) < 1e-9) return 1;
    return 0;
}

/* Brute-force convex hull of a small point set that is in convex position. */
static void vp_build_poly(vp_shape s, vp_polyhedron *P) {
    memset(P, 0, sizeof *P);
    P->nverts = vp_make_verts(s, P->verts);
    const int n = P->nverts;
    const double eps = 1e-9;
    for (int i = 0; i < n; ++i)
        for (int j = i + 1; j < n; ++j)
            for (int k = j + 1; k < n; ++k) {
                double e1[3], e2[3], nn[3];
                for (int c = 0; c < 3; ++c) {
                    e1[c] = P->verts[j][c] - P->verts[i][c];
                    e2[c] = P->verts[k][c] - P->verts[i][c];
                }
                vp_cross3(e1, e2, nn);
                double len = vp_norm3(nn);
                if (len < 1e-9) continue;
                for (int c = 0; c < 3; ++c) nn[c] /= len;
                double d = vp_dot3(nn, P->verts[i]);
                int above = 0, below = 0;
                for (int m = 0; m < n && !(above && below); ++m) {
                    double t = vp_dot3(nn, P->verts[m]) - d;
                    if (t > eps) ++above;
                    if (t < -eps) ++below;
                }
                if (above && below) continue;
                if (above) {
                    for (int c = 0; c < 3; ++c) nn[c] = -nn[c];
                    d = -d;
                }
                int dup = 0;
                for (int f = 0; f < P->nfaces; ++f)
                    if (vp_dot3(P->normals[f], nn) > 1 - 1e-9) dup = 1;
                if (dup) continue;
                /* a new face: collect its vertices and sort them CCW about nn */
                int f = P->nfaces++;
                memcpy(P->normals[f], nn, sizeof nn);
                int idx[VP_POLY_MAX_VERTS], cnt = 0;
                double cen[3] = {0, 0, 0};
                for (int m = 0; m < n; ++m)
                    if (fabs(vp_dot3(nn, P->verts[m]) - d) <= eps) {
                        idx[cnt++] = m;
                        for (int c = 0; c < 3; ++c) cen[c] += P->verts[m][c];
                    }
                for (int c = 0; c < 3; ++c) cen[c] /= cnt;
                double u[3], w[3], ang[VP_POLY_MAX_VERTS];
                for (int c = 0; c < 3; ++c) u[c] = P->verts[idx[0]][c] - cen[c];
                double ul = vp_norm3(u);
                for (int c = 0; c < 3; ++c) u[c] /= ul;
                vp_cross3(nn, u, w);
                for (int m = 0; m < cnt; ++m) {
                    double r[3];
                    for (int c = 0; c < 3; ++c) r[c] = P->verts[idx[m]][c] - cen[c];
                    ang[m] = atan2(vp_dot3(r, w), vp_dot3(r, u));
                }
                for (int a = 1; a < cnt; ++a) /* insertion sort by angle */
                    for (int b = a; b > 0 && ang[b] < ang[b - 1]; --b) {
                        double ta = ang[b];
                        ang[b] = ang[b - 1];
                        ang[b - 1] = ta;
                        int ti = idx[b];
                        idx[b] = idx[b - 1];
                        idx[b - 1] = ti;
                    }
                P->face_size[f] = cnt;
                for (int m = 0; m < cnt; ++m) P->faces[f][m] = idx[m];
            }
    /* unique edges, volume, inradius */
    P->inradius = HUGE_VAL;
    for (int f = 0; f < P->nfaces; ++f) {
        int cnt = P->face_size[f];
        double h = vp_dot3(P->normals[f], P->verts[P->faces[f][0]]);
        if (h < P->inradius) P->inradius = h;
        double area2[3] = {0, 0, 0};
        for (int m = 0; m < cnt; ++m) {
            int a = P->faces[f][m], b = P->faces[f][(m + 1) % cnt], dup = 0;
            double c[3];
            vp_cross3(P->verts[a], P->verts[b], c);
            for (int q = 0; q < 3; ++q) area2[q] += c[q];
            for (int e = 0; e < P->nedges; ++e)
                if ((P->edges[e][0] == a && P->edges[e][1] == b) ||
                    (P->edges[e][0] == b && P->edges[e][1] == a))
                    dup = 1;
            if (!dup) {
                P->edges[P->nedges][0] = a;
                P->edges[P->nedges][1] = b;
                ++P->nedges;
            }
        }
        P->volume += h * 0.5 * vp_dot3(area2, P->normals[f]) / 3.0;
    }
    /* SAT directions, unique up to sign */
    for (int f = 0; f < P->nfaces; ++f)
        if (!vp_dir_known(P->face_dirs, P->nface_dirs, P->normals[f]))
            memcpy(P->face_dirs[P->nface_dirs++], P->normals[f], sizeof P->normals[f]);
    for (int e = 0; e < P->nedges; ++e) {
        double d[3];
        for (int c = 0; c < 3; ++c)
            d[c] = P->verts[P->edges[e][1]][c] - P->verts[P->edges[e][0]][c];
        double len = vp_norm3(d);
        for (int c = 0; c < 3; ++c) d[c] /= len;
        if (!vp_dir_known(P->edge_dirs, P->nedge_dirs, d))
            memcpy(P->edge_dirs[P->nedge_dirs++], d, sizeof d);
    }
}

/* Each solid is built on its first use (the hull of the 120-vertex ones
 * costs milliseconds; a run needs one shape): double-checked under a lock,
 * the flag published with release/acquire. */
const vp_polyhedron *vp_shape_polyhedron(vp_shape s) {
    if ((int)s <= (int)VP_SHAPE_SPHERE || (int)s >= VP_SHAPE_COUNT) return NULL;
    if (!atomic_load_explicit(&vp_polys_built[s], memory_order_acquire)) {
        pthread_mutex_lock(&vp_polys_lock);
        if (!atomic_load_explicit(&vp_polys_built[s], memory_order_relaxed)) {
            vp_build_poly(s, &vp_polys[s]);
            atomic_store_explicit(&vp_polys_built[s], 1, memory_order_release);
        }
        pthread_mutex_unlock(&vp_polys_lock);
    }
    return &vp_polys[s];
}

int vp_shape_overlap_by_gjk(vp_shape s) {
    return (int)s >= (int)VP_SHAPE_TRUNCATED_TETRAHEDRON && (int)s < (int)VP_SHAPE_COUNT;
}

double vp_shape_unit_volume(vp_shape s) {
    if (s == VP_SHAPE_SPHERE) return 4.0 * 3.14159265358979323846 / 3.0;
    const vp_polyhedron *p = vp_shape_polyhedron(s);
    return p ? p->volume : 0.0;
}

/* ------------------------------------------------------------------ */
/* Separating-axis test                                                */

static void vp_interval(const double (*w)[3], int n, const double ax[3], double *lo, double *hi) {
    double mn = vp_dot3(w[0], ax), mx = mn;
    for (int i = 1; i < n; ++i) {
        double t = vp_dot3(w[i], ax);
        if (t < mn) mn = t;
        if (t > mx) mx = t;
    }
    *lo = mn;
    *hi = mx;
}

/* Gap of the two vertex sets along unit axis ax (negative: overlap). */
static double vp_axis_gap(const double (*wa)[3], int na, const double (*wb)[3], int nb,
                          const double ax[3]) {
    double alo, ahi, blo, bhi;
    vp_interval(wa, na, ax, &alo, &ahi);
    vp_interval(wb, nb, ax, &blo, &bhi);
    double g1 = blo - ahi, g2 = alo - bhi;
    return g1 > g2 ? g1 : g2;
}

void vp_poly_pose(const vp_polyhedron *p, double scale, const double q[4], const double t[3],
                  const double o[3], vp_poly_posed *out) {
    static const double qid[4] = {0, 0, 0, 1};
    static const double tzero[3] = {0, 0, 0};
    if (!q) q = qid;
    if (!t) t = tzero;
    if (!o) o = tzero;
    double m[3][3];
    vp_quat_to_matrix(q, m);
    double rel[3] = {t[0] - o[0], t[1] - o[1], t[2] - o[2]};
    out->nverts = p->nverts;
    for (int i = 0; i < p->nverts; ++i)
        for (int r = 0; r < 3; ++r)
            out->w[i][r] = rel[r] + scale * (m[r][0] * p->verts[i][0] + m[r][1] * p->verts[i][1] +
                                             m[r][2] * p->verts[i][2]);
    /* rotated SAT directions (raw normals/edges when the helper fields are
     * not filled in) */
    int useh = p->nface_dirs > 0 && p->nedge_dirs > 0;
    out->nface = useh ? p->nface_dirs : p->nfaces;
    out->nedge = useh ? p->nedge_dirs : p->nedges;
    for (int f = 0; f < out->nface; ++f) {
        const double *n = useh ? p->face_dirs[f] : p->normals[f];
        for (int r = 0; r < 3; ++r) out->f[f][r] = m[r][0] * n[0] + m[r][1] * n[1] + m[r][2] * n[2];
    }
    for (int e = 0; e < out->nedge; ++e) {
        double d[3];
        if (useh) {
            memcpy(d, p->edge_dirs[e], sizeof d);
        } else {
            for (int c = 0; c < 3; ++c)
                d[c] = p->verts[p->edges[e][1]][c] - p->verts[p->edges[e][0]][c];
            double l = vp_norm3(d);
            for (int c = 0; c < 3; ++c) d[c] /= l;
        }
        for (int r = 0; r < 3; ++r) out->e[e][r] = m[r][0] * d[0] + m[r][1] * d[1] + m[r][2] * d[2];
    }
}

/* The SAT over both posed solids: the largest gap, or (stop_at_zero) the
 * first gap >= 0 as soon as one is found. */
static double posed_sat(const vp_poly_posed *a, const vp_poly_posed *b, int stop_at_zero) {
    const double(*wa)[3] = (const double(*)[3])a->w, (*wb)[3] = (const double(*)[3])b->w;
    double best = -HUGE_VAL;
    for (int f = 0; f < a->nface; ++f) {
        double g = vp_axis_gap(wa, a->nverts, wb, b->nverts, a->f[f]);
        if (g > best) best = g;
        if (stop_at_zero && best >= 0.0) return best;
    }
    for (int f = 0; f < b->nface; ++f) {
        double g = vp_axis_gap(wa, a->nverts, wb, b->nverts, b->f[f]);
        if (g > best) best = g;
        if (stop_at_zero && best >= 0.0) return best;
    }
    for (int i = 0; i < a->nedge; ++i)
        for (int j = 0; j < b->nedge; ++j) {
            double c[3];
            vp_cross3(a->e[i], b->e[j], c);
            double l = vp_norm3(c);
            /* (nearly) parallel edges: the axis is ill-defined and is
             * covered by the face normals; skipping it can only make the
             * answer more conservative. */
            if (l < 1e-6) continue;
            c[0] /= l;
            c[1] /= l;
            c[2] /= l;
            double g = vp_axis_gap(wa, a->nverts, wb, b->nverts, c);
            if (g > best) best = g;
            if (stop_at_zero && best >= 0.0) return best;
        }
    return best;
}

double vp_poly_posed_separation(const vp_poly_posed *a, const vp_poly_posed *b) {
    return posed_sat(a, b, 0);
}

int vp_poly_posed_overlap(const vp_poly_posed *a, const vp_poly_posed *b) {
    return !(posed_sat(a, b, 1) >= 0.0);
}

double vp_poly_separation(const vp_polyhedron *a, double sa, const double qa[4], const double ta[3],
                          const vp_polyhedron *b, double sb, const double qb[4],
                          const double tb[3]) {
    /* relative to a's centre, to keep the numbers small */
    vp_poly_posed pa, pb;
    vp_poly_pose(a, sa, qa, ta, ta, &pa);
    vp_poly_pose(b, sb, qb, tb, ta, &pb);
    return posed_sat(&pa, &pb, 0);
}

/* ------------------------------------------------------------------ */
/* Cube against a centre                                               */

int vp_cube_center_test(const double R[3][3], double h, const double d[3], double rin, double r,
                        double eps) {
    double f = 0.0; /* squared distance from the point to the cube: a clamp in its frame */
    for (int k = 0; k < 3; ++k) {
        double u = fabs(R[0][k] * d[0] + R[1][k] * d[1] + R[2][k] * d[2]) - h;
        if (u > 0) f += u * u;
    }
    double lo = rin * (1.0 - 1e-9) - eps, hi = r * (1.0 + 1e-9) + eps;
    if (lo > 0 && f < lo * lo) return 1;
    if (f > hi * hi) return 0;
    return -1;
}
