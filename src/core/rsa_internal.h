/* SPDX-License-Identifier: Apache-2.0 */
/* The random packer's private state, shared by its two files: rsa.c
 * (darts, the exact tests, grow, passes and the entry point) and
 * rsa_split.c (the active cells' refinement and its look-ahead, reached
 * only through vp_rsa_split_cells). The packed-cell encoding and the small
 * helpers both use are here, inline. See docs/rsa.md. Internal. */
#ifndef VDBPACK_CORE_RSA_INTERNAL_H
#define VDBPACK_CORE_RSA_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "vdbpack/vdbpack.h"
#include "core/pair.h"
#include "core/rng.h"
#include "core/rsa_top.h"
#include "core/sgrid.h"
#include "core/shape.h"

#define SPLIT_RATE 0.25       /* split cells when fewer darts succeed */
#define SPLIT_DARTS 4         /* ... and this many darts per cell were thrown at the level */
#define SPLIT_DARTS_SOLID 2   /* (solids: their darts cost more, splitting sooner pays) */
#define SPLIT_DARTS_LEVEL0 12 /* (spheres, level 0: a level-0 parent costs about 14 darts) */
#define BYTES_PER_PARTICLE 64 /* estimate for the memory guard */
#define VALID_BIT 0x80000000u /* cell flag (in z): every point passes the container test */

/* The look-ahead's AVX2 scan (rsa_split.c) where the compiler can build it;
 * used where the processor has it (vp_pack_rsa) */
#if defined(__GNUC__) && defined(__x86_64__)
#define VP_HAVE_AVX2_SCAN 1
#endif

/* mask: bit o (o = x + 2y + 4z, each 0 or 1) is clear when the cell's
 * sub-cell o, one level finer, was proven to hold no admissible centre
 * when the cell was made (what stays true: placed spheres stay). Darts
 * landing there fail at once, without a neighbour query. top: the code
 * of its top ball (core/rsa_top.h), or VP_TOP_NONE. */
typedef struct cell {
    uint32_t x, y, z, mask, top;
} cell;

/* Active cells are stored packed: 4 bytes (10 bits per coordinate and the
 * valid flag in the top bit) at the levels whose coordinates fit in 10
 * bits, 8 bytes (21 bits each) where they fit in 21, and as the three
 * coordinates (12 bytes) at finer levels, where few cells are left; then
 * the top ball's 3 bytes (spheres only) and the mask byte. Cells are the
 * largest structure of a pass (several per particle at levels 1 to 3), so
 * their size is most of the packer's memory. */
#define PACK_BITS 21
#define PACK_MASK ((1u << PACK_BITS) - 1u)
#define PACK4_BITS 10
#define PACK4_MASK ((1u << PACK4_BITS) - 1u)

typedef struct dart {
    double p[3];
    double q[4]; /* orientation (solids), as stored: float, renormalised */
    double d;    /* container distance (or -HUGE_VAL: cell known valid;
                     HUGE_VAL: in a sub-cell proven empty, the dart fails) */
    double clr;  /* spheres: min over earlier particles of |p - c_j| - r_j (capped);
                     solids of a one-radius pass: 1 when the solid fits the wall and
                     overlaps no earlier particle, else 0 */
    uint64_t st; /* its random stream, between the sweeps of make_darts, and
                     for the orientation until it is drawn */
    uint32_t cell;
    int qready; /* solids: q has been drawn (when a test first needs it: a
                     dart rejected by a sphere test never draws it) */
} dart;

typedef struct rsa {
    vp_context *ctx;
    const vp_container *c;
    vp_fit fit;
    vp_particles *p; /* positions stay NULL during the passes: in fpos */
    float *fpos;     /* 3 per particle, relative to base: half the bytes of
                             doubles, so that darts and splits read half the
                             memory; a candidate is rounded to them before its
                             tests, so what is tested is what is stored */
    double base[3];  /* the container's box centre */
    vp_sgrid g;
    const vp_polyhedron *poly; /* a platonic or Archimedean solid, or NULL */
    const vp_mesh_shape *mesh; /* a mesh shape, or NULL */
    double sb;                 /* a superball's exponent, or 0 */
    int gjk;                   /* superballs and the Archimedean solids: GJK on support
                             functions (vp_convex); platonic solids: the SAT */
    vp_shape shape;
    int solid; /* poly or mesh: not spheres (every pass of a mixed set) */
    /* several shapes (passes of their own shapes): the fields above are the
     * pass's kind (kinds[cur]); shape_index of the particle set gives each
     * particle's kind; pairs of two kinds go to vp_kind_overlap */
    int mixed;
    vp_kind kinds[VP_MAX_SHAPES];
    unsigned nkinds, cur;
    double rin;                /* insphere / bounding-sphere radius (1 for spheres):
                             two particles whose centres are closer than
                             rin (r_i + r_j) overlap whatever their orientation */
    int orient_random;         /* solids: draw a rotation per particle */
    int bbox;                  /* solids: overlap by axis-aligned boxes */
    int cube;                  /* cubes with the exact test: most pairs are decided
                             by one centre's distance to the other cube */
    int avx2;                  /* the look-ahead's ball scan four at a time (AVX2; not with
                             VDBPACK_NO_SIMD=1: the same packing, tests compare) */
    int no_top;                /* VDBPACK_NO_TOP_BALLS=1: darts never settled by a top ball
                             (the same packing, more slowly: tests compare) */
    double coord_eps;          /* rounding of a difference of two coordinates (64 ulp
                             of the container's largest coordinate) */
    double bb_lo[3], bb_hi[3]; /* the unit solid's box (bbox mode) */
    double reach;              /* bounding radius of what the overlap test compares, per
                             unit radius: 1, or the box's farthest corner (bbox) */
    double max_r;              /* largest radius placed so far */
    double min_r;              /* smallest radius placed so far (HUGE_VAL: none) */
    double uni_r;              /* the radius of every particle placed so far, or 0 when
                             they differ: the neighbour tests then skip the load
                             of radii[j], a cache miss (particles are in placement
                             order, their neighbours anywhere in memory) */
    double unit_volume;        /* of the shape at bounding radius 1 */
    double lipschitz;          /* bound on |grad distance|: 1 analytic, sqrt(3) for
                             level sets (trilinear interpolation) */
    int threads;
    size_t max_cells_param; /* vp_rsa_params.max_cells (0: automatic) */
    /* margin and gap (spheres): the passes pack spheres inflated by
     * gap_half = gap / 2 (so that two keep gap between their surfaces),
     * deflated when done; wall_off is what a sphere, as packed, keeps from
     * the wall beyond touching it: margin - gap_half with fit inside (its
     * surface, deflated, keeps margin), margin with fit center (its centre) */
    double margin, gap_half, wall_off;
    double pair_gap; /* solids (and every pass of a mixed set): the gap,
                             tested exactly between the shapes grown by half
                             of it (gap_half is then 0: a solid's scale is no
                             offset of its surface) */
    /* the pass in progress */
    double rmin, rmax; /* radius range of the pass */
    int pretest;       /* solids: the pass has one radius (rmin), so darts are
                             tested against the particles before their batch in
                             parallel, and only against the batch's own serially */
    double side[32];   /* cell side at each level: side[0] 2^-level (levels
                             stay below 31: coordinates fit in 31 bits) */
    double origin[3];  /* cell lattice origin */
    double extent[3];  /* size of the box the cells tile (hi - lo) */
    unsigned thin;     /* bit k: the box is thinner along axis k than a
                             level-0 cell (a slab or a needle). While a level's
                             side exceeds that extent, its cells are one cell
                             thick along k and darts are drawn in the cell cut
                             to the box there, so that every cell has the same
                             sampled volume (docs/rsa.md, "Sampling: active
                             cells", thin containers) */
    int level, max_level;
    size_t cell_budget;   /* most active cells a split may make */
    int split_blocked;    /* a split would exceed the budget: plain darts */
    int coord_bits;       /* bits of the level-0 cell coordinates */
    unsigned char *cells; /* ncells cells of csize bytes each */
    vp_top_scale top[32]; /* top-ball encoding of each level (u = 0: none) */
    size_t ncells, csize;
    uint64_t stream_seed;
    /* batch */
    dart *darts;
    size_t ndarts;
    size_t n0;          /* particles before the batch */
    uint64_t dart_base; /* global index of the batch's first dart */
} rsa;

/* Container thresholds on the centre's distance d: d <= thr_ok(r) passes
 * the fit test for every orientation (the bounding sphere is inside);
 * d > thr_drop(r) fails it (the insphere would cross the wall). The two
 * are equal for spheres; between them a solid's surface decides. */
static inline double thr_ok(const rsa *s, double r) {
    return s->fit == VP_FIT_INSIDE ? -r - s->wall_off : -s->wall_off;
}
static inline double thr_drop(const rsa *s, double r) {
    return s->fit == VP_FIT_INSIDE ? -s->rin * r - s->wall_off : -s->wall_off;
}

/* Particle j's centre, in world coordinates. */
static inline void ppos(const rsa *s, size_t j, double out[3]) {
    const float *f = s->fpos + 3 * j;
    for (int k = 0; k < 3; k++) out[k] = s->base[k] + (double)f[k];
}

/* x rounded to what fpos can hold (ppos gives it back exactly). */
static inline void round_pos(const rsa *s, double x[3]) {
    for (int k = 0; k < 3; k++) x[k] = s->base[k] + (double)(float)(x[k] - s->base[k]);
}

static inline void store_pos(rsa *s, size_t j, const double x[3]) {
    for (int k = 0; k < 3; k++) s->fpos[3 * j + k] = (float)(x[k] - s->base[k]);
}

/* The distance below which a centre of the pass's kind and radius r
 * overlaps particle j (radius rj) whatever the orientations: the sum of
 * the inspheres' radii. */
static inline double excluded(const rsa *s, double r, size_t j, double rj) {
    if (!s->mixed) return s->rin * (r + rj) + s->pair_gap;
    return s->rin * r + s->kinds[s->p->shape_index[j]].rin * rj + s->pair_gap;
}


static inline size_t cell_bytes(const rsa *s, int level) {
    int b = s->coord_bits + level; /* bits of a coordinate at this level */
    /* + the top ball (spheres) and the mask: a size that is a multiple of
     * 4 has a top ball */
    return (b <= PACK4_BITS ? 4 : b <= PACK_BITS ? 8 : 12) + (s->solid ? 1 : 4);
}

static inline cell cell_load(const unsigned char *buf, size_t size, size_t i) {
    cell c;
    const unsigned char *e = buf + size * i;
    c.mask = e[size - 1];
    c.top = VP_TOP_NONE;
    if (size % 4 == 0) {
        c.top = (uint32_t)e[size - 4] | (uint32_t)e[size - 3] << 8 | (uint32_t)e[size - 2] << 16;
        size -= 3;
    }
    size--;
    if (size == 4) {
        uint32_t k;
        memcpy(&k, e, 4);
        c.x = k & PACK4_MASK;
        c.y = (k >> PACK4_BITS) & PACK4_MASK;
        c.z = ((k >> (2 * PACK4_BITS)) & PACK4_MASK) | (k & VALID_BIT);
    } else if (size == 8) {
        uint64_t k;
        memcpy(&k, e, 8);
        c.x = (uint32_t)k & PACK_MASK;
        c.y = (uint32_t)(k >> PACK_BITS) & PACK_MASK;
        c.z = ((uint32_t)(k >> (2 * PACK_BITS)) & PACK_MASK) | ((k >> 63) ? VALID_BIT : 0u);
    } else {
        memcpy(&c, e, 12);
    }
    return c;
}

static inline void cell_store(unsigned char *buf, size_t size, size_t i, cell c) {
    unsigned char *e = buf + size * i;
    e[size - 1] = (unsigned char)c.mask;
    if (size % 4 == 0) {
        e[size - 4] = (unsigned char)c.top;
        e[size - 3] = (unsigned char)(c.top >> 8);
        e[size - 2] = (unsigned char)(c.top >> 16);
        size -= 3;
    }
    size--;
    if (size == 4) {
        uint32_t k =
            c.x | c.y << PACK4_BITS | (c.z & ~VALID_BIT) << (2 * PACK4_BITS) | (c.z & VALID_BIT);
        memcpy(e, &k, 4);
    } else if (size == 8) {
        uint64_t k = (uint64_t)c.x | (uint64_t)c.y << PACK_BITS |
                     (uint64_t)(c.z & ~VALID_BIT) << (2 * PACK_BITS) |
                     (uint64_t)((c.z & VALID_BIT) != 0) << 63;
        memcpy(e, &k, 8);
    } else {
        memcpy(e, &c, 12);
    }
}

static inline double cell_side(const rsa *s, int level) { return s->side[level]; }

static inline void cell_center(const rsa *s, const cell *c, int level, double out[3]) {
    double a = cell_side(s, level);
    out[0] = s->origin[0] + ((double)c->x + 0.5) * a;
    out[1] = s->origin[1] + ((double)c->y + 0.5) * a;
    out[2] = s->origin[2] + ((double)(c->z & ~VALID_BIT) + 0.5) * a;
}

/* Refines the active cells of the pass in progress one level (from_box:
 * the level-0 cells of the box of dims cells), dropping those that hold no
 * admissible centre; within the cell budget, else s->split_blocked and
 * the cells stay. rsa_split.c. */
vp_result vp_rsa_split_cells(rsa *s, int from_box, const int64_t dims[3]);

#endif
