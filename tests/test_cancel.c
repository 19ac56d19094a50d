/* SPDX-License-Identifier: Apache-2.0 */
/* Cancellation through the progress callback (issue 4): for every packer,
 * the checker and the mesh loader, a callback that returns 0 after its k-th
 * call makes the running call return VP_ERR_CANCELLED with no output and a
 * message, for k = 1 (at once) and for a k in the middle of the work (the
 * callback counts its calls in an uncancelled run first). Under the
 * sanitizer build (scripts/ci_hardening.sh) this also proves that every
 * cancel path frees what it allocated. */
#include "vdbpack/vdbpack.h"
#include "vdbpack/check.h"
#include "vdbpack/relax.h"
#include "vdbpack/rsa.h"

#include <string.h>

#include "vp_test.h"

typedef struct counter {
    long calls;
    long cancel_at; /* 0: never */
} counter;

static int on_progress(void *user, double fraction, const char *stage) {
    (void)fraction;
    (void)stage;
    counter *c = user;
    c->calls++;
    return !(c->cancel_at && c->calls >= c->cancel_at);
}

typedef vp_result (*job_fn)(vp_context *ctx, void *arg, void **out);
typedef void (*free_fn)(void *out);

/* Runs job uncancelled (counting callbacks), then cancelled at the first and
 * at the middle callback. */
static void cancel_job(const char *name, job_fn job, free_fn release, void *arg) {
    vp_context *ctx = NULL;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_context_set_threads(ctx, 2);
    counter c = {0, 0};
    vp_context_set_progress(ctx, on_progress, &c);
    void *out = NULL;
    ASSERT_OK(ctx, job(ctx, arg, &out));
    ASSERT_TRUE(out != NULL);
    release(out);
    long total = c.calls;
    fprintf(stderr, "   %s: %ld progress calls uncancelled\n", name, total);
    ASSERT_TRUE(total >= 2); /* else "the middle" is not inside the work */
    long at[2] = {1, total / 2 > 1 ? total / 2 : 2};
    for (int i = 0; i < 2; i++) {
        c.calls = 0;
        c.cancel_at = at[i];
        out = NULL;
        vp_result r = job(ctx, arg, &out);
        ASSERT_EQ_INT(r, VP_ERR_CANCELLED);
        ASSERT_TRUE(out == NULL);
        ASSERT_TRUE(strstr(vp_context_message(ctx), "cancel") != NULL);
        ASSERT_EQ_INT(c.calls, at[i]); /* stopped at the first refusal */
        fprintf(stderr, "   %s: cancelled at call %ld: '%s'\n", name, at[i],
                vp_context_message(ctx));
    }
    vp_context_destroy(ctx);
}

static vp_container *g_sphere;

static vp_result job_lattice(vp_context *ctx, void *arg, void **out) {
    (void)arg;
    vp_lattice_params lp;
    vp_lattice_params_init(&lp);
    lp.radius = 0.03;
    lp.offsets = 64;
    return vp_pack_lattice(ctx, g_sphere, &lp, (vp_particles **)out, NULL);
}

static vp_result job_rsa(vp_context *ctx, void *arg, void **out) {
    (void)arg;
    vp_rsa_pass pass;
    vp_rsa_pass_init(&pass);
    pass.maximal = 1;
    vp_size_dist_constant(&pass.radius, 0.02);
    vp_rsa_params rp;
    vp_rsa_params_init(&rp);
    rp.passes = &pass;
    rp.npasses = 1;
    return vp_pack_rsa(ctx, g_sphere, &rp, (vp_particles **)out, NULL);
}

static vp_result job_relax(vp_context *ctx, void *arg, void **out) {
    (void)arg;
    vp_relax_params rp;
    vp_relax_params_init(&rp);
    vp_size_dist_constant(&rp.radius, 0.05);
    rp.count = 3000;
    rp.target_fraction = 0.55;
    return vp_pack_relax(ctx, g_sphere, &rp, (vp_particles **)out, NULL);
}

static vp_result job_jam(vp_context *ctx, void *arg, void **out) {
    (void)arg;
    vp_jam_params jp;
    vp_jam_params_init(&jp);
    jp.count = 400;
    return vp_pack_jam(ctx, g_sphere, &jp, (vp_particles **)out, NULL);
}

static vp_particles *g_packed;
static vp_check_report g_report;

static vp_result job_check(vp_context *ctx, void *arg, void **out) {
    (void)arg;
    vp_check_params cp;
    vp_check_params_init(&cp);
    vp_result r = vp_check_particles(ctx, g_sphere, g_packed, &cp, &g_report);
    *out = r == VP_OK ? (void *)&g_report : NULL; /* nothing owned */
    return r;
}

static vp_result job_load_mesh(vp_context *ctx, void *arg, void **out) {
    vp_container_params cp;
    vp_container_params_init(&cp);
    cp.particle_radius = 0.05;
    return vp_container_load(ctx, (const char *)arg, &cp, (vp_container **)out);
}

static void free_particles(void *p) { vp_particles_destroy(p); }
static void free_nothing(void *p) { (void)p; }
static void free_container(void *c) { vp_container_destroy(c); }

/* The checker's case packs its input first (~370k particles: the checker
 * reports every 65536), so that the other cases do not wait for it. */
static void cancel_check(void) {
    vp_context *ctx = NULL;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    vp_lattice_params lp;
    vp_lattice_params_init(&lp);
    lp.radius = 0.012;
    ASSERT_OK(ctx, vp_pack_lattice(ctx, g_sphere, &lp, &g_packed, NULL));
    cancel_job("check", job_check, free_nothing, NULL);
    vp_particles_destroy(g_packed);
    g_packed = NULL;
    vp_context_destroy(ctx);
}

int main(void) {
    vp_context *ctx = NULL;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    const double centre[3] = {0, 0, 0};
    ASSERT_OK(ctx, vp_container_create_sphere(ctx, centre, 1.0, &g_sphere));

    RUN_CASE(cancel_lattice, cancel_job("lattice", job_lattice, free_particles, NULL));
    RUN_CASE(cancel_rsa_maximal, cancel_job("rsa maximal", job_rsa, free_particles, NULL));
    RUN_CASE(cancel_relax, cancel_job("relax", job_relax, free_particles, NULL));
    RUN_CASE(cancel_jam, cancel_job("jam", job_jam, free_particles, NULL));
    RUN_TEST(cancel_check);
    RUN_CASE(cancel_mesh_load, cancel_job("mesh load", job_load_mesh, free_container,
                                          (void *)VP_SAMPLES "/torus.obj"));

    vp_container_destroy(g_sphere);
    vp_context_destroy(ctx);
    fprintf(stderr, "all cancellation tests passed\n");
    return 0;
}
