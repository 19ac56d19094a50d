/* SPDX-License-Identifier: Apache-2.0 */
/* Random sequential addition of platonic solids (issue 5): packings with
 * random and fixed orientations have no overlaps (vdbpack's checker and an
 * independent point-sampling test) and stay inside the container (their
 * vertices, computed here), the bounding-box mode behaves as the original
 * design's axis-aligned test, grow ends each solid at a contact, and bad
 * combinations are refused. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <string.h>

#include "core/geom.h"
#include "core/shape.h"
#include "vp_test.h"

static vp_context *ctx;

static vp_container *box(double h) {
    double lo[3] = {-h, -h, -h}, hi[3] = {h, h, h};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, hi, &c));
    return c;
}

static void quat(const vp_particles *p, size_t i, double q[4]) {
    const float *f = p->orients + 4 * i;
    double n = 0;
    for (int k = 0; k < 4; k++) n += (double)f[k] * f[k];
    for (int k = 0; k < 4; k++) q[k] = f[k] / sqrt(n);
}

/* World vertices of particle i. */
static int verts(const vp_particles *p, size_t i, const vp_polyhedron *poly, double w[][3]) {
    double q[4];
    quat(p, i, q);
    for (int k = 0; k < poly->nverts; k++) {
        double v[3];
        for (int m = 0; m < 3; m++) v[m] = poly->verts[k][m] * p->radii[i];
        vp_quat_rotate(q, v, w[k]);
        for (int m = 0; m < 3; m++) w[k][m] += p->positions[3 * i + m];
    }
    return poly->nverts;
}

/* 1 if x is strictly inside particle i (its face planes, computed from the
 * rotated face normals and a vertex of each face). */
static int inside(const vp_particles *p, size_t i, const vp_polyhedron *poly, const double x[3]) {
    double q[4], w[VP_POLY_MAX_VERTS][3];
    quat(p, i, q);
    verts(p, i, poly, w);
    for (int f = 0; f < poly->nfaces; f++) {
        double n[3];
        vp_quat_rotate(q, poly->normals[f], n);
        const double *v = w[poly->faces[f][0]];
        double d[3] = {x[0] - v[0], x[1] - v[1], x[2] - v[2]};
        if (vp_dot3(n, d) >= -1e-9 * p->radii[i]) return 0;
    }
    return 1;
}

/* Independent overlap search: for every pair whose bounding spheres meet,
 * points on a grid over the lens between them, tested against both solids'
 * face planes. Returns the number of pairs with a common point. */
static size_t sampled_overlaps(const vp_particles *p, const vp_polyhedron *poly) {
    size_t bad = 0;
    const int G = 9;
    for (size_t i = 0; i < p->count; i++)
        for (size_t j = i + 1; j < p->count; j++) {
            const double *a = p->positions + 3 * i, *b = p->positions + 3 * j;
            double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            double e = p->radii[i] + p->radii[j], dist = vp_norm3(d);
            if (dist >= e) continue;
            /* grid over the box around the midpoint of the surfaces' reach */
            double m[3], h = 0.5 * (e - dist) +
                             0.25 * (p->radii[i] < p->radii[j] ? p->radii[i] : p->radii[j]);
            double t = (p->radii[i] - 0.5 * (e - dist)) / dist;
            for (int k = 0; k < 3; k++) m[k] = a[k] + t * d[k];
            int found = 0;
            for (int x = 0; x < G && !found; x++)
                for (int y = 0; y < G && !found; y++)
                    for (int z = 0; z < G && !found; z++) {
                        double s[3] = {m[0] + h * (2.0 * x / (G - 1) - 1),
                                       m[1] + h * (2.0 * y / (G - 1) - 1),
                                       m[2] + h * (2.0 * z / (G - 1) - 1)};
                        found = inside(p, i, poly, s) && inside(p, j, poly, s);
                    }
            bad += found;
        }
    return bad;
}

static int pack_retries = 2000;

static vp_particles *pack(vp_container *c, vp_shape shape, vp_orient_mode o, vp_overlap_mode ov,
                          double r, size_t count, int maximal, int grow, uint64_t seed) {
    vp_rsa_pass ps;
    vp_rsa_pass_init(&ps);
    ps.count = count;
    ps.maximal = maximal;
    ps.grow = grow;
    ps.retries = pack_retries;
    vp_size_dist_constant(&ps.radius, r);
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.shape = shape;
    rp.orient = o;
    rp.overlap = ov;
    rp.passes = &ps;
    rp.npasses = 1;
    rp.seed = seed;
    vp_particles *p = NULL;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    return p;
}

static void expect_clean(vp_container *c, const vp_particles *p, double h) {
    vp_check_params cp;
    vp_check_params_init(&cp);
    vp_check_report rep;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &rep));
    ASSERT_EQ_INT(rep.overlapping_pairs, 0);
    ASSERT_EQ_INT(rep.outside, 0);
    const vp_polyhedron *poly = vp_shape_polyhedron(p->shape);
    double worst = -HUGE_VAL;
    for (size_t i = 0; i < p->count; i++) {
        double w[VP_POLY_MAX_VERTS][3];
        int n = verts(p, i, poly, w);
        for (int k = 0; k < n; k++)
            for (int m = 0; m < 3; m++)
                if (fabs(w[k][m]) - h > worst) worst = fabs(w[k][m]) - h;
    }
    ASSERT_LE(worst, 1e-12);
    ASSERT_EQ_INT(sampled_overlaps(p, poly), 0);
}

static void test_random_orientations(void) {
    vp_container *c = box(0.5);
    for (int s = VP_SHAPE_TETRAHEDRON; s < VP_SHAPE_COUNT; s++) {
        vp_particles *p =
            pack(c, (vp_shape)s, VP_ORIENT_RANDOM, VP_OVERLAP_EXACT, 0.07, 300, 0, 0, 3);
        ASSERT_TRUE(p->has_orient && p->orients);
        ASSERT_EQ_INT(p->shape, s);
        ASSERT_GE(p->count, 100);
        /* unit quaternions, and not all alike */
        double spread = 0;
        for (size_t i = 0; i < p->count; i++) {
            double n = 0, dq = 0;
            for (int k = 0; k < 4; k++) {
                n += (double)p->orients[4 * i + k] * p->orients[4 * i + k];
                dq += fabs(p->orients[4 * i + k] - p->orients[k]);
            }
            ASSERT_NEAR(n, 1.0, 1e-6);
            if (dq > spread) spread = dq;
        }
        ASSERT_GE(spread, 0.5);
        expect_clean(c, p, 0.5);
        fprintf(stderr, "   %s: %zu placed, fraction %.4f\n", vp_shape_name((vp_shape)s), p->count,
                vp_particles_volume(p));
        vp_particles_destroy(p);
    }
    vp_container_destroy(c);
}

/* Axis-aligned cubes: the bounding box is the cube, so bbox and exact
 * overlap must give the same packing; for octahedra the boxes are loose:
 * no two boxes overlap, and the exact test fits more. */
static void test_bbox_mode(void) {
    vp_container *c = box(0.5);
    vp_particles *a = pack(c, VP_SHAPE_CUBE, VP_ORIENT_FIXED, VP_OVERLAP_BBOX, 0.05, 0, 1, 0, 5);
    vp_particles *b = pack(c, VP_SHAPE_CUBE, VP_ORIENT_FIXED, VP_OVERLAP_EXACT, 0.05, 0, 1, 0, 5);
    ASSERT_EQ_INT(a->count, b->count);
    ASSERT_TRUE(memcmp(a->positions, b->positions, 3 * a->count * sizeof(double)) == 0);
    expect_clean(c, a, 0.5);
    for (size_t i = 0; i < a->count; i++)
        ASSERT_TRUE(a->orients[4 * i + 3] == 1.0f && a->orients[4 * i] == 0.0f);
    fprintf(stderr, "   axis-aligned cubes: bbox %zu = exact %zu\n", a->count, b->count);
    vp_particles_destroy(a);
    vp_particles_destroy(b);
    const vp_polyhedron *oct = vp_shape_polyhedron(VP_SHAPE_OCTAHEDRON);
    double lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = HUGE_VAL, hi[k] = -HUGE_VAL;
        for (int v = 0; v < oct->nverts; v++) {
            if (oct->verts[v][k] < lo[k]) lo[k] = oct->verts[v][k];
            if (oct->verts[v][k] > hi[k]) hi[k] = oct->verts[v][k];
        }
    }
    a = pack(c, VP_SHAPE_OCTAHEDRON, VP_ORIENT_FIXED, VP_OVERLAP_BBOX, 0.06, 0, 1, 0, 7);
    b = pack(c, VP_SHAPE_OCTAHEDRON, VP_ORIENT_FIXED, VP_OVERLAP_EXACT, 0.06, 0, 1, 0, 7);
    for (size_t i = 0; i < a->count; i++)
        for (size_t j = i + 1; j < a->count; j++) {
            int apart = 0;
            const double *x = a->positions + 3 * i, *y = a->positions + 3 * j;
            double ri = a->radii[i], rj = a->radii[j];
            for (int k = 0; k < 3; k++)
                apart |= x[k] + ri * hi[k] <= y[k] + rj * lo[k] ||
                         y[k] + rj * hi[k] <= x[k] + ri * lo[k];
            ASSERT_TRUE(apart);
        }
    expect_clean(c, b, 0.5);
    fprintf(stderr, "   fixed octahedra: bbox %zu, exact %zu\n", a->count, b->count);
    ASSERT_GE((double)b->count, 1.5 * (double)a->count);
    vp_particles_destroy(a);
    vp_particles_destroy(b);
    vp_container_destroy(c);
}

/* Grow: each solid ends touching: 0.1 % larger, it would overlap a
 * neighbour or cross the wall (checked pair by pair here). */
static void test_grow(void) {
    vp_container *c = box(0.5);
    vp_particles *p =
        pack(c, VP_SHAPE_ICOSAHEDRON, VP_ORIENT_RANDOM, VP_OVERLAP_EXACT, 0.05, 150, 0, 1, 9);
    ASSERT_EQ_INT(p->count, 150);
    expect_clean(c, p, 0.5);
    const vp_polyhedron *poly = vp_shape_polyhedron(VP_SHAPE_ICOSAHEDRON);
    double grown = 0;
    for (size_t i = 0; i < p->count; i++) {
        double qi[4], big = p->radii[i] * 1.001;
        quat(p, i, qi);
        int blocked = vp_poly_wall_distance(c, poly, big, qi, p->positions + 3 * i, HUGE_VAL) > 0;
        for (size_t j = 0; j < p->count && !blocked; j++) {
            if (j == i) continue;
            double qj[4];
            quat(p, j, qj);
            blocked = vp_poly_separation(poly, big, qi, p->positions + 3 * i, poly, p->radii[j], qj,
                                         p->positions + 3 * j) < 0;
        }
        ASSERT_TRUE(blocked);
        grown += p->radii[i] / 0.05;
    }
    fprintf(stderr, "   grown icosahedra: mean radius ratio %.3f\n", grown / p->count);
    ASSERT_GE(grown / p->count, 1.05);
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

static void test_bad(void) {
    vp_container *c = box(0.5);
    vp_rsa_pass ps;
    vp_rsa_pass_init(&ps);
    ps.count = 10;
    vp_size_dist_constant(&ps.radius, 0.05);
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.shape = VP_SHAPE_CUBE;
    rp.overlap = VP_OVERLAP_BBOX; /* with the default random orientation */
    rp.passes = &ps;
    rp.npasses = 1;
    vp_particles *p = (vp_particles *)1;
    ASSERT_EQ_INT(vp_pack_rsa(ctx, c, &rp, &p, NULL), VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(p == NULL);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "fixed orientations") != NULL);
    rp.overlap = VP_OVERLAP_EXACT;
    rp.shape = (vp_shape)42;
    ASSERT_EQ_INT(vp_pack_rsa(ctx, c, &rp, &p, NULL), VP_ERR_INVALID_ARGUMENT);
    vp_container_destroy(c);
}

/* A dense count pass of random cubes (20 000 asked for, radius 0.02 in a
 * unit box, 5000 retries: near the end its split to finer cells would be
 * far over the cell budget, and is given up after the first round) gives
 * the same particles, bit for bit, with 1 and 2 threads, and is clean. */
static void test_dense_threads(void) {
    vp_container *c = box(0.5);
    vp_particles *p[2];
    pack_retries = 5000;
    for (int t = 0; t < 2; t++) {
        vp_context_set_threads(ctx, t + 1);
        p[t] = pack(c, VP_SHAPE_CUBE, VP_ORIENT_RANDOM, VP_OVERLAP_EXACT, 0.02, 20000, 0, 0, 1);
    }
    vp_context_set_threads(ctx, 0);
    pack_retries = 2000;
    fprintf(stderr, "   %zu cubes\n", p[0]->count);
    ASSERT_TRUE(p[0]->count > 18000);
    ASSERT_EQ_INT(p[0]->count, p[1]->count);
    ASSERT_TRUE(memcmp(p[0]->positions, p[1]->positions, 3 * p[0]->count * sizeof(double)) == 0);
    ASSERT_TRUE(memcmp(p[0]->radii, p[1]->radii, p[0]->count * sizeof(float)) == 0);
    ASSERT_TRUE(memcmp(p[0]->orients, p[1]->orients, 4 * p[0]->count * sizeof(float)) == 0);
    expect_clean(c, p[0], 0.5);
    vp_particles_destroy(p[0]);
    vp_particles_destroy(p[1]);
    vp_container_destroy(c);
}

/* A pass of one radius pre-tests every dart in parallel (the exact tests
 * against the particles before its batch run while the darts are made),
 * also when the radius is not a float (0.07): the radius drawn is the
 * float nearest it, the same for every particle. A size distribution
 * cannot (each radius is drawn in the serial loop). */
static void test_pretest(void) {
    vp_container *c = box(0.5);
    const double radii[3] = {0.07, 0.0625, -1.0}; /* -1: uniform 0.06..0.07 */
    for (int k = 0; k < 3; k++) {
        vp_rsa_pass ps;
        vp_rsa_pass_init(&ps);
        ps.count = 200;
        ps.retries = 2000;
        if (radii[k] > 0) vp_size_dist_constant(&ps.radius, radii[k]);
        else ASSERT_OK(ctx, vp_size_dist_parse(ctx, "uniform:0.06:0.07", &ps.radius));
        vp_rsa_params rp;
        vp_rsa_params_init(&rp);
        rp.shape = VP_SHAPE_CUBE;
        rp.passes = &ps;
        rp.npasses = 1;
        rp.seed = 5;
        vp_particles *p = NULL;
        vp_rsa_report rep;
        ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
        fprintf(stderr, "   radius %g: %zu placed, %llu tries, %llu pre-tested\n", radii[k],
                p->count, (unsigned long long)rep.passes[0].tries,
                (unsigned long long)rep.passes[0].pretested);
        ASSERT_GE(rep.passes[0].tries, 200);
        if (radii[k] > 0) ASSERT_TRUE(rep.passes[0].pretested == rep.passes[0].tries);
        else ASSERT_TRUE(rep.passes[0].pretested == 0);
        expect_clean(c, p, 0.5);
        vp_particles_destroy(p);
    }
    vp_container_destroy(c);
}

int main(void) {
    ASSERT_OK(NULL, vp_context_create(&ctx));
    RUN_TEST(test_random_orientations);
    RUN_TEST(test_bbox_mode);
    RUN_TEST(test_grow);
    RUN_TEST(test_bad);
    RUN_TEST(test_dense_threads);
    RUN_TEST(test_pretest);
    vp_context_destroy(ctx);
    return 0;
}
