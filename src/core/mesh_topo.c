/* SPDX-License-Identifier: Apache-2.0 */
/* Triangle-mesh topology (see mesh_topo.h). */
#include "core/mesh_topo.h"

#include <stdlib.h>

static int cmp_side(const void *pa, const void *pb) {
    const vp_edge_side *a = pa, *b = pb;
    if (a->key != b->key) return a->key < b->key ? -1 : 1;
    if (a->tri != b->tri) return a->tri < b->tri ? -1 : 1;
    return (a->side > b->side) - (a->side < b->side);
}

vp_edge_side *vp_edge_sides(const uint32_t *tris, size_t ntris) {
    size_t ne = 3 * ntris;
    vp_edge_side *e = malloc((ne ? ne : 1) * sizeof *e);
    if (!e) return NULL;
    for (size_t t = 0; t < ntris; ++t)
        for (int j = 0; j < 3; ++j) {
            uint32_t a = tris[3 * t + j], b = tris[3 * t + (j + 1) % 3];
            vp_edge_side *s = &e[3 * t + (size_t)j];
            s->forward = a < b;
            if (a > b) {
                uint32_t x = a;
                a = b;
                b = x;
            }
            s->key = ((uint64_t)a << 32) | b;
            s->tri = (uint32_t)t;
            s->side = (uint8_t)j;
        }
    qsort(e, ne, sizeof *e, cmp_side);
    return e;
}

uint32_t vp_uf_find(uint32_t *parent, uint32_t x) {
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

void vp_uf_union(uint32_t *parent, uint32_t a, uint32_t b) {
    a = vp_uf_find(parent, a);
    b = vp_uf_find(parent, b);
    if (a == b) return;
    if (a < b) parent[b] = a;
    else parent[a] = b;
}
