/* SPDX-License-Identifier: Apache-2.0 */
/* Fields (include/vdbpack/field.h): the callback wrapper, custom fields,
 * and the checks a field must pass to drive a packing of a container. */
#include "core/field.h"
#include "core/container.h"
#include "core/context.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

const char *vp_field_mode_name(vp_field_mode m) {
    return m == VP_FIELD_SCALE ? "scale" : m == VP_FIELD_ABSOLUTE ? "absolute" : NULL;
}

int vp_field_mode_parse(const char *name, vp_field_mode *out) {
    if (!name || !out) return -1;
    if (!strcmp(name, "scale")) *out = VP_FIELD_SCALE;
    else if (!strcmp(name, "absolute")) *out = VP_FIELD_ABSOLUTE;
    else return -1;
    return 0;
}

vp_result vp_field_wrap(vp_context *ctx, const vp_field_ops *ops, void *user,
                        const vp_field_info *info, vp_field **out) {
    if (!out || !ops || !ops->sample)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "field: sample callback missing");
    *out = NULL;
    vp_field *f = calloc(1, sizeof *f);
    if (!f) return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "field: out of memory");
    f->ops = *ops;
    f->user = user;
    f->info = *info;
    *out = f;
    return VP_OK;
}

vp_result vp_field_create_custom(vp_context *ctx, const vp_field_ops *ops, void *user,
                                 const double bmin[3], const double bmax[3], double vmin,
                                 double vmax, vp_field **out) {
    vp_result r = VP_OK;
    if (!out || !ops || !ops->sample || !bmin || !bmax)
        r = vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                    "custom field: a sample callback, bounds and "
                    "out are required");
    for (int k = 0; r == VP_OK && k < 3; k++)
        if (!isfinite(bmin[k]) || !isfinite(bmax[k]) || !(bmax[k] >= bmin[k]))
            r = vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                        "custom field: bounds must be finite, "
                        "bmin <= bmax");
    if (r == VP_OK && (!isfinite(vmin) || !isfinite(vmax) || !(vmax >= vmin)))
        r = vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                    "custom field: the value range must be "
                    "finite, vmin <= vmax");
    if (r == VP_OK) {
        vp_field_info info;
        memset(&info, 0, sizeof info);
        memcpy(info.bmin, bmin, sizeof info.bmin);
        memcpy(info.bmax, bmax, sizeof info.bmax);
        info.min = vmin;
        info.max = vmax;
        r = vp_field_wrap(ctx, ops, user, &info, out);
    }
    if (r != VP_OK && ops && ops->destroy && user) ops->destroy(user);
    return r;
}

void vp_field_destroy(vp_field *f) {
    if (!f) return;
    if (f->ops.destroy) f->ops.destroy(f->user);
    free(f);
}

double vp_field_sample(const vp_field *f, const double p[3]) { return f->ops.sample(f->user, p); }

void vp_field_get_info(const vp_field *f, vp_field_info *info) {
    if (f && info) *info = f->info;
}

vp_result vp_field_range(vp_context *ctx, const vp_field *f, const double lo[3], const double hi[3],
                         double *vmin, double *vmax) {
    if (!f || !lo || !hi || !vmin || !vmax)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "field range: NULL argument");
    if (!f->range) {
        *vmin = f->info.min;
        *vmax = f->info.max;
        return VP_OK;
    }
    char err[512] = "";
    if (f->range(f, lo, hi, vmin, vmax, err, sizeof err) != 0)
        return vp_fail(ctx, VP_ERR_INTERNAL, "field range: %s", err);
    return VP_OK;
}

void vp_container_inside_box(const vp_container *c, double lo[3], double hi[3]) {
    if (!c || !lo || !hi) return;
    if (c->inside_box && c->inside_box(c, lo, hi) == 0) return;
    memcpy(lo, c->info.bmin, 3 * sizeof *lo);
    memcpy(hi, c->info.bmax, 3 * sizeof *hi);
}

vp_result vp_field_check(vp_context *ctx, const vp_field *f, const char *name, const char *what,
                         int positive, const vp_container *c, double *vmin, double *vmax) {
    if (!f || !c) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "field check: NULL argument");
    if (!name) name = "field";
    if (!what) what = "field";
    double lo[3], hi[3];
    vp_container_inside_box(c, lo, hi);
    const double *fl = f->info.bmin, *fh = f->info.bmax;
    for (int k = 0; k < 3; k++) {
        double tol = 1e-9 * fmax(fabs(lo[k]) + fabs(hi[k]), hi[k] - lo[k]);
        if (fl[k] > lo[k] + tol || fh[k] < hi[k] - tol)
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "%s: the %s does not cover the container: its box [%g %g %g]..[%g %g "
                           "%g] misses part of the container's inside [%g %g %g]..[%g %g %g] "
                           "(a field must cover it; nothing is assumed outside a field)",
                           name, what, fl[0], fl[1], fl[2], fh[0], fh[1], fh[2], lo[0], lo[1],
                           lo[2], hi[0], hi[1], hi[2]);
    }
    double mn, mx;
    vp_result r = vp_field_range(ctx, f, lo, hi, &mn, &mx);
    if (r != VP_OK) return r;
    if (positive && !(mn > 0))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "%s: the %s has values down to %g over the container; radii must be "
                       "positive",
                       name, what, mn + 0.0);
    if (!positive && !(mn >= 0))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "%s: the %s has values down to %g over the container; a density must "
                       "not be negative",
                       name, what, mn);
    if (!positive && !(mx > 0))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "%s: the %s is 0 everywhere over the container: no particle could be "
                       "placed",
                       name, what);
    if (vmin) *vmin = mn;
    if (vmax) *vmax = mx;
    return VP_OK;
}

vp_result vp_field_radii(vp_context *ctx, const vp_container *c, const vp_field *f,
                         vp_field_mode mode, const double *x, size_t xstride, double *r,
                         size_t rstride, size_t n, int keep_volume, double *rmin, double *rmax) {
    if (mode != VP_FIELD_SCALE && mode != VP_FIELD_ABSOLUTE)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "unknown radius field mode");
    vp_result res = vp_field_check(ctx, f, "radius field", "radius field", 1, c, NULL, NULL);
    if (res != VP_OK) return res;
    double before = 0.0, after = 0.0;
    for (size_t i = 0; i < n; i++) {
        double *ri = r + rstride * i, v = vp_field_at(f, x + xstride * i);
        if (!(v > 0) || !isfinite(v))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "the radius field gives %g at (%g, %g, %g); radii must be positive", v,
                           x[xstride * i], x[xstride * i + 1], x[xstride * i + 2]);
        before += *ri * *ri * *ri;
        *ri = mode == VP_FIELD_ABSOLUTE ? v : *ri * v;
        after += *ri * *ri * *ri;
    }
    double k = keep_volume && after > 0 ? cbrt(before / after) : 1.0, lo = HUGE_VAL, hi = 0.0;
    for (size_t i = 0; i < n; i++) {
        double *ri = r + rstride * i;
        *ri *= k;
        if (*ri < lo) lo = *ri;
        if (*ri > hi) hi = *ri;
    }
    if (n && (!(lo >= FLT_MIN) || !(hi <= FLT_MAX)))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "the radius field gives radii of %g..%g, outside 1.2e-38..3.4e38 (radii "
                       "are stored as float)",
                       lo, hi);
    if (rmin) *rmin = lo;
    if (rmax) *rmax = hi;
    return VP_OK;
}
