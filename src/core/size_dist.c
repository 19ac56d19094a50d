/* SPDX-License-Identifier: Apache-2.0 */
/* Particle size distributions: parsing, moments and sampling. */
#include "core/context.h"
#include "core/rng.h"
#include "core/size_dist_sample.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The lognormal is truncated at +-Z standard deviations in log space. */
#define VP_LOGNORMAL_Z 3.719016485455709 /* Phi^-1(1 - 1e-4) */

void vp_size_dist_constant(vp_size_dist *d, double r) {
    memset(d, 0, sizeof *d);
    d->kind = VP_SIZE_CONSTANT;
    d->a = d->b = r;
}

static int parse_pos(const char *s, const char *end, double *out) {
    char buf[64];
    size_t n = (size_t)(end - s);
    if (n == 0 || n >= sizeof buf) return -1;
    memcpy(buf, s, n);
    buf[n] = 0;
    char *e = NULL;
    errno = 0;
    double v = strtod(buf, &e);
    if (e == buf || *e || errno == ERANGE || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

static vp_result bad(vp_context *ctx, const char *text, const char *why) {
    if (ctx) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "size '%s': %s", text, why);
    return VP_ERR_INVALID_ARGUMENT;
}

/* Radii are stored as float (pscale): every size the law can draw must be
 * a normal float, or it would be stored as 0 (or infinity). */
static vp_result float_range(vp_context *ctx, const char *text, const vp_size_dist *d,
                             vp_size_dist *out) {
    double lo = vp_size_dist_min(d), hi = vp_size_dist_max(d);
    if (!(lo >= FLT_MIN))
        return bad(ctx, text,
                   d->kind == VP_SIZE_CONSTANT
                       ? "a radius must be at least 1.2e-38 (radii are stored as float)"
                       : "its sizes reach below 1.2e-38 (radii are stored as float)");
    if (!(hi <= FLT_MAX))
        return bad(ctx, text,
                   d->kind == VP_SIZE_CONSTANT
                       ? "a radius must be at most 3.4e38 (radii are stored as float)"
                       : "its sizes reach above 3.4e38 (radii are stored as float)");
    *out = d[0];
    return VP_OK;
}

vp_result vp_size_dist_parse(vp_context *ctx, const char *text, vp_size_dist *out) {
    if (!text || !out) return bad(ctx, text ? text : "(null)", "no text");
    vp_size_dist d;
    memset(&d, 0, sizeof d);
    const char *colon = strchr(text, ':');
    if (!colon) {
        double v;
        if (parse_pos(text, text + strlen(text), &v) != 0)
            return bad(ctx, text,
                       "not a number or a distribution (uniform:A:B, "
                       "lognormal:MEAN:SD, list:R1:R2:...)");
        if (!(v > 0)) return bad(ctx, text, "a radius must be > 0");
        vp_size_dist_constant(&d, v);
        return float_range(ctx, text, &d, out);
    }
    size_t klen = (size_t)(colon - text);
    double vals[VP_SIZE_LIST_MAX + 1];
    unsigned n = 0;
    const char *s = colon + 1;
    for (;;) {
        const char *e = strchr(s, ':');
        if (!e) e = s + strlen(s);
        if (n > VP_SIZE_LIST_MAX) return bad(ctx, text, "too many values (at most 64)");
        if (parse_pos(s, e, &vals[n]) != 0) return bad(ctx, text, "a value is not a number");
        n++;
        if (!*e) break;
        s = e + 1;
    }
    if (klen == 7 && !strncmp(text, "uniform", 7)) {
        if (n != 2) return bad(ctx, text, "uniform takes two values: uniform:A:B");
        if (!(vals[0] > 0)) return bad(ctx, text, "sizes must be > 0");
        if (vals[0] > vals[1]) return bad(ctx, text, "uniform:A:B needs A <= B");
        d.kind = VP_SIZE_UNIFORM;
        d.a = vals[0];
        d.b = vals[1];
    } else if (klen == 9 && !strncmp(text, "lognormal", 9)) {
        if (n != 2) return bad(ctx, text, "lognormal takes two values: lognormal:MEAN:SD");
        if (!(vals[0] > 0)) return bad(ctx, text, "the mean must be > 0");
        if (vals[1] < 0) return bad(ctx, text, "the standard deviation must be >= 0");
        d.kind = VP_SIZE_LOGNORMAL;
        d.a = vals[0];
        d.b = vals[1];
    } else if (klen == 4 && !strncmp(text, "list", 4)) {
        if (n > VP_SIZE_LIST_MAX) return bad(ctx, text, "too many values (at most 64)");
        for (unsigned i = 0; i < n; i++)
            if (!(vals[i] > 0)) return bad(ctx, text, "sizes must be > 0");
        d.kind = VP_SIZE_LIST;
        d.n = n;
        memcpy(d.values, vals, n * sizeof *vals);
    } else {
        return bad(ctx, text,
                   "unknown distribution (uniform:A:B, lognormal:MEAN:SD, "
                   "list:R1:R2:...)");
    }
    return float_range(ctx, text, &d, out);
}

/* mu, sigma of log r for mean m and standard deviation sd of r. */
static void lognormal_params(const vp_size_dist *d, double *mu, double *sigma) {
    double m = d->a, sd = d->b;
    double s2 = log1p((sd * sd) / (m * m));
    *sigma = sqrt(s2);
    *mu = log(m) - 0.5 * s2;
}

double vp_size_dist_min(const vp_size_dist *d) {
    switch (d->kind) {
    case VP_SIZE_CONSTANT: return d->a;
    case VP_SIZE_UNIFORM: return d->a;
    case VP_SIZE_LOGNORMAL: {
        double mu, s;
        lognormal_params(d, &mu, &s);
        return exp(mu - VP_LOGNORMAL_Z * s);
    }
    case VP_SIZE_LIST: {
        double m = d->values[0];
        for (unsigned i = 1; i < d->n; i++) m = fmin(m, d->values[i]);
        return m;
    }
    }
    return d->a;
}

double vp_size_dist_max(const vp_size_dist *d) {
    switch (d->kind) {
    case VP_SIZE_CONSTANT: return d->a;
    case VP_SIZE_UNIFORM: return d->b;
    case VP_SIZE_LOGNORMAL: {
        double mu, s;
        lognormal_params(d, &mu, &s);
        return exp(mu + VP_LOGNORMAL_Z * s);
    }
    case VP_SIZE_LIST: {
        double m = d->values[0];
        for (unsigned i = 1; i < d->n; i++) m = fmax(m, d->values[i]);
        return m;
    }
    }
    return d->a;
}

/* E[r^k] of the lognormal truncated to |z| <= Z: exp(k mu + k^2 s^2 / 2) *
 * (Phi(Z - k s) - Phi(-Z - k s)) / (Phi(Z) - Phi(-Z)). */
static double lognormal_moment(const vp_size_dist *d, int k) {
    double mu, s;
    lognormal_params(d, &mu, &s);
    double ks = k * s, Z = VP_LOGNORMAL_Z;
    double num = 0.5 * (erfc(-(Z - ks) / M_SQRT2) - erfc(-(-Z - ks) / M_SQRT2));
    double den = 0.5 * (erfc(-Z / M_SQRT2) - erfc(Z / M_SQRT2));
    return exp(k * mu + 0.5 * ks * ks) * num / den;
}

double vp_size_dist_mean(const vp_size_dist *d) {
    switch (d->kind) {
    case VP_SIZE_CONSTANT: return d->a;
    case VP_SIZE_UNIFORM: return 0.5 * (d->a + d->b);
    case VP_SIZE_LOGNORMAL: return lognormal_moment(d, 1);
    case VP_SIZE_LIST: {
        double s = 0;
        for (unsigned i = 0; i < d->n; i++) s += d->values[i];
        return s / d->n;
    }
    }
    return d->a;
}

double vp_size_dist_rel_sd(const vp_size_dist *d) {
    double m1 = vp_size_dist_mean(d), m2 = 0;
    switch (d->kind) {
    case VP_SIZE_CONSTANT: return 0.0;
    case VP_SIZE_UNIFORM: return d->b > d->a ? (d->b - d->a) / sqrt(12.0) / m1 : 0.0;
    case VP_SIZE_LOGNORMAL: m2 = lognormal_moment(d, 2); break;
    case VP_SIZE_LIST:
        for (unsigned i = 0; i < d->n; i++) m2 += d->values[i] * d->values[i];
        m2 /= d->n;
        break;
    }
    double var = m2 - m1 * m1;
    return var > 0 && m1 > 0 ? sqrt(var) / m1 : 0.0;
}

double vp_size_dist_mean_cube(const vp_size_dist *d) {
    switch (d->kind) {
    case VP_SIZE_CONSTANT: return d->a * d->a * d->a;
    case VP_SIZE_UNIFORM: {
        double a = d->a, b = d->b;
        if (b - a <= 0) return a * a * a;
        return (b * b * b * b - a * a * a * a) / (4.0 * (b - a));
    }
    case VP_SIZE_LOGNORMAL: return lognormal_moment(d, 3);
    case VP_SIZE_LIST: {
        double s = 0;
        for (unsigned i = 0; i < d->n; i++) s += d->values[i] * d->values[i] * d->values[i];
        return s / d->n;
    }
    }
    return d->a;
}

void vp_size_dist_scale(vp_size_dist *d, double k) {
    switch (d->kind) {
    case VP_SIZE_LOGNORMAL: /* mean and sd scale alike */
    case VP_SIZE_CONSTANT:
    case VP_SIZE_UNIFORM:
        d->a *= k;
        d->b *= k;
        break;
    case VP_SIZE_LIST:
        for (unsigned i = 0; i < d->n; i++) d->values[i] *= k;
        break;
    }
}

/* The shortest of %.15g, %.16g, %.17g that reads back as v: 0.004493 stays
 * "0.004493" (not 0.0044929999999999996), and the text still gives v exactly. */
static void fmt_exact(char *buf, size_t len, double v) {
    for (int prec = 15; prec <= 17; prec++) {
        snprintf(buf, len, "%.*g", prec, v);
        if (prec == 17 || strtod(buf, NULL) == v) return;
    }
}

void vp_size_dist_format(const vp_size_dist *d, char *out, size_t outlen) {
    char a[32], b[32];
    switch (d->kind) {
    case VP_SIZE_CONSTANT: fmt_exact(out, outlen, d->a); return;
    case VP_SIZE_UNIFORM:
    case VP_SIZE_LOGNORMAL:
        fmt_exact(a, sizeof a, d->a);
        fmt_exact(b, sizeof b, d->b);
        snprintf(out, outlen, "%s:%s:%s", d->kind == VP_SIZE_UNIFORM ? "uniform" : "lognormal", a,
                 b);
        return;
    case VP_SIZE_LIST: {
        size_t at = (size_t)snprintf(out, outlen, "list");
        for (unsigned i = 0; i < d->n && at < outlen; i++) {
            fmt_exact(a, sizeof a, d->values[i]);
            at += (size_t)snprintf(out + at, outlen - at, ":%s", a);
        }
        return;
    }
    }
}

double vp_size_dist_sample(const vp_size_dist *d, uint64_t *s) {
    switch (d->kind) {
    case VP_SIZE_CONSTANT: return d->a;
    case VP_SIZE_UNIFORM: return d->a + (d->b - d->a) * vp_rng_uniform(s);
    case VP_SIZE_LOGNORMAL: {
        double mu, sg;
        lognormal_params(d, &mu, &sg);
        for (;;) { /* truncation by rejection: accepts 99.98 % */
            double z = vp_rng_normal(s);
            if (fabs(z) <= VP_LOGNORMAL_Z) return exp(mu + sg * z);
        }
    }
    case VP_SIZE_LIST: return d->values[vp_rng_next(s) % d->n];
    }
    return d->a;
}

/* Standard normal distribution function. */
static double normal_cdf(double z) { return 0.5 * erfc(-z / sqrt(2.0)); }

double vp_size_dist_sample_below(const vp_size_dist *d, double c, uint64_t *s) {
    double lo = vp_size_dist_min(d);
    if (!(c > lo)) return lo;
    switch (d->kind) {
    case VP_SIZE_CONSTANT: return d->a;
    case VP_SIZE_UNIFORM: return d->a + ((c < d->b ? c : d->b) - d->a) * vp_rng_uniform(s);
    case VP_SIZE_LOGNORMAL: {
        /* inverse transform of the normal truncated to [-Z, zc], inverted
         * by bisection: exact to the double, deterministic, and only the
         * last particles of a maximal pass need it */
        double mu, sg;
        lognormal_params(d, &mu, &sg);
        if (!(sg > 0)) return exp(mu);
        double zl = -VP_LOGNORMAL_Z, zh = (log(c) - mu) / sg;
        if (zh > VP_LOGNORMAL_Z) zh = VP_LOGNORMAL_Z;
        if (!(zh > zl)) return lo;
        double pl = normal_cdf(zl), u = pl + (normal_cdf(zh) - pl) * vp_rng_uniform(s);
        double a = zl, b = zh;
        for (int i = 0; i < 80 && b - a > 1e-15 * (fabs(a) + 1.0); i++) {
            double m = 0.5 * (a + b);
            if (normal_cdf(m) < u) a = m;
            else b = m;
        }
        double r = exp(mu + sg * 0.5 * (a + b));
        return r < lo ? lo : r > c ? c : r;
    }
    case VP_SIZE_LIST: {
        unsigned n = 0;
        for (unsigned i = 0; i < d->n; i++) n += d->values[i] <= c;
        if (!n) return lo;
        unsigned k = (unsigned)(vp_rng_next(s) % n);
        for (unsigned i = 0; i < d->n; i++)
            if (d->values[i] <= c && k-- == 0) return d->values[i];
        return lo;
    }
    }
    return lo;
}
