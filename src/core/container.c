/* SPDX-License-Identifier: Apache-2.0 */
/* Containers: the callback wrapper and the exact analytic sphere and box
 * that keep unit tests exact. */
#include "core/container.h"
#include "core/context.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct analytic {
    int is_box;
    double c[3], r;      /* sphere */
    double lo[3], hi[3]; /* box */
} analytic;

static double analytic_distance(void *user, const double p[3]) {
    const analytic *a = user;
    if (!a->is_box) {
        double dx = p[0] - a->c[0], dy = p[1] - a->c[1], dz = p[2] - a->c[2];
        return sqrt(dx * dx + dy * dy + dz * dz) - a->r;
    }
    /* exact box SDF */
    double q[3], outside = 0.0, inside = -HUGE_VAL;
    for (int i = 0; i < 3; i++) {
        double h = 0.5 * (a->hi[i] - a->lo[i]);
        double m = 0.5 * (a->hi[i] + a->lo[i]);
        q[i] = fabs(p[i] - m) - h;
        if (q[i] > 0) outside += q[i] * q[i];
        if (q[i] > inside) inside = q[i];
    }
    return outside > 0 ? sqrt(outside) : inside;
}

static void analytic_gradient(void *user, const double p[3], double g[3]) {
    const analytic *a = user;
    if (!a->is_box) {
        double d[3] = {p[0] - a->c[0], p[1] - a->c[1], p[2] - a->c[2]};
        double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int i = 0; i < 3; i++) g[i] = n > 0 ? d[i] / n : (i == 2);
        return;
    }
    double q[3], outside = 0.0;
    int best = 0;
    for (int i = 0; i < 3; i++) {
        double h = 0.5 * (a->hi[i] - a->lo[i]), m = 0.5 * (a->hi[i] + a->lo[i]);
        q[i] = fabs(p[i] - m) - h;
        if (q[i] > q[best]) best = i;
        if (q[i] > 0) outside += q[i] * q[i];
    }
    double s[3];
    for (int i = 0; i < 3; i++) s[i] = p[i] >= 0.5 * (a->hi[i] + a->lo[i]) ? 1.0 : -1.0;
    if (outside > 0) {
        double n = sqrt(outside);
        for (int i = 0; i < 3; i++) g[i] = q[i] > 0 ? s[i] * q[i] / n : 0.0;
    } else {
        for (int i = 0; i < 3; i++) g[i] = i == best ? s[i] : 0.0;
    }
}

vp_result vp_container_wrap(vp_context *ctx, const vp_container_ops *ops, void *user,
                            const vp_container_info *info, vp_container **out) {
    if (!out || !ops || !ops->distance)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "container: distance callback missing");
    *out = NULL;
    vp_container *c = calloc(1, sizeof *c);
    if (!c) return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "container: out of memory");
    c->ops = *ops;
    c->user = user;
    c->info = *info;
    *out = c;
    return VP_OK;
}

static vp_result make_analytic(vp_context *ctx, analytic *a, const double lo[3], const double hi[3],
                               double volume, vp_container **out) {
    static const vp_container_ops ops = {analytic_distance, analytic_gradient, free};
    vp_container_info info;
    memset(&info, 0, sizeof info);
    info.kind = VP_CONTAINER_ANALYTIC;
    memcpy(info.bmin, lo, sizeof info.bmin);
    memcpy(info.bmax, hi, sizeof info.bmax);
    info.volume = volume;
    info.interior_band = HUGE_VAL;
    vp_result r = vp_container_wrap(ctx, &ops, a, &info, out);
    if (r != VP_OK) free(a);
    return r;
}

static int finite3(const double v[3]) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

/* Particle positions are stored as float: an analytic container must lie
 * well inside float's range (and its volume inside double's). */
#define VP_ANALYTIC_LIMIT 1e18

static int in_range3(const double v[3]) {
    return fabs(v[0]) <= VP_ANALYTIC_LIMIT && fabs(v[1]) <= VP_ANALYTIC_LIMIT &&
           fabs(v[2]) <= VP_ANALYTIC_LIMIT;
}

vp_result vp_container_create_sphere(vp_context *ctx, const double center[3], double radius,
                                     vp_container **out) {
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "container: out is NULL");
    *out = NULL;
    if (!center || !finite3(center) || !(radius > 0) || !isfinite(radius))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "sphere container: the radius must be a positive finite number");
    if (!in_range3(center) || radius > VP_ANALYTIC_LIMIT)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "sphere container: it must lie within +-1e18 of the origin (positions are "
                       "stored as float)");
    analytic *a = calloc(1, sizeof *a);
    if (!a) return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "container: out of memory");
    double lo[3], hi[3];
    for (int i = 0; i < 3; i++) {
        a->c[i] = center[i];
        lo[i] = center[i] - radius;
        hi[i] = center[i] + radius;
    }
    a->r = radius;
    return make_analytic(ctx, a, lo, hi, 4.0 / 3.0 * M_PI * radius * radius * radius, out);
}

vp_result vp_container_create_box(vp_context *ctx, const double bmin[3], const double bmax[3],
                                  vp_container **out) {
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "container: out is NULL");
    *out = NULL;
    if (!bmin || !bmax || !finite3(bmin) || !finite3(bmax) || !(bmax[0] > bmin[0]) ||
        !(bmax[1] > bmin[1]) || !(bmax[2] > bmin[2]))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "box container: every size must be a positive finite number");
    if (!in_range3(bmin) || !in_range3(bmax))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "box container: it must lie within +-1e18 of the origin (positions are "
                       "stored as float)");
    analytic *a = calloc(1, sizeof *a);
    if (!a) return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "container: out of memory");
    a->is_box = 1;
    memcpy(a->lo, bmin, sizeof a->lo);
    memcpy(a->hi, bmax, sizeof a->hi);
    double vol = (bmax[0] - bmin[0]) * (bmax[1] - bmin[1]) * (bmax[2] - bmin[2]);
    return make_analytic(ctx, a, bmin, bmax, vol, out);
}

vp_result vp_container_create_custom(vp_context *ctx, const vp_container_ops *ops, void *user,
                                     const double bmin[3], const double bmax[3], double volume,
                                     vp_container **out) {
    if (!bmin || !bmax || !finite3(bmin) || !finite3(bmax))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "custom container: bounds must be finite");
    vp_container_info info;
    memset(&info, 0, sizeof info);
    info.kind = VP_CONTAINER_ANALYTIC;
    memcpy(info.bmin, bmin, sizeof info.bmin);
    memcpy(info.bmax, bmax, sizeof info.bmax);
    info.volume = volume;
    info.interior_band = HUGE_VAL;
    return vp_container_wrap(ctx, ops, user, &info, out);
}

void vp_container_destroy(vp_container *c) {
    if (!c) return;
    if (c->ops.destroy) c->ops.destroy(c->user);
    free(c);
}

double vp_container_distance(const vp_container *c, const double p[3]) {
    return c->ops.distance(c->user, p);
}

void vp_container_distances(const vp_container *c, const double *points, size_t n, double *out) {
    if (!c || !points || !out) return;
    for (size_t i = 0; i < n; i++) out[i] = c->ops.distance(c->user, points + 3 * i);
}

void vp_container_gradient(const vp_container *c, const double p[3], double g[3]) {
    if (c->ops.gradient) {
        c->ops.gradient(c->user, p, g);
        return;
    }
    double h = c->info.voxel_size > 0 ? 0.5 * c->info.voxel_size : 1e-6;
    double n = 0;
    for (int i = 0; i < 3; i++) {
        double a[3] = {p[0], p[1], p[2]}, b[3] = {p[0], p[1], p[2]};
        a[i] += h;
        b[i] -= h;
        g[i] = c->ops.distance(c->user, a) - c->ops.distance(c->user, b);
        n += g[i] * g[i];
    }
    n = sqrt(n);
    for (int i = 0; i < 3; i++) g[i] = n > 0 ? g[i] / n : 0.0;
}

void vp_container_get_info(const vp_container *c, vp_container_info *info) {
    if (c && info) *info = c->info;
}
