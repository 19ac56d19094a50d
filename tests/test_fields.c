/* SPDX-License-Identifier: Apache-2.0 */
/* The field interface and masks through the C API, on exact analytic
 * containers and custom fields (no OpenVDB): every sphere of an rsa
 * packing with a radius field has radius r * f(centre) (scale) or
 * f(centre) (absolute) to float rounding, no pair overlaps; a density
 * field with a step puts its ratio of particles in the two halves; a
 * container less a mask has the distance max(d, -d_mask) at random points
 * and its volume to 0.2 %; vp_field_check refuses a field that does not
 * cover the container, radii <= 0 and negative densities; relax and jam
 * keep the field's ratios (jam exactly, up to one common factor). */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "vp_test.h"

static vp_context *ctx;

/* 1 at x = -0.5 down to 0.5 at x = 0.5 */
static double halve(void *user, const double p[3]) {
    (void)user;
    return 1.0 - 0.5 * (p[0] + 0.5);
}
/* the same as radii: 0.03 down to 0.015 */
static double halve_abs(void *user, const double p[3]) { return 0.03 * halve(user, p); }
/* 1 left of x = 0, 3 right of it */
static double step(void *user, const double p[3]) {
    (void)user;
    return p[0] < 0 ? 1.0 : 3.0;
}
static double minus(void *user, const double p[3]) {
    (void)user;
    return p[0];
}

static vp_field *custom(double (*fn)(void *, const double *), double lo, double hi, double vmin,
                        double vmax) {
    vp_field_ops ops = {fn, NULL};
    double bl[3] = {lo, lo, lo}, bh[3] = {hi, hi, hi};
    vp_field *f = NULL;
    ASSERT_OK(ctx, vp_field_create_custom(ctx, &ops, NULL, bl, bh, vmin, vmax, &f));
    return f;
}

static void no_overlap(const vp_particles *p) {
    for (size_t i = 0; i < p->count; i++)
        for (size_t j = i + 1; j < p->count; j++) {
            const double *a = p->positions + 3 * i, *b = p->positions + 3 * j;
            double d = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                            (a[2] - b[2]) * (a[2] - b[2]));
            ASSERT_GE(d, (double)p->radii[i] + p->radii[j]);
        }
}

static vp_particles *rsa(const vp_container *c, const vp_field *rf, vp_field_mode mode,
                         const vp_field *df, double r, size_t n) {
    vp_rsa_pass ps;
    vp_rsa_pass_init(&ps);
    ps.count = n;
    vp_size_dist_constant(&ps.radius, r);
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.passes = &ps;
    rp.npasses = 1;
    rp.radius_field = rf;
    rp.radius_field_mode = mode;
    rp.density_field = df;
    vp_particles *p = NULL;
    vp_rsa_report rep;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
    ASSERT_EQ_INT(rep.passes[0].placed, n);
    return p;
}

static vp_container *g_box;  /* [-0.5, 0.5]^3 */
static vp_field *g_h, *g_ha; /* halve and halve_abs over [-0.6, 0.6]^3 */

/* radius field, scale and absolute: r * f(x) to float rounding */
static void test_radius_field(void) {
    for (int mode = 0; mode < 2; mode++) {
        /* absolute: the pass's radius (1) is not used */
        vp_particles *p =
            rsa(g_box, mode ? g_ha : g_h, (vp_field_mode)mode, NULL, mode ? 1.0 : 0.03, 600);
        for (size_t i = 0; i < p->count; i++) {
            double want = 0.03 * halve(NULL, p->positions + 3 * i);
            ASSERT_NEAR(p->radii[i], want, 1e-6 * want);
            ASSERT_LE(p->radii[i], want); /* rounded down */
        }
        no_overlap(p);
        vp_particles_destroy(p);
    }
    /* the wall holds them (fit inside): exact distances to the box */
    {
        vp_field *a = custom(halve, -0.6, 0.6, 0.4, 1.1);
        vp_particles *p = rsa(g_box, a, VP_FIELD_SCALE, NULL, 0.05, 50);
        for (size_t i = 0; i < p->count; i++)
            ASSERT_LE(vp_container_distance(g_box, p->positions + 3 * i) + p->radii[i], 1e-12);
        vp_particles_destroy(p);
        vp_field_destroy(a);
    }
}

/* density: 3 times as many right of x = 0 (dilute: 4000 of r 0.003) */
static void test_density_field(void) {
    vp_field *d = custom(step, -0.6, 0.6, 1.0, 3.0);
    vp_particles *p = rsa(g_box, NULL, VP_FIELD_SCALE, d, 0.003, 4000);
    size_t left = 0;
    for (size_t i = 0; i < p->count; i++) left += p->positions[3 * i] < 0;
    double sd = sqrt(4000 * 0.25 * 0.75);
    fprintf(stderr, "density step 1:3: %zu of 4000 left (expect 1000 +- %.0f)\n", left, sd);
    ASSERT_LE(fabs((double)left - 1000.0), 4 * sd);
    vp_particles_destroy(p);
    vp_field_destroy(d);
}

/* checks: coverage, radii <= 0, densities < 0 */
static void test_field_checks(void) {
    vp_field *small = custom(halve, -0.3, 0.3, 0.4, 1.1);
    ASSERT_EQ_INT(vp_field_check(ctx, small, "small", "radius field", 1, g_box, NULL, NULL),
                  VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "does not cover") != NULL);
    vp_particles *p = NULL;
    vp_rsa_pass ps;
    vp_rsa_pass_init(&ps);
    ps.count = 10;
    vp_size_dist_constant(&ps.radius, 0.03);
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.passes = &ps;
    rp.npasses = 1;
    rp.radius_field = small;
    ASSERT_EQ_INT(vp_pack_rsa(ctx, g_box, &rp, &p, NULL), VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(p == NULL);
    vp_field *neg = custom(minus, -0.6, 0.6, -0.6, 0.6);
    ASSERT_EQ_INT(vp_field_check(ctx, neg, "neg", "radius field", 1, g_box, NULL, NULL),
                  VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "radii must be positive") != NULL);
    ASSERT_EQ_INT(vp_field_check(ctx, neg, "neg", "density field", 0, g_box, NULL, NULL),
                  VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "must not be negative") != NULL);
    double a, b;
    ASSERT_OK(ctx, vp_field_check(ctx, g_h, "h", "radius field", 1, g_box, &a, &b));
    ASSERT_NEAR(a, 0.4, 0);
    ASSERT_NEAR(b, 1.1, 0);
    vp_field_destroy(small);
    vp_field_destroy(neg);
}

/* a container less a mask: max(d, -d_mask), volume, packers stay out */
static void test_mask(void) {
    double mc[3] = {0.1, 0.0, 0.0};
    vp_container *ball = NULL, *m = NULL;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, mc, 0.25, &ball));
    ASSERT_OK(ctx, vp_container_subtract(ctx, g_box, ball, &m));
    uint64_t s = vp_rng_stream(7, 1);
    for (int t = 0; t < 10000; t++) {
        double x[3];
        for (int k = 0; k < 3; k++) x[k] = 1.4 * vp_rng_uniform(&s) - 0.7;
        double want = fmax(vp_container_distance(g_box, x), -vp_container_distance(ball, x));
        ASSERT_NEAR(vp_container_distance(m, x), want, 0);
    }
    vp_container_info mi;
    vp_container_get_info(m, &mi);
    double want = 1.0 - 4.0 / 3.0 * M_PI * 0.25 * 0.25 * 0.25;
    fprintf(stderr, "masked volume %.6f (exact %.6f)\n", mi.volume, want);
    ASSERT_NEAR(mi.volume, want, 0.002 * want);
    vp_particles *p = rsa(m, NULL, VP_FIELD_SCALE, NULL, 0.03, 800);
    for (size_t i = 0; i < p->count; i++) {
        const double *x = p->positions + 3 * i;
        double d = sqrt((x[0] - 0.1) * (x[0] - 0.1) + x[1] * x[1] + x[2] * x[2]);
        ASSERT_GE(d - p->radii[i], 0.25 - 1e-12);
    }
    vp_particles_destroy(p);
    vp_lattice_params lp;
    vp_lattice_params_init(&lp);
    lp.radius = 0.04;
    ASSERT_OK(ctx, vp_pack_lattice(ctx, m, &lp, &p, NULL));
    ASSERT_TRUE(p->count > 100);
    for (size_t i = 0; i < p->count; i++) {
        const double *x = p->positions + 3 * i;
        double d = sqrt((x[0] - 0.1) * (x[0] - 0.1) + x[1] * x[1] + x[2] * x[2]);
        ASSERT_GE(d - p->uniform_radius, 0.25 - 1e-9);
    }
    vp_particles_destroy(p);
    vp_container_destroy(m); /* before what it borrows */
    vp_container_destroy(ball);
    /* a mask that covers everything */
    vp_container *big = NULL;
    double o[3] = {0, 0, 0};
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, o, 2.0, &big));
    ASSERT_EQ_INT(vp_container_subtract(ctx, g_box, big, &m), VP_ERR_BAD_CONTAINER);
    vp_container_destroy(big);
}

/* jam keeps the field's ratios exactly: every r_i / f(start_i)
 * is one factor, so r ranges within the field's 0.5..1 */
static void test_jam_relax_field(void) {
    vp_jam_params jp;
    vp_jam_params_init(&jp);
    jp.count = 300;
    jp.radius_field = g_h;
    vp_particles *p = NULL;
    ASSERT_OK(ctx, vp_pack_jam(ctx, g_box, &jp, &p, NULL));
    double rmin = HUGE_VAL, rmax = 0;
    for (size_t i = 0; i < p->count; i++) {
        rmin = fmin(rmin, p->radii[i]);
        rmax = fmax(rmax, p->radii[i]);
    }
    fprintf(stderr, "jam: radii %.6g..%.6g, ratio %.4f (field: at most 2)\n", rmin, rmax,
            rmax / rmin);
    ASSERT_LE(rmax / rmin, 2.0 * (1 + 1e-6));
    ASSERT_GE(rmax / rmin, 1.6);
    no_overlap(p);
    vp_particles_destroy(p);
    vp_relax_params xp;
    vp_relax_params_init(&xp);
    xp.count = 300;
    vp_size_dist_constant(&xp.radius, 0.04);
    xp.radius_field = g_h;
    ASSERT_OK(ctx, vp_pack_relax(ctx, g_box, &xp, &p, NULL));
    /* relax: r_i <= 0.04 f(start), shrunk one by one, so the line */
    double sx = 0, sr = 0, sxx = 0, sxr = 0, n = (double)p->count;
    for (size_t i = 0; i < p->count; i++) {
        double x = p->positions[3 * i], r = p->radii[i];
        sx += x, sr += r, sxx += x * x, sxr += x * r;
    }
    double slope = (n * sxr - sx * sr) / (n * sxx - sx * sx), icpt = (sr - slope * sx) / n;
    fprintf(stderr, "relax: fitted radius %.5f at x=-0.5, %.5f at x=0.5 (0.04, 0.02)\n",
            icpt - 0.5 * slope, icpt + 0.5 * slope);
    ASSERT_NEAR(icpt - 0.5 * slope, 0.04, 0.02 * 0.04);
    ASSERT_NEAR(icpt + 0.5 * slope, 0.02, 0.02 * 0.02);
    vp_particles_destroy(p);
}

int main(void) {
    ASSERT_OK(NULL, vp_context_create(&ctx));
    double lo[3] = {-0.5, -0.5, -0.5}, hi[3] = {0.5, 0.5, 0.5};
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, hi, &g_box));
    g_h = custom(halve, -0.6, 0.6, 0.4, 1.1);
    g_ha = custom(halve_abs, -0.6, 0.6, 0.012, 0.033);
    RUN_TEST(test_radius_field);
    RUN_TEST(test_density_field);
    RUN_TEST(test_field_checks);
    RUN_TEST(test_mask);
    RUN_TEST(test_jam_relax_field);
    vp_field_destroy(g_h);
    vp_field_destroy(g_ha);
    vp_container_destroy(g_box);
    vp_context_destroy(ctx);
    fprintf(stderr, "test_fields: ok\n");
    return 0;
}
