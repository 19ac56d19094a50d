/* SPDX-License-Identifier: Apache-2.0 */
/* Several shapes in one packing (issue 30 section 3): the cross-kind overlap
 * test (core/pair.h) against independent geometry, and mixed rsa packings
 * checked pair by pair by this file's own tests: spheres by distance,
 * a sphere against a box by its nearest point, two boxes by the 15-axis
 * separating-axis test of oriented boxes. The mesh shape is a cuboid mesh
 * built here, so every pair of {sphere, cube, cuboid mesh} has an exact
 * test that shares no code with the library's. */
#include "vdbpack/vdbpack.h"
#include "core/geom.h"
#include "core/pair.h"
#include "core/shape.h"
#include "vp_test.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* --- independent geometry --------------------------------------------------- */

/* An oriented box: centre, axes (columns of R, unit), half extents. */
typedef struct obb {
    double c[3], R[3][3], h[3];
} obb;

static uint64_t rng_state = 88172645463325252ull;
static double urand(void) {
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) * 0x1.0p-53;
}
static void rand_quat(double q[4]) {
    double n = 0;
    for (int k = 0; k < 4; k++) q[k] = 2.0 * urand() - 1.0, n += q[k] * q[k];
    n = sqrt(n);
    for (int k = 0; k < 4; k++) q[k] /= n;
}
/* Rotation matrix of q = (x, y, z, w), written out here (not vp_quat_to_matrix). */
static void quat_matrix(const double q[4], double m[3][3]) {
    double x = q[0], y = q[1], z = q[2], w = q[3];
    m[0][0] = 1 - 2 * (y * y + z * z), m[0][1] = 2 * (x * y - z * w), m[0][2] = 2 * (x * z + y * w);
    m[1][0] = 2 * (x * y + z * w), m[1][1] = 1 - 2 * (x * x + z * z), m[1][2] = 2 * (y * z - x * w);
    m[2][0] = 2 * (x * z - y * w), m[2][1] = 2 * (y * z + x * w), m[2][2] = 1 - 2 * (x * x + y * y);
}

/* Signed: > 0 the gap between a ball (centre p, radius r) and box b, < 0
 * an overlap (the ball's centre closer than r to the box). */
static double ball_box_gap(const double p[3], double r, const obb *b) {
    double d[3] = {p[0] - b->c[0], p[1] - b->c[1], p[2] - b->c[2]}, e2 = 0, inside = HUGE_VAL;
    int in = 1;
    for (int k = 0; k < 3; k++) {
        double l = b->R[0][k] * d[0] + b->R[1][k] * d[1] + b->R[2][k] * d[2];
        double o = fabs(l) - b->h[k];
        if (o > 0) e2 += o * o, in = 0;
        if (-o < inside) inside = -o;
    }
    return in ? -inside - r : sqrt(e2) - r;
}

/* Largest separation over the 15 SAT axes of two boxes (> 0 apart). */
static double box_box_sep(const obb *a, const obb *b) {
    double axes[15][3];
    int n = 0;
    for (int i = 0; i < 3; i++) {
        for (int k = 0; k < 3; k++) axes[n][k] = a->R[k][i];
        n++;
        for (int k = 0; k < 3; k++) axes[n][k] = b->R[k][i];
        n++;
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double u[3] = {a->R[0][i], a->R[1][i], a->R[2][i]},
                   v[3] = {b->R[0][j], b->R[1][j], b->R[2][j]};
            axes[n][0] = u[1] * v[2] - u[2] * v[1];
            axes[n][1] = u[2] * v[0] - u[0] * v[2];
            axes[n][2] = u[0] * v[1] - u[1] * v[0];
            n++;
        }
    double best = -HUGE_VAL;
    for (int t = 0; t < n; t++) {
        double *x = axes[t], len = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        if (len < 1e-9) continue;
        double ra = 0, rb = 0, dc = 0;
        for (int i = 0; i < 3; i++) {
            ra += a->h[i] * fabs((a->R[0][i] * x[0] + a->R[1][i] * x[1] + a->R[2][i] * x[2]) / len);
            rb += b->h[i] * fabs((b->R[0][i] * x[0] + b->R[1][i] * x[1] + b->R[2][i] * x[2]) / len);
        }
        for (int k = 0; k < 3; k++) dc += (b->c[k] - a->c[k]) * x[k] / len;
        double s = fabs(dc) - ra - rb;
        if (s > best) best = s;
    }
    return best;
}

/* The cuboid mesh: a box of sides (2, 1.2, 0.8) as 12 triangles, counter-
 * clockwise from outside. Normalised by the library to bounding radius 1:
 * half extents (1, 0.6, 0.4) / |(1, 0.6, 0.4)|. */
static const double cub_side[3] = {2.0, 1.2, 0.8};
static vp_mesh_shape *cuboid_mesh(vp_context *ctx) {
    double v[8][3];
    for (int i = 0; i < 8; i++)
        for (int k = 0; k < 3; k++) v[i][k] = (i >> k & 1 ? 0.5 : -0.5) * cub_side[k];
    static const uint32_t t[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},
                                      {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},
                                      {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    vp_mesh_shape *m = NULL;
    ASSERT_OK(ctx, vp_mesh_shape_from_mesh(ctx, "cuboid.obj", &v[0][0], 8, &t[0][0], 12, &m));
    return m;
}
static void cuboid_half(double h[3]) {
    double n = 0.5 * sqrt(cub_side[0] * cub_side[0] + cub_side[1] * cub_side[1] +
                          cub_side[2] * cub_side[2]);
    for (int k = 0; k < 3; k++) h[k] = 0.5 * cub_side[k] / n;
}

/* Particle i as an oriented box (cubes: half side r / sqrt 3; the cuboid
 * mesh: its half extents times r). */
static void as_box(const double c[3], double r, const double q[4], int cuboid, obb *b) {
    memcpy(b->c, c, sizeof b->c);
    quat_matrix(q, b->R);
    if (cuboid) {
        cuboid_half(b->h);
        for (int k = 0; k < 3; k++) b->h[k] *= r;
    } else {
        for (int k = 0; k < 3; k++) b->h[k] = r / sqrt(3.0);
    }
}

/* --- the cross-kind test against the geometry above -------------------------- */

static void test_kind_overlap_random_pairs(void) {
    vp_context *ctx;
    ASSERT_OK(ctx, vp_context_create(&ctx));
    vp_mesh_shape *cub = cuboid_mesh(ctx);
    vp_kind ks, kc, km;
    ASSERT_EQ_INT(vp_kind_set(&ks, (vp_shape_ref){VP_SHAPE_SPHERE, 0, NULL}), 0);
    ASSERT_EQ_INT(vp_kind_set(&kc, (vp_shape_ref){VP_SHAPE_CUBE, 0, NULL}), 0);
    ASSERT_EQ_INT(vp_kind_set(&km, (vp_shape_ref){VP_SHAPE_MESH, 0, cub}), 0);
    const vp_kind *kinds[3] = {&ks, &kc, &km};
    int counts[3][3][2] = {{{0}}}, decided = 0;
    for (int it = 0; it < 30000; it++) {
        int a = it % 3, b = (it / 3) % 3;
        double ra = 0.5 + urand(), rb = 0.5 + urand(), qa[4], qb[4], ta[3] = {0, 0, 0}, tb[3];
        rand_quat(qa);
        rand_quat(qb);
        double dir[3], n = 0;
        for (int k = 0; k < 3; k++) dir[k] = urand() - 0.5, n += dir[k] * dir[k];
        n = sqrt(n);
        double dist = (ra + rb) * (0.3 + 0.75 * urand());
        for (int k = 0; k < 3; k++) tb[k] = dir[k] / n * dist;
        /* the independent verdict */
        double gap;
        obb A, B;
        if (a) as_box(ta, ra, qa, a == 2, &A);
        if (b) as_box(tb, rb, qb, b == 2, &B);
        if (!a && !b) gap = dist - ra - rb;
        else if (!a) gap = ball_box_gap(ta, ra, &B);
        else if (!b) gap = ball_box_gap(tb, rb, &A);
        else gap = box_box_sep(&A, &B);
        if (fabs(gap) < 1e-7 * (ra + rb)) continue; /* a tie: either answer is right */
        int got = vp_kind_overlap(kinds[a], ra, qa, ta, kinds[b], rb, qb, tb);
        if (got != (gap < 0)) {
            fprintf(stderr, "kinds %d, %d: gap %.17g but vp_kind_overlap says %d\n", a, b, gap,
                    got);
            exit(1);
        }
        /* symmetric */
        ASSERT_EQ_INT(vp_kind_overlap(kinds[b], rb, qb, tb, kinds[a], ra, qa, ta), got);
        counts[a][b][got]++;
        decided++;
    }
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) { /* both answers were exercised for every pairing */
            ASSERT_GE(counts[a][b][0], 200);
            ASSERT_GE(counts[a][b][1], 200);
        }
    fprintf(stderr, "   %d pairs decided, all as the independent geometry\n", decided);
    vp_mesh_shape_destroy(cub);
    vp_context_destroy(ctx);
}

/* A superball and a polyhedron by GJK against the superball's own
 * inequality: a polyhedron vertex inside the superball proves an overlap;
 * the superball's support points all outside the polyhedron's face planes
 * along one face normal prove separation. Only pairs one of the two proves
 * are compared. */
static void test_kind_overlap_superball_octahedron(void) {
    vp_kind kb, ko;
    const double p = 2.0;
    ASSERT_EQ_INT(vp_kind_set(&kb, (vp_shape_ref){VP_SHAPE_SUPERBALL, p, NULL}), 0);
    ASSERT_EQ_INT(vp_kind_set(&ko, (vp_shape_ref){VP_SHAPE_OCTAHEDRON, 0, NULL}), 0);
    const vp_polyhedron *oct = vp_shape_polyhedron(VP_SHAPE_OCTAHEDRON);
    /* the superball scaled to bounding radius 1: |x|^4+|y|^4+|z|^4 <= s^4 with s = 3^(-1/4) */
    const double s = pow(3.0, -0.25);
    int proven_in = 0, proven_apart = 0;
    for (int it = 0; it < 4000; it++) {
        double rb = 1.0, ro = 0.4 + 0.8 * urand(), qo[4], qb[4] = {0, 0, 0, 1}, tb[3] = {0, 0, 0},
               to[3];
        rand_quat(qo);
        double dir[3], n = 0;
        for (int k = 0; k < 3; k++) dir[k] = urand() - 0.5, n += dir[k] * dir[k];
        n = sqrt(n);
        double dist = (rb + ro) * (0.4 + 0.7 * urand());
        for (int k = 0; k < 3; k++) to[k] = dir[k] / n * dist;
        double m[3][3];
        quat_matrix(qo, m);
        int vin = 0; /* a vertex of the octahedron inside the superball */
        for (int v = 0; v < oct->nverts; v++) {
            double x[3], f = 0;
            for (int k = 0; k < 3; k++)
                x[k] = to[k] + ro * (m[k][0] * oct->verts[v][0] + m[k][1] * oct->verts[v][1] +
                                     m[k][2] * oct->verts[v][2]);
            for (int k = 0; k < 3; k++) f += pow(fabs(x[k]) / s, 4.0);
            if (f < 1.0 - 1e-9) vin = 1;
        }
        /* apart along a face normal n of the octahedron: the superball's
         * extent along n (its support, closed form for p = 2: sum |n|^(4/3))
         * below the face plane */
        int apart = 0;
        for (int f = 0; f < oct->nfaces && !apart; f++) {
            double nw[3], h = 0, off = 0;
            for (int k = 0; k < 3; k++)
                nw[k] = m[k][0] * oct->normals[f][0] + m[k][1] * oct->normals[f][1] +
                        m[k][2] * oct->normals[f][2];
            for (int k = 0; k < 3; k++) h += pow(fabs(nw[k]), 4.0 / 3.0);
            h = s * pow(h, 3.0 / 4.0); /* max over the superball of x . n (dual norm) */
            for (int k = 0; k < 3; k++) off += nw[k] * to[k];
            /* the face plane: x . n = off + ro * inradius; the superball lies
             * beyond it (on the octahedron's outside) when -h > off + ro rin */
            double rin = oct->inradius * ro;
            if (-h > -(off - rin) + 1e-9 || h < off - rin - 1e-9) apart = 1;
        }
        if (!vin && !apart) continue;
        ASSERT_TRUE(!(vin && apart));
        int got = vp_kind_overlap(&kb, rb, qb, tb, &ko, ro, qo, to);
        ASSERT_EQ_INT(got, vin);
        proven_in += vin;
        proven_apart += apart;
    }
    fprintf(stderr, "   %d proven overlaps, %d proven separations agree\n", proven_in,
            proven_apart);
    ASSERT_GE(proven_in, 300);
    ASSERT_GE(proven_apart, 300);
}

/* --- mixed packings --------------------------------------------------------------- */

typedef struct mix_out {
    vp_particles *p;
    vp_rsa_report rep;
} mix_out;

static vp_result pack_ternary(vp_context *ctx, const vp_container *c, const vp_mesh_shape *cub,
                              uint64_t seed, mix_out *o) {
    vp_rsa_pass ps[3];
    for (int i = 0; i < 3; i++) vp_rsa_pass_init(&ps[i]);
    ps[0].count = 60; /* cubes */
    vp_size_dist_constant(&ps[0].radius, 0.1);
    ps[0].own_shape = 1;
    ps[0].shape = (vp_shape_ref){VP_SHAPE_CUBE, 0, NULL};
    ps[1].count = 300; /* the cuboid mesh */
    vp_size_dist_constant(&ps[1].radius, 0.07);
    ps[1].own_shape = 1;
    ps[1].shape = (vp_shape_ref){VP_SHAPE_MESH, 0, cub};
    ps[2].maximal = 1; /* spheres (the params' shape), into what is left */
    ps[2].retries = 3000;
    vp_size_dist_constant(&ps[2].radius, 0.03);
    ps[2].grow = 1;
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.passes = ps;
    rp.npasses = 3;
    rp.seed = seed;
    return vp_pack_rsa(ctx, c, &rp, &o->p, &o->rep);
}

/* The ternary set of seed 7 in the unit box, with what it needs (owned;
 * ternary_free). */
typedef struct ternary {
    vp_context *ctx;
    vp_mesh_shape *cub;
    vp_container *c;
    mix_out o;
} ternary;

static void ternary_make(ternary *t) {
    ASSERT_OK(t->ctx, vp_context_create(&t->ctx));
    t->cub = cuboid_mesh(t->ctx);
    ASSERT_OK(t->ctx, vp_container_create_box(t->ctx, (double[3]){-0.5, -0.5, -0.5},
                                              (double[3]){0.5, 0.5, 0.5}, &t->c));
    ASSERT_OK(t->ctx, pack_ternary(t->ctx, t->c, t->cub, 7, &t->o));
}

static void ternary_free(ternary *t) {
    vp_particles_destroy(t->o.p);
    vp_container_destroy(t->c);
    vp_mesh_shape_destroy(t->cub);
    vp_context_destroy(t->ctx);
}

static void test_ternary_pairwise(void) {
    ternary tx;
    ternary_make(&tx);
    vp_context *ctx = tx.ctx;
    vp_mesh_shape *cub = tx.cub;
    vp_container *c = tx.c;
    const vp_particles *p = tx.o.p;
    ASSERT_EQ_INT(p->shape, VP_SHAPE_MIXED);
    ASSERT_EQ_INT(p->shape_count, 3);
    ASSERT_EQ_INT(p->shapes[0].shape, VP_SHAPE_CUBE);
    ASSERT_EQ_INT(p->shapes[1].shape, VP_SHAPE_MESH);
    ASSERT_TRUE(p->shapes[1].mesh == cub);
    ASSERT_EQ_INT(p->shapes[2].shape, VP_SHAPE_SPHERE);
    ASSERT_TRUE(p->has_orient && p->orients && p->shape_index && p->radii);
    size_t per[3] = {0, 0, 0};
    for (size_t i = 0; i < p->count; i++) { /* each pass's group is its shape */
        ASSERT_EQ_INT(p->shape_index[i], p->groups[i]);
        per[p->shape_index[i]]++;
    }
    ASSERT_EQ_INT(per[0], 60);
    ASSERT_EQ_INT(per[1], 300);
    ASSERT_GE(per[2], 500);
    /* every pair, by this file's geometry */
    size_t n = p->count, pairs = 0, close = 0;
    double worst = HUGE_VAL;
    for (size_t i = 0; i < n; i++) {
        const double *ci = p->positions + 3 * i;
        double ri = p->radii[i], qi[4];
        vp_quat_from_float(p->orients + 4 * i, qi);
        int ki = p->shape_index[i];
        /* inside the box: a sphere's extent, a box's corners */
        if (ki == 2) {
            for (int k = 0; k < 3; k++) ASSERT_LE(fabs(ci[k]) + ri, 0.5 + 1e-9);
        } else {
            obb A;
            as_box(ci, ri, qi, ki == 1, &A);
            for (int k = 0; k < 3; k++) {
                double ext = 0;
                for (int a = 0; a < 3; a++) ext += A.h[a] * fabs(A.R[k][a]);
                ASSERT_LE(fabs(ci[k]) + ext, 0.5 + 1e-6);
            }
        }
        for (size_t j = i + 1; j < n; j++) {
            const double *cj = p->positions + 3 * j;
            double rj = p->radii[j], d2 = 0;
            for (int k = 0; k < 3; k++) d2 += (ci[k] - cj[k]) * (ci[k] - cj[k]);
            if (d2 >= (ri + rj) * (ri + rj)) continue;
            double qj[4];
            vp_quat_from_float(p->orients + 4 * j, qj);
            int kj = p->shape_index[j];
            obb A, B;
            if (ki != 2) as_box(ci, ri, qi, ki == 1, &A);
            if (kj != 2) as_box(cj, rj, qj, kj == 1, &B);
            double gap = ki == 2 && kj == 2 ? sqrt(d2) - ri - rj
                         : ki == 2          ? ball_box_gap(ci, ri, &B)
                         : kj == 2          ? ball_box_gap(cj, rj, &A)
                                            : box_box_sep(&A, &B);
            double scale = ri < rj ? ri : rj;
            if (gap / scale < worst) worst = gap / scale;
            if (gap < 1e-3 * scale) close++;
            pairs++;
        }
    }
    fprintf(stderr,
            "   %zu particles (%zu cubes, %zu cuboids, %zu spheres), %zu pairs within "
            "reach, %zu within 1e-3, least gap %.3g of the smaller radius\n",
            n, per[0], per[1], per[2], pairs, close, worst);
    ASSERT_GE(worst, -1e-6);
    ASSERT_GE(close, 50); /* grown spheres touch their neighbours: the test is not vacuous */
    /* vdbpack check agrees */
    vp_check_report cr;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, NULL, &cr));
    ASSERT_EQ_INT(cr.overlapping_pairs, 0);
    ASSERT_EQ_INT(cr.outside, 0);
    ASSERT_NEAR(cr.particle_volume, vp_particles_volume(p), 1e-12);
    /* the volume: each particle its own shape's */
    double vol = 0, hc[3];
    cuboid_half(hc);
    for (size_t i = 0; i < n; i++) {
        double r = p->radii[i];
        int k = p->shape_index[i];
        vol += k == 0   ? pow(2.0 * r / sqrt(3.0), 3)
               : k == 1 ? 8.0 * hc[0] * hc[1] * hc[2] * r * r * r
                        : 4.0 / 3.0 * M_PI * r * r * r;
    }
    ASSERT_NEAR(vp_particles_volume(p), vol, 1e-9 * vol);
    ternary_free(&tx);
}

/* check finds an overlap planted in a mixed set (the test above can fail). */
static void test_check_sees_cross_overlap(void) {
    ternary tx;
    ternary_make(&tx);
    vp_context *ctx = tx.ctx;
    vp_container *c = tx.c;
    vp_particles *p = tx.o.p;
    /* a sphere moved onto a cube's face, 1 % of its radius inside it */
    size_t cube = 0, sphere = 0;
    while (p->shape_index[cube] != 0) cube++;
    while (p->shape_index[sphere] != 2) sphere++;
    double q[4], m[3][3];
    vp_quat_from_float(p->orients + 4 * cube, q);
    quat_matrix(q, m);
    double h = p->radii[cube] / sqrt(3.0), rs = p->radii[sphere];
    for (int k = 0; k < 3; k++)
        p->positions[3 * sphere + k] = p->positions[3 * cube + k] + m[k][0] * (h + 0.99 * rs);
    vp_check_report cr;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, NULL, &cr));
    ASSERT_GE(cr.overlapping_pairs, 1);
    /* the two alone: the depth, by bisection on the common scale, is the
     * planted 1 % up to the shrink's approximation (the cube shrinks too) */
    vp_particles *two;
    ASSERT_OK(ctx, vp_particles_create(ctx, 2, &two));
    two->count = 2;
    two->radii = malloc(2 * sizeof *two->radii);
    two->orients = malloc(8 * sizeof *two->orients);
    two->shape_index = malloc(2);
    ASSERT_TRUE(two->radii && two->orients && two->shape_index);
    two->has_orient = 1;
    two->shape = VP_SHAPE_MIXED;
    two->shape_count = p->shape_count;
    memcpy(two->shapes, p->shapes, sizeof p->shapes);
    size_t pick[2] = {cube, sphere};
    for (int t = 0; t < 2; t++) {
        memcpy(two->positions + 3 * t, p->positions + 3 * pick[t], 3 * sizeof(double));
        two->radii[t] = p->radii[pick[t]];
        memcpy(two->orients + 4 * t, p->orients + 4 * pick[t], 4 * sizeof(float));
        two->shape_index[t] = p->shape_index[pick[t]];
    }
    ASSERT_OK(ctx, vp_check_particles(ctx, c, two, NULL, &cr));
    ASSERT_EQ_INT(cr.overlapping_pairs, 1);
    ASSERT_GE(cr.max_overlap_world, 0.005 * rs);
    ASSERT_LE(cr.max_overlap_world, 0.02 * rs);
    /* moved 2 % of its radius off the face: apart */
    for (int k = 0; k < 3; k++)
        two->positions[3 + k] = two->positions[k] + m[k][0] * (h + 1.02 * rs);
    ASSERT_OK(ctx, vp_check_particles(ctx, c, two, NULL, &cr));
    ASSERT_EQ_INT(cr.overlapping_pairs, 0);
    vp_particles_destroy(two);
    ternary_free(&tx);
}

static int same_particles(const vp_particles *a, const vp_particles *b) {
    if (a->count != b->count || a->has_orient != b->has_orient) return 0;
    size_t n = a->count;
    return !memcmp(a->positions, b->positions, 3 * n * sizeof(double)) &&
           !memcmp(a->radii, b->radii, n * sizeof(float)) &&
           (!a->has_orient || !memcmp(a->orients, b->orients, 4 * n * sizeof(float))) &&
           (!a->shape_index || !memcmp(a->shape_index, b->shape_index, n));
}

static void test_threads_and_one_shape(void) {
    vp_context *ctx;
    ASSERT_OK(ctx, vp_context_create(&ctx));
    vp_mesh_shape *cub = cuboid_mesh(ctx);
    vp_container *c;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, (double[3]){0, 0, 0}, 0.5, &c));
    mix_out a, b;
    vp_context_set_threads(ctx, 1);
    ASSERT_OK(ctx, pack_ternary(ctx, c, cub, 11, &a));
    vp_context_set_threads(ctx, 2);
    ASSERT_OK(ctx, pack_ternary(ctx, c, cub, 11, &b));
    ASSERT_TRUE(same_particles(a.p, b.p));
    vp_particles_destroy(a.p);
    vp_particles_destroy(b.p);
    /* passes that all name the params' own shape: the one-shape packing,
     * bit for bit */
    vp_rsa_pass ps[2];
    for (int i = 0; i < 2; i++) {
        vp_rsa_pass_init(&ps[i]);
        ps[i].count = 150;
        vp_size_dist_constant(&ps[i].radius, i ? 0.05 : 0.08);
    }
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.shape = VP_SHAPE_OCTAHEDRON;
    rp.passes = ps;
    rp.npasses = 2;
    rp.seed = 5;
    vp_particles *plain, *named;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &plain, NULL));
    ps[1].own_shape = 1;
    ps[1].shape = (vp_shape_ref){VP_SHAPE_OCTAHEDRON, 0, NULL};
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &named, NULL));
    ASSERT_EQ_INT(named->shape, VP_SHAPE_OCTAHEDRON);
    ASSERT_TRUE(named->shape_index == NULL);
    ASSERT_TRUE(same_particles(plain, named));
    vp_particles_destroy(named);
    /* every pass a cube, the params' shape a sphere: a packing of cubes */
    ps[0].own_shape = 1;
    ps[0].shape = (vp_shape_ref){VP_SHAPE_CUBE, 0, NULL};
    ps[1].shape = ps[0].shape;
    rp.shape = VP_SHAPE_SPHERE;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &named, NULL));
    ASSERT_EQ_INT(named->shape, VP_SHAPE_CUBE);
    ASSERT_TRUE(named->has_orient && named->shape_index == NULL);
    rp.shape = VP_SHAPE_CUBE;
    ps[0].own_shape = ps[1].own_shape = 0;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &a.p, NULL));
    ASSERT_TRUE(same_particles(a.p, named));
    vp_particles_destroy(a.p);
    vp_particles_destroy(named);
    vp_particles_destroy(plain);
    vp_container_destroy(c);
    vp_mesh_shape_destroy(cub);
    vp_context_destroy(ctx);
}

static void test_refused(void) {
    vp_context *ctx;
    ASSERT_OK(ctx, vp_context_create(&ctx));
    vp_container *c;
    ASSERT_OK(ctx, vp_container_create_box(ctx, (double[3]){0, 0, 0}, (double[3]){1, 1, 1}, &c));
    vp_rsa_pass ps[VP_MAX_SHAPES + 1];
    for (int i = 0; i <= VP_MAX_SHAPES; i++) {
        vp_rsa_pass_init(&ps[i]);
        ps[i].count = 3;
        vp_size_dist_constant(&ps[i].radius, 0.02);
    }
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.passes = ps;
    rp.npasses = 2;
    vp_particles *p = (vp_particles *)1;
    ps[1].own_shape = 1;
    ps[1].shape = (vp_shape_ref){VP_SHAPE_SUPERBALL, 0.3, NULL}; /* concave: not offered */
    ASSERT_FAILS(ctx, VP_ERR_INVALID_ARGUMENT, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    ASSERT_TRUE(p == NULL);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "pass 2") != NULL);
    ps[1].shape = (vp_shape_ref){VP_SHAPE_SUPERBALL, NAN, NULL};
    ASSERT_FAILS(ctx, VP_ERR_INVALID_ARGUMENT, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    ps[1].shape = (vp_shape_ref){VP_SHAPE_MESH, 0, NULL}; /* a mesh shape without its mesh */
    ASSERT_FAILS(ctx, VP_ERR_INVALID_ARGUMENT, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    ps[1].shape = (vp_shape_ref){(vp_shape)40, 0, NULL};
    ASSERT_FAILS(ctx, VP_ERR_INVALID_ARGUMENT, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    ps[1].shape = (vp_shape_ref){VP_SHAPE_MIXED, 0, NULL};
    ASSERT_FAILS(ctx, VP_ERR_INVALID_ARGUMENT, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    /* a mixed set with the bounding-box test (margin and gap:
     * test_solid_margin_gap.c) */
    ps[1].shape = (vp_shape_ref){VP_SHAPE_CUBE, 0, NULL};
    rp.overlap = VP_OVERLAP_BBOX;
    rp.orient = VP_ORIENT_FIXED;
    ASSERT_FAILS(ctx, VP_ERR_INVALID_ARGUMENT, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    rp.overlap = VP_OVERLAP_EXACT;
    rp.orient = VP_ORIENT_RANDOM;
    /* more distinct shapes than a set holds */
    for (int i = 0; i <= VP_MAX_SHAPES; i++) {
        ps[i].own_shape = 1;
        ps[i].shape = (vp_shape_ref){VP_SHAPE_SUPERBALL, 1.0 + 0.25 * i, NULL};
    }
    rp.npasses = VP_MAX_SHAPES + 1;
    ASSERT_FAILS(ctx, VP_ERR_INVALID_ARGUMENT, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    ASSERT_TRUE(strstr(vp_context_message(ctx), "shapes") != NULL);
    rp.npasses = VP_MAX_SHAPES; /* exactly as many: packs */
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    ASSERT_EQ_INT(p->shape_count, VP_MAX_SHAPES);
    char list[4096];
    vp_particles_shape_list(p, list, sizeof list);
    static const char head[] = "superball:1;superball:1.25;superball:1.5;";
    ASSERT_TRUE(!strncmp(list, head, sizeof head - 1));
    vp_shape_ref back[VP_MAX_SHAPES];
    unsigned nb = 0;
    ASSERT_EQ_INT(vp_shape_list_parse(list, back, &nb, NULL), 0);
    ASSERT_EQ_INT(nb, VP_MAX_SHAPES);
    for (unsigned k = 0; k < nb; k++) ASSERT_TRUE(back[k].param == p->shapes[k].param);
    vp_particles_destroy(p);
    vp_container_destroy(c);
    vp_context_destroy(ctx);
}

int main(void) {
    RUN_TEST(test_kind_overlap_random_pairs);
    RUN_TEST(test_kind_overlap_superball_octahedron);
    RUN_TEST(test_ternary_pairwise);
    RUN_TEST(test_check_sees_cross_overlap);
    RUN_TEST(test_threads_and_one_shape);
    RUN_TEST(test_refused);
    return 0;
}
