/* SPDX-License-Identifier: Apache-2.0 */
/* Random sequential addition (RSA) of spheres in passes; see rsa.h and
 * docs/rsa.md.
 *
 * Sampling: candidates are uniform in the union of "active" cells, cubes
 * that may still hold an admissible centre. A cell is dropped once it is
 * known to hold none: wholly outside the admissible region of the container
 * (the distance is 1-Lipschitz), or wholly inside the exclusion ball of one
 * placed sphere. Rejection sampling from any superset of the admissible
 * region gives the same uniform law as sampling the whole box, so this is
 * plain RSA, only without the darts that are known to fail. When the
 * success rate of a batch of darts falls below SPLIT_RATE, every active
 * cell is split in eight and the covered children dropped (the maximal
 * Poisson-disk sampling scheme of Ebeida et al. 2011/2012); when no cell is
 * left the pass is maximal: no centre of that radius fits anywhere.
 * Each cell also records which of its eighths were proven empty (a mask)
 * and one ball that holds much of it (its top ball, core/rsa_top.h), so
 * that most failing darts fail without reading a neighbour. Centres are
 * kept as floats while packing (half the memory a dart reads); a
 * candidate is rounded to that float before its tests.
 *
 * Determinism: dart k of a pass draws its cell and position from its own
 * random stream (seed, pass, k). Darts are made and pre-tested (container,
 * particles placed before the batch) in parallel, then accepted in dart
 * order on one thread, so the result does not depend on the thread count. */
#include "core/rsa_internal.h"
#include "os/bigmem.h"
#include "core/container.h"
#include "core/context.h"
#include "core/geom.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/rsa_field.h"
#include "core/rsa_top.h"
#include "core/sgrid.h"
#include "core/mesh_shape.h"
#include "core/pair.h"
#include "core/shape.h"
#include "core/superball.h"
#include "core/size_dist_sample.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


void vp_rsa_pass_init(vp_rsa_pass *p) {
    memset(p, 0, sizeof *p);
    vp_size_dist_constant(&p->radius, 1.0);
}

/* The group of pass i: its name, else "pass<i + 1>", in buf (at least
 * VP_GROUP_NAME_MAX bytes). */
static const char *group_name(const vp_rsa_params *params, size_t i, char *buf) {
    if (params->passes[i].name[0]) return params->passes[i].name;
    snprintf(buf, VP_GROUP_NAME_MAX, "pass%zu", i + 1);
    return buf;
}

void vp_rsa_params_init(vp_rsa_params *p) {
    memset(p, 0, sizeof *p);
    p->fit = VP_FIT_INSIDE;
}

/* --- particle storage ------------------------------------------------------- */

static int reserve(rsa *s, size_t want) {
    vp_particles *p = s->p;
    if (want <= p->capacity) return 0;
    size_t cap = p->capacity ? p->capacity : 1024;
    while (cap < want) cap += cap / 2;
    float *pos = realloc(s->fpos, cap * 3 * sizeof *pos);
    if (!pos) return -1;
    s->fpos = pos;
    vp_mem_advise_random(pos, cap * 3 * sizeof *pos);
    float *rad = realloc(p->radii, cap * sizeof *rad);
    if (!rad) return -1;
    p->radii = rad;
    vp_mem_advise_random(rad, cap * sizeof *rad);
    uint16_t *grp = realloc(p->groups, cap * sizeof *grp);
    if (!grp) return -1;
    p->groups = grp;
    if (s->mixed) {
        uint8_t *k = realloc(p->shape_index, cap * sizeof *k);
        if (!k) return -1;
        p->shape_index = k;
    }
    if (p->has_orient) {
        float *o = realloc(p->orients, cap * 4 * sizeof *o);
        if (!o) return -1;
        p->orients = o;
        vp_mem_advise_random(o, cap * 4 * sizeof *o);
    }
    p->capacity = cap;
    return 0;
}

/* --- neighbour tests ---------------------------------------------------------- */

typedef struct clr_query {
    const rsa *s;
    const double *x;
    double best; /* min |x - c_j| - r_j so far */
    double stop; /* stop as soon as best < stop */
    size_t from; /* only j >= from */
    size_t upto; /* only j < upto */
    size_t skip; /* never this j */
} clr_query;

static int clr_visit(void *user, uint32_t j) {
    clr_query *q = user;
    if (j < q->from || j >= q->upto || j == q->skip) return 0;
    double c[3];
    ppos(q->s, j, c);
    double dx = q->x[0] - c[0], dy = q->x[1] - c[1], dz = q->x[2] - c[2];
    double r = q->s->uni_r > 0 ? q->s->uni_r : q->s->p->radii[j];
    double lim = q->best + r; /* only a closer surface matters */
    double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 >= lim * lim) return 0;
    q->best = sqrt(d2) - r;
    return q->best < q->stop;
}

/* Min over particles j in [from, upto) of |x - c_j| - r_j, exact when below
 * reach (else reach), stopping early once below stop. The dart's own grid
 * cell is read first: most darts fail, and mostly on a sphere there
 * (8.87 G against 8.98 G instructions for the 1e5 count case, the same
 * packing: below stop the verdict does not depend on the order). */
static double clearance(const rsa *s, const double x[3], double reach, double stop, size_t from,
                        size_t upto) {
    clr_query q = {s, x, reach, stop, from, upto, SIZE_MAX};
    vp_sgrid_query_near(&s->g, x, reach, clr_visit, &q);
    return q.best;
}

/* clearance() over the particles placed since `from` (the particles are
 * inserted in the grid in index order: vp_sgrid_query_near_from). */
static double clearance_since(const rsa *s, const double x[3], double reach, size_t from) {
    clr_query q = {s, x, reach, reach, from, SIZE_MAX, SIZE_MAX};
    vp_sgrid_query_near_from(&s->g, x, reach, (uint32_t)from, clr_visit, &q);
    return q.best;
}

/* --- solids: exact tests ------------------------------------------------------
 * A solid's orientation is tested as written: the float quaternion,
 * renormalised in double (as vdbpack check reads it back). */

#define DEFER_MAX 64

typedef struct solid_query {
    const rsa *s;
    const double *x; /* the candidate: centre, orientation, radius */
    const double *q;
    struct dart *lazy; /* q is this dart's, not drawn yet (else NULL) */
    double r;
    size_t skip; /* never this j (grow: the particle itself) */
    size_t from; /* only j >= from */
    int posed;   /* cand holds the candidate posed about x */
    int framed;  /* cubes: m holds the candidate's rotation */
    double m[3][3];
    vp_poly_posed cand;
    vp_convex cand_sb;
    /* The neighbours that the cheap tests (spheres, the candidate's own
     * cube test) leave undecided, tested exactly after all the others
     * have had their cheap tests: a candidate that some neighbour's cheap
     * test rejects then costs no exact test at all. The verdict is the
     * same conjunction in another order. */
    size_t ndefer;
    uint32_t defer[DEFER_MAX];
} solid_query;

/* The dart's orientation: drawn from its stream on first use (the stream
 * is left after the position, so the value does not depend on when), as
 * stored: float, renormalised in double. */
static const double *dart_quat(const rsa *s, dart *t) {
    if (!t->qready) {
        float f[4] = {0, 0, 0, 1};
        if (s->orient_random) {
            double q[4];
            vp_rng_quat(&t->st, q);
            for (int m = 0; m < 4; m++) f[m] = (float)q[m];
        }
        vp_quat_from_float(f, t->q);
        t->qready = 1;
    }
    return t->q;
}

static const double *cand_quat(solid_query *w) {
    if (w->lazy) {
        dart_quat(w->s, w->lazy);
        w->lazy = NULL;
    }
    return w->q;
}

/* Cubes: 1 (overlap) or 0 (apart) when one centre's distance to the other
 * cube decides (vp_cube_center_test; a cube holds its insphere, radius
 * rin r, and lies in its bounding sphere), else -1 and the SAT decides.
 * Where it decides, the SAT gives the same answer, so the particles are
 * those of the SAT alone, bit for bit; about half of the pairs between the
 * two spheres' tests end here, without posing the neighbour. d: the
 * candidate's centre less c_j. Two tests: cube_quick_cand (c_j against the
 * candidate's cube), then cube_quick_other (the candidate's centre against
 * cube j), which leaves particle j's orientation in qj for the SAT. */
static int cube_quick_cand(solid_query *w, const double d[3], double rj) {
    const rsa *s = w->s;
    if (!w->framed) {
        vp_quat_to_matrix(cand_quat(w), w->m);
        w->framed = 1;
    }
    double nd[3] = {-d[0], -d[1], -d[2]}; /* c_j from the candidate's centre */
    return vp_cube_center_test((const double(*)[3])w->m, s->rin * w->r, nd, s->rin * rj, rj,
                               s->coord_eps);
}

static int cube_quick_other(solid_query *w, const double d[3], double rj, uint32_t j,
                            double qj[4]) {
    const rsa *s = w->s;
    double mj[3][3];
    vp_quat_from_float(s->p->orients + 4 * (size_t)j, qj);
    vp_quat_to_matrix(qj, mj);
    return vp_cube_center_test((const double(*)[3])mj, s->rin * rj, d, s->rin * w->r, w->r,
                               s->coord_eps);
}

/* The exact test of the candidate against particle j, after the sphere
 * tests (and, for cubes, cube_quick_cand) left it undecided. 1 overlap. */
static int solid_exact(solid_query *w, uint32_t j) {
    const rsa *s = w->s;
    double c[3];
    ppos(s, j, c);
    double rj = s->p->radii[j], d[3];
    for (int k = 0; k < 3; k++) d[k] = w->x[k] - c[k];
    double qj[4];
    if (s->cube) {
        int v = cube_quick_other(w, d, rj, j, qj);
        if (v >= 0) return v;
    } else {
        vp_quat_from_float(s->p->orients + 4 * (size_t)j, qj);
    }
    if (s->mixed && s->p->shape_index[j] != s->cur)
        return vp_kind_overlap_gap(&s->kinds[s->cur], w->r, cand_quat(w), w->x,
                                   &s->kinds[s->p->shape_index[j]], rj, qj, c, s->pair_gap);
    if (s->mesh) return vp_mesh_shape_overlap(s->mesh, w->r, cand_quat(w), w->x, rj, qj, c, NULL);
    if (s->gjk) {
        if (!w->posed) { /* the candidate's support, posed once */
            vp_convex_set(&w->cand_sb, s->shape, s->sb, w->r, cand_quat(w), w->x, w->x);
            w->cand_sb.inflate = 0.5 * s->pair_gap;
            w->posed = 1;
        }
        vp_convex o;
        vp_convex_set(&o, s->shape, s->sb, rj, qj, c, w->x);
        o.inflate = 0.5 * s->pair_gap;
        return vp_convex_overlap(&w->cand_sb, &o);
    }
    /* the candidate is posed once for all its neighbours; both relative
     * to its centre (the numbers of vp_poly_separation, bit for bit), and
     * the test stops at the first separating axis */
    if (!w->posed) {
        vp_poly_pose(s->poly, w->r, cand_quat(w), w->x, w->x, &w->cand);
        w->posed = 1;
    }
    vp_poly_posed pj;
    vp_poly_pose(s->poly, rj, qj, c, w->x, &pj);
    return vp_poly_posed_overlap(&w->cand, &pj);
}

/* 1 (stop) when particle j overlaps the candidate. The exact tests wait
 * in w->defer while there is room (see solid_query). */
static int solid_visit(void *user, uint32_t j) {
    solid_query *w = user;
    const rsa *s = w->s;
    if (j == w->skip || j < w->from) return 0;
    double c[3];
    ppos(s, j, c);
    double rj = s->p->radii[j], e = w->r + rj, d[3], d2 = 0.0;
    for (int k = 0; k < 3; k++) {
        d[k] = w->x[k] - c[k];
        d2 += d[k] * d[k];
    }
    if (s->mixed || s->pair_gap > 0) {
        double ein = excluded(s, w->r, j, rj), eb = s->reach * e + s->pair_gap;
        if (d2 < ein * ein) return 1; /* inspheres (with the gap) overlap */
        if (d2 >= eb * eb) return 0;  /* bounding spheres apart */
    } else {
        if (d2 < s->rin * s->rin * e * e) return 1;      /* inspheres overlap */
        if (d2 >= s->reach * s->reach * e * e) return 0; /* bounding spheres (boxes) apart */
    }
    if (s->bbox) { /* boxes apart on one axis (touching counts as apart) */
        for (int k = 0; k < 3; k++)
            if (w->x[k] + w->r * s->bb_lo[k] >= c[k] + rj * s->bb_hi[k] ||
                c[k] + rj * s->bb_lo[k] >= w->x[k] + w->r * s->bb_hi[k])
                return 0;
        return 1;
    }
    if (s->cube) {
        int v = cube_quick_cand(w, d, rj);
        if (v >= 0) return v;
    }
    if (w->ndefer < DEFER_MAX) {
        w->defer[w->ndefer++] = j;
        return 0;
    }
    return solid_exact(w, j);
}

/* The deferred exact tests: 1 when one of them overlaps. */
static int solid_deferred(solid_query *w) {
    for (size_t t = 0; t < w->ndefer; t++)
        if (solid_exact(w, w->defer[t])) return 1;
    return 0;
}

/* 1 if the solid (centre x with container distance d, orientation q,
 * radius r) passes the fit test. */
static int solid_fits_wall(const rsa *s, const double x[3], double d, const double q[4], double r) {
    if (d <= thr_ok(s, r)) return 1;
    if (s->fit == VP_FIT_CENTER || !(d <= thr_drop(s, r))) return 0;
    const double m = -s->margin; /* the surface keeps the margin */
    if (s->mesh) return vp_mesh_shape_wall_distance(s->c, s->mesh, r, q, x, m) <= m;
    if (s->sb > 0) return vp_superball_wall_distance(s->c, s->sb, r, q, x, m) <= m;
    if (!s->poly) return 0; /* a sphere of a mixed set: the thresholds decided */
    return vp_poly_wall_distance(s->c, s->poly, r, q, x, m) <= m;
}

/* 1 if the solid overlaps none of particles [from, count) (but skip).
 * Each pair is tested on its own, so the verdict over [0, count) is the
 * conjunction of those over [0, n) and [n, count) for any n: the darts'
 * parallel pre-test and the serial test of a batch split it so. */
static int solid_clear_from(const rsa *s, const double x[3], const double q[4], dart *lazy,
                            double r, size_t skip, size_t from) {
    solid_query w;
    w.s = s;
    w.x = x;
    w.q = q;
    w.lazy = lazy && !lazy->qready ? lazy : NULL;
    w.r = r;
    w.skip = skip;
    w.from = from;
    w.posed = 0;
    w.framed = 0;
    w.ndefer = 0;
    size_t nnew = s->p->count - from;
    if (from > 0 && nnew <= 32) { /* a few new particles: test them directly */
        for (size_t j = from; j < s->p->count; j++)
            if (solid_visit(&w, (uint32_t)j)) return 0;
        return !solid_deferred(&w);
    }
    /* the grid finds j within reach + r_j: widen it for the boxes */
    double reach = s->reach * r + (s->reach - 1.0) * s->max_r + s->pair_gap;
    /* own grid cell first: a candidate that fails mostly fails on a
     * particle there, and the verdict does not depend on the order */
    return !vp_sgrid_query_near(&s->g, x, reach, solid_visit, &w) && !solid_deferred(&w);
}

/* 1 if the solid fits the wall and overlaps none of particles [0, count). */
static int solid_free(const rsa *s, const double x[3], double d, const double q[4], double r,
                      size_t skip) {
    return solid_fits_wall(s, x, d, q, r) && solid_clear_from(s, x, q, NULL, r, skip, 0);
}

/* solid_free for a dart, drawing its orientation only when a test needs it. */
static int dart_solid_free(const rsa *s, dart *t, double r) {
    if (t->d == HUGE_VAL) return 0; /* in a sub-cell proven empty */
    if (!(t->d <= thr_ok(s, r)) && !solid_fits_wall(s, t->p, t->d, dart_quat(s, t), r)) return 0;
    return solid_clear_from(s, t->p, t->q, t, r, SIZE_MAX, 0);
}

/* --- particle order ------------------------------------------------------------ */

/* One particle's data, held while renumber moves the others. */
typedef struct held {
    float pos[3];
    float r, q[4];
    uint8_t kind;
} held;

static void hold(const rsa *s, size_t i, held *h) {
    const vp_particles *p = s->p;
    memcpy(h->pos, s->fpos + 3 * i, sizeof h->pos);
    h->r = p->radii[i];
    if (p->has_orient) memcpy(h->q, p->orients + 4 * i, sizeof h->q);
    h->kind = s->mixed ? p->shape_index[i] : 0;
}

/* Puts the held particle at i and holds the one that was there. */
static void exchange(rsa *s, size_t i, held *h) {
    vp_particles *p = s->p;
    held t;
    hold(s, i, &t);
    memcpy(s->fpos + 3 * i, h->pos, sizeof h->pos);
    p->radii[i] = h->r;
    if (p->has_orient) memcpy(p->orients + 4 * i, h->q, sizeof h->q);
    if (s->mixed) p->shape_index[i] = h->kind;
    *h = t;
}

/* Renumbers particles [first, count) in the order of the neighbour grid's
 * cells (row by row), so that the particles a query reads lie together in
 * memory instead of in placement order, scattered: the splits gather the
 * balls near every cell, one cache miss per particle otherwise. The new
 * numbers are kept in the grid's links while it is rebuilt (no memory is
 * taken). Nothing in a pass depends on the numbering but its output order. */
static void renumber(rsa *s, size_t first) {
    vp_particles *p = s->p;
    vp_sgrid *g = &s->g;
    size_t n = p->count;
    uint32_t k = (uint32_t)first, *to = g->next; /* to[old] = new, once the walk has read it */
    for (int l = 0; l < g->nlevels; l++) {
        const vp_sgrid_level *L = &g->lev[l];
        size_t ncell = (size_t)(L->dims[0] * L->dims[1] * L->dims[2]);
        for (size_t c = 0; c < ncell; c++)
            for (uint32_t j = L->head[c], nx; j != VP_SGRID_NONE; j = nx) {
                nx = g->next[j];
                to[j] = j < first ? j : k++;
            }
    }
    /* move each particle to its place, cycle by cycle, holding one at a
     * time; to[i] == i: done (groups: one value over the pass) */
    for (size_t i = first; i < n; i++) {
        if (to[i] == i) continue;
        held h;
        hold(s, i, &h);
        for (uint32_t d = to[i]; d != i;) { /* put the held particle at d, hold d's */
            exchange(s, d, &h);
            uint32_t nd = to[d];
            to[d] = d;
            d = nd;
        }
        exchange(s, i, &h);
        to[i] = (uint32_t)i;
    }
    vp_sgrid_clear(g);
    for (size_t i = 0; i < n; i++) { /* cannot fail: the links hold n already */
        double x[3];
        ppos(s, i, x);
        vp_sgrid_insert(g, (uint32_t)i, x, p->radii[i]);
    }
}

/* --- darts ---------------------------------------------------------------------- */

typedef struct dart_job {
    rsa *s;
    size_t chunk;
} dart_job;

/* 1 when a dart at p in sub-cell `sub` of cell c is known to fail from
 * the cell alone: that sub-cell was proven empty (the mask), or p lies in
 * the cell's top ball. */
static int dart_settled(const rsa *s, const cell *c, unsigned sub, const double p[3]) {
    if (!(c->mask >> sub & 1)) return 1;
    if (c->top == VP_TOP_NONE || s->no_top) return 0;
    double m[3];
    cell_center(s, c, s->level, m);
    return vp_top_holds(&s->top[s->level], c->top, m, p);
}

/* Makes darts [lo, hi) of the batch in sweeps (cells; positions and the
 * neighbour grid's cells; the first particle of each grid cell; the
 * tests), so that the memory each dart needs is requested for the whole
 * chunk one sweep before it is used: a dart is a chain of dependent cache misses, and the sweeps let
 * the misses of different darts overlap. Each dart draws from its own
 * stream in the same order as one sweep would (cell, position, rotation). */
static void make_darts(void *user, size_t ci) {
    dart_job *j = user;
    rsa *s = j->s;
    size_t lo = ci * j->chunk, hi = lo + j->chunk;
    if (hi > s->ndarts) hi = s->ndarts;
    double a = cell_side(s, s->level);
    /* thin axes: a cell wider than the box there is drawn in its part
     * inside the box (the same part for every cell: they are all one
     * cell thick there) */
    double cut[3] = {1.0, 1.0, 1.0};
    int thin = 0;
    for (int m = 0; m < 3; m++)
        if ((s->thin >> m & 1) && a > s->extent[m]) {
            cut[m] = s->extent[m] / a;
            thin = 1;
        }
    for (size_t k = lo; k < hi; k++) {
        dart *t = &s->darts[k];
        t->st = vp_rng_stream(s->stream_seed, s->dart_base + k);
        t->cell = (uint32_t)(vp_rng_next(&t->st) % s->ncells);
        __builtin_prefetch(s->cells + (size_t)t->cell * s->csize);
    }
    for (size_t k = lo; k < hi; k++) {
        dart *t = &s->darts[k];
        const cell c = cell_load(s->cells, s->csize, t->cell);
        double u[3];
        for (int m = 0; m < 3; m++) u[m] = vp_rng_uniform(&t->st);
        if (thin)
            for (int m = 0; m < 3; m++) u[m] *= cut[m];
        t->p[0] = s->origin[0] + ((double)c.x + u[0]) * a;
        t->p[1] = s->origin[1] + ((double)c.y + u[1]) * a;
        t->p[2] = s->origin[2] + ((double)(c.z & ~VALID_BIT) + u[2]) * a;
        round_pos(s, t->p); /* as it would be stored */
        unsigned sub = (u[0] >= 0.5) | (u[1] >= 0.5) << 1 | (u[2] >= 0.5) << 2;
        if (dart_settled(s, &c, sub, t->p)) { /* fails, without a neighbour query */
            t->d = HUGE_VAL;
            t->clr = 0.0;
            t->qready = 0;
            continue;
        }
        t->d = (c.z & VALID_BIT) ? -HUGE_VAL : vp_container_distance(s->c, t->p);
        t->clr = HUGE_VAL;
        if (s->solid) { /* the exact tests depend on the radius: on accepting */
            t->qready = 0;
            /* one radius: the exact tests against the particles placed
             * before the batch need not wait for the serial loop */
            if (s->pretest) t->clr = dart_solid_free(s, t, s->rmin);
            continue;
        }
        if (t->d <= thr_ok(s, s->rmin) && s->n0)
            vp_sgrid_prefetch_cells(&s->g, t->p, t->p, s->rmax);
    }
    if (s->solid || !s->n0) return;
    for (size_t k = lo; k < hi; k++) {
        const dart *t = &s->darts[k];
        if (t->d <= thr_ok(s, s->rmin))
            vp_sgrid_prefetch_items(&s->g, t->p, t->p, s->rmax, s->fpos, 3 * sizeof *s->fpos);
    }
    for (size_t k = lo; k < hi; k++) {
        dart *t = &s->darts[k];
        if (t->d <= thr_ok(s, s->rmin)) t->clr = clearance(s, t->p, s->rmax, s->rmin, 0, s->n0);
    }
}

/* The largest radius a sphere at dart t may have (spheres, serial loop):
 * its clearance to the particles placed before its batch and since, and
 * with fit inside to the wall; below rmin when no sphere fits there. Exact
 * up to rmax (the neighbour queries reach no further). */
static double dart_room(const rsa *s, const dart *t) {
    if (!(t->d <= thr_ok(s, s->rmin))) return -HUGE_VAL; /* also a settled dart */
    double room = t->clr;
    if (s->fit == VP_FIT_INSIDE && -t->d - s->wall_off < room) room = -t->d - s->wall_off;
    if (room >= s->rmin && s->p->count > s->n0) {
        /* (not clearance_since: it stops at the first surface within reach) */
        clr_query q = {s, t->p, s->rmax, s->rmin, s->n0, SIZE_MAX, SIZE_MAX};
        vp_sgrid_query_near_from(&s->g, t->p, s->rmax, (uint32_t)s->n0, clr_visit, &q);
        if (q.best < room) room = q.best;
    }
    return room;
}

/* --- grow ------------------------------------------------------------------------- */

/* Radius particle i can grow to: the distance to the nearest other
 * sphere's surface and, with fit inside, to the wall. */
static double grow_one(const rsa *s, size_t i, double diag) {
    double x[3];
    ppos(s, i, x);
    double wall = HUGE_VAL;
    if (s->fit == VP_FIT_INSIDE) wall = -vp_container_distance(s->c, x) - s->wall_off;
    double reach = wall < HUGE_VAL ? wall : 4.0 * s->p->radii[i];
    for (;;) {
        clr_query q = {s, x, reach, -HUGE_VAL, 0, s->p->count, i};
        vp_sgrid_query(&s->g, x, reach, clr_visit, &q);
        if (q.best < reach) return q.best; /* exact: every closer surface was seen */
        if (reach >= wall || reach >= diag) return reach;
        reach = 2.0 * reach < wall ? 2.0 * reach : wall;
    }
}

/* Largest radius (to a relative 1e-6) at which solid i still fits the wall
 * and overlaps no other particle: doubling, then bisection on the exact
 * tests. Scaling a convex solid about its centroid down keeps it inside
 * itself, so "fits" is monotone in the radius. */
static double grow_solid(const rsa *s, size_t i, double diag) {
    double x[3];
    ppos(s, i, x);
    double q[4];
    vp_quat_from_float(s->p->orients + 4 * i, q);
    double d = vp_container_distance(s->c, x);
    double lo = s->p->radii[i], hi = lo;
    for (;;) {
        double next = 2.0 * hi;
        if (next > diag) {
            if (solid_free(s, x, d, q, diag, i)) return diag;
            hi = diag;
            break;
        }
        if (!solid_free(s, x, d, q, next, i)) {
            hi = next;
            break;
        }
        lo = hi = next;
    }
    while (hi - lo > 1e-6 * lo) {
        double mid = 0.5 * (lo + hi);
        if (solid_free(s, x, d, q, mid, i)) lo = mid;
        else hi = mid;
    }
    return lo;
}

/* Grows particles [first, last) in placement order. */
static void grow_pass(rsa *s, size_t first, size_t last, double *mean_ratio) {
    double diag = 0;
    for (int k = 0; k < 3; k++) {
        double e = s->c->info.bmax[k] - s->c->info.bmin[k];
        diag += e * e;
    }
    diag = sqrt(diag);
    double sum = 0;
    for (size_t i = first; i < last; i++) {
        double r0 = s->p->radii[i];
        double b = s->solid ? grow_solid(s, i, diag) : grow_one(s, i, diag);
        /* a hair short of touching, so that the float radius and rounded
         * positions can never make the contact an overlap */
        double target = b * (1.0 - 4e-7);
        float rf = (float)target;
        while ((double)rf > target) rf = nextafterf(rf, 0.0f);
        if ((double)rf > r0) {
            s->p->radii[i] = rf;
            s->uni_r = 0.0;
            if (rf > s->max_r) s->max_r = rf;
            vp_sgrid_grow(&s->g, (uint32_t)i, rf);
        }
        sum += (double)s->p->radii[i] / r0;
    }
    *mean_ratio = last > first ? sum / (double)(last - first) : 1.0;
}

static int cmp_desc(const void *a, const void *b) {
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? 1 : x > y ? -1 : 0;
}

/* --- one pass ------------------------------------------------------------------------ */

/* A pass in progress: what its steps share. */
typedef struct pass_run {
    const vp_rsa_pass *ps;
    unsigned index;
    vp_rsa_pass_report *rep;
    double g;            /* gap_half: every radius drawn is packed inflated by it */
    uint64_t rad_state;  /* the pass's stream of radii */
    double cur_r;        /* the next particle's radius (kept until placed) */
    size_t retries;      /* failed tries in a row that end the pass */
    size_t want;         /* particles asked for (SIZE_MAX: maximal) */
    int fill_dist;       /* maximal with a distribution of radii (spheres) */
    int filling;         /* ... and now placing a radius cut at the room */
    size_t fill_after;   /* failed tries in a row before filling */
    size_t first;        /* the pass's first particle */
    size_t consecutive;  /* failed tries in a row */
    size_t level_darts;  /* darts thrown at this level */
    size_t renumbered;   /* particles when last put in grid order */
    uint64_t dart_index; /* the next batch's first dart */
    uint32_t *hits;      /* cells that received a particle in this batch */
    size_t hit_cap, nhits;
    size_t ok, used; /* the batch's placed particles and darts used */
    int done;
} pass_run;

/* The pass's radius range (radii are stored as float: the float values
 * drawn are bounded) and its random streams. */
static void pass_radii(rsa *s, pass_run *pr, uint64_t seed) {
    const vp_rsa_pass *ps = pr->ps;
    const double g = pr->g;
    double dmin = vp_size_dist_min(&ps->radius) + g, dmax = vp_size_dist_max(&ps->radius) + g;
    float fmin = (float)dmin, fmax = (float)dmax;
    if (ps->radius.kind != VP_SIZE_CONSTANT || g > 0) { /* a constant is drawn as (float) itself */
        if ((double)fmin > dmin) fmin = nextafterf(fmin, 0.0f);
        if ((double)fmax < dmax) fmax = nextafterf(fmax, HUGE_VALF);
    }
    s->rmin = fmin;
    s->rmax = fmax;
    /* every radius drawn is a float in [fmin, fmax]: equal bounds, one radius */
    s->pretest = s->solid && fmin == fmax;
    s->stream_seed = vp_rng_stream(seed, 2 * (uint64_t)pr->index);
    pr->rad_state = vp_rng_stream(seed, 2 * (uint64_t)pr->index + 1);
}

/* The level-0 cells over the box of admissible centres. *no_room: that box
 * is empty (then an error for the first pass, a maximal stop for later
 * ones). */
static vp_result pass_level0(rsa *s, pass_run *pr, int *no_room) {
    const vp_rsa_pass *ps = pr->ps;
    *no_room = 0;
    const vp_container_info *ci = &s->c->info;
    double shrink = s->fit == VP_FIT_INSIDE ? s->rmin + s->wall_off : s->wall_off;
    double lo[3], hi[3], vol = 1.0;
    for (int k = 0; k < 3; k++) {
        lo[k] = ci->bmin[k] + shrink;
        hi[k] = ci->bmax[k] - shrink;
        vol *= hi[k] > lo[k] ? hi[k] - lo[k] : 0.0;
    }
    if (!(hi[0] > lo[0] && hi[1] > lo[1] && hi[2] > lo[2])) {
        if (s->p->count == 0)
            return vp_fail(s->ctx, VP_ERR_NO_FIT,
                           "rsa: pass %u: radius %.9g (as a float)%s leaves no room for a "
                           "centre in the container (its inside is %.6g x %.6g x %.6g)",
                           pr->index + 1, s->rmin - pr->g,
                           s->margin > 0 ? " with the margin from the wall" : "",
                           ci->bmax[0] - ci->bmin[0], ci->bmax[1] - ci->bmin[1],
                           ci->bmax[2] - ci->bmin[2]);
        *no_room = 1;
        return VP_OK;
    }
    /* level-0 cells: fine enough that a placed sphere covers its cell after
     * one split, coarse enough to keep the count near the particles' */
    double expect = ps->maximal ? 0.4 * vol / (s->unit_volume * s->rmin * s->rmin * s->rmin)
                                : (double)ps->count;
    /* diagonal 2 rin rmin: a particle covers its cell */
    double a0 = 2.0 * (s->rin > 0.25 ? s->rin : 0.25) * s->rmin / sqrt(3.0);
    double max_cells = 2.0 * expect;
    if (max_cells < 4096) max_cells = 4096;
    if (max_cells > 1 << 26) max_cells = 1 << 26;
    /* the cells' count is vol over the part of a cell inside the box: a
     * cell is one cell thick along an axis thinner than its side (a slab
     * 1e-20 thick counted as vol / a0^3 would make a grid of 1e16 cells);
     * with no such axis this is vol / a0^3 */
    for (;;) {
        double part = 1.0;
        for (int k = 0; k < 3; k++) part *= hi[k] - lo[k] < a0 ? hi[k] - lo[k] : a0;
        if (!(vol / part > max_cells)) break;
        a0 *= 2.0;
    }
    s->cell_budget = s->max_cells_param ? s->max_cells_param : (size_t)(16.0 * max_cells);
    s->split_blocked = 0;
    for (int l = 0; l < 32; l++) s->side[l] = ldexp(a0, -l);
    int64_t dims[3];
    int64_t maxdim = 1;
    s->thin = 0;
    for (int k = 0; k < 3; k++) {
        s->origin[k] = lo[k];
        s->extent[k] = hi[k] - lo[k];
        if (s->extent[k] < a0) s->thin |= 1u << k;
        dims[k] = (int64_t)ceil((hi[k] - lo[k]) / a0);
        if (dims[k] < 1) dims[k] = 1;
        if (dims[k] > maxdim) maxdim = dims[k];
    }
    int bits = 0;
    while (((int64_t)1 << bits) < maxdim) bits++;
    /* cells no finer than 1e-5 of the radius (and coordinates within 31 bits) */
    s->max_level = (int)ceil(log2(a0 / (1e-5 * s->rmin)));
    if (s->max_level > 30 - bits) s->max_level = 30 - bits;
    s->coord_bits = bits;
    s->level = 0;
    return vp_rsa_split_cells(s, 1, dims);
}

/* When the pass ends, and its first radius. */
static void pass_limits(rsa *s, pass_run *pr) {
    const vp_rsa_pass *ps = pr->ps;
    pr->retries = ps->retries > 0 ? (size_t)ps->retries : VP_RSA_DEFAULT_RETRIES;
    /* maximal: ends when no cell is left. For solids the cells are dropped
     * only by inspheres (a necessary condition), so they seldom run out:
     * the retry limit ends those passes. */
    if (ps->maximal && !s->solid) pr->retries = SIZE_MAX;
    pr->want = ps->maximal ? SIZE_MAX : ps->count;
    /* maximal with a distribution of radii (spheres): first as a count
     * pass (each radius drawn kept until placed) until `retries` tries in a
     * row fail; then (filling) a dart that has room for the smallest
     * radius always places one, of the radius drawn or, where that does
     * not fit, of a radius drawn from the distribution cut at the room
     * there; so the pass ends, as with one radius, when no cell can hold a
     * centre of the smallest radius (docs/rsa.md) */
    pr->fill_dist = ps->maximal && ps->radius.kind != VP_SIZE_CONSTANT && !s->solid;
    pr->filling = 0;
    pr->fill_after = ps->retries > 0 ? (size_t)ps->retries : VP_RSA_DEFAULT_RETRIES;
    pr->first = pr->renumbered = s->p->count;
    pr->consecutive = 0;
    pr->cur_r = (double)(float)(vp_size_dist_sample(&ps->radius, &pr->rad_state) + pr->g);
    pr->rep->stop = VP_RSA_STOP_MAXIMAL;
}

/* A batch of darts (a quarter of the cells, 256 to 8192), made and
 * pre-tested in parallel. */
static vp_result batch_darts(rsa *s, pass_run *pr, size_t *batch) {
    size_t B = s->ncells / 4;
    if (B < 256) B = 256;
    if (B > 8192) B = 8192;
    if (B > s->ndarts) {
        dart *d = realloc(s->darts, B * sizeof *d);
        if (!d) return vp_fail(s->ctx, VP_ERR_OUT_OF_MEMORY, "rsa: out of memory");
        s->darts = d;
    }
    s->ndarts = B;
    s->n0 = s->p->count;
    s->dart_base = pr->dart_index;
    pr->dart_index += B;
    dart_job j = {s, (B + 63) / 64};
    vp_parallel_for(s->threads, 64, make_darts, &j);
    if (B > pr->hit_cap) {
        uint32_t *h = realloc(pr->hits, B * sizeof *pr->hits);
        if (!h) return vp_fail(s->ctx, VP_ERR_OUT_OF_MEMORY, "rsa: out of memory");
        pr->hits = h;
        pr->hit_cap = B;
    }
    *batch = B;
    return VP_OK;
}

/* The batch's darts in order, on one thread: each tested against what
 * the parallel pre-test left out, placed when it passes; the pass ends at
 * its count or its retry limit (pr->done). */
static vp_result batch_accept(rsa *s, pass_run *pr, size_t B) {
    const vp_rsa_pass *ps = pr->ps;
    vp_rsa_pass_report *rep = pr->rep;
    const double g = pr->g;
    /* the loop's state in locals, written back at the end */
    double cur_r = pr->cur_r;
    uint64_t rad_state = pr->rad_state;
    size_t consecutive = pr->consecutive, nhits = 0, ok = 0, used = 0;
    int filling = pr->filling, done = 0;
    uint32_t *hits = pr->hits;
    vp_result r = VP_OK;
    double a = cell_side(s, s->level), diag = a * sqrt(3.0);
    for (size_t k = 0; k < B; k++) {
        dart *t = &s->darts[k];
        used++;
        rep->tries++;
        int good;
        if (s->pretest) { /* a solid, cur_r == rmin; earlier particles done */
            rep->pretested++;
            good = t->clr != 0.0 && (s->p->count == s->n0 ||
                                     solid_clear_from(s, t->p, t->q, t, cur_r, SIZE_MAX, s->n0));
        } else if (s->solid) {
            good = dart_solid_free(s, t, cur_r);
            /* solids, maximal, sizes: the next try draws anew (the
             * retry limit ends the pass) */
            if (!good && ps->maximal && ps->radius.kind != VP_SIZE_CONSTANT)
                cur_r = (double)(float)(vp_size_dist_sample(&ps->radius, &rad_state) + g);
        } else if (filling) {
            double room = dart_room(s, t);
            if ((good = room >= s->rmin) && cur_r > room) {
                cur_r =
                    (double)(float)(vp_size_dist_sample_below(&ps->radius, room - g, &rad_state) +
                                    g);
                if (cur_r > room) cur_r = (double)nextafterf((float)cur_r, 0.0f);
                if (cur_r < s->rmin) cur_r = s->rmin;
            }
        } else if ((good = t->d <= thr_ok(s, cur_r) && t->clr >= cur_r) &&
                   s->p->count > s->n0) { /* spheres placed in this batch */
            size_t nnew = s->p->count - s->n0;
            if (nnew <= 24) {
                for (size_t i = s->n0; i < s->p->count && good; i++) {
                    double c[3];
                    ppos(s, i, c);
                    double dx = t->p[0] - c[0], dy = t->p[1] - c[1], dz = t->p[2] - c[2];
                    double e = cur_r + s->p->radii[i];
                    if (dx * dx + dy * dy + dz * dz < e * e) good = 0;
                }
            } else {
                good = clearance_since(s, t->p, cur_r, s->n0) >= cur_r;
            }
        }
        if (!good) {
            if (pr->fill_dist && !filling && consecutive + 1 >= pr->fill_after) {
                filling = 1;
                consecutive = 0;
                continue;
            }
            if (++consecutive >= pr->retries) {
                rep->stop = VP_RSA_STOP_RETRIES;
                done = 1;
                break;
            }
            continue;
        }
        consecutive = 0;
        if (s->p->count >= UINT32_MAX - 1) {
            r = vp_fail(s->ctx, VP_ERR_OUT_OF_MEMORY, "rsa: more than 2^32 particles");
            done = 1;
            break;
        }
        if (reserve(s, s->p->count + 1) != 0) {
            r = vp_fail(s->ctx, VP_ERR_OUT_OF_MEMORY, "rsa: out of memory at %zu particles",
                        s->p->count);
            done = 1;
            break;
        }
        size_t i = s->p->count++;
        store_pos(s, i, t->p); /* t->p is rounded: the same value back */
        s->p->radii[i] = (float)cur_r;
        if (cur_r > s->max_r) s->max_r = cur_r;
        if (cur_r < s->min_r) s->min_r = cur_r;
        if (i == 0 && !s->mixed) s->uni_r = (float)cur_r; /* (mixed: rin differs) */
        else if (s->uni_r != (double)(float)cur_r) s->uni_r = 0.0;
        s->p->groups[i] = (uint16_t)pr->index;
        if (s->mixed) s->p->shape_index[i] = (uint8_t)s->cur;
        if (s->solid) {
            const double *q = dart_quat(s, t);
            for (int m = 0; m < 4; m++) s->p->orients[4 * i + m] = (float)q[m];
        }
        if (vp_sgrid_insert(&s->g, (uint32_t)i, t->p, cur_r) != 0) {
            r = vp_fail(s->ctx, VP_ERR_OUT_OF_MEMORY, "rsa: out of memory");
            done = 1;
            break;
        }
        ok++;
        if (s->level == 0 && s->top[0].u > 0) { /* a level-0 cell's first sphere: its top ball */
            cell c = cell_load(s->cells, s->csize, t->cell);
            if (c.top == VP_TOP_NONE) {
                double m[3], off[3];
                cell_center(s, &c, 0, m);
                for (int a3 = 0; a3 < 3; a3++) off[a3] = t->p[a3] - m[a3];
                c.top = vp_top_encode(&s->top[0], off);
                cell_store(s->cells, s->csize, t->cell, c);
            }
        }
        /* the new sphere covers its cell for every later candidate */
        if (diag <= s->rin * (s->rmin + cur_r)) hits[nhits++] = t->cell;
        rep->placed++;
        if (rep->placed >= pr->want) {
            rep->stop = VP_RSA_STOP_COUNT;
            done = 1;
            break;
        }
        cur_r = (double)(float)(vp_size_dist_sample(&ps->radius, &rad_state) + g);
    }
    pr->cur_r = cur_r;
    pr->rad_state = rad_state;
    pr->consecutive = consecutive;
    pr->filling = filling;
    pr->nhits = nhits;
    pr->ok = ok;
    pr->used = used;
    pr->done = done;
    return r;
}

/* Drops the cells that received a particle, in dart order (swap with the
 * last cell that is not itself being dropped). */
static void drop_hit_cells(rsa *s, pass_run *pr) {
    uint32_t *hits = pr->hits;
    size_t nhits = pr->nhits;
    if (!nhits) return;
    /* sort hits descending so swaps never move a hit cell; a cell hit
     * twice is dropped once */
    qsort(hits, nhits, sizeof *hits, cmp_desc);
    size_t u = 1;
    for (size_t h = 1; h < nhits; h++)
        if (hits[h] != hits[u - 1]) hits[u++] = hits[h];
    nhits = u;
    for (size_t h = 0; h < nhits; h++) {
        --s->ncells;
        if (hits[h] != s->ncells)
            memcpy(s->cells + hits[h] * s->csize, s->cells + s->ncells * s->csize, s->csize);
    }
}

/* When too few darts of the level succeed: one level finer (after putting
 * the particles in grid order), or the end of the pass where the cells
 * reach the numbers' resolution. */
static vp_result pass_refine(rsa *s, pass_run *pr) {
    const vp_rsa_pass *ps = pr->ps;
    pr->level_darts += pr->used;
    if (s->split_blocked || !((double)pr->ok < SPLIT_RATE * (double)pr->used) ||
        !(pr->level_darts >= (s->solid        ? SPLIT_DARTS_SOLID
                              : s->level == 0 ? SPLIT_DARTS_LEVEL0
                                              : SPLIT_DARTS) *
                                 s->ncells))
        return VP_OK;
    pr->level_darts = 0;
    if (s->level >= s->max_level && pr->fill_dist && !pr->filling) {
        pr->filling = 1; /* only the smallest radius ends the pass */
        pr->consecutive = 0;
        return VP_OK;
    }
    if (s->level >= s->max_level) {
        /* cells this small are below the numbers' resolution: what is left
         * cannot take a centre that differs from a placed one */
        pr->rep->stop = VP_RSA_STOP_MAXIMAL;
        pr->done = 1;
        return VP_OK;
    }
    /* the particles in grid order before the split reads them all, once a
     * tenth of the pass's particles are new since the last time; a pass
     * that grows keeps placement order, its order of growth */
    if (!ps->grow && 10 * (s->p->count - pr->renumbered) >= s->p->count - pr->first) {
        pr->renumbered = s->p->count;
        renumber(s, pr->first);
    }
    vp_result r = vp_rsa_split_cells(s, 0, NULL);
    if (r != VP_OK) return r;
    pr->rep->budget_hit |= s->split_blocked;
    if (s->split_blocked && ps->maximal) /* honest fallback: retries end it */
        pr->retries = ps->retries > 0 ? (size_t)ps->retries : VP_RSA_DEFAULT_RETRIES;
    return VP_OK;
}

/* A pass that placed nothing in an empty packing is an error (said with
 * its reason); a pass with grow grows its particles. */
static vp_result pass_end(rsa *s, pass_run *pr) {
    const vp_rsa_pass *ps = pr->ps;
    vp_rsa_pass_report *rep = pr->rep;
    if (rep->placed == 0 && pr->first == 0 && s->p->count == 0 && rep->stop == VP_RSA_STOP_RETRIES)
        return vp_fail(s->ctx, VP_ERR_NO_FIT,
                       "rsa: pass %u: nothing placed: %zu tries in a row failed for the first "
                       "particle, of radius %.6g (drawn from the pass's sizes, it keeps its radius "
                       "until placed); raise retries=K or narrow the sizes",
                       pr->index + 1, pr->retries, pr->cur_r);
    if (rep->placed == 0 && pr->first == 0 && s->p->count == 0)
        return vp_fail(s->ctx, VP_ERR_NO_FIT,
                       "rsa: pass %u: no sphere of radius %.6g fits in the container (%s%s)",
                       pr->index + 1, s->rmin - pr->g,
                       s->fit == VP_FIT_INSIDE ? "every sphere wholly inside" : "centres inside",
                       s->margin > 0 ? ", the margin from the wall: is it larger than the "
                                       "container's inradius?"
                                     : "");
    if (ps->grow && s->p->count > pr->first) grow_pass(s, pr->first, s->p->count, &rep->grow_mean);
    return VP_OK;
}

static vp_result run_pass(rsa *s, const vp_rsa_pass *ps, unsigned pass_index, uint64_t seed,
                          vp_rsa_pass_report *rep, double prog0, double prog1) {
    double t0 = vp_seconds();
    memset(rep, 0, sizeof *rep);
    rep->requested = ps->maximal ? 0 : ps->count;
    rep->grow_mean = 1.0;
    pass_run pr;
    memset(&pr, 0, sizeof pr);
    pr.ps = ps;
    pr.index = pass_index;
    pr.rep = rep;
    pr.g = s->gap_half;
    pass_radii(s, &pr, seed);
    int no_room;
    vp_result r = pass_level0(s, &pr, &no_room);
    if (r != VP_OK) return r;
    if (no_room) {
        rep->stop = VP_RSA_STOP_MAXIMAL;
        rep->seconds = vp_seconds() - t0;
        return VP_OK;
    }
    pass_limits(s, &pr);
    while (!pr.done) {
        if (s->ncells == 0) {
            rep->stop = VP_RSA_STOP_MAXIMAL;
            break;
        }
        size_t B = 0;
        if ((r = batch_darts(s, &pr, &B)) != VP_OK) break;
        r = batch_accept(s, &pr, B);
        drop_hit_cells(s, &pr);
        if (r != VP_OK || pr.done) break;
        if (!vp_report_progress_counts(
                s->ctx,
                prog0 + (prog1 - prog0) * (ps->maximal ? (double)s->level / s->max_level
                                                       : (double)rep->placed / (double)pr.want),
                "rsa", rep->placed, ps->maximal ? 0 : pr.want)) {
            r = vp_fail(s->ctx, VP_ERR_CANCELLED, "rsa: cancelled");
            break;
        }
        if ((r = pass_refine(s, &pr)) != VP_OK) break;
    }
    free(pr.hits);
    if (r == VP_OK) r = pass_end(s, &pr);
    rep->seconds = vp_seconds() - t0;
    return r;
}

/* The pass's shape as the tests use it (kinds[k]). */
static void use_kind(rsa *s, unsigned k) {
    const vp_kind *K = &s->kinds[k];
    s->cur = k;
    s->poly = K->poly;
    s->mesh = K->mesh;
    s->sb = K->shape == VP_SHAPE_SUPERBALL ? K->param : 0.0;
    s->shape = K->shape;
    /* a gap: GJK on the grown support functions for every solid */
    s->gjk = s->sb > 0 || vp_shape_overlap_by_gjk(K->shape) || s->pair_gap > 0;
    s->rin = s->solid ? K->rin : 1.0;
    s->unit_volume = K->unit_volume;
    s->cube = K->shape == VP_SHAPE_CUBE && !s->bbox && !s->mixed && !(s->pair_gap > 0);
}

/* The passes' shapes: kinds[0..*nkinds) in the order the passes first use
 * them, and each pass's index into them. */
static vp_result resolve_kinds(vp_context *ctx, const vp_rsa_params *params, vp_kind *kinds,
                               unsigned *nkinds, unsigned *pass_kind) {
    *nkinds = 0;
    for (size_t i = 0; i < params->npasses; i++) {
        const vp_rsa_pass *ps = &params->passes[i];
        vp_shape_ref ref = {params->shape, params->shape_param,
                            params->shape == VP_SHAPE_MESH ? params->mesh : NULL};
        if (ps->own_shape) ref = ps->shape;
        if (ref.shape != VP_SHAPE_SUPERBALL) ref.param = 0.0;
        if (ref.shape != VP_SHAPE_MESH) ref.mesh = NULL;
        vp_kind k;
        if (vp_kind_set(&k, ref) != 0) {
            char where[32] = "";
            if (ps->own_shape) snprintf(where, sizeof where, "pass %zu: ", i + 1);
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "rsa: %s%s", where,
                           ref.shape == VP_SHAPE_SUPERBALL
                               ? "a superball's exponent must be in [0.5, 1000]"
                           : ref.shape == VP_SHAPE_MESH ? "a mesh shape needs its vp_mesh_shape"
                                                        : "unknown shape");
        }
        unsigned u = 0;
        while (u < *nkinds &&
               !(kinds[u].shape == k.shape && kinds[u].param == k.param && kinds[u].mesh == k.mesh))
            u++;
        if (u == *nkinds) {
            if (u == VP_MAX_SHAPES)
                return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                               "rsa: pass %zu: more than %d shapes in one packing", i + 1,
                               VP_MAX_SHAPES);
            kinds[(*nkinds)++] = k;
        }
        pass_kind[i] = u;
    }
    return VP_OK;
}

vp_result vp_pack_rsa(vp_context *ctx, const vp_container *c, const vp_rsa_params *params,
                      vp_particles **out, vp_rsa_report *report) {
    double t0 = vp_seconds();
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "rsa: out is NULL");
    *out = NULL;
    if (!c || !params)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "rsa: container and params are required");
    if (params->npasses < 1 || params->npasses > VP_MAX_GROUPS || !params->passes)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "rsa: between 1 and %d passes are needed",
                       VP_MAX_GROUPS);
    if (params->fit != VP_FIT_INSIDE && params->fit != VP_FIT_CENTER)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "rsa: unknown fit");
    vp_kind kinds[VP_MAX_SHAPES];
    unsigned nkinds = 0, pass_kind[VP_MAX_GROUPS];
    vp_result kr = resolve_kinds(ctx, params, kinds, &nkinds, pass_kind);
    if (kr != VP_OK) return kr;
    const vp_kind *k0 = &kinds[0]; /* the shape of a one-shape packing */
    const int mixed = nkinds > 1;
    if (params->orient != VP_ORIENT_RANDOM && params->orient != VP_ORIENT_FIXED)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "rsa: unknown orientation mode");
    if (params->overlap != VP_OVERLAP_EXACT && params->overlap != VP_OVERLAP_BBOX)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "rsa: unknown overlap test");
    if (!(params->margin >= 0) || !(params->gap >= 0) || !isfinite(params->margin) ||
        !isfinite(params->gap))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "rsa: margin and gap must be finite and >= 0 (world units)");
    for (unsigned k = 0; k < nkinds && params->gap > 0; k++)
        if (kinds[k].mesh)
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "rsa: a gap between mesh shapes is not offered in this version (a "
                           "margin is)");
    if ((params->radius_field || params->density_field) &&
        (mixed || k0->shape != params->shape || k0->mesh != params->mesh))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "rsa: the fields pack one shape: passes with shapes of their own are "
                       "not taken with them");
    if (params->radius_field || params->density_field) /* one radius per pass no more */
        return vp_rsa_fields_pack(ctx, c, params, out, report);
    if (params->gap > 0 && k0->shape != VP_SHAPE_SPHERE && params->overlap == VP_OVERLAP_BBOX)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "rsa: a gap is kept by the exact test, not by bounding boxes");
    if (mixed && params->overlap == VP_OVERLAP_BBOX)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "rsa: the bounding-box overlap test takes one shape; passes of several "
                       "shapes are tested exactly");
    if (k0->shape != VP_SHAPE_SPHERE && params->overlap == VP_OVERLAP_BBOX &&
        params->orient == VP_ORIENT_RANDOM)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "rsa: the bounding-box overlap test needs fixed orientations (axis-aligned "
                       "boxes of rotated solids would not bound them)");
    double rmin = HUGE_VAL, rmax = 0, estimate = 0;
    double vmin = 0.0, r1 = 0.0; /* count passes' volume at their smallest sizes; last size */
    size_t nall = 0;             /* particles the count passes ask for */
    int equal = k0->shape == VP_SHAPE_SPHERE && !mixed; /* spheres of one radius */
    const vp_container_info *ci = &c->info;
    for (size_t i = 0; i < params->npasses; i++) {
        const vp_rsa_pass *ps = &params->passes[i];
        const double unit_volume = kinds[pass_kind[i]].unit_volume;
        double a = vp_size_dist_min(&ps->radius), b = vp_size_dist_max(&ps->radius);
        if (!(a > 0) || !(b >= a) || !isfinite(b))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "rsa: pass %zu: radii must be finite and > 0", i + 1);
        if (ps->retries < 0)
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "rsa: pass %zu: retries must be > 0",
                           i + 1);
        if (!ps->maximal && ps->count == 0)
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "rsa: pass %zu: count must be > 0", i + 1);
        for (size_t k = 0; k < i; k++) { /* each pass its own group */
            char bk[VP_GROUP_NAME_MAX], bi[VP_GROUP_NAME_MAX];
            const char *nk = group_name(params, k, bk), *ni = group_name(params, i, bi);
            if (!strcmp(nk, ni))
                return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                               "rsa: passes %zu and %zu have one group name, '%s'", k + 1, i + 1,
                               ni);
        }
        if (params->gap > 0 && !(params->gap < a))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "rsa: pass %zu: the gap %.6g must be smaller than the smallest radius "
                           "(%.6g)",
                           i + 1, params->gap, a);
        if (a < rmin) rmin = a;
        if (b > rmax) rmax = b;
        /* maximal with sizes: between the count of the smallest and that
         * of the mean volume (the geometric mean of the two) */
        double n = !ps->maximal ? (double)ps->count
                   : ps->radius.kind == VP_SIZE_CONSTANT
                       ? 0.4 * ci->volume / (unit_volume * a * a * a)
                       : 0.4 * ci->volume /
                             (unit_volume * sqrt(a * a * a * vp_size_dist_mean_cube(&ps->radius)));
        double fill = 0.4 * ci->volume / (unit_volume * a * a * a);
        estimate += n < fill * 1.2 ? n : fill * 1.2; /* no more than can fit */
        if (ps->radius.kind != VP_SIZE_CONSTANT || (r1 > 0 && a != r1)) equal = 0;
        r1 = a;
        if (!ps->maximal) {
            vmin += (double)ps->count * unit_volume * a * a * a;
            nall += ps->count;
        }
    }
    /* counts that no packing can hold, by bounds that are proofs: the
     * particles' volume (each at the smallest size its law draws) is at most
     * the container's (fit inside); and they lie in a box (the container's
     * box, grown by the largest radius with fit center), whose packing
     * repeated periodically is a packing of space, so equal spheres fill at
     * most pi / sqrt 18 of it (Kepler's bound, Hales). A container shaped
     * to its spheres can be filled past 0.7405, a box cannot. */
    {
        double grow = params->fit == VP_FIT_CENTER ? 2.0 * rmax : 0.0;
        double box = (ci->bmax[0] - ci->bmin[0] + grow) * (ci->bmax[1] - ci->bmin[1] + grow) *
                     (ci->bmax[2] - ci->bmin[2] + grow);
        const char *what = params->fit == VP_FIT_CENTER
                               ? "the container's box grown by the largest radius"
                               : "the container's box";
        if (params->fit == VP_FIT_INSIDE && ci->volume > 0 && vmin > ci->volume) {
            char what_p[64] = "particles of these sizes (at their smallest)";
            if (equal) snprintf(what_p, sizeof what_p, "spheres of radius %.6g", r1);
            return vp_fail(ctx, VP_ERR_NO_FIT,
                           "rsa: %zu %s cannot fit: they fill %.3g times the container's volume; "
                           "ask for fewer, or count=max for as many as fit",
                           nall, what_p, vmin / ci->volume);
        }
        if (box > 0 && vmin > (equal ? VP_KEPLER : 1.0) * box) {
            if (equal)
                return vp_fail(ctx, VP_ERR_NO_FIT,
                               "rsa: %zu spheres of radius %.6g cannot fit: they would fill %.3g "
                               "of %s, more than any packing of equal spheres holds (0.7405); "
                               "ask for fewer, or count=max for as many as fit",
                               nall, r1, vmin / box, what);
            return vp_fail(ctx, VP_ERR_NO_FIT,
                           "rsa: %zu particles of these sizes cannot fit: at their smallest they "
                           "fill %.3g times the volume of %s; ask for fewer, or count=max for as "
                           "many as fit",
                           nall, vmin / box, what);
        }
    }
    double need = estimate * BYTES_PER_PARTICLE;
    if (need > (double)vp_memory_limit(ctx)) {
        char a[32], b[32];
        vp_format_bytes(need, a, sizeof a);
        vp_format_bytes((double)vp_memory_limit(ctx), b, sizeof b);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY,
                       "rsa: about %.3g particles would need %s, over the memory limit of %s",
                       estimate, a, b);
    }
    if (estimate >= (double)UINT32_MAX - 2)
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "rsa: more than 2^32 particles requested");

    rsa s;
    memset(&s, 0, sizeof s);
    s.min_r = HUGE_VAL;
    s.no_top = vp_env_flag("VDBPACK_NO_TOP_BALLS");
#ifdef VP_HAVE_AVX2_SCAN
    s.avx2 = __builtin_cpu_supports("avx2") && !vp_env_flag("VDBPACK_NO_SIMD");
#endif
    s.ctx = ctx;
    s.c = c;
    s.fit = params->fit;
    s.threads = vp_threads_for(ctx);
    s.max_cells_param = params->max_cells;
    s.margin = params->margin;
    s.gap_half = 0.5 * params->gap;
    s.wall_off = params->fit == VP_FIT_INSIDE ? s.margin - s.gap_half : s.margin;
    /* trilinear interpolation of exact distances has partial derivatives up
     * to 1 each, so its gradient can reach sqrt(3) near edges */
    s.lipschitz = ci->voxel_size > 0 ? sqrt(3.0) : 1.0;
    s.rin = 1.0;
    s.reach = 1.0;
    s.mixed = mixed;
    s.nkinds = nkinds;
    memcpy(s.kinds, kinds, sizeof kinds);
    s.solid = mixed || k0->shape != VP_SHAPE_SPHERE;
    s.bbox = s.solid && params->overlap == VP_OVERLAP_BBOX;
    if (s.solid) { /* the gap between the surfaces, tested exactly */
        s.pair_gap = params->gap;
        s.gap_half = 0.0;
        s.wall_off = s.margin;
    }
    use_kind(&s, 0);
    {
        /* the solids' exact tests and the spheres' top balls allow for it */
        double L = 0.0;
        for (int k = 0; k < 3; k++) {
            if (fabs(ci->bmin[k]) > L) L = fabs(ci->bmin[k]);
            if (fabs(ci->bmax[k]) > L) L = fabs(ci->bmax[k]);
        }
        s.coord_eps = 64.0 * DBL_EPSILON * L;
    }
    if (s.solid) {
        s.orient_random = params->orient == VP_ORIENT_RANDOM;
        s.reach = 1.0;
        for (int k = 0; k < 3; k++) {
            s.bb_lo[k] = HUGE_VAL;
            s.bb_hi[k] = -HUGE_VAL;
            for (int v = 0; s.poly && v < s.poly->nverts; v++) {
                if (s.poly->verts[v][k] < s.bb_lo[k]) s.bb_lo[k] = s.poly->verts[v][k];
                if (s.poly->verts[v][k] > s.bb_hi[k]) s.bb_hi[k] = s.poly->verts[v][k];
            }
            if (s.mesh) {
                s.bb_lo[k] = s.mesh->bb_lo[k];
                s.bb_hi[k] = s.mesh->bb_hi[k];
            }
            if (s.sb > 0) { /* the faces' centres, at 1 / circumradius */
                s.bb_hi[k] = 1.0 / vp_superball_circumradius(s.sb);
                s.bb_lo[k] = -s.bb_hi[k];
            }
        }
        if (s.bbox) {
            double c2 = 0.0;
            for (int k = 0; k < 3; k++) {
                double m =
                    fabs(s.bb_lo[k]) > fabs(s.bb_hi[k]) ? fabs(s.bb_lo[k]) : fabs(s.bb_hi[k]);
                c2 += m * m;
            }
            s.reach = sqrt(c2);
        }
    }
    vp_result r = vp_particles_create(ctx, 0, &s.p);
    if (r != VP_OK) return r;
    s.p->has_orient = s.solid;
    for (int k = 0; k < 3; k++) s.base[k] = 0.5 * (ci->bmin[k] + ci->bmax[k]);
    if (reserve(&s, (size_t)(estimate > 1024 ? estimate : 1024)) != 0) {
        free(s.fpos);
        vp_particles_destroy(s.p);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "rsa: out of memory");
    }
    s.p->shape = mixed ? VP_SHAPE_MIXED : k0->shape;
    s.p->mesh = mixed ? NULL : k0->mesh;
    s.p->shape_param = mixed ? 0.0 : k0->param;
    if (mixed) {
        s.p->shape_count = nkinds;
        for (unsigned k = 0; k < nkinds; k++) {
            vp_shape_ref ref = {kinds[k].shape, kinds[k].param, kinds[k].mesh};
            s.p->shapes[k] = ref;
        }
    }
    s.p->group_count = (unsigned)params->npasses;
    for (size_t i = 0; i < params->npasses; i++) {
        char b[VP_GROUP_NAME_MAX];
        snprintf(s.p->group_names[i], VP_GROUP_NAME_MAX, "%s", group_name(params, i, b));
    }
    size_t grid_cells = (size_t)(2.0 * estimate) + 4096;
    if (vp_sgrid_init(&s.g, ci->bmin, ci->bmax, rmin + s.gap_half, rmax + s.gap_half, grid_cells) !=
            0 ||
        vp_sgrid_reserve(&s.g, (size_t)(estimate > 1024 ? estimate : 1024)) != 0) {
        vp_sgrid_free(&s.g);
        free(s.fpos);
        vp_particles_destroy(s.p);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "rsa: out of memory for the neighbour grid");
    }
    vp_rsa_report rep;
    memset(&rep, 0, sizeof rep);
    rep.npasses = params->npasses;
    for (size_t i = 0; i < params->npasses && r == VP_OK; i++) {
        use_kind(&s, pass_kind[i]);
        r = run_pass(&s, &params->passes[i], (unsigned)i, params->seed, &rep.passes[i],
                     (double)i / params->npasses, (double)(i + 1) / params->npasses);
    }
    vp_sgrid_free(&s.g);
    free(s.cells);
    free(s.darts);
    if (r == VP_OK && s.gap_half > 0) /* deflated: the gap between them */
        for (size_t i = 0; i < s.p->count; i++)
            s.p->radii[i] = (float)((double)s.p->radii[i] - s.gap_half);
    if (r == VP_OK) { /* the centres in world coordinates, as doubles */
        s.p->positions = malloc((s.p->count ? s.p->count : 1) * 3 * sizeof *s.p->positions);
        if (!s.p->positions) r = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "rsa: out of memory");
        else
            for (size_t i = 0; i < s.p->count; i++) ppos(&s, i, s.p->positions + 3 * i);
    }
    free(s.fpos);
    if (r != VP_OK) {
        vp_particles_destroy(s.p);
        return r;
    }
    rep.particle_volume = vp_particles_volume(s.p);
    rep.seconds = vp_seconds() - t0;
    if (report) *report = rep;
    *out = s.p;
    return VP_OK;
}
