/* SPDX-License-Identifier: Apache-2.0 */
/* Lattice packer: fills a container with one lattice (spheres on SC, BCC,
 * FCC, HCP; solids on their densest lattices) and searches the lattice
 * offset (and, on request, orientation) that fits the most particles.
 *
 * Search: every lattice point is classified once at offset 0 by its
 * distance to the wall. The distance is 1-Lipschitz, so a point whose
 * distance clears the fit threshold by more than the largest offset m is
 * in (or out) for every offset we try; only the shell of "ambiguous" points
 * is re-tested per offset. That makes each candidate placement cost the
 * shell, not the whole volume, so hundreds of placements take well under a
 * second. The final placement is regenerated and tested exactly. */
#include "core/container.h"
#include "core/context.h"
#include "core/depth_map.h"
#include "core/geom.h"
#include "core/lattice_basis.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/shape.h"
#include "core/superball.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct setup {
    const vp_container *c;
    vp_fit fit;
    const vp_polyhedron *poly; /* NULL: sphere (or superball) */
    double sb;                 /* superball exponent; 0: not a superball */
    double r;                  /* bounding-sphere radius */
    double q[4];               /* global rotation */
    double b[3][3];            /* world lattice vectors b[k] */
    double binv[3][3];         /* inverse of the matrix with columns b[k] */
    int nsites;
    double sites[2][3];     /* world site offsets */
    double lo[3], hi[3];    /* box that holds every admissible centre */
    double tol;             /* rounding allowed at the wall (setup_build) */
    double margin;          /* kept from the wall */
    double thr_in;          /* d <= thr_in - m: in for every offset */
    double thr_out;         /* d >  thr_out + m: out for every offset */
    const vp_depth_map *dm; /* coarse depth bounds, or NULL (depth_map.h) */
} setup;

/* --- small helpers ------------------------------------------------------ */

static int invert3(const double m[3][3], double inv[3][3]) {
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                 m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (!(fabs(det) > 0)) return -1;
    double id = 1.0 / det;
    inv[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) * id;
    inv[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * id;
    inv[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * id;
    inv[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) * id;
    inv[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * id;
    inv[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * id;
    inv[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) * id;
    inv[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * id;
    inv[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * id;
    return 0;
}

/* margin: kept from the wall; gap_half: spheres are spaced as if their
 * radius were r + gap_half (their fit uses r). */
static void setup_build(setup *s, const vp_container *c, const vp_lattice_basis *lb,
                        const vp_polyhedron *poly, double sb, vp_fit fit, double r,
                        const double q[4], double margin, double gap_half) {
    memset(s, 0, sizeof *s);
    s->c = c;
    s->fit = fit;
    s->poly = poly;
    s->sb = sb;
    s->r = r;
    s->margin = margin;
    memcpy(s->q, q, sizeof s->q);
    double m[3][3];
    const double rl = r + gap_half; /* the lattice's scale */
    for (int k = 0; k < 3; k++) {
        double v[3] = {lb->a[k][0] * rl, lb->a[k][1] * rl, lb->a[k][2] * rl};
        vp_quat_rotate(q, v, s->b[k]);
        for (int i = 0; i < 3; i++) m[i][k] = s->b[k][i];
    }
    invert3(m, s->binv);
    s->nsites = lb->nsites;
    for (int k = 0; k < lb->nsites; k++) {
        double v[3] = {lb->sites[k][0] * rl, lb->sites[k][1] * rl, lb->sites[k][2] * rl};
        vp_quat_rotate(q, v, s->sites[k]);
    }
    double shrink = 0.0;
    if (poly || sb > 0) {
        if (fit == VP_FIT_INSIDE) shrink = (poly ? poly->inradius : vp_superball_inradius(sb)) * r;
    } else if (fit == VP_FIT_INSIDE) {
        shrink = r;
    }
    /* Touching the wall counts as inside, up to rounding: a lattice point
     * computed as o + n b is off by a few ulps of the coordinates, which
     * made spheres that touch both walls of a box (radius 0.05 in a unit
     * box, simple cubic: 1000 fit) fail d <= -r and gave 729. The
     * tolerance, 1e-12 of the container's coordinates, is far below what
     * vdbpack check allows at the wall (1e-9, or a tenth of a voxel, plus
     * the stored positions' rounding). */
    double scale = r;
    for (int i = 0; i < 3; i++) {
        double a = fmax(fabs(c->info.bmin[i]), fabs(c->info.bmax[i]));
        if (a > scale) scale = a;
    }
    double tol = s->tol = 1e-12 * scale;
    shrink += margin;
    for (int i = 0; i < 3; i++) {
        s->lo[i] = c->info.bmin[i] + shrink - tol;
        s->hi[i] = c->info.bmax[i] - shrink + tol;
    }
    if (fit == VP_FIT_CENTER) {
        s->thr_in = tol - margin;
        s->thr_out = tol - margin;
    } else if (!poly && !(sb > 0)) {
        s->thr_in = -r + tol - margin;
        s->thr_out = -r + tol - margin;
    } else {
        s->thr_in = -r + tol - margin; /* circumsphere inside: wholly inside */
        s->thr_out = -margin;          /* centroid outside: not inside */
    }
}

/* Lattice coordinates that put a lattice point on the low corner of the
 * box of admissible centres (bmin + r with fit inside): with a box
 * container whose sides are whole multiples of the spacing, that is the
 * placement where particles touch both walls, which no sampled offset
 * finds (it is a single point of the cell). */
static void corner_offset(const setup *s, double u[3]) {
    double p[3];
    for (int i = 0; i < 3; i++) p[i] = s->lo[i] + s->tol - s->sites[0][i];
    for (int k = 0; k < 3; k++) {
        double t = s->binv[k][0] * p[0] + s->binv[k][1] * p[1] + s->binv[k][2] * p[2];
        u[k] = t - floor(t);
    }
}

static inline double dist(const setup *s, const double x[3]) {
    return s->c->ops.distance(s->c->user, x);
}

/* Exact fit test of a particle centred at x. The depth map decides the
 * bulk without sampling (its bounds hold for the sampled distance, so the
 * answer is the same). */
static int fits(const setup *s, const double x[3]) {
    double b = vp_depth_map_at(s->dm, x);
    if (b < 0.0 && b <= s->thr_in) return 1;
    if (b > 0.0 && b > s->thr_out) return 0;
    double d = dist(s, x);
    if (d <= s->thr_in) return 1;
    if (d > s->thr_out || (!s->poly && !(s->sb > 0)) || s->fit == VP_FIT_CENTER) return 0;
    const double m = -s->margin; /* the surface keeps the margin */
    if (s->sb > 0) return vp_superball_wall_distance(s->c, s->sb, s->r, s->q, x, m) <= m;
    return vp_poly_wall_distance(s->c, s->poly, s->r, s->q, x, m) <= m;
}

/* Integer ranges of lattice coordinate k over box [lo,hi] at offset o. */
static void coord_range(const setup *s, const double o[3], const double lo[3], const double hi[3],
                        int k, long *kmin, long *kmax) {
    double mn = HUGE_VAL, mx = -HUGE_VAL;
    for (int corner = 0; corner < 8; corner++) {
        double p[3];
        for (int i = 0; i < 3; i++) p[i] = ((corner >> i) & 1 ? hi[i] : lo[i]) - o[i];
        double t = s->binv[k][0] * p[0] + s->binv[k][1] * p[1] + s->binv[k][2] * p[2];
        if (t < mn) mn = t;
        if (t > mx) mx = t;
    }
    *kmin = (long)floor(mn) - 1;
    *kmax = (long)ceil(mx) + 1;
}

/* Visits every lattice point inside [lo,hi] whose third coordinate is n3,
 * in a fixed order. Returns 0 from the callback to stop. */
typedef int (*visit_fn)(void *user, const double x[3]);

static int visit_slab(const setup *s, const double o[3], const double lo[3], const double hi[3],
                      long n3, long n2min, long n2max, visit_fn fn, void *user) {
    for (int site = 0; site < s->nsites; site++) {
        for (long n2 = n2min; n2 <= n2max; n2++) {
            double base[3];
            for (int i = 0; i < 3; i++)
                base[i] =
                    o[i] + s->sites[site][i] + (double)n2 * s->b[1][i] + (double)n3 * s->b[2][i];
            double tmin = -HUGE_VAL, tmax = HUGE_VAL;
            int empty = 0;
            for (int i = 0; i < 3 && !empty; i++) {
                double bi = s->b[0][i];
                if (fabs(bi) < 1e-300) {
                    if (base[i] < lo[i] || base[i] > hi[i]) empty = 1;
                    continue;
                }
                double t0 = (lo[i] - base[i]) / bi, t1 = (hi[i] - base[i]) / bi;
                if (t0 > t1) {
                    double t = t0;
                    t0 = t1;
                    t1 = t;
                }
                if (t0 > tmin) tmin = t0;
                if (t1 < tmax) tmax = t1;
            }
            if (empty || tmin > tmax) continue;
            long a = (long)ceil(tmin), bnd = (long)floor(tmax);
            for (long n1 = a; n1 <= bnd; n1++) {
                double x[3];
                for (int i = 0; i < 3; i++) x[i] = base[i] + (double)n1 * s->b[0][i];
                if (x[0] < lo[0] || x[0] > hi[0] || x[1] < lo[1] || x[1] > hi[1] || x[2] < lo[2] ||
                    x[2] > hi[2])
                    continue;
                if (!fn(user, x)) return 0;
            }
        }
    }
    return 1;
}

/* --- classification at offset 0 ------------------------------------------ */

typedef struct point_list {
    double *x; /* 3*n */
    size_t n, cap;
    int oom;
} point_list;

static void list_push(point_list *l, const double x[3]) {
    if (l->oom) return;
    if (l->n == l->cap) {
        size_t nc = l->cap ? l->cap * 2 : 1024;
        double *nx = realloc(l->x, nc * 3 * sizeof(double));
        if (!nx) {
            l->oom = 1;
            return;
        }
        l->x = nx;
        l->cap = nc;
    }
    memcpy(l->x + 3 * l->n, x, 3 * sizeof(double));
    l->n++;
}

typedef struct classify_job {
    const setup *s;
    double m;            /* largest offset norm */
    double lo[3], hi[3]; /* box grown by m */
    long n3min, n2min, n2max;
    long slab_stride; /* visit every slab_stride-th slab */
    size_t *in_count; /* per slab */
    point_list *amb;  /* per slab */
} classify_job;

typedef struct classify_slab {
    const classify_job *job;
    size_t in;
    point_list *amb;
} classify_slab;

static int classify_visit(void *user, const double x[3]) {
    classify_slab *cs = user;
    const setup *s = cs->job->s;
    double m = cs->job->m;
    double b = vp_depth_map_at(s->dm, x);
    if (b < 0.0 && b + m <= s->thr_in) {
        cs->in++;
        return 1;
    }
    if (b > 0.0 && b - m > s->thr_out) return 1;
    double d = dist(s, x);
    if (d <= s->thr_in - m) cs->in++;
    else if (d <= s->thr_out + m) list_push(cs->amb, x);
    return 1;
}

static void classify_task(void *user, size_t i) {
    classify_job *j = user;
    classify_slab cs = {j, 0, &j->amb[i]};
    visit_slab(j->s, (const double[3]){0, 0, 0}, j->lo, j->hi, j->n3min + (long)i * j->slab_stride,
               j->n2min, j->n2max, classify_visit, &cs);
    j->in_count[i] = cs.in;
}

typedef struct classified {
    size_t always_in;
    double *amb; /* 3*namb */
    size_t namb;
    size_t stride; /* amb holds every stride-th ambiguous point */
    double m;
} classified;

/* Ambiguous points the search re-tests per placement, at most: past that
 * it re-tests an even subsample (every k-th point in lattice order, so
 * spread over the whole wall) and scales its count. Placements of a large
 * packing differ by a few particles in a million, below what the
 * subsample resolves, and what it picks is regenerated and counted
 * exactly; this keeps the search's cost flat in the packing's size. */
#define VP_AMB_MAX 65536

/* slab_stride > 1: classifies every slab_stride-th slab only, and scales
 * the counts (an estimate, for stepping the radius of a large packing). */
static int classify(const setup *s, double m, int threads, long slab_stride, classified *out) {
    classify_job j;
    memset(&j, 0, sizeof j);
    j.s = s;
    j.m = m;
    for (int i = 0; i < 3; i++) {
        j.lo[i] = s->lo[i] - m;
        j.hi[i] = s->hi[i] + m;
    }
    long n3min, n3max, n2min, n2max;
    double zero[3] = {0, 0, 0};
    coord_range(s, zero, j.lo, j.hi, 2, &n3min, &n3max);
    coord_range(s, zero, j.lo, j.hi, 1, &n2min, &n2max);
    if (slab_stride < 1) slab_stride = 1;
    size_t nslabs = (size_t)((n3max - n3min) / slab_stride + 1);
    j.slab_stride = slab_stride;
    j.n3min = n3min;
    j.n2min = n2min;
    j.n2max = n2max;
    j.in_count = calloc(nslabs, sizeof(size_t));
    j.amb = calloc(nslabs, sizeof(point_list));
    if (!j.in_count || !j.amb) {
        free(j.in_count);
        free(j.amb);
        return -1;
    }
    vp_parallel_for(threads, nslabs, classify_task, &j);
    size_t total = 0, in = 0;
    int oom = 0;
    for (size_t i = 0; i < nslabs; i++) {
        total += j.amb[i].n;
        in += j.in_count[i];
        oom |= j.amb[i].oom;
    }
    double *all = oom ? NULL : malloc((total ? total : 1) * 3 * sizeof(double));
    if (all) {
        size_t at = 0;
        for (size_t i = 0; i < nslabs; i++) {
            if (j.amb[i].n) memcpy(all + 3 * at, j.amb[i].x, j.amb[i].n * 3 * sizeof(double));
            at += j.amb[i].n;
        }
    }
    for (size_t i = 0; i < nslabs; i++) free(j.amb[i].x);
    free(j.amb);
    free(j.in_count);
    if (!all) return -1;
    size_t stride = total > VP_AMB_MAX ? (total + VP_AMB_MAX - 1) / VP_AMB_MAX : 1;
    if (stride > 1) {
        size_t k = 0;
        for (size_t i = 0; i < total; i += stride, k++)
            memmove(all + 3 * k, all + 3 * i, 3 * sizeof(double));
        total = k;
    }
    out->always_in = in * (size_t)slab_stride;
    out->amb = all;
    out->namb = total;
    out->stride = stride * (size_t)slab_stride;
    out->m = m;
    return 0;
}

/* --- offsets ------------------------------------------------------------- */

/* World offset of lattice coordinates u, reduced to a short representative
 * modulo the lattice (so that |offset| stays near the covering radius). */
static void offset_world(const setup *s, const double u[3], double o[3]) {
    double best = HUGE_VAL;
    for (int a = -1; a <= 1; a++)
        for (int b = -1; b <= 1; b++)
            for (int c = -1; c <= 1; c++) {
                double uu[3] = {u[0] - floor(u[0] + 0.5) + a, u[1] - floor(u[1] + 0.5) + b,
                                u[2] - floor(u[2] + 0.5) + c};
                double v[3];
                for (int i = 0; i < 3; i++)
                    v[i] = uu[0] * s->b[0][i] + uu[1] * s->b[1][i] + uu[2] * s->b[2][i];
                double n = vp_dot3(v, v);
                if (n < best) {
                    best = n;
                    memcpy(o, v, sizeof v);
                }
            }
}

static double covering_bound(const setup *s) {
    /* Largest reduced offset over a dense quasi-random probe of the cell. */
    double m = 0.0;
    for (int i = 0; i < 4096; i++) {
        double u[3] = {fmod(0.5 + i * 0.8191725133961645, 1.0),
                       fmod(0.5 + i * 0.6710436067037893, 1.0),
                       fmod(0.5 + i * 0.5497004779019703, 1.0)};
        double o[3];
        offset_world(s, u, o);
        double n = vp_norm3(o);
        if (n > m) m = n;
    }
    return m * 1.05;
}

typedef struct eval_job {
    const setup *s;
    const classified *cl;
    const double (*u)[3]; /* candidates in lattice coordinates */
    size_t *counts;
} eval_job;

static size_t count_at(const setup *s, const classified *cl, const double u[3]) {
    double o[3];
    offset_world(s, u, o);
    if (vp_norm3(o) > cl->m) return 0; /* outside what the classification covers */
    size_t n = 0;
    for (size_t i = 0; i < cl->namb; i++) {
        const double *x = cl->amb + 3 * i;
        double y[3] = {x[0] + o[0], x[1] + o[1], x[2] + o[2]};
        if (y[0] < s->lo[0] || y[0] > s->hi[0] || y[1] < s->lo[1] || y[1] > s->hi[1] ||
            y[2] < s->lo[2] || y[2] > s->hi[2])
            continue;
        n += (size_t)fits(s, y);
    }
    return cl->always_in + n * cl->stride;
}

static void eval_task(void *user, size_t i) {
    eval_job *j = user;
    j->counts[i] = count_at(j->s, j->cl, j->u[i]);
}

/* --- the search ---------------------------------------------------------- */

typedef struct placement {
    double q[4];
    double u[3];
    size_t count;
} placement;

typedef struct search_cfg {
    const vp_container *c;
    const vp_lattice_basis *lb;
    const vp_polyhedron *poly;
    double sb;
    vp_fit fit;
    double margin, gap_half; /* (setup_build) */
    int offsets;   /* stage-one offsets per orientation */
    int rotations; /* orientations (1 = identity only) */
    int refine;    /* pattern-search refinement */
    int budgeted;  /* automatic offsets: cap the point tests (see search) */
    uint64_t seed;
    int threads;
    vp_context *ctx;
    const vp_depth_map *dm;         /* or NULL */
    long slab_stride;               /* > 1: estimate counts from every k-th slab */
    const struct search_cfg *plain; /* also run (see search), or NULL */
} search_cfg;

/* Point tests the automatic search may spend per stage (about
 * a tenth of a second); explicit --offsets are not capped. */
#define VP_SEARCH_BUDGET 5.0e5

typedef struct search_stats {
    int offsets_tried;
    int rotations_tried;
} search_stats;

/* Evaluates n candidates (u) for one orientation in parallel. */
static int eval_many(const setup *s, const classified *cl, const double (*u)[3], size_t n,
                     size_t *counts, int threads) {
    eval_job j = {s, cl, u, counts};
    vp_parallel_for(threads, n, eval_task, &j);
    return 0;
}

static vp_result search_once(const search_cfg *cfg, double r, placement *best, search_stats *st) {
    uint64_t rng = cfg->seed ^ 0x5EEDull;
    memset(best, 0, sizeof *best);
    best->q[3] = 1.0;
    int have = 0;
    int nrot = cfg->rotations < 1 ? 1 : cfg->rotations;
    int noff = cfg->offsets < 1 ? 1 : cfg->offsets;
    double(*u)[3] = malloc(sizeof(double[3]) * (size_t)(noff > 8 ? noff : 8));
    size_t *counts = malloc(sizeof(size_t) * (size_t)(noff > 8 ? noff : 8));
    if (!u || !counts) {
        free(u);
        free(counts);
        return vp_fail(cfg->ctx, VP_ERR_OUT_OF_MEMORY, "lattice: out of memory");
    }
    /* stage-one offsets: a Kronecker (R3) sequence, the first one 0 */
    for (int i = 0; i < noff; i++) {
        u[i][0] = fmod(i * 0.8191725133961645, 1.0);
        u[i][1] = fmod(i * 0.6710436067037893, 1.0);
        u[i][2] = fmod(i * 0.5497004779019703, 1.0);
    }
    classified best_cl = {0};
    setup best_s;
    for (int rot = 0; rot < nrot; rot++) {
        double q[4] = {0, 0, 0, 1};
        if (rot > 0) vp_rng_quat_shoemake(&rng, q);
        setup s;
        setup_build(&s, cfg->c, cfg->lb, cfg->poly, cfg->sb, cfg->fit, r, q, cfg->margin,
                    cfg->gap_half);
        s.dm = cfg->dm;
        if (noff > 1) corner_offset(&s, u[1]); /* in place of the sequence's first after 0 */
        classified cl;
        double m = noff > 1 ? covering_bound(&s) : 0.0;
        if (cfg->c->info.voxel_size > 0) m += 0.05 * cfg->c->info.voxel_size;
        if (cfg->c->info.voxel_size > 0 && !cfg->dm) {
            /* Points deeper than the interior band read the band's depth,
             * so a point is known to fit for every offset up to m only
             * while r + m stays within the band: past that every inside
             * point would be re-tested for every offset. Offsets are then
             * limited to |o| <= m (count_at gives the others 0). With a
             * depth map the deep points are classified by the map, and
             * only the shell within about band + 16 voxels of the wall is
             * re-tested. */
            double avail = cfg->c->info.interior_band + s.thr_in - 0.05 * cfg->c->info.voxel_size;
            if (m > avail) m = avail > 0.0 ? avail : 0.0;
        }
        if (classify(&s, m, cfg->threads, cfg->slab_stride, &cl) != 0) {
            free(u);
            free(counts);
            free(best_cl.amb);
            return vp_fail(cfg->ctx, VP_ERR_OUT_OF_MEMORY, "lattice: out of memory");
        }
        if (cfg->budgeted && rot == 0) {
            /* Each offset re-tests every ambiguous point, a shell about the
             * wall whose share of all points falls as 1/N^(1/3): for large
             * packings the search costs seconds and gains a few particles
             * in a million. Spend at most VP_SEARCH_BUDGET point tests in
             * stage one (and as many in refinement), with at least 8
             * offsets per orientation. */
            double per = (double)(cl.namb ? cl.namb : 1) * nrot;
            int cap = (int)(VP_SEARCH_BUDGET / per);
            if (cap < 8) cap = 8;
            if (cap < noff) noff = cap;
        }
        /* in chunks, so that cancellation (a signal in the CLI) is prompt */
        for (int c0 = 0; c0 < noff; c0 += 32) {
            int cn = noff - c0 < 32 ? noff - c0 : 32;
            eval_many(&s, &cl, (const double(*)[3])(u + c0), (size_t)cn, counts + c0, cfg->threads);
            if (!vp_report_progress(cfg->ctx, 0.8 * (rot + (double)(c0 + cn) / noff) / nrot,
                                    "placement search")) {
                free(u);
                free(counts);
                free(best_cl.amb);
                free(cl.amb);
                return vp_fail(cfg->ctx, VP_ERR_CANCELLED, "cancelled");
            }
        }
        st->offsets_tried += noff;
        if (rot + 1 > st->rotations_tried) st->rotations_tried = rot + 1;
        size_t bi = 0;
        for (int i = 1; i < noff; i++)
            if (counts[i] > counts[bi]) bi = (size_t)i;
        if (!have || counts[bi] > best->count) {
            have = 1;
            memcpy(best->q, q, sizeof best->q);
            memcpy(best->u, u[bi], sizeof best->u);
            best->count = counts[bi];
            free(best_cl.amb);
            best_cl = cl;
            best_s = s;
        } else {
            free(cl.amb);
        }
        if (!vp_report_progress(cfg->ctx, 0.8 * (rot + 1) / nrot, "placement search")) {
            free(u);
            free(counts);
            free(best_cl.amb);
            return vp_fail(cfg->ctx, VP_ERR_CANCELLED, "cancelled");
        }
    }
    /* refinement: pattern search around the best placement */
    if (cfg->refine && noff > 1) {
        double step = 0.5 / cbrt((double)noff);
        int evals = 0;
        int max_evals = 400;
        if (cfg->budgeted) {
            double cap = VP_SEARCH_BUDGET / (double)(best_cl.namb ? best_cl.namb : 1);
            if (cap < max_evals) max_evals = cap < 12 ? 12 : (int)cap;
        }
        while (step > 0.004 && evals < max_evals) {
            double cand[6][3];
            size_t cc[6];
            for (int k = 0; k < 6; k++) {
                memcpy(cand[k], best->u, sizeof cand[k]);
                cand[k][k / 2] += (k & 1) ? -step : step;
            }
            eval_many(&best_s, &best_cl, (const double(*)[3])cand, 6, cc, cfg->threads);
            evals += 6;
            st->offsets_tried += 6;
            int bk = -1;
            for (int k = 0; k < 6; k++)
                if (cc[k] > best->count && (bk < 0 || cc[k] > cc[bk])) bk = k;
            if (bk >= 0) {
                memcpy(best->u, cand[bk], sizeof best->u);
                best->count = cc[bk];
            } else {
                step *= 0.5;
            }
        }
    }
    free(best_cl.amb);
    free(u);
    free(counts);
    return VP_OK;
}

/* The search of cfg, and then of cfg->plain if set, keeping the better
 * (the plain one on a tie). --rotate tries each orientation with fewer
 * offsets (32, not 128), so on its own it could end below the identity's
 * own search (2399 against 2400 spheres of radius 0.05 in the peanut):
 * with the search without --rotate run too, asking for rotations never
 * loses particles. */
static vp_result search(const search_cfg *cfg, double r, placement *best, search_stats *st) {
    vp_result res = search_once(cfg, r, best, st);
    if (res != VP_OK || !cfg->plain) return res;
    placement p;
    res = search_once(cfg->plain, r, &p, st);
    if (res == VP_OK && p.count >= best->count) *best = p;
    return res;
}

/* --- final generation ------------------------------------------------------ */

typedef struct gen_job {
    const setup *s;
    double o[3];
    long n3min, n2min, n2max;
    point_list *out; /* per slab */
} gen_job;

typedef struct gen_slab {
    const setup *s;
    point_list *l;
} gen_slab;

static int gen_visit(void *user, const double x[3]) {
    gen_slab *g = user;
    if (fits(g->s, x)) list_push(g->l, x);
    return 1;
}

static void gen_task(void *user, size_t i) {
    gen_job *j = user;
    gen_slab g = {j->s, &j->out[i]};
    visit_slab(j->s, j->o, j->s->lo, j->s->hi, j->n3min + (long)i, j->n2min, j->n2max, gen_visit,
               &g);
}

static vp_result generate(vp_context *ctx, const setup *s, const double u[3], int threads,
                          vp_particles **out, double o_out[3]) {
    gen_job j;
    memset(&j, 0, sizeof j);
    j.s = s;
    offset_world(s, u, j.o);
    memcpy(o_out, j.o, sizeof j.o);
    long n3max, n2max;
    coord_range(s, j.o, s->lo, s->hi, 2, &j.n3min, &n3max);
    coord_range(s, j.o, s->lo, s->hi, 1, &j.n2min, &n2max);
    j.n2max = n2max;
    size_t nslabs = (size_t)(n3max - j.n3min + 1);
    j.out = calloc(nslabs, sizeof(point_list));
    if (!j.out) return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "lattice: out of memory");
    vp_parallel_for(threads, nslabs, gen_task, &j);
    size_t total = 0;
    int oom = 0;
    for (size_t i = 0; i < nslabs; i++) {
        total += j.out[i].n;
        oom |= j.out[i].oom;
    }
    vp_particles *p = NULL;
    vp_result r = oom ? vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "lattice: out of memory")
                      : vp_particles_create(ctx, total ? total : 1, &p);
    if (r == VP_OK) {
        size_t at = 0;
        for (size_t i = 0; i < nslabs; i++) {
            if (j.out[i].n)
                memcpy(p->positions + 3 * at, j.out[i].x, j.out[i].n * 3 * sizeof(double));
            at += j.out[i].n;
        }
        p->count = total;
    }
    for (size_t i = 0; i < nslabs; i++) free(j.out[i].x);
    free(j.out);
    *out = p;
    return r;
}

/* --- public entry ---------------------------------------------------------- */

void vp_lattice_params_init(vp_lattice_params *p) {
    if (!p) return;
    memset(p, 0, sizeof *p);
    p->shape = VP_SHAPE_SPHERE;
    p->lattice = VP_LATTICE_DEFAULT;
    p->fit = VP_FIT_INSIDE;
    p->seed = 1;
}

/* Estimated particles for radius r (from the lattice fraction). */
static double estimate_count(const vp_container *c, const vp_lattice_basis *lb, double unit_vol,
                             double r) {
    return c->info.volume * lb->fraction / (unit_vol * r * r * r);
}

/* Lattice points the placement search keeps as ambiguous at radius r (an
 * estimate, for the guards below): those within the largest offset m of
 * the faces of the box of admissible centres, that box grown by m less
 * that box shrunk by m. A container thinner than about 2m has no point
 * that fits for every offset, so every point is kept, which the count
 * from the volume misses: box:1e-4,1,1 at radius 4e-5 has 2.8e8
 * particles by volume, 3.9e8 points to classify. m scales with r: *m_unit
 * keeps m / r from the first call (0 before it). */
static double ambiguous_count(const vp_container *c, const vp_lattice_basis *lb,
                              const vp_polyhedron *poly, double sb, const vp_lattice_params *lp,
                              double r, double *m_unit) {
    setup s;
    setup_build(&s, c, lb, poly, sb, lp->fit, r, (const double[4]){0, 0, 0, 1}, lp->margin,
                0.5 * lp->gap);
    if (!(*m_unit > 0.0)) *m_unit = covering_bound(&s) / r;
    double m = *m_unit * r, outer = 1.0, inner = 1.0;
    for (int i = 0; i < 3; i++) {
        double w = s.hi[i] - s.lo[i];
        outer *= w + 2.0 * m > 0.0 ? w + 2.0 * m : 0.0;
        inner *= w - 2.0 * m > 0.0 ? w - 2.0 * m : 0.0;
    }
    double cell = fabs(vp_det3(s.b[0], s.b[1], s.b[2]));
    return cell > 0.0 ? (outer - inner) * s.nsites / cell : HUGE_VAL;
}

/* Bytes per ambiguous point while it is classified: 24 in its slab's list
 * (which may hold twice that as it grows) and 24 in the joined list. */
#define VP_AMB_BYTES 72.0
/* Count mode does not step to a radius with more ambiguous points than
 * this plus 100 per particle asked (2e6: about 0.1 s of classification):
 * ordinary containers have a few per cent of their particles near the
 * wall; a thin one has all its points there, and the count jumps from
 * none (one layer does not fit) to 1e8 or more (box:1e-4,1,1 --count 10
 * stepped its radius down into that layer, 2.2 GB and 11 s to run out
 * of memory; box:1e-7,1,1 ran on). */
#define VP_COUNT_AMB_WORK 2e6

/* Count mode's radius step: count ~ r^-3, so r (count / target)^(1/3),
 * kept within the interior band for --fit inside. */
static double radius_step(const vp_container *c, vp_fit fit, double r, size_t count,
                          double target) {
    double nr = r * cbrt(count ? (double)count / target : 0.125);
    if (fit == VP_FIT_INSIDE && nr > c->info.interior_band) nr = c->info.interior_band;
    return nr;
}

/* What vp_pack_lattice works from: its arguments, checked, and what
 * follows from them. */
typedef struct lattice_job {
    vp_context *ctx;
    const vp_container *c;
    const vp_lattice_params *params;
    vp_lattice_basis lb;
    const vp_polyhedron *poly; /* NULL: sphere or superball */
    int superball;
    double sb;       /* superball exponent; 0: not a superball */
    double unit_vol; /* particle volume at radius 1 */
    double extent;   /* the container's smallest extent */
    int count_mode;  /* --count without --radius */
    double r;        /* the radius (count mode: the first guess) */
    uint64_t limit;  /* the context's memory limit */
    double m_unit;   /* largest offset / r (ambiguous_count) */
} lattice_job;

/* The searches of one call: the full one (cfg), the one without rotations
 * it also runs (plain), count mode's quick one, and the depth map they
 * share (freed by the caller). */
typedef struct lattice_searches {
    search_cfg cfg, plain, quick;
    vp_depth_map dm;
} lattice_searches;

/* Where count mode stopped short: the radius its guard refused (0: none),
 * that radius's ambiguous points, and the smallest radius searched. */
typedef struct count_stop {
    double wall_r, wall_amb, min_r;
} count_stop;

/* Step 1: checks the shape, lattice, container and radius, and fills J. */
static vp_result check_arguments(vp_context *ctx, const vp_container *c,
                                 const vp_lattice_params *params, lattice_job *J) {
    memset(J, 0, sizeof *J);
    J->ctx = ctx;
    J->c = c;
    J->params = params;
    J->superball = params->shape == VP_SHAPE_SUPERBALL;
    J->sb = J->superball ? params->shape_param : 0.0;
    const int superball = J->superball;
    const double sb = J->sb;
    if (superball && !(sb >= VP_SUPERBALL_P_MIN && sb <= VP_SUPERBALL_P_MAX))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "lattice: a superball's exponent must be in [%g, %g], not %g",
                       VP_SUPERBALL_P_MIN, VP_SUPERBALL_P_MAX, sb);
    if (vp_lattice_basis_get_param(params->shape, sb, params->lattice, &J->lb) != 0)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "--lattice %s is for spheres; a %s packs on its densest lattice",
                       vp_lattice_name(params->lattice), vp_shape_name(params->shape));
    if (!(params->margin >= 0) || !(params->gap >= 0) || !isfinite(params->margin) ||
        !isfinite(params->gap))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "lattice: margin and gap must be finite and >= 0 (world units)");
    if (params->gap > 0 && params->shape != VP_SHAPE_SPHERE)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "lattice: a gap spaces a lattice of spheres in this version, not of %s "
                       "(rsa keeps a gap between any convex shapes)",
                       vp_shape_name(params->shape));
    J->poly = vp_shape_polyhedron(params->shape);
    J->unit_vol = vp_shape_unit_volume_param(params->shape, sb);
    const double rin = J->poly ? J->poly->inradius : superball ? vp_superball_inradius(sb) : 1.0;
    if (!(c->info.volume > 0))
        return vp_fail(ctx, VP_ERR_BAD_CONTAINER, "the container has no inside (volume 0)");
    double r = params->radius;
    if (r == 0.0 && params->count > 0) {
        J->count_mode = 1;
        r = cbrt(c->info.volume * J->lb.fraction / ((double)params->count * J->unit_vol));
    } else if (!(r > 0) || !isfinite(r)) {
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "the radius must be a positive finite number (or give --count N > 0)");
    }
    double extent = HUGE_VAL;
    for (int i = 0; i < 3; i++) {
        double e = c->info.bmax[i] - c->info.bmin[i];
        if (e < extent) extent = e;
    }
    J->extent = extent;
    if (!J->count_mode && params->fit == VP_FIT_INSIDE && 2 * r * rin > extent)
        return vp_fail(ctx, VP_ERR_NO_FIT,
                       "radius %g is too large: no particle fits in the container (its smallest "
                       "extent is %g)",
                       r, extent);
    /* the depth the fit test reads: the radius (fit inside) and the margin */
    const double band = c->info.interior_band - params->margin;
    if (params->fit == VP_FIT_INSIDE && J->count_mode && r > band && band > 0) r = band;
    if (params->margin > c->info.interior_band * (1 + 1e-9) ||
        (params->fit == VP_FIT_INSIDE && r > band * (1 + 1e-9)))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       params->margin > 0
                           ? "radius %g and the margin exceed the container's interior band %g "
                             "(distances deeper inside are unknown); reload the container for "
                             "them (vp_container_params_for_lattice)"
                           : "radius %g exceeds the container's interior band %g (distances "
                             "deeper inside are unknown); reload the container for this radius",
                       r, c->info.interior_band);
    J->r = r;
    return VP_OK;
}

/* Step 2: the memory and work guard, before anything large is allocated. */
static vp_result check_budget(lattice_job *J) {
    vp_context *ctx = J->ctx;
    const vp_lattice_params *params = J->params;
    const double r = J->r;
    double est = estimate_count(J->c, &J->lb, J->unit_vol, r);
    double bytes = est * 40.0 + est * 40.0; /* positions + output attributes */
    J->limit = vp_memory_limit(ctx);
    const uint64_t limit = J->limit;
    if (bytes > (double)limit || est > 4e9) {
        char a[32], b[32];
        vp_format_bytes(bytes, a, sizeof a);
        vp_format_bytes((double)limit, b, sizeof b);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY,
                       "about %.3g particles of radius %g need an estimated %s, more than the "
                       "limit of %s (--max-memory)",
                       est, r, a, b);
    }
    J->m_unit = 0.0;
    double amb = ambiguous_count(J->c, &J->lb, J->poly, J->sb, params, r, &J->m_unit);
    if (J->count_mode && (amb > VP_COUNT_AMB_WORK + 100.0 * (double)params->count ||
                          amb * VP_AMB_BYTES > (double)limit))
        return vp_fail(ctx, VP_ERR_NO_FIT,
                       "lattice: --count %zu is out of reach in this container (smallest extent "
                       "%g): at radius %g about %.3g lattice points lie near its walls, too many "
                       "to search for %zu; give --radius, or use --method rsa",
                       params->count, J->extent, r, amb, params->count);
    if (amb * VP_AMB_BYTES > (double)limit) {
        char a[32], b[32];
        vp_format_bytes(amb * VP_AMB_BYTES, a, sizeof a);
        vp_format_bytes((double)limit, b, sizeof b);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY,
                       "lattice: at radius %g about %.3g lattice points lie near the container's "
                       "walls (all of them when it is only a few radii thick), and the placement "
                       "search would need an estimated %s for them, more than the limit of %s "
                       "(--max-memory)",
                       r, amb, a, b);
    }
    return VP_OK;
}

/* Step 3: the searches' settings, and the container's depth map (level
 * sets only; S->dm, which the caller frees). */
static void plan_searches(const lattice_job *J, lattice_searches *S) {
    const vp_lattice_params *params = J->params;
    search_cfg *cfg = &S->cfg;
    memset(cfg, 0, sizeof *cfg);
    cfg->c = J->c;
    cfg->lb = &J->lb;
    cfg->poly = J->poly;
    cfg->sb = J->sb;
    cfg->fit = params->fit;
    cfg->margin = params->margin;
    cfg->gap_half = 0.5 * params->gap;
    cfg->seed = params->seed;
    cfg->threads = vp_threads_for(J->ctx);
    cfg->ctx = J->ctx;
    memset(&S->dm, 0, sizeof S->dm);
    if (J->c->depth_map && J->c->depth_map(J->c, &S->dm) == 0) cfg->dm = &S->dm;
    cfg->refine = 1;
    cfg->rotations = params->rotate ? (params->rotations > 0 ? params->rotations : 24) : 1;
    if (params->offsets > 0) {
        cfg->offsets = params->offsets;
        cfg->refine = params->offsets > 1;
    } else {
        cfg->offsets = params->rotate ? 32 : 128;
        cfg->budgeted = 1;
    }

    /* with --rotate, also the search that runs without it (search) */
    S->plain = *cfg;
    if (cfg->rotations > 1) {
        S->plain.rotations = 1;
        if (params->offsets == 0) S->plain.offsets = 128;
        cfg->plain = &S->plain;
    }

    /* Count mode finds the radius with one offset per radius (the search
     * moves the count by a fraction of a per cent), then searches once. */
    search_cfg *quick = &S->quick;
    *quick = *cfg;
    quick->offsets = 1;
    quick->rotations = 1;
    quick->refine = 0;
    quick->budgeted = 0;
    quick->plain = NULL;
    /* the first count of a large packing only steps the radius (below):
     * an estimate from every 4th slab is within a few in 10^4 */
    if (J->count_mode && params->count >= 1e5 && (cfg->offsets > 1 || cfg->rotations > 1))
        quick->slab_stride = 4;
}

/* Step 4 (count mode): the radius whose best placement comes closest to
 * the count asked, from the first search's radius J->r and placement
 * *best; the radius in J->r, its placement in *best. *stop says where a
 * guard stopped the steps. */
static vp_result fit_count(lattice_job *J, lattice_searches *S, placement *best, search_stats *st,
                           vp_lattice_report *rep, count_stop *stop) {
    const vp_container *c = J->c;
    const vp_lattice_params *params = J->params;
    search_cfg *cfg = &S->cfg, *quick = &S->quick;
    double r = J->r;
    vp_result res = VP_OK;
    /* count ~ r^-3 locally: r <- r (count/N)^(1/3); keep the closest.
     * First with the quick evaluation, then (the search adds particles,
     * a lot of them in small packings) with the full search, which for
     * large packings is already within 1 % on its first try. */
    double target = (double)params->count;
    /* phase 0's closest, when it was measured exactly (not the large
     * packing's estimate): the full search maximises the count at each
     * radius, so it may never come as close (one sphere asked in
     * box:1,2,3: it finds 3 up to radius 0.5 and none beyond) */
    int kept = 0;
    double kept_r = r, kept_err = HUGE_VAL;
    placement kept_p = *best;
    for (int phase = 0; phase < 2; phase++) {
        const search_cfg *sc = phase ? cfg : quick;
        if (phase) {
            if (cfg->offsets <= 1 && cfg->rotations <= 1) break;
            if (best->count == 0 && stop->wall_r > 0.0) break; /* refused below */
            res = search(cfg, r, best, st);
            if (res != VP_OK) goto out;
        }
        double best_r = r, best_err = best->count ? fabs((double)best->count - target) : HUGE_VAL;
        placement best_p = *best;
        if (phase == 0 && target >= 1e5 && (cfg->offsets > 1 || cfg->rotations > 1)) {
            /* A large packing: the full search follows and counts
             * again, and the r^-3 model is then within a fraction of
             * a per cent, so step once without re-evaluating. */
            double nr = radius_step(c, params->fit, r, best->count, target);
            if (best_err > 0.001 * target && nr != r) {
                r = nr;
                rep->radius_iterations++;
            }
            quick->slab_stride = 1;
            continue;
        }
        /* the largest radius seen whose count reached the target and
         * the smallest whose count fell short: a bracket for the
         * bisection below */
        double lo_r = best->count >= target ? r : 0, hi_r = best->count < target ? r : HUGE_VAL;
        /* full searches (phase 1) cost far more than quick ones */
        int max_it = phase ? 16 : 48;
        for (int it = 0; it < max_it && best_err > 0.01 * target; it++) {
            double nr = radius_step(c, params->fit, r, best->count, target);
            if (lo_r > 0 && hi_r < HUGE_VAL && (it >= 16 || !(nr > lo_r && nr < hi_r))) {
                /* Small counts move in steps of one or more, so the
                 * r^-3 model overshoots or stalls around them (5 on
                 * the peanut gave 4): bisect the bracket instead. */
                /* a jump in the count (a layer): no radius between */
                if (hi_r - lo_r <= 1e-6 * hi_r) break;
                nr = 0.5 * (lo_r + hi_r);
            } else if (it >= 16) {
                break;
            }
            if (nr == r) break;
            r = nr;
            if (estimate_count(c, &J->lb, J->unit_vol, r) > 4e9) break;
            double na = ambiguous_count(c, &J->lb, J->poly, J->sb, params, r, &J->m_unit);
            if (na > VP_COUNT_AMB_WORK + 100.0 * target || na * VP_AMB_BYTES > (double)J->limit) {
                stop->wall_r = r;
                stop->wall_amb = na;
                break;
            }
            res = search(sc, r, best, st);
            if (res != VP_OK) goto out;
            rep->radius_iterations++;
            if (r < stop->min_r) stop->min_r = r;
            if (best->count >= target && r > lo_r) lo_r = r;
            if (best->count < target && r < hi_r) hi_r = r;
            /* no particle at all is never the answer */
            double e = best->count ? fabs((double)best->count - target) : HUGE_VAL;
            /* equally close: the count above the target (at least N) */
            if (e < best_err || (e == best_err && best->count > best_p.count)) {
                best_err = e;
                best_r = r;
                best_p = *best;
            }
        }
        r = best_r;
        *best = best_p;
        if (phase == 0) {
            kept = 1;
            kept_r = r;
            kept_err = best_err;
            kept_p = *best;
        } else if (kept && kept_err < best_err) {
            r = kept_r;
            *best = kept_p;
        }
    }
out:
    J->r = r;
    return res;
}

/* Step 5: the particles of the chosen placement at radius J->r, and the
 * report. */
static vp_result place(const lattice_job *J, const lattice_searches *S, const placement *best,
                       const search_stats *st, vp_lattice_report *rep, vp_particles **out) {
    vp_context *ctx = J->ctx;
    const vp_lattice_params *params = J->params;
    const double r = J->r;
    setup s;
    setup_build(&s, J->c, &J->lb, J->poly, J->sb, params->fit, r, best->q, params->margin,
                0.5 * params->gap);
    s.dm = S->cfg.dm;
    vp_particles *p = NULL;
    double o[3];
    vp_result res = generate(ctx, &s, best->u, S->cfg.threads, &p, o);
    if (res != VP_OK) return res;
    if (p->count == 0) {
        vp_particles_destroy(p);
        return vp_fail(ctx, VP_ERR_NO_FIT,
                       "no particle of radius %g fits in the container with --fit %s", r,
                       params->fit == VP_FIT_INSIDE ? "inside" : "center");
    }
    p->uniform_radius = (float)r;
    p->shape = params->shape;
    p->shape_param = J->sb;
    if (J->poly || J->superball) {
        p->has_orient = 1;
        for (int i = 0; i < 4; i++) p->uniform_orient[i] = (float)best->q[i];
    }
    rep->radius = r;
    rep->count = p->count;
    rep->offsets_tried = st->offsets_tried;
    rep->rotations_tried = st->rotations_tried;
    memcpy(rep->offset, o, sizeof rep->offset);
    memcpy(rep->rotation, best->q, sizeof rep->rotation);
    rep->lattice_fraction = J->lb.fraction;
    rep->particle_volume = vp_particles_volume(p);
    *out = p;
    return VP_OK;
}

vp_result vp_pack_lattice(vp_context *ctx, const vp_container *c, const vp_lattice_params *params,
                          vp_particles **out, vp_lattice_report *report) {
    double t0 = vp_seconds();
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "lattice: out is NULL");
    *out = NULL;
    if (!c) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "lattice: no container");
    vp_lattice_params def;
    if (!params) {
        vp_lattice_params_init(&def);
        params = &def;
    }
    lattice_job J;
    vp_result res = check_arguments(ctx, c, params, &J);
    if (res == VP_OK) res = check_budget(&J);
    if (res != VP_OK) return res;

    lattice_searches S;
    plan_searches(&J, &S);
    vp_lattice_report rep;
    memset(&rep, 0, sizeof rep);
    placement best;
    search_stats st = {0, 0};
    count_stop stop = {0.0, 0.0, J.r};
    res = search(J.count_mode ? &S.quick : &S.cfg, J.r, &best, &st);
    if (res == VP_OK) {
        rep.radius_iterations = 1;
        if (J.count_mode) res = fit_count(&J, &S, &best, &st, &rep, &stop);
    }
    if (res == VP_OK && J.count_mode && best.count == 0 && stop.wall_r > 0.0)
        res =
            vp_fail(ctx, VP_ERR_NO_FIT,
                    "lattice: --count %zu is out of reach in this container (smallest extent "
                    "%g): no particle fits at radius %g or larger, and at radius %g about "
                    "%.3g lattice points lie near its walls, too many to search for %zu; give "
                    "--radius, or use --method rsa",
                    params->count, J.extent, stop.min_r, stop.wall_r, stop.wall_amb, params->count);
    vp_particles *p = NULL;
    if (res == VP_OK) res = place(&J, &S, &best, &st, &rep, &p);
    vp_depth_map_free(&S.dm);
    if (res != VP_OK) return res;
    rep.seconds = vp_seconds() - t0;
    vp_report_progress(ctx, 1.0, "done");
    if (report) *report = rep;
    *out = p;
    return VP_OK;
}
