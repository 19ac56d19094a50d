/* SPDX-License-Identifier: Apache-2.0 */
/* Neighbour search for spheres of mixed sizes: a hierarchy of dense cell
 * grids (cell linked lists), one level per factor of two in radius, so a
 * query costs about the same for small and large radii when sizes differ a
 * lot (the random packers, vdbpack check). Internal to the core.
 *
 * Ownership: the grid owns its heads and links, never the positions and
 * radii it indexes (the caller's arrays, which may grow: pass the current
 * pointers to every call). Not thread-safe for insertion; queries may run
 * concurrently with each other. */
#ifndef VDBPACK_CORE_SGRID_H
#define VDBPACK_CORE_SGRID_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#define VP_SGRID_MAX_LEVELS 20
#define VP_SGRID_NONE UINT32_MAX

typedef struct vp_sgrid_level {
    double h;     /* cell size */
    double inv_h; /* 1 / h: cells are found by multiplying (monotone, and
                              the same function for insertion and queries) */
    int64_t dims[3];
    uint32_t *head; /* dims[0]*dims[1]*dims[2] first indices, or NONE */
    double rmax;    /* largest radius stored at this level */
} vp_sgrid_level;

typedef struct vp_sgrid {
    double origin[3];
    int nlevels;
    vp_sgrid_level lev[VP_SGRID_MAX_LEVELS];
    uint32_t *next;    /* per particle: next index in its cell */
    uint8_t *level_of; /* per particle: its level (NULL with one level) */
    size_t capacity;   /* of next/level_of */
} vp_sgrid;

/* Sets up an empty grid over [lo, hi] for radii in [rmin, rmax] (rmax may
 * be exceeded later: queries stay exact, only slower). max_cells bounds the
 * cells of each level (its cells grow to fit). Returns 0, or -1 when out of
 * memory. */
int vp_sgrid_init(vp_sgrid *g, const double lo[3], const double hi[3], double rmin, double rmax,
                  size_t max_cells);
void vp_sgrid_free(vp_sgrid *g);
/* Empties every cell (keeps the allocation). */
void vp_sgrid_clear(vp_sgrid *g);
/* Inserts particle i (centre pos, radius r). Grows the links as needed;
 * returns -1 when out of memory. Points outside [lo, hi] are clamped into
 * the border cells (queries remain exact). */
int vp_sgrid_insert(vp_sgrid *g, uint32_t i, const double pos[3], double r);
/* Makes room for particles [0, n) without growing again (the grid grows
 * by half when a larger index comes). Returns 0, or -1 when out of memory. */
int vp_sgrid_reserve(vp_sgrid *g, size_t n);
/* Notes that particle i (already inserted) now has radius r. */
void vp_sgrid_grow(vp_sgrid *g, uint32_t i, double r);

/* Calls fn(user, j) for every particle j that may lie within `reach` of p
 * in the sense |p - c_j| < reach + r_j (a superset: the caller tests
 * exactly). Stops early and returns 1 when fn returns nonzero; else 0. */
typedef int (*vp_sgrid_visit)(void *user, uint32_t j);
static inline int vp_sgrid_query(const vp_sgrid *g, const double p[3], double reach,
                                 vp_sgrid_visit fn, void *user);

/* vp_sgrid_query visiting the particles of p's own cell (on each level)
 * first: a caller that stops at the first hit (an overlap) mostly finds it
 * there. The same particles, in another order. */
static inline int vp_sgrid_query_near(const vp_sgrid *g, const double p[3], double reach,
                                      vp_sgrid_visit fn, void *user);

/* The same for every particle j that may lie within `reach` + r_j of the
 * box [lo, hi] (per axis: a superset of the particles whose ball of radius
 * reach + r_j meets the box). */
static inline int vp_sgrid_query_box(const vp_sgrid *g, const double lo[3], const double hi[3],
                                     double reach, vp_sgrid_visit fn, void *user);

/* Memory hints for a later vp_sgrid_query_box(g, lo, hi, reach, ...)
 * (lo = hi = p for vp_sgrid_query): the first
 * fetches the heads of the cells it will read, the second (once those
 * have arrived) the first particle of each, its link and its data at
 * `positions` + `stride` bytes times its index. Queries are latency-bound (cells
 * and particles are scattered in memory), so a caller with many
 * independent queries issues the hints for all of them first. */
void vp_sgrid_prefetch_cells(const vp_sgrid *g, const double lo[3], const double hi[3],
                             double reach);
void vp_sgrid_prefetch_items(const vp_sgrid *g, const double lo[3], const double hi[3],
                             double reach, const void *positions, size_t stride);

/* Bytes the grid holds. */
size_t vp_sgrid_bytes(const vp_sgrid *g);

/* The queries are defined here, inline, so that a caller's visitor (a
 * constant function) is inlined into the loop over the cells: they run
 * once per dart and per split cell of the random packer, and a call per
 * particle visited was a sixth of its instructions. */
static inline int64_t vp_sgrid_cell_coord(const vp_sgrid_level *L, double x, double o, int k) {
    double f = (x - o) * L->inv_h;
    if (!(f >= 0)) return 0; /* also NaN */
    if (f >= (double)L->dims[k]) return L->dims[k] - 1;
    return (int64_t)f; /* truncation is floor here: f >= 0 */
}

/* Cells [a, b] of level L that a query of the box [lo, hi] with reach
 * reads; 0 when the level is empty. */
static inline int vp_sgrid_level_range(const vp_sgrid *g, const vp_sgrid_level *L,
                                       const double lo[3], const double hi[3], double reach,
                                       int64_t a[3], int64_t b[3]) {
    if (L->rmax <= 0) return 0;
    double R = reach + L->rmax;
    for (int k = 0; k < 3; k++) {
        a[k] = vp_sgrid_cell_coord(L, lo[k] - R, g->origin[k], k);
        b[k] = vp_sgrid_cell_coord(L, hi[k] + R, g->origin[k], k);
    }
    return 1;
}

static inline int vp_sgrid_query_box(const vp_sgrid *g, const double lo[3], const double hi[3],
                                     double reach, vp_sgrid_visit fn, void *user) {
    for (int l = 0; l < g->nlevels; l++) {
        const vp_sgrid_level *L = &g->lev[l];
        int64_t a[3], b[3];
        if (!vp_sgrid_level_range(g, L, lo, hi, reach, a, b)) continue;
        for (int64_t z = a[2]; z <= b[2]; z++)
            for (int64_t y = a[1]; y <= b[1]; y++) {
                const uint32_t *row = L->head + (size_t)((z * L->dims[1] + y) * L->dims[0]);
                for (int64_t x = a[0]; x <= b[0]; x++)
                    for (uint32_t j = row[x]; j != VP_SGRID_NONE; j = g->next[j])
                        if (fn(user, j)) return 1;
            }
    }
    return 0;
}

static inline int vp_sgrid_query(const vp_sgrid *g, const double p[3], double reach,
                                 vp_sgrid_visit fn, void *user) {
    return vp_sgrid_query_box(g, p, p, reach, fn, user);
}

/* vp_sgrid_query_near over the particles of index >= from only, for a
 * grid whose particles were inserted in increasing index order (each
 * cell's list then holds them in decreasing order, vp_sgrid_insert
 * putting the newest first): each list is read only down to the first
 * older one, so the few particles inserted since `from` are found
 * without walking the rest. */
static inline int vp_sgrid_query_near_from(const vp_sgrid *g, const double p[3], double reach,
                                           uint32_t from, vp_sgrid_visit fn, void *user) {
    for (int l = 0; l < g->nlevels; l++) {
        const vp_sgrid_level *L = &g->lev[l];
        int64_t a[3], b[3], c[3];
        if (!vp_sgrid_level_range(g, L, p, p, reach, a, b)) continue;
        for (int k = 0; k < 3; k++) c[k] = vp_sgrid_cell_coord(L, p[k], g->origin[k], k);
        size_t own = (size_t)((c[2] * L->dims[1] + c[1]) * L->dims[0] + c[0]);
        for (uint32_t j = L->head[own]; j != VP_SGRID_NONE && j >= from; j = g->next[j])
            if (fn(user, j)) return 1;
        for (int64_t z = a[2]; z <= b[2]; z++)
            for (int64_t y = a[1]; y <= b[1]; y++) {
                size_t row = (size_t)((z * L->dims[1] + y) * L->dims[0]);
                for (int64_t x = a[0]; x <= b[0]; x++) {
                    if (row + (size_t)x == own) continue;
                    for (uint32_t j = L->head[row + (size_t)x]; j != VP_SGRID_NONE && j >= from;
                         j = g->next[j])
                        if (fn(user, j)) return 1;
                }
            }
    }
    return 0;
}

static inline int vp_sgrid_query_near(const vp_sgrid *g, const double p[3], double reach,
                                      vp_sgrid_visit fn, void *user) {
    return vp_sgrid_query_near_from(g, p, reach, 0, fn, user);
}
#endif
