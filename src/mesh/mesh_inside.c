/* SPDX-License-Identifier: Apache-2.0 */
/* Preparing a mesh for the winding-number inside (see mesh.h,
 * vp_mesh_prepare_winding, and docs/design.md, "Inside of a mesh"):
 *  1. a triangle given twice counts once, and a triangle given with both
 *     orientations (a double wall, as two pieces glued face to face leave
 *     it) counts not at all: the winding number would add them;
 *  2. each connected piece gets one orientation: triangles whose neighbour
 *     across a two-triangle edge runs the other way are turned, the fewer
 *     side of each disagreement;
 *  3. an open piece is turned inside out as a whole when its own winding
 *     number behind its largest triangles says it faces inward (below
 *     0.25 where a piece facing outward has 0.5 to 1);
 *  4. a closed piece whose signed volume is negative is a cavity when it
 *     lies inside the rest of the mesh (the winding number of the other
 *     pieces at a point just inside it is at least 0.5: a hollow ball's
 *     reversed inner shell) and is kept so; elsewhere it is an inside-out
 *     piece and is turned. */
#include "mesh/mesh.h"
#include "core/mesh_topo.h"
#include "core/winding.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct tri_key {
    uint32_t v[3]; /* sorted corners */
    int32_t sign;  /* +1: the triangle's corner order is an even permutation of v */
    uint32_t tri;
} tri_key;

static int cmp_key(const void *pa, const void *pb)
{
    const tri_key *a = pa, *b = pb;
    for (int k = 0; k < 3; k++)
        if (a->v[k] != b->v[k]) return a->v[k] < b->v[k] ? -1 : 1;
    return (a->tri > b->tri) - (a->tri < b->tri);
}

/* Step 1: duplicates. Keeps one triangle of each group with the group's net
 * orientation, none where the orientations cancel. Returns the new count. */
static size_t drop_duplicates(vp_mesh *m, vp_mesh_repair *rep, int *oom)
{
    size_t nt = m->ntris;
    tri_key *k = malloc((nt ? nt : 1) * sizeof *k);
    uint8_t *keep = calloc(nt ? nt : 1, 1);
    if (!k || !keep) {
        free(k);
        free(keep);
        *oom = 1;
        return nt;
    }
    for (size_t t = 0; t < nt; t++) {
        uint32_t a = m->tris[3 * t], b = m->tris[3 * t + 1], c = m->tris[3 * t + 2];
        uint32_t v[3] = {a, b, c};
        int swaps = 0;
        for (int i = 0; i < 2; i++)
            for (int j = 0; j < 2 - i; j++)
                if (v[j] > v[j + 1]) {
                    uint32_t s = v[j];
                    v[j] = v[j + 1];
                    v[j + 1] = s;
                    swaps++;
                }
        memcpy(k[t].v, v, sizeof v);
        k[t].sign = swaps % 2 ? -1 : 1;
        k[t].tri = (uint32_t)t;
    }
    qsort(k, nt, sizeof *k, cmp_key);
    for (size_t i = 0; i < nt;) {
        size_t j = i;
        int net = 0;
        while (j < nt && !memcmp(k[j].v, k[i].v, sizeof k[i].v)) net += k[j++].sign;
        if (j - i == 1) {
            keep[k[i].tri] = 1;
        } else {
            /* the first triangle of the group with the net orientation */
            size_t pick = j;
            for (size_t q = i; q < j && net; q++)
                if (k[q].sign == (net > 0 ? 1 : -1)) {
                    pick = q;
                    break;
                }
            if (pick < j) keep[k[pick].tri] = 1;
            if (net) rep->duplicate_triangles += j - i - 1;
            else rep->opposite_triangles += j - i;
        }
        i = j;
    }
    size_t w = 0;
    for (size_t t = 0; t < nt; t++)
        if (keep[t]) memmove(m->tris + 3 * w++, m->tris + 3 * t, 3 * sizeof *m->tris);
    free(k);
    free(keep);
    return w;
}

static void flip_tri(uint32_t *t)
{
    uint32_t s = t[1];
    t[1] = t[2];
    t[2] = s;
}

/* Step 2: one orientation a piece, by a breadth-first walk across the
 * edges of exactly two triangles; labels each triangle with its piece
 * (0..npieces-1, in order of first triangle). Returns 0, or -1 when out of
 * memory. */
static int orient_pieces(vp_mesh *m, uint32_t *piece, size_t *npieces, vp_mesh_repair *rep)
{
    size_t nt = m->ntris, ne = 3 * nt;
    vp_edge_side *e = vp_edge_sides(m->tris, nt);
    /* for each triangle side, the other side of its edge when the edge has
     * exactly two (else UINT32_MAX) */
    uint32_t *mate = malloc((ne ? ne : 1) * sizeof *mate);
    uint32_t *queue = malloc((nt ? nt : 1) * sizeof *queue);
    uint8_t *flip = calloc(nt ? nt : 1, 1);
    if (!e || !mate || !queue || !flip) {
        free(e);
        free(mate);
        free(queue);
        free(flip);
        return -1;
    }
    for (size_t i = 0; i < ne; i++) mate[i] = UINT32_MAX;
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && e[j].key == e[i].key) j++;
        if (j - i == 2) {
            /* index sides as 3 * tri + side */
            uint32_t s0 = 3 * e[i].tri + e[i].side, s1 = 3 * e[i + 1].tri + e[i + 1].side;
            mate[s0] = s1;
            mate[s1] = s0;
        }
        i = j;
    }
    for (size_t t = 0; t < nt; t++) piece[t] = UINT32_MAX;
    size_t np = 0;
    for (size_t seed = 0; seed < nt; seed++) {
        if (piece[seed] != UINT32_MAX) continue;
        size_t head = 0, tail = 0, flipped = 0, members = 0;
        piece[seed] = (uint32_t)np;
        queue[tail++] = (uint32_t)seed;
        while (head < tail) {
            uint32_t t = queue[head++];
            members++;
            for (int s = 0; s < 3; s++) {
                uint32_t o = mate[3 * t + (uint32_t)s];
                if (o == UINT32_MAX) continue;
                uint32_t u = o / 3;
                /* t runs along the edge a -> b (after its own flip); a
                 * consistent neighbour runs b -> a */
                uint32_t a = m->tris[3 * t + (uint32_t)s],
                         b = m->tris[3 * t + ((uint32_t)s + 1) % 3];
                if (flip[t]) {
                    uint32_t x = a;
                    a = b;
                    b = x;
                }
                uint32_t ua = m->tris[o], ub = m->tris[3 * u + (o % 3 + 1) % 3];
                int same_way = (ua == a && ub == b);
                if (piece[u] == UINT32_MAX) {
                    piece[u] = (uint32_t)np;
                    flip[u] = (uint8_t)same_way;
                    flipped += flip[u];
                    queue[tail++] = u;
                }
            }
        }
        /* the fewer side of the piece turns */
        if (2 * flipped > members) {
            for (size_t i = 0; i < tail; i++) flip[queue[i]] ^= 1;
            flipped = members - flipped;
        }
        rep->reoriented_triangles += flipped;
        np++;
    }
    for (size_t t = 0; t < nt; t++)
        if (flip[t]) flip_tri(m->tris + 3 * t);
    *npieces = np;
    free(e);
    free(mate);
    free(queue);
    free(flip);
    return 0;
}

typedef struct piece_info {
    double volume;   /* signed, about the mesh's centre (x 6) */
    size_t boundary; /* sides with no partner (or more than one) */
    size_t largest;  /* its triangle of largest area */
    double largest_area;
    double lo[3], hi[3];
} piece_info;

typedef struct lo_key {
    double lo;
    uint32_t i;
} lo_key;

static int cmp_lo(const void *pa, const void *pb)
{
    const lo_key *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    return (a->i > b->i) - (a->i < b->i);
}

/* 1 when the bounding boxes of two pieces overlap: a sweep along x. */
static int boxes_overlap(const piece_info *pi, size_t np)
{
    if (np < 2) return 0;
    lo_key *order = malloc(np * sizeof *order);
    if (!order) return 1; /* assume the worst: the winding route is always right */
    for (size_t i = 0; i < np; i++) order[i] = (lo_key){pi[i].lo[0], (uint32_t)i};
    qsort(order, np, sizeof *order, cmp_lo);
    int hit = 0;
    for (size_t i = 0; i < np && !hit; i++) {
        const piece_info *a = &pi[order[i].i];
        for (size_t j = i + 1; j < np && !hit; j++) {
            const piece_info *b = &pi[order[j].i];
            if (b->lo[0] > a->hi[0]) break;
            hit = b->lo[1] <= a->hi[1] && a->lo[1] <= b->hi[1] && b->lo[2] <= a->hi[2] &&
                  a->lo[2] <= b->hi[2];
        }
    }
    free(order);
    return hit;
}

static void turn_piece(vp_mesh *m, const uint32_t *piece, uint32_t p)
{
    for (size_t t = 0; t < m->ntris; t++)
        if (piece[t] == p) flip_tri(m->tris + 3 * t);
}

/* The winding number of piece p's triangles at q (exact). */
static double piece_winding(const vp_mesh *m, const uint32_t *piece, uint32_t p, const double q[3])
{
    double w = 0;
    for (size_t t = 0; t < m->ntris; t++)
        if (piece[t] == p) w += vp_winding_exact(m->verts, m->tris + 3 * t, 1, q);
    return w;
}

/* A point just behind triangle t (off its centre, against its normal, by
 * eps). */
static void behind(const vp_mesh *m, size_t t, double eps, double q[3])
{
    const uint32_t *c = m->tris + 3 * t;
    const double *p0 = m->verts + 3 * (size_t)c[0], *p1 = m->verts + 3 * (size_t)c[1],
                 *p2 = m->verts + 3 * (size_t)c[2];
    double u[3], v[3], n[3];
    for (int k = 0; k < 3; k++) {
        u[k] = p1[k] - p0[k];
        v[k] = p2[k] - p0[k];
    }
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    double ln = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(ln > 0)) ln = 1;
    for (int k = 0; k < 3; k++) q[k] = (p0[k] + p1[k] + p2[k]) / 3.0 - eps * n[k] / ln;
}

/* Step 3's test: the median of the piece's own winding number behind its
 * (up to) 8 largest triangles, by a piece-sized step (a hundredth of its
 * bounding box's diagonal) so that the point is past the surface's local
 * detail. */
static int open_piece_inside_out(const vp_mesh *m, const uint32_t *piece, uint32_t p,
                                 const piece_info *info)
{
    enum { K = 8 };
    size_t best[K];
    double area[K];
    int nb = 0;
    for (size_t t = 0; t < m->ntris; t++) {
        if (piece[t] != p) continue;
        const uint32_t *c = m->tris + 3 * t;
        const double *p0 = m->verts + 3 * (size_t)c[0], *p1 = m->verts + 3 * (size_t)c[1],
                     *p2 = m->verts + 3 * (size_t)c[2];
        double u[3], v[3];
        for (int k = 0; k < 3; k++) {
            u[k] = p1[k] - p0[k];
            v[k] = p2[k] - p0[k];
        }
        double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2],
               z = u[0] * v[1] - u[1] * v[0];
        double a = x * x + y * y + z * z;
        if (nb == K && a <= area[K - 1]) continue;
        int at = nb < K ? nb++ : K - 1;
        while (at > 0 && area[at - 1] < a) {
            area[at] = area[at - 1];
            best[at] = best[at - 1];
            at--;
        }
        area[at] = a;
        best[at] = t;
    }
    double diag = 0;
    for (int k = 0; k < 3; k++) diag += (info->hi[k] - info->lo[k]) * (info->hi[k] - info->lo[k]);
    double w[K];
    for (int i = 0; i < nb; i++) {
        double q[3];
        behind(m, best[i], 0.01 * sqrt(diag), q);
        w[i] = piece_winding(m, piece, p, q);
    }
    for (int i = 1; i < nb; i++) /* sort for the median */
        for (int j = i; j > 0 && w[j] < w[j - 1]; j--) {
            double s = w[j];
            w[j] = w[j - 1];
            w[j - 1] = s;
        }
    return nb > 0 && w[nb / 2] < 0.25;
}

vp_result vp_mesh_prepare_winding(vp_mesh *m, vp_mesh_repair *rep)
{
    vp_mesh_repair local;
    if (!rep) rep = &local;
    memset(rep, 0, sizeof *rep);
    int oom = 0;
    m->ntris = drop_duplicates(m, rep, &oom);
    if (oom) return VP_ERR_OUT_OF_MEMORY;
    if (m->ntris == 0) return vp_mesh_recount(m);
    size_t nt = m->ntris, np = 0;
    uint32_t *piece = malloc(nt * sizeof *piece);
    if (!piece || orient_pieces(m, piece, &np, rep) != 0) {
        free(piece);
        return VP_ERR_OUT_OF_MEMORY;
    }
    rep->pieces = np;
    piece_info *pi = calloc(np, sizeof *pi);
    vp_edge_side *e = vp_edge_sides(m->tris, nt);
    if (!pi || !e) {
        free(piece);
        free(pi);
        free(e);
        return VP_ERR_OUT_OF_MEMORY;
    }
    double c[3];
    for (int k = 0; k < 3; k++) c[k] = 0.5 * (m->bmin[k] + m->bmax[k]);
    for (size_t p = 0; p < np; p++)
        for (int k = 0; k < 3; k++) {
            pi[p].lo[k] = HUGE_VAL;
            pi[p].hi[k] = -HUGE_VAL;
        }
    for (size_t t = 0; t < nt; t++) {
        piece_info *q = &pi[piece[t]];
        const double *p0 = m->verts + 3 * (size_t)m->tris[3 * t];
        const double *p1 = m->verts + 3 * (size_t)m->tris[3 * t + 1];
        const double *p2 = m->verts + 3 * (size_t)m->tris[3 * t + 2];
        double a[3], b[3], d[3];
        for (int k = 0; k < 3; k++) {
            a[k] = p0[k] - c[k];
            b[k] = p1[k] - c[k];
            d[k] = p2[k] - c[k];
            double lo = fmin(p0[k], fmin(p1[k], p2[k])), hi = fmax(p0[k], fmax(p1[k], p2[k]));
            if (lo < q->lo[k]) q->lo[k] = lo;
            if (hi > q->hi[k]) q->hi[k] = hi;
        }
        double x[3] = {(b[1] - a[1]) * (d[2] - a[2]) - (b[2] - a[2]) * (d[1] - a[1]),
                       (b[2] - a[2]) * (d[0] - a[0]) - (b[0] - a[0]) * (d[2] - a[2]),
                       (b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0])};
        double area = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        if (area > q->largest_area) {
            q->largest_area = area;
            q->largest = t;
        }
        q->volume += a[0] * (b[1] * d[2] - b[2] * d[1]) + a[1] * (b[2] * d[0] - b[0] * d[2]) +
                     a[2] * (b[0] * d[1] - b[1] * d[0]);
    }
    for (size_t i = 0; i < 3 * nt;) {
        size_t j = i + 1;
        while (j < 3 * nt && e[j].key == e[i].key) j++;
        if (j - i != 2)
            for (size_t q = i; q < j; q++) pi[piece[e[q].tri]].boundary++;
        i = j;
    }
    free(e);
    rep->pieces_overlap = boxes_overlap(pi, np);
    /* step 3: an open piece is turned only when it is clearly inside out:
     * its own winding number just behind its largest triangles (on the side
     * their normals point away from) is below 0.25, where a piece that
     * faces outward has it above 0.5 (a nearly closed piece: about 1) or
     * about 0.5 (a sheet, such as terrain, whose two sides the winding
     * number cannot tell apart: left as it is) */
    for (size_t p = 0; p < np; p++) {
        if (!pi[p].boundary) continue;
        rep->open_pieces++;
        if (open_piece_inside_out(m, piece, (uint32_t)p, &pi[p])) {
            turn_piece(m, piece, (uint32_t)p);
            pi[p].volume = -pi[p].volume;
            rep->turned_pieces++;
        }
    }
    /* step 4: closed pieces with a negative volume, largest first: a cavity
     * inside the rest, or an inside-out piece */
    size_t ncand = 0;
    uint32_t *cand = malloc(np * sizeof *cand);
    if (!cand) {
        free(piece);
        free(pi);
        return VP_ERR_OUT_OF_MEMORY;
    }
    for (size_t p = 0; p < np; p++)
        if (!pi[p].boundary && pi[p].volume < 0) cand[ncand++] = (uint32_t)p;
    for (size_t i = 1; i < ncand; i++) /* by volume, most negative first */
        for (size_t j = i; j > 0 && pi[cand[j]].volume < pi[cand[j - 1]].volume; j--) {
            uint32_t s = cand[j];
            cand[j] = cand[j - 1];
            cand[j - 1] = s;
        }
    vp_winding *all = ncand ? vp_winding_build(m->verts, m->nverts, m->tris, nt, NULL) : NULL;
    if (ncand && !all) {
        free(cand);
        free(piece);
        free(pi);
        return VP_ERR_OUT_OF_MEMORY;
    }
    size_t nturned = 0;
    uint32_t *turned = malloc((ncand ? ncand : 1) * sizeof *turned);
    for (size_t i = 0; i < ncand && turned; i++) {
        uint32_t p = cand[i];
        /* a point just inside the piece: off its largest triangle's centre
         * along its (inward, the piece being inside out) normal */
        const uint32_t *t = m->tris + 3 * pi[p].largest;
        const double *p0 = m->verts + 3 * (size_t)t[0], *p1 = m->verts + 3 * (size_t)t[1],
                     *p2 = m->verts + 3 * (size_t)t[2];
        double u[3], v[3], n[3], q[3];
        for (int k = 0; k < 3; k++) {
            u[k] = p1[k] - p0[k];
            v[k] = p2[k] - p0[k];
        }
        n[0] = u[1] * v[2] - u[2] * v[1];
        n[1] = u[2] * v[0] - u[0] * v[2];
        n[2] = u[0] * v[1] - u[1] * v[0];
        double ln = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double diag = 0;
        for (int k = 0; k < 3; k++)
            diag += (pi[p].hi[k] - pi[p].lo[k]) * (pi[p].hi[k] - pi[p].lo[k]);
        double eps = 1e-4 * sqrt(diag);
        for (int k = 0; k < 3; k++) q[k] = (p0[k] + p1[k] + p2[k]) / 3.0 + eps * n[k] / ln;
        /* the other pieces' winding number there: the whole mesh's, less
         * this piece's own (-1 inside it), corrected for pieces turned
         * before (each now adds twice what it took away) */
        double others = vp_winding_at(all, q) + 1.0;
        for (size_t j = 0; j < nturned; j++) others += 2.0 * piece_winding(m, piece, turned[j], q);
        if (others >= 0.5) {
            rep->cavities++;
        } else {
            turn_piece(m, piece, p);
            turned[nturned++] = p;
            rep->turned_pieces++;
        }
    }
    vp_winding_destroy(all);
    free(turned);
    free(cand);
    free(piece);
    free(pi);
    return vp_mesh_recount(m);
}

vp_result vp_mesh_hole_boxes(const vp_mesh *m, double **boxes, size_t *nboxes)
{
    *boxes = NULL;
    *nboxes = 0;
    if (!m->boundary_edges) return VP_OK;
    size_t ne = 3 * m->ntris;
    vp_edge_side *e = vp_edge_sides(m->tris, m->ntris);
    uint32_t *parent = malloc((m->nverts ? m->nverts : 1) * sizeof *parent);
    uint32_t *slot = malloc((m->nverts ? m->nverts : 1) * sizeof *slot);
    if (!e || !parent || !slot) {
        free(e);
        free(parent);
        free(slot);
        return VP_ERR_OUT_OF_MEMORY;
    }
    for (size_t v = 0; v < m->nverts; v++) {
        parent[v] = (uint32_t)v;
        slot[v] = UINT32_MAX;
    }
    /* the rims: vertices joined by boundary edges */
    uint8_t *on_rim = calloc(m->nverts ? m->nverts : 1, 1);
    if (!on_rim) {
        free(e);
        free(parent);
        free(slot);
        return VP_ERR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && e[j].key == e[i].key) j++;
        if (j - i == 1) {
            uint32_t a = (uint32_t)(e[i].key >> 32), b = (uint32_t)e[i].key;
            vp_uf_union(parent, a, b);
            on_rim[a] = on_rim[b] = 1;
        }
        i = j;
    }
    free(e);
    size_t n = 0;
    for (size_t v = 0; v < m->nverts; v++)
        if (on_rim[v] && vp_uf_find(parent, (uint32_t)v) == v) slot[v] = (uint32_t)n++;
    double *b = malloc((n ? n : 1) * 6 * sizeof *b);
    if (!b) {
        free(parent);
        free(slot);
        free(on_rim);
        return VP_ERR_OUT_OF_MEMORY;
    }
    for (size_t k = 0; k < n; k++)
        for (int a = 0; a < 3; a++) {
            b[6 * k + a] = HUGE_VAL;
            b[6 * k + 3 + a] = -HUGE_VAL;
        }
    for (size_t v = 0; v < m->nverts; v++) {
        if (!on_rim[v]) continue;
        double *x = b + 6 * (size_t)slot[vp_uf_find(parent, (uint32_t)v)];
        for (int a = 0; a < 3; a++) {
            x[a] = fmin(x[a], m->verts[3 * v + (size_t)a]);
            x[3 + a] = fmax(x[3 + a], m->verts[3 * v + (size_t)a]);
        }
    }
    /* the film spans its rim and bulges from it: half the rim's size each
     * way, within the mesh's bounds grown by a tenth of their diagonal (an
     * open sheet's inside reaches a little past them) */
    double md = 0;
    for (int a = 0; a < 3; a++) md += (m->bmax[a] - m->bmin[a]) * (m->bmax[a] - m->bmin[a]);
    md = 0.1 * sqrt(md);
    for (size_t k = 0; k < n; k++) {
        double *x = b + 6 * k, d = 0;
        for (int a = 0; a < 3; a++) d += (x[3 + a] - x[a]) * (x[3 + a] - x[a]);
        d = 0.5 * sqrt(d);
        for (int a = 0; a < 3; a++) {
            x[a] = fmax(x[a] - d, m->bmin[a] - md);
            x[3 + a] = fmin(x[3 + a] + d, m->bmax[a] + md);
        }
    }
    free(parent);
    free(slot);
    free(on_rim);
    *boxes = b;
    *nboxes = n;
    return VP_OK;
}

uint8_t *vp_mesh_rim_triangles(const vp_mesh *m)
{
    uint8_t *rim = calloc(m->ntris ? m->ntris : 1, 1);
    vp_edge_side *e = vp_edge_sides(m->tris, m->ntris);
    if (!rim || !e) {
        free(rim);
        free(e);
        return NULL;
    }
    size_t ne = 3 * m->ntris;
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && e[j].key == e[i].key) j++;
        if (j - i == 1) rim[e[i].tri] = 1;
        i = j;
    }
    free(e);
    return rim;
}
