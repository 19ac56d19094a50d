/* SPDX-License-Identifier: Apache-2.0 */
/* The winding-number inside against the closed-surface voxelization
 * (issue 26): voxelizing a mesh of about 100 000 triangles at the default
 * voxel size, from arrays (vp_container_from_mesh, so that no file import
 * is timed), as
 *  1. the closed mesh (OpenVDB's voxelization: the reference);
 *  2. the same mesh with 5 holes (the triangles within a tenth of the
 *     bounding box's diagonal of 5 vertices removed, as a scan has them);
 *  3. the same mesh with 1 % of its triangles removed at random (a hole at
 *     every hundredth triangle: the worst case);
 *  4. the closed mesh forced through the winding route (--inside winding).
 * Each case 3 times, alternating; the best time of each and its ratio to
 * the reference are printed, with the volumes.
 * Usage: build/bench/bench_inside [MESH]   (default ../shared/containers/skull.obj)
 * No pass/fail: figures and ratios are printed for the notes. */
#include "vdbpack/vdbpack.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mesh/mesh.h"

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

typedef struct arrays {
    double *v;
    uint32_t *t;
    size_t nv, nt;
} arrays;

static double run(vp_context *ctx, const arrays *a, vp_inside_mode mode, double *volume,
                  const char **route) {
    vp_container_params cp;
    vp_container_params_init(&cp);
    cp.inside = mode;
    vp_container *c = NULL;
    double t0 = now();
    if (vp_container_from_mesh(ctx, a->v, a->nv, a->t, a->nt, &cp, &c) != VP_OK) {
        fprintf(stderr, "bench_inside: %s\n", vp_context_message(ctx));
        exit(1);
    }
    double dt = now() - t0;
    vp_container_info ci;
    vp_container_get_info(c, &ci);
    *volume = ci.volume;
    *route = ci.inside == VP_INSIDE_WINDING ? "winding" : "closed";
    vp_container_destroy(c);
    return dt;
}

int main(int argc, char **argv) {
    const char *path = argc > 1 ? argv[1] : VP_SHARED_CONTAINERS "/skull.obj";
    char err[1024];
    vp_mesh *m = NULL;
    if (vp_mesh_load(path, &m, err, sizeof err) != VP_OK) {
        fprintf(stderr, "bench_inside: %s\n", err);
        return 77;
    }
    arrays closed = {m->verts, m->tris, m->nverts, m->ntris};
    double diag = 0;
    for (int k = 0; k < 3; k++) diag += (m->bmax[k] - m->bmin[k]) * (m->bmax[k] - m->bmin[k]);
    diag = sqrt(diag);
    arrays holes = closed, sieve = closed;
    holes.t = malloc(3 * m->ntris * sizeof *holes.t);
    sieve.t = malloc(3 * m->ntris * sizeof *sieve.t);
    holes.nt = sieve.nt = 0;
    uint64_t s = 12345;
    for (size_t t = 0; t < m->ntris; t++) {
        double c[3] = {0, 0, 0};
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++) c[k] += m->verts[3 * (size_t)m->tris[3 * t + j] + k] / 3;
        int cut = 0;
        for (int h = 0; h < 5 && !cut; h++) {
            const double *p = m->verts + 3 * (size_t)((h + 1) * (m->nverts / 6));
            double d2 = 0;
            for (int k = 0; k < 3; k++) d2 += (c[k] - p[k]) * (c[k] - p[k]);
            cut = d2 < 0.01 * diag * diag * 0.25;
        }
        if (!cut) memcpy(holes.t + 3 * holes.nt++, m->tris + 3 * t, 3 * sizeof *m->tris);
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        if ((s >> 33) % 100 != 0)
            memcpy(sieve.t + 3 * sieve.nt++, m->tris + 3 * t, 3 * sizeof *m->tris);
    }
    vp_context *ctx = NULL;
    vp_context_create(&ctx);
    struct {
        const char *name;
        const arrays *a;
        vp_inside_mode mode;
        double best, volume;
        const char *route;
    } cases[4] = {{"closed mesh (reference)", &closed, VP_INSIDE_AUTO, HUGE_VAL, 0, ""},
                  {"5 holes", &holes, VP_INSIDE_AUTO, HUGE_VAL, 0, ""},
                  {"1 % of triangles removed", &sieve, VP_INSIDE_AUTO, HUGE_VAL, 0, ""},
                  {"closed, --inside winding", &closed, VP_INSIDE_WINDING, HUGE_VAL, 0, ""}};
    for (int rep = 0; rep < 3; rep++)
        for (int c = 0; c < 4; c++) {
            double v;
            const char *route;
            double dt = run(ctx, cases[c].a, cases[c].mode, &v, &route);
            if (dt < cases[c].best) cases[c].best = dt;
            cases[c].volume = v;
            cases[c].route = route;
        }
    printf("bench_inside: %s, %zu triangles, default voxel size (1/200 of the diagonal %g)\n", path,
           m->ntris, diag);
    for (int c = 0; c < 4; c++)
        printf("  %-28s %6zu triangles  %-7s  best %6.3f s  x%.2f  volume %.6g\n", cases[c].name,
               cases[c].a->nt, cases[c].route, cases[c].best, cases[c].best / cases[0].best,
               cases[c].volume);
    free(holes.t);
    free(sieve.t);
    vp_mesh_destroy(m);
    vp_context_destroy(ctx);
    return 0;
}
