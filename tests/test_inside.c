/* SPDX-License-Identifier: Apache-2.0 */
/* The inside of broken meshes (issue 26): a sphere with 2, 10 and 30 % of
 * its triangles removed at random, a box missing a face, two overlapping
 * spheres, a sphere with a reversed inner shell (a cavity), a sphere with
 * 10 % of its faces flipped, an inside-out sphere, a soup of disconnected
 * triangles. Each is handed over as arrays (vp_container_from_mesh) and
 * packed by lattice and by maximal random sequential addition; every
 * particle is checked against the shape the mesh stands for, by this
 * test's own geometry, and the packing fraction against the clean mesh's.
 * Then the meshes with no inside, and the inside modes. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vp_test.h"

typedef struct mesh {
    double *v;
    uint32_t *t;
    size_t nv, nt;
} mesh;

static uint32_t add_vertex(mesh *m, double x, double y, double z) {
    m->v = realloc(m->v, 3 * (m->nv + 1) * sizeof *m->v);
    m->v[3 * m->nv] = x;
    m->v[3 * m->nv + 1] = y;
    m->v[3 * m->nv + 2] = z;
    return (uint32_t)m->nv++;
}

static void add_tri(mesh *m, uint32_t a, uint32_t b, uint32_t c) {
    m->t = realloc(m->t, 3 * (m->nt + 1) * sizeof *m->t);
    m->t[3 * m->nt] = a;
    m->t[3 * m->nt + 1] = b;
    m->t[3 * m->nt + 2] = c;
    m->nt++;
}

static void free_mesh(mesh *m) {
    free(m->v);
    free(m->t);
    memset(m, 0, sizeof *m);
}

/* A UV sphere of radius r about c (welded: poles shared), outward. */
static void sphere(mesh *m, double r, const double c[3], int nu, int nv) {
    uint32_t base = (uint32_t)m->nv;
    add_vertex(m, c[0], c[1], c[2] + r); /* north */
    for (int i = 1; i < nv; i++) {
        double th = M_PI * i / nv;
        for (int j = 0; j < nu; j++) {
            double ph = 2 * M_PI * j / nu;
            add_vertex(m, c[0] + r * sin(th) * cos(ph), c[1] + r * sin(th) * sin(ph),
                       c[2] + r * cos(th));
        }
    }
    uint32_t south = add_vertex(m, c[0], c[1], c[2] - r);
#define RING(i, j) (base + 1 + (uint32_t)((i)-1) * (uint32_t)nu + (uint32_t)((j) % nu))
    for (int j = 0; j < nu; j++) add_tri(m, base, RING(1, j), RING(1, j + 1));
    for (int i = 1; i < nv - 1; i++)
        for (int j = 0; j < nu; j++) {
            add_tri(m, RING(i, j), RING(i + 1, j), RING(i + 1, j + 1));
            add_tri(m, RING(i, j), RING(i + 1, j + 1), RING(i, j + 1));
        }
    for (int j = 0; j < nu; j++) add_tri(m, RING(nv - 1, j), south, RING(nv - 1, j + 1));
#undef RING
}

static void flip(mesh *m, size_t t) {
    uint32_t s = m->t[3 * t + 1];
    m->t[3 * t + 1] = m->t[3 * t + 2];
    m->t[3 * t + 2] = s;
}

static uint64_t g_rng = 0x9E3779B97F4A7C15ULL;
static double urand(void) {
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return (double)(g_rng >> 11) / 9007199254740992.0;
}

/* The intended inside, as this test knows it: the largest amount by which
 * a particle (centre p, radius r) leaves it (<= 0: wholly inside). */
typedef double (*outside_fn)(const double p[3], double r);

static double out_ball(const double p[3], double r) { /* unit ball */
    return sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) + r - 1.0;
}
static double out_box(const double p[3], double r) { /* [-0.5, 0.5]^3 */
    double m = -HUGE_VAL;
    for (int k = 0; k < 3; k++) m = fmax(m, fabs(p[k]) + r - 0.5);
    return m;
}
static double out_two(const double p[3], double r) { /* balls of 0.7 at x = -+0.35 */
    double a = sqrt((p[0] + 0.35) * (p[0] + 0.35) + p[1] * p[1] + p[2] * p[2]) + r - 0.7;
    double b = sqrt((p[0] - 0.35) * (p[0] - 0.35) + p[1] * p[1] + p[2] * p[2]) + r - 0.7;
    return fmin(a, b); /* inside one of them is enough for the union */
}
static double out_shell(const double p[3], double r) { /* 0.5 <= |p| <= 1 */
    double l = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    return fmax(l + r - 1.0, 0.5 - (l - r));
}

typedef struct result {
    size_t count;
    double fraction;
    double worst; /* largest excursion, world units */
} result;

/* Packs c by the method and checks every particle with `outside`. */
static result pack_and_check(vp_context *ctx, const vp_container *c, int rsa, outside_fn outside) {
    vp_particles *p = NULL;
    if (rsa) {
        vp_rsa_pass ps;
        vp_rsa_pass_init(&ps);
        ps.maximal = 1;
        vp_size_dist_constant(&ps.radius, 0.06);
        vp_rsa_params rp;
        vp_rsa_params_init(&rp);
        rp.passes = &ps;
        rp.npasses = 1;
        rp.seed = 5;
        ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, NULL));
    } else {
        vp_lattice_params lp;
        vp_lattice_params_init(&lp);
        lp.radius = 0.06;
        ASSERT_OK(ctx, vp_pack_lattice(ctx, c, &lp, &p, NULL));
    }
    vp_container_info ci;
    vp_container_get_info(c, &ci);
    result res = {p->count, vp_particles_volume(p) / ci.volume, -HUGE_VAL};
    for (size_t i = 0; i < p->count; i++) {
        double r = p->radii ? p->radii[i] : p->uniform_radius;
        res.worst = fmax(res.worst, outside(p->positions + 3 * i, r));
    }
    vp_particles_destroy(p);
    return res;
}

static vp_container *load(vp_context *ctx, const mesh *m, vp_inside_mode mode, double voxel) {
    vp_container_params cp;
    vp_container_params_init(&cp);
    cp.particle_radius = 0.06;
    cp.voxel_size = voxel;
    cp.inside = mode;
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_from_mesh(ctx, m->v, m->nv, m->t, m->nt, &cp, &c));
    return c;
}

#define VOXEL 0.02

/* The broken mesh against the clean one: both methods; no particle leaves
 * the intended inside by more than a fifth of a voxel (the level set's
 * resolution), and the fractions agree within 0.02. */
static void against_clean(const char *what, const mesh *clean, const mesh *broken, outside_fn out,
                          vp_inside_mode want) {
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_container *c0 = load(ctx, clean, VP_INSIDE_AUTO, VOXEL);
    vp_container *c1 = load(ctx, broken, VP_INSIDE_AUTO, VOXEL);
    vp_container_info i1;
    vp_container_get_info(c1, &i1);
    ASSERT_EQ_INT(i1.inside, want);
    for (int rsa = 0; rsa < 2; rsa++) {
        result a = pack_and_check(ctx, c0, rsa, out), b = pack_and_check(ctx, c1, rsa, out);
        fprintf(stderr,
                "   %s, %s: %zu particles, fraction %.4f (clean %zu, %.4f), worst "
                "excursion %.2g voxel\n",
                what, rsa ? "rsa max" : "lattice", b.count, b.fraction, a.count, a.fraction,
                b.worst / VOXEL);
        ASSERT_LE(b.worst, 0.2 * VOXEL);
        ASSERT_LE(a.worst, 0.2 * VOXEL);
        ASSERT_NEAR(b.fraction, a.fraction, 0.02);
        ASSERT_TRUE(b.count > 100);
    }
    vp_container_destroy(c0);
    vp_container_destroy(c1);
    vp_context_destroy(ctx);
}

static const double ORIGIN[3] = {0, 0, 0};

static void test_holes(void) {
    mesh clean = {0};
    sphere(&clean, 1.0, ORIGIN, 48, 24);
    static const double share[3] = {0.02, 0.10, 0.30};
    for (int s = 0; s < 3; s++) {
        mesh m = {0};
        m.v = malloc(3 * clean.nv * sizeof *m.v);
        memcpy(m.v, clean.v, 3 * clean.nv * sizeof *m.v);
        m.nv = clean.nv;
        for (size_t t = 0; t < clean.nt; t++)
            if (urand() >= share[s])
                add_tri(&m, clean.t[3 * t], clean.t[3 * t + 1], clean.t[3 * t + 2]);
        char what[64];
        snprintf(what, sizeof what, "sphere, %.0f %% of triangles removed", 100 * share[s]);
        against_clean(what, &clean, &m, out_ball, VP_INSIDE_WINDING);
        free_mesh(&m);
    }
    free_mesh(&clean);
}

static void box(mesh *m, int faces) {
    static const double V[8 * 3] = {-0.5, -0.5, -0.5, 0.5,  -0.5, -0.5, 0.5, 0.5,
                                    -0.5, -0.5, 0.5,  -0.5, -0.5, -0.5, 0.5, 0.5,
                                    -0.5, 0.5,  0.5,  0.5,  0.5,  -0.5, 0.5, 0.5};
    static const uint32_t T[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                   2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};
    for (int i = 0; i < 8; i++) add_vertex(m, V[3 * i], V[3 * i + 1], V[3 * i + 2]);
    for (int f = 0; f < 2 * faces; f++) add_tri(m, T[3 * f], T[3 * f + 1], T[3 * f + 2]);
}

static void test_box_missing_face(void) {
    mesh clean = {0}, m = {0};
    box(&clean, 6);
    box(&m, 5);
    against_clean("box missing a face", &clean, &m, out_box, VP_INSIDE_WINDING);
    free_mesh(&clean);
    free_mesh(&m);
}

/* Overlapping pieces: the union, counted once (the clean mesh is the same
 * union: here compared with itself through the two modes' volumes). */
static void test_overlapping_spheres(void) {
    mesh m = {0};
    double a[3] = {-0.35, 0, 0}, b[3] = {0.35, 0, 0};
    sphere(&m, 0.7, a, 48, 24);
    sphere(&m, 0.7, b, 48, 24);
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_container *c = load(ctx, &m, VP_INSIDE_AUTO, VOXEL);
    vp_container_info ci;
    vp_container_get_info(c, &ci);
    ASSERT_EQ_INT(ci.inside, VP_INSIDE_WINDING); /* closed pieces whose boxes overlap */
    ASSERT_EQ_INT(ci.mesh_pieces, 2);
    /* the union of two balls of 0.7 whose centres are 0.7 apart: two
     * balls less the lens between them (each cap of height 0.35) */
    double R = 0.7, hcap = 0.35;
    double lens = 2 * M_PI * hcap * hcap * (3 * R - hcap) / 3;
    double uni = 2 * 4.0 / 3.0 * M_PI * R * R * R - lens;
    fprintf(stderr, "   union volume %.4f, level set %.4f, estimate %.4f\n", uni, ci.volume,
            ci.volume_estimate);
    ASSERT_NEAR(ci.volume, uni, 0.02 * uni);
    ASSERT_EQ_INT(ci.volume_estimate_kind, VP_ESTIMATE_WINDING);
    ASSERT_NEAR(ci.volume_estimate, uni, 0.02 * uni);
    ASSERT_EQ_INT(ci.volume_mismatch, 0);
    for (int rsa = 0; rsa < 2; rsa++) {
        result r = pack_and_check(ctx, c, rsa, out_two);
        ASSERT_LE(r.worst, 0.2 * VOXEL);
        ASSERT_TRUE(r.count > 500);
    }
    vp_container_destroy(c);
    vp_context_destroy(ctx);
    free_mesh(&m);
}

/* A hollow ball: the reversed inner shell is a cavity; no particle in it. */
static void test_cavity(void) {
    mesh m = {0};
    sphere(&m, 1.0, ORIGIN, 48, 24);
    size_t first = m.nt;
    sphere(&m, 0.5, ORIGIN, 48, 24);
    for (size_t t = first; t < m.nt; t++) flip(&m, t);
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_container *c = load(ctx, &m, VP_INSIDE_AUTO, VOXEL);
    vp_container_info ci;
    vp_container_get_info(c, &ci);
    double shell = 4.0 / 3.0 * M_PI * (1.0 - 0.125);
    fprintf(stderr, "   hollow ball: volume %.4f (shell %.4f), cavities %zu\n", ci.volume, shell,
            ci.cavities);
    ASSERT_EQ_INT(ci.inside, VP_INSIDE_WINDING);
    ASSERT_EQ_INT(ci.cavities, 1);
    ASSERT_NEAR(ci.volume, shell, 0.03 * shell);
    double centre[3] = {0, 0, 0};
    ASSERT_TRUE(vp_container_distance(c, centre) > 0); /* the cavity is outside */
    for (int rsa = 0; rsa < 2; rsa++) {
        result r = pack_and_check(ctx, c, rsa, out_shell);
        fprintf(stderr, "   hollow ball, %s: %zu particles, worst excursion %.2g voxel\n",
                rsa ? "rsa max" : "lattice", r.count, r.worst / VOXEL);
        ASSERT_LE(r.worst, 0.2 * VOXEL);
        ASSERT_TRUE(r.count > 300);
    }
    vp_container_destroy(c);
    vp_context_destroy(ctx);
    free_mesh(&m);
}

static void test_flipped_faces(void) {
    mesh clean = {0}, m = {0};
    sphere(&clean, 1.0, ORIGIN, 48, 24);
    sphere(&m, 1.0, ORIGIN, 48, 24);
    size_t n = 0;
    for (size_t t = 0; t < m.nt; t++)
        if (urand() < 0.10) {
            flip(&m, t);
            n++;
        }
    fprintf(stderr, "   %zu of %zu faces flipped\n", n, m.nt);
    against_clean("sphere, 10 % of faces flipped", &clean, &m, out_ball, VP_INSIDE_WINDING);
    /* and the whole sphere inside out */
    for (size_t t = 0; t < m.nt; t++) flip(&m, t);
    mesh inv = {0};
    sphere(&inv, 1.0, ORIGIN, 48, 24);
    for (size_t t = 0; t < inv.nt; t++) flip(&inv, t);
    against_clean("sphere inside out", &clean, &inv, out_ball, VP_INSIDE_CLOSED);
    free_mesh(&clean);
    free_mesh(&m);
    free_mesh(&inv);
}

/* Every triangle on its own: shrunk by 1 % about its centre, so that no
 * vertex is shared. */
static void test_soup(void) {
    mesh clean = {0}, m = {0};
    sphere(&clean, 1.0, ORIGIN, 32, 16);
    for (size_t t = 0; t < clean.nt; t++) {
        double c[3] = {0, 0, 0};
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++) c[k] += clean.v[3 * clean.t[3 * t + j] + k] / 3;
        uint32_t id[3];
        for (int j = 0; j < 3; j++) {
            const double *p = clean.v + 3 * clean.t[3 * t + j];
            id[j] = add_vertex(&m, c[0] + 0.99 * (p[0] - c[0]), c[1] + 0.99 * (p[1] - c[1]),
                               c[2] + 0.99 * (p[2] - c[2]));
        }
        add_tri(&m, id[0], id[1], id[2]);
    }
    against_clean("soup of disconnected triangles", &clean, &m, out_ball, VP_INSIDE_WINDING);
    free_mesh(&clean);
    free_mesh(&m);
}

/* No inside at all: a square (one sheet) and a row of degenerate
 * triangles; and the modes. */
static void test_no_inside_and_modes(void) {
    vp_context *ctx;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_container_params cp;
    vp_container_params_init(&cp);
    cp.particle_radius = 0.05;
    vp_container *c = (vp_container *)1;
    double sq[4 * 3] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    uint32_t st[6] = {0, 1, 2, 0, 2, 3};
    vp_result r = vp_container_from_mesh(ctx, sq, 4, st, 2, &cp, &c);
    ASSERT_EQ_INT(r, VP_ERR_BAD_CONTAINER);
    ASSERT_TRUE(c == NULL);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "has no inside") != NULL);
    double line[5 * 3] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 4, 0, 0};
    uint32_t lt[9] = {0, 1, 2, 1, 2, 3, 2, 3, 4};
    r = vp_container_from_mesh(ctx, line, 5, lt, 3, &cp, &c);
    ASSERT_EQ_INT(r, VP_ERR_BAD_CONTAINER);
    fprintf(stderr, "   %s\n", vp_context_message(ctx));
    /* closed refuses what auto takes; winding forces the winding route */
    mesh m = {0};
    box(&m, 5);
    cp.inside = VP_INSIDE_CLOSED;
    r = vp_container_from_mesh(ctx, m.v, m.nv, m.t, m.nt, &cp, &c);
    ASSERT_EQ_INT(r, VP_ERR_OPEN_MESH);
    free_mesh(&m);
    mesh s = {0};
    sphere(&s, 1.0, ORIGIN, 16, 8);
    flip(&s, 3);
    r = vp_container_from_mesh(ctx, s.v, s.nv, s.t, s.nt, &cp, &c);
    ASSERT_EQ_INT(r, VP_ERR_OPEN_MESH);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "not consistently oriented") != NULL);
    flip(&s, 3);
    ASSERT_OK(ctx, vp_container_from_mesh(ctx, s.v, s.nv, s.t, s.nt, &cp, &c));
    vp_container_info ci;
    vp_container_get_info(c, &ci);
    ASSERT_EQ_INT(ci.inside, VP_INSIDE_CLOSED);
    ASSERT_EQ_INT(ci.volume_estimate_kind, VP_ESTIMATE_MESH_VOLUME);
    double vc = ci.volume;
    vp_container_destroy(c);
    cp.inside = VP_INSIDE_WINDING;
    ASSERT_OK(ctx, vp_container_from_mesh(ctx, s.v, s.nv, s.t, s.nt, &cp, &c));
    vp_container_get_info(c, &ci);
    ASSERT_EQ_INT(ci.inside, VP_INSIDE_WINDING);
    ASSERT_NEAR(ci.volume, vc, 0.01 * vc); /* the same inside both ways */
    vp_container_destroy(c);
    free_mesh(&s);
    ASSERT_TRUE(strcmp(vp_inside_name(VP_INSIDE_WINDING), "winding") == 0);
    vp_inside_mode mode;
    ASSERT_EQ_INT(vp_inside_parse("closed", &mode), 0);
    ASSERT_EQ_INT(mode, VP_INSIDE_CLOSED);
    ASSERT_EQ_INT(vp_inside_parse("open", &mode), -1);
    vp_context_destroy(ctx);
}

int main(int argc, char **argv) {
    /* one case by name: test_inside test_cavity (as VP_TEST=test_cavity) */
    if (argc > 1) setenv("VP_TEST", argv[1], 1);
    RUN_TEST(test_holes);
    RUN_TEST(test_box_missing_face);
    RUN_TEST(test_overlapping_spheres);
    RUN_TEST(test_cavity);
    RUN_TEST(test_flipped_faces);
    RUN_TEST(test_soup);
    RUN_TEST(test_no_inside_and_modes);
    return 0;
}
