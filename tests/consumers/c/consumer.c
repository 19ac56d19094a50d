/* SPDX-License-Identifier: Apache-2.0 */
/* A program outside vdbpack's tree, built against an installed prefix
 * through pkg-config (tests/sh_install.sh):
 *   cc consumer.c $(pkg-config --cflags --libs vdbpack)
 * It packs a cube handed over as arrays, writes the .vdb and the .csv given
 * as arguments, reads both back and checks them. Public API only. */
#include <vdbpack/vdbpack.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#define CHECK(call)                                                                                \
    do {                                                                                           \
        vp_result r_ = (call);                                                                     \
        if (r_ != VP_OK) {                                                                         \
            fprintf(stderr, "consumer-c: %s: %s: %s\n", #call, vp_result_name(r_),                 \
                    vp_context_message(ctx));                                                      \
            return 1;                                                                              \
        }                                                                                          \
    } while (0)

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: consumer OUT.vdb OUT.csv\n");
        return 2;
    }
    if (strcmp(vp_version(), VP_VERSION_STRING) != 0) {
        fprintf(stderr, "consumer-c: headers %s, library %s\n", VP_VERSION_STRING, vp_version());
        return 1;
    }
    static const double v[8 * 3] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                                    0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    static const uint32_t t[12 * 3] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                       2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};
    vp_context *ctx = NULL;
    if (vp_context_create(&ctx) != VP_OK) return 1;
    vp_lattice_params lp;
    vp_lattice_params_init(&lp);
    lp.radius = 0.1;
    vp_container_params cp;
    vp_container_params_init(&cp);
    cp.name = "unit cube";
    vp_container_params_for_lattice(&cp, &lp);
    vp_container *c = NULL;
    CHECK(vp_container_from_mesh(ctx, v, 8, t, 12, &cp, &c));
    vp_particles *p = NULL;
    vp_lattice_report rep;
    CHECK(vp_pack_lattice(ctx, c, &lp, &p, &rep));
    /* FCC spheres of radius 0.1 in a unit cube: a few hundred */
    if (p->count < 100) {
        fprintf(stderr, "consumer-c: only %zu spheres\n", p->count);
        return 1;
    }
    CHECK(vp_write_points(ctx, argv[1], p, NULL));
    vp_export_params ep;
    vp_export_params_init(&ep);
    CHECK(vp_export(ctx, argv[2], p, &ep));
    vp_particles *q = NULL, *s = NULL;
    CHECK(vp_read_points(ctx, argv[1], &q));
    CHECK(vp_import(ctx, argv[2], VP_FORMAT_UNKNOWN, &s, NULL));
    if (q->count != p->count || s->count != p->count) {
        fprintf(stderr, "consumer-c: read back %zu and %zu of %zu\n", q->count, s->count, p->count);
        return 1;
    }
    double worst = 0;
    for (size_t i = 0; i < 3 * p->count; i++) {
        worst = fmax(worst, fabs(q->positions[i] - p->positions[i]));
        if (s->positions[i] != p->positions[i]) {
            fprintf(stderr, "consumer-c: CSV position %zu differs\n", i / 3);
            return 1;
        }
    }
    if (worst > q->position_error + 1e-12) {
        fprintf(stderr, "consumer-c: .vdb positions off by %g (codec error %g)\n", worst,
                q->position_error);
        return 1;
    }
    printf("consumer-c: vdbpack %s, %zu spheres of radius %g in the cube, read back\n",
           vp_version(), p->count, rep.radius);
    vp_particles_destroy(p);
    vp_particles_destroy(q);
    vp_particles_destroy(s);
    vp_container_destroy(c);
    vp_context_destroy(ctx);
    return 0;
}
