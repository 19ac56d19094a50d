/* SPDX-License-Identifier: Apache-2.0 */
/* Particle sets (structure of arrays; see vdbpack.h). */
#include "core/context.h"
#include "core/shape.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

vp_result vp_particles_create(vp_context *ctx, size_t capacity, vp_particles **out) {
    if (!out) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "particles: out is NULL");
    *out = NULL;
    vp_particles *p = calloc(1, sizeof *p);
    if (!p) return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "particles: out of memory");
    if (capacity) {
        if (capacity > SIZE_MAX / (3 * sizeof(double)) ||
            !(p->positions = malloc(capacity * 3 * sizeof(double)))) {
            free(p);
            return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "particles: cannot allocate %zu particles",
                           capacity);
        }
    }
    p->capacity = capacity;
    p->uniform_orient[3] = 1.0f;
    p->group_count = 1;
    strcpy(p->group_names[0], "pass1");
    *out = p;
    return VP_OK;
}

void vp_particles_destroy(vp_particles *p) {
    if (!p) return;
    free(p->positions);
    free(p->radii);
    free(p->orients);
    free(p->groups);
    free(p->shape_index);
    free(p);
}

vp_shape_ref vp_particles_shape_of(const vp_particles *p, size_t i) {
    if (p->shape == VP_SHAPE_MIXED && p->shape_index && i < p->count &&
        p->shape_index[i] < p->shape_count)
        return p->shapes[p->shape_index[i]];
    vp_shape_ref r = {p->shape, p->shape_param, p->shape == VP_SHAPE_MESH ? p->mesh : NULL};
    return r;
}

const char *vp_particles_shape_list(const vp_particles *p, char *buf, size_t n) {
    if (!n) return buf;
    buf[0] = 0;
    unsigned count = p->shape == VP_SHAPE_MIXED ? p->shape_count : 1;
    size_t used = 0;
    for (unsigned k = 0; k < count && k < VP_MAX_SHAPES; k++) {
        vp_shape_ref r = p->shape == VP_SHAPE_MIXED ? p->shapes[k] : vp_particles_shape_of(p, 0);
        char one[300];
        if (r.shape == VP_SHAPE_MESH && r.mesh)
            snprintf(one, sizeof one, "mesh:%s", vp_mesh_shape_name(r.mesh));
        else if (r.shape == VP_SHAPE_MESH && p->shape == VP_SHAPE_MIXED && p->shape_names[k][0])
            snprintf(one, sizeof one, "mesh:%.*s", VP_SHAPE_NAME_MAX, p->shape_names[k]);
        else if (r.shape == VP_SHAPE_MESH) snprintf(one, sizeof one, "mesh");
        else vp_shape_format(r.shape, r.param, one, sizeof one);
        int w = snprintf(buf + used, n - used, "%s%s", k ? ";" : "", one);
        if (w < 0 || (size_t)w >= n - used) break;
        used += (size_t)w;
    }
    return buf;
}

int vp_shape_list_parse(const char *text, vp_shape_ref *shapes, unsigned *count,
                        char (*names)[VP_SHAPE_NAME_MAX]) {
    *count = 0;
    for (const char *a = text;;) {
        const char *b = strchr(a, ';');
        size_t len = b ? (size_t)(b - a) : strlen(a);
        char one[300];
        if (*count == VP_MAX_SHAPES || len == 0 || len >= sizeof one) return -1;
        memcpy(one, a, len);
        one[len] = 0;
        vp_shape_ref r = {VP_SHAPE_SPHERE, 0.0, NULL};
        if (names) names[*count][0] = 0;
        if (!strcmp(one, "mesh") || !strncmp(one, "mesh:", 5)) {
            r.shape = VP_SHAPE_MESH;
            if (names && one[4] == ':')
                snprintf(names[*count], VP_SHAPE_NAME_MAX, "%.*s", VP_SHAPE_NAME_MAX - 1, one + 5);
        } else if (vp_shape_parse_param(one, &r.shape, &r.param) != 0) {
            return -1;
        }
        shapes[(*count)++] = r;
        if (!b) return 0;
        a = b + 1;
    }
}

/* Volume at bounding radius 1 of a shape (0 for an invalid one). */
static double ref_volume(vp_shape_ref r) {
    return r.shape == VP_SHAPE_MESH ? vp_mesh_shape_volume(r.mesh)
                                    : vp_shape_unit_volume_param(r.shape, r.param);
}

double vp_particles_volume(const vp_particles *p) {
    if (!p) return 0.0;
    if (p->shape == VP_SHAPE_MIXED) { /* per particle */
        double unit[VP_MAX_SHAPES], sum = 0.0;
        for (unsigned k = 0; k < p->shape_count && k < VP_MAX_SHAPES; k++)
            unit[k] = ref_volume(p->shapes[k]);
        for (size_t i = 0; i < p->count; i++) {
            double r = p->radii ? p->radii[i] : p->uniform_radius;
            unsigned k = p->shape_index ? p->shape_index[i] : 0;
            sum += (k < p->shape_count ? unit[k] : 0.0) * r * r * r;
        }
        return sum;
    }
    double unit = ref_volume(vp_particles_shape_of(p, 0)), sum = 0.0;
    if (!p->radii) {
        double r = p->uniform_radius;
        return unit * r * r * r * (double)p->count;
    }
    for (size_t i = 0; i < p->count; i++) {
        double r = p->radii[i];
        sum += r * r * r;
    }
    return unit * sum;
}
