/* SPDX-License-Identifier: Apache-2.0 */
/* Random sequential addition driven by fields (docs/fields.md): a radius
 * field gives each candidate the radius at its centre, a density field
 * thins the darts to a relative number density. One plain mechanism,
 * separate from rsa.c (whose empty-space cells assume one radius per
 * pass): darts uniform in the box of the container's inside, kept with
 * probability density(x) / max density, given radius r(x), accepted when
 * the wall and every placed sphere are clear (the mixed-size neighbour
 * grid of sgrid.h). Serial, and deterministic in the seed: dart k of pass
 * i draws from its own stream (seed, i, k). */
#include "core/container.h"
#include "core/context.h"
#include "core/field.h"
#include "core/rng.h"
#include "core/rsa_field.h"
#include "core/sgrid.h"
#include "core/size_dist_sample.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct fstate {
    vp_particles *p;
    double *pos; /* 3 per particle */
    float *rad;
    uint16_t *grp;
    size_t cap;
    vp_sgrid g;
    /* the candidate of the visitor */
    const double *x;
    double r, gap;
} fstate;

static int grow(fstate *s, size_t n) {
    if (n <= s->cap) return 0;
    size_t cap = s->cap ? s->cap : 1024;
    while (cap < n) cap += cap / 2;
    double *pos = realloc(s->pos, cap * 3 * sizeof *pos);
    if (!pos) return -1;
    s->pos = pos;
    float *rad = realloc(s->rad, cap * sizeof *rad);
    if (!rad) return -1;
    s->rad = rad;
    uint16_t *grp = realloc(s->grp, cap * sizeof *grp);
    if (!grp) return -1;
    s->grp = grp;
    if (vp_sgrid_reserve(&s->g, cap) != 0) return -1;
    s->cap = cap;
    return 0;
}

static int hits(void *user, uint32_t j) {
    const fstate *s = user;
    const double *c = s->pos + 3 * (size_t)j;
    double dx = s->x[0] - c[0], dy = s->x[1] - c[1], dz = s->x[2] - c[2];
    double need = s->r + (double)s->rad[j] + s->gap;
    return dx * dx + dy * dy + dz * dz < need * need;
}

/* The radius as stored: a float no larger than r. */
static double float_radius(double r) {
    float f = (float)r;
    if ((double)f > r) f = nextafterf(f, 0.0f);
    return (double)f;
}

vp_result vp_rsa_fields_pack(vp_context *ctx, const vp_container *c, const vp_rsa_params *params,
                             vp_particles **out, vp_rsa_report *report) {
    double t0 = vp_seconds();
    const vp_field *rf = params->radius_field, *df = params->density_field;
    if (params->shape != VP_SHAPE_SPHERE)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "rsa: radius and density fields pack spheres in this version");
    if (rf && params->radius_field_mode != VP_FIELD_SCALE &&
        params->radius_field_mode != VP_FIELD_ABSOLUTE)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "rsa: unknown radius field mode");
    double fmin = 1.0, fmax = 1.0, dmax = 1.0, dmin;
    vp_result r;
    if (rf && (r = vp_field_check(ctx, rf, "rsa", "radius field", 1, c, &fmin, &fmax)) != VP_OK)
        return r;
    if (df && (r = vp_field_check(ctx, df, "rsa", "density field", 0, c, &dmin, &dmax)) != VP_OK)
        return r;
    int absolute = rf && params->radius_field_mode == VP_FIELD_ABSOLUTE;
    double rmin = HUGE_VAL, rmax = 0.0;
    for (size_t i = 0; i < params->npasses; i++) {
        const vp_rsa_pass *ps = &params->passes[i];
        if (ps->retries < 0 || (!ps->maximal && ps->count == 0))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "rsa: pass %zu: count and retries must be > 0", i + 1);
        if (ps->grow)
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "rsa: pass %zu: grow does not go with a radius or density field", i + 1);
        double a = absolute ? fmin : fmin * vp_size_dist_min(&ps->radius);
        double b = absolute ? fmax : fmax * vp_size_dist_max(&ps->radius);
        if (!(a > 0) || !isfinite(b))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "rsa: pass %zu: radii must be finite and > 0", i + 1);
        if (params->gap > 0 && !(params->gap < a))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "rsa: pass %zu: the gap %.6g must be smaller than the smallest radius "
                           "the field gives (%.6g)",
                           i + 1, params->gap, a);
        if (a < rmin) rmin = a;
        if (b > rmax) rmax = b;
        if (!ps->maximal && ps->count >= UINT32_MAX / 2)
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "rsa: pass %zu: count too large", i + 1);
    }
    double lo[3], hi[3];
    vp_container_inside_box(c, lo, hi);

    fstate s;
    memset(&s, 0, sizeof s);
    s.gap = params->gap;
    if ((r = vp_particles_create(ctx, 0, &s.p)) != VP_OK) return r;
    if (vp_sgrid_init(&s.g, lo, hi, rmin + 0.5 * s.gap, rmax + 0.5 * s.gap, (size_t)1 << 24) != 0) {
        vp_particles_destroy(s.p);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "rsa: out of memory for the neighbour grid");
    }
    vp_rsa_report rep;
    memset(&rep, 0, sizeof rep);
    rep.npasses = params->npasses;
    s.p->group_count = (unsigned)params->npasses;
    for (size_t i = 0; i < params->npasses; i++) {
        if (params->passes[i].name[0])
            snprintf(s.p->group_names[i], VP_GROUP_NAME_MAX, "%s", params->passes[i].name);
        else snprintf(s.p->group_names[i], VP_GROUP_NAME_MAX, "pass%zu", i + 1);
    }
    size_t n = 0;
    for (size_t i = 0; i < params->npasses && r == VP_OK; i++) {
        const vp_rsa_pass *ps = &params->passes[i];
        vp_rsa_pass_report *pr = &rep.passes[i];
        double tp = vp_seconds();
        uint64_t retries = ps->retries > 0 ? (uint64_t)ps->retries : VP_RSA_DEFAULT_RETRIES;
        /* darts that miss the container or are thinned out are not tries;
         * this many of them in a row end the pass too (a field that is
         * nearly 0 everywhere, a container far smaller than its box) */
        uint64_t misses_max = 1000 * retries + 1000000;
        uint64_t fails = 0, misses = 0, seed = vp_rng_stream(params->seed, 0x5EED0000u + i);
        pr->requested = ps->maximal ? 0 : ps->count;
        pr->stop = VP_RSA_STOP_RETRIES;
        pr->grow_mean = 1.0;
        size_t placed = 0;
        for (uint64_t k = 0;; k++) {
            if (!ps->maximal && placed >= ps->count) {
                pr->stop = VP_RSA_STOP_COUNT;
                break;
            }
            if (fails >= retries || misses >= misses_max) break;
            if ((k & 4095) == 0) {
                double done = ps->maximal ? (double)fails / (double)retries
                                          : (double)placed / (double)ps->count;
                if (!vp_report_progress_counts(ctx, ((double)i + done) / (double)params->npasses,
                                               "rsa", placed, ps->maximal ? 0 : ps->count)) {
                    r = vp_fail(ctx, VP_ERR_CANCELLED, "rsa: cancelled");
                    break;
                }
            }
            uint64_t st = vp_rng_stream(seed, k);
            double x[3];
            for (int a = 0; a < 3; a++) x[a] = lo[a] + (hi[a] - lo[a]) * vp_rng_uniform(&st);
            double u = vp_rng_uniform(&st); /* drawn for every dart: streams stay aligned */
            double d = vp_container_distance(c, x);
            if (!(d <= -params->margin)) { /* not even the centre fits */
                misses++;
                continue;
            }
            if (df && !(u * dmax < vp_field_at(df, x))) {
                misses++;
                continue;
            }
            double rad =
                absolute ? vp_field_at(rf, x)
                         : vp_size_dist_sample(&ps->radius, &st) * (rf ? vp_field_at(rf, x) : 1.0);
            rad = float_radius(rad);
            if (!(rad > 0) || !isfinite(rad)) {
                r = vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                            "rsa: the radius field gives %g at (%g, %g, %g); radii must be "
                            "positive",
                            rad, x[0], x[1], x[2]);
                break;
            }
            misses = 0;
            pr->tries++;
            if (params->fit == VP_FIT_INSIDE && !(d <= -(rad + params->margin))) {
                fails++;
                continue;
            }
            s.x = x;
            s.r = rad;
            if (vp_sgrid_query_near(&s.g, x, rad + s.gap, hits, &s)) {
                fails++;
                continue;
            }
            if (grow(&s, n + 1) != 0 || vp_sgrid_insert(&s.g, (uint32_t)n, x, rad) != 0) {
                r = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "rsa: out of memory at %zu particles", n);
                break;
            }
            memcpy(s.pos + 3 * n, x, sizeof x);
            s.rad[n] = (float)rad;
            s.grp[n] = (uint16_t)i;
            n++;
            placed++;
            fails = 0;
        }
        pr->placed = placed;
        pr->seconds = vp_seconds() - tp;
    }
    vp_sgrid_free(&s.g);
    if (r != VP_OK) {
        free(s.pos);
        free(s.rad);
        free(s.grp);
        vp_particles_destroy(s.p);
        return r;
    }
    s.p->count = n;
    s.p->capacity = s.cap;
    s.p->positions = s.pos ? s.pos : malloc(3 * sizeof(double));
    s.p->radii = s.rad ? s.rad : malloc(sizeof(float));
    s.p->groups = s.grp ? s.grp : malloc(sizeof(uint16_t));
    if (!s.p->positions || !s.p->radii || !s.p->groups) {
        vp_particles_destroy(s.p);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "rsa: out of memory");
    }
    rep.particle_volume = vp_particles_volume(s.p);
    rep.seconds = vp_seconds() - t0;
    if (report) *report = rep;
    *out = s.p;
    return VP_OK;
}
