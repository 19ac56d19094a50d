/* SPDX-License-Identifier: Apache-2.0 */
/* Training workload for the profile-guided build (VP_PGO in CMakeLists.txt):
 * run once during the build by a copy of the C library whose rsa.c is
 * instrumented; its branch and call counts then steer the optimisation of
 * the real rsa.c. It
 * runs the random packers as users do, at about 1e5 particles (a few
 * seconds): spheres by count and maximal RSA, a grown two-pass packing and a
 * size distribution, solids, relaxation, and the check of each result. A
 * packer that fails or a check that finds a violation fails the build
 * (exit 1). Each line ends with a digest of the packing (FNV-1a over
 * positions, radii and orientations): the test pgo_same_packings builds this
 * file against the real library and compares its lines with those of the
 * training run, so a profile that changed a result would be seen.
 * Usage: vdbpack_pgo_train (no arguments; not installed). */
#include "vdbpack/vdbpack.h"

#include <stdint.h>
#include <stdio.h>

static int failed;

static uint64_t fnv(uint64_t h, const void *data, size_t n) {
    const unsigned char *b = data;
    for (size_t i = 0; i < n; i++) h = (h ^ b[i]) * 0x100000001b3ull;
    return h;
}

static uint64_t digest(const vp_particles *p) {
    uint64_t h = fnv(0xcbf29ce484222325ull, &p->count, sizeof p->count);
    h = fnv(h, p->positions, 3 * p->count * sizeof *p->positions);
    if (p->radii) h = fnv(h, p->radii, p->count * sizeof *p->radii);
    if (p->orients) h = fnv(h, p->orients, 4 * p->count * sizeof *p->orients);
    return h;
}

static void check(vp_context *ctx, const vp_container *c, const vp_particles *p, vp_fit fit,
                  const char *what) {
    vp_check_params cp;
    vp_check_params_init(&cp);
    cp.fit = fit;
    vp_check_report cr;
    if (vp_check_particles(ctx, c, p, &cp, &cr) != VP_OK || cr.overlapping_pairs || cr.outside) {
        fprintf(stderr, "pgo_train: %s: check failed: %s\n", what, vp_context_message(ctx));
        failed = 1;
        return;
    }
    printf("pgo_train: %-28s %7zu particles, fraction %.4f, digest %016llx\n", what, p->count,
           cr.fraction, (unsigned long long)digest(p));
}

static void rsa(vp_context *ctx, const vp_container *c, vp_shape shape, vp_rsa_pass *passes,
                size_t npasses, vp_fit fit, const char *what) {
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.shape = shape;
    rp.fit = fit;
    rp.passes = passes;
    rp.npasses = npasses;
    rp.seed = 1;
    vp_particles *p = NULL;
    if (vp_pack_rsa(ctx, c, &rp, &p, NULL) != VP_OK) {
        fprintf(stderr, "pgo_train: %s: %s\n", what, vp_context_message(ctx));
        failed = 1;
        return;
    }
    check(ctx, c, p, fit, what);
    vp_particles_destroy(p);
}

static vp_rsa_pass pass(vp_context *ctx, size_t count, const char *radius, int grow) {
    vp_rsa_pass ps;
    vp_rsa_pass_init(&ps);
    ps.count = count;
    ps.maximal = count == 0;
    ps.grow = grow;
    if (vp_size_dist_parse(ctx, radius, &ps.radius) != VP_OK) failed = 1;
    return ps;
}

int main(void) {
    vp_context *ctx = NULL;
    if (vp_context_create(&ctx) != VP_OK) return 1;
    /* one thread: the instrumented counters need no atomic updates (with
     * them, every file instrumented and two threads, the run took 40 s);
     * the packings do not depend on the thread count */
    vp_context_set_threads(ctx, 1);
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    vp_container *box = NULL, *ball = NULL;
    if (vp_container_create_box(ctx, lo, hi, &box) != VP_OK ||
        vp_container_create_sphere(ctx, zero, 0.5, &ball) != VP_OK)
        return 1;

    vp_rsa_pass one = pass(ctx, 100000, "0.00926", 0);
    rsa(ctx, box, VP_SHAPE_SPHERE, &one, 1, VP_FIT_INSIDE, "rsa count");
    vp_rsa_pass mx = pass(ctx, 0, "0.0125", 0);
    rsa(ctx, box, VP_SHAPE_SPHERE, &mx, 1, VP_FIT_INSIDE, "rsa maximal");
    vp_rsa_pass two[2] = {pass(ctx, 400, "0.04", 1), pass(ctx, 0, "0.012", 0)};
    rsa(ctx, ball, VP_SHAPE_SPHERE, two, 2, VP_FIT_INSIDE, "rsa binary, grown");
    vp_rsa_pass law = pass(ctx, 20000, "lognormal:0.008:0.002", 0);
    rsa(ctx, ball, VP_SHAPE_SPHERE, &law, 1, VP_FIT_CENTER, "rsa lognormal");
    vp_rsa_pass cubes = pass(ctx, 0, "0.04", 0);
    rsa(ctx, box, VP_SHAPE_CUBE, &cubes, 1, VP_FIT_INSIDE, "rsa cubes");
    vp_rsa_pass octa = pass(ctx, 2000, "0.03", 0);
    rsa(ctx, ball, VP_SHAPE_OCTAHEDRON, &octa, 1, VP_FIT_INSIDE, "rsa octahedra");

    const vp_container *relax_in[2] = {box, ball};
    for (int k = 0; k < 2; k++) {
        vp_relax_params xp;
        vp_relax_params_init(&xp);
        vp_size_dist_constant(&xp.radius, 1.0);
        xp.count = 5000;
        xp.target_fraction = 0.6;
        xp.seed = 1;
        vp_particles *p = NULL;
        vp_relax_report rep;
        if (vp_pack_relax(ctx, relax_in[k], &xp, &p, &rep) != VP_OK) {
            fprintf(stderr, "pgo_train: relax: %s\n", vp_context_message(ctx));
            failed = 1;
            continue;
        }
        check(ctx, relax_in[k], p, VP_FIT_INSIDE, k ? "relax, sphere" : "relax, box");
        vp_particles_destroy(p);
    }
    vp_container_destroy(box);
    vp_container_destroy(ball);
    vp_context_destroy(ctx);
    return failed;
}
