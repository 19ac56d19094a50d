/* SPDX-License-Identifier: Apache-2.0 */
/* RSA figures of issue 3, each case in its own process (peak memory):
 *  1. one radius 0.0043 in a unit box, count 1e6 x SCALE, default retries:
 *     placed, stop reason, accepted particles per second, fraction;
 *  2. maximal mode, radius giving about 1e6 x SCALE particles: time, fraction;
 *  3. binary with grow against one radius (maximal, same small radius);
 *  4. the reference, timed in the same run: textbook RSA (uniform darts in
 *     the box, a cell grid, the same retry limit) at the case-1 radius.
 * Memory: (peak RSS - RSS before packing) / particles.
 * Usage: build/bench/bench_rsa [SCALE]   (default 1; 0.1 for a quick run)
 * No pass/fail: figures and ratios are printed for the notes. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdint.h>

#include "bench_random_common.h"
#include "core/rng.h"

static double g_scale = 1.0;

static vp_container *unit_box(vp_context *ctx) {
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    vp_container *c = NULL;
    vp_container_create_box(ctx, lo, hi, &c);
    return c;
}

static const char *stop_name(vp_rsa_stop s) {
    return s == VP_RSA_STOP_COUNT ? "count" : s == VP_RSA_STOP_RETRIES ? "retries" : "maximal";
}

typedef struct rsa_case {
    const char *name;
    int npasses;
    vp_rsa_pass passes[2];
} rsa_case;

static void run_case(void *arg) {
    rsa_case *k = arg;
    vp_context *ctx = NULL;
    vp_context_create(&ctx);
    vp_container *c = unit_box(ctx);
    long before = bench_status_kb("VmRSS:");
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.passes = k->passes;
    rp.npasses = (size_t)k->npasses;
    rp.seed = 1;
    vp_particles *p = NULL;
    vp_rsa_report rep;
    double t0 = bench_now();
    if (vp_pack_rsa(ctx, c, &rp, &p, &rep) != VP_OK) {
        printf("%s: error: %s\n", k->name, vp_context_message(ctx));
        return;
    }
    double t = bench_now() - t0;
    long peak = bench_status_kb("VmHWM:");
    double frac = vp_particles_volume(p); /* unit box */
    printf("%-26s %9zu particles, fraction %.4f, %.2f s, %.0f particles/s, peak %.1f B/particle",
           k->name, p->count, frac, t, p->count / t, (peak - before) * 1024.0 / p->count);
    for (int i = 0; i < k->npasses; i++)
        printf("%s pass%d: %zu placed, stop %s", i ? ";" : " |", i + 1, rep.passes[i].placed,
               stop_name(rep.passes[i].stop));
    printf("\n");
    vp_particles_destroy(p);
    vp_container_destroy(c);
    vp_context_destroy(ctx);
}

/* Textbook RSA: uniform darts in [r, 1-r]^3, a dense cell grid of side 2r
 * holding up to 8 particles per cell, stop at n or `retries` failures in a
 * row. */
typedef struct naive_arg {
    double r;
    size_t n;
    int retries;
} naive_arg;

static void run_naive(void *arg) {
    naive_arg *a = arg;
    double r = a->r, h = 2 * r;
    int dim = (int)ceil(1.0 / h);
    size_t cells = (size_t)dim * dim * dim;
    uint32_t *cnt = calloc(cells, sizeof *cnt);
    float(*pos)[8][3] = malloc(cells * sizeof *pos);
    uint64_t st = 7;
    size_t placed = 0;
    int fails = 0;
    double t0 = bench_now();
    while (placed < a->n && fails < a->retries) {
        double x[3];
        for (int k = 0; k < 3; k++) x[k] = r + (1 - 2 * r) * vp_rng_uniform(&st);
        int ci[3];
        for (int k = 0; k < 3; k++) ci[k] = (int)(x[k] / h) < dim ? (int)(x[k] / h) : dim - 1;
        int ok = 1;
        for (int dz = -1; dz <= 1 && ok; dz++)
            for (int dy = -1; dy <= 1 && ok; dy++)
                for (int dx = -1; dx <= 1 && ok; dx++) {
                    int X = ci[0] + dx, Y = ci[1] + dy, Z = ci[2] + dz;
                    if (X < 0 || Y < 0 || Z < 0 || X >= dim || Y >= dim || Z >= dim) continue;
                    size_t c = ((size_t)Z * dim + Y) * dim + X;
                    for (uint32_t m = 0; m < cnt[c] && ok; m++) {
                        double ex = x[0] - pos[c][m][0], ey = x[1] - pos[c][m][1],
                               ez = x[2] - pos[c][m][2];
                        ok = ex * ex + ey * ey + ez * ez >= 4 * r * r;
                    }
                }
        if (!ok) {
            fails++;
            continue;
        }
        fails = 0;
        size_t c = ((size_t)ci[2] * dim + ci[1]) * dim + ci[0];
        if (cnt[c] < 8) {
            for (int k = 0; k < 3; k++) pos[c][cnt[c]][k] = (float)x[k];
            cnt[c]++;
        }
        placed++;
    }
    double t = bench_now() - t0;
    printf("%-26s %9zu particles, fraction %.4f, %.2f s, %.0f particles/s (stop %s)\n",
           "reference: textbook RSA", placed, placed * 4.0 / 3.0 * M_PI * r * r * r, t, placed / t,
           placed >= a->n ? "count" : "retries");
    free(cnt);
    free(pos);
}

int main(int argc, char **argv) {
    if (argc > 1) g_scale = atof(argv[1]);
    if (!(g_scale > 0)) g_scale = 1;
    double s3 = cbrt(g_scale);
    printf("bench_rsa: scale %g (1 = the issue's 1e6-particle figures)\n", g_scale);
    /* 1. one radius, count */
    rsa_case one = {"rsa count, one radius", 1, {{0}}};
    vp_rsa_pass_init(&one.passes[0]);
    one.passes[0].count = (size_t)(1e6 * g_scale);
    vp_size_dist_constant(&one.passes[0].radius, 0.0043 / s3);
    bench_fork(run_case, &one);
    naive_arg na = {0.0043 / s3, (size_t)(1e6 * g_scale), VP_RSA_DEFAULT_RETRIES};
    bench_fork(run_naive, &na);
    /* 2. maximal */
    double rmax = cbrt(0.38 / (1e6 * g_scale * 4.0 / 3.0 * M_PI));
    rsa_case mx = {"rsa maximal", 1, {{0}}};
    vp_rsa_pass_init(&mx.passes[0]);
    mx.passes[0].maximal = 1;
    vp_size_dist_constant(&mx.passes[0].radius, rmax);
    bench_fork(run_case, &mx);
    /* 3. binary with grow vs one radius (same smallest radius) */
    double rs = 0.01 / s3;
    rsa_case single = {"one radius (maximal)", 1, {{0}}};
    vp_rsa_pass_init(&single.passes[0]);
    single.passes[0].maximal = 1;
    vp_size_dist_constant(&single.passes[0].radius, rs);
    bench_fork(run_case, &single);
    rsa_case bin = {"binary: 4r grown + maximal", 2, {{0}}};
    vp_rsa_pass_init(&bin.passes[0]);
    vp_rsa_pass_init(&bin.passes[1]);
    bin.passes[0].count = (size_t)(0.3 / (4.0 / 3.0 * M_PI * pow(4 * rs, 3)));
    vp_size_dist_constant(&bin.passes[0].radius, 4 * rs);
    bin.passes[0].grow = 1;
    bin.passes[1].maximal = 1;
    vp_size_dist_constant(&bin.passes[1].radius, rs);
    bench_fork(run_case, &bin);
    printf("targets (issue 3): count case all placed at >= 250k particles/s; maximal <= 10 s "
           "at fraction >= 0.37; binary >= one radius + 0.05; <= 64 B/particle\n");
    return 0;
}
