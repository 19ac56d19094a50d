/* SPDX-License-Identifier: Apache-2.0 */
/* rsa's margin and gap for solids (issue 31, section 4): cubes, grown
 * until they touch, keep the margin from the box's wall (every corner, by
 * this file's arithmetic) and the gap between each other (the exact
 * distance of two boxes written here: corners against the other box,
 * edges against edges), with pairs at the gap (the test sees contacts);
 * vdbpack check holds them to both and flags a larger gap or margin; mixed
 * sets keep the gap between kinds; mesh shapes refuse a gap. */
#include "vdbpack/vdbpack.h"
#include "vp_test.h"

#include <math.h>
#include <string.h>

typedef struct box {
    double c[3], ax[3][3], h; /* centre, unit axes (rows), half side */
} box;

static void make_box(const vp_particles *p, size_t i, box *b) {
    const float *f = p->orients + 4 * i;
    double x = f[0], y = f[1], z = f[2], w = f[3], n = sqrt(x * x + y * y + z * z + w * w);
    x /= n, y /= n, z /= n, w /= n;
    double m[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
                      {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
                      {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < 3; k++) b->ax[a][k] = m[k][a];
    memcpy(b->c, p->positions + 3 * i, sizeof b->c);
    b->h = p->radii[i] / sqrt(3.0);
}

static void corner(const box *b, int v, double out[3]) {
    for (int k = 0; k < 3; k++) {
        out[k] = b->c[k];
        for (int a = 0; a < 3; a++) out[k] += (v >> a & 1 ? b->h : -b->h) * b->ax[a][k];
    }
}

static double point_box(const double p[3], const box *b) {
    double e2 = 0;
    for (int a = 0; a < 3; a++) {
        double l = 0;
        for (int k = 0; k < 3; k++) l += (p[k] - b->c[k]) * b->ax[a][k];
        double o = fabs(l) - b->h;
        if (o > 0) e2 += o * o;
    }
    return sqrt(e2);
}

static double seg_seg(const double p1[3], const double q1[3], const double p2[3],
                      const double q2[3]) {
    double d1[3], d2[3], r[3];
    for (int k = 0; k < 3; k++) d1[k] = q1[k] - p1[k], d2[k] = q2[k] - p2[k], r[k] = p1[k] - p2[k];
    double a = 0, e = 0, f = 0, b = 0, c = 0;
    for (int k = 0; k < 3; k++)
        a += d1[k] * d1[k], e += d2[k] * d2[k], f += d2[k] * r[k], b += d1[k] * d2[k],
            c += d1[k] * r[k];
    double den = a * e - b * b, s = den > 1e-300 ? (b * f - c * e) / den : 0.0, t;
    s = s < 0 ? 0 : s > 1 ? 1 : s;
    t = (b * s + f) / e;
    if (t < 0) t = 0, s = -c / a;
    else if (t > 1) t = 1, s = (b - c) / a;
    s = s < 0 ? 0 : s > 1 ? 1 : s;
    double d = 0;
    for (int k = 0; k < 3; k++) {
        double x = p1[k] + d1[k] * s - p2[k] - d2[k] * t;
        d += x * x;
    }
    return sqrt(d);
}

/* Euclidean distance of two disjoint boxes (0 if they meet): the closest
 * points are a corner and the other box, or two edges. */
static double box_box_distance(const box *A, const box *B) {
    double best = HUGE_VAL, p[3], q[3];
    for (int v = 0; v < 8; v++) {
        corner(A, v, p);
        best = fmin(best, point_box(p, B));
        corner(B, v, p);
        best = fmin(best, point_box(p, A));
    }
    double a0[3], a1[3], b0[3], b1[3];
    for (int v = 0; v < 8; v++)
        for (int ax = 0; ax < 3; ax++) {
            if (v >> ax & 1) continue; /* each edge once: from its lower corner */
            corner(A, v, a0);
            corner(A, v | 1 << ax, a1);
            for (int u = 0; u < 8; u++)
                for (int bx = 0; bx < 3; bx++) {
                    if (u >> bx & 1) continue;
                    corner(B, u, b0);
                    corner(B, u | 1 << bx, b1);
                    best = fmin(best, seg_seg(a0, a1, b0, b1));
                }
        }
    (void)q;
    return best;
}

static void test_cubes_keep_margin_and_gap(void) {
    vp_context *ctx;
    ASSERT_OK(ctx, vp_context_create(&ctx));
    vp_container *c;
    ASSERT_OK(ctx, vp_container_create_box(ctx, (double[3]){-0.5, -0.5, -0.5},
                                           (double[3]){0.5, 0.5, 0.5}, &c));
    const double M = 0.04, G = 0.015;
    vp_rsa_pass ps;
    vp_rsa_pass_init(&ps);
    ps.maximal = 1;
    ps.retries = 1500;
    ps.grow = 1;
    vp_size_dist_constant(&ps.radius, 0.07);
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.shape = VP_SHAPE_CUBE;
    rp.passes = &ps;
    rp.npasses = 1;
    rp.seed = 3;
    rp.margin = M;
    rp.gap = G;
    vp_particles *p;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    ASSERT_GE(p->count, 150);
    double least_wall = HUGE_VAL, least_gap = HUGE_VAL;
    size_t at_gap = 0, near = 0;
    for (size_t i = 0; i < p->count; i++) {
        box A;
        make_box(p, i, &A);
        for (int v = 0; v < 8; v++) {
            double x[3];
            corner(&A, v, x);
            for (int k = 0; k < 3; k++) least_wall = fmin(least_wall, 0.5 - fabs(x[k]));
        }
        for (size_t j = i + 1; j < p->count; j++) {
            double d2 = 0;
            for (int k = 0; k < 3; k++) {
                double t = p->positions[3 * i + k] - p->positions[3 * j + k];
                d2 += t * t;
            }
            double reach = p->radii[i] + p->radii[j] + 2 * G;
            if (d2 >= reach * reach) continue;
            box B;
            make_box(p, j, &B);
            double d = box_box_distance(&A, &B);
            near++;
            least_gap = fmin(least_gap, d);
            if (d < G * (1 + 1e-3)) at_gap++;
        }
    }
    fprintf(stderr,
            "   %zu cubes: least wall distance %.9f (margin %g), least distance %.9f "
            "(gap %g), %zu of %zu near pairs within 1e-3 of the gap\n",
            p->count, least_wall, M, least_gap, G, at_gap, near);
    ASSERT_GE(least_wall, M - 1e-9);
    ASSERT_GE(least_gap, G - 1e-9);
    ASSERT_GE(at_gap, 20); /* grown to the gap: contacts at G exist */
    /* check holds them to both, and flags a larger gap or margin */
    vp_check_params cp;
    vp_check_params_init(&cp);
    cp.margin = M;
    cp.gap = G;
    vp_check_report cr;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &cr));
    ASSERT_EQ_INT(cr.overlapping_pairs, 0);
    ASSERT_EQ_INT(cr.outside, 0);
    ASSERT_GE(cr.contact_pairs, at_gap);
    cp.gap = 1.5 * G;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &cr));
    ASSERT_GE(cr.overlapping_pairs, at_gap);
    cp.gap = G;
    cp.margin = 1.5 * M;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &cr));
    ASSERT_GE(cr.outside, 1);
    vp_particles_destroy(p);
    vp_container_destroy(c);
    vp_context_destroy(ctx);
}

static void test_mixed_gap_and_mesh_refused(void) {
    vp_context *ctx;
    ASSERT_OK(ctx, vp_context_create(&ctx));
    vp_container *c;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, (double[3]){0, 0, 0}, 0.5, &c));
    vp_rsa_pass ps[2];
    for (int i = 0; i < 2; i++) {
        vp_rsa_pass_init(&ps[i]);
        ps[i].maximal = 1;
        ps[i].retries = 1000;
        ps[i].grow = 1;
    }
    vp_size_dist_constant(&ps[0].radius, 0.08);
    ps[0].own_shape = 1;
    ps[0].shape = (vp_shape_ref){VP_SHAPE_OCTAHEDRON, 0, NULL};
    vp_size_dist_constant(&ps[1].radius, 0.03); /* spheres */
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.passes = ps;
    rp.npasses = 2;
    rp.seed = 9;
    rp.gap = 0.01;
    rp.margin = 0.02;
    vp_particles *p;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    ASSERT_EQ_INT(p->shape, VP_SHAPE_MIXED);
    /* spheres against spheres and the wall, by distance */
    double least = HUGE_VAL, wall = HUGE_VAL;
    for (size_t i = 0; i < p->count; i++) {
        if (p->shape_index[i] != 1) continue;
        const double *x = p->positions + 3 * i;
        wall = fmin(wall, 0.5 - sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - p->radii[i]);
        for (size_t j = i + 1; j < p->count; j++) {
            if (p->shape_index[j] != 1) continue;
            const double *y = p->positions + 3 * j;
            double d = sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                            (x[2] - y[2]) * (x[2] - y[2]));
            least = fmin(least, d - p->radii[i] - p->radii[j]);
        }
    }
    ASSERT_GE(least, 0.01 - 1e-7);
    ASSERT_GE(wall, 0.02 - 1e-7);
    vp_check_params cp;
    vp_check_params_init(&cp);
    cp.margin = 0.02;
    cp.gap = 0.01;
    vp_check_report cr;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &cr));
    ASSERT_EQ_INT(cr.overlapping_pairs, 0);
    ASSERT_EQ_INT(cr.outside, 0);
    ASSERT_GE(cr.contact_pairs, 10);
    cp.gap = 0.02;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &cr));
    ASSERT_GE(cr.overlapping_pairs, 10);
    vp_particles_destroy(p);
    /* a mesh shape with a gap: refused, one line */
    static const double v[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                   {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
    static const uint32_t t[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},
                                      {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},
                                      {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    vp_mesh_shape *m;
    ASSERT_OK(ctx, vp_mesh_shape_from_mesh(ctx, "box.obj", &v[0][0], 8, &t[0][0], 12, &m));
    rp.npasses = 1;
    ps[0].shape = (vp_shape_ref){VP_SHAPE_MESH, 0, m};
    p = (vp_particles *)1;
    ASSERT_FAILS(ctx, VP_ERR_INVALID_ARGUMENT, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    ASSERT_TRUE(p == NULL && strstr(vp_context_message(ctx), "mesh") != NULL);
    rp.gap = 0; /* the margin alone is kept by mesh shapes */
    ps[0].maximal = 0;
    ps[0].count = 40;
    ps[0].grow = 0;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    vp_check_params_init(&cp);
    cp.margin = 0.02;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &cr));
    ASSERT_EQ_INT(cr.outside, 0);
    cp.margin = 0.2;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &cr));
    ASSERT_GE(cr.outside, 1);
    vp_particles_destroy(p);
    vp_mesh_shape_destroy(m);
    vp_container_destroy(c);
    vp_context_destroy(ctx);
}

int main(void) {
    RUN_TEST(test_cubes_keep_margin_and_gap);
    RUN_TEST(test_mixed_gap_and_mesh_refused);
    return 0;
}
