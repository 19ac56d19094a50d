/* SPDX-License-Identifier: Apache-2.0 */
/* libFuzzer target: every path that opens a .vdb: the container loader
 * (level-set choice, grid-type checks, interior band), `vdbpack info`'s
 * description and `vdbpack check`'s points reader. The input is written to
 * a temporary file (in $TMPDIR, else /tmp; removed after each input), as
 * OpenVDB reads files. Each must return a result code with a message, never
 * crash, leak or hang. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "vdbpack/vdbpack.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (size > 1 << 20) return 0;
    static char path[4096];
    if (!path[0]) {
        const char *dir = getenv("TMPDIR");
        if (!dir || !dir[0]) dir = "/tmp";
        snprintf(path, sizeof path, "%s/vp_fuzz_vdb_%d.vdb", dir, (int)getpid());
    }
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    if (size) fwrite(data, 1, size, f);
    fclose(f);

    vp_context *ctx = NULL;
    if (vp_context_create(&ctx) != VP_OK) {
        unlink(path);
        return 0;
    }
    vp_context_set_max_memory(ctx, (uint64_t)512 << 20);
    vp_context_set_threads(ctx, 1);

    vp_container_params cp;
    vp_container_params_init(&cp);
    cp.particle_radius = 0.05;
    vp_container *c = NULL;
    vp_result r = vp_container_load(ctx, path, &cp, &c);
    if (r == VP_OK) {
        double p[3] = {0, 0, 0}, g[3];
        (void)vp_container_distance(c, p);
        vp_container_gradient(c, p, g);
        vp_container_destroy(c);
    } else if (c || !vp_context_message(ctx)[0]) {
        __builtin_trap();
    }
    char *text = NULL;
    if (vp_describe_file(ctx, path, (int)(size & 1), &text) == VP_OK) free(text);
    vp_particles *pts = NULL;
    if (vp_read_points(ctx, path, &pts) == VP_OK) vp_particles_destroy(pts);
    vp_context_destroy(ctx);
    unlink(path);
    return 0;
}
