/* SPDX-License-Identifier: Apache-2.0 */
/* The random packers and the checker through the public API, on exact
 * analytic containers, verified here by brute force (every pair, every
 * particle against the analytic wall), never by the checker alone:
 * size distributions (sample moments), RSA (zero overlaps, inside, groups,
 * count and retry semantics, grow makes contacts, maximal leaves no room
 * on a fine probe grid, determinism across thread counts, particles in
 * grid order after refinements, a refinement
 * given up over the cell budget), relaxation (overlap bound, inside,
 * radius scale), RSA in slabs and needles far thinner than a level-0
 * cell (all placed, bounded time and memory) and vp_check_particles (known
 * overlaps, outsiders and contacts, spheres and cubes). */
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

static double rad(const vp_particles *p, size_t i) {
    return p->radii ? p->radii[i] : p->uniform_radius;
}

/* Worst pair overlap relative to r_i + r_j, by brute force. */
static double worst_overlap(const vp_particles *p) {
    double worst = -HUGE_VAL;
    for (size_t i = 0; i < p->count; i++)
        for (size_t j = i + 1; j < p->count; j++) {
            const double *a = p->positions + 3 * i, *b = p->positions + 3 * j;
            double d = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                            (a[2] - b[2]) * (a[2] - b[2]));
            double e = rad(p, i) + rad(p, j), o = (e - d) / e;
            if (o > worst) worst = o;
        }
    return worst;
}

/* Largest d(centre) + r over a box [-h, h]^3 (fit inside: must be <= 0). */
static double worst_wall_box(const vp_particles *p, double h) {
    double worst = -HUGE_VAL;
    for (size_t i = 0; i < p->count; i++)
        for (int k = 0; k < 3; k++) {
            double v = fabs(p->positions[3 * i + k]) + rad(p, i) - h;
            if (v > worst) worst = v;
        }
    return worst;
}

static vp_container *unit_box(void) {
    double lo[3] = {-0.5, -0.5, -0.5}, hi[3] = {0.5, 0.5, 0.5};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, hi, &c));
    return c;
}

/* One pass of radius r: count spheres, or maximal when count is 0. */
static void one_pass(vp_rsa_pass *ps, vp_rsa_params *rp, double r, size_t count, uint64_t seed) {
    vp_rsa_pass_init(ps);
    ps->count = count;
    ps->maximal = count == 0;
    vp_size_dist_constant(&ps->radius, r);
    vp_rsa_params_init(rp);
    rp->passes = ps;
    rp->npasses = 1;
    rp->seed = seed;
}

/* Two passes: n0 spheres of radius law r0 (0: maximal), grown or not,
 * then n1 of law r1 (0: maximal). */
static void two_passes(vp_rsa_pass ps[2], vp_rsa_params *rp, const char *r0, size_t n0, int grow0,
                       const char *r1, size_t n1, uint64_t seed) {
    const char *law[2] = {r0, r1};
    size_t n[2] = {n0, n1};
    for (int k = 0; k < 2; k++) {
        vp_rsa_pass_init(&ps[k]);
        ps[k].count = n[k];
        ps[k].maximal = n[k] == 0;
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, law[k], &ps[k].radius));
    }
    ps[0].grow = grow0;
    vp_rsa_params_init(rp);
    rp->passes = ps;
    rp->npasses = 2;
    rp->seed = seed;
}

/* vp_rng_quat is uniform on the 3-sphere: unit length, and the moments of
 * the uniform law, E[q_i^2] = 1/4, E[q_i^4] = 1/8, E[q_i^2 q_j^2] = 1/24
 * and E[q_i] = 0, within 5 standard errors over 400 000 draws. */
static void test_rng_quat(void) {
    const int n = 400000;
    double m1[4] = {0}, m2[4] = {0}, m4[4] = {0}, m22 = 0;
    uint64_t st = vp_rng_stream(7, 3);
    for (int k = 0; k < n; k++) {
        double q[4];
        vp_rng_quat(&st, q);
        ASSERT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1.0, 1e-12);
        for (int i = 0; i < 4; i++) {
            m1[i] += q[i];
            m2[i] += q[i] * q[i];
            m4[i] += q[i] * q[i] * q[i] * q[i];
        }
        m22 += q[0] * q[0] * q[3] * q[3];
    }
    /* standard deviations of one draw: q_i 1/2, q_i^2 sqrt(1/8 - 1/16),
     * q_i^4 sqrt(E q^8 - 1/64) with E q^8 = 105/(4 6 8 10) = 7/128,
     * q_0^2 q_3^2 at most 1/4 */
    double se = 1.0 / sqrt((double)n);
    for (int i = 0; i < 4; i++) {
        ASSERT_NEAR(m1[i] / n, 0.0, 5 * 0.5 * se);
        ASSERT_NEAR(m2[i] / n, 0.25, 5 * sqrt(1.0 / 16) * se);
        ASSERT_NEAR(m4[i] / n, 0.125, 5 * sqrt(7.0 / 128 - 1.0 / 64) * se);
    }
    ASSERT_NEAR(m22 / n, 1.0 / 24, 5 * 0.25 * se);
    fprintf(stderr, "   E q^2 %.4f %.4f %.4f %.4f (1/4), E q^4 %.4f (1/8), E q0^2 q3^2 %.4f (1/24)\n",
            m2[0] / n, m2[1] / n, m2[2] / n, m2[3] / n, m4[0] / n, m22 / n);
}

static void test_size_dist(void) {
    const char *specs[] = {"0.25", "uniform:0.1:0.3", "lognormal:0.2:0.05", "list:0.1:0.2:0.6"};
    for (int s = 0; s < 4; s++) {
        vp_size_dist d;
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, specs[s], &d));
        uint64_t st = 12345;
        double m1 = 0, m3 = 0, lo = HUGE_VAL, hi = 0;
        const int n = 400000;
        double sum2 = 0;
        for (int i = 0; i < n; i++) {
            double r = vp_size_dist_sample(&d, &st);
            m1 += r;
            sum2 += r * r;
            m3 += r * r * r;
            if (r < lo) lo = r;
            if (r > hi) hi = r;
        }
        m1 /= n;
        m3 /= n;
        double sd = sqrt(sum2 / n - m1 * m1);
        fprintf(stderr, "   %s: mean %.5f (expected %.5f), E[r^3] %.6f (%.6f), sd %.5f, range "
                        "[%.4f, %.4f]\n", specs[s], m1, vp_size_dist_mean(&d), m3,
                vp_size_dist_mean_cube(&d), sd, lo, hi);
        ASSERT_NEAR(m1, vp_size_dist_mean(&d), 0.005 * vp_size_dist_mean(&d));
        ASSERT_NEAR(m3, vp_size_dist_mean_cube(&d), 0.01 * vp_size_dist_mean_cube(&d));
        ASSERT_GE(lo, vp_size_dist_min(&d));
        ASSERT_LE(hi, vp_size_dist_max(&d));
        if (s == 1) ASSERT_NEAR(sd, 0.2 / sqrt(12.0), 0.002);        /* uniform */
        if (s == 2) ASSERT_NEAR(sd, 0.05, 0.05 * 0.03);               /* lognormal SD */
        if (s == 3) ASSERT_NEAR(m1, 0.3, 0.003);
    }
    /* formatted as written (shortest text that reads back exactly), and
     * parsed back to the same values */
    const char *fmt[] = {"0.004493", "uniform:0.1:0.3", "lognormal:0.2:0.05", "list:0.1:0.2:0.6",
                         "0.1000000000000000055511151231257827", "1e-30"};
    const char *want[] = {"0.004493", "uniform:0.1:0.3", "lognormal:0.2:0.05", "list:0.1:0.2:0.6",
                          "0.1", "1e-30"};
    for (int s = 0; s < 6; s++) {
        vp_size_dist d, e;
        char buf[256];
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, fmt[s], &d));
        vp_size_dist_format(&d, buf, sizeof buf);
        fprintf(stderr, "   format(%s) = %s\n", fmt[s], buf);
        ASSERT_TRUE(!strcmp(buf, want[s]));
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, buf, &e));
        ASSERT_TRUE(e.kind == d.kind && e.a == d.a && e.b == d.b && e.n == d.n);
        for (unsigned i = 0; i < d.n; i++) ASSERT_TRUE(e.values[i] == d.values[i]);
    }
    {   /* radii are stored as float: every size a law draws must be a normal float */
        vp_size_dist d;
        const char *ok[] = {"1.2e-38", "3.4e38", "uniform:1.2e-38:1", "lognormal:1:0.5"};
        const char *no[] = {"1e-38", "1e-300", "3.5e38", "uniform:1e-39:1", "list:1:1e-40",
                            "lognormal:1e-37:1e-36", "uniform:1:1e39"};
        for (int i = 0; i < 4; i++) ASSERT_OK(ctx, vp_size_dist_parse(ctx, ok[i], &d));
        for (int i = 0; i < 7; i++) {
            ASSERT_EQ_INT(vp_size_dist_parse(ctx, no[i], &d), VP_ERR_INVALID_ARGUMENT);
            ASSERT_TRUE(strstr(vp_context_message(ctx), "float") != NULL);
        }
    }
    {   /* a value that needs 17 digits keeps them */
        vp_size_dist d, e;
        char buf[64];
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, "0.30000000000000004", &d));
        vp_size_dist_format(&d, buf, sizeof buf);
        ASSERT_TRUE(!strcmp(buf, "0.30000000000000004"));
        ASSERT_OK(ctx, vp_size_dist_parse(ctx, buf, &e));
        ASSERT_TRUE(e.a == d.a);
    }
    const char *bad[] = {"-1", "0", "uniform:0.3:0.1", "gamma:1:2", "lognormal:0.1", "list:",
                         "uniform:0.1:nan", "1e400", "0.1x"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        vp_size_dist d;
        ASSERT_EQ_INT(vp_size_dist_parse(ctx, bad[i], &d), VP_ERR_INVALID_ARGUMENT);
        ASSERT_TRUE(strlen(vp_context_message(ctx)) > 0);
    }
}

static void test_rsa_binary_grow(void) {
    vp_container *c = unit_box();
    vp_rsa_pass ps[2];
    vp_rsa_params rp;
    two_passes(ps, &rp, "0.07", 40, 1, "uniform:0.012:0.02", 1200, 5);
    vp_particles *p = NULL;
    vp_rsa_report rep;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
    ASSERT_EQ_INT(p->count, 1240);
    ASSERT_EQ_INT(rep.passes[0].placed, 40);
    ASSERT_EQ_INT(rep.passes[1].placed, 1200);
    ASSERT_EQ_INT(rep.passes[0].stop, VP_RSA_STOP_COUNT);
    ASSERT_EQ_INT(p->group_count, 2);
    ASSERT_TRUE(!strcmp(p->group_names[0], "pass1") && !strcmp(p->group_names[1], "pass2"));
    size_t g0 = 0;
    for (size_t i = 0; i < p->count; i++) g0 += p->groups[i] == 0;
    ASSERT_EQ_INT(g0, 40);
    double wo = worst_overlap(p), ww = worst_wall_box(p, 0.5);
    fprintf(stderr, "   worst overlap %.3g, worst wall %.3g, grow x%.4f\n", wo, ww,
            rep.passes[0].grow_mean);
    ASSERT_LE(wo, 0.0);
    ASSERT_LE(ww, 0.0);
    ASSERT_GE(rep.passes[0].grow_mean, 1.05);
    /* grow: every pass-1 sphere touches a sphere or the wall (gap <= 1e-6),
     * measured against the particles present when it grew (pass 1 only) */
    for (size_t i = 0; i < 40; i++) {
        double gap = 0.5 - (fabs(p->positions[3 * i]) > fabs(p->positions[3 * i + 1])
                                ? fabs(p->positions[3 * i]) : fabs(p->positions[3 * i + 1]));
        double z = 0.5 - fabs(p->positions[3 * i + 2]);
        if (z < gap) gap = z;
        gap -= rad(p, i);
        for (size_t j = 0; j < 40; j++) {
            if (j == i) continue;
            const double *a = p->positions + 3 * i, *b = p->positions + 3 * j;
            double d = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                            (a[2] - b[2]) * (a[2] - b[2])) - rad(p, i) - rad(p, j);
            if (d < gap) gap = d;
        }
        ASSERT_LE(gap, 1e-6);
        ASSERT_GE(gap, 0.0);
    }
    /* the checker agrees */
    vp_check_report cr;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, NULL, &cr));
    ASSERT_EQ_INT(cr.overlapping_pairs, 0);
    ASSERT_EQ_INT(cr.outside, 0);
    ASSERT_GE(cr.contact_pairs, 20); /* 40 grown spheres each touch something */
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

static void test_rsa_retries_and_no_fit(void) {
    vp_container *c = unit_box();
    vp_rsa_pass ps;
    vp_rsa_params rp;
    vp_particles *p = NULL;
    vp_rsa_report rep;
    /* 500 spheres of radius 0.2 fill 16.8 boxes: refused up front */
    one_pass(&ps, &rp, 0.2, 500, 0);
    ASSERT_EQ_INT(vp_pack_rsa(ctx, c, &rp, &p, &rep), VP_ERR_NO_FIT);
    ASSERT_TRUE(p == NULL);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "cannot fit") != NULL);
    /* 1500 of radius 0.05 fill 0.785 of the box: under its volume, over
     * Kepler's 0.7405, which holds in a box */
    one_pass(&ps, &rp, 0.05, 1500, 0);
    ASSERT_EQ_INT(vp_pack_rsa(ctx, c, &rp, &p, &rep), VP_ERR_NO_FIT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "0.7405") != NULL);
    one_pass(&ps, &rp, 0.05, 1400, 0); /* 0.733: packed as far as it goes */
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
    ASSERT_TRUE(rep.passes[0].placed < 1400 && rep.passes[0].stop == VP_RSA_STOP_MAXIMAL);
    vp_particles_destroy(p);
    p = NULL;
    /* 20 fill 0.67 of it, under the bound: packed until the retries end it */
    one_pass(&ps, &rp, 0.2, 20, 0);
    ps.retries = 200;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
    fprintf(stderr, "   radius 0.2, count 20: placed %zu, stop %d, tries %llu\n",
            rep.passes[0].placed, (int)rep.passes[0].stop,
            (unsigned long long)rep.passes[0].tries);
    ASSERT_TRUE(rep.passes[0].placed > 0 && rep.passes[0].placed < 20);
    ASSERT_TRUE(rep.passes[0].stop != VP_RSA_STOP_COUNT);
    ASSERT_LE(worst_overlap(p), 0.0);
    vp_particles_destroy(p);
    /* a radius larger than the box: an error, not an empty packing */
    vp_size_dist_constant(&ps.radius, 0.6);
    ASSERT_EQ_INT(vp_pack_rsa(ctx, c, &rp, &p, &rep), VP_ERR_NO_FIT);
    ASSERT_TRUE(p == NULL);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "radius") != NULL);
    /* retries 0 means the default; negative is refused */
    ps.retries = -1;
    vp_size_dist_constant(&ps.radius, 0.1);
    ASSERT_EQ_INT(vp_pack_rsa(ctx, c, &rp, &p, &rep), VP_ERR_INVALID_ARGUMENT);
    /* two passes of one group name (the first named pass2, the second
     * pass2 by default) are refused before packing: the .vdb writer
     * refused them after it, and CSV merged the two groups */
    vp_rsa_pass two[2];
    vp_rsa_pass_init(&two[0]);
    vp_rsa_pass_init(&two[1]);
    vp_size_dist_constant(&two[0].radius, 0.1);
    vp_size_dist_constant(&two[1].radius, 0.05);
    two[0].count = two[1].count = 5;
    snprintf(two[0].name, sizeof two[0].name, "pass2");
    rp.passes = two;
    rp.npasses = 2;
    ASSERT_EQ_INT(vp_pack_rsa(ctx, c, &rp, &p, &rep), VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(p == NULL);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "passes 1 and 2 have one group name, 'pass2'"));
    snprintf(two[0].name, sizeof two[0].name, "big");
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
    ASSERT_TRUE(!strcmp(p->group_names[0], "big") && !strcmp(p->group_names[1], "pass2"));
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

static void test_rsa_maximal_leaves_no_room(void) {
    double ctr[3] = {0, 0, 0};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, ctr, 1.0, &c));
    const double r = 0.06;
    vp_rsa_pass ps;
    vp_rsa_params rp;
    one_pass(&ps, &rp, r, 0, 11);
    vp_particles *p = NULL;
    vp_rsa_report rep;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
    ASSERT_EQ_INT(rep.passes[0].stop, VP_RSA_STOP_MAXIMAL);
    ASSERT_LE(worst_overlap(p), 0.0);
    /* probe a fine grid (and random points): no admissible centre is free */
    const int n = 90;
    size_t admissible = 0, free_ = 0;
    uint64_t st = 99;
    for (int k = 0; k < n * n * n + 300000; k++) {
        double x[3];
        if (k < n * n * n) {
            x[0] = -1 + 2 * ((k % n) + 0.5) / n;
            x[1] = -1 + 2 * (((k / n) % n) + 0.5) / n;
            x[2] = -1 + 2 * ((k / n / n) + 0.5) / n;
        } else {
            for (int m = 0; m < 3; m++) x[m] = -1 + 2 * vp_rng_uniform(&st);
        }
        if (sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) > 1 - r) continue;
        admissible++;
        int blocked = 0;
        for (size_t i = 0; i < p->count && !blocked; i++) {
            const double *c2 = p->positions + 3 * i;
            double dx = x[0] - c2[0], dy = x[1] - c2[1], dz = x[2] - c2[2];
            blocked = dx * dx + dy * dy + dz * dz < (r + rad(p, i)) * (r + rad(p, i));
        }
        free_ += !blocked;
    }
    double frac = vp_particles_volume(p) / (4.0 / 3.0 * M_PI);
    fprintf(stderr, "   maximal: %zu spheres, fraction %.4f; %zu admissible probes, %zu free\n",
            p->count, frac, admissible, free_);
    ASSERT_EQ_INT(free_, 0);
    ASSERT_GE(admissible, 300000);
    ASSERT_GE(frac, 0.30); /* the wall costs a little against 0.38 in the bulk */
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

/* A count near saturation (0.333 of the box, saturated RSA: 0.384) is
 * reached with the default retries: the sampler refines its cells in count
 * mode too, instead of stopping by retries near 0.30 as plain darts do. */
static void test_rsa_count_near_saturation(void) {
    vp_container *c = unit_box();
    const size_t n = 20000;
    const double r = cbrt(0.333 / (n * 4.0 / 3.0 * M_PI));
    vp_rsa_pass ps;
    vp_rsa_params rp;
    one_pass(&ps, &rp, r, n, 5);
    vp_particles *p = NULL;
    vp_rsa_report rep;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
    fprintf(stderr, "   %zu of %zu placed, stop %d, %llu tries\n", p->count, n, (int)rep.passes[0].stop,
            (unsigned long long)rep.passes[0].tries);
    ASSERT_EQ_INT(rep.passes[0].stop, VP_RSA_STOP_COUNT);
    ASSERT_EQ_INT(p->count, n);
    ASSERT_LE(worst_overlap(p), 0.0);
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

/* A refinement over the cell budget (vp_rsa_params.max_cells) is given
 * up part-way: the parents not yet split and the split ones that kept a
 * child go back to the current level, and plain darts go on. With this
 * seed the level-0 to level-1 split (46 656 parents at 36 251 spheres, 2
 * rounds) runs over 100 000 cells in its second round (75 368 + 32 623):
 * the 13 888 parents not yet split and the first round's parents that
 * kept one of their 75 368 children go back. The packing must stay valid
 * (no overlap, inside, the same for any thread count) and dense: the
 * cells handed back still hold every admissible centre, so with 30 000
 * retries the pass reaches the fraction printed (0.31 at least);
 * handing back only the parents not yet split (a mutation tried on
 * 2026-11-23, when level 0 took 4 darts a cell and the budget here was
 * 140 000) loses the rest of the space and stopped at 0.252. */
static void test_rsa_cell_budget(void) {
    vp_container *c = unit_box();
    vp_rsa_pass ps;
    vp_rsa_params rp;
    one_pass(&ps, &rp, 0.012, 0, 21);
    ps.retries = 30000;
    rp.max_cells = 100000;
    vp_particles *a = NULL, *b = NULL;
    vp_rsa_report rep;
    vp_context_set_threads(ctx, 1);
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &a, &rep));
    vp_context_set_threads(ctx, 2);
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &b, NULL));
    vp_context_set_threads(ctx, 0);
    double frac = vp_particles_volume(a);
    fprintf(stderr, "   budget %zu cells: %zu spheres, fraction %.4f, stop %d, budget hit %d\n",
            rp.max_cells, a->count, frac, (int)rep.passes[0].stop, rep.passes[0].budget_hit);
    ASSERT_EQ_INT(rep.passes[0].budget_hit, 1);
    ASSERT_EQ_INT(rep.passes[0].stop, VP_RSA_STOP_RETRIES);
    ASSERT_EQ_INT(a->count, b->count);
    ASSERT_TRUE(!memcmp(a->positions, b->positions, 3 * a->count * sizeof(double)));
    ASSERT_LE(worst_overlap(a), 0.0);
    ASSERT_LE(worst_wall_box(a, 0.5), 0.0);
    ASSERT_GE(frac, 0.31);
    vp_particles_destroy(a);
    vp_particles_destroy(b);
    /* the automatic budget is not reached by the same pass */
    rp.max_cells = 0;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &a, &rep));
    ASSERT_EQ_INT(rep.passes[0].budget_hit, 0);
    ASSERT_EQ_INT(rep.passes[0].stop, VP_RSA_STOP_MAXIMAL);
    fprintf(stderr, "   automatic budget: %zu spheres, fraction %.4f\n", a->count,
            vp_particles_volume(a));
    vp_particles_destroy(a);
    vp_container_destroy(c);
}

/* Largest |x_k| + r - h_k over the particles (fit inside the box of
 * half sides h: must be <= 0), relative to the radius r0. */
static double worst_wall_aabb(const vp_particles *p, const double h[3], double r0) {
    double worst = -HUGE_VAL;
    for (size_t i = 0; i < p->count; i++)
        for (int k = 0; k < 3; k++) {
            double v = (fabs(p->positions[3 * i + k]) + rad(p, i) - h[k]) / r0;
            if (v > worst) worst = v;
        }
    return worst;
}

/* n spheres of radius 0.4 t in the box t x 1 x 1 (or t x t x 1, a
 * needle): every one placed (stop count), no overlap, inside, in a child
 * bounded to 30 s and 1.5 GB. Before the fix, the level-0 cells were sized
 * from the volume and tiled the slab with cubes far thicker than it:
 * t = 1e-20 made 1e16 cells (24 GB, killed), t = 1e-8 placed none, t =
 * 1e-6 placed 3 of 50 (5000 tries in a row failed: a dart fell in the
 * slab once in 10^4). */
static double thin_t;
static size_t thin_n;
static int thin_needle;
static vp_shape thin_shape;

static void thin_case(void) {
    double t = thin_t, r = 0.4 * t;
    double h[3] = {0.5 * t, thin_needle ? 0.5 * t : 0.5, 0.5};
    double lo[3] = {-h[0], -h[1], -h[2]};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, h, &c));
    vp_rsa_pass ps;
    vp_rsa_params rp;
    one_pass(&ps, &rp, r, thin_n, 7);
    rp.shape = thin_shape;
    vp_particles *p = NULL;
    vp_rsa_report rep;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    fprintf(stderr, "   %s%s %g, r %g: placed %zu of %zu, stop %d, %llu tries, peak %ld MB\n",
            thin_shape == VP_SHAPE_CUBE ? "cubes, " : "", thin_needle ? "needle" : "slab", t, r, rep.passes[0].placed, thin_n,
            (int)rep.passes[0].stop, (unsigned long long)rep.passes[0].tries,
            ru.ru_maxrss / 1024);
    ASSERT_EQ_INT(rep.passes[0].stop, VP_RSA_STOP_COUNT);
    ASSERT_EQ_INT(p->count, thin_n);
    if (thin_shape == VP_SHAPE_SPHERE) ASSERT_LE(worst_overlap(p), 0.0);
    ASSERT_LE(worst_wall_aabb(p, h, r), 1e-9);
    /* the darts are drawn in the slab: few fail (each fails with the
     * chance that it lands within 2r of a placed centre, or, for a
     * solid, too near the wall for its orientation) */
    ASSERT_LE((double)rep.passes[0].tries, 4.0 * (double)thin_n + 100.0);
    /* 10 particles: the memory of the packer, not of a grid (the test's
     * own baseline is about 40 MB; the 1e-7 slab took 690 MB before) */
    if (!VP_TEST_SANITIZED) ASSERT_LE((double)ru.ru_maxrss, 200.0 * 1024);
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

static void test_rsa_thin_containers(void) {
    const double ts[] = {1e-20, 1e-10, 1e-8, 1e-7, 1e-6, 1e-3};
    for (size_t i = 0; i < sizeof ts / sizeof ts[0]; i++) {
        thin_t = ts[i];
        thin_n = ts[i] == 1e-6 ? 50 : 10;
        thin_needle = 0;
        thin_shape = VP_SHAPE_SPHERE;
        vp_test_bounded(thin_case, 30, 1500ull << 20);
    }
    thin_t = 1e-8; /* a needle: two thin axes */
    thin_n = 10;
    thin_needle = 1;
    vp_test_bounded(thin_case, 30, 1500ull << 20);
    thin_t = 1e-6; /* a solid in a slab */
    thin_n = 50;
    thin_needle = 0;
    thin_shape = VP_SHAPE_CUBE;
    vp_test_bounded(thin_case, 30, 1500ull << 20);
}

/* A maximal pass in a slab 2.5 radii thick (one layer): no overlap,
 * inside, stop maximal, and denser than a quarter of the slab's area in
 * disks of the radius (2D RSA saturates at 0.547 of the area for disks
 * that must not overlap; here the centres may also move across the
 * slab, so disks of radius r*sqrt(1 - (0.25)^2) bound it from below). */
static void test_rsa_thin_maximal(void) {
    double t = 1e-6, r = 0.4 * t, w = 2e-5;
    double h[3] = {0.5 * t, 0.5 * w, 0.5 * w}, lo[3] = {-h[0], -h[1], -h[2]};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_box(ctx, lo, h, &c));
    vp_rsa_pass ps;
    vp_rsa_params rp;
    one_pass(&ps, &rp, r, 0, 3);
    vp_particles *p = NULL;
    vp_rsa_report rep;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
    double area = (w - 2 * r) * (w - 2 * r), disk = 3.14159265358979 * r * r;
    fprintf(stderr, "   slab %g x %g x %g, r %g, maximal: %zu spheres, %.3f of the area in disks\n",
            t, w, w, r, p->count, (double)p->count * disk / area);
    ASSERT_EQ_INT(rep.passes[0].stop, VP_RSA_STOP_MAXIMAL);
    ASSERT_LE(worst_overlap(p), 0.0);
    ASSERT_LE(worst_wall_aabb(p, h, r), 1e-9);
    ASSERT_GE((double)p->count * disk / area, 0.25);
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

/* Mean distance between particles i and i + lag of [first, last). */
static double mean_step(const vp_particles *p, size_t first, size_t last, size_t lag) {
    double sum = 0.0;
    for (size_t i = first; i + lag < last; i++) {
        const double *a = p->positions + 3 * i, *b = p->positions + 3 * (i + lag);
        sum += sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                    (a[2] - b[2]) * (a[2] - b[2]));
    }
    return sum / (double)(last - first - lag);
}

/* Passes that refine their cells renumber their particles in the order of
 * the neighbour grid's cells (positions, radii and, for solids,
 * orientations move together; tests/test_rsa_solids checks cubes): a
 * maximal pass and a size distribution after it, brute-force checked,
 * each pass's particles still together, consecutive particles close in
 * space. A pass that grows keeps placement order (random in space). */
static void test_rsa_grid_order(void) {
    /* enough spheres in the second pass that its level-0 darts (8 a cell)
     * do not place them all: it splits, and renumbers before it does */
    enum { N2 = 40000 };
    vp_container *c = unit_box();
    vp_rsa_pass ps[2];
    vp_rsa_params rp;
    two_passes(ps, &rp, "0.03", 0, 0, "uniform:0.006:0.01", N2, 8);
    for (int grow = 0; grow < 2; grow++) {
        ps[0].grow = grow;
        vp_particles *p = NULL;
        vp_rsa_report rep;
        ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &p, &rep));
        size_t n1 = rep.passes[0].placed;
        ASSERT_EQ_INT(rep.passes[1].placed, N2);
        ASSERT_EQ_INT(p->count, n1 + N2);
        ASSERT_LE(worst_overlap(p), 0.0);
        ASSERT_LE(worst_wall_box(p, 0.5), 0.0);
        for (size_t i = 0; i < p->count; i++) {
            ASSERT_EQ_INT(p->groups[i], i < n1 ? 0 : 1);
            if (i >= n1) ASSERT_TRUE(p->radii[i] >= 0.006f && p->radii[i] <= 0.01f);
            else if (!grow) ASSERT_TRUE(p->radii[i] == (float)0.03);
        }
        /* consecutive particles against particles half a pass apart */
        double r0 = mean_step(p, 0, n1, 1) / mean_step(p, 0, n1, n1 / 2),
               r1 = mean_step(p, n1, p->count, 1) / mean_step(p, n1, p->count, N2 / 2);
        fprintf(stderr, "   grow %d: %zu + %d spheres; step ratio %.3f, %.3f\n", grow, n1, N2,
                r0, r1);
        if (grow) ASSERT_GE(r0, 0.8);
        else ASSERT_LE(r0, 0.3);
        ASSERT_LE(r1, 0.6); /* the spheres placed after its last split follow in placement order */
        vp_particles_destroy(p);
    }
    vp_container_destroy(c);
}

static void test_rsa_deterministic(void) {
    vp_container *c = unit_box();
    vp_rsa_pass ps[2];
    vp_rsa_params rp;
    two_passes(ps, &rp, "0.05", 100, 1, "0.02", 0, 3);
    vp_particles *a = NULL, *b = NULL;
    vp_context_set_threads(ctx, 1);
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &a, NULL));
    vp_context_set_threads(ctx, 2);
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &b, NULL));
    vp_context_set_threads(ctx, 0);
    ASSERT_EQ_INT(a->count, b->count);
    ASSERT_TRUE(!memcmp(a->positions, b->positions, 3 * a->count * sizeof(double)));
    ASSERT_TRUE(!memcmp(a->radii, b->radii, a->count * sizeof(float)));
    vp_particles_destroy(b);
    rp.seed = 4;
    ASSERT_OK(ctx, vp_pack_rsa(ctx, c, &rp, &b, NULL));
    ASSERT_TRUE(a->count != b->count ||
                memcmp(a->positions, b->positions, 3 * a->count * sizeof(double)));
    vp_particles_destroy(a);
    vp_particles_destroy(b);
    vp_container_destroy(c);
}

static void test_relax(void) {
    double ctr[3] = {0, 0, 0};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, ctr, 1.0, &c));
    vp_relax_params xp;
    vp_relax_params_init(&xp);
    ASSERT_OK(ctx, vp_size_dist_parse(ctx, "uniform:0.5:1", &xp.radius));
    xp.count = 1500;
    xp.target_fraction = 0.55;
    xp.seed = 8;
    vp_particles *p = NULL;
    vp_relax_report rep;
    ASSERT_OK(ctx, vp_pack_relax(ctx, c, &xp, &p, &rep));
    double wo = worst_overlap(p), ww = -HUGE_VAL;
    for (size_t i = 0; i < p->count; i++) {
        const double *x = p->positions + 3 * i;
        double v = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) + rad(p, i) - 1.0;
        if (v > ww) ww = v;
    }
    double frac = vp_particles_volume(p) / (4.0 / 3.0 * M_PI);
    fprintf(stderr, "   relax: %d sweeps, worst overlap %.3g (reported %.3g), worst wall %.3g, "
                    "fraction %.4f (%.4f before), radius scale %.4f\n", rep.sweeps, wo,
            rep.max_overlap, ww, frac, rep.initial_fraction, rep.radius_scale);
    ASSERT_LE(wo, 1e-6);
    ASSERT_LE(rep.max_overlap, 1e-6);
    ASSERT_LE(ww, 1e-12);
    ASSERT_NEAR(rep.initial_fraction, 0.55, 1e-9);
    ASSERT_TRUE(rep.radius_scale > 0.9 && rep.radius_scale <= 1.0);
    ASSERT_NEAR(frac, 0.55 * pow(rep.radius_scale, 3), 1e-4);
    vp_particles_destroy(p);
    /* centre fit: no centre outside, no overlap (a radius step alone cannot
     * bring a centre back: this caught that) */
    xp.fit = VP_FIT_CENTER;
    vp_size_dist_constant(&xp.radius, 0.1);
    xp.count = 600;
    xp.target_fraction = 0.6;
    ASSERT_OK(ctx, vp_pack_relax(ctx, c, &xp, &p, &rep));
    double cw = -HUGE_VAL;
    for (size_t i = 0; i < p->count; i++) {
        const double *x = p->positions + 3 * i;
        double v = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - 1.0;
        if (v > cw) cw = v;
    }
    fprintf(stderr, "   relax, centre fit: worst centre %.3g outside, worst overlap %.3g\n", cw,
            worst_overlap(p));
    ASSERT_LE(cw, 1e-12);
    ASSERT_LE(worst_overlap(p), 1e-6);
    vp_particles_destroy(p);
    xp.fit = VP_FIT_INSIDE;
    /* more volume than any packing can hold: refused */
    xp.target_fraction = 0;
    vp_size_dist_constant(&xp.radius, 0.5);
    xp.count = 100;
    ASSERT_EQ_INT(vp_pack_relax(ctx, c, &xp, &p, &rep), VP_ERR_NO_FIT);
    ASSERT_TRUE(p == NULL);
    xp.target_fraction = 1.0;
    ASSERT_EQ_INT(vp_pack_relax(ctx, c, &xp, &p, &rep), VP_ERR_INVALID_ARGUMENT);
    vp_container_destroy(c);
}

/* Relax with a margin and a gap: brute force over pairs and the analytic
 * wall finds both kept, for both fits; a gap as large as the radii and a
 * negative margin are refused. */
static void test_relax_margin_gap(void) {
    double ctr[3] = {0, 0, 0};
    vp_container *c = NULL;
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, ctr, 1.0, &c));
    for (int f = 0; f < 2; f++) {
        vp_relax_params xp;
        vp_relax_params_init(&xp);
        xp.fit = f ? VP_FIT_CENTER : VP_FIT_INSIDE;
        vp_size_dist_constant(&xp.radius, 0.08);
        xp.count = 800;
        xp.target_fraction = 0.45;
        xp.seed = 5;
        xp.margin = 0.06;
        xp.gap = 0.012;
        vp_particles *p = NULL;
        vp_relax_report rep;
        ASSERT_OK(ctx, vp_pack_relax(ctx, c, &xp, &p, &rep));
        double least_gap = HUGE_VAL, least_margin = HUGE_VAL;
        for (size_t i = 0; i < p->count; i++) {
            const double *x = p->positions + 3 * i;
            double d = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) - 1.0;
            least_margin = fmin(least_margin, f ? -d : -d - rad(p, i));
            for (size_t j = i + 1; j < p->count; j++) {
                const double *y = p->positions + 3 * j;
                double e = sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                                (x[2] - y[2]) * (x[2] - y[2]));
                least_gap = fmin(least_gap, e - rad(p, i) - rad(p, j));
            }
        }
        fprintf(stderr, "   relax, fit %s, margin 0.06, gap 0.012: least margin %.9g, least gap "
                        "%.9g, radius scale %.4f, %d sweeps\n", f ? "center" : "inside",
                least_margin, least_gap, rep.radius_scale, rep.sweeps);
        ASSERT_TRUE(least_margin >= 0.06 * (1 - 1e-9));
        ASSERT_TRUE(least_gap >= 0.012 * (1 - 1e-6));
        ASSERT_TRUE(least_gap < 0.012 * 1.05); /* some pair at the gap: it shaped the packing */
        vp_particles_destroy(p);
    }
    vp_relax_params xp;
    vp_relax_params_init(&xp);
    vp_size_dist_constant(&xp.radius, 0.08);
    xp.count = 100;
    xp.gap = 0.08;
    vp_particles *p = NULL;
    ASSERT_EQ_INT(vp_pack_relax(ctx, c, &xp, &p, NULL), VP_ERR_INVALID_ARGUMENT);
    xp.gap = 0;
    xp.margin = -1;
    ASSERT_EQ_INT(vp_pack_relax(ctx, c, &xp, &p, NULL), VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(p == NULL);
    vp_container_destroy(c);
}

static void test_check_known_cases(void) {
    vp_container *c = unit_box();
    vp_particles *p = NULL;
    ASSERT_OK(ctx, vp_particles_create(ctx, 4, &p));
    p->radii = malloc(4 * sizeof(float));
    p->count = 4;
    double pos[4][3] = {{-0.2, 0, 0}, {0.0, 0, 0}, {0.3, 0, 0}, {0, 0.45, 0}};
    float r[4] = {0.1f, 0.1f, 0.1f, 0.1f};
    memcpy(p->positions, pos, sizeof pos);
    memcpy(p->radii, r, sizeof r);
    /* 0-1 touch exactly (d = 0.2); 1-2 gap 0.1; 3 crosses the wall by 0.05 */
    vp_check_report rep;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, NULL, &rep));
    ASSERT_EQ_INT(rep.overlapping_pairs, 0);
    ASSERT_EQ_INT(rep.contact_pairs, 1);
    ASSERT_EQ_INT(rep.outside, 1);
    ASSERT_NEAR(rep.max_outside, 0.05, 1e-7);
    ASSERT_NEAR(rep.mean_contacts, 0.5, 1e-12);
    ASSERT_NEAR(rep.fraction, 4 * 4.0 / 3.0 * M_PI * pow(0.1f, 3), 1e-9);
    /* centre fit: 3 is inside */
    vp_check_params cp;
    vp_check_params_init(&cp);
    cp.fit = VP_FIT_CENTER;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &rep));
    ASSERT_EQ_INT(rep.outside, 0);
    /* overlap 1 and 2 by 0.02 of r_i + r_j */
    p->positions[6] = 0.2 * (1 - 0.02);
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, NULL, &rep));
    ASSERT_EQ_INT(rep.overlapping_pairs, 1);
    ASSERT_NEAR(rep.max_overlap, 0.02, 1e-6);
    ASSERT_NEAR(rep.max_overlap_world, 0.004, 1e-7);
    cp.fit = VP_FIT_INSIDE;
    cp.overlap_tolerance = 0.03;
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, &cp, &rep));
    ASSERT_EQ_INT(rep.overlapping_pairs, 0);
    /* cubes: face to face touching is no overlap; turned 45 degrees about z,
     * the second one's edge enters the first */
    p->shape = VP_SHAPE_CUBE;
    p->has_orient = 1;
    double s = 0.1, half = s / sqrt(3.0); /* circumradius 0.1: half edge 0.1/sqrt(3) */
    double cpos[4][3] = {{0, 0, 0}, {2 * half, 0, 0}, {-0.3, -0.3, -0.3}, {0.3, 0.3, 0.3}};
    memcpy(p->positions, cpos, sizeof cpos);
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, NULL, &rep));
    ASSERT_EQ_INT(rep.overlapping_pairs, 0);
    ASSERT_EQ_INT(rep.contact_pairs, 1);
    ASSERT_EQ_INT(rep.outside, 0);
    p->orients = malloc(16 * sizeof(float));
    for (int i = 0; i < 4; i++) {
        float q[4] = {0, 0, 0, 1};
        if (i == 1) q[2] = (float)sin(M_PI / 8), q[3] = (float)cos(M_PI / 8);
        memcpy(p->orients + 4 * i, q, sizeof q);
    }
    ASSERT_OK(ctx, vp_check_particles(ctx, c, p, NULL, &rep));
    fprintf(stderr, "   turned cube: overlap %.4f of the radius\n", rep.max_overlap);
    ASSERT_EQ_INT(rep.overlapping_pairs, 1);
    /* penetration: the edge reaches half * sqrt(2) - half beyond the face */
    ASSERT_NEAR(rep.max_overlap_world, half * (sqrt(2.0) - 1), 1e-6);
    vp_particles_destroy(p);
    vp_container_destroy(c);
}

int main(void) {
    ASSERT_OK(NULL, vp_context_create(&ctx));
    RUN_TEST(test_rng_quat);
    RUN_TEST(test_size_dist);
    RUN_TEST(test_rsa_binary_grow);
    RUN_TEST(test_rsa_retries_and_no_fit);
    RUN_TEST(test_rsa_maximal_leaves_no_room);
    RUN_TEST(test_rsa_count_near_saturation);
    RUN_TEST(test_rsa_deterministic);
    RUN_TEST(test_rsa_grid_order);
    RUN_TEST(test_rsa_cell_budget);
    RUN_TEST(test_rsa_thin_containers);
    RUN_TEST(test_rsa_thin_maximal);
    RUN_TEST(test_relax);
    RUN_TEST(test_relax_margin_gap);
    RUN_TEST(test_check_known_cases);
    vp_context_destroy(ctx);
    fprintf(stderr, "PASS\n");
    return 0;
}
