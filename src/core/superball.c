// SPDX-License-Identifier: Apache-2.0
/* Superballs: geometry, GJK overlap on support functions, the
 * tessellation shared by rendering, export and the wall test, and the
 * lattice families of Jiao, Stillinger & Torquato 2009. See superball.h. */
#include "core/superball.h"
#include "core/geom.h"
#include "core/mesh_shape.h"

#include <ctype.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ */
/* Geometry                                                            */

double vp_superball_circumradius(double p) { return p <= 1.0 ? 1.0 : pow(3.0, 0.5 - 0.5 / p); }

static double beta_fn(double a, double b) { return exp(lgamma(a) + lgamma(b) - lgamma(a + b)); }

double vp_superball_raw_volume(double p) {
    double h = 0.5 / p;
    return 2.0 / (p * p) * beta_fn(h, (2.0 * p + 1.0) * h) * beta_fn(h, (p + 1.0) / p);
}

double vp_superball_unit_volume(double p) {
    double R = vp_superball_circumradius(p);
    return vp_superball_raw_volume(p) / (R * R * R);
}

/* the nearest surface point: the axis for p >= 1, the diagonal below */
double vp_superball_inradius(double p) { return pow(3.0, -fabs(0.5 - 0.5 / p)); }

/* Support of the unscaled superball (norm q = 2p; dual exponent q* with
 * 1/q + 1/q* = 1): x_i = sign(d_i) t_i^(q*-1) / (sum t^q*)^(1/q), with
 * t = |d| / max |d| so that no power overflows. q*-1 = 1/(2p-1); p = 2
 * (a cube root) is the common case and is taken apart. */
static void raw_support(double p, const double d[3], double x[3]) {
    double a[3] = {fabs(d[0]), fabs(d[1]), fabs(d[2])};
    double m = a[0] > a[1] ? a[0] : a[1];
    if (a[2] > m) m = a[2];
    if (!(m > 0)) {
        x[0] = 1.0;
        x[1] = x[2] = 0.0;
        return;
    }
    if (p <= 0.5 + 1e-12) { /* the octahedron: a vertex */
        int k = a[0] >= a[1] && a[0] >= a[2] ? 0 : a[1] >= a[2] ? 1 : 2;
        x[0] = x[1] = x[2] = 0.0;
        x[k] = d[k] < 0 ? -1.0 : 1.0;
        return;
    }
    double e = 1.0 / (2.0 * p - 1.0), s = 0.0, t[3];
    for (int k = 0; k < 3; k++) {
        double u = a[k] / m;
        t[k] = p == 2.0 ? cbrt(u) : p == 1.0 ? u : pow(u, e); /* t^(q*-1) */
        s += t[k] * u;                                        /* t^q* */
    }
    double n = p == 1.0 ? sqrt(s) : p == 2.0 ? sqrt(sqrt(s)) : pow(s, 0.5 / p);
    for (int k = 0; k < 3; k++) x[k] = (d[k] < 0 ? -t[k] : t[k]) / n;
}

void vp_superball_support(double p, const double d[3], double x[3]) {
    raw_support(p, d, x);
    double R = vp_superball_circumradius(p);
    for (int k = 0; k < 3; k++) x[k] /= R;
}

/* ------------------------------------------------------------------ */
/* GJK                                                                 */

void vp_convex_set(vp_convex *c, vp_shape shape, double p, double scale, const double q[4],
                   const double t[3], const double origin[3]) {
    static const double qid[4] = {0, 0, 0, 1};
    memset(c, 0, sizeof *c);
    c->poly = vp_shape_polyhedron(shape);
    c->kind = shape == VP_SHAPE_SUPERBALL ? 1 : c->poly ? 2 : 0;
    c->p = p;
    c->scale = c->kind == 1 ? scale / vp_superball_circumradius(p) : scale;
    vp_quat_to_matrix(q ? q : qid, c->m);
    for (int k = 0; k < 3; k++) c->t[k] = t[k] - (origin ? origin[k] : 0.0);
}

void vp_convex_set_triangle(vp_convex *c, const double a[3], const double b[3], const double cc[3],
                            const double origin[3]) {
    memset(c, 0, sizeof *c);
    c->kind = 3;
    const double *v[3] = {a, b, cc};
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) c->tri[i][k] = v[i][k] - (origin ? origin[k] : 0.0);
    for (int k = 0; k < 3; k++) c->t[k] = (c->tri[0][k] + c->tri[1][k] + c->tri[2][k]) / 3.0;
}

void vp_convex_support(const vp_convex *c, const double d[3], double x[3]) {
    if (c->kind == 3) {
        int best = 0;
        double bv = vp_dot3(c->tri[0], d);
        for (int v = 1; v < 3; v++) {
            double s = vp_dot3(c->tri[v], d);
            if (s > bv) {
                bv = s;
                best = v;
            }
        }
        memcpy(x, c->tri[best], 3 * sizeof *x);
        return;
    }
    /* the direction in the shape's frame: m^T d */
    double l[3], y[3];
    for (int k = 0; k < 3; k++) l[k] = c->m[0][k] * d[0] + c->m[1][k] * d[1] + c->m[2][k] * d[2];
    if (c->kind == 1) {
        raw_support(c->p, l, y);
    } else if (c->kind == 2) {
        int best = 0;
        double bv = -HUGE_VAL;
        for (int v = 0; v < c->poly->nverts; v++) {
            double s = vp_dot3(c->poly->verts[v], l);
            if (s > bv) {
                bv = s;
                best = v;
            }
        }
        memcpy(y, c->poly->verts[best], sizeof y);
    } else {
        double n = vp_norm3(l);
        for (int k = 0; k < 3; k++) y[k] = n > 0 ? l[k] / n : (k == 0);
    }
    for (int k = 0; k < 3; k++)
        x[k] = c->t[k] + c->scale * (c->m[k][0] * y[0] + c->m[k][1] * y[1] + c->m[k][2] * y[2]);
    if (c->inflate > 0) {
        double n = vp_norm3(d);
        for (int k = 0; k < 3; k++) x[k] += n > 0 ? c->inflate * d[k] / n : 0.0;
    }
}

static void mdiff(const vp_convex *a, const vp_convex *b, const double d[3], double w[3]) {
    double nd[3] = {-d[0], -d[1], -d[2]}, sa[3], sb[3];
    vp_convex_support(a, d, sa);
    vp_convex_support(b, nd, sb);
    for (int k = 0; k < 3; k++) w[k] = sa[k] - sb[k];
}

static void sub3(const double a[3], const double b[3], double o[3]) {
    o[0] = a[0] - b[0];
    o[1] = a[1] - b[1];
    o[2] = a[2] - b[2];
}
/* (a x b) x c */
static void triple(const double a[3], const double b[3], const double c[3], double o[3]) {
    double t[3];
    vp_cross3(a, b, t);
    vp_cross3(t, c, o);
}

/* The simplex step of the boolean GJK: the simplex s[0..*n) (newest last)
 * is cut to the feature nearest the origin and *d points from it to the
 * origin. Returns 1 when the origin is enclosed (or lies on the simplex). */
static int do_simplex(double s[4][3], int *n, double d[3]) {
    double *A = s[*n - 1], AO[3] = {-A[0], -A[1], -A[2]};
    if (*n == 2) {
        double AB[3];
        sub3(s[0], A, AB);
        if (vp_dot3(AB, AO) > 0) {
            triple(AB, AO, AB, d);
            if (vp_dot3(d, d) == 0) return 1; /* the origin on the segment */
        } else {
            memcpy(s[0], A, sizeof s[0]);
            *n = 1;
            memcpy(d, AO, sizeof AO);
        }
        return 0;
    }
    if (*n == 3) {
        double *B = s[1], *C = s[0], AB[3], AC[3], ABC[3], t[3];
        sub3(B, A, AB);
        sub3(C, A, AC);
        vp_cross3(AB, AC, ABC);
        vp_cross3(ABC, AC, t);
        if (vp_dot3(t, AO) > 0) {
            if (vp_dot3(AC, AO) > 0) { /* edge AC */
                memcpy(s[1], A, sizeof s[1]);
                *n = 2;
                triple(AC, AO, AC, d);
                return vp_dot3(d, d) == 0;
            }
            goto edge_ab;
        }
        vp_cross3(AB, ABC, t);
        if (vp_dot3(t, AO) > 0) goto edge_ab;
        double side = vp_dot3(ABC, AO);
        if (side > 0) {
            memcpy(d, ABC, sizeof ABC);
        } else if (side < 0) { /* below: keep the winding so that d = normal */
            double tmp[3];
            memcpy(tmp, s[0], sizeof tmp);
            memcpy(s[0], s[1], sizeof tmp);
            memcpy(s[1], tmp, sizeof tmp);
            d[0] = -ABC[0];
            d[1] = -ABC[1];
            d[2] = -ABC[2];
        } else {
            return 1; /* in the triangle's plane, inside it */
        }
        return 0;
    edge_ab:
        if (vp_dot3(AB, AO) > 0) {
            memcpy(s[0], B, sizeof s[0]);
            memcpy(s[1], A, sizeof s[1]);
            *n = 2;
            triple(AB, AO, AB, d);
            return vp_dot3(d, d) == 0;
        }
        memcpy(s[0], A, sizeof s[0]);
        *n = 1;
        memcpy(d, AO, sizeof AO);
        return 0;
    }
    /* tetrahedron D C B A (s[0..3]); the triangle C B A (s[0..2]) was
     * wound so that its normal points at the origin, away from D's side? */
    double *B = s[2], *C = s[1], *D = s[0], AB[3], AC[3], AD[3], n1[3], n2[3], n3[3];
    sub3(B, A, AB);
    sub3(C, A, AC);
    sub3(D, A, AD);
    vp_cross3(AB, AC, n1); /* face ABC */
    vp_cross3(AC, AD, n2); /* face ACD */
    vp_cross3(AD, AB, n3); /* face ADB */
    /* orient each face normal away from the fourth vertex */
    if (vp_dot3(n1, AD) > 0) {
        n1[0] = -n1[0];
        n1[1] = -n1[1];
        n1[2] = -n1[2];
    }
    if (vp_dot3(n2, AB) > 0) {
        n2[0] = -n2[0];
        n2[1] = -n2[1];
        n2[2] = -n2[2];
    }
    if (vp_dot3(n3, AC) > 0) {
        n3[0] = -n3[0];
        n3[1] = -n3[1];
        n3[2] = -n3[2];
    }
    double a[3], b[3], c[3];
    memcpy(a, A, sizeof a);
    if (vp_dot3(n1, AO) > 0) {
        memcpy(b, B, sizeof b);
        memcpy(c, C, sizeof c);
    } else if (vp_dot3(n2, AO) > 0) {
        memcpy(b, C, sizeof b);
        memcpy(c, D, sizeof c);
    } else if (vp_dot3(n3, AO) > 0) {
        memcpy(b, D, sizeof b);
        memcpy(c, B, sizeof c);
    } else {
        return 1; /* inside every face */
    }
    memcpy(s[0], c, sizeof s[0]);
    memcpy(s[1], b, sizeof s[1]);
    memcpy(s[2], a, sizeof s[2]);
    *n = 3;
    return do_simplex(s, n, d);
}

int vp_convex_overlap(const vp_convex *a, const vp_convex *b) {
    return vp_convex_overlap_state(a, b) != 0;
}

int vp_convex_overlap_state(const vp_convex *a, const vp_convex *b) {
    double d[3], s[4][3], w[3];
    sub3(b->t, a->t, d);
    if (vp_dot3(d, d) == 0) return 1; /* one centre: both hold it */
    mdiff(a, b, d, w);
    memcpy(s[0], w, sizeof w);
    int n = 1;
    d[0] = -w[0];
    d[1] = -w[1];
    d[2] = -w[2];
    for (int it = 0; it < 96; it++) {
        if (vp_dot3(d, d) == 0) return 1;
        mdiff(a, b, d, w);
        /* every point of A - B lies at most w.d along d: below 0, the
         * plane through the origin normal to d separates the shapes */
        if (vp_dot3(w, d) < 0) return 0;
        memcpy(s[n++], w, sizeof w);
        if (do_simplex(s, &n, d)) return 1;
    }
    return -1; /* undecided (see superball.h) */
}

int vp_superball_overlap(double p, double sa, const double qa[4], const double ta[3], double sb,
                         const double qb[4], const double tb[3]) {
    vp_convex A, B;
    vp_convex_set(&A, VP_SHAPE_SUPERBALL, p, sa, qa, ta, ta);
    vp_convex_set(&B, VP_SHAPE_SUPERBALL, p, sb, qb, tb, ta);
    return vp_convex_overlap(&A, &B);
}

/* ------------------------------------------------------------------ */
/* Tessellation                                                        */

#define SB_CACHE 32
#define SB_N 24 /* cells per cube face edge: even, so the axis points are vertices */

static struct {
    double p, inflate;
    vp_mesh_shape *m;
} sb_cache[SB_CACHE];
static int sb_ncache;
static pthread_mutex_t sb_lock = PTHREAD_MUTEX_INITIALIZER;

static double pnorm(double p, const double x[3]) {
    double s = 0.0;
    for (int k = 0; k < 3; k++) s += pow(fabs(x[k]), 2.0 * p);
    return pow(s, 0.5 / p);
}

typedef struct {
    double x[3];
    uint32_t id;
} keyed;
static int cmp_keyed(const void *a, const void *b) {
    const keyed *u = a, *v = b;
    for (int k = 0; k < 3; k++)
        if (u->x[k] != v->x[k]) return u->x[k] < v->x[k] ? -1 : 1;
    return u->id < v->id ? -1 : u->id > v->id;
}

static vp_mesh_shape *build_mesh(double p, double *inflate_out) {
    const int n = SB_N, per = (n + 1) * (n + 1);
    size_t nv = 6 * (size_t)per, nt = 6 * (size_t)n * n * 2;
    double *v = malloc(nv * 3 * sizeof *v);
    uint32_t *t = malloc(nt * 3 * sizeof *t), *remap = malloc(nv * sizeof *remap);
    keyed *ks = malloc(nv * sizeof *ks);
    if (!v || !t || !remap || !ks) {
        free(v);
        free(t);
        free(remap);
        free(ks);
        return NULL;
    }
    const double R = vp_superball_circumradius(p);
    /* the cube's faces, each as (axis, sign): grid points c + u U + w W on
     * the face, projected along their ray onto the surface */
    for (int f = 0; f < 6; f++) {
        int ax = f / 2, u = (ax + 1) % 3, w = (ax + 2) % 3;
        double sg = f % 2 ? -1.0 : 1.0;
        for (int i = 0; i <= n; i++)
            for (int j = 0; j <= n; j++) {
                double c[3];
                c[ax] = sg;
                c[u] = -1.0 + 2.0 * i / n;
                c[w] = -1.0 + 2.0 * j / n;
                double r = pnorm(p, c);
                size_t id = (size_t)f * per + (size_t)i * (n + 1) + j;
                for (int k = 0; k < 3; k++) ks[id].x[k] = c[k]; /* weld on the cube point */
                ks[id].id = (uint32_t)id;
                for (int k = 0; k < 3; k++) v[3 * id + k] = c[k] / r / R;
            }
    }
    /* weld the shared edges: equal cube points are one vertex */
    qsort(ks, nv, sizeof *ks, cmp_keyed);
    size_t nu = 0;
    double *vu = malloc(nv * 3 * sizeof *vu);
    if (!vu) {
        free(v);
        free(t);
        free(remap);
        free(ks);
        return NULL;
    }
    for (size_t i = 0; i < nv; i++) {
        if (i > 0 && memcmp(ks[i - 1].x, ks[i].x, sizeof ks[i].x) == 0) {
            remap[ks[i].id] = (uint32_t)(nu - 1);
            continue;
        }
        memcpy(vu + 3 * nu, v + 3 * (size_t)ks[i].id, 3 * sizeof *vu);
        remap[ks[i].id] = (uint32_t)nu++;
    }
    size_t ti = 0;
    for (int f = 0; f < 6; f++) {
        int ax = f / 2;
        double sg = f % 2 ? -1.0 : 1.0;
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                uint32_t a = remap[(size_t)f * per + (size_t)i * (n + 1) + j];
                uint32_t b = remap[(size_t)f * per + (size_t)(i + 1) * (n + 1) + j];
                uint32_t c = remap[(size_t)f * per + (size_t)(i + 1) * (n + 1) + j + 1];
                uint32_t d = remap[(size_t)f * per + (size_t)i * (n + 1) + j + 1];
                /* (u, w, ax) is right-handed: u x w = +ax, so a b c runs
                 * counter-clockwise seen from outside on the + faces */
                uint32_t q[6] = {a, b, c, a, c, d};
                if (sg < 0) {
                    q[1] = c;
                    q[2] = b;
                    q[4] = d;
                    q[5] = c;
                }
                (void)ax;
                for (int k = 0; k < 6; k++) t[3 * ti + k] = q[k];
                ti += 2;
            }
    }
    /* the gap: the largest radial factor from a triangle's points out to
     * the surface, sampled on each triangle, with a margin */
    double worst = 1.0;
    for (size_t k = 0; k < ti; k++) {
        const double *P0 = vu + 3 * t[3 * k], *P1 = vu + 3 * t[3 * k + 1],
                     *P2 = vu + 3 * t[3 * k + 2];
        const int m = 8;
        for (int i = 0; i <= m; i++)
            for (int j = 0; i + j <= m; j++) {
                double b0 = (double)i / m, b1 = (double)j / m, b2 = 1.0 - b0 - b1, x[3];
                for (int c = 0; c < 3; c++) x[c] = (b0 * P0[c] + b1 * P1[c] + b2 * P2[c]) * R;
                double g = 1.0 / pnorm(p, x);
                if (g > worst) worst = g;
            }
    }
    *inflate_out = 1.0 + 1.5 * (worst - 1.0) + 1e-9;
    free(v);
    free(remap);
    free(ks);
    vp_mesh_shape *ms = NULL;
    char name[64];
    vp_superball_format(p, name, sizeof name);
    if (vp_mesh_shape_create(NULL, name, vu, nu, t, ti, &ms) != VP_OK) return NULL;
    return ms;
}

const vp_mesh_shape *vp_superball_mesh(double p, double *inflate) {
    const vp_mesh_shape *out = NULL;
    double inf = 1.0;
    pthread_mutex_lock(&sb_lock);
    for (int i = 0; i < sb_ncache; i++)
        if (sb_cache[i].p == p) {
            out = sb_cache[i].m;
            inf = sb_cache[i].inflate;
        }
    if (!out && sb_ncache < SB_CACHE) {
        vp_mesh_shape *m = build_mesh(p, &inf);
        if (m) {
            sb_cache[sb_ncache].p = p;
            sb_cache[sb_ncache].m = m;
            sb_cache[sb_ncache].inflate = inf;
            sb_ncache++;
            out = m;
        }
    } else if (!out) { /* a full cache: build, and keep it for good (rare) */
        out = build_mesh(p, &inf);
    }
    pthread_mutex_unlock(&sb_lock);
    if (inflate) *inflate = inf;
    return out;
}

double vp_superball_wall_distance(const struct vp_container *c, double p, double scale,
                                  const double q[4], const double t[3], double stop) {
    double inf;
    const vp_mesh_shape *m = vp_superball_mesh(p, &inf);
    if (!m) return HUGE_VAL;
    return vp_mesh_shape_wall_distance(c, m, scale * inf, q, t, stop);
}

/* ------------------------------------------------------------------ */
/* Lattices (Jiao, Stillinger & Torquato 2009, eqs. 2-3, 7-8, 10, 15-16) */

static const char *const sb_family_names[] = {"C0", "C1", "O0", "O1"};
const char *vp_superball_family_name(vp_superball_family f) {
    return (int)f >= 0 && (int)f < 4 ? sb_family_names[f] : NULL;
}

/* the root of an increasing-through-zero f in [lo, hi] by bisection */
static double bisect(double (*f)(double, double), double p, double lo, double hi) {
    double flo = f(p, lo);
    for (int i = 0; i < 200 && hi - lo > 0; i++) {
        double mid = 0.5 * (lo + hi), fm = f(p, mid);
        if (mid <= lo || mid >= hi) break;
        if ((fm < 0) == (flo < 0)) {
            lo = mid;
            flo = fm;
        } else hi = mid;
    }
    return 0.5 * (lo + hi);
}

static double c0_eq(double p, double s) { /* eq. 3 */
    return pow(s + pow(2.0, -0.5 / p), 2 * p) + pow(s, 2 * p) + pow(2.0, -2 * p) - 1.0;
}
static double c1_eq(double p, double s) { /* eq. 8 */
    return pow(s + pow(2.0, -0.5 / p), 2 * p) + 2.0 * pow(s, 2 * p) - 1.0;
}
static double o1_eq(double p, double q) { /* eq. 16 with s = (1 - 2 q^2p)^(1/2p) */
    double l = pow(3.0, -0.5 / p), s = pow(fmax(0.0, 1.0 - 2.0 * pow(q, 2 * p)), 0.5 / p);
    return pow(l + q, 2 * p) + pow(fabs(s - l), 2 * p) + pow(fabs(l - q), 2 * p) - 1.0;
}

static double po_star(void) { return log(3.0) / log(4.0); }

static void o1_vectors(const double x[3], double a[3][3]) {
    const double l = x[0], q = x[1], s = x[2];
    a[0][0] = 2 * l;
    a[0][1] = 2 * l;
    a[0][2] = -2 * l;
    a[1][0] = -2 * q;
    a[1][1] = 2 * s;
    a[1][2] = -2 * q;
    a[2][0] = 2 * q;
    a[2][1] = -2 * q;
    a[2][2] = -2 * s;
}

/* The lattice a scaled to contact: the least gauge of v/2 over the
 * vectors with coefficients in [-2, 2] (a lattice packs the centrally
 * symmetric K iff no lattice vector lies inside 2K). */
static double contact_scale(double p, const double a[3][3]) {
    double best = HUGE_VAL;
    for (int i = -2; i <= 2; i++)
        for (int j = -2; j <= 2; j++)
            for (int k = -2; k <= 2; k++) {
                if (!i && !j && !k) continue;
                double g = 0.0;
                for (int c = 0; c < 3; c++)
                    g += pow(fabs(0.5 * (i * a[0][c] + j * a[1][c] + k * a[2][c])), 2 * p);
                if (g < best) best = g;
            }
    return pow(best, 0.5 / p);
}

static double o1_density(double p, const double x[3]) {
    double a[3][3];
    o1_vectors(x, a);
    double lam = contact_scale(p, a);
    return lam * lam * lam / fabs(vp_det3(a[0], a[1], a[2]));
}

/* The O1 vectors as printed (eqs. 15-16 of arXiv:0902.1504) make
 * -e1 + e2 + e3 a vector inside 2K for every p in (0.5, p*_o): the
 * superballs overlap (by 0.8 % of the gauge at p = 0.55). So the form's
 * three parameters (l, q, s) are searched, from the printed ones, for the
 * densest lattice of that form scaled to contact (a pattern search on
 * the density; docs/lattices.md). At p = 0.5 the printed vectors are
 * Minkowski's, already a packing, and stay. */
static void o1_refine(double p, double x[3], double a[3][3]) {
    double f = o1_density(p, x), step = 0.02;
    while (step > 1e-12) {
        int better = 0;
        for (int i = 0; i < 3; i++)
            for (int sg = -1; sg <= 1; sg += 2) {
                double y[3] = {x[0], x[1], x[2]};
                y[i] += sg * step;
                double fy = o1_density(p, y);
                if (fy > f) {
                    memcpy(x, y, sizeof y);
                    f = fy;
                    better = 1;
                }
            }
        if (!better) step *= 0.5;
    }
    o1_vectors(x, a);
    double lam = contact_scale(p, a);
    for (int i = 0; i < 3; i++)
        for (int c = 0; c < 3; c++) a[i][c] /= lam;
}

static int family_basis(vp_superball_family f, double p, double a[3][3]) {
    memset(a, 0, 9 * sizeof(double));
    const double c = pow(2.0, -0.5 / p), k = pow(2.0, 1.0 - 0.5 / p);
    switch (f) {
    case VP_SB_C0: { /* eq. 2 */
        if (p < 1.0) return -1;
        double s = bisect(c0_eq, p, 0.0, 1.0);
        a[0][0] = k;
        a[0][1] = k;
        a[1][2] = 2.0;
        a[2][0] = -2.0 * s;
        a[2][1] = 2.0 * (s + c);
        a[2][2] = 1.0;
        return 0;
    }
    case VP_SB_C1: { /* eq. 7 */
        if (p < 1.0) return -1;
        double s = bisect(c1_eq, p, 0.0, 1.0);
        a[0][0] = k;
        a[0][1] = k;
        a[1][0] = k;
        a[1][2] = k;
        a[2][0] = 2.0 * (s + c);
        a[2][1] = -2.0 * s;
        a[2][2] = -2.0 * s;
        return 0;
    }
    case VP_SB_O0: { /* eq. 10; every other layer would overlap below p*_o (eq. 11) */
        if (p < po_star()) return -1;
        a[0][0] = 2.0;
        a[1][1] = 2.0;
        a[2][0] = 1.0;
        a[2][1] = 1.0;
        a[2][2] = 2.0 * pow(1.0 - pow(2.0, 1.0 - 2.0 * p), 0.5 / p);
        return 0;
    }
    case VP_SB_O1: { /* eqs. 15-16 as the paper's starting point (the root of
                      * least q: Minkowski's q = 1/6 at p = 0.5; none above
                      * p*_o), then the densest non-overlapping member of
                      * the same form (see o1_refine) */
        if (p < 0.5 || p >= po_star()) return -1;
        const double qmax = pow(0.5, 0.5 / p);
        const int steps = 4000;
        double prev = o1_eq(p, 0.0), lo = -1, hi = -1;
        for (int i = 1; i <= steps; i++) {
            double q = qmax * i / steps, v = o1_eq(p, q);
            if ((v < 0) != (prev < 0)) {
                lo = qmax * (i - 1) / steps;
                hi = q;
                break;
            }
            prev = v;
        }
        if (lo < 0) return -1;
        double x[3];
        x[1] = bisect(o1_eq, p, lo, hi);
        x[0] = pow(3.0, -0.5 / p);
        x[2] = pow(1.0 - 2.0 * pow(x[1], 2 * p), 0.5 / p);
        o1_refine(p, x, a);
        return 0;
    }
    }
    return -1;
}

int vp_superball_family_basis(vp_superball_family f, double p, double a[3][3]) {
    if (!(p >= VP_SUPERBALL_P_MIN) || !(p <= VP_SUPERBALL_P_MAX)) return -1;
    return family_basis(f, p, a);
}

static double family_density(vp_superball_family f, double p) {
    double a[3][3];
    if (family_basis(f, p, a) != 0) return 0.0;
    return vp_superball_raw_volume(p) / fabs(vp_det3(a[0], a[1], a[2]));
}
static double c_diff(double unused, double p) {
    (void)unused;
    return family_density(VP_SB_C0, p) - family_density(VP_SB_C1, p);
}

static double sb_pc;
static pthread_once_t sb_pc_once = PTHREAD_ONCE_INIT;
/* C0 is the denser just above 1, C1 from 1.1509...: one crossing in (1.01, 2) */
static void pc_init(void) { sb_pc = bisect(c_diff, 0.0, 1.01, 2.0); }

double vp_superball_pc(void) {
    pthread_once(&sb_pc_once, pc_init);
    return sb_pc;
}

vp_superball_family vp_superball_best_family(double p) {
    if (p < po_star()) return VP_SB_O1;
    if (p < 1.0) return VP_SB_O0;
    if (p < vp_superball_pc()) return VP_SB_C0;
    return VP_SB_C1;
}

void vp_superball_format(double p, char *buf, size_t n) {
    for (int prec = 15; prec <= 17; prec++) {
        snprintf(buf, n, "superball:%.*g", prec, p);
        if (strtod(buf + 10, NULL) == p) return;
    }
}

int vp_superball_parse(const char *text, double *p) {
    static const char key[] = "superball:";
    if (!text) return -1;
    for (size_t i = 0; i < sizeof key - 1; i++)
        if (tolower((unsigned char)text[i]) != key[i]) return -1;
    const char *v = text + sizeof key - 1;
    char *end = NULL;
    double x = strtod(v, &end);
    if (end == v || *end != '\0' || !isfinite(x) || x < VP_SUPERBALL_P_MIN ||
        x > VP_SUPERBALL_P_MAX)
        return -2;
    *p = x;
    return 0;
}
