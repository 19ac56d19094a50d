/* SPDX-License-Identifier: Apache-2.0 */
/* count=max with a distribution of radii (issue 31): "maximal" means that
 * no centre has room for the smallest radius of the distribution. Checked
 * by brute force on exact analytic containers, never through the packer's
 * own tests: random probe centres (admissible for the smallest radius by
 * the analytic wall) all meet a placed sphere; a pass stopped early leaves
 * free probes (so the probe can fail); no overlaps, every sphere inside,
 * radii within the law's bounds and, while room is plentiful, drawn from
 * it; the same packing on 1 and 2 threads. Also the truncated draw the
 * pass uses where a drawn radius does not fit (vp_size_dist_sample_below)
 * against rejection from the untruncated law. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "core/size_dist_sample.h"
#include "vp_test.h"

static vp_context *ctx;

static const char *LAWS[] = {"uniform:0.04:0.08", "lognormal:0.05:0.012", "list:0.04:0.06:0.09"};

/* The law truncated at c, its mean by two independent routes: the
 * truncated draw, and rejection from untruncated draws (within 5 standard
 * errors); every truncated draw within [min, c]. */
static void test_sample_below(void) {
    for (int l = 0; l < 3; l++) {
        vp_size_dist d;
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, LAWS[l], &d));
        double lo = vp_size_dist_min(&d);
        double cs[2] = {vp_size_dist_mean(&d), 0.5 * (lo + vp_size_dist_mean(&d))};
        for (int k = 0; k < 2; k++) {
            double c = cs[k];
            uint64_t s1 = 7, s2 = 8;
            const int n = 200000;
            double m_t = 0, v_t = 0, m_r = 0, v_r = 0, worst_hi = -HUGE_VAL, worst_lo = HUGE_VAL;
            int nr = 0;
            for (int i = 0; i < n; i++) {
                double r = vp_size_dist_sample_below(&d, c, &s1);
                m_t += r;
                v_t += r * r;
                if (r > worst_hi) worst_hi = r;
                if (r < worst_lo) worst_lo = r;
            }
            while (nr < n) {
                double r = vp_size_dist_sample(&d, &s2);
                if (r > c) continue;
                m_r += r;
                v_r += r * r;
                nr++;
            }
            m_t /= n;
            m_r /= n;
            v_t = v_t / n - m_t * m_t;
            v_r = v_r / n - m_r * m_r;
            double se = sqrt((v_t + v_r) / n);
            fprintf(stderr,
                    "   %s below %.4f: mean %.6f (truncated draw), %.6f (rejection), "
                    "se %.2g; range [%.6f, %.6f]\n",
                    LAWS[l], c, m_t, m_r, se, worst_lo, worst_hi);
            ASSERT_LE(worst_hi, c);
            ASSERT_GE(worst_lo, lo);
            ASSERT_LE(fabs(m_t - m_r), 5 * se + 1e-12);
        }
    }
}

/* Room for a sphere centred at x: the wall's (container kind: box of half
 * side h, or sphere of radius h), and the nearest surface's. */
static double wall_room(int sphere, double h, const double x[3], vp_fit fit) {
    double d;
    if (sphere) {
        d = h - sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    } else {
        d = HUGE_VAL;
        for (int k = 0; k < 3; k++) d = fmin(d, h - fabs(x[k]));
    }
    if (fit == VP_FIT_CENTER) return d >= 0 ? HUGE_VAL : -HUGE_VAL;
    return d;
}

static double particle_room(const vp_particles *p, const double x[3]) {
    double best = HUGE_VAL;
    for (size_t i = 0; i < p->count; i++) {
        const double *c = p->positions + 3 * i;
        double dx = x[0] - c[0], dy = x[1] - c[1], dz = x[2] - c[2];
        double s = sqrt(dx * dx + dy * dy + dz * dz) - p->radii[i];
        if (s < best) best = s;
    }
    return best;
}

/* Probes uniform in the container's box: those where a sphere of the
 * smallest radius rmin would be inside (admissible), and of those, the
 * ones where it would overlap no placed sphere (free). */
static void probe(const vp_particles *p, int sphere, double h, vp_fit fit, double rmin,
                  size_t nprobe, size_t *admissible, size_t *free_) {
    uint64_t st = 4242;
    *admissible = *free_ = 0;
    for (size_t k = 0; k < nprobe; k++) {
        double x[3];
        for (int m = 0; m < 3; m++) x[m] = h * (2 * vp_rng_uniform(&st) - 1);
        if (wall_room(sphere, h, x, fit) < rmin) continue;
        ++*admissible;
        *free_ += particle_room(p, x) >= rmin;
    }
}

static vp_result pack(const vp_container *c, const char *law, size_t count, vp_fit fit, int threads,
                      vp_particles **p, vp_rsa_report *rep) {
    vp_rsa_pass ps;
    vp_rsa_pass_init(&ps);
    ps.maximal = count == 0;
    ps.count = count;
    ASSERT_OK(ctx, vp_size_dist_parse(ctx, law, &ps.radius));
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.passes = &ps;
    rp.npasses = 1;
    rp.fit = fit;
    rp.seed = 5;
    vp_context_set_threads(ctx, threads);
    return vp_pack_rsa(ctx, c, &rp, p, rep);
}

static void check_maximal(int sphere, vp_fit fit) {
    const double h = sphere ? 0.6 : 0.5;
    vp_container *c = NULL;
    double ctr[3] = {0, 0, 0}, lo[3] = {-h, -h, -h}, hi[3] = {h, h, h};
    ASSERT_OK(ctx, sphere ? vp_container_create_sphere(ctx, ctr, h, &c)
                          : vp_container_create_box(ctx, lo, hi, &c));
    for (int l = 0; l < 3; l++) {
        vp_size_dist d;
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, LAWS[l], &d));
        double rmin = (float)vp_size_dist_min(&d), rmax = vp_size_dist_max(&d);
        vp_particles *p = NULL, *q = NULL;
        vp_rsa_report rep, rep2;
        ASSERT_OK(ctx, pack(c, LAWS[l], 0, fit, 2, &p, &rep));
        ASSERT_EQ_INT(rep.passes[0].stop, VP_RSA_STOP_MAXIMAL);
        /* no overlap, inside, radii in bounds */
        double worst = -HUGE_VAL, worst_wall = HUGE_VAL, rlo = HUGE_VAL, rhi = 0;
        for (size_t i = 0; i < p->count; i++) {
            const double *a = p->positions + 3 * i;
            double ri = p->radii[i];
            rlo = fmin(rlo, ri);
            rhi = fmax(rhi, ri);
            worst_wall =
                fmin(worst_wall, wall_room(sphere, h, a, fit) - (fit == VP_FIT_INSIDE ? ri : 0));
            for (size_t j = i + 1; j < p->count; j++) {
                const double *b = p->positions + 3 * j;
                double dd = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                                 (a[2] - b[2]) * (a[2] - b[2]));
                double e = ri + p->radii[j];
                worst = fmax(worst, (e - dd) / e);
            }
        }
        /* drawn from the law: the pass begins as a count pass does (each
         * radius drawn kept until placed) until `retries` tries in a row
         * fail, so a count pass (same seed) that ends so is part of it,
         * and its radii are draws of the law. Its count is the maximal
         * pass's own estimate (run_pass in rsa.c), which sizes the level-0
         * cells that the darts are drawn from: the same darts */
        double shrink = fit == VP_FIT_INSIDE ? rmin : 0.0;
        double vol = pow(2 * (h - shrink), 3); /* the container's box, shrunk */
        size_t same = (size_t)(0.4 * vol / (4.0 / 3.0 * M_PI * rmin * rmin * rmin));
        vp_particles *c150 = NULL;
        ASSERT_OK(ctx, pack(c, LAWS[l], same, fit, 1, &c150, &rep2));
        ASSERT_EQ_INT(rep2.passes[0].stop, VP_RSA_STOP_RETRIES);
        size_t n0 = c150->count, found = 0;
        double m = 0, v = 0;
        for (size_t i = 0; i < n0; i++) m += c150->radii[i];
        m /= (double)n0;
        for (size_t i = 0; i < n0; i++) v += (c150->radii[i] - m) * (c150->radii[i] - m);
        double se = sqrt(v / (double)(n0 - 1) / (double)n0);
        for (size_t i = 0; i < n0; i++)
            for (size_t j = 0; j < p->count; j++)
                if (!memcmp(c150->positions + 3 * i, p->positions + 3 * j, 3 * sizeof(double)) &&
                    c150->radii[i] == p->radii[j]) {
                    found++;
                    break;
                }
        vp_particles_destroy(c150);
        size_t adm, fr, adm2, fr2;
        probe(p, sphere, h, fit, rmin, 60000, &adm, &fr);
        /* an early stop (half the count) leaves room: the probe can fail */
        ASSERT_OK(ctx, pack(c, LAWS[l], p->count / 2, fit, 1, &q, &rep2));
        probe(q, sphere, h, fit, rmin, 60000, &adm2, &fr2);
        fprintf(stderr,
                "   %s %s fit %s: %zu spheres, radii [%.5f, %.5f] (law [%.5f, %.5f]), "
                "a count pass stopped by retries, %zu: mean %.5f (law %.5f, se %.2g), %zu of them "
                "in it; worst overlap %.2g, wall %.2g; "
                "probes %zu admissible, %zu free (half the count: %zu free)\n",
                LAWS[l], sphere ? "sphere" : "box", fit == VP_FIT_INSIDE ? "inside" : "center",
                p->count, rlo, rhi, rmin, rmax, n0, m, vp_size_dist_mean(&d), se, found, worst,
                worst_wall, adm, fr, fr2);
        ASSERT_LE(worst, 1e-6);
        ASSERT_GE(worst_wall, -1e-6);
        ASSERT_GE(rlo, rmin);
        ASSERT_LE(rhi, (float)rmax);
        ASSERT_LE(fabs(m - vp_size_dist_mean(&d)), 5 * se);
        ASSERT_EQ_INT(found, n0);
        ASSERT_GE(adm, 20000);
        ASSERT_EQ_INT(fr, 0);
        ASSERT_GE(fr2, 100);
        vp_particles_destroy(q);
        /* the thread count does not change the packing */
        vp_particles *p1 = NULL;
        ASSERT_OK(ctx, pack(c, LAWS[l], 0, fit, 1, &p1, &rep2));
        ASSERT_EQ_INT(p1->count, p->count);
        ASSERT_TRUE(!memcmp(p1->positions, p->positions, p->count * 3 * sizeof(double)));
        ASSERT_TRUE(!memcmp(p1->radii, p->radii, p->count * sizeof(float)));
        vp_particles_destroy(p1);
        vp_particles_destroy(p);
    }
    vp_container_destroy(c);
}

static void test_maximal_box_inside(void) { check_maximal(0, VP_FIT_INSIDE); }
static void test_maximal_sphere_inside(void) { check_maximal(1, VP_FIT_INSIDE); }
static void test_maximal_box_center(void) { check_maximal(0, VP_FIT_CENTER); }

int main(void) {
    ASSERT_OK(NULL, vp_context_create(&ctx));
    RUN_TEST(test_sample_below);
    RUN_TEST(test_maximal_box_inside);
    RUN_TEST(test_maximal_sphere_inside);
    RUN_TEST(test_maximal_box_center);
    vp_context_destroy(ctx);
    fprintf(stderr, "PASS\n");
    return 0;
}
