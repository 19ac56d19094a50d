/* SPDX-License-Identifier: Apache-2.0 */
/* Hierarchical cell grid for neighbour search; see sgrid.h. */
#include "core/sgrid.h"

#include "os/bigmem.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int level_alloc(vp_sgrid_level *L, const double lo[3], const double hi[3], double h,
                       size_t max_cells) {
    for (;;) {
        double cells = 1.0, dims[3];
        for (int k = 0; k < 3; k++) {
            double n = floor((hi[k] - lo[k]) / h) + 1.0;
            dims[k] = n < 1 ? 1 : n;
            cells *= dims[k];
        }
        if (cells <= (double)max_cells || cells <= 1.0) {
            /* converted once they fit: a tiny h over a long axis (a slab
             * 1e-20 thick sizes h by its radii) is far beyond int64 */
            for (int k = 0; k < 3; k++) L->dims[k] = (int64_t)dims[k];
            break;
        }
        h *= 1.25;
    }
    L->h = h;
    L->inv_h = 1.0 / h;
    size_t n = (size_t)(L->dims[0] * L->dims[1] * L->dims[2]);
    L->head = malloc(n * sizeof *L->head);
    if (!L->head) return -1;
    vp_mem_advise_random(L->head, n * sizeof *L->head);
    memset(L->head, 0xff, n * sizeof *L->head);
    L->rmax = 0.0;
    return 0;
}

int vp_sgrid_init(vp_sgrid *g, const double lo[3], const double hi[3], double rmin, double rmax,
                  size_t max_cells) {
    memset(g, 0, sizeof *g);
    if (!(rmin > 0)) rmin = rmax > 0 ? rmax : 1.0;
    if (!(rmax >= rmin)) rmax = rmin;
    memcpy(g->origin, lo, sizeof g->origin);
    if (max_cells < 64) max_cells = 64;
    /* level L holds radii up to h_L / 2, h_L = 2 rmin 2^L */
    int n = 1;
    while (n < VP_SGRID_MAX_LEVELS && 2.0 * rmin * ldexp(1.0, n - 1) < 2.0 * rmax) n++;
    g->nlevels = n;
    for (int l = 0; l < n; l++) {
        if (level_alloc(&g->lev[l], lo, hi, 2.0 * rmin * ldexp(1.0, l), max_cells) != 0) {
            vp_sgrid_free(g);
            return -1;
        }
    }
    return 0;
}

void vp_sgrid_free(vp_sgrid *g) {
    for (int l = 0; l < g->nlevels; l++) free(g->lev[l].head);
    free(g->next);
    free(g->level_of);
    memset(g, 0, sizeof *g);
}

void vp_sgrid_clear(vp_sgrid *g) {
    for (int l = 0; l < g->nlevels; l++) {
        vp_sgrid_level *L = &g->lev[l];
        memset(L->head, 0xff, (size_t)(L->dims[0] * L->dims[1] * L->dims[2]) * sizeof *L->head);
        L->rmax = 0.0;
    }
}

int vp_sgrid_reserve(vp_sgrid *g, size_t n) {
    if (n <= g->capacity) return 0;
    uint32_t *nx = realloc(g->next, n * sizeof *nx);
    if (!nx) return -1;
    g->next = nx;
    vp_mem_advise_random(nx, n * sizeof *nx);
    if (g->nlevels > 1) { /* one level: every particle is on it */
        uint8_t *lv = realloc(g->level_of, n);
        if (!lv) return -1;
        g->level_of = lv;
    }
    g->capacity = n;
    return 0;
}

int vp_sgrid_insert(vp_sgrid *g, uint32_t i, const double pos[3], double r) {
    if ((size_t)i >= g->capacity) {
        size_t cap = g->capacity ? g->capacity : 1024;
        while (cap <= (size_t)i) cap += cap / 2;
        if (vp_sgrid_reserve(g, cap) != 0) return -1;
    }
    int l = 0;
    while (l + 1 < g->nlevels && 2.0 * r > g->lev[l].h) l++;
    vp_sgrid_level *L = &g->lev[l];
    int64_t c[3];
    for (int k = 0; k < 3; k++) c[k] = vp_sgrid_cell_coord(L, pos[k], g->origin[k], k);
    size_t idx = (size_t)((c[2] * L->dims[1] + c[1]) * L->dims[0] + c[0]);
    g->next[i] = L->head[idx];
    L->head[idx] = i;
    if (g->level_of) g->level_of[i] = (uint8_t)l;
    if (r > L->rmax) L->rmax = r;
    return 0;
}

void vp_sgrid_grow(vp_sgrid *g, uint32_t i, double r) {
    vp_sgrid_level *L = &g->lev[g->level_of ? g->level_of[i] : 0];
    if (r > L->rmax) L->rmax = r;
}

/* Issues the hints for every row of cells a query of [lo, hi] with reach
 * reads (positions NULL: the rows; else their first particles). It walks
 * the rows as vp_sgrid_query_box does; a shared row walker would put a
 * call per row on the query's hot path. */
static void prefetch_rows(const vp_sgrid *g, const double lo[3], const double hi[3], double reach,
                          const char *positions, size_t stride) {
    for (int l = 0; l < g->nlevels; l++) {
        const vp_sgrid_level *L = &g->lev[l];
        int64_t a[3], b[3];
        if (!vp_sgrid_level_range(g, L, lo, hi, reach, a, b)) continue;
        for (int64_t z = a[2]; z <= b[2]; z++)
            for (int64_t y = a[1]; y <= b[1]; y++) {
                const uint32_t *row = L->head + (size_t)((z * L->dims[1] + y) * L->dims[0]);
                if (!positions) {
                    __builtin_prefetch(row + a[0]);
                    __builtin_prefetch(row + b[0]);
                    continue;
                }
                for (int64_t x = a[0]; x <= b[0]; x++) {
                    uint32_t j = row[x];
                    if (j == VP_SGRID_NONE) continue;
                    __builtin_prefetch(g->next + j);
                    __builtin_prefetch(positions + stride * (size_t)j);
                }
            }
    }
}

void vp_sgrid_prefetch_cells(const vp_sgrid *g, const double lo[3], const double hi[3],
                             double reach) {
    prefetch_rows(g, lo, hi, reach, NULL, 0);
}

void vp_sgrid_prefetch_items(const vp_sgrid *g, const double lo[3], const double hi[3],
                             double reach, const void *positions, size_t stride) {
    prefetch_rows(g, lo, hi, reach, positions, stride);
}

size_t vp_sgrid_bytes(const vp_sgrid *g) {
    size_t b = g->capacity * (sizeof(uint32_t) + (g->level_of ? 1 : 0));
    for (int l = 0; l < g->nlevels; l++)
        b += (size_t)(g->lev[l].dims[0] * g->lev[l].dims[1] * g->lev[l].dims[2]) * sizeof(uint32_t);
    return b;
}
