/* SPDX-License-Identifier: Apache-2.0 */
/* Binary little-endian PLY: one vertex element, one vertex per particle
 * (x y z pscale id [orient_x orient_y orient_z orient_w] group), the shape,
 * group names and metadata as comment lines. The reader takes what the
 * writer makes (and any vertex-only binary little-endian PLY with those
 * properties), strictly: see docs/export.md. */
#include "io/io_internal.h"
#include "core/context.h"
#include "core/shape.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static void put_f32(unsigned char *b, float v) {
    uint32_t u;
    memcpy(&u, &v, 4);
    for (int i = 0; i < 4; i++) b[i] = (unsigned char)(u >> (8 * i));
}
static void put_i32(unsigned char *b, int32_t v) {
    uint32_t u = (uint32_t)v;
    for (int i = 0; i < 4; i++) b[i] = (unsigned char)(u >> (8 * i));
}

/* A comment line's text: no line breaks (they would end the comment), at
 * most 4000 characters (the reader takes lines up to 8 KiB). */
static void put_comment(FILE *f, const char *key, const char *val) {
    fprintf(f, "comment %s ", key);
    for (const char *c = val; *c && c - val < 4000; c++)
        fputc((*c == '\n' || *c == '\r') ? ' ' : *c, f);
    fputc('\n', f);
}

vp_result vpio_write_ply(vp_context *ctx, const char *path, const vp_particles *p,
                         const vp_export_params *params) {
    vp_result r = vpio_check_particles(ctx, path, p);
    if (r == VP_OK) r = vpio_check_writable(ctx, path, p, 1, "PLY");
    if (r != VP_OK) return r;
    vpio_out o;
    if ((r = vpio_open(ctx, path, &o)) != VP_OK) return r;
    FILE *f = o.f;
    fprintf(f, "ply\nformat binary_little_endian 1.0\ncomment vdbpack %s\n", VP_VERSION_STRING);
    char shape_text[64];
    int mixed = p->shape == VP_SHAPE_MIXED;
    vp_shape_format(p->shape, p->shape_param, shape_text, sizeof shape_text);
    fprintf(f, "comment shape %s\n", shape_text[0] ? shape_text : "sphere");
    if (mixed) {
        char list[4096];
        put_comment(f, "shapes", vp_particles_shape_list(p, list, sizeof list));
    }
    for (unsigned g = 0; g < p->group_count; g++)
        fprintf(f, "comment group %u %.*s\n", g, VP_GROUP_NAME_MAX, p->group_names[g]);
    for (size_t i = 0; i < params->vdb.meta_count; i++) {
        const vp_meta *m = &params->vdb.meta[i];
        char key[160], val[64];
        snprintf(key, sizeof key, "meta %s", m->key ? m->key : "");
        for (char *c = key + 5; *c; c++) /* the key is one word */
            if (*c == '\n' || *c == '\r' || *c == ' ') *c = '_';
        if (m->type == VP_META_STRING) {
            put_comment(f, key, m->s ? m->s : "");
        } else {
            if (m->type == VP_META_INT) snprintf(val, sizeof val, "%lld", (long long)m->i);
            else snprintf(val, sizeof val, "%.17g", m->d);
            put_comment(f, key, val);
        }
    }
    fprintf(f, "element vertex %zu\n", p->count);
    fputs("property float x\nproperty float y\nproperty float z\nproperty float pscale\n"
          "property int id\n",
          f);
    if (p->has_orient)
        fputs("property float orient_x\nproperty float orient_y\nproperty float orient_z\n"
              "property float orient_w\n",
              f);
    fputs(mixed ? "property uchar group\nproperty uchar shape\nend_header\n"
                : "property uchar group\nend_header\n",
          f);
    unsigned char rec[64];
    size_t stride = 12 + 4 + 4 + (p->has_orient ? 16 : 0) + 1 + (mixed ? 1 : 0);
    for (size_t i = 0; i < p->count && !ferror(f); i++) {
        unsigned char *b = rec;
        for (int c = 0; c < 3; c++, b += 4) put_f32(b, (float)p->positions[3 * i + c]);
        put_f32(b, vpio_radius(p, i)), b += 4;
        put_i32(b, (int32_t)i), b += 4;
        if (p->has_orient) {
            const float *q = vpio_orient(p, i);
            for (int c = 0; c < 4; c++, b += 4) put_f32(b, q[c]);
        }
        *b++ = (unsigned char)vpio_group(p, i);
        if (mixed) *b = p->shape_index[i];
        fwrite(rec, 1, stride, f);
    }
    return vpio_close(ctx, &o, 0);
}

/* --- reading ---------------------------------------------------------------- */

typedef enum { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 } ptype;
static const struct {
    const char *name;
    ptype t;
    int size;
} k_types[] = {
    {"char", T_I8, 1},   {"int8", T_I8, 1},     {"uchar", T_U8, 1},   {"uint8", T_U8, 1},
    {"short", T_I16, 2}, {"int16", T_I16, 2},   {"ushort", T_U16, 2}, {"uint16", T_U16, 2},
    {"int", T_I32, 4},   {"int32", T_I32, 4},   {"uint", T_U32, 4},   {"uint32", T_U32, 4},
    {"float", T_F32, 4}, {"float32", T_F32, 4}, {"double", T_F64, 8}, {"float64", T_F64, 8},
};

static double get_val(const unsigned char *b, ptype t) {
    uint64_t u = 0;
    int n = t == T_F64                                 ? 8
            : (t == T_I32 || t == T_U32 || t == T_F32) ? 4
            : (t == T_I16 || t == T_U16)               ? 2
                                                       : 1;
    for (int i = 0; i < n; i++) u |= (uint64_t)b[i] << (8 * i);
    switch (t) {
    case T_I8: return (double)(int8_t)u;
    case T_U8: return (double)(uint8_t)u;
    case T_I16: return (double)(int16_t)u;
    case T_U16: return (double)(uint16_t)u;
    case T_I32: return (double)(int32_t)u;
    case T_U32: return (double)(uint32_t)u;
    case T_F32: {
        uint32_t w = (uint32_t)u;
        float v;
        memcpy(&v, &w, 4);
        return v;
    }
    case T_F64: {
        double v;
        memcpy(&v, &u, 8);
        return v;
    }
    default: return 0;
    }
}

enum { P_X, P_Y, P_Z, P_PSCALE, P_ID, P_QX, P_QY, P_QZ, P_QW, P_GROUP, P_SHAPE, P_COUNT };
static const char *const k_props[P_COUNT] = {"x",        "y",        "z",        "pscale",
                                             "id",       "orient_x", "orient_y", "orient_z",
                                             "orient_w", "group",    "shape"};

typedef struct ply_header {
    size_t n;
    size_t stride;
    int off[P_COUNT]; /* byte offset in a record, -1 if absent */
    ptype type[P_COUNT];
    int shape_set;
    vp_shape shape;
    double shape_param;
    int shapes_set; /* "comment shapes" of a mixed set */
    unsigned nshapes;
    vp_shape_ref shapes[VP_MAX_SHAPES];
    char shape_names[VP_MAX_SHAPES][VP_SHAPE_NAME_MAX];
    int named[VP_MAX_GROUPS];
    char names[VP_MAX_GROUPS][VP_GROUP_NAME_MAX];
} ply_header;

#define BAD(...) vp_fail(ctx, VP_ERR_FORMAT, __VA_ARGS__)

/* One header line (without the newline) into line; -1 at EOF or if longer
 * than the buffer. */
static int read_line(FILE *f, char *line, size_t cap, size_t *total) {
    size_t n = 0;
    int c;
    while ((c = fgetc(f)) != EOF) {
        (*total)++;
        if (c == '\n') {
            if (n && line[n - 1] == '\r') n--;
            line[n] = 0;
            return 0;
        }
        if (n + 1 >= cap) return -1;
        line[n++] = (char)c;
    }
    return -1;
}

static vp_result parse_header(vp_context *ctx, const char *path, FILE *f, ply_header *h,
                              size_t *header_bytes) {
    memset(h, 0, sizeof *h);
    for (int i = 0; i < P_COUNT; i++) h->off[i] = -1;
    char line[8192];
    size_t total = 0;
    int nline = 0, in_vertex = 0, have_vertex = 0, have_format = 0;
    char seen_names[64][64];
    int nseen = 0;
    for (;;) {
        if (total > 65536)
            return BAD("%s: not a PLY file vdbpack reads: header longer than 64 KiB", path);
        if (read_line(f, line, sizeof line, &total) != 0)
            return BAD("%s: not a PLY file vdbpack reads: %s", path,
                       nline == 0 ? "empty or not text"
                                  : "the header has no end_header line (or a line over 8 KiB)");
        nline++;
        if (nline == 1) {
            if (strcmp(line, "ply") != 0)
                return BAD("%s: not a PLY file (it does not start with 'ply')", path);
            continue;
        }
        char w0[32] = "", w1[64] = "", w2[64] = "", w3[64] = "";
        int nw = sscanf(line, "%31s %63s %63s %63s", w0, w1, w2, w3);
        if (nw <= 0) continue;
        if (!strcmp(w0, "end_header")) break;
        if (!strcmp(w0, "format")) {
            if (nw != 3 || strcmp(w1, "binary_little_endian") != 0 || strcmp(w2, "1.0") != 0)
                return BAD(
                    "%s: PLY format '%s %s' is not read (vdbpack reads binary_little_endian 1.0)",
                    path, w1, w2);
            have_format = 1;
        } else if (!strcmp(w0, "comment") || !strcmp(w0, "obj_info")) {
            if (!strcmp(w0, "comment") && !strcmp(w1, "shape") && nw >= 3 && !strcmp(w2, "mixed")) {
                h->shape = VP_SHAPE_MIXED;
                h->shape_set = 1;
            } else if (!strcmp(w0, "comment") && !strcmp(w1, "shapes") && nw >= 3) {
                /* the list is one word: shape names have no spaces, mesh names may */
                const char *list = strstr(line, "shapes") + 7;
                if (vp_shape_list_parse(list, h->shapes, &h->nshapes, h->shape_names) != 0)
                    return BAD("%s: malformed shapes comment '%s' (names of shapes joined by ;)",
                               path, list);
                h->shapes_set = 1;
            } else if (!strcmp(w0, "comment") && !strcmp(w1, "shape") && nw >= 3) {
                if (vp_shape_parse_param(w2, &h->shape, &h->shape_param) != 0)
                    return BAD("%s: unknown shape '%s' in the PLY header", path, w2);
                h->shape_set = 1;
            } else if (!strcmp(w0, "comment") && !strcmp(w1, "group") && nw >= 3) {
                char *end;
                long g = strtol(w2, &end, 10);
                if (*end || g < 0 || g >= VP_MAX_GROUPS || nw != 4 ||
                    !vpio_valid_group_name(w3, strlen(w3)))
                    return BAD(
                        "%s: malformed group comment '%s' (comment group K NAME, K < %d, NAME of "
                        "letters, digits, _ | :)",
                        path, line, VP_MAX_GROUPS);
                if (h->named[g]) return BAD("%s: group %ld is named twice", path, g);
                h->named[g] = 1;
                snprintf(h->names[g], VP_GROUP_NAME_MAX, "%s", w3);
            }
        } else if (!strcmp(w0, "element")) {
            if (!have_format) return BAD("%s: PLY header: element before the format line", path);
            if (have_vertex || strcmp(w1, "vertex") != 0)
                return BAD("%s: PLY element '%s': vdbpack reads a single vertex element", path, w1);
            char *end;
            errno = 0;
            unsigned long long n = strtoull(w2, &end, 10);
            if (nw != 3 || *end || w2[0] == '-' || errno || n > 2147483647ull)
                return BAD("%s: PLY 'element vertex %s': not a count in 0..2147483647", path, w2);
            h->n = (size_t)n;
            have_vertex = in_vertex = 1;
        } else if (!strcmp(w0, "property")) {
            if (!in_vertex) return BAD("%s: PLY property outside the vertex element", path);
            if (!strcmp(w1, "list"))
                return BAD("%s: PLY list property in the vertex element", path);
            if (nw != 3) return BAD("%s: malformed PLY line '%s'", path, line);
            int t = -1;
            for (size_t i = 0; i < sizeof k_types / sizeof k_types[0]; i++)
                if (!strcmp(w1, k_types[i].name)) t = (int)i;
            if (t < 0) return BAD("%s: unknown PLY property type '%s'", path, w1);
            for (int i = 0; i < nseen; i++)
                if (!strcmp(seen_names[i], w2))
                    return BAD("%s: PLY property '%s' given twice", path, w2);
            if (nseen >= 64) return BAD("%s: more than 64 PLY vertex properties", path);
            snprintf(seen_names[nseen++], 64, "%s", w2);
            for (int i = 0; i < P_COUNT; i++)
                if (!strcmp(w2, k_props[i])) {
                    h->off[i] = (int)h->stride;
                    h->type[i] = k_types[t].t;
                }
            h->stride += (size_t)k_types[t].size;
        } else {
            return BAD("%s: unknown PLY header line '%s'", path, line);
        }
    }
    if (!have_format) return BAD("%s: PLY header has no format line", path);
    if (!have_vertex) return BAD("%s: PLY header has no vertex element", path);
    for (int i = P_X; i <= P_ID; i++)
        if (h->off[i] < 0) return BAD("%s: PLY vertex has no '%s' property", path, k_props[i]);
    for (int i = P_X; i <= P_PSCALE; i++)
        if (h->type[i] != T_F32 && h->type[i] != T_F64)
            return BAD("%s: PLY property '%s' must be float or double", path, k_props[i]);
    if (h->type[P_ID] == T_F32 || h->type[P_ID] == T_F64)
        return BAD("%s: PLY property 'id' must be an integer type", path);
    int nq = 0;
    for (int i = P_QX; i <= P_QW; i++) nq += h->off[i] >= 0;
    if (nq != 0 && nq != 4)
        return BAD("%s: PLY vertex has %d of the 4 orient_* properties", path, nq);
    for (int i = P_QX; i <= P_QW && nq; i++)
        if (h->type[i] != T_F32 && h->type[i] != T_F64)
            return BAD("%s: PLY property '%s' must be float or double", path, k_props[i]);
    if (h->off[P_GROUP] >= 0 && (h->type[P_GROUP] == T_F32 || h->type[P_GROUP] == T_F64))
        return BAD("%s: PLY property 'group' must be an integer type", path);
    int mixed = h->shape_set && h->shape == VP_SHAPE_MIXED;
    if (mixed && (!h->shapes_set || h->off[P_SHAPE] < 0))
        return BAD("%s: the PLY says shape mixed but has no %s", path,
                   h->shapes_set ? "shape property" : "shapes comment");
    if (mixed && (h->type[P_SHAPE] == T_F32 || h->type[P_SHAPE] == T_F64))
        return BAD("%s: PLY property 'shape' must be an integer type", path);
    if (!mixed) h->off[P_SHAPE] = -1; /* another file's own property: not ours */
    *header_bytes = total;
    return VP_OK;
}

vp_result vpio_read_ply(vp_context *ctx, const char *path, vp_particles **out, int *needs_shape) {
    *out = NULL;
    *needs_shape = 0;
    FILE *f = NULL;
    vp_result ro = vpio_open_read(ctx, path, &f);
    if (ro != VP_OK) return ro;
    ply_header h;
    size_t hb = 0;
    vp_result r = parse_header(ctx, path, f, &h, &hb);
    if (r != VP_OK) {
        fclose(f);
        return r;
    }
    unsigned long long want = (unsigned long long)hb + (unsigned long long)h.n * h.stride;
    struct stat st;
    if (fstat(fileno(f), &st) != 0) st.st_size = 0;
    if ((unsigned long long)st.st_size != want) {
        fclose(f);
        return BAD("%s: %s: the header promises %zu vertices of %zu bytes (%llu bytes in all), the "
                   "file has %lld",
                   path, (unsigned long long)st.st_size < want ? "truncated" : "trailing data", h.n,
                   h.stride, want, (long long)st.st_size);
    }
    int with_q = h.off[P_QX] >= 0;
    vp_particles *p = vpio_alloc(h.n, with_q);
    unsigned char *seen = calloc(h.n ? h.n : 1, 1);
    unsigned char *chunk = malloc(h.stride * 4096);
    if (!p || !seen || !chunk) {
        r = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "%s: out of memory for %zu particles", path, h.n);
        goto done;
    }
    p->shape = h.shape_set ? h.shape : VP_SHAPE_SPHERE;
    p->shape_param = h.shape_set && h.shape != VP_SHAPE_MIXED ? h.shape_param : 0.0;
    if (p->shape == VP_SHAPE_MIXED) {
        p->shape_count = h.nshapes;
        memcpy(p->shapes, h.shapes, sizeof h.shapes);
        memcpy(p->shape_names, h.shape_names, sizeof h.shape_names);
        p->shape_index = malloc(h.n ? h.n : 1);
        if (!p->shape_index) {
            r = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "%s: out of memory for %zu particles", path,
                        h.n);
            goto done;
        }
    }
    *needs_shape = with_q && !h.shape_set;
    int maxg = -1;
    for (size_t k0 = 0; k0 < h.n; k0 += 4096) {
        size_t m = h.n - k0 < 4096 ? h.n - k0 : 4096;
        if (fread(chunk, h.stride, m, f) != m) {
            r = BAD("%s: read error or truncated data at vertex %zu", path, k0);
            goto done;
        }
        for (size_t j = 0; j < m; j++) {
            size_t k = k0 + j;
            const unsigned char *b = chunk + j * h.stride;
            double x[3], q[4], ps = get_val(b + h.off[P_PSCALE], h.type[P_PSCALE]);
            for (int c = 0; c < 3; c++) x[c] = get_val(b + h.off[P_X + c], h.type[P_X + c]);
            for (int c = 0; c < 4 && with_q; c++)
                q[c] = get_val(b + h.off[P_QX + c], h.type[P_QX + c]);
            if ((r = vpio_check_values(ctx, path, "vertex", k, x, ps, with_q ? q : NULL)) != VP_OK)
                goto done;
            if (!(ps < 3.4e38)) {
                r = BAD("%s: vertex %zu: pscale %g is beyond float range", path, k, ps);
                goto done;
            }
            long long id = (long long)get_val(b + h.off[P_ID], h.type[P_ID]);
            if ((r = vpio_place_id(ctx, path, "vertex", k, id, h.n, seen)) != VP_OK) goto done;
            for (int c = 0; c < 3; c++) p->positions[3 * id + c] = x[c];
            p->radii[id] = (float)ps;
            for (int c = 0; c < 4 && with_q; c++) p->orients[4 * id + c] = (float)q[c];
            if (h.off[P_GROUP] >= 0) {
                double g = get_val(b + h.off[P_GROUP], h.type[P_GROUP]);
                if (g < 0 || g >= VP_MAX_GROUPS) {
                    r = BAD("%s: vertex %zu: group %g is not in 0..%d", path, k, g,
                            VP_MAX_GROUPS - 1);
                    goto done;
                }
                p->groups[id] = (uint16_t)g;
                if ((int)g > maxg) maxg = (int)g;
            }
            if (h.off[P_SHAPE] >= 0) {
                double v = get_val(b + h.off[P_SHAPE], h.type[P_SHAPE]);
                if (!(v >= 0 && v < h.nshapes)) {
                    r = BAD("%s: vertex %zu: shape %g is not in 0..%u", path, k, v, h.nshapes - 1);
                    goto done;
                }
                p->shape_index[id] = (uint8_t)v;
            }
        }
    }
    /* groups: every index used or named, names from the comments or passK */
    int ng = maxg + 1;
    for (int g = 0; g < VP_MAX_GROUPS; g++)
        if (h.named[g] && g + 1 > ng) ng = g + 1;
    if (ng < 1) ng = 1;
    p->group_count = (unsigned)ng;
    for (int g = 0; g < ng; g++) {
        if (h.named[g]) snprintf(p->group_names[g], VP_GROUP_NAME_MAX, "%s", h.names[g]);
        else snprintf(p->group_names[g], VP_GROUP_NAME_MAX, "pass%d", g + 1);
        for (int e = 0; e < g; e++)
            if (!strcmp(p->group_names[e], p->group_names[g])) {
                r = BAD("%s: group name '%s' is used twice", path, p->group_names[g]);
                goto done;
            }
    }
    r = VP_OK;
done:
    fclose(f);
    free(seen);
    free(chunk);
    if (r != VP_OK) {
        vp_particles_destroy(p);
        return r;
    }
    *out = p;
    return VP_OK;
}
