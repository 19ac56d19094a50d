/* SPDX-License-Identifier: Apache-2.0 */
/* The jammed packer; see jam.h and docs/jam.md.
 *
 * Soft spheres with a harmonic overlap energy
 *     U = sum over pairs 1/2 max(0, r_i + r_j - |x_i - x_j|)^2
 *       + sum over spheres 1/2 max(0, r_i + d(x_i))^2    (fit inside;
 *                                                          d(x_i) for centre)
 * (d the container's signed distance, the force along its gradient) are
 * placed at random, overlapping, with their radii (r_i = scale r0_i)
 * scaled so that they overfill the container, and U is minimised by FIRE
 * (Bitzek et al. 2006, with the semi-implicit Euler step of Guenole et al.
 * 2020): the quench. Then the scale becomes one more degree of freedom,
 * pushed up by a constant force (a pressure) and held back by the
 * overlaps, and the enthalpy U - drive * scale is minimised by the same
 * FIRE, as a barostat minimises with the box (LAMMPS's fix box/relax
 * does): at a minimum the mean overlap is what the drive asks.
 * The pressure falls by tenths until the largest overlap of a minimum is
 * below FINISH_OVERLAP: the packing is then at its jamming point to that
 * precision (O'Hern et al. 2003), and an exact last step scales all radii
 * by one factor so that no pair and no wall overlaps at all (in double
 * precision). Polydisperse radii start denser and trade places between
 * neighbours in the quench where that lowers U (swap_radii). A sphere
 * caught in a part of the container thinner than itself would hold all
 * radii down to that part's: after a minimisation under pressure it moves
 * to the freest of a few places drawn at random, and the minimisation is
 * repeated (relocate_squeezed).
 *
 * Speed: positions (with r0) are kept in cell order (re-sorted when the
 * neighbour list is rebuilt), the list holds every pair within
 * r_i + r_j + skin and is rebuilt only when a sphere may have closed in
 * on another by the skin (the radii's growth counted): the two largest
 * displacements added, and past that each sphere that moved over half
 * the skin against its neighbours (list_still_holds); the wall is sampled only for spheres the
 * list build found within reach of it, and its direction (six samples) kept while a sphere
 * stays within WALL_KEEP mean diameters of where it was taken (wall_kept); the pair forces, and the list
 * build's distance tests, take four list entries (candidates) at a time
 * (AVX2 where the processor has it, the same arithmetic without; the FIRE
 * move and the force pass's sums too); the list's cells are half the reach
 * in x, so a row of candidates fills the lanes better; a build after the
 * first is one pass over the cells, not a count and a fill.
 * The quench, two thirds of the steps, keeps 16-byte records instead:
 * positions in fixed point (32-bit integers, a unit of 2^-30 of the
 * container's largest extent) and the scaled radius as a float, so that
 * the differences of positions are exact and the pair forces and the list
 * tests take eight at a time in single precision (enter_quench,
 * leave_quench); the barostat needs double precision and has it.
 * Determinism: work is split into a fixed number of chunks whatever the
 * thread count, each sphere's force is summed over its own list in a fixed
 * order, and the chunks' sums are added in chunk order. */
#include "core/container.h"
#include "core/context.h"
#include "core/field.h"
#include "core/geom.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/size_dist_sample.h"

#if defined(__SSE2__) && defined(__x86_64__)
#include <emmintrin.h>
#endif
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NCHUNK 256 /* at most; n / 512 for fewer spheres, never fewer than 1 */
#define FAR_CAP 64 /* far spheres a chunk's step keeps (disp_track); more: the list is rebuilt */
#define FAR_SEEN 8 /* far spheres checked since a build, at most n / FAR_SEEN: then rebuilt */
#define XSPLIT 2   /* list cells: the reach in y and z, half of it in x */
/* FIRE (Bitzek et al. 2006, their Table I) in units where k = m = 1; the
 * largest step is near the stability limit of the stiffest contacts
 * (2 / sqrt(12)), which FIRE's restarts keep in check */
#define FIRE_DT0 0.02
#define FIRE_DTMAX 0.5
#define FIRE_NDELAY 5
#define FIRE_FINC 1.1
#define FIRE_FDEC 0.5
#define FIRE_ALPHA0 0.1
#define FIRE_FALPHA 0.99
#define MAX_STEPS 200000 /* FIRE steps of one minimisation, at most */
/* and past STALL_STEPS steps since its force ratio (rms force over rms
 * overlap) last halved: it no longer converges (minimize) */
#define STALL_STEPS 20000
/* or BARO_STALL_STEPS under a pressure. There a box's force ratio halves
 * every few hundred steps to the end (100 000 spheres: each pressure in
 * under 1 000 steps), but in a mesh with thin parts, whose wall pushes
 * along a smoothed direction rather than the distance's own gradient (not
 * quite a force of the energy), the last, smallest pressures wander:
 * suzanne.obj, 2 000 spheres, seeds 1 to 8, took 7 214 to 73 833 FIRE
 * steps in all (mean 32 262; with the quench to 1.5e-3, seed 7 ran one
 * pressure 27 526 steps and left it at a force ratio of 0.2); with 5 000
 * here 7 214 to 53 272 (mean 22 845), fractions within 0.0011 of before.
 * 2 000 cut the mean to 15 487 but left long channels less jammed, where
 * slow pressures even out along the length (box:10,1,1 --count 3930
 * --seed 2: 39 % rattlers against 17 %; with 5 000 16 %). */
#define BARO_STALL_STEPS 5000
#define MAX_MINIMIZATIONS 12
/* The protocol: random centres with radii that fill START_FRACTION, a
 * quench there (rms force below QUENCH_TOL of the rms overlap: the deeper
 * it goes the denser the packing jams), then the radius scale set free
 * under a pressure that holds a mean overlap of MID_OVERLAP, then
 * pressures a tenth or less of the last, aimed at a largest overlap of
 * half FINISH_OVERLAP, each minimised to FORCE_TOL. (The first pressure
 * minimised only to 0.1 left the next ones more to do: this takes 18 to
 * 34 % fewer steps in all at 10 000 spheres and 12 % fewer at 100 000,
 * at the same density or a little more; docs/log/jam-performance.md.) */
#define START_FRACTION 0.70
/* Polydisperse packings (radii with a standard deviation of POLYDISPERSE
 * of their mean or more, not taken from a field) start at
 * POLY_START_FRACTION and swap radii between neighbours in the quench,
 * after every SWAP_EVERY-th list build, where a swap lowers the energy and
 * changes neither radius by more than SWAP_REACH of the skin. Such
 * mixtures do not crystallise (no sphere is solid-like by q6 at either
 * start), so the denser start costs no order; with the swaps they jam
 * 0.004 denser in fewer steps (docs/jam.md). Equal spheres, or nearly
 * equal, keep START_FRACTION: denser starts order their walls. */
#define POLYDISPERSE 0.1
#define POLY_START_FRACTION 0.75
#define SWAP_EVERY 4
#define SWAP_REACH 0.5
#define QUENCH_TOL 0.0012
#define MID_OVERLAP 1e-3
#define FORCE_TOL 0.01
#define FINISH_OVERLAP 8e-5 /* largest overlap / (r_i + r_j) of the last minimum */
#define QUENCH_SKIN 0.35    /* the list's skin in the quench, of the mean diameter */
#define SKIN 0.15           /* and after it */
#define CORE_DIAMETERS 5.0
/* a sphere's wall direction is kept while it stays within this many mean
 * diameters of where it was taken (wall_kept) */
#define WALL_KEEP 0.001
/* The quench ends when its rms overlap falls below this many mean
 * diameters: the start's scale is not jammed (with --fit center, say, the
 * spheres may hang over the wall, so 0.70 of the volume does not fill it)
 * and the pressures after it find the jamming point from there. A jammed
 * quench sits near 0.05; the first pressure's mean overlap is MID_OVERLAP.
 * Until 2026-11-29 this was 1e-3 of FINISH_OVERLAP (8e-8), and a mesh's
 * wall, which pushes along its smoothed direction rather than the
 * distance's own gradient, could leave an rms overlap near 1e-6 that FIRE
 * circled around without clearing: peanut.obj --count 5000 --seed 2
 * --fit center ran its quench to the 200 000-step cap. */
#define UNJAMMED (1e-2 * MID_OVERLAP)

/* Whether the radii are spread enough to swap them (and start denser). */
static int polydisperse(const vp_jam_params *P) {
    return !P->radius_field && vp_size_dist_rel_sd(&P->radius) >= POLYDISPERSE;
}

static double start_fraction(const vp_jam_params *P) {
    return polydisperse(P) ? POLY_START_FRACTION : START_FRACTION;
}

void vp_jam_params_init(vp_jam_params *p) {
    memset(p, 0, sizeof *p);
    p->fit = VP_FIT_INSIDE;
    vp_size_dist_constant(&p->radius, 1.0);
    p->target_fraction = 0.64;
    p->tolerance = 1e-6;
    p->contact_gap = 1e-4;
}

typedef struct jam {
    const vp_container *c;
    vp_fit fit;
    double margin, gap; /* kept from the wall, between surfaces (world) */
    size_t n;
    double *x;   /* 4n: position and r0 of each sphere, in cell order (after the quench) */
    int32_t *xq; /* 4(n + 8): the quench's records: position in fixed point (units of
                    * qres from qc) and, as a float's bits, the scaled radius in those units
                    * (x is NULL then; past n, zeros the list build's eight-wide loads read) */
    double *r0q; /* n: r0 in the quench */
    double qc[3], qres, qinv; /* the fixed point's origin, unit and 1 / unit */
    float *v;                 /* 3n velocities */
    float *f;                 /* 3n forces */
    float *xr;                /* 3n positions at the last list build */
    uint32_t *id;             /* n: the sphere's index in the output */
    uint32_t *off;            /* n + 1: list of sphere i is nb[off[i] .. off[i+1]) */
    uint32_t *nb;
    size_t nb_cap;
    uint8_t *near_wall; /* n: within reach of the wall until the next build */
    /* the wall's direction kept for each near-wall sphere, in sphere order
     * (wall_kept): where it was taken (x, y, z; NaN: not yet since the
     * build) and the direction, six floats a sphere; each chunk's first */
    float *wdir;
    size_t wdir_cap;
    uint32_t wbase[NCHUNK], wcount[NCHUNK];
    double wkeep2; /* the squared distance a kept direction serves */
    double scale, skin, r0max, dmean;
    /* the chunks' last list sizes, and the one-pass build's regions */
    uint32_t tot[NCHUNK], reg[NCHUNK], est[NCHUNK];
    uint8_t over[NCHUNK];
    int have_tot; /* tot holds the last build's */
    /* the cell grid of list builds */
    double lo[3], cell, csize[3]; /* the reach; the cells' sizes (x: cell / XSPLIT) */
    int dims[3];
    uint32_t *cstart; /* cells + 1 */
    size_t ncells;
    /* a step's parameters and the chunks' sums */
    double dt, alpha, vscale; /* mixing: v <- (1 - alpha) v + vscale F */
    int zero_v;
    size_t chunk, nchunk;
    double sum[NCHUNK][7]; /* energy, F.v, F.F, v.v, the two largest displacements^2 since
                            * the list's build, dU/dscale */
    /* the radius scale as a degree of freedom (pressure control): its
     * mass-weighted velocity, sqrt(mass), the constant force that drives
     * it up, and the scale at the last list build */
    int baro, avx2;
    double vs, msq, drive, s_build;
    double scale_lo, scale_hi; /* beyond these the spheres escape the wall */
    /* radius swaps in the quench (polydisperse packings), and twice the
     * largest radius change they made since the list's build */
    int swap;
    double swap_grow;
    /* the spheres moved more than half the skin left, each chunk's
     * (FAR_CAP apart; how many, which may be more than it holds) */
    double far2;
    uint32_t *far;
    uint32_t nfar[NCHUNK];
    double xr_err;     /* a displacement's error from xr's rounding, at most (xr_rounding) */
    size_t far_seen;   /* far spheres list_still_holds checked since the build */
    uint32_t rows_cap; /* ROWS_CAP, or less under VDBPACK_JAM_ROWS_CAP (tests) */
    int check_lists;   /* VDBPACK_JAM_CHECK_LISTS: kept lists checked, how many and pairs */
    int no_relieve;    /* VDBPACK_JAM_NO_RELIEVE (tests): the last step shrinks only */
    long lists_checked, pairs_checked;
} jam;

/* the radius of sphere i before scaling: r_i = scale R0(s, i) (after the
 * quench; r0_of and centre_of in either) */
#define R0(s, i) ((s)->x[4 * (size_t)(i) + 3])

static inline float q_radius(const jam *s, size_t i) {
    float r;
    memcpy(&r, s->xq + 4 * i + 3, sizeof r);
    return r;
}

static inline void q_set_radius(jam *s, size_t i, double r0) {
    float r = (float)(s->scale * r0 / s->qres);
    memcpy(s->xq + 4 * i + 3, &r, sizeof r);
}

#define Q_MAX 2147483647

/* u rounded to an integer, half to even (the processor's own rounding where
 * it has SSE2: no libm call) */
static inline int64_t q_round(double u) {
#if defined(__SSE2__) && defined(__x86_64__)
    if (!(fabs(u) < 4e18)) return u < 0 ? -(int64_t)4e18 : (int64_t)4e18;
    return _mm_cvtsd_si64(_mm_set_sd(u));
#else
    return (int64_t)nearbyint(u);
#endif
}

/* x in the fixed point, rounded half away from zero (without a libm call) */
static inline int32_t q_coord(const jam *s, int k, double x) {
    double t = (x - s->qc[k]) * s->qinv;
    t += t < 0 ? -0.5 : 0.5;
    return t < -2147483647.0 ? -2147483647 : t > 2147483647.0 ? 2147483647 : (int32_t)t;
}

static inline double r0_of(const jam *s, size_t i) { return s->xq ? s->r0q[i] : s->x[4 * i + 3]; }

static inline void set_r0(jam *s, size_t i, double r) {
    if (s->xq) {
        s->r0q[i] = r;
        q_set_radius(s, i, r);
    } else {
        s->x[4 * i + 3] = r;
    }
}

static inline void centre_of(const jam *s, size_t i, double p[3]) {
    if (s->xq)
        for (int k = 0; k < 3; k++) p[k] = s->qc[k] + s->qres * (double)s->xq[4 * i + k];
    else
        for (int k = 0; k < 3; k++) p[k] = s->x[4 * i + k];
}

static void chunk_range(const jam *s, size_t ci, size_t *lo, size_t *hi) {
    *lo = ci * s->chunk;
    *hi = *lo + s->chunk;
    if (*lo > s->n) *lo = s->n;
    if (*hi > s->n) *hi = s->n;
}

/* The direction the wall pushes a sphere of radius r at x back: minus a
 * gradient of d taken by central differences r/2 either side of x, not
 * made a unit vector. The container's own gradient jumps across its
 * medial axis (at an edge of a box, from one face's normal to the
 * other's), where a sphere touching both faces was pushed by one and then
 * the other in turn and FIRE never settled; the differences blend the two
 * over r/2, so the wall's force is continuous: the mean of the faces'
 * normals at an edge (length 0.71 for a right angle), and in a part of
 * the container about as thin as the sphere, pressed from both sides, a
 * vector that shrinks to nothing mid-way. (Until 2026-11-29 it was made a
 * unit vector, which there pointed anywhere: a sphere in such a part was
 * pushed to and fro at full strength and its minimisations ran to their
 * cap, suzanne.obj's ears; see relocate_squeezed.) A centre outside the
 * container (d, its distance, >= 0: --fit center's overlap) is pushed
 * back at full strength, the direction made a unit vector: near the edge
 * of a level set's band, where the distance flattens out, the blend alone
 * fades and let such a centre stay outside (peanut.obj, 5 000 spheres,
 * --fit center, seed 2: one held 1.05 radii out). Where the differences
 * vanish altogether (beyond the band), the container's own gradient. */
static void wall_direction(const jam *s, const double *x, double d, double r, double g[3]) {
    double h = 0.5 * r, n2 = 0;
    for (int a = 0; a < 3; a++) {
        double p[3] = {x[0], x[1], x[2]}, q[3] = {x[0], x[1], x[2]};
        p[a] += h;
        q[a] -= h;
        g[a] = (vp_container_distance(s->c, p) - vp_container_distance(s->c, q)) / (2 * h);
    }
    for (int a = 0; a < 3; a++) n2 += g[a] * g[a];
    if (!(n2 > 0)) {
        vp_container_gradient(s->c, x, g);
    } else if (d >= 0 && n2 != 1) {
        double inv = 1.0 / sqrt(n2);
        for (int a = 0; a < 3; a++) g[a] *= inv;
    }
}

/* The wall's overlap of a sphere of radius r whose centre is at distance d
 * from the wall (<= 0: none). */
static double wall_depth_at(const jam *s, double d, double r) {
    return (s->fit == VP_FIT_INSIDE ? d + r : d) + s->margin;
}

/* The same for a sphere at x. */
static double wall_depth(const jam *s, const double *x, double r) {
    return wall_depth_at(s, vp_container_distance(s->c, x), r);
}

/* The wall's overlap (wall_depth) and, when it overlaps, the direction it
 * pushes the sphere back (wall_direction): the one kept in slot
 * while the sphere stays within sqrt(wkeep2) (WALL_KEEP mean diameters)
 * of where it was taken, and taken again (and kept) past that. The
 * overlap is always the container's at x; the kept direction is off the
 * one at x by at most about sqrt(wkeep2) / (r / 2) radians, 0.004 for a
 * sphere of the mean size (the differences' blend turns over r / 2 at
 * the sharpest), and the six samples that take it, most of a mesh
 * container's time, are taken only while the sphere still moves. */
static double wall_kept(const jam *s, const double *x, double r, double g[3], float *slot) {
    double d = vp_container_distance(s->c, x), w = wall_depth_at(s, d, r);
    if (w <= 0) return w;
    double e0 = x[0] - slot[0], e1 = x[1] - slot[1], e2 = x[2] - slot[2];
    if (e0 * e0 + e1 * e1 + e2 * e2 <= s->wkeep2) { /* false for NaN: none kept */
        g[0] = slot[3];
        g[1] = slot[4];
        g[2] = slot[5];
        return w;
    }
    wall_direction(s, x, d, r, g);
    for (int k = 0; k < 3; k++) {
        slot[k] = (float)x[k];
        slot[3 + k] = (float)g[k];
    }
    return w;
}

/* ---- the neighbour list ------------------------------------------------ */

/* the cell along axis k holding coordinate x (the grid's edge cells
 * hold what lies beyond) */
static inline int cell_along(const jam *s, int k, double x) {
    double t = (x - s->lo[k]) / s->csize[k];
    return t < 0 ? 0 : t >= s->dims[k] ? s->dims[k] - 1 : (int)t;
}

static size_t cell_of(const jam *s, const double *x) {
    int c[3];
    for (int k = 0; k < 3; k++) c[k] = cell_along(s, k, x[k]);
    return ((size_t)c[2] * (size_t)s->dims[1] + (size_t)c[1]) * (size_t)s->dims[0] + (size_t)c[0];
}

/* Sets the grid for cells of at least `cell` (the largest pair reach) in y
 * and z and a XSPLIT-th of it in x, over the container's box grown by it,
 * with at most about 8 XSPLIT n cells. A sphere's candidates are then the
 * 3 x 3 rows of 2 XSPLIT + 1 cells around its own: a sixth fewer than in
 * rows of three whole cells, and rows short enough to fill the list
 * build's eight lanes better. */
static int grid_init(jam *s, double cell) {
    const vp_container_info *ci = &s->c->info;
    for (;;) {
        double cells = 1;
        for (int k = 0; k < 3; k++) {
            s->lo[k] = ci->bmin[k] - cell;
            s->csize[k] = k == 0 ? cell / XSPLIT : cell;
            double d = ceil((ci->bmax[k] - ci->bmin[k] + 2 * cell) / s->csize[k]);
            s->dims[k] = d < 1 ? 1 : d > 1e6 ? 1000000 : (int)d;
            cells *= s->dims[k];
        }
        if (cells <= 8.0 * XSPLIT * (double)s->n + 64) break;
        cell *= 1.25;
    }
    s->cell = cell;
    s->ncells = (size_t)s->dims[0] * s->dims[1] * s->dims[2];
    free(s->cstart);
    s->cstart = malloc((s->ncells + 1) * sizeof *s->cstart);
    return s->cstart ? 0 : -1;
}

/* The cell sort's passes over the spheres, a chunk at a time: the keys
 * (what 0), then for one array at a time the gather through perm into
 * tmp (1) and the copy back (2). An array: elements of `size` bytes (4
 * or 8), sphere i's at base[stride i + k]. */
typedef struct sort_pass {
    jam *s;
    uint32_t *key, *perm;
    void *tmp;
    int what;
    void *base;
    size_t size, stride, k;
} sort_pass;

static void sort_chunk(void *user, size_t ci) {
    sort_pass *p = user;
    const jam *s = p->s;
    size_t lo, hi;
    chunk_range(s, ci, &lo, &hi);
    if (p->what == 0) {
        for (size_t i = lo; i < hi; i++) {
            double x[3];
            centre_of(s, i, x);
            p->key[i] = (uint32_t)cell_of(s, x);
        }
    } else if (p->size == 4) {
        uint32_t *a = p->base, *t = p->tmp;
        if (p->what == 1)
            for (size_t i = lo; i < hi; i++) t[i] = a[p->stride * p->perm[i] + p->k];
        else
            for (size_t i = lo; i < hi; i++) a[p->stride * i + p->k] = t[i];
    } else {
        uint64_t *a = p->base, *t = p->tmp;
        if (p->what == 1)
            for (size_t i = lo; i < hi; i++) t[i] = a[p->stride * p->perm[i] + p->k];
        else
            for (size_t i = lo; i < hi; i++) a[p->stride * i + p->k] = t[i];
    }
}

/* Reorders the spheres by cell (a stable counting sort: deterministic)
 * and fills cstart. Its scratch is the forces (recomputed after every
 * build) and the positions at the last build (rewritten by it), so a
 * build allocates only the cells' write positions. The keys and the
 * reordering run on the threads, chunk by chunk; the counts and the
 * permutation on one. */
static int sort_by_cell(jam *s, int threads) {
    size_t n = s->n, nc = s->ncells;
    uint32_t *key = (uint32_t *)s->f, *perm = key + n;     /* 8n of f's 12n bytes */
    sort_pass p = {s, key, perm, s->xr, 0, NULL, 0, 0, 0}; /* tmp: 8n of xr's 12n bytes */
    uint32_t *pos = malloc(nc * sizeof *pos);
    if (!pos) return -1;
    vp_parallel_for(threads, s->nchunk, sort_chunk, &p);
    memset(s->cstart, 0, (nc + 1) * sizeof *s->cstart);
    for (size_t i = 0; i < n; i++) s->cstart[key[i] + 1]++;
    for (size_t c = 0; c < nc; c++) s->cstart[c + 1] += s->cstart[c];
    /* perm[new] = old */
    memcpy(pos, s->cstart, nc * sizeof *pos);
    for (size_t i = 0; i < n; i++) perm[pos[key[i]]++] = (uint32_t)i;
    free(pos);
    /* apply, one component at a time through tmp */
    struct {
        void *base;
        size_t size, stride, count;
    } arr[4] = {{s->xq ? (void *)s->xq : (void *)s->x, s->xq ? 4 : 8, 4, 4},
                {s->xq ? (void *)s->r0q : NULL, 8, 1, 1},
                {s->v, 4, 3, 3},
                {s->id, 4, 1, 1}};
    for (int a = 0; a < 4; a++) {
        if (!arr[a].base) continue;
        p.base = arr[a].base;
        p.size = arr[a].size;
        p.stride = arr[a].stride;
        for (p.k = 0; p.k < arr[a].count; p.k++) {
            p.what = 1;
            vp_parallel_for(threads, s->nchunk, sort_chunk, &p);
            p.what = 2;
            vp_parallel_for(threads, s->nchunk, sort_chunk, &p);
        }
    }
    return 0;
}

/* The spheres j of [a, e) (j != i) within ri + r_j + reach_extra of
 * sphere i, appended to out (NULL: only counted) from out[count]; returns
 * the new count. The AVX2 form tests four at a time with the same
 * arithmetic, so the lists are the same. */
static uint32_t scan_c(const jam *s, size_t i, double ri, double reach_extra, uint32_t a,
                       uint32_t e, uint32_t *out, uint32_t count) {
    const double *xi = s->x + 4 * i;
    for (uint32_t j = a; j < e; j++) {
        if (j == i) continue;
        const double *xj = s->x + 4 * (size_t)j;
        double reach = ri + s->scale * R0(s, j) + reach_extra;
        double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
        if (dx * dx + dy * dy + dz * dz < reach * reach) {
            if (out) out[count] = j;
            count++;
        }
    }
    return count;
}

/* The same in the quench, in its units (single precision, the fixed
 * point's differences exact): reach = base + r_j (base = r_i + the
 * reach's extra). The AVX2 form tests eight at a time with the same
 * arithmetic. */
static uint32_t scan_q_c(const jam *s, size_t i, float base, uint32_t a, uint32_t e, uint32_t *out,
                         uint32_t count) {
    const int32_t *xi = s->xq + 4 * i;
    for (uint32_t j = a; j < e; j++) {
        if (j == i) continue;
        const int32_t *xj = s->xq + 4 * (size_t)j;
        float reach = base + q_radius(s, j);
        float dx = (float)(xi[0] - xj[0]), dy = (float)(xi[1] - xj[1]), dz = (float)(xi[2] - xj[2]);
        if ((dx * dx + dy * dy) + dz * dz < reach * reach) {
            if (out) out[count] = j;
            count++;
        }
    }
    return count;
}

/* The quench's list build a row of cells at a time: the nine rows of cells
 * around the row (y, z) that a sphere's candidates lie in, copied once as
 * four arrays (x, y, z in the fixed point and the scaled radius), so that
 * each sphere of the row tests eight candidates with four loads and no
 * transpose (the scan takes a third less time than from the records). */
#define ROWS_CAP 8192 /* entries; a longer set of rows is scanned as records */
#define ROWS_PAD 8    /* entries past the rows' end that the eight-wide loads may read */
typedef struct qrows {
    int y, z;          /* the row last asked for; y < 0: none */
    int held;          /* 1: rows around (y, z) held; 0: too many, or no memory */
    int nrow;          /* rows held (those inside the grid) */
    size_t cell0[9];   /* each row's cell at x = 0 */
    uint32_t first[9]; /* its first sphere */
    uint32_t at[9];    /* where it starts in the arrays */
    uint32_t cap;      /* entries the arrays hold, each with ROWS_PAD more */
    int32_t *buf;      /* x, y, z and the radius's bits, cap + ROWS_PAD apart */
} qrows;

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#define VP_JAM_AVX2 1

/* Whether rb holds the rows around (y, z), filling it if they are new to
 * it: 0 when they hold more than ROWS_CAP spheres or no memory is left
 * for them (the caller scans the records). rb owns buf, the caller frees
 * it. */
static int qrows_hold(const jam *s, qrows *rb, int y, int z) {
    if (rb->y == y && rb->z == z) return rb->held;
    uint32_t total = 0;
    int nrow = 0;
    rb->y = y;
    rb->z = z;
    rb->held = 0;
    for (int dz = -1; dz <= 1; dz++) {
        int zz = z + dz;
        if (zz < 0 || zz >= s->dims[2]) continue;
        for (int dy = -1; dy <= 1; dy++) {
            int yy = y + dy;
            if (yy < 0 || yy >= s->dims[1]) continue;
            size_t c0 = ((size_t)zz * s->dims[1] + (size_t)yy) * s->dims[0];
            uint32_t a = s->cstart[c0], e = s->cstart[c0 + (size_t)s->dims[0]];
            rb->cell0[nrow] = c0;
            rb->first[nrow] = a;
            rb->at[nrow] = total;
            total += e - a;
            nrow++;
        }
    }
    if (total > s->rows_cap) return 0;
    if (total > rb->cap || !rb->buf) {
        uint32_t cap = total < 512                    ? 512
                       : total + total / 4 < ROWS_CAP ? total + total / 4
                                                      : ROWS_CAP;
        free(rb->buf);
        rb->buf = malloc(4 * ((size_t)cap + ROWS_PAD) * sizeof *rb->buf);
        rb->cap = rb->buf ? cap : 0;
        if (!rb->buf) return 0;
    }
    const size_t st = (size_t)rb->cap + ROWS_PAD;
    int32_t *X = rb->buf, *Y = X + st, *Z = Y + st, *R = Z + st;
    for (int r = 0; r < nrow; r++) {
        uint32_t a = rb->first[r], e = s->cstart[rb->cell0[r] + (size_t)s->dims[0]];
        for (uint32_t j = a, b = rb->at[r]; j < e; j++, b++) {
            const int32_t *q = s->xq + 4 * (size_t)j;
            X[b] = q[0];
            Y[b] = q[1];
            Z[b] = q[2];
            R[b] = q[3];
        }
    }
    for (uint32_t b = total; b < total + ROWS_PAD; b++) X[b] = Y[b] = Z[b] = R[b] = 0;
    rb->nrow = nrow;
    rb->held = 1;
    return 1;
}

/* The byte shuffle that packs the lanes of a 4-bit mask to the front, in order. */
static const uint8_t compress_lut[16][16] = {
    {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},
    {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},
    {4, 5, 6, 7, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},
    {0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 0, 1, 2, 3},
    {8, 9, 10, 11, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},
    {0, 1, 2, 3, 8, 9, 10, 11, 0, 1, 2, 3, 0, 1, 2, 3},
    {4, 5, 6, 7, 8, 9, 10, 11, 0, 1, 2, 3, 0, 1, 2, 3},
    {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 0, 1, 2, 3},
    {12, 13, 14, 15, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3},
    {0, 1, 2, 3, 12, 13, 14, 15, 0, 1, 2, 3, 0, 1, 2, 3},
    {4, 5, 6, 7, 12, 13, 14, 15, 0, 1, 2, 3, 0, 1, 2, 3},
    {0, 1, 2, 3, 4, 5, 6, 7, 12, 13, 14, 15, 0, 1, 2, 3},
    {8, 9, 10, 11, 12, 13, 14, 15, 0, 1, 2, 3, 0, 1, 2, 3},
    {0, 1, 2, 3, 8, 9, 10, 11, 12, 13, 14, 15, 0, 1, 2, 3},
    {4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 0, 1, 2, 3},
    {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15}};

/* Four spheres' (x, y, z, r0), one per register, as x, y, z and r0 of
 * the four. */
__attribute__((target("avx2"))) static inline void transpose4(__m256d p0, __m256d p1, __m256d p2,
                                                              __m256d p3, __m256d out[4]) {
    __m256d t0 = _mm256_unpacklo_pd(p0, p1), t1 = _mm256_unpackhi_pd(p0, p1);
    __m256d t2 = _mm256_unpacklo_pd(p2, p3), t3 = _mm256_unpackhi_pd(p2, p3);
    out[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
    out[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
    out[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
    out[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
}

__attribute__((target("avx2"))) static uint32_t scan_avx2(const jam *s, size_t i, double ri,
                                                          double reach_extra, uint32_t a,
                                                          uint32_t e, uint32_t *out, uint32_t count,
                                                          int room4) {
    const double *xi = s->x + 4 * i;
    const __m256d xi0 = _mm256_set1_pd(xi[0]), xi1 = _mm256_set1_pd(xi[1]),
                  xi2 = _mm256_set1_pd(xi[2]), vri = _mm256_set1_pd(ri),
                  vsc = _mm256_set1_pd(s->scale), vex = _mm256_set1_pd(reach_extra);
    uint32_t j = a;
    for (; j + 4 <= e; j += 4) {
        const double *p = s->x + 4 * (size_t)j;
        __m256d q[4];
        transpose4(_mm256_loadu_pd(p), _mm256_loadu_pd(p + 4), _mm256_loadu_pd(p + 8),
                   _mm256_loadu_pd(p + 12), q);
        const __m256d xj0 = q[0], xj1 = q[1], xj2 = q[2], r0j = q[3];
        __m256d reach = _mm256_add_pd(_mm256_add_pd(vri, _mm256_mul_pd(vsc, r0j)), vex);
        __m256d dx = _mm256_sub_pd(xi0, xj0), dy = _mm256_sub_pd(xi1, xj1),
                dz = _mm256_sub_pd(xi2, xj2);
        __m256d d2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)),
                                   _mm256_mul_pd(dz, dz));
        unsigned mb = (unsigned)_mm256_movemask_pd(
            _mm256_cmp_pd(d2, _mm256_mul_pd(reach, reach), _CMP_LT_OQ));
        if (i >= j && i < (size_t)j + 4) mb &= ~(1u << (i - j));
        if (!out) {
            count += (uint32_t)__builtin_popcount(mb);
            continue;
        }
        if (room4) {
            /* all four lanes stored, the hits first: no branch per hit */
            __m128i idx = _mm_add_epi32(_mm_set1_epi32((int)j), _mm_setr_epi32(0, 1, 2, 3));
            idx = _mm_shuffle_epi8(idx, _mm_loadu_si128((const __m128i *)compress_lut[mb]));
            _mm_storeu_si128((__m128i *)(void *)(out + count), idx);
            count += (uint32_t)__builtin_popcount(mb);
            continue;
        }
        while (mb) {
            out[count++] = j + (uint32_t)__builtin_ctz(mb);
            mb &= mb - 1;
        }
    }
    return scan_c(s, i, ri, reach_extra, j, e, out, count);
}

/* Eight spheres' single-precision (x, y, z, r0) records, a to d in the
 * low halves and e to h in the high, as x, y, z and r0 of the eight in
 * lanes a, b, c, d, e, f, g, h. */
__attribute__((target("avx2"))) static inline void
transpose8(const float *a, const float *b, const float *c, const float *d, const float *e,
           const float *f, const float *g, const float *h, __m256 out[4]) {
    __m256 p0 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(a)), _mm_load_ps(e), 1);
    __m256 p1 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(b)), _mm_load_ps(f), 1);
    __m256 p2 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(c)), _mm_load_ps(g), 1);
    __m256 p3 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(d)), _mm_load_ps(h), 1);
    __m256 t0 = _mm256_unpacklo_ps(p0, p1), t1 = _mm256_unpackhi_ps(p0, p1);
    __m256 t2 = _mm256_unpacklo_ps(p2, p3), t3 = _mm256_unpackhi_ps(p2, p3);
    out[0] = _mm256_shuffle_ps(t0, t2, 0x44);
    out[1] = _mm256_shuffle_ps(t0, t2, 0xEE);
    out[2] = _mm256_shuffle_ps(t1, t3, 0x44);
    out[3] = _mm256_shuffle_ps(t1, t3, 0xEE);
}

/* x_i - x_j in the fixed point's units, exact, then rounded to float */
__attribute__((target("avx2"))) static inline __m256 q_diff(__m256i xi, __m256 xj) {
    return _mm256_cvtepi32_ps(_mm256_sub_epi32(xi, _mm256_castps_si256(xj)));
}

/* Stores j + the lanes of a 4-bit mask, packed to the front, at out;
 * returns their count (four entries are written). */
__attribute__((target("avx2"))) static inline uint32_t store_hits4(uint32_t *out, uint32_t j,
                                                                   unsigned mb) {
    __m128i idx = _mm_add_epi32(_mm_set1_epi32((int)j), _mm_setr_epi32(0, 1, 2, 3));
    idx = _mm_shuffle_epi8(idx, _mm_loadu_si128((const __m128i *)compress_lut[mb]));
    _mm_storeu_si128((__m128i *)(void *)out, idx);
    return (uint32_t)__builtin_popcount(mb);
}

/* The list test of eight candidates j .. j + 7 (x, y, z in the fixed
 * point, the scaled radius) against sphere i (xi, base = r_i + the reach's
 * extra): the mask of those within reach, lanes from e on and i itself
 * off. Both scans use it, so their lists are the same. */
__attribute__((target("avx2"))) static inline __attribute__((always_inline)) unsigned
q_hits8(size_t i, const __m256i xi[3], __m256 base, __m256i x, __m256i y, __m256i z, __m256 r,
        uint32_t j, uint32_t e) {
    const __m256i lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    __m256 reach = _mm256_add_ps(base, r);
    __m256 dx = _mm256_cvtepi32_ps(_mm256_sub_epi32(xi[0], x)),
           dy = _mm256_cvtepi32_ps(_mm256_sub_epi32(xi[1], y)),
           dz = _mm256_cvtepi32_ps(_mm256_sub_epi32(xi[2], z));
    __m256 d2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
                              _mm256_mul_ps(dz, dz));
    __m256 m = _mm256_cmp_ps(d2, _mm256_mul_ps(reach, reach), _CMP_LT_OQ);
    m = _mm256_and_ps(m, _mm256_castsi256_ps(_mm256_cmpgt_epi32(
                             _mm256_set1_epi32((int)(e - j < 8 ? e - j : 8)), lanes)));
    unsigned mb = (unsigned)_mm256_movemask_ps(m);
    if (i >= j && i < (size_t)j + 8) mb &= ~(1u << (i - j));
    return mb;
}

/* scan_q_c, eight candidates at a time; the last group's lanes past e are
 * off (xq holds eight records of zeros past n for their loads). */
__attribute__((target("avx2"))) static uint32_t scan_q_avx2(const jam *s, size_t i, float base,
                                                            uint32_t a, uint32_t e, uint32_t *out,
                                                            uint32_t count, int room4) {
    const int32_t *xi = s->xq + 4 * i;
    const __m256i vxi[3] = {_mm256_set1_epi32(xi[0]), _mm256_set1_epi32(xi[1]),
                            _mm256_set1_epi32(xi[2])};
    const __m256 vb = _mm256_set1_ps(base);
    for (uint32_t j = a; j < e; j += 8) {
        const float *p = (const float *)(const void *)(s->xq + 4 * (size_t)j);
        __m256 q[4];
        transpose8(p, p + 4, p + 8, p + 12, p + 16, p + 20, p + 24, p + 28, q);
        unsigned mb = q_hits8(i, vxi, vb, _mm256_castps_si256(q[0]), _mm256_castps_si256(q[1]),
                              _mm256_castps_si256(q[2]), q[3], j, e);
        if (!out) {
            count += (uint32_t)__builtin_popcount(mb);
            continue;
        }
        if (room4) {
            count += store_hits4(out + count, j, mb & 15);
            count += store_hits4(out + count, j + 4, mb >> 4);
            continue;
        }
        while (mb) {
            out[count++] = j + (uint32_t)__builtin_ctz(mb);
            mb &= mb - 1;
        }
    }
    return count;
}

/* Sphere i's list from the rows in rb (qrows_hold; i in the middle row),
 * the candidates in cells x0 .. x1 of each: the tests and the order of
 * scan_q_avx2 over those rows, so the same list. mode 0: only counted; 1:
 * written at out; 2: written at out four at a time while room (from out)
 * holds the row's candidates and three more, else counted from there on
 * and *over set. Returns the count. */
__attribute__((target("avx2"))) static uint32_t
scan_rows_q_avx2(const jam *s, const qrows *rb, size_t i, float base, int x0, int x1, uint32_t *out,
                 uint32_t room, int mode, int *over) {
    const int32_t *xi = s->xq + 4 * i;
    const __m256i vxi[3] = {_mm256_set1_epi32(xi[0]), _mm256_set1_epi32(xi[1]),
                            _mm256_set1_epi32(xi[2])};
    const __m256 vb = _mm256_set1_ps(base);
    const size_t st = (size_t)rb->cap + ROWS_PAD;
    const int32_t *X = rb->buf, *Y = X + st, *Z = Y + st;
    const float *R = (const float *)(const void *)(Z + st);
    uint32_t count = 0;
    for (int r = 0; r < rb->nrow; r++) {
        const uint32_t *cs = s->cstart + rb->cell0[r];
        const uint32_t a = cs[x0], e = cs[x1 + 1];
        if (mode == 2 && count + (e - a) + 3 > room) {
            mode = 0;
            *over = 1;
        }
        const uint32_t shift = rb->at[r] - rb->first[r]; /* buffer entry of sphere j: j + shift */
        for (uint32_t j = a; j < e; j += 8) {
            const uint32_t b = j + shift;
            unsigned mb =
                q_hits8(i, vxi, vb, _mm256_loadu_si256((const __m256i *)(const void *)(X + b)),
                        _mm256_loadu_si256((const __m256i *)(const void *)(Y + b)),
                        _mm256_loadu_si256((const __m256i *)(const void *)(Z + b)),
                        _mm256_loadu_ps(R + b), j, e);
            if (mode == 0) {
                count += (uint32_t)__builtin_popcount(mb);
            } else if (mode == 2) {
                count += store_hits4(out + count, j, mb & 15);
                count += store_hits4(out + count, j + 4, mb >> 4);
            } else {
                while (mb) {
                    out[count++] = j + (uint32_t)__builtin_ctz(mb);
                    mb &= mb - 1;
                }
            }
        }
    }
    return count;
}
#endif

typedef struct build_pass {
    jam *s;
    int fill; /* 0: count into off[i + 1]; 1: write nb; 2: both, into the chunk's region */
} build_pass;

static void build_chunk(void *user, size_t ci) {
    build_pass *b = user;
    jam *s = b->s;
    size_t lo, hi;
    chunk_range(s, ci, &lo, &hi);
    const double reach_extra = s->skin + s->gap;
    /* fill 2: the chunk's lists go to nb[reg[ci] ..), est[ci] entries at
     * most (past them it only counts, and the build is done again in two
     * passes); off[i + 1] is the count */
    uint32_t *region = b->fill == 2 ? s->nb + s->reg[ci] : NULL;
    uint32_t room = b->fill == 2 ? s->est[ci] : 0, used = 0;
    int over = 0;
    qrows rb = {.y = -1};
    uint32_t nwall = 0;
    for (size_t i = lo; i < hi; i++) {
        double xi[3];
        centre_of(s, i, xi);
        double ri = s->scale * r0_of(s, i);
        const float base = s->xq ? (float)((ri + reach_extra) / s->qres) : 0.0f;
        int c[3];
        for (int k = 0; k < 3; k++) c[k] = cell_along(s, k, xi[k]);
        uint32_t k_out = b->fill ? s->off[i] : 0, count = 0;
        int rows = 0; /* scanned from rb */
#ifdef VP_JAM_AVX2
        rows = s->xq && s->avx2 && qrows_hold(s, &rb, c[1], c[2]);
        if (rows) {
            int x0 = c[0] > XSPLIT ? c[0] - XSPLIT : 0,
                x1 = c[0] + XSPLIT < s->dims[0] ? c[0] + XSPLIT : s->dims[0] - 1;
            if (b->fill == 1)
                count = scan_rows_q_avx2(s, &rb, i, base, x0, x1, s->nb + k_out, 0, 1, &over);
            else if (region && !over)
                count =
                    scan_rows_q_avx2(s, &rb, i, base, x0, x1, region + used, room - used, 2, &over);
            else count = scan_rows_q_avx2(s, &rb, i, base, x0, x1, NULL, 0, 0, &over);
        }
#endif
        for (int dz = -1; !rows && dz <= 1; dz++) {
            int z = c[2] + dz;
            if (z < 0 || z >= s->dims[2]) continue;
            for (int dy = -1; dy <= 1; dy++) {
                int y = c[1] + dy;
                if (y < 0 || y >= s->dims[1]) continue;
                size_t row = ((size_t)z * s->dims[1] + (size_t)y) * s->dims[0];
                int x0 = c[0] > XSPLIT ? c[0] - XSPLIT : 0,
                    x1 = c[0] + XSPLIT < s->dims[0] ? c[0] + XSPLIT : s->dims[0] - 1;
                uint32_t a = s->cstart[row + (size_t)x0], e = s->cstart[row + (size_t)x1 + 1];
                uint32_t *out = b->fill == 1 ? s->nb + k_out : NULL;
                if (region && !over) {
                    /* room for the row's candidates and three more: its
                     * four-wide stores may write three entries past the hits */
                    if (used + count + (e - a) + 3 > room) over = 1;
                    else out = region + used;
                }
#ifdef VP_JAM_AVX2
                if (s->avx2) {
                    count =
                        s->xq ? scan_q_avx2(s, i, base, a, e, out, count, region != NULL)
                              : scan_avx2(s, i, ri, reach_extra, a, e, out, count, region != NULL);
                    continue;
                }
#endif
                count = s->xq ? scan_q_c(s, i, base, a, e, out, count)
                              : scan_c(s, i, ri, reach_extra, a, e, out, count);
            }
        }
        used += count;
        if (b->fill != 1) {
            s->off[i + 1] = count;
            /* the wall: within reach until a sphere has moved skin / 2 */
            s->near_wall[i] = wall_depth(s, xi, ri) > -s->skin;
            nwall += s->near_wall[i];
            for (int k = 0; k < 3; k++) s->xr[3 * i + k] = (float)xi[k];
        }
    }
    if (b->fill != 1) s->wcount[ci] = nwall;
    free(rb.buf);
    s->tot[ci] = used;
    s->over[ci] = (uint8_t)over;
}

/* The list ends with NB_PAD entries of sphere 0, so that the pair forces
 * may load four (eight, in the quench) entries where fewer are left (the lanes past the end are
 * switched off). */
#define NB_PAD 8

/* After a build: each chunk's first slot of kept wall directions, none
 * kept yet. 0, or -1 (out of memory). */
static int wall_slots(jam *s) {
    size_t total = 0;
    for (size_t c = 0; c < s->nchunk; c++) {
        s->wbase[c] = (uint32_t)total;
        total += s->wcount[c];
    }
    if (total > s->wdir_cap || total < s->wdir_cap / 2) {
        size_t cap = total + total / 8 + 16;
        float *w = realloc(s->wdir, 6 * cap * sizeof *w);
        if (!w) return -1;
        s->wdir = w;
        s->wdir_cap = cap;
    }
    for (size_t k = 0; k < 6 * total; k++) s->wdir[k] = NAN;
    return 0;
}

/* Sorts the spheres by cell and builds the list: 0, or -1 (out of memory).
 * After the first build, in one pass (each chunk into a region sized from
 * its last list, the regions then closed up); in two (count, then write)
 * the first time and when a chunk's list outgrew its region. Either way
 * the same list. */
static int build_list(jam *s, int threads) {
    if (2 * s->scale * s->r0max + s->skin > s->cell &&
        grid_init(s, 2 * s->scale * s->r0max + s->skin) != 0)
        return -1;
    s->s_build = s->scale;
    s->swap_grow = 0;
    s->far_seen = 0;
    if (sort_by_cell(s, threads) != 0) return -1;
    build_pass b = {s, 2};
    s->off[0] = 0;
    if (s->have_tot) {
        /* one pass: each chunk writes its lists to a region the size of
         * its last list and a thirty-second more, then the regions close up */
        size_t want = 0;
        for (size_t c = 0; c < s->nchunk; c++) {
            s->reg[c] = (uint32_t)want;
            s->est[c] = s->tot[c] + s->tot[c] / 32 + 24;
            want += s->est[c];
        }
        want += NB_PAD;
        if (want > s->nb_cap || want < s->nb_cap / 2) {
            uint32_t *nb = realloc(s->nb, want * sizeof *nb);
            if (!nb) return -1;
            s->nb = nb;
            s->nb_cap = want;
        }
        vp_parallel_for(threads, s->nchunk, build_chunk, &b);
        int over = 0;
        for (size_t c = 0; c < s->nchunk; c++) over |= s->over[c];
        if (!over) {
            size_t at = 0;
            for (size_t c = 0; c < s->nchunk; c++) {
                if (at != s->reg[c])
                    memmove(s->nb + at, s->nb + s->reg[c], s->tot[c] * sizeof *s->nb);
                at += s->tot[c];
            }
            memset(s->nb + at, 0, NB_PAD * sizeof *s->nb);
            for (size_t i = 0; i < s->n; i++) s->off[i + 1] += s->off[i];
            return wall_slots(s);
        }
    }
    /* two passes: count, then write */
    b.fill = 0;
    vp_parallel_for(threads, s->nchunk, build_chunk, &b);
    for (size_t i = 0; i < s->n; i++) s->off[i + 1] += s->off[i];
    size_t total = s->off[s->n];
    if (total + NB_PAD > s->nb_cap || total < s->nb_cap / 2) {
        /* grown with a sixteenth to spare; shrunk after the quench's wide skin */
        size_t cap = total + total / 16 + 64;
        uint32_t *nb = realloc(s->nb, cap * sizeof *nb);
        if (!nb) return -1;
        s->nb = nb;
        s->nb_cap = cap;
    }
    b.fill = 1;
    vp_parallel_for(threads, s->nchunk, build_chunk, &b);
    memset(s->nb + total, 0, NB_PAD * sizeof *s->nb);
    s->have_tot = 1;
    return wall_slots(s);
}

/* ---- forces and the FIRE step -------------------------------------------- */

/* The pair forces on sphere i from its list, four list entries at a time
 * in four lanes whose sums are added as (l0 + l1) + (l2 + l3): out = force
 * x, y, z, energy (a quarter of overlap^2 per entry: each pair is in both
 * lists), dU/dscale (half of overlap (r0_i + r0_j) per entry). The
 * portable form below and the AVX2 form do the same arithmetic in the
 * same order (no FMA), so the packing does not depend on the processor. */
typedef struct pair_sum {
    double f[3], e, duds;
} pair_sum;

static void lanes_add(const double l[5][4], pair_sum *o) {
    o->f[0] = (l[0][0] + l[0][1]) + (l[0][2] + l[0][3]);
    o->f[1] = (l[1][0] + l[1][1]) + (l[1][2] + l[1][3]);
    o->f[2] = (l[2][0] + l[2][1]) + (l[2][2] + l[2][3]);
    o->e = (l[3][0] + l[3][1]) + (l[3][2] + l[3][3]);
    o->duds = (l[4][0] + l[4][1]) + (l[4][2] + l[4][3]);
}

/* One lane's entry: j (the neighbour) or, past the list's end, nothing. */
static void lane_entry(const jam *s, size_t i, uint32_t j, double l[5][4], int lane) {
    const double *xi = s->x + 4 * i, *xj = s->x + 4 * (size_t)j;
    const double sc = s->scale;
    double sij = (sc * R0(s, i) + s->gap) + sc * R0(s, j);
    double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
    double d2 = dx * dx + dy * dy + dz * dz;
    if (!(d2 < sij * sij)) return;
    double d = sqrt(d2);
    double dl = sij - d;
    if (d > 0) {
        double g = dl / d;
        l[0][lane] += g * dx;
        l[1][lane] += g * dy;
        l[2][lane] += g * dz;
    } else {
        l[0][lane] += i < j ? dl : -dl; /* coincident centres: apart along x */
    }
    l[3][lane] += 0.25 * (dl * dl);
    l[4][lane] += 0.5 * (dl * (R0(s, i) + R0(s, j)));
}

static void pair_forces_c(const jam *s, size_t i, pair_sum *o) {
    double l[5][4];
    memset(l, 0, sizeof l);
    uint32_t k = s->off[i], e = s->off[i + 1];
    for (; k < e; k++) lane_entry(s, i, s->nb[k], l, (int)((k - s->off[i]) & 3));
    lanes_add(l, o);
}

#ifdef VP_JAM_AVX2
/* The AVX2 form of pair_forces_c: out = fx, fy, fz, energy, and *duds; 1
 * (nothing out) where two centres coincide, for the portable form. The
 * lanes are added as lanes_add does, by horizontal additions. */
__attribute__((target("avx2"))) static inline __attribute__((always_inline)) int
pair_forces_avx2(const jam *s, size_t i, __m256d *out, double *duds) {
    const double *xi = s->x + 4 * i;
    const double sc = s->scale;
    const __m256d xi0 = _mm256_set1_pd(xi[0]), xi1 = _mm256_set1_pd(xi[1]),
                  xi2 = _mm256_set1_pd(xi[2]);
    const __m256d vsc = _mm256_set1_pd(sc), ri = _mm256_set1_pd(sc * R0(s, i) + s->gap),
                  r0i = _mm256_set1_pd(R0(s, i)), quarter = _mm256_set1_pd(0.25),
                  half = _mm256_set1_pd(0.5), zero = _mm256_setzero_pd();
    __m256d ax = zero, ay = zero, az = zero, ae = zero, as = zero;
    uint32_t k0 = s->off[i], e = s->off[i + 1];
    for (uint32_t k = k0; k < e; k += 4) {
        int live = (int)(e - k < 4 ? e - k : 4);
        /* four spheres' (x, y, z, r0), transposed to x, y, z, r0 of four */
        /* past the list's end: the next spheres' entries, or NB_PAD */
        __m256d q[4];
        transpose4(_mm256_load_pd(s->x + 4 * (size_t)s->nb[k]),
                   _mm256_load_pd(s->x + 4 * (size_t)s->nb[k + 1]),
                   _mm256_load_pd(s->x + 4 * (size_t)s->nb[k + 2]),
                   _mm256_load_pd(s->x + 4 * (size_t)s->nb[k + 3]), q);
        const __m256d xj0 = q[0], xj1 = q[1], xj2 = q[2], r0j = q[3];
        __m256d sij = _mm256_add_pd(ri, _mm256_mul_pd(vsc, r0j));
        __m256d dx = _mm256_sub_pd(xi0, xj0), dy = _mm256_sub_pd(xi1, xj1),
                dz = _mm256_sub_pd(xi2, xj2);
        __m256d d2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)),
                                   _mm256_mul_pd(dz, dz));
        __m256d m = _mm256_cmp_pd(d2, _mm256_mul_pd(sij, sij), _CMP_LT_OQ);
        /* lanes past the end: off */
        const __m256i lanes = _mm256_set_epi64x(3, 2, 1, 0);
        __m256d on = _mm256_castsi256_pd(_mm256_cmpgt_epi64(_mm256_set1_epi64x(live), lanes));
        m = _mm256_and_pd(m, on);
        int mb = _mm256_movemask_pd(m);
        if (!mb) continue;
        if (_mm256_movemask_pd(_mm256_and_pd(m, _mm256_cmp_pd(d2, zero, _CMP_EQ_OQ))))
            return 1; /* coincident centres: the portable form */
        __m256d d = _mm256_sqrt_pd(d2);
        __m256d dl = _mm256_and_pd(_mm256_sub_pd(sij, d), m);
        __m256d g = _mm256_div_pd(dl, _mm256_blendv_pd(_mm256_set1_pd(1.0), d, m));
        ax = _mm256_add_pd(ax, _mm256_mul_pd(g, dx));
        ay = _mm256_add_pd(ay, _mm256_mul_pd(g, dy));
        az = _mm256_add_pd(az, _mm256_mul_pd(g, dz));
        ae = _mm256_add_pd(ae, _mm256_mul_pd(quarter, _mm256_mul_pd(dl, dl)));
        as = _mm256_add_pd(as, _mm256_mul_pd(half, _mm256_mul_pd(dl, _mm256_add_pd(r0i, r0j))));
    }
    /* (l0 + l1) + (l2 + l3) of each, as lanes_add */
    const __m256d h1 = _mm256_hadd_pd(ax, ay), h2 = _mm256_hadd_pd(az, ae);
    *out =
        _mm256_add_pd(_mm256_permute2f128_pd(h1, h2, 0x20), _mm256_permute2f128_pd(h1, h2, 0x31));
    const __m256d hs = _mm256_hadd_pd(as, as);
    *duds = _mm_cvtsd_f64(_mm_add_sd(_mm256_castpd256_pd128(hs), _mm256_extractf128_pd(hs, 1)));
    return 0;
}
#endif

/* The quench's pair forces, in its units and single precision (float sums
 * in eight lanes, entry k in lane k mod 8, added as ((l0 + l1) + (l2 +
 * l3)) + ((l4 + l5) + (l6 + l7))): otherwise as pair_forces_c, but for
 * dU/dscale, which the quench does not use (0). The differences of
 * positions are exact in the fixed point, then rounded to float: about
 * 1e-7 of a diameter. Forces out in the fixed point's units (force_chunk
 * scales them). */
static inline float lanes8_add(const float l[8]) {
    return ((l[0] + l[1]) + (l[2] + l[3])) + ((l[4] + l[5]) + (l[6] + l[7]));
}

static inline void lanes8_out(const float l[5][8], pair_sum *o) {
    for (int k = 0; k < 3; k++) o->f[k] = lanes8_add(l[k]);
    o->e = lanes8_add(l[3]);
    o->duds = lanes8_add(l[4]);
}

static void pair_forces_q_c(const jam *s, size_t i, pair_sum *o) {
    float l[5][8];
    memset(l, 0, sizeof l);
    const int32_t *xi = s->xq + 4 * i;
    const float ri = q_radius(s, i) + (float)(s->gap / s->qres);
    uint32_t k0 = s->off[i], e = s->off[i + 1];
    for (uint32_t k = k0; k < e; k++) {
        uint32_t j = s->nb[k];
        int lane = (int)((k - k0) & 7);
        const int32_t *xj = s->xq + 4 * (size_t)j;
        float sij = ri + q_radius(s, j);
        float dx = (float)(xi[0] - xj[0]), dy = (float)(xi[1] - xj[1]), dz = (float)(xi[2] - xj[2]);
        float d2 = (dx * dx + dy * dy) + dz * dz;
        if (!(d2 < sij * sij)) continue;
        float d = sqrtf(d2), dl = sij - d;
        if (d > 0) {
            float g = dl / d;
            l[0][lane] += g * dx;
            l[1][lane] += g * dy;
            l[2][lane] += g * dz;
        } else {
            l[0][lane] += i < j ? dl : -dl; /* coincident centres: apart along x */
        }
        l[3][lane] += 0.25f * (dl * dl);
    }
    lanes8_out(l, o);
}

#ifdef VP_JAM_AVX2
/* The AVX2 form of pair_forces_q_c: out = fx, fy, fz, energy (float lane
 * sums, added as lanes8_add does, by horizontal additions); 1 (nothing out)
 * where two centres coincide, for the portable form. */
__attribute__((target("avx2"))) static inline __attribute__((always_inline)) int
pair_forces_q_avx2(const jam *s, size_t i, float gap_q, __m128 *out) {
    const int32_t *xi = s->xq + 4 * i;
    const __m256i xi0 = _mm256_set1_epi32(xi[0]), xi1 = _mm256_set1_epi32(xi[1]),
                  xi2 = _mm256_set1_epi32(xi[2]);
    const __m256 ri = _mm256_set1_ps(q_radius(s, i) + gap_q), quarter = _mm256_set1_ps(0.25f),
                 one = _mm256_set1_ps(1.0f), zero = _mm256_setzero_ps();
    const __m256i lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    __m256 ax = zero, ay = zero, az = zero, ae = zero;
    uint32_t k0 = s->off[i], e = s->off[i + 1];
    for (uint32_t k = k0; k < e; k += 8) {
        /* past the list's end: the next spheres' entries, or NB_PAD */
        const uint32_t *J = s->nb + k;
        const float *p = (const float *)(const void *)s->xq;
        __m256 q[4];
        transpose8(p + 4 * (size_t)J[0], p + 4 * (size_t)J[1], p + 4 * (size_t)J[2],
                   p + 4 * (size_t)J[3], p + 4 * (size_t)J[4], p + 4 * (size_t)J[5],
                   p + 4 * (size_t)J[6], p + 4 * (size_t)J[7], q);
        __m256 sij = _mm256_add_ps(ri, q[3]);
        __m256 dx = q_diff(xi0, q[0]), dy = q_diff(xi1, q[1]), dz = q_diff(xi2, q[2]);
        __m256 d2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
                                  _mm256_mul_ps(dz, dz));
        __m256 m = _mm256_cmp_ps(d2, _mm256_mul_ps(sij, sij), _CMP_LT_OQ);
        m = _mm256_and_ps(m, _mm256_castsi256_ps(_mm256_cmpgt_epi32(
                                 _mm256_set1_epi32((int)(e - k < 8 ? e - k : 8)), lanes)));
        if (!_mm256_movemask_ps(m)) continue;
        if (_mm256_movemask_ps(_mm256_and_ps(m, _mm256_cmp_ps(d2, zero, _CMP_EQ_OQ))))
            return 1; /* coincident centres: the portable form */
        __m256 d = _mm256_sqrt_ps(d2);
        __m256 dl = _mm256_and_ps(_mm256_sub_ps(sij, d), m);
        __m256 g = _mm256_div_ps(dl, _mm256_blendv_ps(one, d, m));
        ax = _mm256_add_ps(ax, _mm256_mul_ps(g, dx));
        ay = _mm256_add_ps(ay, _mm256_mul_ps(g, dy));
        az = _mm256_add_ps(az, _mm256_mul_ps(g, dz));
        ae = _mm256_add_ps(ae, _mm256_mul_ps(quarter, _mm256_mul_ps(dl, dl)));
    }
    /* ((l0 + l1) + (l2 + l3)) + ((l4 + l5) + (l6 + l7)) of each */
    const __m256 h = _mm256_hadd_ps(_mm256_hadd_ps(ax, ay), _mm256_hadd_ps(az, ae));
    *out = _mm_add_ps(_mm256_castps256_ps128(h), _mm256_extractf128_ps(h, 1));
    return 0;
}
#endif

/* The wall's force and energy on sphere i (near it, its kept direction in
 * slot), added to f (x, y, z), *e and *duds. */
static void wall_force(const jam *s, size_t i, float *slot, double f[3], double *e, double *duds) {
    const double r0i = r0_of(s, i), ri = s->scale * r0i;
    double g[3], xi[3];
    centre_of(s, i, xi);
    double w = wall_kept(s, xi, ri, g, slot);
    if (w > 0) {
        f[0] -= w * g[0];
        f[1] -= w * g[1];
        f[2] -= w * g[2];
        *e += 0.5 * w * w;
        if (s->fit == VP_FIT_INSIDE) *duds += w * r0i;
    }
}

#ifdef VP_JAM_AVX2
/* force_chunk's loop for the spheres [lo, hi) with the AVX2 kernels inlined:
 * the same arithmetic in the same order. out: energy, F.v, F.F, v.v,
 * dU/dscale. */
__attribute__((target("avx2"))) static void force_range_avx2(jam *s, size_t lo, size_t hi,
                                                             float *slot, double out[5]) {
    double e = 0, fv = 0, ff = 0, vv = 0, duds = 0;
    const __m256d qs = _mm256_set_pd(s->qres * s->qres, s->qres, s->qres, s->qres);
    const __m128i m3 = _mm_setr_epi32(-1, -1, -1, 0);
    const float gap_q = s->xq ? (float)(s->gap / s->qres) : 0.0f;
    for (size_t i = lo; i < hi; i++) {
        __m256d F; /* fx, fy, fz, energy */
        if (s->xq) {
            __m128 q;
            if (!pair_forces_q_avx2(s, i, gap_q, &q)) {
                F = _mm256_mul_pd(_mm256_cvtps_pd(q), qs);
            } else {
                pair_sum ps;
                _mm256_zeroupper();
                pair_forces_q_c(s, i, &ps);
                F = _mm256_mul_pd(_mm256_setr_pd(ps.f[0], ps.f[1], ps.f[2], ps.e), qs);
            }
            /* no dU/dscale in the quench */
        } else {
            double d;
            if (pair_forces_avx2(s, i, &F, &d)) {
                pair_sum ps;
                _mm256_zeroupper();
                pair_forces_c(s, i, &ps);
                F = _mm256_setr_pd(ps.f[0], ps.f[1], ps.f[2], ps.e);
                d = ps.duds;
            }
            duds += d;
        }
        const __m128d fz_e = _mm256_extractf128_pd(F, 1);
        e += _mm_cvtsd_f64(_mm_unpackhi_pd(fz_e, fz_e));
        if (s->near_wall[i]) {
            double f[3];
            _mm_storeu_pd(f, _mm256_castpd256_pd128(F));
            f[2] = _mm_cvtsd_f64(fz_e);
            _mm256_zeroupper();
            wall_force(s, i, slot, f, &e, &duds);
            slot += 6;
            F = _mm256_setr_pd(f[0], f[1], f[2], 0.0);
        } else {
            F = _mm256_blend_pd(F, _mm256_setzero_pd(), 0x8);
        }
        /* whole four floats but for the range's last sphere: the fourth
         * lane is the next sphere's, written or read in its turn (a masked
         * store is slow on some processors, such as AMD's Zen 3) */
        const __m128 F4 = _mm256_cvtpd_ps(F);
        __m128 V4;
        if (i + 1 < hi) {
            _mm_storeu_ps(s->f + 3 * i, F4);
            V4 = _mm_and_ps(_mm_loadu_ps(s->v + 3 * i), _mm_castsi128_ps(m3));
        } else {
            _mm_maskstore_ps(s->f + 3 * i, m3, F4);
            V4 = _mm_maskload_ps(s->v + 3 * i, m3);
        }
        const __m256d V = _mm256_cvtps_pd(V4);
        /* (p0 + p1) + p2 of F.v, F.F and v.v (the fourth lanes 0) */
        const __m256d h = _mm256_hadd_pd(_mm256_mul_pd(F, V), _mm256_mul_pd(F, F));
        const __m128d t = _mm_add_pd(_mm256_castpd256_pd128(h), _mm256_extractf128_pd(h, 1));
        const __m256d hv = _mm256_hadd_pd(_mm256_mul_pd(V, V), _mm256_mul_pd(V, V));
        const __m128d tv = _mm_add_pd(_mm256_castpd256_pd128(hv), _mm256_extractf128_pd(hv, 1));
        fv += _mm_cvtsd_f64(t);
        ff += _mm_cvtsd_f64(_mm_unpackhi_pd(t, t));
        vv += _mm_cvtsd_f64(tv);
    }
    out[0] = e;
    out[1] = fv;
    out[2] = ff;
    out[3] = vv;
    out[4] = duds;
}
#endif

static void force_chunk(void *user, size_t ci) {
    jam *s = user;
    size_t lo, hi;
    chunk_range(s, ci, &lo, &hi);
    float *slot = s->wdir + 6 * (size_t)s->wbase[ci];
#ifdef VP_JAM_AVX2
    if (s->avx2) {
        double o[5];
        force_range_avx2(s, lo, hi, slot, o);
        s->sum[ci][0] = o[0];
        s->sum[ci][1] = o[1];
        s->sum[ci][2] = o[2];
        s->sum[ci][3] = o[3];
        s->sum[ci][6] = o[4];
        return;
    }
#endif
    double e = 0, fv = 0, ff = 0, vv = 0, duds = 0;
    for (size_t i = lo; i < hi; i++) {
        pair_sum ps;
        if (s->xq) {
            pair_forces_q_c(s, i, &ps);
            for (int k = 0; k < 3; k++) ps.f[k] *= s->qres;
            ps.e *= s->qres * s->qres;
        } else {
            pair_forces_c(s, i, &ps);
        }
        double f[3] = {ps.f[0], ps.f[1], ps.f[2]};
        e += ps.e;
        duds += ps.duds;
        if (s->near_wall[i]) {
            wall_force(s, i, slot, f, &e, &duds);
            slot += 6;
        }
        float *fi = s->f + 3 * i;
        const float *vi = s->v + 3 * i;
        fi[0] = (float)f[0];
        fi[1] = (float)f[1];
        fi[2] = (float)f[2];
        fv += f[0] * vi[0] + f[1] * vi[1] + f[2] * vi[2];
        ff += f[0] * f[0] + f[1] * f[1] + f[2] * f[2];
        vv += (double)vi[0] * vi[0] + (double)vi[1] * vi[1] + (double)vi[2] * vi[2];
    }
    s->sum[ci][0] = e;
    s->sum[ci][1] = fv;
    s->sum[ci][2] = ff;
    s->sum[ci][3] = vv;
    s->sum[ci][6] = duds;
}

/* One sphere's FIRE move: v <- (1 - alpha) v + vscale F (or 0), v += dt F,
 * x += dt v (in the quench, the move rounded to the fixed point's unit).
 * Returns its squared displacement since the list's build. */
static double move_one_c(jam *s, size_t i, double a, double b, double dt) {
    float *vi = s->v + 3 * i;
    const float *fi = s->f + 3 * i;
    const float *xr = s->xr + 3 * i;
    double d2 = 0;
    for (int k = 0; k < 3; k++) {
        double v = s->zero_v ? 0.0 : a * vi[k] + b * fi[k];
        v += dt * fi[k];
        vi[k] = (float)v;
        double x;
        if (s->xq) {
            /* the move rounded to the fixed point's unit */
            int32_t *q = s->xq + 4 * i + k;
            int64_t m = (int64_t)*q + q_round(dt * v * s->qinv);
            *q = m > Q_MAX ? Q_MAX : m < -Q_MAX ? -Q_MAX : (int32_t)m;
            x = s->qc[k] + s->qres * (double)*q;
        } else {
            x = s->x[4 * i + k] += dt * v;
        }
        double d = x - xr[k];
        d2 += d * d;
    }
    return d2;
}

/* A chunk's displacements since the list's build, as its spheres move:
 * the two largest (squared) and the spheres past the half of the skin
 * the list has left (the far ones, which maybe_rebuild checks against
 * their neighbours). */
typedef struct disp_track {
    double dmax, dmax2, far2; /* far2: the far ones' squared displacement */
    uint32_t *far;            /* FAR_CAP entries, owned by the jam */
    uint32_t nfar;            /* may pass FAR_CAP: then not all are held */
} disp_track;

static inline void track(disp_track *t, size_t i, double d2) {
    if (d2 > t->dmax2) {
        t->dmax2 = d2 > t->dmax ? t->dmax : d2;
        if (d2 > t->dmax) t->dmax = d2;
    }
    if (d2 > t->far2) {
        if (t->nfar < FAR_CAP) t->far[t->nfar] = (uint32_t)i;
        t->nfar++;
    }
}

#ifdef VP_JAM_AVX2
/* Four spheres' three floats (twelve, as loaded: a = x0 y0 z0 x1, b = y1 z1
 * x2 y2, c = z2 x3 y3 z3) one sphere a register, x y z and 0. */
__attribute__((target("avx2"))) static inline void split3(__m128 a, __m128 b, __m128 c,
                                                          __m128 out[4]) {
    const __m128 m3 = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
    const __m128i ai = _mm_castps_si128(a), bi = _mm_castps_si128(b), ci = _mm_castps_si128(c);
    out[0] = _mm_and_ps(a, m3);
    out[1] = _mm_and_ps(_mm_castsi128_ps(_mm_alignr_epi8(bi, ai, 12)), m3);
    out[2] = _mm_and_ps(_mm_castsi128_ps(_mm_alignr_epi8(ci, bi, 8)), m3);
    out[3] = _mm_castsi128_ps(_mm_srli_si128(ci, 4));
}

/* and back: four spheres' x y z (the fourth lane ignored) as twelve floats */
__attribute__((target("avx2"))) static inline void join3(const __m128 p[4], float *out) {
    _mm_storeu_ps(out, _mm_blend_ps(p[0], _mm_permute_ps(p[1], 0x00), 0x8));
    _mm_storeu_ps(out + 4, _mm_shuffle_ps(p[1], p[2], _MM_SHUFFLE(1, 0, 2, 1)));
    _mm_storeu_ps(out + 8, _mm_blend_ps(_mm_permute_ps(p[3], _MM_SHUFFLE(2, 1, 0, 0)),
                                        _mm_permute_ps(p[2], _MM_SHUFFLE(2, 2, 2, 2)), 0x1));
}

/* move_one_c for the spheres [lo, hi), four at a time, each one's three
 * components in three lanes of four (the fourth 0): the same double
 * arithmetic in the same order (no FMA), so the same packing; whole
 * 48-byte groups of v, f and xr are loaded and stored (a masked store
 * would stall the next sphere's load). In the fixed point, the lanes'
 * 32-bit sums cannot overflow while |move| < 2^29 units and |position| <=
 * 2^30; a group outside that (never seen), and the last spheres of the
 * range short of four, move by move_one_c. */
__attribute__((target("avx2"))) static void move_range_avx2(jam *s, size_t lo, size_t hi, double a,
                                                            double b, double dt, disp_track *t) {
    const __m256d va = _mm256_set1_pd(a), vb = _mm256_set1_pd(b), vdt = _mm256_set1_pd(dt);
    const int zero_v = s->zero_v;
    int32_t *const xq = s->xq;
    double *const xd = s->x;
    float *const vel = s->v;
    const float *const force = s->f, *const xr = s->xr;
    const __m256d qinv = _mm256_set1_pd(s->qinv), qres = _mm256_set1_pd(s->qres),
                  qc = _mm256_set_pd(0.0, s->qc[2], s->qc[1], s->qc[0]),
                  umax = _mm256_set1_pd(536870912.0), sign = _mm256_set1_pd(-0.0);
    const __m128i qmax = _mm_set1_epi32(1 << 30), m3 = _mm_setr_epi32(-1, -1, -1, 0);
    size_t i = lo;
    for (; i + 4 <= hi; i += 4) {
        __m128 vk[4], fk[4], rk[4];
        split3(_mm_loadu_ps(vel + 3 * i), _mm_loadu_ps(vel + 3 * i + 4),
               _mm_loadu_ps(vel + 3 * i + 8), vk);
        split3(_mm_loadu_ps(force + 3 * i), _mm_loadu_ps(force + 3 * i + 4),
               _mm_loadu_ps(force + 3 * i + 8), fk);
        split3(_mm_loadu_ps(xr + 3 * i), _mm_loadu_ps(xr + 3 * i + 4), _mm_loadu_ps(xr + 3 * i + 8),
               rk);
        __m256d v[4];
        for (int k = 0; k < 4; k++) {
            const __m256d f = _mm256_cvtps_pd(fk[k]);
            __m256d w = zero_v ? _mm256_setzero_pd()
                               : _mm256_add_pd(_mm256_mul_pd(va, _mm256_cvtps_pd(vk[k])),
                                               _mm256_mul_pd(vb, f));
            v[k] = _mm256_add_pd(w, _mm256_mul_pd(vdt, f));
        }
        __m256d x[4];
        if (xq) {
            /* rounded as q_round: the processor's rounding, half to even */
            __m256d u[4];
            __m128i qi[4];
            int bad = 0;
            for (int k = 0; k < 4; k++) {
                u[k] = _mm256_mul_pd(_mm256_mul_pd(vdt, v[k]), qinv);
                qi[k] = _mm_load_si128((const __m128i *)(const void *)(xq + 4 * (i + k)));
                bad |= _mm256_movemask_pd(
                           _mm256_cmp_pd(_mm256_andnot_pd(sign, u[k]), umax, _CMP_NLT_UQ)) |
                       (_mm_movemask_epi8(_mm_cmpgt_epi32(_mm_abs_epi32(qi[k]), qmax)) & 0xfff);
            }
            if (bad) {
                _mm256_zeroupper(); /* into legacy SSE code */
                for (int k = 0; k < 4; k++) track(t, i + k, move_one_c(s, i + k, a, b, dt));
                continue;
            }
            for (int k = 0; k < 4; k++) {
                qi[k] = _mm_add_epi32(qi[k], _mm_and_si128(_mm256_cvtpd_epi32(u[k]), m3));
                _mm_store_si128((__m128i *)(void *)(xq + 4 * (i + k)), qi[k]);
                x[k] = _mm256_add_pd(qc, _mm256_mul_pd(qres, _mm256_cvtepi32_pd(qi[k])));
            }
        } else {
            /* the fourth lane adds 0 to r0 */
            for (int k = 0; k < 4; k++) {
                double *p = xd + 4 * (i + k);
                x[k] = _mm256_add_pd(_mm256_load_pd(p), _mm256_mul_pd(vdt, v[k]));
                _mm256_store_pd(p, x[k]);
            }
        }
        __m128 vf[4];
        for (int k = 0; k < 4; k++) {
            vf[k] = _mm256_cvtpd_ps(v[k]);
            const __m256d d = _mm256_sub_pd(x[k], _mm256_cvtps_pd(rk[k]));
            const __m256d d2 = _mm256_mul_pd(d, d);
            const __m128d l = _mm256_castpd256_pd128(d2), h = _mm256_extractf128_pd(d2, 1);
            track(t, i + k, _mm_cvtsd_f64(_mm_add_sd(_mm_add_sd(l, _mm_unpackhi_pd(l, l)), h)));
        }
        join3(vf, vel + 3 * i);
    }
    _mm256_zeroupper(); /* into legacy SSE code */
    for (; i < hi; i++) track(t, i, move_one_c(s, i, a, b, dt));
}
#endif

static void move_chunk(void *user, size_t ci) {
    jam *s = user;
    size_t lo, hi;
    chunk_range(s, ci, &lo, &hi);
    const double dt = s->dt, a = 1.0 - s->alpha, b = s->vscale;
    disp_track t = {0, 0, s->far2, s->far + ci * FAR_CAP, 0};
#ifdef VP_JAM_AVX2
    if (s->avx2) move_range_avx2(s, lo, hi, a, b, dt, &t);
    else
#endif
        for (size_t i = lo; i < hi; i++) track(&t, i, move_one_c(s, i, a, b, dt));
    s->sum[ci][4] = t.dmax;
    s->sum[ci][5] = t.dmax2;
    s->nfar[ci] = t.nfar;
}

typedef struct sums {
    double e, fv, ff, vv, disp2[2], duds;
} sums;

static sums add_up(const jam *s, int col_max4) {
    sums t = {0, 0, 0, 0, {0, 0}, 0};
    for (size_t c = 0; c < s->nchunk; c++) {
        t.e += s->sum[c][0];
        t.fv += s->sum[c][1];
        t.ff += s->sum[c][2];
        t.vv += s->sum[c][3];
        t.duds += s->sum[c][6];
        for (int k = 4; col_max4 && k < 6; k++) {
            double d2 = s->sum[c][k];
            if (d2 > t.disp2[1]) {
                t.disp2[1] = d2 > t.disp2[0] ? t.disp2[0] : d2;
                if (d2 > t.disp2[0]) t.disp2[0] = d2;
            }
        }
    }
    return t;
}

/* ---- radius swaps (polydisperse packings) ---------------------------------- */

/* The energy of sphere i's pairs (but the one with `other`, which a swap
 * leaves as it is) and of its wall, with its unscaled radius a (e[0]) and
 * b (e[1]); dwall is the container's distance at its centre. */
static void swap_energies(const jam *s, size_t i, uint32_t other, double a, double b, double dwall,
                          double e[2]) {
    double xi[3];
    centre_of(s, i, xi);
    const double sc = s->scale, ra = sc * a + s->gap, rb = sc * b + s->gap;
    double ea = 0, eb = 0;
    for (uint32_t k = s->off[i]; k < s->off[i + 1]; k++) {
        uint32_t j = s->nb[k];
        if (j == other) continue;
        double xj[3], r0j = r0_of(s, j);
        centre_of(s, j, xj);
        double sa = ra + sc * r0j, sb = rb + sc * r0j, sm = sa > sb ? sa : sb;
        double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
        double d2 = dx * dx + dy * dy + dz * dz;
        if (!(d2 < sm * sm)) continue;
        double d = sqrt(d2);
        if (sa > d) ea += 0.5 * (sa - d) * (sa - d);
        if (sb > d) eb += 0.5 * (sb - d) * (sb - d);
    }
    if (s->near_wall[i] && s->fit == VP_FIT_INSIDE) {
        double wa = dwall + sc * a + s->margin, wb = dwall + sc * b + s->margin;
        if (wa > 0) ea += 0.5 * wa * wa;
        if (wb > 0) eb += 0.5 * wb * wb;
    }
    e[0] = ea;
    e[1] = eb;
}

static double centre_distance(const jam *s, size_t i) {
    if (!s->near_wall[i]) return 0.0;
    double x[3];
    centre_of(s, i, x);
    return vp_container_distance(s->c, x);
}

/* One pass over the pairs of a list just built (no sphere has moved since),
 * in sphere order on one thread: neighbours i < j trade radii where that
 * lowers U, each sphere at most once a pass and by at most SWAP_REACH of
 * the skin, so that the list still holds every pair within reach of the
 * new radii (each pair's sum grows by at most the skin) and the next
 * rebuild counts the change. The radii stay the ones drawn, in another
 * order: the distribution is kept exactly. 0, or -1 (out of memory). */
static int swap_radii(jam *s) {
    uint8_t *done = calloc(s->n, 1);
    if (!done) return -1;
    const double sc = s->scale, reach = SWAP_REACH * s->skin;
    double grown = 0;
    for (size_t i = 0; i < s->n; i++) {
        double wi = centre_distance(s, i);
        for (uint32_t k = s->off[i]; k < s->off[i + 1] && !done[i]; k++) {
            uint32_t j = s->nb[k];
            double a = r0_of(s, i), b = r0_of(s, j), dr = sc * fabs(a - b);
            if (j <= i || done[j] || !(dr > 0) || dr > reach) continue;
            double ei[2], ej[2];
            swap_energies(s, i, j, a, b, wi, ei);
            swap_energies(s, j, (uint32_t)i, b, a, centre_distance(s, j), ej);
            if (!(ei[1] + ej[1] < ei[0] + ej[0])) continue;
            set_r0(s, i, b);
            set_r0(s, j, a);
            done[i] = done[j] = 1;
            if (dr > grown) grown = dr;
        }
    }
    free(done);
    s->swap_grow += 2.0 * grown;
    return 0;
}

/* Calls visit(s, i, j, user) for every sphere j != i whose build
 * position's cell lies within R of sphere i's build position on each
 * axis, until one returns non-zero; returns that (else 0). */
typedef int (*pair_visit)(const jam *s, size_t i, uint32_t j, void *user);

/* The same for any point p (i: a sphere not to visit, or n). */
static int visit_near_point(const jam *s, size_t i, const double p[3], double R, pair_visit visit,
                            void *user) {
    int c0[3], c1[3];
    for (int k = 0; k < 3; k++) {
        c0[k] = cell_along(s, k, p[k] - R);
        c1[k] = cell_along(s, k, p[k] + R);
    }
    for (int z = c0[2]; z <= c1[2]; z++)
        for (int y = c0[1]; y <= c1[1]; y++) {
            size_t row = ((size_t)z * s->dims[1] + (size_t)y) * s->dims[0];
            uint32_t e = s->cstart[row + (size_t)c1[0] + 1];
            for (uint32_t j = s->cstart[row + (size_t)c0[0]]; j < e; j++) {
                int r = j != i ? visit(s, i, j, user) : 0;
                if (r) return r;
            }
        }
    return 0;
}

static int visit_near_build(const jam *s, size_t i, double R, pair_visit visit, void *user) {
    const double p[3] = {s->xr[3 * i], s->xr[3 * i + 1], s->xr[3 * i + 2]};
    return visit_near_point(s, i, p, R, visit, user);
}

typedef struct lack_visit {
    double xi[3];
    long pairs;
} lack_visit;

static int lacks_visit(const jam *s, size_t i, uint32_t j, void *user) {
    lack_visit *v = user;
    double xj[3], d2 = 0;
    centre_of(s, j, xj);
    for (int k = 0; k < 3; k++) d2 += (v->xi[k] - xj[k]) * (v->xi[k] - xj[k]);
    double reach = s->scale * (r0_of(s, i) + r0_of(s, j)) + s->gap;
    if (d2 >= reach * reach) return 0;
    v->pairs++;
    uint32_t k = s->off[i];
    while (k < s->off[i + 1] && s->nb[k] != j) k++;
    return k == s->off[i + 1];
}

/* The check VDBPACK_JAM_CHECK_LISTS asks for (tests): whether a pair in
 * reach now (centres closer than r_i + r_j + gap) is missing from the
 * list, found without list_still_holds's reasoning: every sphere against
 * every other whose build position lay within the largest reach and
 * twice the largest displacement m (which no pair in reach can exceed)
 * of its own. Counts the lists and pairs checked. */
static int list_lacks_pair(jam *s, double m) {
    const double R = (2 * s->scale * s->r0max + s->gap + 2 * m) * (1 + 1e-5);
    lack_visit v = {{0, 0, 0}, 0};
    int lacks = 0;
    s->lists_checked++;
    for (size_t i = 0; i < s->n && !lacks; i++) {
        centre_of(s, i, v.xi);
        lacks = visit_near_build(s, i, R, lacks_visit, &v);
    }
    s->pairs_checked += v.pairs;
    return lacks;
}

/* What the list's pairs may have lost since the build without any
 * sphere moving: twice the growth of the largest radius (the scale's and
 * the swaps'). */
static double list_grown(const jam *s) {
    double grow = s->scale > s->s_build ? 2.0 * (s->scale - s->s_build) * s->r0max : 0.0;
    return grow + s->swap_grow;
}

typedef struct hold_visit {
    double xi[3], di[3], ri, g;
} hold_visit;

/* 1 when far sphere i and j are in reach now and may have closed in by
 * more than the skin allows */
static int breaks_visit(const jam *s, size_t i, uint32_t j, void *user) {
    const hold_visit *v = user;
    const float *rj0 = s->xr + 3 * (size_t)j;
    double xj[3], rel2 = 0, dist2 = 0;
    centre_of(s, j, xj);
    for (int k = 0; k < 3; k++) {
        double u = v->di[k] - (xj[k] - rj0[k]), w = v->xi[k] - xj[k];
        rel2 += u * u;
        dist2 += w * w;
    }
    if (sqrt(rel2) + v->g + 2 * s->xr_err <= s->skin) return 0;
    double reach = (v->ri + s->scale * r0_of(s, j) + s->gap) * (1 + 1e-6);
    return dist2 < reach * reach;
}

/* Whether the list still holds every pair within reach although the two
 * largest displacements together passed what the skin allows (g: what
 * the radii grew, m: the largest displacement). A pair the list lacks
 * was skin + reach apart at the build; it can have closed in by at most
 * |d_i - d_j|, so while that stays under skin - g it is out of reach.
 * Spheres at most h = (skin - g) / 2 from their build position cannot
 * break that between themselves: only the far ones the move noted
 * (past h) are checked, against every sphere whose build position lay
 * near enough to be in reach now, and only pairs in reach now count (a
 * pair out of reach needs no list entry this step). A far sphere must
 * also stay within the wall's skin unless it was near the wall. Every
 * bound gives up xr_err per sphere to the build positions' rounding.
 * Returns 0 (rebuild) when a chunk noted more far spheres than it holds,
 * or the far spheres checked since the build pass n / FAR_SEEN (where
 * spheres drift together, as along a long thin box, many are far at each
 * step and checking them all, step after step, costs more than a build). */
static int list_still_holds(jam *s, double g, double m) {
    const double h = 0.5 * (s->skin - g - 2 * s->xr_err), rmax = s->scale * s->r0max;
    if (!(h > 0)) return 0;
    for (size_t c = 0; c < s->nchunk; c++) {
        if (s->nfar[c] > FAR_CAP) return 0;
        s->far_seen += s->nfar[c];
    }
    /* each check walks a sphere's cells as the build does: past FAR_SEEN
     * of the spheres since the build, a build is the cheaper */
    if (s->far_seen > s->n / FAR_SEEN) return 0;
    for (size_t c = 0; c < s->nchunk; c++)
        for (uint32_t f = 0; f < s->nfar[c]; f++) {
            size_t i = s->far[c * FAR_CAP + f];
            hold_visit v;
            double d2 = 0;
            centre_of(s, i, v.xi);
            for (int k = 0; k < 3; k++) {
                v.di[k] = v.xi[k] - s->xr[3 * i + k];
                d2 += v.di[k] * v.di[k];
            }
            double dl = sqrt(d2);
            if (!s->near_wall[i] && dl + g + s->xr_err > s->skin) return 0;
            v.ri = s->scale * r0_of(s, i);
            v.g = g;
            /* partners were within this of i at the build (and the
             * floats' rounding) */
            double R = (2 * rmax + s->gap + dl + m) * (1 + 1e-5);
            if (visit_near_build(s, i, R, breaks_visit, &v)) return 0;
        }
    return 1;
}

/* What a sphere's displacement (from its build position rounded to
 * float, xr) may be off by: half a float's unit in the last place of
 * each coordinate, at most 2^-24 of the position's length, doubled;
 * the spheres lie within the container's box and its extent again. In a
 * unit box about 3e-7, in box:350,1,1 6e-5. */
static double xr_rounding(const vp_container_info *ci) {
    double m2 = 0;
    for (int k = 0; k < 3; k++) {
        double a = fabs(ci->bmin[k]) > fabs(ci->bmax[k]) ? fabs(ci->bmin[k]) : fabs(ci->bmax[k]);
        a += ci->bmax[k] - ci->bmin[k];
        m2 += a * a;
    }
    return sqrt(m2) * 0x1p-23;
}

/* Rebuilds the list unless it still holds every pair within reach (the
 * radii's growth counted): 0, -1 (out of memory) or -3 (a kept list
 * lacks a pair, under VDBPACK_JAM_CHECK_LISTS). */
static int maybe_rebuild(jam *s, int threads, const double disp2[2], int *builds) {
    /* the two largest displacements added: any pair has closed in by at
     * most that much; past the skin, list_still_holds looks closer */
    double g = list_grown(s);
    if (sqrt(disp2[0]) + sqrt(disp2[1]) + g + 2 * s->xr_err <= s->skin) return 0;
    if (list_still_holds(s, g, sqrt(disp2[0]))) {
        /* VDBPACK_JAM_CHECK_LISTS: the list kept, checked by brute force */
        if (s->check_lists && list_lacks_pair(s, sqrt(disp2[0]))) return -3;
        return 0;
    }
    if (build_list(s, threads) != 0) return -1;
    (*builds)++;
    return 0;
}

/* Minimises U (s->baro 0: at the current scale) or the enthalpy
 * U - drive * scale (s->baro 1: the scale is one more degree of freedom,
 * of mass msq^2, pushed up by a constant force and held by the overlaps)
 * by FIRE. A minimum: rms force below ftol of the rms overlap and, with
 * the scale free, dU/dscale within ftol of the drive. Returns 0, -1 (out
 * of memory), -2 (cancelled) or -3 (VDBPACK_JAM_CHECK_LISTS found a
 * pair missing). */
static int minimize(jam *s, vp_context *ctx, int threads, double ftol, long *steps_total,
                    int *builds, double progress_lo, double progress_hi) {
    size_t n = s->n;
    double dm = s->dmean;
    memset(s->v, 0, 3 * n * sizeof *s->v);
    s->vs = 0;
    s->dt = FIRE_DT0;
    s->alpha = FIRE_ALPHA0;
    int npos = 0;
    long step;
    sums t = {0, 0, 0, 0, {0, 0}, 0};
    double best = HUGE_VAL; /* the force ratio when it last halved, at step best_step */
    long best_step = 0;
    for (step = 0; step < MAX_STEPS; step++) {
        vp_parallel_for(threads, s->nchunk, force_chunk, s);
        t = add_up(s, 0);
        double fs = 0;
        if (s->baro) {
            fs = (s->drive - t.duds) / s->msq;
            t.fv += fs * s->vs;
            t.ff += fs * fs;
            t.vv += s->vs * s->vs;
        }
        double rms_overlap = sqrt(2.0 * t.e / (double)n);
        double rms_force = sqrt(t.ff / (double)n);
        if (!s->baro && rms_overlap < UNJAMMED * dm) break;
        if (rms_force < ftol * rms_overlap &&
            (!s->baro || fabs(s->drive - t.duds) < ftol * s->drive))
            break;
        /* a minimisation that no longer converges ends, and the pressures
         * after it (or the finish) go on from where it is: with the squeeze
         * test (relocate_squeezed) at four times the pair overlap,
         * suzanne.obj, 8 000 spheres, seed 2, ran two pressures to the
         * 200 000-step cap with the largest overlap already 5e-6, its force
         * ratio never below the tolerance; so stopped, 128 622 steps in all
         * (428 328), fraction 0.6026 (0.6038) */
        if (rms_force < 0.5 * best * rms_overlap) {
            best = rms_force / rms_overlap;
            best_step = step;
        } else if (step - best_step > (s->baro ? BARO_STALL_STEPS : STALL_STEPS)) {
            break;
        }
        if ((step & 255) == 255) {
            double frac = progress_lo + (progress_hi - progress_lo) * (1.0 - exp(-step / 20000.0));
            if (!vp_report_progress(ctx, frac, "jam")) return -2;
        }
        /* FIRE */
        s->zero_v = 0;
        if (t.fv > 0) {
            if (++npos > FIRE_NDELAY) {
                s->dt = s->dt * FIRE_FINC < FIRE_DTMAX ? s->dt * FIRE_FINC : FIRE_DTMAX;
                s->alpha *= FIRE_FALPHA;
            }
        } else {
            npos = 0;
            s->dt *= FIRE_FDEC;
            s->alpha = FIRE_ALPHA0;
            s->zero_v = 1;
        }
        s->vscale = t.ff > 0 ? s->alpha * sqrt(t.vv / t.ff) : 0.0;
        if (s->baro) {
            double v = s->zero_v ? 0.0 : (1.0 - s->alpha) * s->vs + s->vscale * fs;
            v += s->dt * fs;
            s->vs = v;
            s->scale += s->dt * v / s->msq;
            if (!(s->scale > s->scale_lo && s->scale < s->scale_hi)) break;
        }
        double h = 0.5 * (s->skin - list_grown(s) - 2 * s->xr_err);
        s->far2 = h > 0 ? h * h : 0.0;
        vp_parallel_for(threads, s->nchunk, move_chunk, s);
        sums mv = add_up(s, 1);
        int built = *builds;
        int rc = maybe_rebuild(s, threads, mv.disp2, builds);
        if (rc != 0) return rc;
        /* swaps in the quench, on a list just built */
        if (s->swap && !s->baro && *builds != built && *builds % SWAP_EVERY == 0 &&
            swap_radii(s) != 0)
            return -1;
    }
    *steps_total += step;
    return 0;
}

/* The largest relative overlap (pairs over r_i + r_j, the wall over r_i)
 * at the current scale, and of the pairs alone (relocate_squeezed). */
typedef struct overlap_q {
    jam *s;
    double worst[NCHUNK], pair[NCHUNK];
} overlap_q;

static void overlap_chunk(void *user, size_t ci) {
    overlap_q *q = user;
    jam *s = q->s;
    size_t lo, hi;
    chunk_range(s, ci, &lo, &hi);
    double worst = 0;
    for (size_t i = lo; i < hi; i++) {
        const double *xi = s->x + 4 * i;
        double ri = s->scale * R0(s, i);
        for (uint32_t k = s->off[i]; k < s->off[i + 1]; k++) {
            uint32_t j = s->nb[k];
            if (j < i) continue;
            const double *xj = s->x + 4 * (size_t)j;
            double sij = ri + s->scale * R0(s, j), reach = sij + s->gap;
            double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
            double d2 = dx * dx + dy * dy + dz * dz;
            if (d2 >= reach * reach) continue;
            double o = (reach - sqrt(d2)) / sij;
            if (o > worst) worst = o;
        }
    }
    q->pair[ci] = worst;
    for (size_t i = lo; i < hi; i++) {
        if (s->near_wall[i]) {
            double ri = s->scale * R0(s, i), w = wall_depth(s, s->x + 4 * i, ri);
            double o = w / ri; /* the factor the last step takes from the radii */
            if (w > 0 && o > worst) worst = o;
        }
    }
    q->worst[ci] = worst;
}

static double largest_overlap(jam *s, int threads, double *pair) {
    overlap_q *q = malloc(sizeof *q);
    if (!q) return 0.0;
    q->s = s;
    vp_parallel_for(threads, s->nchunk, overlap_chunk, q);
    double w = 0, p = 0;
    for (size_t c = 0; c < s->nchunk; c++) {
        if (q->worst[c] > w) w = q->worst[c];
        if (q->pair[c] > p) p = q->pair[c];
    }
    free(q);
    if (pair) *pair = p;
    return w;
}

/* ---- the exact last step ------------------------------------------------- */

/* The largest factor (<= 1) for all radii at which no pair and no wall
 * overlaps, at the current positions (the list is current). */
static double safe_factor(jam *s) {
    double f = 1.0;
    for (size_t i = 0; i < s->n; i++) {
        const double *xi = s->x + 4 * i;
        double r0i = R0(s, i);
        for (uint32_t k = s->off[i]; k < s->off[i + 1]; k++) {
            uint32_t j = s->nb[k];
            if (j < i) continue;
            const double *xj = s->x + 4 * (size_t)j;
            double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
            double d = sqrt(dx * dx + dy * dy + dz * dz);
            double g = (d - s->gap) / (s->scale * (r0i + R0(s, j)));
            if (g < f) f = g;
        }
        if (s->fit == VP_FIT_INSIDE) {
            double d = vp_container_distance(s->c, xi);
            double g = (-d - s->margin) / (s->scale * r0i);
            if (g < f) f = g;
        }
    }
    return f;
}

/* One step of a centre x out of the wall: where the signed distance is
 * over want, x moves back along the gradient by the excess and a little
 * more (extra), and the move is written to u. Returns the excess, 0 where
 * there is none (or the distance is NaN). The caller owns x and u. */
static double wall_step(const jam *s, double *x, double want, double extra, double u[3]) {
    double d = vp_container_distance(s->c, x);
    if (!(d > want)) return 0.0;
    double g[3];
    vp_container_gradient(s->c, x, g);
    double step = (d - want) * (1.0 + 1e-9) + extra;
    for (int k = 0; k < 3; k++) {
        u[k] = step * g[k];
        x[k] -= u[k];
    }
    return d - want;
}

/* Centres outside the container (or, fit inside, closer to the wall than
 * a small part of their radius) move back along the gradient. */
static void project_centres(jam *s) {
    for (size_t i = 0; i < s->n; i++) {
        double *x = s->x + 4 * i, u[3];
        double want = (s->fit == VP_FIT_INSIDE ? -0.5 * s->scale * R0(s, i) : 0.0) - s->margin;
        for (int it = 0; it < 8; it++)
            if (wall_step(s, x, want, 1e-12 + 1e-9 * s->scale * R0(s, i) * (1 << it), u) == 0.0)
                break;
    }
}

/* The last minimum's overlaps are not all the largest: shrinking every
 * radius by the largest (safe_factor) leaves most contacts apart by up to
 * that much. Instead the radii shrink by RELIEVE_SHARE of it and the
 * overlaps left are pushed apart, pair by pair and from the wall, in index
 * order (one thread: the same moves for any thread count), for at most
 * RELIEVE_SWEEPS sweeps; safe_factor then takes what is left. Kept only if
 * it ends with larger radii than the plain shrink; otherwise the centres
 * go back (their moves, summed in f, are undone). The moves are a small
 * part of the list's skin, so the list still holds every pair in reach. */
#define RELIEVE_SHARE 0.25
#define RELIEVE_SWEEPS 64
#define RELIEVE_TOL 1e-7 /* of r_i + r_j: what is left costs no more */

/* One sweep at the scale sc: each overlapping pair apart by half its
 * overlap each, each centre out of the wall; moves summed in s->f. Returns
 * the largest overlap it met, of r_i + r_j (of 2 r_i at the wall). */
static double relieve_sweep(jam *s, double sc) {
    double worst = 0;
    for (size_t i = 0; i < s->n; i++) {
        double *xi = s->x + 4 * i, r0i = R0(s, i);
        float *fi = s->f + 3 * i;
        for (uint32_t k = s->off[i]; k < s->off[i + 1]; k++) {
            uint32_t j = s->nb[k];
            if (j < i) continue;
            double *xj = s->x + 4 * (size_t)j, sij = sc * (r0i + R0(s, j));
            double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
            double d = sqrt(dx * dx + dy * dy + dz * dz), o = sij + s->gap - d;
            if (!(o > 0) || !(d > 0)) continue;
            if (o > worst * sij) worst = o / sij;
            double h = (0.5 * o * (1.0 + 1e-9) + 1e-12 * sij) / d;
            double u[3] = {h * dx, h * dy, h * dz};
            float *fj = s->f + 3 * (size_t)j;
            for (int a = 0; a < 3; a++) {
                xi[a] += u[a];
                xj[a] -= u[a];
                fi[a] += (float)u[a];
                fj[a] -= (float)u[a];
            }
        }
        if (!s->near_wall[i]) continue;
        double want = (s->fit == VP_FIT_INSIDE ? -sc * r0i : 0.0) - s->margin, u[3];
        double e = wall_step(s, xi, want, 1e-12 * sc * r0i, u);
        if (e == 0.0) continue;
        if (e > worst * 2 * sc * r0i) worst = e / (2 * sc * r0i);
        for (int a = 0; a < 3; a++) fi[a] -= (float)u[a];
    }
    return worst;
}

/* The factor for all radii that leaves no overlap, given f0 = safe_factor
 * (the plain shrink); the centres may move (above). */
static double relieve_overlaps(jam *s, double f0) {
    if (s->no_relieve || !(f0 < 1.0)) return f0;
    const double sc = s->scale, ft = 1.0 - RELIEVE_SHARE * (1.0 - f0);
    memset(s->f, 0, 3 * s->n * sizeof *s->f);
    for (int it = 0; it < RELIEVE_SWEEPS; it++)
        if (relieve_sweep(s, sc * ft) < RELIEVE_TOL) break;
    /* the list holds every pair in reach while no centre has moved half
     * the skin since its build (a quarter here) */
    double moved2 = 0;
    for (size_t i = 0; i < s->n; i++) {
        const float *fi = s->f + 3 * i;
        double m2 = (double)fi[0] * fi[0] + (double)fi[1] * fi[1] + (double)fi[2] * fi[2];
        if (m2 > moved2) moved2 = m2;
    }
    if (moved2 < 0.0625 * s->skin * s->skin) {
        s->scale = sc * ft;
        double f1 = safe_factor(s);
        s->scale = sc;
        if (ft * f1 > f0) return ft * f1;
    }
    for (size_t i = 0; i < s->n; i++)
        for (int a = 0; a < 3; a++) s->x[4 * i + a] -= s->f[3 * i + a];
    return safe_factor(s);
}

/* ---- squeezed spheres ------------------------------------------------------ */

/* A sphere in a part of the container thinner than itself (a mesh's thin
 * ear or fin, a narrow tube) is pressed by the wall from opposite sides:
 * no move clears that overlap, and since one factor scales all radii it
 * would hold every radius down to the thin part's. After a minimisation
 * under pressure such a sphere, one whose wall overlap is over SQUEEZE
 * times the largest pair overlap while the wall's pushes leave less than
 * SQUEEZE_PUSH of one (wall_direction's blend: 0 mid-sheet, 0.7 at a
 * right-angled edge, 0.87 in a corner), moves to the place of least
 * overlap among SQUEEZE_TRIES drawn at random where it fits, and the
 * minimisation is repeated; at most MAX_RELOCATIONS rounds. */
#define SQUEEZE 2.0
#define SQUEEZE_PUSH 0.5
#define SQUEEZE_TRIES 64
#define MAX_RELOCATIONS 8

typedef struct spot_visit {
    double p[3], ri, e;
} spot_visit;

static int spot_visit_fn(const jam *s, size_t i, uint32_t j, void *user) {
    (void)i;
    spot_visit *v = user;
    const double *xj = s->x + 4 * (size_t)j;
    double sij = v->ri + s->scale * R0(s, j) + s->gap;
    double dx = v->p[0] - xj[0], dy = v->p[1] - xj[1], dz = v->p[2] - xj[2];
    double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 < sij * sij) {
        double o = sij - sqrt(d2);
        v->e += o * o;
    }
    return 0;
}

/* Moves the squeezed spheres (above) to better places, drawn from *rs,
 * given the largest pair overlap (largest_overlap's); returns how many
 * moved (the list must then be rebuilt). */
static size_t relocate_squeezed(jam *s, double pair, uint64_t *rs) {
    if (s->fit != VP_FIT_INSIDE) return 0;
    const vp_container_info *ci = &s->c->info;
    size_t moved = 0;
    for (size_t i = 0; i < s->n; i++) {
        if (!s->near_wall[i]) continue;
        double *xi = s->x + 4 * i, ri = s->scale * R0(s, i), g[3];
        double d = vp_container_distance(s->c, xi), w = wall_depth_at(s, d, ri);
        if (!(w > 0)) continue;
        wall_direction(s, xi, d, ri, g);
        if (g[0] * g[0] + g[1] * g[1] + g[2] * g[2] >= SQUEEZE_PUSH * SQUEEZE_PUSH) continue;
        if (!(w > SQUEEZE * pair * ri)) continue;
        double in = ri + s->margin, lo[3], hi[3];
        for (int k = 0; k < 3; k++) {
            lo[k] = ci->bmin[k] + in;
            hi[k] = ci->bmax[k] - in;
        }
        spot_visit best = {{0, 0, 0}, ri, HUGE_VAL};
        for (int t = 0, found = 0; t < 100 * SQUEEZE_TRIES && found < SQUEEZE_TRIES; t++) {
            spot_visit v = {{0, 0, 0}, ri, 0};
            for (int k = 0; k < 3; k++) v.p[k] = lo[k] + (hi[k] - lo[k]) * vp_rng_uniform(rs);
            if (!(vp_container_distance(s->c, v.p) <= -in)) continue;
            found++;
            visit_near_point(s, i, v.p, ri + s->scale * s->r0max + s->gap + s->skin, spot_visit_fn,
                             &v);
            if (v.e < best.e) best = v;
        }
        if (best.e == HUGE_VAL) continue;
        for (int k = 0; k < 3; k++) {
            xi[k] = best.p[k];
            s->v[3 * i + k] = 0.0f;
        }
        moved++;
    }
    return moved;
}

/* ---- contacts, rattlers and the core -------------------------------------- */

static void contacts(jam *s, double gap, vp_jam_report *rep) {
    size_t n = s->n;
    uint8_t *z = calloc(n, 1);
    uint8_t *rattler = calloc(n, 1);
    if (!z || !rattler) {
        free(z);
        free(rattler);
        return;
    }
    /* contact counts (pairs both ways, the wall once) */
    for (size_t i = 0; i < n; i++) {
        const double *xi = s->x + 4 * i;
        double ri = s->scale * R0(s, i);
        unsigned c = 0;
        for (uint32_t k = s->off[i]; k < s->off[i + 1]; k++) {
            uint32_t j = s->nb[k];
            const double *xj = s->x + 4 * (size_t)j;
            double sij = ri + s->scale * R0(s, j);
            double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
            if (sqrt(dx * dx + dy * dy + dz * dz) - sij - s->gap < gap * sij) c++;
        }
        if (s->near_wall[i]) {
            if (-wall_depth(s, xi, ri) < gap * 2 * ri) c++;
        }
        z[i] = (uint8_t)(c > 255 ? 255 : c);
    }
    /* rattlers: fewer than 4 contacts with non-rattlers, removed until none
     * is left (removing one takes a contact from each neighbour) */
    int changed = 1;
    while (changed) {
        changed = 0;
        for (size_t i = 0; i < n; i++) {
            if (rattler[i] || z[i] >= 4) continue;
            rattler[i] = 1;
            changed = 1;
            const double *xi = s->x + 4 * i;
            double ri = s->scale * R0(s, i);
            for (uint32_t k = s->off[i]; k < s->off[i + 1]; k++) {
                uint32_t j = s->nb[k];
                const double *xj = s->x + 4 * (size_t)j;
                double sij = ri + s->scale * R0(s, j);
                double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
                if (sqrt(dx * dx + dy * dy + dz * dz) - sij - s->gap < gap * sij && z[j] > 0)
                    z[j]--;
            }
        }
    }
    size_t nr = 0, zsum = 0;
    for (size_t i = 0; i < n; i++) {
        if (rattler[i]) nr++;
        else zsum += z[i];
    }
    rep->rattler_fraction = (double)nr / (double)n;
    rep->mean_contacts = n > nr ? (double)zsum / (double)(n - nr) : 0.0;
    free(z);
    free(rattler);
}

/* Whether x is known to lie deeper than `depth` inside: by the distance
 * (exact in analytic containers; a level set's values are clamped past
 * its narrow band, so they never read deeper than it), or past the band
 * by the depth map's lower bound (core/depth_map.h: true depth >= -bound
 * where it decides). Conservative: a point neither decides is not deep. */
static int deeper_than(const vp_container *c, const vp_depth_map *dm, const double x[3],
                       double depth) {
    if (vp_container_distance(c, x) < -depth) return 1;
    double b = vp_depth_map_at(dm, x); /* NaN without a map or undecided */
    return b < 0 && -b > depth;
}

/* The core: centres deeper than CORE_DIAMETERS mean diameters (of the
 * final radii; none when it holds fewer than 100 spheres), by
 * deeper_than: in a level set narrower than that, the part of the core
 * its depth map vouches for. Its volume is measured on a grid of about
 * 2^21 sample points over the container's box, each counting the share
 * of its cell inside the core: where the distance is exact at the core's
 * boundary, the share is linear in it across a cell's width (the
 * boundary's error then falls as the cell squared); elsewhere 0 or 1 by
 * deeper_than. (Counted 0 or 1 everywhere until 2026-11-27: a core a
 * whole number of cells wide, up to 3 % off at 100 000 spheres.) */
static void core(jam *s, vp_jam_report *rep) {
    const vp_container_info *ci = &s->c->info;
    double mean_r = 0;
    for (size_t i = 0; i < s->n; i++) mean_r += R0(s, i);
    mean_r = s->scale * mean_r / (double)s->n;
    double depth = CORE_DIAMETERS * 2.0 * mean_r;
    size_t count = 0;
    double vol = 0;
    vp_depth_map dm;
    memset(&dm, 0, sizeof dm);
    const vp_depth_map *dmp = NULL;
    if (s->c->depth_map && ci->interior_band < depth && s->c->depth_map(s->c, &dm) == 0) dmp = &dm;
    for (size_t i = 0; i < s->n; i++) {
        if (deeper_than(s->c, dmp, s->x + 4 * i, depth)) {
            count++;
            double r = s->scale * R0(s, i);
            vol += 4.0 / 3.0 * M_PI * r * r * r;
        }
    }
    double ext[3], bv = 1;
    for (int k = 0; k < 3; k++) {
        ext[k] = ci->bmax[k] - ci->bmin[k];
        bv *= ext[k];
    }
    double h = cbrt(bv / 2097152.0);
    int m[3];
    for (int k = 0; k < 3; k++) {
        m[k] = (int)ceil(ext[k] / h);
        if (m[k] < 1) m[k] = 1;
    }
    /* a cell's width, and whether the distance is exact a cell past the core */
    double w = cbrt(bv / ((double)m[0] * m[1] * m[2]));
    const int ramp = !dmp && ci->interior_band >= depth + w;
    double inside = 0;
    for (int k = 0; k < m[2]; k++)
        for (int j = 0; j < m[1]; j++)
            for (int i = 0; i < m[0]; i++) {
                double p[3] = {ci->bmin[0] + (i + 0.5) * ext[0] / m[0],
                               ci->bmin[1] + (j + 0.5) * ext[1] / m[1],
                               ci->bmin[2] + (k + 0.5) * ext[2] / m[2]};
                if (ramp) {
                    double phi = vp_container_distance(s->c, p) + depth; /* < 0: in the core */
                    inside += phi <= -0.5 * w ? 1.0 : phi >= 0.5 * w ? 0.0 : 0.5 - phi / w;
                } else if (deeper_than(s->c, dmp, p, depth)) {
                    inside += 1.0;
                }
            }
    vp_depth_map_free(&dm);
    double cv = inside * bv / ((double)m[0] * m[1] * m[2]);
    /* a core of fewer than 100 spheres says nothing: none */
    if (count < 100 || !(cv > 0)) {
        count = 0;
        cv = vol = 0;
    }
    rep->core_count = count;
    rep->core_volume = cv;
    rep->core_fraction = count ? vol / cv : 0.0;
}

/* ---- the entry point ------------------------------------------------------ */

static vp_result check_params(vp_context *ctx, const vp_container *c, const vp_jam_params *P) {
    double dmin = vp_size_dist_min(&P->radius), dmax = vp_size_dist_max(&P->radius);
    if (!(dmin > 0) || !(dmax >= dmin) || !isfinite(dmax))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "jam: radii must be finite and > 0");
    if (!(dmin >= FLT_MIN) || !(dmax <= FLT_MAX))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "jam: radii must be in 1.2e-38..3.4e38 (radii are stored as float), "
                       "not %g..%g",
                       dmin, dmax);
    if (P->fit != VP_FIT_INSIDE && P->fit != VP_FIT_CENTER)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "jam: unknown fit");
    if (!(P->tolerance > 0) || !(P->tolerance < 0.1))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "jam: the tolerance must be in (0, 0.1), not %g", P->tolerance);
    if (!(P->contact_gap > 0) || !(P->contact_gap < 0.1))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "jam: the contact gap must be in (0, 0.1), not %g", P->contact_gap);
    int equal = dmin == dmax;
    if (P->count == 0 && (!(P->target_fraction > 0) || !(P->target_fraction < 1)))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "jam: the target fraction must be in (0, 1), not %g", P->target_fraction);
    if (P->count == 0 && equal && P->target_fraction > VP_KEPLER)
        return vp_fail(ctx, VP_ERR_NO_FIT,
                       "jam: a fraction of %g of equal spheres is more than any packing holds "
                       "(0.7405, the densest); random close packing is about 0.64",
                       P->target_fraction);
    if (!(P->margin >= 0) || !isfinite(P->margin) || !(P->gap >= 0) || !isfinite(P->gap))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "jam: the margin and the gap must be finite and >= 0, not %g and %g",
                       P->margin, P->gap);
    if (!c || !(c->info.volume > 0))
        return vp_fail(ctx, VP_ERR_BAD_CONTAINER, "jam: the container has no volume");
    return VP_OK;
}

/* The number of spheres: count, or target_fraction of the volume. */
static vp_result sphere_count(vp_context *ctx, const vp_container *c, const vp_jam_params *P,
                              size_t *out) {
    double m3 = vp_size_dist_mean_cube(&P->radius);
    double v = 4.0 / 3.0 * M_PI * m3;
    double n = P->count ? (double)P->count : floor(P->target_fraction * c->info.volume / v + 0.5);
    if (n < 1)
        return vp_fail(ctx, VP_ERR_NO_FIT,
                       "jam: the container (volume %g) holds no sphere of mean volume %g at a "
                       "fraction of %g",
                       c->info.volume, v, P->target_fraction);
    if (n >= (double)(UINT32_MAX / 64))
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "jam: %.0f spheres are too many", n);
    double need = n * 160.0;
    if (need > (double)vp_memory_limit(ctx)) {
        char a[32], b[32];
        vp_format_bytes(need, a, sizeof a);
        vp_format_bytes((double)vp_memory_limit(ctx), b, sizeof b);
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY,
                       "jam: %.0f spheres would need about %s, over the memory limit of %s", n, a,
                       b);
    }
    *out = (size_t)n;
    return VP_OK;
}

static void jam_free(jam *s) {
    free(s->x);
    free(s->xq);
    free(s->r0q);
    free(s->v);
    free(s->f);
    free(s->xr);
    free(s->id);
    free(s->off);
    free(s->nb);
    free(s->near_wall);
    free(s->wdir);
    free(s->cstart);
    free(s->far);
}

/* The quench runs in single precision: its records (xq, with eight of
 * zeros past the last for the list build's eight-wide loads) and r0q
 * from x, which is freed; or, for spheres too small against the
 * container for the fixed point, in double as after it (xq stays NULL).
 * 0, or -1 (out of memory). */
static int enter_quench(jam *s, double mean_r0) {
    size_t n = s->n;
    /* the unit: 2^31 of them reach twice the container's largest extent
     * from its box's centre (further out the wall holds no sphere) */
    const vp_container_info *ci = &s->c->info;
    double ext = 0;
    for (int k = 0; k < 3; k++) {
        s->qc[k] = 0.5 * (ci->bmin[k] + ci->bmax[k]);
        if (ci->bmax[k] - ci->bmin[k] > ext) ext = ci->bmax[k] - ci->bmin[k];
    }
    /* the quench stops at forces of about 1e-4 of a radius: with spheres
     * under 1e5 units (a mean radius below 9.3e-5 of the extent: a long
     * thin container), the unit would be too coarse for them, and the
     * quench stays in double precision */
    if (!(s->scale * mean_r0 * 1073741824.0 >= 1e5 * ext)) return 0;
    s->qres = ext / 1073741824.0;
    s->qinv = 1073741824.0 / ext;
    s->xq = aligned_alloc(64, (4 * (n + 8) * sizeof *s->xq + 63) / 64 * 64);
    s->r0q = malloc(n * sizeof *s->r0q);
    if (!s->xq || !s->r0q) return -1;
    for (size_t i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++) s->xq[4 * i + k] = q_coord(s, k, s->x[4 * i + k]);
        s->r0q[i] = s->x[4 * i + 3];
        q_set_radius(s, i, s->r0q[i]);
    }
    memset(s->xq + 4 * n, 0, 32 * sizeof *s->xq);
    free(s->x);
    s->x = NULL;
    return 0;
}

/* And back to double precision after it: x from xq and r0q (freed), and
 * the list freed first (the next minimisation rebuilds it with its own
 * skin), so that the two sets of records are never held beside it.
 * 0, or -1 (out of memory). */
static int leave_quench(jam *s) {
    size_t n = s->n;
    if (!s->xq) return 0;
    free(s->nb);
    s->nb = NULL;
    s->nb_cap = 0;
    s->x = aligned_alloc(64, (4 * n * sizeof *s->x + 63) / 64 * 64);
    if (!s->x) return -1;
    for (size_t i = 0; i < n; i++) {
        centre_of(s, i, s->x + 4 * i);
        s->x[4 * i + 3] = s->r0q[i];
    }
    free(s->xq);
    free(s->r0q);
    s->xq = NULL;
    s->r0q = NULL;
    return 0;
}

/* Radii from the distribution and centres at random where a sphere of the
 * given radius fits (overlaps allowed). */
/* The share of the container's volume deeper than the margin, from 4096
 * points at random in its box (1 without a margin): the room the spheres
 * start in. */
static double room_share(const jam *s, uint64_t seed) {
    if (!(s->margin > 0)) return 1.0;
    const vp_container_info *ci = &s->c->info;
    uint64_t rs = vp_rng_stream(seed, 3);
    size_t in = 0, deep = 0;
    for (int t = 0; t < 4096; t++) {
        double x[3];
        for (int k = 0; k < 3; k++)
            x[k] = ci->bmin[k] + (ci->bmax[k] - ci->bmin[k]) * vp_rng_uniform(&rs);
        double d = vp_container_distance(s->c, x);
        in += d <= 0;
        deep += d <= -s->margin;
    }
    return in ? fmax((double)deep / (double)in, 1.0 / 64.0) : 1.0;
}

static vp_result place_random(vp_context *ctx, jam *s, const vp_jam_params *P) {
    const vp_container_info *ci = &s->c->info;
    uint64_t rs = vp_rng_stream(P->seed, 1), ps = vp_rng_stream(P->seed, 2);
    double rmax = 0;
    for (size_t i = 0; i < s->n; i++) {
        R0(s, i) = vp_size_dist_sample(&P->radius, &rs);
        if (R0(s, i) > rmax) rmax = R0(s, i);
        s->id[i] = (uint32_t)i;
    }
    s->r0max = rmax;
    for (size_t i = 0; i < s->n; i++) {
        double r = s->scale * R0(s, i), lo[3], hi[3];
        double in = (s->fit == VP_FIT_INSIDE ? r : 0.0) + s->margin;
        for (int k = 0; k < 3; k++) {
            lo[k] = ci->bmin[k] + in;
            hi[k] = ci->bmax[k] - in;
        }
        int placed = 0;
        if (hi[0] > lo[0] && hi[1] > lo[1] && hi[2] > lo[2])
            for (int t = 0; t < 100000 && !placed; t++) {
                double *x = s->x + 4 * i;
                for (int k = 0; k < 3; k++) x[k] = lo[k] + (hi[k] - lo[k]) * vp_rng_uniform(&ps);
                placed = vp_container_distance(s->c, x) <= -in;
            }
        if (!placed)
            return vp_fail(ctx, VP_ERR_NO_FIT,
                           "jam: no place in the container for a sphere of radius %.6g (%s%s): "
                           "the container is smaller than one sphere%s",
                           r, s->fit == VP_FIT_INSIDE ? "wholly inside" : "centre inside",
                           s->margin > 0 ? ", with the margin" : "",
                           s->margin > 0 ? " and its margin" : "");
    }
    return VP_OK;
}

vp_result vp_pack_jam(vp_context *ctx, const vp_container *c, const vp_jam_params *params,
                      vp_particles **out, vp_jam_report *report) {
    double t0 = vp_seconds();
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "jam: out is NULL");
    *out = NULL;
    if (!c || !params)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "jam: container and params are required");
    const vp_jam_params *P = params;
    vp_result res = check_params(ctx, c, P);
    if (res != VP_OK) return res;
    size_t n = 0;
    res = sphere_count(ctx, c, P, &n);
    if (res != VP_OK) return res;

    jam s;
    memset(&s, 0, sizeof s);
    s.c = c;
    s.fit = P->fit;
    s.margin = P->margin;
    s.gap = P->gap;
    s.swap = polydisperse(P);
    s.n = n;
    s.nchunk = n / 512 < 1 ? 1 : n / 512 > NCHUNK ? NCHUNK : n / 512;
    s.chunk = (n + s.nchunk - 1) / s.nchunk;
    /* 32 bytes a sphere, each in one cache line */
    s.x = aligned_alloc(64, (4 * n * sizeof *s.x + 63) / 64 * 64);
    s.v = calloc(3 * n, sizeof *s.v);
    s.f = calloc(3 * n, sizeof *s.f);
    s.xr = malloc(3 * n * sizeof *s.xr);
    s.id = malloc(n * sizeof *s.id);
    s.off = malloc((n + 1) * sizeof *s.off);
    s.near_wall = malloc(n);
    s.far = malloc(s.nchunk * FAR_CAP * sizeof *s.far);
    vp_particles *p = NULL;
    vp_jam_report rep;
    memset(&rep, 0, sizeof rep);
    if (!s.x || !s.v || !s.f || !s.xr || !s.id || !s.off || !s.near_wall || !s.far) {
        res = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "jam: out of memory for %zu spheres", n);
        goto done;
    }
    /* 1. radii scaled to overfill the container, centres at random */
    double m3 = vp_size_dist_mean_cube(&P->radius);
    double vmean = 4.0 / 3.0 * M_PI * m3;
    s.scale =
        cbrt(start_fraction(P) * room_share(&s, P->seed) * c->info.volume / ((double)n * vmean));
    /* a gap makes each sphere take the room of one gap / 2 larger */
    const double no_gap = s.scale;
    s.scale -= 0.5 * P->gap / cbrt(m3);
    const double start_scale = s.scale;
    if (!(P->gap < 0.9 * s.scale * vp_size_dist_min(&P->radius))) {
        res = vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                      "jam: the gap %g is not smaller than the smallest radius (about %.3g for "
                      "%zu spheres in this container, less half the gap)",
                      P->gap, no_gap * vp_size_dist_min(&P->radius), n);
        goto done;
    }
    res = place_random(ctx, &s, P);
    if (res == VP_OK && P->radius_field) /* radii from a field at the starting centres */
        res = vp_field_radii(ctx, c, P->radius_field, P->radius_field_mode, s.x, 4, s.x + 3, 4, n,
                             1, NULL, &s.r0max);
    if (res != VP_OK) goto done;
    double mean_r0 = 0;
    for (size_t i = 0; i < n; i++) mean_r0 += R0(&s, i);
    mean_r0 /= (double)n;
    if (enter_quench(&s, mean_r0) != 0) {
        res = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "jam: out of memory for %zu spheres", n);
        goto done;
    }
    int threads = vp_threads_for(ctx);
#ifdef VP_JAM_AVX2
    s.avx2 = __builtin_cpu_supports("avx2") && !vp_env_flag("VDBPACK_NO_SIMD");
#endif
    s.xr_err = xr_rounding(&c->info);
    /* tests: VDBPACK_JAM_ROWS_CAP=N scans sets of rows over N spheres
     * as records (as a long thin box does with every set) */
    const char *rows_cap = getenv("VDBPACK_JAM_ROWS_CAP");
    s.rows_cap = ROWS_CAP;
    if (rows_cap && *rows_cap) {
        long v = strtol(rows_cap, NULL, 10);
        s.rows_cap = v < 0 ? 0 : v < ROWS_CAP ? (uint32_t)v : ROWS_CAP;
    }
    s.check_lists = vp_env_flag("VDBPACK_JAM_CHECK_LISTS");
    s.no_relieve = vp_env_flag("VDBPACK_JAM_NO_RELIEVE");

    /* 2. a quench at the start's scale, then the scale set free under a
     * falling pressure until the largest overlap is below the finish */
    int builds = 0, mins = 0, relocations = 0;
    uint64_t rr = vp_rng_stream(P->seed, 4);
    long steps = 0;
    double worst = HUGE_VAL, pair = 0; /* largest overlap: of all, of the pairs */
    s.dmean = 2 * s.scale * mean_r0;
    s.wkeep2 = WALL_KEEP * s.dmean * WALL_KEEP * s.dmean;
    s.skin = QUENCH_SKIN * s.dmean;
    if (grid_init(&s, 2 * s.scale * s.r0max + s.skin) != 0 || build_list(&s, threads) != 0) {
        res = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "jam: out of memory for the neighbour list");
        goto done;
    }
    builds++;
    /* the scale's mass: the stiffness of the scale, sum over contacts of
     * (r0_i + r0_j)^2, about 3 n (2 mean r0)^2, so that it moves as fast as
     * a sphere does */
    s.msq = sqrt(3.0 * (double)n) * 2.0 * mean_r0;
    double tau = 0; /* the mean overlap asked: none in the quench */
    /* no packing jams with radii half the start's (an eighth of its
     * fraction) or 1.25 times them (fraction 1.37): spheres that the wall
     * does not hold drive the scale there */
    s.scale_lo = 0.5 * start_scale;
    s.scale_hi = 1.25 * start_scale;
    for (mins = 0; mins < MAX_MINIMIZATIONS; mins++) {
        double plo = 0.95 * (1.0 - exp(-mins / 3.0));
        s.baro = mins > 0;
        if (mins == 1) {
            /* the quench moves spheres far: a wide skin; then a narrow one */
            s.skin = SKIN * s.dmean;
            if (build_list(&s, threads) != 0) {
                res =
                    vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "jam: out of memory for the neighbour list");
                goto done;
            }
            builds++;
        }
        /* the drive that holds a mean overlap of tau (r_i + r_j) over 3 n
         * contacts: dU/dscale = sum of overlap (r0_i + r0_j) */
        s.drive = 3.0 * (double)n * tau * s.scale * 4.0 * mean_r0 * mean_r0;
        double ftol = mins == 0 ? QUENCH_TOL : FORCE_TOL;
        int rc = minimize(&s, ctx, threads, ftol, &steps, &builds, plo,
                          0.95 * (1.0 - exp(-(mins + 1) / 3.0)));
        if (rc == -2) {
            res = vp_fail(ctx, VP_ERR_CANCELLED, "jam: cancelled");
            goto done;
        }
        if (rc == -3) {
            res = vp_fail(ctx, VP_ERR_INTERNAL,
                          "jam: a neighbour list kept lacks a pair in reach "
                          "(VDBPACK_JAM_CHECK_LISTS; please report it)");
            goto done;
        }
        if (rc != 0 || (mins == 0 && leave_quench(&s) != 0)) {
            res = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "jam: out of memory for the neighbour list");
            goto done;
        }
        /* after the quench the next pressure does not depend on it */
        if (mins > 0) worst = largest_overlap(&s, threads, &pair);
        if (!(s.scale > s.scale_lo && s.scale < s.scale_hi)) break;
        if (mins > 0 && relocations < MAX_RELOCATIONS) {
            size_t m = relocate_squeezed(&s, pair, &rr);
            if (m > 0) {
                relocations++;
                if (build_list(&s, threads) != 0) {
                    res = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY,
                                  "jam: out of memory for the neighbour list");
                    goto done;
                }
                builds++;
                mins--; /* the same pressure again */
                continue;
            }
        }
        if (mins > 0 && worst <= FINISH_OVERLAP) break;
        /* the next pressure: the mean overlap falls with it in proportion */
        double next = mins == 0 ? MID_OVERLAP : tau * 0.5 * FINISH_OVERLAP / worst;
        if (next < 0.1 * tau) next = 0.1 * tau;
        tau = next;
    }
    /* no jamming point found, or the scale ran off: spheres that the wall
     * does not hold (a centre pushed past a level set's band, where the
     * distance has no gradient) leave, and the rest are squeezed on and on
     * or grow without bound; or, in a mesh whose thin parts the level set's
     * voxels barely resolve, spheres stay pressed into the wall and every
     * minimisation runs to its cap (suzanne.obj, 2 000 spheres, seed 1, at
     * the default voxel: docs/jam.md). An error, not a packing of vanishing
     * spheres. */
    if (mins >= MAX_MINIMIZATIONS || !(s.scale > s.scale_lo && s.scale < s.scale_hi)) {
        res = vp_fail(ctx, VP_ERR_NO_FIT,
                      "jam: no jammed state found (radii scaled by %.3g of the start after %d "
                      "minimisations): spheres escape the container's wall or stay pressed into "
                      "it%s",
                      s.scale / start_scale, mins,
                      s.fit == VP_FIT_CENTER   ? " (with --fit center, try --fit inside)"
                      : c->info.voxel_size > 0 ? " (where it is thin: try a finer --voxel-size)"
                                               : "");
        goto done;
    }
    if (!vp_report_progress(ctx, 0.96, "jam")) {
        res = vp_fail(ctx, VP_ERR_CANCELLED, "jam: cancelled");
        goto done;
    }

    /* 3. the exact last step: one factor for all radii, no overlap left */
    project_centres(&s);
    s.skin = SKIN * s.dmean;
    if (build_list(&s, threads) != 0) {
        res = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "jam: out of memory for the neighbour list");
        goto done;
    }
    builds++;
    double f = relieve_overlaps(&s, safe_factor(&s));
    if (!(f > 0.5)) {
        res = vp_fail(ctx, VP_ERR_NO_FIT,
                      "jam: no overlap-free state without shrinking the spheres by half (%g)", f);
        goto done;
    }
    s.scale *= f * (1.0 - 4 * DBL_EPSILON);
    double last_worst = largest_overlap(&s, threads, NULL);

    /* 4. what the packing is: contacts, rattlers, the core */
    contacts(&s, P->contact_gap, &rep);
    if (s.check_lists)
        fprintf(stderr,
                "vdbpack: jam: %ld neighbour lists kept and checked, %ld pairs in reach, none "
                "missing\n",
                s.lists_checked, s.pairs_checked);
    core(&s, &rep);

    /* 5. the output, in the order the spheres were drawn */
    free(s.v);
    free(s.f);
    free(s.nb);
    s.v = NULL;
    s.f = NULL;
    s.nb = NULL;
    s.nb_cap = 0;
    res = vp_particles_create(ctx, n, &p);
    if (res != VP_OK) goto done;
    p->radii = malloc(n * sizeof *p->radii);
    if (!p->radii) {
        res = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "jam: out of memory");
        goto done;
    }
    double vol = 0;
    for (size_t i = 0; i < n; i++) {
        size_t o = s.id[i];
        memcpy(p->positions + 3 * o, s.x + 4 * i, 3 * sizeof(double));
        double r = s.scale * R0(&s, i);
        float rf = (float)r;
        while ((double)rf > r) rf = nextafterf(rf, 0.0f);
        p->radii[o] = rf;
        vol += (double)rf * rf * rf;
    }
    vol *= 4.0 / 3.0 * M_PI;
    p->count = n;
    p->shape = VP_SHAPE_SPHERE;
    if (!vp_report_progress(ctx, 1.0, "jam")) {
        res = vp_fail(ctx, VP_ERR_CANCELLED, "jam: cancelled");
        goto done;
    }
    if (report) {
        rep.count = n;
        rep.fraction = vol / c->info.volume;
        rep.max_overlap = last_worst;
        rep.radius_scale = s.scale;
        rep.particle_volume = vol;
        rep.minimizations = mins + 1;
        rep.iterations = steps;
        rep.list_builds = builds;
        rep.seconds = vp_seconds() - t0;
        *report = rep;
    }
    *out = p;
    p = NULL;
done:
    vp_particles_destroy(p);
    jam_free(&s);
    return res;
}

void vp_container_params_for_jam(vp_container_params *cp, const vp_jam_params *xp) {
    if (!cp || !xp) return;
    cp->narrow_band = 0;
    cp->particle_count = xp->count;
    cp->extra_depth = xp->margin;
    /* the radii end near those that fill 0.64 (any count); the band must
     * reach the largest at the start, when they overfill by start_fraction */
    double rmax = vp_size_dist_max(&xp->radius), m3 = vp_size_dist_mean_cube(&xp->radius);
    cp->particle_radius = 0;
    cp->space_per_particle = 4.0 / 3.0 * M_PI * (m3 / (rmax * rmax * rmax)) / start_fraction(xp);
    if (!xp->count) {
        cp->particle_radius = rmax * cbrt(start_fraction(xp) / xp->target_fraction);
        cp->space_per_particle = 0;
    }
}
