/* SPDX-License-Identifier: Apache-2.0 */
/* CSV: a header row (id,x,y,z,pscale[,qx,qy,qz,qw],group[,shape]) and one
 * row per particle in id order; positions with %.17g (the stored doubles
 * exactly), pscale and orient with %.9g (floats exactly), the group by
 * name, and for a set of several shapes each particle's shape by name
 * ("cube", "superball:2", "mesh:rock.obj"). No
 * comment lines: several CSV readers (numpy's genfromtxt with names=True,
 * spreadsheets) would take them for the header. */
#include "io/io_internal.h"
#include "core/context.h"
#include "core/shape.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char k_head[] = "id,x,y,z,pscale,group";
static const char k_head_q[] = "id,x,y,z,pscale,qx,qy,qz,qw,group";
static const char k_head_qs[] = "id,x,y,z,pscale,qx,qy,qz,qw,group,shape";

vp_result vpio_write_csv(vp_context *ctx, const char *path, const vp_particles *p,
                         const vp_export_params *params) {
    (void)params;
    vp_result r = vpio_check_particles(ctx, path, p);
    if (r == VP_OK) r = vpio_check_writable(ctx, path, p, 0, "CSV");
    if (r != VP_OK) return r;
    for (unsigned g = 0; g < p->group_count; g++)
        if (!vpio_valid_group_name(p->group_names[g],
                                   strnlen(p->group_names[g], VP_GROUP_NAME_MAX)))
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: group %u has no valid name", path, g);
    /* a mixed set: each shape's name, which must hold no comma */
    int mixed = p->shape == VP_SHAPE_MIXED;
    char names[VP_MAX_SHAPES][300];
    if (mixed) {
        char list[4096];
        vp_particles_shape_list(p, list, sizeof list);
        unsigned k = 0;
        for (char *a = list, *b; k < VP_MAX_SHAPES; a = b + 1) {
            b = strchr(a, ';');
            if (b) *b = 0;
            snprintf(names[k++], sizeof names[0], "%.299s", a);
            if (strchr(names[k - 1], ','))
                return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                               "%s: shape '%s' has a comma in its name, which a CSV field "
                               "cannot hold",
                               path, names[k - 1]);
            if (!b) break;
        }
        if (!p->has_orient || k != p->shape_count || !p->shape_index)
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: a mixed set without its shapes",
                           path);
    }
    vpio_out o;
    if ((r = vpio_open(ctx, path, &o)) != VP_OK) return r;
    FILE *f = o.f;
    fprintf(f, "%s\n", mixed ? k_head_qs : p->has_orient ? k_head_q : k_head);
    for (size_t i = 0; i < p->count && !ferror(f); i++) {
        const double *x = p->positions + 3 * i;
        fprintf(f, "%zu,%.17g,%.17g,%.17g,%.9g", i, x[0], x[1], x[2], (double)vpio_radius(p, i));
        if (p->has_orient) {
            const float *q = vpio_orient(p, i);
            fprintf(f, ",%.9g,%.9g,%.9g,%.9g", (double)q[0], (double)q[1], (double)q[2],
                    (double)q[3]);
        }
        if (mixed)
            fprintf(f, ",%s,%s\n", p->group_names[vpio_group(p, i)], names[p->shape_index[i]]);
        else fprintf(f, ",%s\n", p->group_names[vpio_group(p, i)]);
    }
    return vpio_close(ctx, &o, 0);
}

#define BAD(...) vp_fail(ctx, VP_ERR_FORMAT, __VA_ARGS__)

/* A whole field as a number (no spaces, nothing after it). */
static int field_double(const char *s, double *out) {
    if (!*s || *s == ' ' || *s == '\t') return -1;
    char *end;
    errno = 0;
    *out = strtod(s, &end);
    return (*end || errno == ERANGE) ? -1 : 0;
}
static int field_int(const char *s, long long *out) {
    if (!*s || *s == ' ' || *s == '\t' || *s == '+') return -1;
    char *end;
    errno = 0;
    *out = strtoll(s, &end, 10);
    return (*end || errno) ? -1 : 0;
}

typedef struct rows {
    size_t n, cap;
    double *x; /* 3 per row */
    float *r;
    float *q; /* 4 per row, or NULL */
    uint16_t *g;
    uint8_t *s; /* shape index per row, or NULL */
    long long *id;
} rows;

static int rows_grow(rows *t, int with_q) {
    if (t->n < t->cap) return 0;
    size_t c = t->cap ? 2 * t->cap : 4096;
    double *x = realloc(t->x, c * 3 * sizeof *x);
    if (x) t->x = x;
    float *r = realloc(t->r, c * sizeof *r);
    if (r) t->r = r;
    uint16_t *g = realloc(t->g, c * sizeof *g);
    if (g) t->g = g;
    long long *id = realloc(t->id, c * sizeof *id);
    if (id) t->id = id;
    float *q = with_q ? realloc(t->q, c * 4 * sizeof *q) : NULL;
    if (q) t->q = q;
    uint8_t *s = with_q == 2 ? realloc(t->s, c * sizeof *s) : NULL;
    if (s) t->s = s;
    if (!x || !r || !g || !id || (with_q && !q) || (with_q == 2 && !s)) return -1;
    t->cap = c;
    return 0;
}

static void rows_free(rows *t) {
    free(t->x);
    free(t->r);
    free(t->q);
    free(t->g);
    free(t->s);
    free(t->id);
}

vp_result vpio_read_csv(vp_context *ctx, const char *path, vp_particles **out, int *has_orient) {
    *out = NULL;
    *has_orient = 0;
    FILE *f = NULL;
    vp_result ro = vpio_open_read(ctx, path, &f);
    if (ro != VP_OK) return ro;
    rows t = {0};
    vp_particles *p = NULL;
    unsigned char *seen = NULL;
    vp_result r = VP_OK;
    char line[4096];
    char names[VP_MAX_GROUPS][VP_GROUP_NAME_MAX];
    unsigned ngroups = 0;
    int with_q = 0, with_s = 0; /* with_s: a shape column (a mixed set) */
    char snames[VP_MAX_SHAPES][300];
    vp_shape_ref shapes[VP_MAX_SHAPES];
    char snames_short[VP_MAX_SHAPES][VP_SHAPE_NAME_MAX];
    memset(snames_short, 0, sizeof snames_short);
    memset(shapes, 0, sizeof shapes); /* (sphere: an empty file's one shape) */
    unsigned nshapes = 0;
    size_t lineno = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        size_t len = strlen(line);
        if (len == 0 || line[len - 1] != '\n') {
            r = BAD(feof(f) ? "%s: line %zu has no newline at the end (truncated file?)"
                            : "%s: line %zu is longer than 4 KiB or holds a NUL byte",
                    path, lineno);
            goto done;
        }
        line[--len] = 0;
        if (len && line[len - 1] == '\r') line[--len] = 0;
        if (lineno == 1) {
            if (!strcmp(line, k_head_q)) with_q = 1;
            else if (!strcmp(line, k_head_qs)) with_q = with_s = 1;
            else if (strcmp(line, k_head) != 0) {
                r = BAD("%s: not a CSV that vdbpack reads: the header row must be '%s', '%s' or "
                        "'%s'",
                        path, k_head, k_head_q, k_head_qs);
                goto done;
            }
            continue;
        }
        char *fld[12];
        int nf = 0;
        for (char *s = line;;) {
            if (nf == 12) break;
            fld[nf++] = s;
            char *c = strchr(s, ',');
            if (!c) break;
            *c = 0;
            s = c + 1;
        }
        int want = with_q ? 10 + with_s : 6;
        if (nf != want) {
            r = BAD("%s: line %zu has %s%d fields, the header %d", path, lineno,
                    nf >= 12 ? "at least " : "", nf == 1 && !*fld[0] ? 0 : nf, want);
            goto done;
        }
        if (rows_grow(&t, with_q + with_s) != 0) {
            r = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "%s: out of memory at line %zu", path, lineno);
            goto done;
        }
        size_t k = t.n;
        double x[3], ps, q[4];
        long long id;
        if (field_int(fld[0], &id) != 0) {
            r = BAD("%s: line %zu: id '%s' is not a whole number", path, lineno, fld[0]);
            goto done;
        }
        for (int c = 0; c < 3; c++)
            if (field_double(fld[1 + c], &x[c]) != 0) {
                r = BAD("%s: line %zu: %c '%s' is not a number", path, lineno, "xyz"[c],
                        fld[1 + c]);
                goto done;
            }
        if (field_double(fld[4], &ps) != 0 || !(ps < 3.4e38)) {
            r = BAD("%s: line %zu: pscale '%s' is not a number in float range", path, lineno,
                    fld[4]);
            goto done;
        }
        for (int c = 0; c < 4 && with_q; c++)
            if (field_double(fld[5 + c], &q[c]) != 0) {
                r = BAD("%s: line %zu: q%c '%s' is not a number", path, lineno, "xyzw"[c],
                        fld[5 + c]);
                goto done;
            }
        if ((r = vpio_check_values(ctx, path, "line", lineno, x, ps, with_q ? q : NULL)) != VP_OK)
            goto done;
        const char *gname = fld[want - 1 - with_s];
        if (!vpio_valid_group_name(gname, strlen(gname))) {
            r = BAD("%s: line %zu: group '%s' is not a valid name (letters, digits, _ | :)", path,
                    lineno, gname);
            goto done;
        }
        unsigned g = 0;
        while (g < ngroups && strcmp(names[g], gname) != 0) g++;
        if (g == ngroups) {
            if (ngroups == VP_MAX_GROUPS) {
                r = BAD("%s: line %zu: more than %d groups", path, lineno, VP_MAX_GROUPS);
                goto done;
            }
            snprintf(names[ngroups++], VP_GROUP_NAME_MAX, "%s", gname);
        }
        for (int c = 0; c < 3; c++) t.x[3 * k + c] = x[c];
        t.r[k] = (float)ps;
        for (int c = 0; c < 4 && with_q; c++) t.q[4 * k + c] = (float)q[c];
        t.g[k] = (uint16_t)g;
        if (with_s) { /* the shapes in the order they first appear */
            const char *sn = fld[want - 1];
            unsigned u = 0;
            while (u < nshapes && strcmp(snames[u], sn) != 0) u++;
            if (u == nshapes) {
                unsigned one = 0;
                if (nshapes == VP_MAX_SHAPES || strlen(sn) >= sizeof snames[0] ||
                    vp_shape_list_parse(sn, &shapes[u], &one, &snames_short[u]) != 0 || one != 1) {
                    r = BAD("%s: line %zu: shape '%s' is not a shape name (or more than %d "
                            "shapes)",
                            path, lineno, sn, VP_MAX_SHAPES);
                    goto done;
                }
                snprintf(snames[nshapes++], sizeof snames[0], "%s", sn);
            }
            t.s[k] = (uint8_t)u;
        }
        t.id[k] = id;
        t.n++;
        if (t.n > 2147483647u) {
            r = BAD("%s: more than 2147483647 rows", path);
            goto done;
        }
    }
    if (ferror(f)) {
        r = vp_fail(ctx, VP_ERR_IO, "%s: read error", path);
        goto done;
    }
    if (lineno == 0) {
        r = BAD("%s: empty file (a CSV needs at least the header row)", path);
        goto done;
    }
    p = vpio_alloc(t.n, with_q);
    seen = calloc(t.n ? t.n : 1, 1);
    if (p && with_s) {
        p->shape = VP_SHAPE_MIXED;
        p->shape_count = nshapes ? nshapes : 1;
        memcpy(p->shapes, shapes, sizeof shapes);
        memcpy(p->shape_names, snames_short, sizeof snames_short);
        p->shape_index = calloc(t.n ? t.n : 1, 1);
    }
    if (!p || !seen || (with_s && !p->shape_index)) {
        r = vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "%s: out of memory for %zu particles", path, t.n);
        goto done;
    }
    for (size_t k = 0; k < t.n; k++) {
        /* rows are 1-based lines after the header */
        if ((r = vpio_place_id(ctx, path, "line", k + 2, t.id[k], t.n, seen)) != VP_OK) goto done;
        size_t d = (size_t)t.id[k];
        memcpy(p->positions + 3 * d, t.x + 3 * k, 3 * sizeof(double));
        p->radii[d] = t.r[k];
        if (with_q) memcpy(p->orients + 4 * d, t.q + 4 * k, 4 * sizeof(float));
        p->groups[d] = t.g[k];
        if (with_s) p->shape_index[d] = t.s[k];
    }
    p->group_count = ngroups ? ngroups : 1;
    for (unsigned g = 0; g < ngroups; g++) memcpy(p->group_names[g], names[g], VP_GROUP_NAME_MAX);
    *has_orient = with_q && !with_s; /* (a mixed set names its shapes) */
    r = VP_OK;
done:
    fclose(f);
    rows_free(&t);
    free(seen);
    if (r != VP_OK) {
        vp_particles_destroy(p);
        return r;
    }
    *out = p;
    return VP_OK;
}
