/* SPDX-License-Identifier: Apache-2.0 */
/* Peak memory per particle of a lattice fill beyond the level set.
 * Loads a mesh container (level set), notes the resident memory (VmRSS),
 * packs about N spheres on FCC and writes them, then reads the peak (VmHWM):
 * (peak - resident after load) / particles. If voxelizing peaked higher than
 * packing, this over-states the figure, never under-states it.
 * Usage: bench_lattice_memory MESH N [VOXEL]   prints one JSON line. */
#include "vdbpack/vdbpack.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static long status_kb(const char *key) {
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    long v = -1;
    size_t k = strlen(key);
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, key, k)) v = strtol(line + k + 1, NULL, 10);
    if (f) fclose(f);
    return v;
}

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int main(int argc, char **argv) {
    if (argc < 3) {
        fprintf(stderr, "usage: bench_lattice_memory MESH N [VOXEL]\n");
        return 2;
    }
    vp_context *ctx = NULL;
    vp_context_create(&ctx);
    vp_container_params cp;
    vp_container_params_init(&cp);
    cp.particle_count = (size_t)strtoull(argv[2], NULL, 10);
    cp.narrow_band = 1; /* as the CLI loads containers for the lattice packer */
    if (argc > 3) cp.voxel_size = atof(argv[3]);
    double t0 = now();
    vp_container *c = NULL;
    if (vp_container_load(ctx, argv[1], &cp, &c) != VP_OK) {
        fprintf(stderr, "%s\n", vp_context_message(ctx));
        return 1;
    }
    double t1 = now();
    long rss_load = status_kb("VmRSS:");
    vp_lattice_params lp;
    vp_lattice_params_init(&lp);
    lp.count = cp.particle_count;
    vp_particles *p = NULL;
    vp_lattice_report rep;
    if (vp_pack_lattice(ctx, c, &lp, &p, &rep) != VP_OK) {
        fprintf(stderr, "%s\n", vp_context_message(ctx));
        return 1;
    }
    double t2 = now();
    vp_write_params wp;
    vp_write_params_init(&wp);
    if (vp_write_points(ctx, "/tmp/bench_lattice_memory.vdb", p, &wp) != VP_OK) {
        fprintf(stderr, "%s\n", vp_context_message(ctx));
        return 1;
    }
    double t3 = now();
    long hwm = status_kb("VmHWM:");
    vp_container_info ci;
    vp_container_get_info(c, &ci);
    printf("{\"count\":%zu,\"radius\":%.9g,\"voxel\":%.9g,\"load_s\":%.3f,\"pack_s\":%.3f,"
           "\"write_s\":%.3f,\"rss_after_load_mb\":%.1f,\"peak_mb\":%.1f,"
           "\"bytes_per_particle\":%.1f}\n",
           p->count, rep.radius, ci.voxel_size, t1 - t0, t2 - t1, t3 - t2, rss_load / 1024.0,
           hwm / 1024.0, (hwm - rss_load) * 1024.0 / (double)p->count);
    remove("/tmp/bench_lattice_memory.vdb");
    vp_particles_destroy(p);
    vp_container_destroy(c);
    vp_context_destroy(ctx);
    return 0;
}
