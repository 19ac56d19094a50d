/* SPDX-License-Identifier: Apache-2.0 */
/* Jammed packing figures of issue 28, each case in its own process.
 * Usage: build/bench/bench_jam [--seed S | --seed A-B] [--threads N] [CASE...]
 *   (default: every case, seed 1, every core; cases run in the order named,
 *   each seed in turn, so `relax100k box100k box1M relax100k` brackets the
 *   boxes with the reference; names below). Two builds compare best when
 *   both run at once with --threads 1, one on each core: the machine's
 *   speed then moves under both alike.
 * Memory: (peak RSS - RSS before packing) / particles.
 *
 * The reference measured in the same run: case relax100k is the issue's
 * own baseline (`--method relax`, 100 000 equal spheres in box:1,1,1,
 * --target-fraction 0.64, seed 1 whatever --seed says), which the issue
 * reports as 0.601 in 29 s on this machine when it was filed. This
 * machine's speed moves by half from hour to hour, so each box100k and
 * box1M time over relax100k's
 * (the mean of its runs), times 29 s, is printed at the end when both ran:
 * the time at the hour, against its 30 s and 5 minutes. The ratio
 * itself moves by a quarter from run to run (relax waits on memory more
 * than jam does; docs/jam.md). */
#define _DEFAULT_SOURCE /* MAP_ANONYMOUS */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#include "bench_random_common.h"

typedef struct jam_case {
    const char *name;
    int kind; /* 0 unit box, 1 sphere of radius R r (R = param), 2 mesh file,
               * 3 the relax reference in a unit box */
    double param;
    const char *dist; /* --radius text */
    size_t count;
    const char *file;
    int threads; /* --threads; 0: every core */
    uint64_t seed;
    double *seconds; /* shared with the parent: the packing's time, or -1 */
} jam_case;

/* The baseline: relax, 100 000 spheres, target fraction 0.64. */
static void run_relax(jam_case *k, vp_context *ctx, vp_container *c) {
    vp_relax_params xp;
    vp_relax_params_init(&xp);
    vp_size_dist_constant(&xp.radius, 1.0);
    xp.count = k->count;
    xp.target_fraction = 0.64;
    xp.seed = 1; /* the run, whatever --seed asks of the jam cases */
    vp_container_info ci;
    vp_container_get_info(c, &ci);
    vp_particles *p = NULL;
    vp_relax_report rep;
    double t0 = bench_now();
    vp_result res = vp_pack_relax(ctx, c, &xp, &p, &rep);
    double t = bench_now() - t0;
    if (res != VP_OK) {
        printf("%s: error: %s\n", k->name, vp_context_message(ctx));
        return;
    }
    printf("%-20s seed %-3llu %8zu spheres  fraction %.4f  %7.2f s  [relax, %d sweeps; the "
           "issue: 0.601 in 29 s]\n",
           k->name, (unsigned long long)xp.seed, p->count, vp_particles_volume(p) / ci.volume, t,
           rep.sweeps);
    *k->seconds = t;
    vp_particles_destroy(p);
}

static void run_case(void *arg) {
    jam_case *k = arg;
    vp_context *ctx = NULL;
    vp_context_create(&ctx);
    if (k->threads) vp_context_set_threads(ctx, k->threads);
    vp_jam_params jp;
    vp_jam_params_init(&jp);
    jp.count = k->count;
    jp.seed = k->seed;
    if (vp_size_dist_parse(ctx, k->dist, &jp.radius) != VP_OK) {
        printf("%s: bad distribution %s\n", k->name, k->dist);
        return;
    }
    vp_container *c = NULL;
    double zero[3] = {0, 0, 0}, lo[3] = {-0.5, -0.5, -0.5}, hi[3] = {0.5, 0.5, 0.5};
    vp_result res;
    if (k->kind == 1) {
        /* the radius that fills 0.64 of a sphere of radius R r with count spheres */
        res = vp_container_create_sphere(ctx, zero, 1.0, &c);
    } else if (k->kind == 2) {
        vp_container_params cp;
        vp_container_params_init(&cp);
        vp_container_params_for_jam(&cp, &jp);
        res = vp_container_load(ctx, k->file, &cp, &c);
    } else {
        res = vp_container_create_box(ctx, lo, hi, &c);
    }
    if (res != VP_OK) {
        printf("%s: container: %s\n", k->name, vp_context_message(ctx));
        return;
    }
    if (k->kind == 3) {
        run_relax(k, ctx, c);
        vp_container_destroy(c);
        vp_context_destroy(ctx);
        return;
    }
    vp_container_info ci;
    vp_container_get_info(c, &ci);
    long before = bench_status_kb("VmRSS:");
    vp_particles *p = NULL;
    vp_jam_report rep;
    double t0 = bench_now();
    res = vp_pack_jam(ctx, c, &jp, &p, &rep);
    double t = bench_now() - t0;
    if (res != VP_OK) {
        printf("%s: error: %s\n", k->name, vp_context_message(ctx));
        return;
    }
    long peak = bench_status_kb("VmHWM:");
    printf("%-20s seed %-3llu %8zu spheres  fraction %.4f  core %.4f (%zu)  Z %.3f  rattlers %.3f  "
           "%7.2f s  %.0f B/particle  [%d minimisations, %ld steps, %d lists]\n",
           k->name, (unsigned long long)k->seed, rep.count, rep.fraction, rep.core_fraction,
           rep.core_count, rep.mean_contacts, rep.rattler_fraction, t,
           (peak - before) * 1024.0 / rep.count, rep.minimizations, rep.iterations,
           rep.list_builds);
    *k->seconds = t;
    fflush(stdout);
    vp_particles_destroy(p);
    vp_container_destroy(c);
    vp_context_destroy(ctx);
}

int main(int argc, char **argv) {
    static jam_case cases[] = {
        {"box10k", 0, 0, "1", 10000, NULL},
        {"box100k", 0, 0, "1", 100000, NULL},
        {"box1M", 0, 0, "1", 1000000, NULL},
        {"sphere20r", 1, 20, "1", 5120, NULL},  /* 0.64 * 20^3 */
        {"sphere40r", 1, 40, "1", 40960, NULL}, /* 0.64 * 40^3 */
        {"lognormal100k", 0, 0, "lognormal:1:0.2", 100000, NULL},
        {"binary100k", 0, 0, "list:1:1:1:1:1:1:1:1:2", 100000, NULL},
        {"peanut30k", 2, 0, "1", 30000, VP_SOURCE_DIR "/vdb_samples/peanut.obj"},
        {"peanut200k", 2, 0, "1", 200000, VP_SOURCE_DIR "/vdb_samples/peanut.obj"},
        {"skull200k", 2, 0, "1", 200000, VP_SHARED_CONTAINERS "/skull.obj"},
        {"relax100k", 3, 0, "1", 100000, NULL},
    };
    size_t nc = sizeof cases / sizeof *cases;
    unsigned long long seed_lo = 1, seed_hi = 1;
    int threads = 0;
    size_t order[64], no = 0; /* the cases named, in order */
    for (int a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--seed") && a + 1 < argc) {
            char *end = NULL;
            seed_lo = seed_hi = strtoull(argv[++a], &end, 10);
            if (*end == '-') seed_hi = strtoull(end + 1, &end, 10);
            if (*end || seed_lo < 1 || seed_hi < seed_lo || seed_hi - seed_lo > 999) {
                fprintf(stderr, "bench_jam: --seed S or A-B (1 <= A <= B, at most 1 000)\n");
                return 2;
            }
            continue;
        }
        if (!strcmp(argv[a], "--threads") && a + 1 < argc) {
            char *end = NULL;
            long n = strtol(argv[++a], &end, 10);
            if (*end || n < 1 || n > 256) {
                fprintf(stderr, "bench_jam: --threads N (1 to 256)\n");
                return 2;
            }
            threads = (int)n;
            continue;
        }
        size_t i = 0;
        while (i < nc && strcmp(argv[a], cases[i].name)) i++;
        if (i == nc || no == sizeof order / sizeof *order) {
            fprintf(stderr, "bench_jam: unknown case %s (or too many)\n", argv[a]);
            return 2;
        }
        order[no++] = i;
    }
    if (no == 0)
        for (size_t i = 0; i < nc; i++) order[no++] = i;
    size_t runs = no * (size_t)(seed_hi - seed_lo + 1);
    /* each run's time, written by its child process */
    double *seconds = mmap(NULL, runs * sizeof *seconds, PROT_READ | PROT_WRITE,
                           MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (seconds == MAP_FAILED) return 1;
    for (size_t r = 0; r < runs; r++) {
        jam_case k = cases[order[r % no]];
        k.seed = seed_lo + r / no;
        k.threads = threads; /* 0: every core */
        k.seconds = seconds + r;
        seconds[r] = -1;
        bench_fork(run_case, &k);
    }
    /* the boxes at the hour: over the reference's mean time */
    double ref = 0;
    int nref = 0;
    for (size_t r = 0; r < runs; r++)
        if (!strcmp(cases[order[r % no]].name, "relax100k") && seconds[r] > 0) {
            ref += seconds[r];
            nref++;
        }
    if (nref == 0) return 0;
    ref /= nref;
    for (size_t r = 0; r < runs; r++) {
        const char *name = cases[order[r % no]].name;
        double asked = !strcmp(name, "box100k") ? 30.0 : !strcmp(name, "box1M") ? 300.0 : 0.0;
        if (asked == 0 || seconds[r] <= 0) continue;
        printf("%s seed %llu / relax100k (mean of %d, %.2f s) = %.3f: at the issue's hour (relax "
               "29 s) %.1f s (%.0f s asked)\n",
               name, seed_lo + r / no, nref, ref, seconds[r] / ref, 29.0 * seconds[r] / ref, asked);
    }
    return 0;
}
