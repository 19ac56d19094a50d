/* SPDX-License-Identifier: Apache-2.0 */
/* Relaxation packer after He, Ekere & Cai (1999); see relax.h and
 * docs/relax.md.
 *
 * Overlap relaxation: in one sweep every sphere i that overlaps others
 * moves to the mean, over its overlapping neighbours j, of the position at
 * which it would just touch j along the line of centres,
 *     R_j + (R_i - R_j) (r_i + r_j) / d_ij,
 * and the wall counts as one more neighbour (the centre pushed back along
 * the distance gradient until the sphere touches it). All moves of a sweep
 * are computed from the positions before it (Jacobi), so a sweep runs in
 * parallel and the result does not depend on the thread count.
 * Radius relaxation: when the largest overlap stops falling, every sphere
 * that still overlaps shrinks by a small part of its own worst overlap.
 * At the end a last radius step removes what is left exactly (each sphere
 * shrinks by half its worst pair overlap and all of its wall overlap), so
 * the output has no overlap at all in double precision. */
#include "core/container.h"
#include "core/context.h"
#include "core/field.h"
#include "core/geom.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/sgrid.h"
#include "core/size_dist_sample.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Schedule (tuned on 10k spheres at a target of 0.62, docs/relax.md): every
 * STALL_WINDOW sweeps, if the worst overlap did not fall below STALL_GAIN of
 * the previous window's, each sphere still overlapping shrinks by SHRINK of
 * its worst relative overlap. Overlap relaxation stops once the worst
 * overlap is below FINISH (or the tolerance, if larger); the exact last
 * radius step then takes at most FINISH of r_i + r_j / 2 from a radius for a
 * pair, and all of a wall overlap (up to 2 FINISH r_i). */
#define STALL_WINDOW 64
#define STALL_GAIN 0.9
#define SHRINK 0.25
#define FINISH 1e-2
#define NCHUNKS 64

void vp_relax_params_init(vp_relax_params *p) {
    memset(p, 0, sizeof *p);
    p->fit = VP_FIT_INSIDE;
    vp_size_dist_constant(&p->radius, 1.0);
    p->tolerance = 1e-6;
}

typedef struct relax {
    const vp_container *c;
    vp_fit fit;
    double margin, gap; /* kept from the wall, between surfaces (world) */
    size_t n;
    double *x;   /* 3n positions */
    double *nx;  /* 3n positions after the sweep */
    double *r;   /* n radii */
    float *ov;   /* n worst relative overlap (pairs and wall) */
    float *wall; /* n wall overlap (world) */
    vp_sgrid g;
    double rmax;
    size_t chunk;
} relax;

typedef struct nb {
    const relax *s;
    size_t i;
    double sum[3];
    int k;
    double worst;     /* worst relative pair overlap */
    double worst_abs; /* worst pair overlap (world) */
} nb;

static int nb_visit(void *user, uint32_t j) {
    nb *q = user;
    if (j == q->i) return 0;
    const relax *s = q->s;
    const double *xi = s->x + 3 * q->i, *xj = s->x + 3 * (size_t)j;
    double rr = s->r[q->i] + s->r[j], e = rr + s->gap; /* the distance wanted */
    double d[3] = {xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2]};
    double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    if (d2 >= e * e) return 0;
    double dist = sqrt(d2);
    if (dist < 1e-12 * e) {
        /* coincident centres: separate along a direction fixed by the pair */
        uint64_t st = ((uint64_t)(q->i < j ? q->i : j) << 32) ^ (q->i < j ? j : q->i);
        double u[3] = {vp_rng_normal(&st), vp_rng_normal(&st), vp_rng_normal(&st)};
        double un = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        double sg = q->i < j ? 1.0 : -1.0;
        for (int k = 0; k < 3; k++) d[k] = sg * u[k] / un;
        dist = 1.0;
    }
    double f = e / dist;
    for (int k = 0; k < 3; k++) q->sum[k] += xj[k] + d[k] * f;
    q->k++;
    double o = (e - sqrt(d2)) / rr;
    if (o > q->worst) q->worst = o;
    if (e - sqrt(d2) > q->worst_abs) q->worst_abs = e - sqrt(d2);
    return 0;
}

/* Wall overlap of sphere i (world; <= 0: none) and the push direction. */
static double wall_overlap(const relax *s, const double x[3], double r, double g[3]) {
    double d = vp_container_distance(s->c, x);
    double w = (s->fit == VP_FIT_INSIDE ? d + r : d) + s->margin;
    if (w > 0) vp_container_gradient(s->c, x, g);
    return w;
}

static void sweep_chunk(void *user, size_t ci) {
    relax *s = user;
    size_t lo = ci * s->chunk, hi = lo + s->chunk;
    if (hi > s->n) hi = s->n;
    for (size_t i = lo; i < hi; i++) {
        const double *xi = s->x + 3 * i;
        double ri = s->r[i];
        nb q = {s, i, {0, 0, 0}, 0, 0.0, 0.0};
        vp_sgrid_query(&s->g, xi, ri + s->gap, nb_visit, &q);
        double g[3];
        double w = wall_overlap(s, xi, ri, g);
        if (w > 0) {
            for (int k = 0; k < 3; k++) q.sum[k] += xi[k] - w * g[k];
            q.k++;
        }
        double wo = w > 0 ? w / (2.0 * ri) : 0.0;
        s->ov[i] = (float)(q.worst > wo ? q.worst : wo);
        s->wall[i] = (float)(w > 0 ? w : 0.0);
        double *out = s->nx + 3 * i;
        if (!q.k) {
            memcpy(out, xi, 3 * sizeof *out);
            continue;
        }
        double mv[3], m2 = 0;
        for (int k = 0; k < 3; k++) {
            mv[k] = q.sum[k] / q.k - xi[k];
            m2 += mv[k] * mv[k];
        }
        /* at most half a radius per sweep: keeps centres inside the band
         * where the container's distance and gradient are exact */
        double lim = 0.5 * ri, f = m2 > lim * lim ? lim / sqrt(m2) : 1.0;
        for (int k = 0; k < 3; k++) out[k] = xi[k] + f * mv[k];
    }
}

typedef struct final_q {
    const relax *s;
    size_t i;
    double worst; /* worst pair overlap (world) */
} final_q;

static int final_visit(void *user, uint32_t j) {
    final_q *q = user;
    if (j == q->i) return 0;
    const double *xi = q->s->x + 3 * q->i, *xj = q->s->x + 3 * (size_t)j;
    double e = q->s->r[q->i] + q->s->r[j] + q->s->gap;
    double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
    double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 < e * e) {
        double o = e - sqrt(d2);
        if (o > q->worst) q->worst = o;
    }
    return 0;
}

/* Moves every centre that is outside (fit center) back along the distance
 * gradient until the distance there is <= -margin. */
static void project_centres(relax *s) {
    for (size_t i = 0; i < s->n; i++) {
        double *x = s->x + 3 * i;
        for (int it = 0; it < 8; it++) {
            double d = vp_container_distance(s->c, x) + s->margin;
            if (d <= 0) break;
            double g[3];
            vp_container_gradient(s->c, x, g);
            double step = d * (1.0 + 1e-9) + 1e-12 + (it ? 1e-9 * s->r[i] * (1 << it) : 0.0);
            for (int k = 0; k < 3; k++) x[k] -= step * g[k];
        }
    }
}

static void rebuild(relax *s) {
    vp_sgrid_clear(&s->g);
    for (size_t i = 0; i < s->n; i++) vp_sgrid_insert(&s->g, (uint32_t)i, s->x + 3 * i, s->r[i]);
}

/* Largest overlap (relative to r_i + r_j, wall relative to 2 r_i) over all
 * spheres, recomputed exactly. */
static double measure(relax *s, int shrink) {
    rebuild(s);
    double worst = 0;
    /* per-sphere shrink amounts first (from the same radii), then apply */
    double *cut = shrink ? calloc(s->n, sizeof *cut) : NULL;
    for (size_t i = 0; i < s->n; i++) {
        final_q q = {s, i, 0.0};
        vp_sgrid_query(&s->g, s->x + 3 * i, s->r[i] + s->gap, final_visit, &q);
        double g[3];
        double w = wall_overlap(s, s->x + 3 * i, s->r[i], g);
        double rel = q.worst / (2.0 * s->r[i]); /* >= worst/(r_i + r_j) for the smaller */
        if (w > 0 && w / (2.0 * s->r[i]) > rel) rel = w / (2.0 * s->r[i]);
        if (rel > worst) worst = rel;
        if (cut) {
            double c = 0.5 * q.worst;
            if (w > 0 && w > c) c = w;
            cut[i] = c;
        }
    }
    if (cut) {
        for (size_t i = 0; i < s->n; i++)
            if (cut[i] > 0) s->r[i] = (s->r[i] - cut[i]) * (1.0 - 1e-9) - 1e-15;
        free(cut);
    }
    return worst;
}

vp_result vp_pack_relax(vp_context *ctx, const vp_container *c, const vp_relax_params *params,
                        vp_particles **out, vp_relax_report *report) {
    double t0 = vp_seconds();
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "relax: out is NULL");
    *out = NULL;
    if (!c || !params)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "relax: container and params are required");
    const vp_relax_params *P = params;
    double dmin = vp_size_dist_min(&P->radius), dmax = vp_size_dist_max(&P->radius);
    if (!(dmin > 0) || !(dmax >= dmin) || !isfinite(dmax))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "relax: radii must be finite and > 0");
    /* radii are stored as float (pscale), as vp_size_dist_parse demands */
    if (!(dmin >= FLT_MIN) || !(dmax <= FLT_MAX))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "relax: radii must be in 1.2e-38..3.4e38 (radii are stored as float), "
                       "not %g..%g",
                       dmin, dmax);
    if (P->count == 0) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "relax: count must be > 0");
    if (!(P->target_fraction >= 0) || !(P->target_fraction < 1))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "relax: the target fraction must be in [0, 1), not %g", P->target_fraction);
    if (!(P->tolerance > 0) || !(P->tolerance < 0.1))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "relax: the tolerance must be in (0, 0.1), not %g", P->tolerance);
    if (P->fit != VP_FIT_INSIDE && P->fit != VP_FIT_CENTER)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "relax: unknown fit");
    if (!(P->margin >= 0) || !isfinite(P->margin) || !(P->gap >= 0) || !isfinite(P->gap))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "relax: the margin and the gap must be finite and >= 0, not %g and %g",
                       P->margin, P->gap);
    if (P->count >= UINT32_MAX - 1)
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "relax: more than 2^32 spheres requested");
    double need = (double)P->count * 100.0;
    if (need > (double)vp_memory_limit(ctx)) {
        char a[32], b[32];
        vp_format_bytes(need, a, sizeof a);
        vp_format_bytes((double)vp_memory_limit(ctx), b, sizeof b);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY,
                       "relax: %zu spheres would need about %s, over the memory limit of %s",
                       P->count, a, b);
    }
    const vp_container_info *ci = &c->info;
    if (!(ci->volume > 0))
        return vp_fail(ctx, VP_ERR_BAD_CONTAINER, "relax: the container has no volume");

    relax s;
    memset(&s, 0, sizeof s);
    s.c = c;
    s.fit = P->fit;
    s.margin = P->margin;
    s.gap = P->gap;
    s.n = P->count;
    size_t n = s.n;
    s.x = malloc(3 * n * sizeof *s.x);
    s.nx = malloc(3 * n * sizeof *s.nx);
    s.r = malloc(n * sizeof *s.r);
    s.ov = malloc(n * sizeof *s.ov);
    s.wall = malloc(n * sizeof *s.wall);
    vp_particles *p = NULL;
    vp_result res = VP_OK;
    if (!s.x || !s.nx || !s.r || !s.ov || !s.wall) {
        res = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "relax: out of memory for %zu spheres", n);
        goto done;
    }
    /* radii */
    uint64_t rs = vp_rng_stream(P->seed, 1);
    double vol = 0;
    for (size_t i = 0; i < n; i++) {
        s.r[i] = vp_size_dist_sample(&P->radius, &rs);
        vol += s.r[i] * s.r[i] * s.r[i];
    }
    vol *= 4.0 / 3.0 * M_PI;
    double scale = 1.0;
    if (P->target_fraction > 0) {
        scale = cbrt(P->target_fraction * ci->volume / vol);
        for (size_t i = 0; i < n; i++) s.r[i] *= scale;
        vol = P->target_fraction * ci->volume;
    }
    double initial_fraction = vol / ci->volume;
    if (initial_fraction > VP_KEPLER)
        res = vp_fail(ctx, VP_ERR_NO_FIT,
                      "relax: %zu spheres of these radii fill %.3g times the container's volume, "
                      "more than any packing of spheres can hold (0.74); use fewer or smaller "
                      "spheres, or --target-fraction",
                      n, initial_fraction);
    if (res != VP_OK) goto done;
    double rmin = HUGE_VAL, rmax = 0;
    for (size_t i = 0; i < n; i++) {
        if (s.r[i] < rmin) rmin = s.r[i];
        if (s.r[i] > rmax) rmax = s.r[i];
    }
    s.rmax = rmax;
    if (!(rmin >= FLT_MIN) || !(rmax <= FLT_MAX))
        res = vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                      "relax: the radii scaled to fill the target fraction %g of this container "
                      "span %g..%g, outside 1.2e-38..3.4e38 (radii are stored as float)",
                      P->target_fraction, rmin, rmax);
    else if (!(P->gap < rmin))
        res =
            vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                    "relax: the gap %g is not smaller than the smallest radius (%g)", P->gap, rmin);
    if (res != VP_OK) goto done;
    /* random centres in the admissible region (overlaps allowed) */
    uint64_t ps = vp_rng_stream(P->seed, 2);
    for (size_t i = 0; i < n; i++) {
        double r = s.r[i], lo[3], hi[3];
        double shrink = (s.fit == VP_FIT_INSIDE ? r : 0.0) + s.margin;
        for (int k = 0; k < 3; k++) {
            lo[k] = ci->bmin[k] + shrink;
            hi[k] = ci->bmax[k] - shrink;
        }
        int placed = 0;
        if (hi[0] > lo[0] && hi[1] > lo[1] && hi[2] > lo[2]) {
            for (int t = 0; t < 100000 && !placed; t++) {
                double *x = s.x + 3 * i;
                for (int k = 0; k < 3; k++) x[k] = lo[k] + (hi[k] - lo[k]) * vp_rng_uniform(&ps);
                double d = vp_container_distance(c, x);
                placed = d <= -shrink;
            }
        }
        if (!placed) {
            res = vp_fail(ctx, VP_ERR_NO_FIT,
                          "relax: no place in the container for a sphere of radius %.6g (%s%s)", r,
                          s.fit == VP_FIT_INSIDE ? "wholly inside" : "centre inside",
                          s.margin > 0 ? ", with the margin" : "");
            goto done;
        }
    }
    if (P->radius_field) {
        /* radii from a field at the starting centres (docs/fields.md); a
         * target fraction keeps the volume it asked for */
        res = vp_field_radii(ctx, c, P->radius_field, P->radius_field_mode, s.x, 3, s.r, 1, n,
                             P->target_fraction > 0, &rmin, &rmax);
        if (res != VP_OK) goto done;
        s.rmax = rmax;
        vol = 0;
        for (size_t i = 0; i < n; i++) vol += s.r[i] * s.r[i] * s.r[i];
        vol *= 4.0 / 3.0 * M_PI;
        initial_fraction = vol / ci->volume;
    }
    size_t cells = 4 * n + 4096;
    if (vp_sgrid_init(&s.g, ci->bmin, ci->bmax, rmin, rmax, cells) != 0 ||
        vp_sgrid_insert(&s.g, (uint32_t)(n - 1), s.x, rmin) != 0) {
        res = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "relax: out of memory for the neighbour grid");
        goto done;
    }
    s.chunk = (n + NCHUNKS - 1) / NCHUNKS;
    int threads = vp_threads_for(ctx);
    int max_sweeps = P->max_sweeps > 0 ? P->max_sweeps : 20000;
    double best = HUGE_VAL, window_best = HUGE_VAL;
    int since = 0, sweeps = 0;
    const int check_every = STALL_WINDOW;
    const double stall = STALL_GAIN, cutf = SHRINK, fin = FINISH;
    double worst = HUGE_VAL;
    for (sweeps = 0; sweeps < max_sweeps; sweeps++) {
        rebuild(&s);
        vp_parallel_for(threads, NCHUNKS, sweep_chunk, &s);
        worst = 0;
        for (size_t i = 0; i < n; i++)
            if (s.ov[i] > worst) worst = s.ov[i];
        if (worst <= (fin > P->tolerance ? fin : P->tolerance)) break;
        double *t = s.x;
        s.x = s.nx;
        s.nx = t;
        if (worst < best) best = worst;
        /* radius relaxation when the worst overlap stalls */
        if (++since >= check_every) {
            if (!vp_report_progress(ctx, (double)sweeps / max_sweeps, "relax")) {
                res = vp_fail(ctx, VP_ERR_CANCELLED, "relax: cancelled");
                goto done;
            }
            if (!(best < stall * window_best)) {
                for (size_t i = 0; i < n; i++)
                    if (s.ov[i] > P->tolerance) s.r[i] *= 1.0 - cutf * s.ov[i];
            }
            window_best = best;
            best = HUGE_VAL;
            since = 0;
        }
    }
    /* with centre fit, centres still outside go back onto the wall first
     * (a radius step cannot move a centre) */
    if (s.fit == VP_FIT_CENTER) project_centres(&s);
    /* the last radius step: removes what is left exactly */
    measure(&s, 1);
    double final_worst = measure(&s, 0);
    for (size_t i = 0; i < n; i++)
        if (!(s.r[i] > 0.5 * rmin)) {
            res = vp_fail(ctx, VP_ERR_NO_FIT,
                          "relax: no overlap-free state after %d sweeps without shrinking "
                          "spheres by half (use fewer spheres or a lower --target-fraction)",
                          sweeps);
            goto done;
        }
    /* the work arrays go before the output is made (peak memory) */
    vp_sgrid_free(&s.g);
    free(s.nx);
    free(s.ov);
    free(s.wall);
    s.nx = NULL;
    s.ov = s.wall = NULL;
    /* output */
    res = vp_particles_create(ctx, n, &p);
    if (res != VP_OK) goto done;
    p->radii = malloc(n * sizeof *p->radii);
    if (!p->radii) {
        res = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "relax: out of memory");
        goto done;
    }
    double vol1 = 0;
    for (size_t i = 0; i < n; i++) {
        memcpy(p->positions + 3 * i, s.x + 3 * i, 3 * sizeof(double));
        float rf = (float)s.r[i];
        while ((double)rf > s.r[i]) rf = nextafterf(rf, 0.0f);
        p->radii[i] = rf;
        vol1 += (double)rf * rf * rf;
    }
    vol1 *= 4.0 / 3.0 * M_PI;
    p->count = n;
    p->shape = VP_SHAPE_SPHERE;
    if (report) {
        memset(report, 0, sizeof *report);
        report->count = n;
        report->sweeps = sweeps;
        report->radius_scale = cbrt(vol1 / vol);
        report->initial_fraction = initial_fraction;
        report->max_overlap = final_worst;
        report->particle_volume = vol1;
        report->seconds = vp_seconds() - t0;
    }
    *out = p;
    p = NULL;
done:
    vp_particles_destroy(p);
    vp_sgrid_free(&s.g);
    free(s.x);
    free(s.nx);
    free(s.r);
    free(s.ov);
    free(s.wall);
    return res;
}
