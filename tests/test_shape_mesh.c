// SPDX-License-Identifier: Apache-2.0
/* vp_shape_mesh: the unit shape's surface as arrays (public API only). For
 * every solid, two superballs and a mesh shape the arrays are exactly what
 * the OBJ writers write (parsed here), and, checked here: every face turns
 * counter-clockwise seen from outside, every edge is shared by two faces
 * in opposite directions (closed, consistently oriented), V - E + F = 2,
 * and the vertices lie within the bounding sphere of radius 1 and reach
 * it. The counting call, short arrays, spheres, bad exponents and a
 * missing mesh give the documented results. */
#include "vdbpack/vdbpack.h"
#include "vp_test.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct {
    double *v;
    size_t nv;
    uint32_t *fs, *idx;
    size_t nf, ni;
} mesh_arrays;

static void free_arrays(mesh_arrays *m) {
    free(m->v);
    free(m->fs);
    free(m->idx);
    memset(m, 0, sizeof *m);
}

/* An OBJ as the library writes it: v lines, f lines of 1-based indices. */
static mesh_arrays read_obj(const char *path) {
    mesh_arrays m = {0};
    size_t cv = 0, cf = 0, ci = 0;
    FILE *f = fopen(path, "r");
    ASSERT_TRUE(f != NULL);
    char line[4096];
    while (fgets(line, sizeof line, f)) {
        if (line[0] == 'v' && line[1] == ' ') {
            if (m.nv == cv) m.v = realloc(m.v, 3 * (cv = cv * 2 + 16) * sizeof *m.v);
            char *p = line + 2;
            for (int c = 0; c < 3; c++) m.v[3 * m.nv + c] = strtod(p, &p);
            m.nv++;
        } else if (line[0] == 'f' && line[1] == ' ') {
            if (m.nf == cf) m.fs = realloc(m.fs, (cf = cf * 2 + 16) * sizeof *m.fs);
            char *p = line + 1, *end;
            uint32_t k = 0;
            for (long x; (x = strtol(p, &end, 10)), end != p; p = end) {
                if (m.ni == ci) m.idx = realloc(m.idx, (ci = ci * 2 + 64) * sizeof *m.idx);
                m.idx[m.ni++] = (uint32_t)(x - 1);
                k++;
            }
            m.fs[m.nf++] = k;
        }
    }
    fclose(f);
    return m;
}

static mesh_arrays get_mesh(vp_context *ctx, vp_shape s, double param, const vp_mesh_shape *ms) {
    mesh_arrays m = {0};
    ASSERT_OK(ctx, vp_shape_mesh(ctx, s, param, ms, NULL, &m.nv, NULL, &m.nf, NULL, &m.ni));
    ASSERT_TRUE(m.nv >= 4 && m.nf >= 4 && m.ni >= 3 * m.nf);
    m.v = malloc(3 * m.nv * sizeof *m.v);
    m.fs = malloc(m.nf * sizeof *m.fs);
    m.idx = malloc(m.ni * sizeof *m.idx);
    size_t nv = m.nv, nf = m.nf, ni = m.ni;
    ASSERT_OK(ctx, vp_shape_mesh(ctx, s, param, ms, m.v, &nv, m.fs, &nf, m.idx, &ni));
    ASSERT_TRUE(nv == m.nv && nf == m.nf && ni == m.ni);
    return m;
}

/* The checks written here, independent of the library's geometry. */
static void check_surface(const mesh_arrays *m, const char *what) {
    double rmax = 0;
    for (size_t i = 0; i < m->nv; i++) {
        const double *x = m->v + 3 * i;
        double r = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        ASSERT_LE(r, 1 + 1e-12);
        rmax = fmax(rmax, r);
    }
    ASSERT_NEAR(rmax, 1.0, 1e-9);
    /* directed edges: each (a, b) once, and (b, a) once too */
    size_t ne = m->ni, k = 0;
    uint64_t *e = malloc(ne * sizeof *e);
    for (size_t f = 0, o = 0; f < m->nf; o += m->fs[f], f++) {
        const uint32_t *id = m->idx + o;
        uint32_t n = m->fs[f];
        ASSERT_TRUE(n >= 3);
        double nrm[3] = {0, 0, 0}, c[3] = {0, 0, 0};
        for (uint32_t i = 0; i < n; i++) {
            ASSERT_TRUE(id[i] < m->nv);
            const double *a = m->v + 3 * id[i], *b = m->v + 3 * id[(i + 1) % n];
            nrm[0] += (a[1] - b[1]) * (a[2] + b[2]); /* Newell's normal */
            nrm[1] += (a[2] - b[2]) * (a[0] + b[0]);
            nrm[2] += (a[0] - b[0]) * (a[1] + b[1]);
            for (int j = 0; j < 3; j++) c[j] += a[j] / n;
            e[k++] = (uint64_t)id[i] << 32 | id[(i + 1) % n];
        }
        /* outward: the shapes here are star-shaped about the origin */
        if (!(nrm[0] * c[0] + nrm[1] * c[1] + nrm[2] * c[2] > 0)) {
            fprintf(stderr, "%s: face %zu turns clockwise seen from outside\n", what, f);
            exit(1);
        }
    }
    for (size_t i = 0; i < ne; i++) {
        uint64_t rev = (e[i] << 32) | (e[i] >> 32);
        int same = 0, opposite = 0;
        for (size_t j = 0; j < ne; j++) same += e[j] == e[i], opposite += e[j] == rev;
        if (same != 1 || opposite != 1) {
            fprintf(stderr, "%s: edge %u-%u in %d faces, reversed in %d\n", what,
                    (unsigned)(e[i] >> 32), (unsigned)(e[i] & 0xffffffffu), same, opposite);
            exit(1);
        }
    }
    ASSERT_EQ_INT((long long)m->nv - (long long)(ne / 2) + (long long)m->nf, 2);
    free(e);
}

static void same_as_obj(const mesh_arrays *m, const char *obj, const char *what) {
    mesh_arrays o = read_obj(obj);
    if (o.nv != m->nv || o.nf != m->nf || o.ni != m->ni ||
        memcmp(o.v, m->v, 3 * m->nv * sizeof *m->v) != 0 ||
        memcmp(o.fs, m->fs, m->nf * sizeof *m->fs) != 0 ||
        memcmp(o.idx, m->idx, m->ni * sizeof *m->idx) != 0) {
        fprintf(stderr, "%s: arrays (%zu v, %zu f) differ from the OBJ (%zu v, %zu f)\n", what,
                m->nv, m->nf, o.nv, o.nf);
        exit(1);
    }
    free_arrays(&o);
}

int main(void) {
    vp_context *ctx = NULL;
    ASSERT_OK(NULL, vp_context_create(&ctx));
    char dir[] = "/tmp/vp-shape-mesh-XXXXXX", obj[256];
    ASSERT_TRUE(mkdtemp(dir) != NULL);
    snprintf(obj, sizeof obj, "%s/shape.obj", dir);

    int tested = 0;
    for (int s = 1; s < VP_SHAPE_COUNT; s++) { /* the 5 platonic and 13 Archimedean solids */
        mesh_arrays m = get_mesh(ctx, (vp_shape)s, 0.0, NULL);
        check_surface(&m, vp_shape_name((vp_shape)s));
        ASSERT_OK(ctx, vp_shape_write_obj(ctx, (vp_shape)s, obj));
        same_as_obj(&m, obj, vp_shape_name((vp_shape)s));
        free_arrays(&m);
        tested++;
    }
    const double ps[] = {2.0, 0.6};
    for (int i = 0; i < 2; i++) {
        mesh_arrays m = get_mesh(ctx, VP_SHAPE_SUPERBALL, ps[i], NULL);
        check_surface(&m, "superball");
        for (size_t f = 0; f < m.nf; f++) ASSERT_EQ_INT(m.fs[f], 3);
        /* every vertex on the superball's surface: |x|^2p + ... = 1 after
         * undoing the scaling to bounding radius 1 */
        double c = ps[i] <= 1 ? 1.0 : sqrt(3.0) * pow(3.0, -0.5 / ps[i]);
        for (size_t v = 0; v < m.nv; v++) {
            double g = 0;
            for (int k = 0; k < 3; k++) g += pow(fabs(m.v[3 * v + k] * c), 2 * ps[i]);
            ASSERT_NEAR(g, 1.0, 1e-9);
        }
        ASSERT_OK(ctx, vp_shape_write_obj_param(ctx, VP_SHAPE_SUPERBALL, ps[i], obj));
        same_as_obj(&m, obj, "superball");
        fprintf(stderr, "superball:%g: %zu vertices, %zu triangles\n", ps[i], m.nv, m.nf);
        free_arrays(&m);
        tested++;
    }
    vp_mesh_shape *ms = NULL;
    ASSERT_OK(ctx, vp_mesh_shape_load(ctx, VP_SAMPLES "/box.obj", &ms));
    mesh_arrays m = get_mesh(ctx, VP_SHAPE_MESH, 0.0, ms);
    check_surface(&m, "box.obj");
    ASSERT_EQ_INT(m.nf, vp_mesh_shape_triangles(ms));
    ASSERT_OK(ctx, vp_mesh_shape_write_obj(ctx, ms, obj));
    same_as_obj(&m, obj, "box.obj");
    tested++;

    /* short arrays: refused, nothing written */
    size_t nv = m.nv, nf = m.nf - 1, ni = m.ni;
    double sentinel = m.v[0] = -7.0;
    ASSERT_EQ_INT(vp_shape_mesh(ctx, VP_SHAPE_MESH, 0, ms, m.v, &nv, m.fs, &nf, m.idx, &ni),
                  VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(m.v[0] == sentinel && nf == m.nf - 1);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "arrays for") != NULL);
    free_arrays(&m);
    vp_mesh_shape_destroy(ms);
    /* what has no polygons, or no exponent, or no mesh */
    ASSERT_EQ_INT(vp_shape_mesh(ctx, VP_SHAPE_SPHERE, 0, NULL, NULL, &nv, NULL, &nf, NULL, &ni),
                  VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "sphere") != NULL);
    ASSERT_EQ_INT(
        vp_shape_mesh(ctx, VP_SHAPE_SUPERBALL, 0.3, NULL, NULL, &nv, NULL, &nf, NULL, &ni),
        VP_ERR_INVALID_ARGUMENT);
    ASSERT_TRUE(strstr(vp_context_message(ctx), "not 0.3") != NULL);
    ASSERT_EQ_INT(
        vp_shape_mesh(ctx, VP_SHAPE_SUPERBALL, NAN, NULL, NULL, &nv, NULL, &nf, NULL, &ni),
        VP_ERR_INVALID_ARGUMENT);
    ASSERT_EQ_INT(vp_shape_mesh(ctx, VP_SHAPE_MESH, 0, NULL, NULL, &nv, NULL, &nf, NULL, &ni),
                  VP_ERR_INVALID_ARGUMENT);
    ASSERT_EQ_INT(vp_shape_mesh(ctx, (vp_shape)40, 0, NULL, NULL, &nv, NULL, &nf, NULL, &ni),
                  VP_ERR_INVALID_ARGUMENT);
    ASSERT_EQ_INT(vp_shape_mesh(ctx, VP_SHAPE_CUBE, 0, NULL, NULL, NULL, NULL, &nf, NULL, &ni),
                  VP_ERR_INVALID_ARGUMENT);

    unlink(obj);
    rmdir(dir);
    vp_context_destroy(ctx);
    fprintf(stderr, "vp_shape_mesh: %d shapes equal their OBJ, closed and outward\n", tested);
    return 0;
}
