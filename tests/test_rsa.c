/* SPDX-License-Identifier: Apache-2.0 */
/* RSA of spheres through the public API, on exact analytic containers,
 * verified by brute force (every pair, every particle against the analytic
 * wall), never by the checker alone: zero overlaps, inside, groups, count
 * and retry semantics, grow makes contacts, maximal leaves no room on a
 * fine probe grid, determinism across thread counts, particles in grid
 * order after refinements, a refinement given up over the cell budget. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "random_util.h"
#include "vp_test.h"

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
                                ? fabs(p->positions[3 * i])
                                : fabs(p->positions[3 * i + 1]));
        double z = 0.5 - fabs(p->positions[3 * i + 2]);
        if (z < gap) gap = z;
        gap -= rad(p, i);
        for (size_t j = 0; j < 40; j++) {
            if (j == i) continue;
            const double *a = p->positions + 3 * i, *b = p->positions + 3 * j;
            double d = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                            (a[2] - b[2]) * (a[2] - b[2])) -
                       rad(p, i) - rad(p, j);
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
            rep.passes[0].placed, (int)rep.passes[0].stop, (unsigned long long)rep.passes[0].tries);
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
    fprintf(stderr, "   %zu of %zu placed, stop %d, %llu tries\n", p->count, n,
            (int)rep.passes[0].stop, (unsigned long long)rep.passes[0].tries);
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
 * handing back only the parents not yet split (a mutation tried when
 * level 0 took 4 darts a cell and the budget here was 140 000) loses the rest of the space and stopped at 0.252. */
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
        fprintf(stderr, "   grow %d: %zu + %d spheres; step ratio %.3f, %.3f\n", grow, n1, N2, r0,
                r1);
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

int main(void) {
    ASSERT_OK(NULL, vp_context_create(&ctx));
    RUN_TEST(test_rsa_binary_grow);
    RUN_TEST(test_rsa_retries_and_no_fit);
    RUN_TEST(test_rsa_maximal_leaves_no_room);
    RUN_TEST(test_rsa_count_near_saturation);
    RUN_TEST(test_rsa_deterministic);
    RUN_TEST(test_rsa_grid_order);
    RUN_TEST(test_rsa_cell_budget);
    vp_context_destroy(ctx);
    fprintf(stderr, "PASS\n");
    return 0;
}
