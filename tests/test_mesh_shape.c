/* SPDX-License-Identifier: Apache-2.0 */
/* Mesh-shaped particles (issue 5): the exact overlap test of two placed
 * meshes against references that share no code with it (the platonic
 * cube's separating-axis test for a cube mesh; dense point sampling with an
 * analytic inside test for a concave L-shaped prism), touching, edge-edge
 * and containment cases, normalisation, load errors, and RSA packings of a
 * concave shape checked pair by pair by sampling. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/geom.h"
#include "core/mesh_shape.h"
#include "core/rng.h"
#include "core/shape.h"
#include "vp_test.h"

static vp_context *ctx;

static vp_mesh_shape *from_arrays(const double *v, size_t nv, const uint32_t *t, size_t nt) {
    double *vv = malloc(3 * nv * sizeof *vv);
    uint32_t *tt = malloc(3 * nt * sizeof *tt);
    memcpy(vv, v, 3 * nv * sizeof *vv);
    memcpy(tt, t, 3 * nt * sizeof *tt);
    vp_mesh_shape *s = NULL;
    ASSERT_OK(ctx, vp_mesh_shape_create(ctx, "test", vv, nv, tt, nt, &s));
    return s;
}

/* A box [0,a]x[0,b]x[0,c] (off-centre on purpose: the loader centres it). */
static vp_mesh_shape *box_mesh(double a, double b, double c) {
    double v[8][3];
    for (int i = 0; i < 8; i++) {
        v[i][0] = (i & 1) ? a : 0;
        v[i][1] = (i & 2) ? b : 0;
        v[i][2] = (i & 4) ? c : 0;
    }
    static const uint32_t t[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6},
                                      {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},
                                      {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    return from_arrays(&v[0][0], 8, &t[0][0], 12);
}

static void rand_quat(uint64_t *st, double q[4]) { vp_rng_quat(st, q); }

/* A cube mesh overlaps exactly where the platonic cube's separating-axis
 * test says so (same unit shape: circumradius 1, faces along the axes). */
static void test_cube_mesh_matches_sat(void) {
    vp_mesh_shape *m = box_mesh(2, 2, 2);
    const vp_polyhedron *cube = vp_shape_polyhedron(VP_SHAPE_CUBE);
    ASSERT_NEAR(vp_mesh_shape_volume(m), cube->volume, 1e-12);
    ASSERT_NEAR(vp_mesh_shape_inradius(m), cube->inradius, 1e-12);
    uint64_t st = 12345;
    int agree = 0, over = 0, near = 0;
    for (int n = 0; n < 4000; n++) {
        double qa[4], qb[4], ta[3] = {0, 0, 0}, tb[3], dir[3];
        rand_quat(&st, qa);
        rand_quat(&st, qb);
        double sa = 0.5 + vp_rng_uniform(&st), sb = 0.5 + vp_rng_uniform(&st);
        double z = 2 * vp_rng_uniform(&st) - 1, ph = 6.283185307179586 * vp_rng_uniform(&st);
        dir[0] = sqrt(1 - z * z) * cos(ph);
        dir[1] = sqrt(1 - z * z) * sin(ph);
        dir[2] = z;
        double d = (sa + sb) * (0.3 + 0.8 * vp_rng_uniform(&st));
        for (int k = 0; k < 3; k++) tb[k] = d * dir[k];
        double sep = vp_poly_separation(cube, sa, qa, ta, cube, sb, qb, tb);
        if (fabs(sep) < 1e-9) continue; /* rounding decides touching pairs */
        int ref = sep < 0;
        double depth;
        int got = vp_mesh_shape_overlap(m, sa, qa, ta, sb, qb, tb, &depth);
        ASSERT_EQ_INT(got, ref);
        ASSERT_EQ_INT(vp_mesh_shape_overlap(m, sa, qa, ta, sb, qb, tb, NULL), ref);
        if (got) ASSERT_TRUE(depth > 0);
        agree++;
        over += ref;
        near += fabs(sep) < 0.02 * (sa + sb);
    }
    fprintf(stderr, "   %d pairs agree with the SAT (%d overlapping, %d within 1%% of contact)\n",
            agree, over, near);
    ASSERT_TRUE(over > 500 && agree - over > 500 && near > 50);
    vp_mesh_shape_destroy(m);
}

/* Face to face, edge to edge and vertex to face contacts are not overlaps;
 * pushed together by 1e-6 they are. */
static void test_touching(void) {
    vp_mesh_shape *m = box_mesh(1, 1, 1);
    double h = 1.0 / sqrt(3.0); /* half edge at circumradius 1 */
    double qi[4] = {0, 0, 0, 1}, o[3] = {0, 0, 0};
    double face[3] = {2 * h, 0, 0}, edge[3] = {2 * h, 2 * h, 0}, in[3] = {2 * h - 1e-6, 0, 0};
    double depth;
    ASSERT_EQ_INT(vp_mesh_shape_overlap(m, 1, qi, o, 1, qi, face, &depth), 0);
    ASSERT_EQ_INT(vp_mesh_shape_overlap(m, 1, qi, o, 1, qi, edge, NULL), 0);
    ASSERT_EQ_INT(vp_mesh_shape_overlap(m, 1, qi, o, 1, qi, in, &depth), 1);
    ASSERT_NEAR(depth, 1e-6, 1e-9);
    /* a vertex of a cube turned 45 degrees about z and x touching a face */
    double q45[4] = {0, 0, sin(M_PI / 8), cos(M_PI / 8)};
    double c45 = h * sqrt(2.0); /* its reach along x */
    double vf[3] = {h + c45 + 1e-9, 0, 0}, vf2[3] = {h + c45 - 1e-6, 0, 0};
    ASSERT_EQ_INT(vp_mesh_shape_overlap(m, 1, qi, o, 1, q45, vf, NULL), 0);
    ASSERT_EQ_INT(vp_mesh_shape_overlap(m, 1, qi, o, 1, q45, vf2, NULL), 1);
    vp_mesh_shape_destroy(m);
}

/* Two rods crossing like an X: no vertex of either is inside the other,
 * only their faces cross. And a small copy wholly inside a large one: no
 * faces cross, the containment test decides. */
static void test_edge_crossing_and_containment(void) {
    vp_mesh_shape *rod = box_mesh(10, 1, 1);
    double qi[4] = {0, 0, 0, 1}, qz[4] = {0, 0, sin(M_PI / 4), cos(M_PI / 4)};
    double o[3] = {0, 0, 0}, up[3] = {0, 0, 0.05}, far[3] = {0, 0, 0.25};
    /* the rods are 0.0995 thick at circumradius 1: 0.05 apart they cross */
    ASSERT_EQ_INT(vp_mesh_shape_overlap(rod, 1, qi, o, 1, qz, up, NULL), 1);
    ASSERT_EQ_INT(vp_mesh_shape_overlap(rod, 1, qi, o, 1, qz, far, NULL), 0);
    vp_mesh_shape *cube = box_mesh(1, 1, 1);
    double depth;
    ASSERT_EQ_INT(vp_mesh_shape_overlap(cube, 1, qi, o, 0.1, qz, up, &depth), 1);
    ASSERT_TRUE(depth > 0);
    ASSERT_EQ_INT(vp_mesh_shape_overlap(cube, 0.1, qz, up, 1, qi, o, NULL), 1);
    vp_mesh_shape_destroy(rod);
    vp_mesh_shape_destroy(cube);
}

/* --- a concave shape with an analytic inside test ------------------------- */

/* L-shaped prism: the polygon (0,0) (2,0) (2,1) (1,1) (1,2) (0,2), z in [0,1]. */
static const double L_poly[6][2] = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};

static vp_mesh_shape *l_prism(void) {
    double v[12][3];
    for (int i = 0; i < 6; i++) {
        v[i][0] = v[i + 6][0] = L_poly[i][0];
        v[i][1] = v[i + 6][1] = L_poly[i][1];
        v[i][2] = 0;
        v[i + 6][2] = 1;
    }
    uint32_t t[20][3];
    int n = 0;
    /* bottom (seen from below: clockwise in xy) and top, as fans from the
     * reflex-free corner 0: (0,1,2) (0,2,3) (0,3,4) (0,4,5) cover the L */
    for (int i = 1; i < 5; i++) {
        t[n][0] = 0, t[n][1] = (uint32_t)i + 1, t[n][2] = (uint32_t)i, n++;
        t[n][0] = 6, t[n][1] = (uint32_t)i + 6, t[n][2] = (uint32_t)i + 7, n++;
    }
    for (uint32_t i = 0; i < 6; i++) {
        uint32_t j = (i + 1) % 6;
        t[n][0] = i, t[n][1] = j, t[n][2] = j + 6, n++;
        t[n][0] = i, t[n][1] = j + 6, t[n][2] = i + 6, n++;
    }
    return from_arrays(&v[0][0], 12, &t[0][0], 20);
}

/* The L's centroid and bounding radius, from its two rectangles. */
static void l_frame(double c[3], double *rmax) {
    /* areas 2 ([0,2]x[0,1]) and 1 ([0,1]x[1,2]) */
    c[0] = (2 * 1.0 + 1 * 0.5) / 3.0;
    c[1] = (2 * 0.5 + 1 * 1.5) / 3.0;
    c[2] = 0.5;
    double r = 0;
    for (int i = 0; i < 6; i++)
        for (int z = 0; z < 2; z++) {
            double d[3] = {L_poly[i][0] - c[0], L_poly[i][1] - c[1], z - c[2]};
            r = fmax(r, vp_norm3(d));
        }
    *rmax = r;
}

/* Strictly inside the L (unit shape coordinates), with a margin eps. */
static int l_inside(const double p[3], double eps) {
    double c[3], r;
    l_frame(c, &r);
    double x = p[0] * r + c[0], y = p[1] * r + c[1], z = p[2] * r + c[2];
    if (!(z > eps && z < 1 - eps)) return 0;
    int a = x > eps && x < 2 - eps && y > eps && y < 1 - eps;
    int b = x > eps && x < 1 - eps && y > eps && y < 2 - eps;
    return a || b;
}

/* Point of A's unit frame -> B's unit frame. */
static void a_to_b(const double p[3], double sa, const double qa[4], const double ta[3], double sb,
                   const double qb[4], const double tb[3], double out[3]) {
    double w[3], v[3], qbi[4] = {-qb[0], -qb[1], -qb[2], qb[3]};
    for (int k = 0; k < 3; k++) v[k] = p[k] * sa;
    vp_quat_rotate(qa, v, w);
    for (int k = 0; k < 3; k++) w[k] += ta[k] - tb[k];
    vp_quat_rotate(qbi, w, v);
    for (int k = 0; k < 3; k++) out[k] = v[k] / sb;
}

/* Reference: a grid of points inside A (spacing g, unit frame) that are
 * also inside B, both by the analytic test with margin eps. */
static int sampled_overlap(double sa, const double qa[4], const double ta[3], double sb,
                           const double qb[4], const double tb[3], double g, double eps) {
    for (double x = -1; x <= 1; x += g)
        for (double y = -1; y <= 1; y += g)
            for (double z = -1; z <= 1; z += g) {
                double p[3] = {x, y, z}, pb[3];
                if (!l_inside(p, eps)) continue;
                a_to_b(p, sa, qa, ta, sb, qb, tb, pb);
                if (l_inside(pb, eps)) return 1;
            }
    return 0;
}

static void test_concave_against_sampling(void) {
    vp_mesh_shape *m = l_prism();
    double c[3], r;
    l_frame(c, &r);
    ASSERT_NEAR(vp_mesh_shape_volume(m), 3.0 / (r * r * r), 1e-12);
    /* its normalised vertices: bounding radius 1 */
    double vmax = 0;
    for (size_t v = 0; v < m->nverts; v++) vmax = fmax(vmax, vp_norm3(m->verts + 3 * v));
    ASSERT_NEAR(vmax, 1.0, 1e-12);
    /* the centroid (1.1667, 0.8333) lies in the L: a positive inradius */
    ASSERT_TRUE(vp_mesh_shape_inradius(m) > 0.1);
    uint64_t st = 777;
    int over = 0, apart = 0, thin = 0;
    for (int n = 0; n < 400; n++) {
        double qa[4], qb[4], ta[3] = {0, 0, 0}, tb[3];
        rand_quat(&st, qa);
        rand_quat(&st, qb);
        for (int k = 0; k < 3; k++) tb[k] = 1.6 * (2 * vp_rng_uniform(&st) - 1);
        if (vp_norm3(tb) > 2.0) continue;
        double depth;
        int got = vp_mesh_shape_overlap(m, 1, qa, ta, 1, qb, tb, &depth);
        int ref = sampled_overlap(1, qa, ta, 1, qb, tb, 0.02, 1e-9);
        /* sampling finds common points: the exact test must overlap */
        if (ref) ASSERT_EQ_INT(got, 1);
        /* the exact test overlaps but the grid saw no common point: only
         * for a thin overlap, shallower than the grid spacing */
        if (got && !ref) {
            ASSERT_LE(depth, 0.02 * 2);
            thin++;
        }
        over += got;
        apart += !got;
    }
    fprintf(stderr, "   %d overlapping, %d apart (%d thinner than the sampling grid)\n", over,
            apart, thin);
    ASSERT_TRUE(over > 50 && apart > 50);
    vp_mesh_shape_destroy(m);
}

/* RSA of L prisms in a box: zero overlaps by vdbpack's checker and by the
 * sampling reference pair by pair; every vertex inside the box. */
static void test_rsa_l_prisms(void) {
    vp_mesh_shape *m = l_prism();
    double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, hi, &c));
    vp_rsa_pass pass;
    vp_rsa_pass_init(&pass);
    pass.count = 400;
    pass.radius.kind = VP_SIZE_CONSTANT;
    pass.radius.a = 0.2;
    pass.retries = 3000;
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.shape = VP_SHAPE_MESH;
    rp.mesh = m;
    rp.passes = &pass;
    rp.npasses = 1;
    rp.seed = 5;
    vp_particles *p = NULL;
    vp_rsa_report rep;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
    fprintf(stderr, "   placed %zu L prisms (%llu tries)\n", p->count,
            (unsigned long long)rep.passes[0].tries);
    ASSERT_TRUE(p->count > 100);
    ASSERT_TRUE(p->shape == VP_SHAPE_MESH && p->mesh == m && p->orients);
    vp_check_report cr;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, NULL, &cr));
    ASSERT_EQ_INT(cr.overlapping_pairs, 0);
    ASSERT_EQ_INT(cr.outside, 0);
    size_t pairs = 0;
    for (size_t i = 0; i < p->count; i++) {
        double qi[4];
        vp_quat_from_float(p->orients + 4 * i, qi);
        for (size_t v = 0; v < m->nverts; v++) {
            double w[3], u[3];
            for (int k = 0; k < 3; k++) u[k] = m->verts[3 * v + k] * p->radii[i];
            vp_quat_rotate(qi, u, w);
            for (int k = 0; k < 3; k++) ASSERT_LE(fabs(w[k] + p->positions[3 * i + k]), 1.0);
        }
        for (size_t j = i + 1; j < p->count; j++) {
            const double *a = p->positions + 3 * i, *b = p->positions + 3 * j;
            double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
            if (vp_norm3(d) >= p->radii[i] + p->radii[j]) continue;
            double qj[4];
            vp_quat_from_float(p->orients + 4 * j, qj);
            pairs++;
            ASSERT_EQ_INT(sampled_overlap(p->radii[i], qi, a, p->radii[j], qj, b, 0.04, 1e-7), 0);
        }
    }
    fprintf(stderr, "   %zu pairs with overlapping bounding spheres, none share a point\n", pairs);
    ASSERT_TRUE(pairs > 50);
    /* a corrupted copy (one particle moved onto another) is caught */
    memcpy(p->positions + 3, p->positions, 3 * sizeof *p->positions);
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, NULL, &cr));
    ASSERT_TRUE(cr.overlapping_pairs >= 1);
    vp_particles_destroy(p);
    vp_container_destroy(c);
    vp_mesh_shape_destroy(m);
}

static void write_file(const char *path, const char *text) {
    FILE *f = fopen(path, "w");
    ASSERT_TRUE(f != NULL);
    fputs(text, f);
    fclose(f);
}

static void test_load_errors(void) {
    char dir[] = "/tmp/vp_mesh_shape_XXXXXX";
    ASSERT_TRUE(mkdtemp(dir) != NULL);
    char open_obj[256], flat_obj[256], ok_obj[256];
    snprintf(open_obj, sizeof open_obj, "%s/open.obj", dir);
    snprintf(flat_obj, sizeof flat_obj, "%s/flat.obj", dir);
    snprintf(ok_obj, sizeof ok_obj, "%s/tet.obj", dir);
    /* a tetrahedron without one face: 3 boundary edges */
    write_file(open_obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n");
    /* a closed tetrahedron whose four vertices lie in one plane */
    write_file(flat_obj,
               "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    write_file(ok_obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    vp_mesh_shape *s = NULL;
    ASSERT_EQ_INT(vp_mesh_shape_load(ctx, open_obj, &s), VP_ERR_OPEN_MESH);
    ASSERT_TRUE(s == NULL && strstr(vp_context_message(ctx), "3 boundary edges"));
    ASSERT_EQ_INT(vp_mesh_shape_load(ctx, flat_obj, &s), VP_ERR_FORMAT);
    ASSERT_TRUE(s == NULL && strstr(vp_context_message(ctx), "no volume"));
    char missing[300];
    snprintf(missing, sizeof missing, "%s/none.obj", dir);
    ASSERT_EQ_INT(vp_mesh_shape_load(ctx, missing, &s), VP_ERR_IO);
    ASSERT_TRUE(s == NULL);
    ASSERT_OK(ctx, vp_mesh_shape_load(ctx, ok_obj, &s));
    ASSERT_TRUE(strcmp(vp_mesh_shape_name(s), "tet.obj") == 0);
    /* a corner tetrahedron of volume 1/6: normalised about its centroid */
    double c[3] = {0.25, 0.25, 0.25}, far[3] = {0.75, -0.25, -0.25};
    double r = vp_norm3(far);
    (void)c;
    ASSERT_NEAR(vp_mesh_shape_volume(s), (1.0 / 6.0) / (r * r * r), 1e-12);
    vp_mesh_shape_destroy(s);
    unlink(open_obj);
    unlink(flat_obj);
    unlink(ok_obj);
    rmdir(dir);
}

int main(void) {
    ASSERT_OK(NULL, vp_context_create(&ctx));
    RUN_TEST(test_cube_mesh_matches_sat);
    RUN_TEST(test_touching);
    RUN_TEST(test_edge_crossing_and_containment);
    RUN_TEST(test_concave_against_sampling);
    RUN_TEST(test_rsa_l_prisms);
    RUN_TEST(test_load_errors);
    vp_context_destroy(ctx);
    fprintf(stderr, "all mesh shape tests passed\n");
    return 0;
}
