/* SPDX-License-Identifier: Apache-2.0 */
/* Mesh input through Assimp's C API (see mesh.h).
 *
 * Files are imported with NO Assimp post-processing (flags 0); this file
 * does the rest itself:
 *  - node transforms are applied to each mesh instance (what
 *    aiProcess_PreTransformVertices does; an instance with a mirroring
 *    transform has its winding reversed so it stays outward);
 *  - polygons are triangulated by ear clipping in the plane of their Newell
 *    normal (aiProcess_Triangulate's job), with a fan as the fallback;
 *  - points and lines are skipped (what aiProcess_SortByPType would help
 *    with);
 *  - vertices are welded by exact position (not JoinIdenticalVertices, which
 *    would also compare normals and UVs), degenerate triangles are counted,
 *    and non-finite coordinates are refused (not FindDegenerates or
 *    FindInvalidData, which alter geometry silently).
 * Why not let Assimp post-process: the packaged Assimp 5.2.5 has internal
 * assertions enabled that abort() the process (TriangulateProcess asserts
 * on meshes whose mPrimitiveTypes claims polygons it has not, which its OFF
 * and OBJ readers make from malformed input), and aiApplyPostProcessing's
 * failure path releases an already-freed scene. Malformed input must give
 * an error, never a crash.
 *
 * Assimp is built here with single-precision ai_real, so coordinates arrive
 * as float and are widened to double (transforms are applied in double);
 * two distinct decimal values that round to the same float are welded. No
 * Assimp logger is attached, so Assimp prints nothing. */
#include "mesh/mesh.h"
#include "mesh/isolate.h"
#include "os/input.h"
#include "os/text.h"

#include <assimp/cimport.h>
#include <assimp/scene.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>


static void set_err(char *err, size_t errlen, const char *fmt, const char *name, const char *detail)
{
    if (!err || errlen == 0) return;
    vp_os_format(err, errlen, fmt, name, detail);
    /* One line: replace any newline in Assimp's message. */
    for (char *c = err; *c; ++c)
        if (*c == '\n' || *c == '\r') *c = ' ';
}

/* ------------------------------------------------------------------ */
/* Scene to welded mesh.                                               */

/* A mesh placed in the world by a node: Assimp's aiProcess_PreTransformVertices,
 * done here (see the comment at the top). */
typedef struct instance {
    const struct aiMesh *mesh;
    double m[12]; /* rows of the 3x4 affine part */
    int flip;     /* negative determinant: reverse the winding */
} instance;

typedef struct inst_list {
    instance *v;
    size_t n, cap;
    int overflow;
} inst_list;

#define VP_MESH_MAX_DEPTH 256
#define VP_MESH_MAX_INSTANCES (1u << 20)

static void mat_mul(const double a[12], const double b[12], double out[12])
{
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) {
            double s = a[4 * r + 0] * b[c] + a[4 * r + 1] * b[4 + c] + a[4 * r + 2] * b[8 + c];
            if (c == 3) s += a[4 * r + 3];
            out[4 * r + c] = s;
        }
    }
}

static void walk_nodes(const struct aiScene *sc, const struct aiNode *nd, const double parent[12],
                       int depth, inst_list *L)
{
    if (!nd || depth > VP_MESH_MAX_DEPTH || L->overflow) return;
    const struct aiMatrix4x4 *t = &nd->mTransformation;
    double local[12] = {t->a1, t->a2, t->a3, t->a4, t->b1, t->b2,
                        t->b3, t->b4, t->c1, t->c2, t->c3, t->c4};
    double world[12];
    mat_mul(parent, local, world);
    if (nd->mMeshes) {
        for (unsigned i = 0; i < nd->mNumMeshes; ++i) {
            unsigned mi = nd->mMeshes[i];
            if (mi >= sc->mNumMeshes || !sc->mMeshes[mi]) continue;
            if (L->n == L->cap) {
                size_t nc = L->cap ? 2 * L->cap : 16;
                if (nc > VP_MESH_MAX_INSTANCES) {
                    L->overflow = 1;
                    return;
                }
                instance *nv = realloc(L->v, nc * sizeof *nv);
                if (!nv) {
                    L->overflow = 1;
                    return;
                }
                L->v = nv;
                L->cap = nc;
            }
            instance *in = &L->v[L->n++];
            in->mesh = sc->mMeshes[mi];
            memcpy(in->m, world, sizeof world);
            double det = world[0] * (world[5] * world[10] - world[6] * world[9]) -
                         world[1] * (world[4] * world[10] - world[6] * world[8]) +
                         world[2] * (world[4] * world[9] - world[5] * world[8]);
            in->flip = det < 0;
        }
    }
    if (nd->mChildren)
        for (unsigned i = 0; i < nd->mNumChildren; ++i)
            walk_nodes(sc, nd->mChildren[i], world, depth + 1, L);
}

/* Faces this mesh contributes (>= 3 corners, all indices valid). */
static int face_usable(const struct aiMesh *am, const struct aiFace *fc)
{
    if (fc->mNumIndices < 3 || !fc->mIndices) return 0;
    for (unsigned k = 0; k < fc->mNumIndices; ++k)
        if (fc->mIndices[k] >= am->mNumVertices) return 0;
    return 1;
}

static int mesh_usable(const struct aiMesh *am)
{
    return am && am->mVertices && am->mFaces && am->mNumFaces > 0 && am->mNumVertices > 0;
}

/* Ear clipping of one polygon (n corners, positions pos[idx[k]]), projected
 * on the plane of its Newell normal. Writes n-2 triangles of corner numbers
 * (0..n-1) to out. Falls back to a fan for what it cannot clip (degenerate
 * or self-intersecting polygons) and for very large polygons. work: 3n
 * doubles + n ints of scratch. */
#define VP_MESH_EARCLIP_MAX 1024

static double cross2(const double *a, const double *b, const double *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

static void triangulate_polygon(const double *pos, const unsigned *idx, unsigned n, uint32_t *out,
                                double *xy, unsigned *ring)
{
    size_t w = 0;
    if (n > VP_MESH_EARCLIP_MAX) goto fan_all;
    double nn[3] = {0, 0, 0};
    for (unsigned k = 0; k < n; ++k) {
        const double *a = pos + 3 * (size_t)idx[k], *b = pos + 3 * (size_t)idx[(k + 1) % n];
        nn[0] += (a[1] - b[1]) * (a[2] + b[2]);
        nn[1] += (a[2] - b[2]) * (a[0] + b[0]);
        nn[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    int ax = 0;
    if (fabs(nn[1]) > fabs(nn[ax])) ax = 1;
    if (fabs(nn[2]) > fabs(nn[ax])) ax = 2;
    if (!(fabs(nn[ax]) > 0)) goto fan_all;
    int u = (ax + 1) % 3, v = (ax + 2) % 3;
    if (nn[ax] < 0) {
        int s = u;
        u = v;
        v = s;
    } /* keep the polygon counter-clockwise */
    for (unsigned k = 0; k < n; ++k) {
        xy[2 * k] = pos[3 * (size_t)idx[k] + u];
        xy[2 * k + 1] = pos[3 * (size_t)idx[k] + v];
        ring[k] = k;
    }
    unsigned m = n;
    unsigned start = 0;
    while (m > 3) {
        int clipped = 0;
        for (unsigned t = 0; t < m; ++t) {
            unsigned i = (start + t) % m;
            unsigned ip = ring[(i + m - 1) % m], ic = ring[i], in = ring[(i + 1) % m];
            const double *a = xy + 2 * ip, *b = xy + 2 * ic, *c = xy + 2 * in;
            if (!(cross2(a, b, c) > 0)) continue;
            int ear = 1;
            for (unsigned j = 0; j < m && ear; ++j) {
                unsigned q = ring[j];
                if (q == ip || q == ic || q == in) continue;
                const double *p = xy + 2 * q;
                if ((p[0] == a[0] && p[1] == a[1]) || (p[0] == b[0] && p[1] == b[1]) ||
                    (p[0] == c[0] && p[1] == c[1]))
                    continue;
                if (cross2(a, b, p) >= 0 && cross2(b, c, p) >= 0 && cross2(c, a, p) >= 0) ear = 0;
            }
            if (!ear) continue;
            out[w++] = ip;
            out[w++] = ic;
            out[w++] = in;
            memmove(ring + i, ring + i + 1, (m - i - 1) * sizeof *ring);
            --m;
            start = i % m;
            clipped = 1;
            break;
        }
        if (!clipped) break;
    }
    /* The rest (a triangle, or what could not be clipped) as a fan. */
    for (unsigned k = 1; k + 1 < m; ++k) {
        out[w++] = ring[0];
        out[w++] = ring[k];
        out[w++] = ring[k + 1];
    }
    return;
fan_all:
    for (unsigned k = 1; k + 1 < n; ++k) {
        out[w++] = 0;
        out[w++] = k;
        out[w++] = k + 1;
    }
}

/* The scene's mesh instances (node transforms applied), or those of the
 * mesh list when the scene has no node tree. */
static void collect_instances(const struct aiScene *sc, inst_list *L)
{
    static const double identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    if (sc->mRootNode) {
        walk_nodes(sc, sc->mRootNode, identity, 0, L);
        return;
    }
    for (unsigned i = 0; i < sc->mNumMeshes && !L->overflow; ++i) {
        if (!sc->mMeshes[i]) continue;
        if (L->n == L->cap) {
            size_t nc = L->cap ? 2 * L->cap : 16;
            instance *nv = realloc(L->v, nc * sizeof *nv);
            if (!nv) {
                L->overflow = 1;
                break;
            }
            L->v = nv;
            L->cap = nc;
        }
        L->v[L->n].mesh = sc->mMeshes[i];
        memcpy(L->v[L->n].m, identity, sizeof identity);
        L->v[L->n++].flip = 0;
    }
}

/* Sizes of what the instances contribute: vertices, triangles (a polygon
 * of n corners gives n - 2), the largest polygon and mesh. */
typedef struct scene_counts {
    size_t nraw, ntri_max, maxverts;
    unsigned maxpoly;
} scene_counts;

static int instance_has_faces(const struct aiMesh *am)
{
    if (!mesh_usable(am)) return 0;
    for (unsigned f = 0; f < am->mNumFaces; ++f)
        if (face_usable(am, &am->mFaces[f])) return 1;
    return 0;
}

static scene_counts count_scene(const inst_list *L)
{
    scene_counts n = {0, 0, 0, 0};
    for (size_t i = 0; i < L->n; ++i) {
        const struct aiMesh *am = L->v[i].mesh;
        if (!mesh_usable(am)) continue;
        size_t t = 0;
        for (unsigned f = 0; f < am->mNumFaces; ++f)
            if (face_usable(am, &am->mFaces[f])) {
                t += am->mFaces[f].mNumIndices - 2;
                if (am->mFaces[f].mNumIndices > n.maxpoly) n.maxpoly = am->mFaces[f].mNumIndices;
            }
        if (t == 0) continue;
        n.nraw += am->mNumVertices;
        n.ntri_max += t;
        if (am->mNumVertices > n.maxverts) n.maxverts = am->mNumVertices;
    }
    return n;
}

/* Scratch of weld_instances, sized by count_scene. */
typedef struct scene_scratch {
    double *raw;     /* world positions of the current instance */
    uint32_t *wid;   /* raw vertex -> welded id */
    uint32_t *ptris; /* polygon triangulation */
    double *pxy;
    unsigned *pring;
} scene_scratch;

/* Transforms, checks and welds every instance's vertices and triangulates
 * its faces into tris (welded ids); *ntri and *zero count the triangles
 * kept and those collapsed by welding. VP_OK or VP_ERR_FORMAT (a
 * non-finite coordinate, named in err). */
static vp_result weld_instances(const inst_list *L, const char *name, vp_weld *w, scene_scratch *x,
                                uint32_t *tris, size_t *ntri, size_t *zero, char *err,
                                size_t errlen)
{
    size_t base = 0;
    for (size_t i = 0; i < L->n; ++i) {
        const struct aiMesh *am = L->v[i].mesh;
        const double *M = L->v[i].m;
        if (!instance_has_faces(am)) continue;
        for (unsigned v = 0; v < am->mNumVertices; ++v) {
            double q[3] = {am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z};
            double p[3];
            for (int k = 0; k < 3; ++k)
                p[k] = M[4 * k] * q[0] + M[4 * k + 1] * q[1] + M[4 * k + 2] * q[2] + M[4 * k + 3];
            /* As read first (a NaN spreads to all three through the
             * transform), then as placed in the world. */
            for (int pass = 0; pass < 2; ++pass) {
                const double *c = pass ? p : q;
                for (int k = 0; k < 3; ++k) {
                    if (isfinite(c[k])) continue;
                    if (err && errlen)
                        snprintf(
                            err, errlen,
                            "%s: vertex %zu has a non-finite coordinate (%s) at (%g, %g, %g)%s",
                            name, base + v, vp_mesh_nonfinite_name(c[k]), c[0], c[1], c[2],
                            pass ? " after its node's transform" : "");
                    return VP_ERR_FORMAT;
                }
            }
            memcpy(x->raw + 3 * (size_t)v, p, sizeof p);
            x->wid[v] = vp_weld_add(w, p);
        }
        for (unsigned f = 0; f < am->mNumFaces; ++f) {
            const struct aiFace *fc = &am->mFaces[f];
            if (!face_usable(am, fc)) continue;
            unsigned n = fc->mNumIndices;
            if (n == 3) {
                x->ptris[0] = 0;
                x->ptris[1] = 1;
                x->ptris[2] = 2;
            } else {
                triangulate_polygon(x->raw, fc->mIndices, n, x->ptris, x->pxy, x->pring);
            }
            for (unsigned t = 0; t < n - 2; ++t) {
                uint32_t c[3];
                for (int j = 0; j < 3; ++j) c[j] = x->wid[fc->mIndices[x->ptris[3 * t + j]]];
                if (L->v[i].flip) {
                    uint32_t s = c[1];
                    c[1] = c[2];
                    c[2] = s;
                }
                if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) {
                    ++*zero;
                    continue;
                }
                memcpy(tris + 3 * *ntri, c, sizeof c);
                ++*ntri;
            }
        }
        base += am->mNumVertices;
    }
    return VP_OK;
}

/* The scene's mesh instances (into L, whose array the caller frees) and
 * their counts, checked: VP_ERR_FORMAT when there is no triangle,
 * VP_ERR_OUT_OF_MEMORY when there are too many instances, vertices or
 * triangles (named in err). */
static vp_result gather_scene(const struct aiScene *sc, const char *name, inst_list *L,
                              scene_counts *n, char *err, size_t errlen)
{
    if (!sc || !sc->mMeshes || sc->mNumMeshes == 0) {
        set_err(err, errlen, "%s: %s", name, "no triangles in the file (no mesh in the scene)");
        return VP_ERR_FORMAT;
    }
    collect_instances(sc, L);
    if (L->overflow) {
        set_err(err, errlen, "%s: %s", name, "too many mesh instances in the scene");
        return VP_ERR_OUT_OF_MEMORY;
    }
    *n = count_scene(L);
    if (n->ntri_max == 0) {
        set_err(err, errlen, "%s: %s", name,
                "no triangles in the file (no face with 3 or more corners)");
        return VP_ERR_FORMAT;
    }
    if (n->nraw >= UINT32_MAX / 2 || n->ntri_max >= UINT32_MAX / 3) {
        set_err(err, errlen, "%s: %s", name, "too many vertices or triangles");
        return VP_ERR_OUT_OF_MEMORY;
    }
    return VP_OK;
}

/* weld_instances' scratch, its triangle array (*tris) and the welder, for
 * the counts n; VP_ERR_OUT_OF_MEMORY ("out of memory" in err) when any
 * fails. The caller frees them (free_scratch, free, vp_weld_free) either
 * way. */
static vp_result alloc_scratch(const scene_counts *n, const char *name, scene_scratch *x,
                               uint32_t **tris, vp_weld *w, char *err, size_t errlen)
{
    x->raw = malloc(3 * n->maxverts * sizeof *x->raw);
    x->wid = malloc(n->maxverts * sizeof *x->wid);
    x->ptris = malloc(3 * (size_t)n->maxpoly * sizeof *x->ptris);
    x->pxy = malloc(2 * (size_t)n->maxpoly * sizeof *x->pxy);
    x->pring = malloc((size_t)n->maxpoly * sizeof *x->pring);
    *tris = malloc(3 * n->ntri_max * sizeof **tris);
    if (!x->raw || !x->wid || !x->ptris || !x->pxy || !x->pring || !*tris ||
        vp_weld_init(w, n->nraw) != 0) {
        set_err(err, errlen, "%s: %s", name, "out of memory");
        return VP_ERR_OUT_OF_MEMORY;
    }
    return VP_OK;
}

static void free_scratch(scene_scratch *x)
{
    free(x->raw);
    free(x->wid);
    free(x->ptris);
    free(x->pxy);
    free(x->pring);
}

/* The ntri welded triangles as one mesh (the shared finish, mesh_build.c):
 * VP_ERR_FORMAT when welding left none. Takes tris (*tris becomes NULL)
 * once there is a triangle. */
static vp_result finish_mesh(vp_weld *w, uint32_t **tris, size_t ntri, size_t nraw, size_t zero,
                             const char *name, vp_mesh **out, char *err, size_t errlen)
{
    if (ntri == 0) {
        set_err(err, errlen, "%s: %s", name,
                "no triangles in the file (all degenerate after welding)");
        return VP_ERR_FORMAT;
    }
    {
        uint32_t *shrunk = realloc(*tris, 3 * ntri * sizeof **tris);
        if (shrunk) *tris = shrunk;
    }
    vp_result res = vp_mesh_finish(w, *tris, ntri, nraw, zero, out);
    *tris = NULL; /* owned by the mesh, or freed */
    if (res != VP_OK) set_err(err, errlen, "%s: %s", name, "out of memory");
    return res;
}

/* The scene as one welded mesh: its instances and counts, scratch,
 * welding and triangulation, then the shared finish. */
static vp_result build_mesh(const struct aiScene *sc, const char *name, vp_mesh **out, char *err,
                            size_t errlen)
{
    inst_list L = {0};
    scene_counts n = {0, 0, 0, 0};
    vp_weld w = {0};
    scene_scratch x = {0};
    uint32_t *tris = NULL;
    size_t ntri = 0, zero = 0;
    *out = NULL;

    vp_result res = gather_scene(sc, name, &L, &n, err, errlen);
    if (res == VP_OK) res = alloc_scratch(&n, name, &x, &tris, &w, err, errlen);
    if (res == VP_OK) res = weld_instances(&L, name, &w, &x, tris, &ntri, &zero, err, errlen);
    if (res == VP_OK) res = finish_mesh(&w, &tris, ntri, n.nraw, zero, name, out, err, errlen);

    free(L.v);
    free_scratch(&x);
    free(tris);
    vp_weld_free(&w);
    return res;
}

static vp_result import_failed(const char *name, char *err, size_t errlen);

/* Checks Assimp is known to get wrong on hostile input, run on the first
 * bytes of the file before Assimp sees it. Assimp 5.2's PLY reader loops
 * forever on a PLY header without an end_header line. */
#define VP_MESH_PRECHECK_BYTES (1u << 20)

static int starts_with_ci(const unsigned char *d, size_t n, const char *word)
{
    size_t k = strlen(word);
    if (n < k) return 0;
    for (size_t i = 0; i < k; ++i) {
        unsigned char c = d[i];
        if (c >= 'A' && c <= 'Z') c = (unsigned char)(c - 'A' + 'a');
        if (c != (unsigned char)word[i]) return 0;
    }
    return 1;
}

/* Bytes of a PLY scalar type, 0 if unknown. */
static int ply_type_size(const char *t)
{
    static const char *const one[] = {"char", "uchar", "int8", "uint8"};
    static const char *const two[] = {"short", "ushort", "int16", "uint16"};
    static const char *const four[] = {"int", "uint", "int32", "uint32", "float", "float32"};
    for (size_t i = 0; i < 4; ++i)
        if (!strcmp(t, one[i])) return 1;
    for (size_t i = 0; i < 4; ++i)
        if (!strcmp(t, two[i])) return 2;
    for (size_t i = 0; i < 6; ++i)
        if (!strcmp(t, four[i])) return 4;
    if (!strcmp(t, "double") || !strcmp(t, "float64")) return 8;
    return 0;
}

/* The elements a PLY header (d[0..hend), end_header's line included)
 * declares against the bytes that follow it: Assimp 5.2 allocates what
 * "element vertex 200000000" claims before it reads any of it (2.3 GB for
 * a 360-byte file), so a header that claims more data than the file holds
 * is refused here. Each element takes at least its properties' bytes
 * (binary; a list at least its count) or two characters a value (ASCII:
 * the value and a separator, one less at the end). VP_OK when the data can
 * fit or the header cannot be understood (Assimp then says what is
 * wrong). */
static vp_result ply_claims(const unsigned char *d, size_t hend, size_t total, const char *name,
                            char *err, size_t errlen)
{
    int ascii = -1;
    double need = 0, count = 0, per = 0; /* the element being read */
    char big[33] = "";
    double big_count = 0;
    size_t i = 0;
    while (i < hend) {
        size_t e = i;
        while (e < hend && d[e] != '\n') ++e;
        char line[256];
        size_t len = e - i < sizeof line - 1 ? e - i : sizeof line - 1;
        memcpy(line, d + i, len);
        line[len] = 0;
        i = e + 1;
        char w0[32] = "", w1[40] = "", w2[32] = "", w3[32] = "";
        int nw = sscanf(line, "%31s %39s %31s %31s", w0, w1, w2, w3);
        if (nw >= 2 && !strcmp(w0, "format")) {
            ascii = !strcmp(w1, "ascii") ? 1 : 0;
        } else if (nw >= 3 && !strcmp(w0, "element")) {
            need += count * per;
            char *end = NULL;
            count = strtod(w2, &end);
            if (!end || *end || !(count >= 0)) return VP_OK;
            per = 0;
            if (count > big_count) {
                big_count = count;
                snprintf(big, sizeof big, "%s", w1);
            }
        } else if (nw >= 3 && !strcmp(w0, "property")) {
            int sz = ply_type_size(!strcmp(w1, "list") ? w2 : w1);
            if (!sz || ascii < 0) return VP_OK;
            per += ascii ? 2 : sz;
        }
    }
    need += count * per;
    if (ascii == 1 && need > 0) need -= 1; /* the last value needs no separator */
    size_t have = total > hend ? total - hend : 0;
    if (need <= (double)have) return VP_OK;
    if (err && errlen)
        vp_os_format(err, errlen,
                     "%s: not a mesh file Assimp can read (its PLY header declares %.0f '%s' "
                     "elements, at least %.3g bytes of data in all, but %zu bytes follow the "
                     "header: the file is truncated or corrupt)",
                     name, big_count, big, need, have);
    return VP_ERR_FORMAT;
}

/* n: the bytes scanned (the first VP_MESH_PRECHECK_BYTES at most), total:
 * the file's size. */
static vp_result precheck(const unsigned char *d, size_t n, size_t total, const char *name,
                          char *err, size_t errlen)
{
    size_t i = 0;
    while (i < n && (d[i] == ' ' || d[i] == '\t' || d[i] == '\r' || d[i] == '\n')) ++i;
    if (starts_with_ci(d + i, n - i, "ply")) {
        static const char tag[] = "end_header";
        size_t k = sizeof tag - 1;
        for (size_t j = i; j + k <= n; ++j)
            if (d[j] == 'e' && memcmp(d + j, tag, k) == 0) {
                size_t hend = j + k;
                while (hend < n && d[hend] != '\n') ++hend;
                return ply_claims(d, hend < n ? hend + 1 : n, total, name, err, errlen);
            }
        set_err(err, errlen, "%s: not a mesh file Assimp can read (%s)", name,
                "PLY header without an end_header line");
        return VP_ERR_FORMAT;
    }
    return VP_OK;
}

static vp_result finish_import(const struct aiScene *sc, const char *name, vp_mesh **out, char *err,
                               size_t errlen)
{
    vp_result r = build_mesh(sc, name, out, err, errlen);
    aiReleaseImport(sc);
    return r;
}

static vp_result import_failed(const char *name, char *err, size_t errlen)
{
    const char *msg = aiGetErrorString();
    set_err(err, errlen, "%s: not a mesh file Assimp can read (%s)", name,
            (msg && *msg) ? msg : "unknown error");
    return VP_ERR_FORMAT;
}

static int has_suffix_ci(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && starts_with_ci((const unsigned char *)s + n - k, k, suffix);
}

/* Assimp's OBJ reader makes one vertex per face corner, so the index that
 * build_mesh names is not the file's: this finds the first `v` line of an
 * OBJ file with a coordinate that is not finite as a float (Assimp reads
 * floats: 1e39 is inf there) and names it as the file does (vertex K is
 * what `f` lines call K, counting from 1). Returns 0 when none is found. */
static int obj_nonfinite_vertex(const char *path, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    char *line = NULL;
    size_t cap = 0, lineno = 0, vert = 0;
    ssize_t len;
    int found = 0;
    while (!found && (len = getline(&line, &cap, f)) >= 0) {
        ++lineno;
        const char *c = line;
        while (*c == ' ' || *c == '\t') ++c;
        if (c[0] != 'v' || (c[1] != ' ' && c[1] != '\t')) continue;
        ++vert;
        c += 1;
        for (int k = 0; k < 3 && !found; ++k) {
            char *end;
            double x = strtod(c, &end);
            if (end == c) break;
            if (!isfinite((float)x)) {
                while (len > 0 && (line[len - 1] == '\n' || line[len - 1] == '\r'))
                    line[--len] = '\0';
                snprintf(err, errlen,
                         "%s: vertex %zu (line %zu: '%.60s') has a non-finite coordinate (%s)",
                         path, vert, lineno, line, vp_mesh_nonfinite_name((float)x));
                found = 1;
            }
            c = end;
        }
    }
    free(line);
    fclose(f);
    return found;
}

/* The importers run in a child process (isolate.c): Assimp 5.2 loops
 * forever or aborts on some malformed files, whatever the prechecks. */
static vp_result import_path(const void *arg, vp_mesh **out, char *err, size_t errlen)
{
    const char *path = arg;
    const struct aiScene *sc = aiImportFile(path, 0);
    if (!sc) return import_failed(path, err, errlen);
    vp_result r = finish_import(sc, path, out, err, errlen);
    if (r == VP_ERR_FORMAT && err && errlen && strstr(err, "non-finite coordinate") &&
        has_suffix_ci(path, ".obj"))
        obj_nonfinite_vertex(path, err, errlen);
    return r;
}

typedef struct memory_source {
    const void *data;
    size_t size;
    const char *hint;
} memory_source;

static vp_result import_memory(const void *arg, vp_mesh **out, char *err, size_t errlen)
{
    const memory_source *src = arg;
    const struct aiScene *sc =
        aiImportFileFromMemory((const char *)src->data, (unsigned)src->size, 0, src->hint);
    if (!sc) return import_failed("<memory>", err, errlen);
    return finish_import(sc, "<memory>", out, err, errlen);
}

vp_result vp_mesh_load(const char *path, vp_mesh **out, char *err, size_t errlen)
{
    return vp_mesh_load_guarded(path, NULL, out, err, errlen);
}

vp_result vp_mesh_load_guarded(const char *path, const vp_subproc_guard *guard, vp_mesh **out,
                               char *err, size_t errlen)
{
    if (err && errlen) err[0] = '\0';
    if (!out) {
        set_err(err, errlen, "%s: %s", path ? path : "(null)", "no output pointer");
        return VP_ERR_INVALID_ARGUMENT;
    }
    *out = NULL;
    if (!path || !*path) {
        set_err(err, errlen, "%s%s", "", "mesh: empty file name");
        return VP_ERR_INVALID_ARGUMENT;
    }

    /* Check the file ourselves first: Assimp's messages for a missing or
     * unreadable file are poor, and it would block for ever on a FIFO. */
    char msg[1024];
    int fd = vp_os_open_input(path, msg, sizeof msg);
    FILE *f = fd < 0 ? NULL : fdopen(fd, "rb");
    if (!f) {
        if (fd >= 0) {
            vp_os_format(msg, sizeof msg, "%s: cannot open file (%s)", path, strerror(errno));
            close(fd);
        }
        set_err(err, errlen, "%s%s", msg, "");
        return VP_ERR_IO;
    }
    struct stat st;
    memset(&st, 0, sizeof st);
    fstat(fileno(f), &st);
    unsigned char *head = malloc(VP_MESH_PRECHECK_BYTES);
    if (!head) {
        fclose(f);
        set_err(err, errlen, "%s: %s", path, "out of memory");
        return VP_ERR_OUT_OF_MEMORY;
    }
    errno = 0;
    size_t got = fread(head, 1, VP_MESH_PRECHECK_BYTES, f);
    if (got < VP_MESH_PRECHECK_BYTES && ferror(f)) {
        int e = errno ? errno : EIO;
        fclose(f);
        free(head);
        set_err(err, errlen, "%s: cannot open file (%s)", path, strerror(e));
        return VP_ERR_IO;
    }
    fclose(f);
    if (got == 0) {
        free(head);
        set_err(err, errlen, "%s: not a mesh file Assimp can read (%s)", path, "the file is empty");
        return VP_ERR_FORMAT;
    }
    vp_result pr = precheck(head, got, (size_t)st.st_size, path, err, errlen);
    free(head);
    if (pr != VP_OK) return pr;

    return vp_mesh_import_isolated(import_path, path, path,
                                   vp_mesh_import_timeout((size_t)st.st_size), guard, out, err,
                                   errlen);
}

vp_result vp_mesh_load_memory(const void *data, size_t size, const char *hint, vp_mesh **out,
                              char *err, size_t errlen)
{
    const char *name = "<memory>";
    if (err && errlen) err[0] = '\0';
    if (!out) {
        set_err(err, errlen, "%s: %s", name, "no output pointer");
        return VP_ERR_INVALID_ARGUMENT;
    }
    *out = NULL;
    if (!data || size == 0) {
        set_err(err, errlen, "%s: not a mesh file Assimp can read (%s)", name,
                "the buffer is empty");
        return VP_ERR_FORMAT;
    }
    if (size > UINT32_MAX) {
        set_err(err, errlen, "%s: %s", name, "buffer too large for Assimp");
        return VP_ERR_INVALID_ARGUMENT;
    }
    size_t scan = size < VP_MESH_PRECHECK_BYTES ? size : VP_MESH_PRECHECK_BYTES;
    vp_result pr = precheck((const unsigned char *)data, scan, size, name, err, errlen);
    if (pr != VP_OK) return pr;
    memory_source src = {data, size, hint ? hint : ""};
    return vp_mesh_import_isolated(import_memory, &src, name, vp_mesh_import_timeout(size), NULL,
                                   out, err, errlen);
}

void vp_mesh_destroy(vp_mesh *m)
{
    if (!m) return;
    free(m->verts);
    free(m->tris);
    free(m);
}
