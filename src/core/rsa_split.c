/* SPDX-License-Identifier: Apache-2.0 */
/* The random packer's refinement of the empty space (docs/rsa.md,
 * "Sampling: active cells"): each active cell is split in eight, children
 * outside the container or inside one placed particle's exclusion ball are
 * dropped, and a look-ahead (ball lists, scanned four at a time with AVX2)
 * proves sub-cells empty a few levels further. Split rounds run in
 * parallel over chunks of parents and are joined in parent order, so the
 * cells do not depend on the thread count. Reached only through
 * vp_rsa_split_cells (rsa_internal.h). */
#include "core/rsa_internal.h"

#include "core/container.h"
#include "core/context.h"
#include "core/parallel.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Container test of a cell at `level`: 0 = no admissible centre in it,
 * 1 = maybe, 2 = every point passes the container test. */
static int classify(const rsa *s, const cell *c, int level) {
    double a = cell_side(s, level), half = 0.5 * a, hd = half * sqrt(3.0);
    double m[3];
    cell_center(s, c, level, m);
    double d = vp_container_distance(s->c, m);
    /* the slack shrinks with the cell: a fixed one would keep a shell of
     * cells beyond the wall alive at every level */
    double reach = hd * s->lipschitz + 1e-12;
    if (!(d - reach <= thr_drop(s, s->rmin))) return 0; /* also NaN */
    return d + reach <= thr_ok(s, s->rmax) ? 2 : 1;
}

typedef struct cover_query {
    const rsa *s;
    const double *m;
    double half;
} cover_query;

static int cover_visit(void *user, uint32_t j) {
    cover_query *q = user;
    double c[3];
    ppos(q->s, j, c);
    const rsa *s = q->s;
    double e = excluded(s, s->rmin, j, s->uni_r > 0 ? s->uni_r : s->p->radii[j]), f = 0.0;
    for (int k = 0; k < 3; k++) {
        double t = fabs(q->m[k] - c[k]) + q->half;
        f += t * t;
    }
    return f < e * e;
}

/* 1 if one placed sphere's exclusion ball (for the pass's smallest radius)
 * holds the whole cell. */
static int covered(const rsa *s, const cell *c, int level) {
    if (!s->p->count) return 0;
    double a = cell_side(s, level), m[3];
    cell_center(s, c, level, m);
    cover_query q = {s, m, 0.5 * a};
    return vp_sgrid_query(&s->g, m, s->rmin + 0.5 * a * sqrt(3.0), cover_visit, &q);
}

/* The children o of parent p (bits o) that do not lie wholly beyond the
 * box along a thin axis: those that do hold no point of the box, where
 * every admissible centre lies. As a mask of the children, so that the
 * split's loop over them pays nothing for it. */
static unsigned thin_children(const rsa *s, const cell *p, int child_level) {
    static const unsigned upper[3] = {0xAA, 0xCC, 0xF0}; /* bit k of o set */
    double a = cell_side(s, child_level);
    uint32_t v[3] = {p->x, p->y, p->z & ~VALID_BIT};
    unsigned keep = 0xFF;
    for (int k = 0; k < 3; k++) {
        if (!(s->thin >> k & 1)) continue;
        if ((double)(2 * v[k] + 1) * a >= s->extent[k]) keep &= ~upper[k];
        if ((double)(2 * v[k]) * a >= s->extent[k]) keep = 0;
    }
    return keep;
}

static int keep_cell(const rsa *s, cell *c, int level) {
    int k = classify(s, c, level);
    if (!k || covered(s, c, level)) return 0;
    if (k == 2) c->z |= VALID_BIT;
    else c->z &= ~VALID_BIT;
    return 1;
}

/* Split work: parent cells [lo, hi) of chunk i into their own buffer. */
typedef struct split_job {
    const rsa *s;
    const unsigned char *parents;  /* psize bytes each */
    size_t nparents, psize, osize; /* parents; bytes of a parent, of a child */
    int child_level;               /* level of the output cells */
    int from_box;                  /* level-0 build: "parents" are rows of the box */
    int64_t dims[3];
    size_t chunk;
    unsigned char **out;
    size_t *nout, *cap;
    size_t budget; /* cells a chunk may make before the split gives up */
    int failed;
    int over; /* a chunk alone exceeded the budget */
} split_job;

/* A chunk's output while it is being made: kept by the thread that makes
 * it and written back to the job at the end, so that the threads do not
 * write to one cache line (the job's arrays of counts) for every cell:
 * that false sharing took a tenth of the split's time on 2 cores. */
typedef struct split_out {
    unsigned char *buf;
    size_t n, cap, osize;
} split_out;

static int push_cell(split_out *o, cell c) {
    if (o->n == o->cap) {
        size_t nc = o->cap ? o->cap + o->cap / 2 : 256;
        unsigned char *b = realloc(o->buf, nc * o->osize);
        if (!b) return -1;
        o->buf = b;
        o->cap = nc;
    }
    cell_store(o->buf, o->osize, o->n++, c);
    return 0;
}

/* --- look-ahead coverage ---------------------------------------------------------
 * A child cell is dropped when it is proven to hold no admissible centre:
 * the cell, or each of its sub-cells down to LOOKAHEAD levels below it, is
 * either outside the container's admissible region or inside the exclusion
 * ball of one placed sphere. The sub-cells are only visited, never stored,
 * so cells on the seams between exclusion balls (covered by their union but
 * by no single ball) are dropped at once instead of being split and stored
 * level after level. The balls tested are gathered once per parent cell:
 * only a ball that meets the parent can hold one of its sub-cells. Dropping
 * needs a proof, so a ball left out (a full list) only keeps a cell. */
#define LOOKAHEAD 3
#define BALLS_MAX 96

typedef struct ball_list {
    size_t n;
    /* centres by axis, so that balls are tested four at a time where the
     * processor can (ball_scan_avx2); entries n .. n + 3 have e2 = -1 */
    double c[3][BALLS_MAX + 4];
    double e2[BALLS_MAX + 4]; /* (rin (rmin + r_j))^2 */
    const rsa *s;
    double m[3];   /* parent centre */
    double half;   /* parent half side */
    double smin;   /* side of the smallest box the look-ahead tests */
    double uni_e2; /* (rin (rmin + r))^2 when every radius is r, else 0 */
} ball_list;

static int gather_visit(void *user, uint32_t j) {
    ball_list *b = user;
    double c[3];
    ppos(b->s, j, c);
    double e2 = b->uni_e2, d2 = 0.0;
    if (!(e2 > 0)) {
        double e = excluded(b->s, b->s->rmin, j, b->s->p->radii[j]);
        e2 = e * e;
    }
    /* a ball that can hold no cube of side smin in the parent box holds
     * none of the boxes tested (each holds such a cube): along an axis
     * where c lies outside the box, the farthest corner of such a cube is
     * at least t + smin from c, along one where c lies within it at least
     * smin / 2 */
    for (int k = 0; k < 3; k++) {
        double t = fabs(b->m[k] - c[k]) - b->half;
        t = t > 0 ? t + b->smin : 0.5 * b->smin;
        d2 += t * t;
    }
    if (d2 >= e2 || b->n == BALLS_MAX) return 0;
    for (int k = 0; k < 3; k++) b->c[k][b->n] = c[k];
    b->e2[b->n] = e2;
    b->n++;
    return 0;
}

/* Entries past the last ball never hold a box (the vector scan reads
 * them). */
static void ball_list_seal(ball_list *b) {
    for (size_t i = b->n; i < b->n + 4; i++) b->e2[i] = -1.0;
}

/* 1 if ball i holds the whole box (centre m, half side h): its farthest
 * corner is inside. */
static inline int ball_holds_box(const ball_list *b, size_t i, const double m[3], double h) {
    double f = 0.0;
    for (int k = 0; k < 3; k++) {
        double u = fabs(m[k] - b->c[k][i]) + h;
        f += u * u;
    }
    return f < b->e2[i];
}

/* The first ball from 1 on that holds the box, or n. */
static size_t ball_scan(const ball_list *b, const double m[3], double h) {
    for (size_t i = 1; i < b->n; i++)
        if (ball_holds_box(b, i, m, h)) return i;
    return b->n;
}

#ifdef VP_HAVE_AVX2_SCAN
#include <immintrin.h>
/* ball_scan four balls at a time with AVX2: the same arithmetic in the
 * same order as ball_holds_box (no FMA), so the same answer. */
__attribute__((target("avx2"))) static size_t ball_scan_avx2(const ball_list *b, const double m[3],
                                                             double h) {
    const __m256d sign = _mm256_set1_pd(-0.0), hh = _mm256_set1_pd(h);
    const __m256d m0 = _mm256_set1_pd(m[0]), m1 = _mm256_set1_pd(m[1]), m2 = _mm256_set1_pd(m[2]);
    for (size_t i = 0; i < b->n; i += 4) {
        __m256d u0 = _mm256_add_pd(
            _mm256_andnot_pd(sign, _mm256_sub_pd(m0, _mm256_loadu_pd(b->c[0] + i))), hh);
        __m256d u1 = _mm256_add_pd(
            _mm256_andnot_pd(sign, _mm256_sub_pd(m1, _mm256_loadu_pd(b->c[1] + i))), hh);
        __m256d u2 = _mm256_add_pd(
            _mm256_andnot_pd(sign, _mm256_sub_pd(m2, _mm256_loadu_pd(b->c[2] + i))), hh);
        __m256d f = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(u0, u0), _mm256_mul_pd(u1, u1)),
                                  _mm256_mul_pd(u2, u2));
        unsigned bits =
            (unsigned)_mm256_movemask_pd(_mm256_cmp_pd(f, _mm256_loadu_pd(b->e2 + i), _CMP_LT_OQ));
        if (i == 0) bits &= ~1u; /* ball 0 was tested before */
        if (bits) return i + (size_t)__builtin_ctz(bits);
    }
    return b->n;
}
#endif

/* 1 if one ball of the list holds the whole box (centre m, half side h).
 * The ball that does is moved to the front: neighbouring boxes are mostly
 * held by the same ball, tried first next time. */
static int ball_holds(ball_list *b, const double m[3], double h) {
    size_t n = b->n;
    if (!n) return 0;
    if (ball_holds_box(b, 0, m, h)) return 1;
    if (n == 1) return 0;
    size_t i;
#ifdef VP_HAVE_AVX2_SCAN
    i = b->s->avx2 && n > 4 ? ball_scan_avx2(b, m, h) : ball_scan(b, m, h);
#else
    i = ball_scan(b, m, h);
#endif
    if (i >= n) return 0;
    for (int k = 0; k < 3; k++) {
        double t = b->c[k][i];
        b->c[k][i] = b->c[k][0];
        b->c[k][0] = t;
    }
    double e = b->e2[i];
    b->e2[i] = b->e2[0];
    b->e2[0] = e;
    return 1;
}

/* Bit o set when the list's front ball holds the sub-box o of the box of
 * centre m (centre m[k] - q or + q as bit k of o is 0 or 1, half side q):
 * the eight tests share their per-axis terms. */
static unsigned front_holds_subs(const ball_list *b, const double m[3], double q) {
    if (!b->n) return 0;
    double u[3][2];
    for (int k = 0; k < 3; k++) {
        double lo = fabs(m[k] - q - b->c[k][0]) + q, hi = fabs(m[k] + q - b->c[k][0]) + q;
        u[k][0] = lo * lo;
        u[k][1] = hi * hi;
    }
    unsigned bits = 0;
    for (int o = 0; o < 8; o++)
        if (u[0][o & 1] + u[1][(o >> 1) & 1] + u[2][o >> 2] < b->e2[0]) bits |= 1u << o;
    return bits;
}

/* The code of the cell's top ball (centre m): the ball at the front of the
 * parent's list, the last that held a box in the cell's look-ahead (or,
 * without one, in a sibling's), mostly one that holds much of the cell;
 * VP_TOP_NONE when the list is empty or that ball does not meet the cell.
 * The deepest ball of the list (largest e^2 - |c - m|^2) did no better and
 * cost a scan of the list per cell (docs/rsa.md). */
static uint32_t top_ball(const vp_top_scale *ts, const ball_list *b, const double m[3]) {
    if (!(ts->u > 0) || !b->n) return VP_TOP_NONE;
    double off[3] = {b->c[0][0] - m[0], b->c[1][0] - m[1], b->c[2][0] - m[2]};
    return vp_top_encode(ts, off);
}

/* Container test of a box by its centre and half side, as classify(). */
static int classify_box(const rsa *s, const double m[3], double half) {
    double d = vp_container_distance(s->c, m);
    double reach = half * sqrt(3.0) * s->lipschitz + 1e-12;
    if (!(d - reach <= thr_drop(s, s->rmin))) return 0;
    return d + reach <= thr_ok(s, s->rmax) ? 2 : 1;
}

static int box_excluded(const rsa *s, ball_list *b, const double m[3], double h, int valid,
                        int depth);

/* The sub-boxes (centre m +- q per axis as bit k of o says, half side
 * q = h / 2) of the box (m, h) not proven to hold no admissible centre,
 * as bits o. They are looked into `depth` levels deep up to the first
 * such one; after it, with `all`, each gets one ball test (a mask for a
 * cell being made), and without, the result is returned at once (nonzero:
 * enough for box_excluded). valid: the box passes the container test. */
static unsigned live_subs(const rsa *s, ball_list *b, const double m[3], double h, int valid,
                          int depth, int all) {
    double q = 0.5 * h;
    unsigned live = 0xFFu & ~front_holds_subs(b, m, q), found = 0; /* settled in one go */
    for (int o = 0; o < 8; o++) {
        if (!(live >> o & 1)) continue;
        double c[3] = {m[0] + ((o & 1) ? q : -q), m[1] + ((o & 2) ? q : -q),
                       m[2] + ((o & 4) ? q : -q)};
        int v = valid;
        if (!v) {
            int k = classify_box(s, c, q);
            if (!k) {
                live &= ~(1u << o);
                continue;
            }
            v = k == 2;
        }
        if (found ? ball_holds(b, c, q) : box_excluded(s, b, c, q, v, depth)) {
            live &= ~(1u << o);
        } else if (!found) {
            found = 1;
            if (!all) return live;
        }
    }
    return live;
}

/* 1 if the box is proven to hold no admissible centre, looking `depth`
 * levels of sub-cells deep. valid: the box passes the container test. */
static int box_excluded(const rsa *s, ball_list *b, const double m[3], double h, int valid,
                        int depth) {
    if (ball_holds(b, m, h)) return 1;
    return depth > 0 && !live_subs(s, b, m, h, valid, depth - 1, 0);
}

static void split_chunk_into(split_job *j, size_t i, split_out *out) {
    size_t lo = i * j->chunk, hi = lo + j->chunk;
    if (j->from_box) {
        size_t rows = (size_t)(j->dims[1] * j->dims[2]);
        if (hi > rows) hi = rows;
        for (size_t r = lo; r < hi; r++) {
            cell c = {0, 0, 0, 0xFF, VP_TOP_NONE}; /* sub-cells not tested: all may hold a centre */
            c.y = (uint32_t)(r % (size_t)j->dims[1]);
            c.z = (uint32_t)(r / (size_t)j->dims[1]);
            for (int64_t x = 0; x < j->dims[0]; x++) {
                c.x = (uint32_t)x;
                cell t = c;
                if (keep_cell(j->s, &t, 0) && push_cell(out, t)) j->failed = 1;
            }
        }
        return;
    }
    if (hi > j->nparents) hi = j->nparents;
    const rsa *s = j->s;
    double a = cell_side(s, j->child_level), h = 0.5 * a;
    /* solids: their cells are dropped by inspheres, small against the
     * cells, whose unions seldom cover a sub-cell that no single one does:
     * the look-ahead cost more than it saved (docs/rsa.md) */
    int depth = s->solid ? 0 : LOOKAHEAD;
    unsigned thin = s->thin;
    if (j->child_level + depth > s->max_level) depth = s->max_level - j->child_level;
    if (depth < 0) depth = 0;
    ball_list *b = malloc(sizeof *b);
    if (!b) {
        j->failed = 1;
        return;
    }
    const vp_top_scale *ts = &s->top[j->child_level];
    b->s = s;
    b->uni_e2 = 0.0;
    if (s->uni_r > 0) {
        double e = s->rin * (s->rmin + s->uni_r);
        b->uni_e2 = e * e;
    }
    for (size_t k = lo; k < hi; k++) {
        if (out->n > j->budget) {
            j->over = 1;
            break;
        }
        cell p = cell_load(j->parents, j->psize, k);
        if (thin) p.mask &= thin_children(s, &p, j->child_level);
        int pvalid = (p.z & VALID_BIT) != 0;
        uint32_t pz = p.z & ~VALID_BIT;
        double pm[3];
        cell_center(s, &p, j->child_level - 1, pm);
        b->n = 0;
        memcpy(b->m, pm, sizeof b->m);
        b->half = a;
        b->smin = ldexp(a, -depth);
        if (s->p->count) { /* balls (radius rin (rmin + r_j) <= rmin + r_j) meeting the parent */
            double blo[3] = {pm[0] - a, pm[1] - a, pm[2] - a},
                   bhi[3] = {pm[0] + a, pm[1] + a, pm[2] + a};
            /* a useful ball's centre lies closer than e - smin <= rmin + r_j - smin
             * to the box along each axis (gather_visit) */
            double reach = s->rmin - b->smin > 0 ? s->rmin - b->smin : 0.0;
            vp_sgrid_query_box(&s->g, blo, bhi, reach, gather_visit, b);
        }
        ball_list_seal(b);
        for (int o = 0; o < 8; o++) {
            if (!(p.mask >> o & 1)) continue; /* proven empty when p was made */
            cell c = {2 * p.x + (o & 1), 2 * p.y + ((o >> 1) & 1), 2 * pz + ((o >> 2) & 1), 0xFF,
                      VP_TOP_NONE};
            double m[3];
            cell_center(s, &c, j->child_level, m);
            int v = pvalid;
            if (!v) {
                int kk = classify_box(s, m, h);
                if (!kk) continue;
                v = kk == 2;
            }
            /* box_excluded(m, h, depth), noting in the mask the sub-cells
             * proven empty: the look-ahead up to the first sub-cell that
             * may hold a centre (which keeps the child), one ball test for
             * each after it */
            if (ball_holds(b, m, h)) continue;
            if (depth > 0 && !(c.mask = live_subs(s, b, m, h, v, depth - 1, 1))) continue;
            if (v) c.z |= VALID_BIT;
            c.top = top_ball(ts, b, m);
            if (push_cell(out, c)) j->failed = 1;
        }
    }
    free(b);
}

static void split_chunk(void *user, size_t i) {
    split_job *j = user;
    split_out o = {j->out[i], j->nout[i], j->cap[i], j->osize};
    split_chunk_into(j, i, &o);
    j->out[i] = o.buf;
    j->nout[i] = o.n;
    j->cap[i] = o.cap;
}

/* Parents split per round: the parents are taken from the end of the
 * array, and the array shrinks as they are used, so a split holds about
 * max(parents, children) cells at once instead of parents + children. */
#define SPLIT_ROUND 32768
#define SPLIT_CHUNKS 64

/* Gives the parents of a split that was given up back their place: the
 * parents not yet split stay, and each split parent that kept a child is
 * rebuilt from it (children of one parent are consecutive). A parent all
 * of whose children were dropped holds no admissible centre, so leaving it
 * out keeps the law. Its valid flag is recomputed (set only when proven),
 * and its mask has every bit set (nothing proven: the rare path). */
static vp_result unsplit(rsa *s, size_t np, unsigned char *out, size_t nout, size_t osize) {
    int level = s->level;
    size_t n = np;
    uint32_t lx = UINT32_MAX, ly = 0, lz = 0;
    for (size_t i = 0; i < nout; i++) {
        cell c = cell_load(out, osize, i);
        cell p = {c.x >> 1, c.y >> 1, (c.z & ~VALID_BIT) >> 1, 0, VP_TOP_NONE};
        if (p.x == lx && p.y == ly && p.z == lz) continue;
        lx = p.x, ly = p.y, lz = p.z;
        n++;
    }
    unsigned char *cells = realloc(s->cells, (n ? n : 1) * s->csize);
    if (!cells) return vp_fail(s->ctx, VP_ERR_OUT_OF_MEMORY, "rsa: out of memory");
    s->cells = cells;
    lx = UINT32_MAX;
    n = np;
    for (size_t i = 0; i < nout; i++) {
        cell c = cell_load(out, osize, i);
        cell p = {c.x >> 1, c.y >> 1, (c.z & ~VALID_BIT) >> 1, 0xFF, VP_TOP_NONE};
        if (p.x == lx && p.y == ly && p.z == lz) continue;
        lx = p.x, ly = p.y, lz = p.z;
        if (classify(s, &p, level) == 2) p.z |= VALID_BIT;
        cell_store(s->cells, s->csize, n++, p);
    }
    s->ncells = n;
    return VP_OK;
}

/* Replaces the active cells by the kept children of every active cell (or,
 * with from_box, by the kept level-0 cells of the whole box). */
vp_result vp_rsa_split_cells(rsa *s, int from_box, const int64_t dims[3]) {
    size_t nchunks = SPLIT_CHUNKS;
    split_job j;
    memset(&j, 0, sizeof j);
    j.s = s;
    j.child_level = from_box ? 0 : s->level + 1;
    /* top balls: spheres, once there are balls (solids' cells are dropped
     * by inspheres, which seldom hold much of a cell); every exclusion
     * radius rmin + r_j is in [emin, emax] */
    s->top[j.child_level] =
        s->solid ? (vp_top_scale){0.0, 0.0}
        : from_box
            /* level 0: the first sphere this pass places in a cell becomes
             * its top ball (in the serial loop), of exclusion radius
             * rmin + r, r in [rmin, rmax] of the pass */
            ? vp_top_scale_make(2.0 * s->rmin, s->rmin + s->rmax, 0.5 * sqrt(3.0) * cell_side(s, 0),
                                s->coord_eps)
            : s->p->count > 0
                  ? vp_top_scale_make(s->rmin + s->min_r, s->rmin + s->max_r,
                                      0.5 * sqrt(3.0) * cell_side(s, j.child_level), s->coord_eps)
                  : (vp_top_scale){0.0, 0.0};
    j.from_box = from_box;
    j.psize = s->csize;
    j.osize = cell_bytes(s, j.child_level);
    if (from_box) memcpy(j.dims, dims, sizeof j.dims);
    j.out = calloc(nchunks, sizeof *j.out);
    j.nout = calloc(nchunks, sizeof *j.nout);
    j.cap = calloc(nchunks, sizeof *j.cap);
    unsigned char *out = NULL;
    size_t nout = 0, cap = 0;
    size_t np = from_box ? 0 : s->ncells;
    vp_result r = VP_OK;
    if (!j.out || !j.nout || !j.cap) {
        r = VP_ERR_OUT_OF_MEMORY;
        goto done;
    }
    for (int first = 1; first || np > 0; first = 0) {
        size_t take = np < SPLIT_ROUND ? np : SPLIT_ROUND;
        size_t units = from_box ? (size_t)(dims[1] * dims[2]) : take;
        j.parents = from_box ? NULL : s->cells + (np - take) * j.psize;
        j.nparents = take;
        j.chunk = (units + nchunks - 1) / nchunks;
        if (!j.chunk) j.chunk = 1;
        j.budget = s->cell_budget - nout;
        memset(j.nout, 0, nchunks * sizeof *j.nout);
        vp_parallel_for(s->threads, nchunks, split_chunk, &j);
        if (j.failed) {
            r = VP_ERR_OUT_OF_MEMORY;
            goto done;
        }
        size_t total = 0;
        for (size_t i = 0; i < nchunks; i++) total += j.nout[i];
        /* solids: cells are dropped by a necessary condition only, so a
         * split far over the budget is common near the end of a pass; the
         * first round's ratio of children to parents tells it early (twice
         * over: a wrong guess only keeps the current cells) */
        if (!from_box && first && s->solid &&
            (double)total / (double)(take ? take : 1) * (double)np > 2.0 * (double)s->cell_budget)
            j.over = 1;
        if (!from_box && (j.over || total > s->cell_budget - nout)) {
            /* finer cells would take more memory than the budget allows: go on
             * with darts at this level (plain RSA in these cells) */
            s->split_blocked = 1;
            r = unsplit(s, np, out, nout, j.osize);
            goto done;
        }
        if (nout + total > cap) {
            size_t nc = cap + cap / 2;
            if (!cap && !from_box) /* the first round's ratio, 5 % over */
                nc = (size_t)((double)total / (double)(take ? take : 1) * 1.05 * (double)np) + 1024;
            if (nc < nout + total) nc = nout + total;
            if (!from_box && nc > 8 * (nout + np)) nc = 8 * (nout + np); /* at most 8 children */
            unsigned char *b = realloc(out, (nc ? nc : 1) * j.osize);
            if (!b) {
                r = VP_ERR_OUT_OF_MEMORY;
                goto done;
            }
            out = b;
            cap = nc;
        }
        for (size_t i = 0; i < nchunks; i++) {
            if (j.nout[i]) memcpy(out + nout * j.osize, j.out[i], j.nout[i] * j.osize);
            nout += j.nout[i];
        }
        if (from_box) break;
        np -= take;
        if (np) { /* give the split parents' memory back */
            unsigned char *b = realloc(s->cells, np * j.psize);
            if (b) s->cells = b;
        }
    }
    free(s->cells);
    if (nout < cap) { /* trim */
        unsigned char *b = realloc(out, (nout ? nout : 1) * j.osize);
        if (b) out = b;
    }
    s->cells = out;
    out = NULL;
    s->ncells = nout;
    s->csize = j.osize;
    s->level = j.child_level;
done:
    free(out);
    if (j.out)
        for (size_t i = 0; i < nchunks; i++) free(j.out[i]);
    free(j.out);
    free(j.nout);
    free(j.cap);
    if (r != VP_OK) return vp_fail(s->ctx, r, "rsa: out of memory while refining the empty space");
    return VP_OK;
}
