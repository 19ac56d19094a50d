/* SPDX-License-Identifier: Apache-2.0 */
/* Fields read from .vdb float grids (the sampler is src/vdb/vdb_field.cpp)
 * and containers with a mask taken out (include/vdbpack/field.h). */
#include "api/probe.h"
#include "core/container.h"
#include "core/context.h"
#include "core/field.h"
#include "os/input.h"
#include "vdb/vdb_field.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double grid_sample(void *user, const double p[3]) { return vpv_field_sample(user, p); }
static void grid_destroy(void *user) { vpv_field_destroy(user); }
static int grid_range(const vp_field *f, const double lo[3], const double hi[3], double *vmin,
                      double *vmax, char *err, size_t errlen) {
    return vpv_field_range(f->user, lo, hi, vmin, vmax, err, errlen) == VP_OK ? 0 : -1;
}

typedef struct probe_field_arg {
    const char *path, *grid;
} probe_field_arg;

/* The whole read, checks included, in the probe's throw-away child. */
static int probe_field(const void *arg, char *err, size_t errlen) {
    const probe_field_arg *a = arg;
    vpv_field *f = NULL;
    int rc = vpv_field_read(a->path, a->grid, &f, err, errlen);
    vpv_field_destroy(f);
    return rc;
}

vp_result vp_field_load(vp_context *ctx, const char *path, const char *grid_name, vp_field **out) {
    if (!out || !path) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "field: no file given");
    *out = NULL;
    char why[1024];
    if (vp_os_check_input(path, why, sizeof why) != 0) return vp_fail(ctx, VP_ERR_IO, "%s", why);
    /* as a container's .vdb: OpenVDB's reader first in a child with a
     * deadline and the memory limit (a hostile file crashes or hangs it) */
    probe_field_arg pa = {path, grid_name};
    vp_result pr = vp_probe_read(ctx, path, probe_field, &pa);
    if (pr != VP_OK) return pr;
    char err[1024] = "";
    vpv_field *g = NULL;
    int rc = vpv_field_read(path, grid_name, &g, err, sizeof err);
    if (rc != VP_OK) return vp_fail(ctx, (vp_result)rc, "%s", err);
    vpv_field_info gi;
    vpv_field_get_info(g, &gi);
    vp_field_info info;
    memset(&info, 0, sizeof info);
    memcpy(info.bmin, gi.bmin, sizeof info.bmin);
    memcpy(info.bmax, gi.bmax, sizeof info.bmax);
    info.voxel_size = gi.voxel_size;
    info.min = gi.min;
    info.max = gi.max;
    snprintf(info.grid_name, sizeof info.grid_name, "%s", gi.name);
    static const vp_field_ops ops = {grid_sample, grid_destroy};
    vp_result r = vp_field_wrap(ctx, &ops, g, &info, out);
    if (r != VP_OK) {
        vpv_field_destroy(g);
        return r;
    }
    (*out)->range = grid_range;
    return VP_OK;
}

/* --- a container less a mask ------------------------------------------- */

typedef struct masked {
    const vp_container *base, *mask; /* borrowed */
} masked;

static double masked_distance(void *user, const double p[3]) {
    const masked *m = user;
    double a = vp_container_distance(m->base, p), b = -vp_container_distance(m->mask, p);
    return a > b ? a : b;
}

static void masked_gradient(void *user, const double p[3], double g[3]) {
    const masked *m = user;
    double a = vp_container_distance(m->base, p), b = -vp_container_distance(m->mask, p);
    if (a >= b) {
        vp_container_gradient(m->base, p, g);
        return;
    }
    vp_container_gradient(m->mask, p, g);
    for (int k = 0; k < 3; k++) g[k] = -g[k];
}

static void masked_destroy(void *user) { free(user); }

static int masked_inside_box(const vp_container *c, double lo[3], double hi[3]) {
    const masked *m = c->user;
    vp_container_inside_box(m->base, lo, hi);
    return 0;
}

/* The volume of mask inside base, on a grid of about 2^21 cell centres
 * over the box both share. */
static double overlap_volume(const vp_container *base, const vp_container *mask) {
    double lo[3], hi[3], ext[3], vol = 1.0;
    for (int k = 0; k < 3; k++) {
        lo[k] = fmax(base->info.bmin[k], mask->info.bmin[k]);
        hi[k] = fmin(base->info.bmax[k], mask->info.bmax[k]);
        ext[k] = hi[k] - lo[k];
        if (!(ext[k] > 0)) return 0.0;
        vol *= ext[k];
    }
    double h = cbrt(vol / 2097152.0);
    long n[3];
    for (int k = 0; k < 3; k++) {
        n[k] = (long)ceil(ext[k] / h);
        if (n[k] < 1) n[k] = 1;
        if (n[k] > 4096) n[k] = 4096;
    }
    size_t in = 0;
    for (long i = 0; i < n[0]; i++)
        for (long j = 0; j < n[1]; j++)
            for (long k = 0; k < n[2]; k++) {
                double p[3] = {lo[0] + (i + 0.5) * ext[0] / n[0], lo[1] + (j + 0.5) * ext[1] / n[1],
                               lo[2] + (k + 0.5) * ext[2] / n[2]};
                if (vp_container_distance(mask, p) < 0 && vp_container_distance(base, p) < 0) in++;
            }
    return vol * (double)in / ((double)n[0] * (double)n[1] * (double)n[2]);
}

vp_result vp_container_subtract(vp_context *ctx, const vp_container *base, const vp_container *mask,
                                vp_container **out) {
    if (!out || !base || !mask)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "mask: a container, a mask and out are "
                       "required");
    *out = NULL;
    masked *m = calloc(1, sizeof *m);
    if (!m) return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "mask: out of memory");
    m->base = base;
    m->mask = mask;
    vp_container_info info = base->info;
    double ov = overlap_volume(base, mask);
    info.volume = base->info.volume - ov;
    if (!(info.volume > 0)) {
        free(m);
        return vp_fail(ctx, VP_ERR_BAD_CONTAINER,
                       "mask: the mask covers the whole container: "
                       "nothing is left to pack");
    }
    /* a level set mask knows its distance only as far out as its band:
     * beyond it, every point reads the band's depth */
    if (mask->levelset) {
        double far[3];
        for (int k = 0; k < 3; k++)
            far[k] = mask->info.bmax[k] + 2.0 * (mask->info.bmax[k] - mask->info.bmin[k]) + 1.0;
        double band = vp_container_distance(mask, far);
        if (band < info.interior_band) info.interior_band = band;
    }
    info.volume_estimate_kind = VP_ESTIMATE_NONE;
    info.volume_estimate = 0;
    info.volume_mismatch = 0;
    static const vp_container_ops ops = {masked_distance, masked_gradient, masked_destroy};
    vp_result r = vp_container_wrap(ctx, &ops, m, &info, out);
    if (r != VP_OK) {
        free(m);
        return r;
    }
    (*out)->inside_box = masked_inside_box;
    return VP_OK;
}
