/* SPDX-License-Identifier: Apache-2.0 */
/* Lattice packer on exact analytic containers: counts where they are known,
 * no particle outside, no overlaps, count mode, thread independence,
 * refusals of impossible requests, and thin boxes (one layer packed; a
 * count or a radius out of reach refused at once). */
#include "vp_test.h"

#include <string.h>

#include "core/container.h"
#include "core/geom.h"
#include "core/shape.h"
#include "vdbpack/vdbpack.h"

static vp_context *ctx;

static vp_particles *pack(const vp_container *c, vp_shape shape, vp_lattice lat, vp_fit fit,
                          double r, size_t count, vp_lattice_report *rep) {
    vp_lattice_params p;
    vp_lattice_params_init(&p);
    p.shape = shape;
    p.lattice = lat;
    p.fit = fit;
    p.radius = r;
    p.count = count;
    vp_particles *out = NULL;
    ASSERT_OK(ctx, vp_pack_lattice(ctx, c, &p, &out, rep));
    return out;
}

/* Smallest centre distance over all pairs (grid-free O(n^2) for small n). */
static double min_pair_distance(const vp_particles *p) {
    double best = HUGE_VAL;
    for (size_t i = 0; i < p->count; i++)
        for (size_t j = i + 1; j < p->count; j++) {
            const double *a = p->positions + 3 * i, *b = p->positions + 3 * j;
            double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
            double n = vp_norm3(d);
            if (n < best) best = n;
        }
    return best;
}

static void test_sc_in_box_finds_aligned_placement(void) {
    /* L = 2rk + 0.2r: at most k per axis fit wholly inside; the search must
     * find a placement that reaches k^3. */
    const double r = 1.0;
    const int k = 6;
    double L = 2 * r * k + 0.2 * r;
    double lo[3] = {-L / 2, -L / 2, -L / 2}, hi[3] = {L / 2, L / 2, L / 2};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, hi, &c));
    vp_lattice_report rep;
    vp_particles *p = pack(c, VP_SHAPE_SPHERE, VP_LATTICE_SC, VP_FIT_INSIDE, r, 0, &rep);
    ASSERT_EQ_INT(p->count, k * k * k);
    ASSERT_GE(rep.offsets_tried, 2);
    for (size_t i = 0; i < p->count; i++)
        for (int a = 0; a < 3; a++) {
            ASSERT_GE(p->positions[3 * i + a], lo[a] + r - 1e-12);
            ASSERT_LE(p->positions[3 * i + a], hi[a] - r + 1e-12);
        }
    ASSERT_NEAR(min_pair_distance(p), 2 * r, 1e-9);
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

/* Spheres that touch both walls: a box whose sides are whole multiples of
 * the spacing holds exactly (L / 2r)^3 (or one more per axis with fit
 * center). That placement is a single point of the offset cell, and the
 * touching spheres sit at d = -r up to rounding: it gave 729 of 1000. */
static void test_sc_touching_both_walls(void) {
    const struct {
        double hx, hy, hz, r;
        vp_fit fit;
        size_t want;
    } cases[] = {
        {0.5, 0.5, 0.5, 0.05, VP_FIT_INSIDE, 1000},
        {1.0, 1.5, 2.0, 0.25, VP_FIT_INSIDE, 4 * 6 * 8},
        {0.5, 0.5, 0.5, 0.05, VP_FIT_CENTER, 11 * 11 * 11},
        {40.0, 40.0, 40.0, 4.0, VP_FIT_INSIDE, 1000},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        double lo[3] = {-cases[k].hx, -cases[k].hy, -cases[k].hz};
        double hi[3] = {cases[k].hx, cases[k].hy, cases[k].hz};
        vp_container *c = NULL;
        ASSERT_OK(ctx, vp_container_create_box(ctx, lo, hi, &c));
        vp_lattice_report rep;
        double r = cases[k].r;
        vp_particles *p = pack(c, VP_SHAPE_SPHERE, VP_LATTICE_SC, cases[k].fit, r, 0, &rep);
        fprintf(stderr, "   box %gx%gx%g r %g: %zu (%zu fit)\n", 2 * cases[k].hx, 2 * cases[k].hy,
                2 * cases[k].hz, r, p->count, cases[k].want);
        ASSERT_EQ_INT(p->count, cases[k].want);
        double shrink = cases[k].fit == VP_FIT_INSIDE ? r : 0.0;
        for (size_t i = 0; i < p->count; i++)
            for (int a = 0; a < 3; a++) { /* within rounding of the wall */
                ASSERT_GE(p->positions[3 * i + a], lo[a] + shrink - 1e-12 * cases[k].hz);
                ASSERT_LE(p->positions[3 * i + a], hi[a] - shrink + 1e-12 * cases[k].hz);
            }
        ASSERT_NEAR(min_pair_distance(p), 2 * r, 1e-9 * r);
        vp_particles_destroy(p);
        vp_container_destroy(c);
    }
}

/* A level set's values stop at its interior band: deeper points read the
 * band's depth. A sphere of radius R whose distance is clamped so, with the
 * band 2.5 r deep (the band vdbpack sizes for r at voxel r/2), stands in for
 * a voxelized container. */
typedef struct clamped_sphere {
    double R, band;
} clamped_sphere;

static double clamped_distance(void *user, const double p[3]) {
    const clamped_sphere *c = user;
    double d = vp_norm3(p) - c->R;
    return d < -c->band ? -c->band : d;
}

/* The placement search must still know which points fit for every offset
 * when the band is only just deep enough: it limits its offsets to the band
 * instead of re-testing every inside point per offset (which its budget
 * then cut to its minimum of offsets), and finds as good a placement as on
 * the exact sphere. */
static void test_search_with_a_shallow_band(void) {
    const double r = 1.0, R = 30.0;
    clamped_sphere cs = {R, 2.5 * r - 3e-6};
    vp_container_info info;
    memset(&info, 0, sizeof info);
    info.kind = VP_CONTAINER_LEVEL_SET;
    for (int k = 0; k < 3; k++) {
        info.bmin[k] = -R;
        info.bmax[k] = R;
    }
    info.volume = 4.0 / 3.0 * M_PI * R * R * R;
    info.voxel_size = 0.5 * r;
    info.interior_band = cs.band;
    static const vp_container_ops ops = {clamped_distance, NULL, NULL};
    vp_container *c = NULL, *exact = NULL;
    ASSERT_OK(ctx, vp_container_wrap(ctx, &ops, &cs, &info, &c));
    double ctr[3] = {0, 0, 0};
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, ctr, R, &exact));
    vp_lattice_report rep, rep_exact;
    vp_particles *p = pack(c, VP_SHAPE_SPHERE, VP_LATTICE_FCC, VP_FIT_INSIDE, r, 0, &rep);
    vp_particles *q = pack(exact, VP_SHAPE_SPHERE, VP_LATTICE_FCC, VP_FIT_INSIDE, r, 0, &rep_exact);
    fprintf(stderr, "   band 2.5 r: %zu particles, %d offsets; exact sphere: %zu, %d offsets\n",
            p->count, rep.offsets_tried, q->count, rep_exact.offsets_tried);
    ASSERT_GE(rep.offsets_tried, 128);
    ASSERT_GE((double)p->count, 0.999 * (double)q->count);
    for (size_t i = 0; i < p->count; i++) ASSERT_LE(vp_norm3(p->positions + 3 * i), R - r + 1e-9);
    vp_particles_destroy(p);
    vp_particles_destroy(q);
    vp_container_destroy(c);
    vp_container_destroy(exact);
}

static void test_every_sphere_lattice_inside_and_touching(void) {
    double c0[3] = {0.3, -0.2, 0.1};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, c0, 8.0, &c));
    vp_lattice lats[] = {VP_LATTICE_SC, VP_LATTICE_BCC, VP_LATTICE_FCC, VP_LATTICE_HCP};
    for (int li = 0; li < 4; li++) {
        vp_lattice_report rep;
        vp_particles *p = pack(c, VP_SHAPE_SPHERE, lats[li], VP_FIT_INSIDE, 1.0, 0, &rep);
        ASSERT_GE(p->count, 10);
        for (size_t i = 0; i < p->count; i++)
            ASSERT_LE(vp_container_distance(c, p->positions + 3 * i), -1.0 + 1e-9);
        ASSERT_NEAR(min_pair_distance(p), 2.0, 1e-9);
        double frac = vp_particles_volume(p) / (4.0 / 3.0 * M_PI * 512.0);
        ASSERT_LE(frac, rep.lattice_fraction);
        ASSERT_NEAR(rep.particle_volume, vp_particles_volume(p), 1e-9);
        vp_particles_destroy(p);
    }
    vp_container_destroy(c);
}

static void test_fit_center_admits_more_than_inside(void) {
    double c0[3] = {0, 0, 0};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, c0, 6.0, &c));
    vp_particles *in = pack(c, VP_SHAPE_SPHERE, VP_LATTICE_FCC, VP_FIT_INSIDE, 1.0, 0, NULL);
    vp_particles *ce = pack(c, VP_SHAPE_SPHERE, VP_LATTICE_FCC, VP_FIT_CENTER, 1.0, 0, NULL);
    ASSERT_GE(ce->count, in->count + 1);
    int beyond = 0;
    for (size_t i = 0; i < ce->count; i++) {
        double d = vp_container_distance(c, ce->positions + 3 * i);
        ASSERT_LE(d, 1e-12);
        beyond += d > -1.0;
    }
    ASSERT_GE(beyond, 1); /* some centres sit closer to the wall than r */
    vp_particles_destroy(in);
    vp_particles_destroy(ce);
    vp_container_destroy(c);
}

static void test_solids_every_vertex_inside_and_no_overlap(void) {
    double c0[3] = {0, 0, 0};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, c0, 6.0, &c));
    for (int s = VP_SHAPE_TETRAHEDRON; s < VP_SHAPE_COUNT; s++) {
        vp_particles *p = pack(c, (vp_shape)s, VP_LATTICE_DEFAULT, VP_FIT_INSIDE, 1.0, 0, NULL);
        const vp_polyhedron *poly = vp_shape_polyhedron((vp_shape)s);
        ASSERT_TRUE(poly != NULL);
        ASSERT_EQ_INT(p->has_orient, 1);
        double q[4] = {p->uniform_orient[0], p->uniform_orient[1], p->uniform_orient[2],
                       p->uniform_orient[3]};
        ASSERT_GE(p->count, 5);
        for (size_t i = 0; i < p->count; i++)
            for (int v = 0; v < poly->nverts; v++) {
                double w[3], x[3];
                vp_quat_rotate(q, poly->verts[v], w);
                for (int a = 0; a < 3; a++) x[a] = p->positions[3 * i + a] + w[a];
                ASSERT_LE(vp_container_distance(c, x), 1e-9);
            }
        int close = 0;
        for (size_t i = 0; i < p->count; i++)
            for (size_t j = i + 1; j < p->count; j++) {
                const double *a = p->positions + 3 * i, *b = p->positions + 3 * j;
                double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
                if (vp_norm3(d) >= 2.0) continue;
                close++;
                double sep = vp_poly_separation(poly, 1.0, q, a, poly, 1.0, q, b);
                ASSERT_GE(sep, -1e-9);
            }
        ASSERT_GE(close, 1); /* the check above saw neighbours */
        vp_particles_destroy(p);
    }
    vp_container_destroy(c);
}

static void test_count_mode_within_two_percent(void) {
    double c0[3] = {0, 0, 0};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, c0, 1.0, &c));
    size_t wants[] = {500, 3000};
    for (int i = 0; i < 2; i++) {
        vp_lattice_report rep;
        vp_particles *p =
            pack(c, VP_SHAPE_SPHERE, VP_LATTICE_FCC, VP_FIT_INSIDE, 0, wants[i], &rep);
        ASSERT_LE(fabs((double)p->count - (double)wants[i]), 0.02 * (double)wants[i]);
        ASSERT_NEAR(p->uniform_radius, rep.radius, 1e-6 * rep.radius);
        vp_particles_destroy(p);
    }
    vp_container_destroy(c);
}

/* Small counts move in whole steps: the radius search brackets N and
 * bisects, and never settles on a radius where nothing fits. --count 5 in
 * a sphere is 5 (the r^-3 steps alone gave 4 in the peanut); one sphere in
 * a 1 x 2 x 3 box is one (the search failed: it stepped to radius 0.71,
 * where none fits, and kept it as the closest to 1). */
static void test_count_mode_small_counts(void) {
    double c0[3] = {0, 0, 0};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, c0, 1.0, &c));
    for (size_t n = 1; n <= 7; n++) {
        vp_lattice_report rep;
        vp_particles *p = pack(c, VP_SHAPE_SPHERE, VP_LATTICE_FCC, VP_FIT_INSIDE, 0, n, &rep);
        ASSERT_EQ_INT(p->count, n);
        vp_particles_destroy(p);
    }
    vp_container_destroy(c);
    double lo[3] = {-0.5, -1, -1.5}, hi[3] = {0.5, 1, 1.5};
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, hi, &c));
    size_t wants[] = {1, 4, 5, 17, 23};
    for (int i = 0; i < 5; i++) {
        vp_lattice_report rep;
        vp_particles *p =
            pack(c, VP_SHAPE_SPHERE, VP_LATTICE_FCC, VP_FIT_INSIDE, 0, wants[i], &rep);
        fprintf(stderr, "   box 1x2x3 --count %zu: %zu\n", wants[i], p->count);
        ASSERT_EQ_INT(p->count, wants[i]);
        vp_particles_destroy(p);
    }
    vp_container_destroy(c);
}

static void test_same_output_for_any_thread_count(void) {
    double c0[3] = {0, 0, 0};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, c0, 10.0, &c));
    vp_context_set_threads(ctx, 1);
    vp_particles *a = pack(c, VP_SHAPE_SPHERE, VP_LATTICE_HCP, VP_FIT_INSIDE, 1.0, 0, NULL);
    vp_context_set_threads(ctx, 3);
    vp_particles *b = pack(c, VP_SHAPE_SPHERE, VP_LATTICE_HCP, VP_FIT_INSIDE, 1.0, 0, NULL);
    vp_context_set_threads(ctx, 0);
    ASSERT_EQ_INT(a->count, b->count);
    ASSERT_TRUE(memcmp(a->positions, b->positions, a->count * 3 * sizeof(double)) == 0);
    vp_particles_destroy(a);
    vp_particles_destroy(b);
    vp_container_destroy(c);
}

static void test_refusals(void) {
    double c0[3] = {0, 0, 0};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, c0, 1.0, &c));
    vp_lattice_params p;
    vp_particles *out = NULL;
    vp_lattice_params_init(&p);
    p.radius = -1;
    ASSERT_EQ_INT(vp_pack_lattice(ctx, c, &p, &out, NULL), VP_ERR_INVALID_ARGUMENT);
    p.radius = NAN;
    ASSERT_EQ_INT(vp_pack_lattice(ctx, c, &p, &out, NULL), VP_ERR_INVALID_ARGUMENT);
    p.radius = 2.0; /* larger than the container */
    ASSERT_EQ_INT(vp_pack_lattice(ctx, c, &p, &out, NULL), VP_ERR_NO_FIT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "too large") != NULL);
    p.radius = 1e-5; /* ~10^15 particles: refused before allocating */
    ASSERT_EQ_INT(vp_pack_lattice(ctx, c, &p, &out, NULL), VP_ERR_OUT_OF_MEMORY);
    ASSERT_TRUE(out == NULL);
    p.radius = 0.1;
    p.shape = VP_SHAPE_CUBE;
    p.lattice = VP_LATTICE_BCC; /* sphere lattice for a solid */
    ASSERT_EQ_INT(vp_pack_lattice(ctx, c, &p, &out, NULL), VP_ERR_INVALID_ARGUMENT);
    vp_container_destroy(c);
}

/* Boxes far thinner than they are wide. Count mode stepped its radius
 * down until one layer fit, where every lattice point is near a wall and
 * kept for the search: box 1e-4 x 1 x 1 --count 10 grew to 2.2 GB and
 * ran out of memory after 11 s (with --max-memory 500M), 1e-7 ran on.
 * Now refused with one message, in a child bounded to 20 s and 1.5 GB. */
static vp_result thin_pack(double t, double r, size_t count, vp_particles **out) {
    double lo[3] = {-0.5 * t, -0.5, -0.5}, hi[3] = {0.5 * t, 0.5, 0.5};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, hi, &c));
    vp_lattice_params p;
    vp_lattice_params_init(&p);
    p.radius = r;
    p.count = count;
    *out = NULL;
    vp_result res = vp_pack_lattice(ctx, c, &p, out, NULL);
    fprintf(stderr, "   box %g x 1 x 1, radius %g, count %zu: %s\n", t, r, count,
            res == VP_OK ? "packed" : vp_context_message(ctx));
    vp_container_destroy(c);
    return res;
}

static void thin_refusals(void) {
    const double ts[] = {1e-4, 1e-7, 1e-20};
    vp_particles *out = NULL;
    for (int i = 0; i < 3; i++) {
        ASSERT_EQ_INT(thin_pack(ts[i], 0, 10, &out), VP_ERR_NO_FIT);
        ASSERT_TRUE(out == NULL);
        ASSERT_TRUE(strstr(vp_context_message(ctx), "--count 10 is out of reach") != NULL);
    }
    vp_context_set_max_memory(ctx, 500ull << 20);
    ASSERT_EQ_INT(thin_pack(1e-4, 0, 10, &out), VP_ERR_NO_FIT);
    /* a radius: 2.8e8 particles by volume (22 GB), under a 24 GB limit,
     * but 3.8e8 points near the walls for the search (28 GB) */
    vp_context_set_max_memory(ctx, 24ull << 30);
    ASSERT_EQ_INT(thin_pack(1e-4, 4e-5, 0, &out), VP_ERR_OUT_OF_MEMORY);
    ASSERT_TRUE(out == NULL);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "near the container's walls") != NULL);
    vp_context_set_max_memory(ctx, 0);
}

static void test_thin_boxes(void) {
    vp_test_bounded(thin_refusals, 20, 1500ull << 20);
    /* one layer that fits: simple cubic r = 0.004 in 0.01 x 1 x 1, centres
     * in |x| <= 0.001, 125 x 125 of them 0.008 apart in y and z */
    double lo[3] = {-0.005, -0.5, -0.5}, hi[3] = {0.005, 0.5, 0.5};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, hi, &c));
    vp_particles *p = pack(c, VP_SHAPE_SPHERE, VP_LATTICE_SC, VP_FIT_INSIDE, 0.004, 0, NULL);
    fprintf(stderr, "   simple cubic r 0.004 in 0.01 x 1 x 1: %zu\n", p->count);
    ASSERT_EQ_INT(p->count, 125 * 125);
    for (size_t i = 0; i < p->count; i++)
        for (int k = 0; k < 3; k++)
            ASSERT_LE(fabs(p->positions[3 * i + k]) + 0.004, hi[k] * (1 + 1e-9));
    ASSERT_GE(min_pair_distance(p), 0.008 * (1 - 1e-9));
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

int main(void) {
    ASSERT_OK(NULL, vp_context_create(&ctx));
    RUN_TEST(test_sc_in_box_finds_aligned_placement);
    RUN_TEST(test_every_sphere_lattice_inside_and_touching);
    RUN_TEST(test_fit_center_admits_more_than_inside);
    RUN_TEST(test_solids_every_vertex_inside_and_no_overlap);
    RUN_TEST(test_count_mode_within_two_percent);
    RUN_TEST(test_count_mode_small_counts);
    RUN_TEST(test_sc_touching_both_walls);
    RUN_TEST(test_same_output_for_any_thread_count);
    RUN_TEST(test_refusals);
    RUN_TEST(test_search_with_a_shallow_band);
    RUN_TEST(test_thin_boxes);
    vp_context_destroy(ctx);
    return 0;
}
