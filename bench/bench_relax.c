/* SPDX-License-Identifier: Apache-2.0 */
/* Relaxation figures of issue 3, each case in its own process:
 *  1. 1e5 x SCALE spheres of one radius in a unit box, target fraction F;
 *  2. spheres of one radius in a sphere container of radius 20 r;
 *  3. the reference, in the same run: maximal RSA of the same radius (the
 *     loosest random packing the product makes) for the density gain.
 * Memory: (peak RSS - RSS before packing) / particles.
 * Usage: build/bench/bench_relax [SCALE [F]]   (defaults 1 and 0.62) */
#include "vdbpack/vdbpack.h"

#include <math.h>

#include "bench_random_common.h"

typedef struct relax_case {
    const char *name;
    int sphere; /* container: sphere of radius 1, else unit box */
    size_t count;
    double fraction; /* target */
    int rsa;         /* 1: maximal RSA at the radius relax starts from */
} relax_case;

static void run_case(void *arg) {
    relax_case *k = arg;
    vp_context *ctx = NULL;
    vp_context_create(&ctx);
    vp_container *c = NULL;
    double zero[3] = {0, 0, 0}, lo[3] = {-0.5, -0.5, -0.5}, hi[3] = {0.5, 0.5, 0.5};
    if (k->sphere) vp_container_create_sphere(ctx, zero, 1.0, &c);
    else vp_container_create_box(ctx, lo, hi, &c);
    vp_container_info ci;
    vp_container_get_info(c, &ci);
    double r = cbrt(k->fraction * ci.volume / (k->count * 4.0 / 3.0 * M_PI));
    long before = bench_status_kb("VmRSS:");
    vp_particles *p = NULL;
    double t0 = bench_now();
    vp_result res;
    char extra[160] = "";
    if (k->rsa) {
        vp_rsa_pass ps;
        vp_rsa_pass_init(&ps);
        ps.maximal = 1;
        vp_size_dist_constant(&ps.radius, r);
        vp_rsa_params rp;
        vp_rsa_params_init(&rp);
        rp.passes = &ps;
        rp.npasses = 1;
        res = vp_pack_rsa(ctx, c, &rp, &p, NULL);
    } else {
        vp_relax_params xp;
        vp_relax_params_init(&xp);
        vp_size_dist_constant(&xp.radius, 1.0);
        xp.count = k->count;
        xp.target_fraction = k->fraction;
        xp.seed = 1;
        vp_relax_report rep;
        res = vp_pack_relax(ctx, c, &xp, &p, &rep);
        if (res == VP_OK)
            snprintf(extra, sizeof extra, ", %d sweeps, radius scale %.4f, largest overlap %.2g",
                     rep.sweeps, rep.radius_scale, rep.max_overlap);
    }
    double t = bench_now() - t0;
    if (res != VP_OK) {
        printf("%s: error: %s\n", k->name, vp_context_message(ctx));
        return;
    }
    long peak = bench_status_kb("VmHWM:");
    printf("%-34s %7zu spheres, fraction %.4f, %.2f s, peak %.1f B/particle (container/r = "
           "%.1f)%s\n",
           k->name, p->count, vp_particles_volume(p) / ci.volume, t,
           (peak - before) * 1024.0 / p->count, (ci.bmax[0] - ci.bmin[0]) / (2 * r), extra);
    vp_particles_destroy(p);
    vp_container_destroy(c);
    vp_context_destroy(ctx);
}

int main(int argc, char **argv) {
    double scale = argc > 1 ? atof(argv[1]) : 1.0, f = argc > 2 ? atof(argv[2]) : 0.62;
    if (!(scale > 0)) scale = 1;
    if (!(f > 0 && f < 0.74)) f = 0.62;
    printf("bench_relax: scale %g, target fraction %.3f\n", scale, f);
    size_t n = (size_t)(1e5 * scale);
    relax_case box = {"relax, box", 0, n, f, 0};
    relax_case box_rsa = {"reference: maximal RSA, box", 0, n, f, 1};
    /* a sphere of radius 20 r: N = F * 20^3 */
    size_t ns = (size_t)(f * 8000.0);
    relax_case sph = {"relax, sphere of radius 20 r", 1, ns, f, 0};
    relax_case sph_rsa = {"reference: maximal RSA, sphere", 1, ns, f, 1};
    bench_fork(run_case, &box);
    bench_fork(run_case, &box_rsa);
    bench_fork(run_case, &sph);
    bench_fork(run_case, &sph_rsa);
    printf("targets (issue 3): box >= 0.58 within 60 s (packing-generation's force-biased "
           "algorithm: 0.589 in 92 s on this machine, per the issue); sphere of 20 r >= 0.55 "
           "(Yade randomDensePack: 0.485, per the issue); <= 100 B/particle\n");
    return 0;
}
