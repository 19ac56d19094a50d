/* SPDX-License-Identifier: Apache-2.0 */
/* Preview-render figures of issue 6, each case in its own process (peak
 * memory):
 *  1. about 1M spheres (FCC in a unit box, vp_pack_lattice) at 1920x1080, default settings (4 AO rays, shadows): seconds,
 *     rays per second (primary + one shadow + the AO rays of every covered
 *     pixel: an upper bound, back-lit pixels skip the shadow ray), and the
 *     renderer's bytes per particle: (peak RSS - RSS with the particles and
 *     nothing else) - image bytes, over the count;
 *  2. the same at about 10M particles and 640x360: the memory figure at
 *     the size the issue asks for.
 * Usage: build/bench/bench_render [THREADS]   (default: all cores)
 * No pass/fail: figures are printed for the notes. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdint.h>

#include "bench_random_common.h"

static int g_threads = 0;

typedef struct render_case {
    const char *name;
    size_t count; /* particles wanted */
    int width, height;
} render_case;

static void run_case(void *arg) {
    render_case *k = arg;
    vp_context *ctx = NULL;
    vp_context_create(&ctx);
    if (g_threads) vp_context_set_threads(ctx, g_threads);
    /* FCC spheres in a unit box, as vdbpack pack box:1,1,1 --count N makes
     * them (one offset: the placement search is not what is measured) */
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    vp_container *c = NULL;
    vp_container_create_box(ctx, lo, hi, &c);
    vp_lattice_params lp;
    vp_lattice_params_init(&lp);
    lp.count = k->count;
    lp.offsets = 1;
    vp_particles *p = NULL;
    if (vp_pack_lattice(ctx, c, &lp, &p, NULL) != VP_OK) {
        printf("%s: %s\n", k->name, vp_context_message(ctx));
        return;
    }
    vp_container_destroy(c);
    size_t n = p->count;
    long before = bench_status_kb("VmRSS:");
    vp_render_params rp;
    vp_render_params_init(&rp);
    rp.width = k->width;
    rp.height = k->height;
    vp_image *img = NULL;
    double t0 = bench_now();
    if (vp_render(ctx, p, &rp, &img) != VP_OK) {
        printf("%s: error: %s\n", k->name, vp_context_message(ctx));
        return;
    }
    double t = bench_now() - t0;
    long peak = bench_status_kb("VmHWM:");
    size_t npix = (size_t)img->width * img->height, covered = 0;
    for (size_t q = 0; q < npix; q++) covered += img->rgba[4 * q + 3] > 0;
    double rays = (double)npix + (double)covered * (1.0 + rp.ao_samples);
    double img_bytes = (double)npix * 24.0;
    double per = ((peak - before) * 1024.0 - img_bytes) / (double)n;
    double set_bytes = (double)before * 1024.0 / (double)n;
    printf(
        "%-22s %9zu spheres (r %.4g) %5dx%-5d %6.2f s  %5.1f Mrays/s  covered %4.1f %%  renderer "
        "%5.1f B/particle (+ particle set ~%.0f B/particle, image %.0f MB)\n",
        k->name, n, (double)p->uniform_radius, img->width, img->height, t, rays / t * 1e-6,
        100.0 * covered / npix, per, set_bytes, img_bytes * 1e-6);
    vp_image_destroy(img);
    vp_particles_destroy(p);
    vp_context_destroy(ctx);
}

int main(int argc, char **argv) {
    if (argc > 1) g_threads = atoi(argv[1]);
    render_case cases[] = {
        {"1M @ 1920x1080", 1000000, 1920, 1080},
        {"10M @ 640x360", 10000000, 640, 360},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) bench_fork(run_case, &cases[c]);
    return 0;
}
