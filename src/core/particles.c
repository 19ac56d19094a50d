/* SPDX-License-Identifier: Apache-2.0 */
/* Particle sets (structure of arrays; see vdbpack.h). */
#include "core/context.h"
#include "core/shape.h"

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
    free(p);
}

double vp_particles_volume(const vp_particles *p) {
    if (!p) return 0.0;
    double unit = p->shape == VP_SHAPE_MESH ? vp_mesh_shape_volume(p->mesh)
                                            : vp_shape_unit_volume_param(p->shape, p->shape_param),
           sum = 0.0;
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
