/* SPDX-License-Identifier: Apache-2.0 */
/* Welded triangle meshes, whatever they come from (see mesh.h): an
 * imported file (mesh.c, through Assimp) or arrays handed over in memory
 * (vp_mesh_from_arrays). Both weld by exact position and count the
 * topology here, so that a mesh gives the same container either way. No
 * Assimp in this file. */
#include "mesh/mesh.h"
#include "core/mesh_topo.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ */
/* Welding: open-addressing hash on the bit pattern of (x, y, z).     */

static uint64_t mix64(uint64_t h)
{
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ULL;
    h ^= h >> 33;
    return h;
}

static uint64_t hash_pos(const double p[3])
{
    uint64_t h = 0x9e3779b97f4a7c15ULL;
    for (int k = 0; k < 3; ++k) {
        uint64_t b;
        memcpy(&b, &p[k], sizeof b);
        h = mix64(h ^ b) + 0x9e3779b97f4a7c15ULL * (uint64_t)(k + 1);
    }
    return mix64(h);
}

/* 1 when the triangle's corners are collinear (zero area, to rounding). */
static int zero_area(const double *p0, const double *p1, const double *p2)
{
    double e1[3], e2[3], e3[3];
    for (int k = 0; k < 3; ++k) {
        e1[k] = p1[k] - p0[k];
        e2[k] = p2[k] - p0[k];
        e3[k] = p2[k] - p1[k];
    }
    double cx = e1[1] * e2[2] - e1[2] * e2[1];
    double cy = e1[2] * e2[0] - e1[0] * e2[2];
    double cz = e1[0] * e2[1] - e1[1] * e2[0];
    double area2 = sqrt(cx * cx + cy * cy + cz * cz);
    double l1 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    double l2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    double l3 = e3[0] * e3[0] + e3[1] * e3[1] + e3[2] * e3[2];
    double lmax = l1 > l2 ? l1 : l2;
    if (l3 > lmax) lmax = l3;
    return area2 <= 1e-12 * lmax;
}

/* Topology, bbox and volume of m (verts and tris already set; see
 * mesh.h). Returns VP_OK or VP_ERR_OUT_OF_MEMORY. */
vp_result vp_mesh_recount(vp_mesh *m)
{
    size_t nt = m->ntris, ne = 3 * nt;
    for (int k = 0; k < 3; ++k) {
        m->bmin[k] = HUGE_VAL;
        m->bmax[k] = -HUGE_VAL;
    }
    for (size_t i = 0; i < m->nverts; ++i)
        for (int k = 0; k < 3; ++k) {
            double v = m->verts[3 * i + k];
            if (v < m->bmin[k]) m->bmin[k] = v;
            if (v > m->bmax[k]) m->bmax[k] = v;
        }

    double c[3];
    for (int k = 0; k < 3; ++k) c[k] = 0.5 * (m->bmin[k] + m->bmax[k]);
    double vol = 0.0;
    for (size_t t = 0; t < nt; ++t) {
        const double *p0 = m->verts + 3 * (size_t)m->tris[3 * t];
        const double *p1 = m->verts + 3 * (size_t)m->tris[3 * t + 1];
        const double *p2 = m->verts + 3 * (size_t)m->tris[3 * t + 2];
        double a[3], b[3], d[3];
        for (int k = 0; k < 3; ++k) {
            a[k] = p0[k] - c[k];
            b[k] = p1[k] - c[k];
            d[k] = p2[k] - c[k];
        }
        vol += a[0] * (b[1] * d[2] - b[2] * d[1]) + a[1] * (b[2] * d[0] - b[0] * d[2]) +
               a[2] * (b[0] * d[1] - b[1] * d[0]);
    }
    m->signed_volume = vol / 6.0;

    vp_edge_side *edges = vp_edge_sides(m->tris, nt);
    uint32_t *parent = malloc((nt ? nt : 1) * sizeof *parent);
    if (!edges || !parent) {
        free(edges);
        free(parent);
        return VP_ERR_OUT_OF_MEMORY;
    }
    for (size_t t = 0; t < nt; ++t) parent[t] = (uint32_t)t;
    m->boundary_edges = m->nonmanifold_edges = m->inconsistent_edges = 0;
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && edges[j].key == edges[i].key) {
            vp_uf_union(parent, edges[i].tri, edges[j].tri);
            ++j;
        }
        if (j - i == 1) m->boundary_edges++;
        else if (j - i >= 3) m->nonmanifold_edges++;
        else if (edges[i].forward == edges[i + 1].forward)
            m->inconsistent_edges++; /* both triangles run the same way along it */
        i = j;
    }
    m->components = 0;
    for (size_t t = 0; t < nt; ++t)
        if (vp_uf_find(parent, (uint32_t)t) == t) m->components++;
    free(edges);
    free(parent);
    return VP_OK;
}


/* ------------------------------------------------------------------ */
/* The welder and the finished mesh (mesh.h).                          */

const char *vp_mesh_nonfinite_name(double v)
{
    if (isnan(v)) return "nan";
    return v > 0 ? "inf" : "-inf";
}

int vp_weld_init(vp_weld *w, size_t max_points)
{
    memset(w, 0, sizeof *w);
    w->cap = 16;
    while (w->cap < 2 * max_points) w->cap <<= 1;
    w->table = calloc(w->cap, sizeof *w->table);
    w->pos = malloc(3 * (max_points ? max_points : 1) * sizeof *w->pos);
    if (!w->table || !w->pos) {
        vp_weld_free(w);
        return -1;
    }
    return 0;
}

uint32_t vp_weld_add(vp_weld *w, const double p[3])
{
    double q[3] = {p[0] + 0.0, p[1] + 0.0, p[2] + 0.0}; /* -0.0 becomes +0.0 */
    size_t s = (size_t)hash_pos(q) & (w->cap - 1);
    for (;;) {
        uint32_t id = w->table[s];
        if (id == 0) {
            w->table[s] = (uint32_t)(w->n + 1);
            memcpy(w->pos + 3 * w->n, q, sizeof q);
            return (uint32_t)w->n++;
        }
        const double *e = w->pos + 3 * (size_t)(id - 1);
        if (e[0] == q[0] && e[1] == q[1] && e[2] == q[2]) return id - 1;
        s = (s + 1) & (w->cap - 1);
    }
}

void vp_weld_free(vp_weld *w)
{
    free(w->table);
    free(w->pos);
    memset(w, 0, sizeof *w);
}

vp_result vp_mesh_finish(vp_weld *w, uint32_t *tris, size_t ntri, size_t nraw,
                         size_t zero_area_tris, vp_mesh **out)
{
    *out = NULL;
    /* only the welded vertices that kept triangles use, in order of first
     * use */
    uint32_t *remap = malloc((w->n ? w->n : 1) * sizeof *remap);
    vp_mesh *m = calloc(1, sizeof *m);
    if (!remap || !m) {
        free(remap);
        free(m);
        free(tris);
        return VP_ERR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < w->n; ++i) remap[i] = UINT32_MAX;
    size_t nv = 0;
    for (size_t i = 0; i < 3 * ntri; ++i) {
        uint32_t o = tris[i];
        if (remap[o] == UINT32_MAX) remap[o] = (uint32_t)nv++;
        tris[i] = remap[o];
    }
    m->tris = tris;
    m->verts = malloc(3 * (nv ? nv : 1) * sizeof *m->verts);
    if (!m->verts) {
        free(remap);
        vp_mesh_destroy(m);
        return VP_ERR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < w->n; ++i)
        if (remap[i] != UINT32_MAX)
            memcpy(m->verts + 3 * (size_t)remap[i], w->pos + 3 * i, 3 * sizeof *w->pos);
    free(remap);
    m->nverts_raw = nraw;
    m->nverts = nv;
    m->ntris = ntri;
    m->zero_area_tris = zero_area_tris;
    for (size_t t = 0; t < ntri; ++t)
        m->zero_area_tris += (size_t)zero_area(m->verts + 3 * (size_t)tris[3 * t],
                                               m->verts + 3 * (size_t)tris[3 * t + 1],
                                               m->verts + 3 * (size_t)tris[3 * t + 2]);
    vp_result r = vp_mesh_recount(m);
    if (r != VP_OK) {
        vp_mesh_destroy(m);
        return r;
    }
    *out = m;
    return VP_OK;
}

static vp_result arrays_fail(char *err, size_t errlen, vp_result r, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 4, 5)))
#endif
    ;
static vp_result arrays_fail(char *err, size_t errlen, vp_result r, const char *fmt, ...)
{
    if (err && errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return r;
}

vp_result vp_mesh_from_arrays(const double *verts, size_t nverts, const uint32_t *tris,
                              size_t ntris, const char *name, vp_mesh **out, char *err,
                              size_t errlen)
{
    if (err && errlen) err[0] = '\0';
    if (!name || !*name) name = "mesh";
    if (!out) return arrays_fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "%s: out is NULL", name);
    *out = NULL;
    if (nverts == 0 || ntris == 0)
        return arrays_fail(err, errlen, VP_ERR_FORMAT,
                           "%s: no triangles (%zu vertices, %zu triangles given)", name, nverts,
                           ntris);
    if (!verts)
        return arrays_fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                           "%s: vertices is NULL (%zu vertices claimed)", name, nverts);
    if (!tris)
        return arrays_fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                           "%s: triangles is NULL (%zu triangles claimed)", name, ntris);
    if ((uintptr_t)verts % _Alignof(double) != 0)
        return arrays_fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                           "%s: vertices is not aligned for double (address %p)", name,
                           (const void *)verts);
    if ((uintptr_t)tris % _Alignof(uint32_t) != 0)
        return arrays_fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                           "%s: triangles is not aligned for uint32_t (address %p)", name,
                           (const void *)tris);
    if (nverts >= UINT32_MAX / 2 || ntris >= UINT32_MAX / 3)
        return arrays_fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                           "%s: too many vertices or triangles (%zu, %zu; at most %u)", name,
                           nverts, ntris, UINT32_MAX / 3 - 1);
    for (size_t v = 0; v < nverts; ++v) {
        const double *c = verts + 3 * v;
        for (int k = 0; k < 3; ++k)
            if (!isfinite(c[k]))
                return arrays_fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                                   "%s: vertex %zu has a non-finite coordinate (%s) at (%g, %g, "
                                   "%g)",
                                   name, v, vp_mesh_nonfinite_name(c[k]), c[0], c[1], c[2]);
    }
    for (size_t t = 0; t < ntris; ++t)
        for (int j = 0; j < 3; ++j)
            if (tris[3 * t + j] >= nverts)
                return arrays_fail(err, errlen, VP_ERR_INVALID_ARGUMENT,
                                   "%s: triangle %zu has vertex index %u, out of range (there "
                                   "are %zu vertices, indexed from 0)",
                                   name, t, tris[3 * t + j], nverts);
    vp_weld w;
    uint32_t *wid = malloc(nverts * sizeof *wid);
    uint32_t *kept = malloc(3 * ntris * sizeof *kept);
    if (!wid || !kept || vp_weld_init(&w, nverts) != 0) {
        free(wid);
        free(kept);
        return arrays_fail(err, errlen, VP_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    for (size_t v = 0; v < nverts; ++v) wid[v] = vp_weld_add(&w, verts + 3 * v);
    size_t nkept = 0, zero = 0;
    for (size_t t = 0; t < ntris; ++t) {
        uint32_t a = wid[tris[3 * t]], b = wid[tris[3 * t + 1]], c = wid[tris[3 * t + 2]];
        if (a == b || b == c || a == c) {
            ++zero; /* collapsed by welding, as a file's would be */
            continue;
        }
        kept[3 * nkept] = a;
        kept[3 * nkept + 1] = b;
        kept[3 * nkept + 2] = c;
        ++nkept;
    }
    free(wid);
    if (nkept == 0) {
        vp_weld_free(&w);
        free(kept);
        return arrays_fail(err, errlen, VP_ERR_FORMAT,
                           "%s: no triangles (all %zu are degenerate after welding)", name, ntris);
    }
    vp_result r = vp_mesh_finish(&w, kept, nkept, nverts, zero, out);
    vp_weld_free(&w);
    if (r != VP_OK) return arrays_fail(err, errlen, r, "%s: out of memory", name);
    return VP_OK;
}
