/* SPDX-License-Identifier: Apache-2.0 */
/* The exact overlap test of two particles of any shapes; see pair.h. */
#include "core/pair.h"

#include "core/geom.h"
#include "core/mesh_shape.h"
#include "core/shape.h"
#include "core/superball.h"

#include <math.h>
#include <string.h>

int vp_kind_set(vp_kind *k, vp_shape_ref ref) {
    memset(k, 0, sizeof *k);
    k->shape = ref.shape;
    if (ref.shape == VP_SHAPE_MESH) {
        if (!ref.mesh) return -1;
        k->mesh = ref.mesh;
        k->rin = ref.mesh->inradius;
        k->unit_volume = ref.mesh->volume;
        return 0;
    }
    if (ref.shape == VP_SHAPE_SUPERBALL) {
        if (!(ref.param >= VP_SUPERBALL_P_MIN && ref.param <= VP_SUPERBALL_P_MAX)) return -1;
        k->param = ref.param;
        k->rin = vp_superball_inradius(ref.param);
        k->unit_volume = vp_shape_unit_volume_param(ref.shape, ref.param);
        return 0;
    }
    if ((int)ref.shape < 0 || ref.shape >= VP_SHAPE_COUNT) return -1;
    k->poly = vp_shape_polyhedron(ref.shape);
    k->rin = k->poly ? k->poly->inradius : 1.0;
    k->unit_volume = vp_shape_unit_volume(ref.shape);
    return 0;
}

int vp_kind_overlap(const vp_kind *ka, double sa, const double qa[4], const double ta[3],
                    const vp_kind *kb, double sb, const double qb[4], const double tb[3]) {
    return vp_kind_overlap_gap(ka, sa, qa, ta, kb, sb, qb, tb, 0.0);
}

int vp_kind_overlap_gap(const vp_kind *ka, double sa, const double qa[4], const double ta[3],
                        const vp_kind *kb, double sb, const double qb[4], const double tb[3],
                        double gap) {
    return vp_kind_overlap_state(ka, sa, qa, ta, kb, sb, qb, tb, gap) != 0;
}

int vp_kind_overlap_state(const vp_kind *ka, double sa, const double qa[4], const double ta[3],
                          const vp_kind *kb, double sb, const double qb[4], const double tb[3],
                          double gap) {
    double d2 = 0.0;
    for (int k = 0; k < 3; k++) d2 += (ta[k] - tb[k]) * (ta[k] - tb[k]);
    double e = sa + sb + gap, ein = ka->rin * sa + kb->rin * sb + gap;
    if (d2 >= e * e) return 0;    /* bounding spheres apart (or touching) */
    if (d2 < ein * ein) return 1; /* inspheres overlap */
    if (gap > 0) {
        if (ka->mesh || kb->mesh) return 1; /* not offered: refuse */
        vp_convex A, B;
        vp_convex_set(&A, ka->shape, ka->param, sa, qa, ta, ta);
        vp_convex_set(&B, kb->shape, kb->param, sb, qb, tb, ta);
        A.inflate = B.inflate = 0.5 * gap;
        return vp_convex_overlap_state(&A, &B);
    }
    if (ka->mesh && kb->mesh)
        return vp_mesh_shape_overlap2(ka->mesh, sa, qa, ta, kb->mesh, sb, qb, tb, NULL);
    if (ka->mesh || kb->mesh) {
        const vp_kind *km = ka->mesh ? ka : kb, *kc = ka->mesh ? kb : ka;
        double sm = ka->mesh ? sa : sb, sc = ka->mesh ? sb : sa;
        const double *qm = ka->mesh ? qa : qb, *qc = ka->mesh ? qb : qa;
        const double *tm = ka->mesh ? ta : tb, *tc = ka->mesh ? tb : ta;
        vp_convex C; /* posed about its own centre: small numbers */
        vp_convex_set(&C, kc->shape, kc->param, sc, qc, tc, tc);
        return vp_mesh_shape_overlap_convex(km->mesh, sm, qm, tm, &C, tc,
                                            sc); /* (refuses undecided) */
    }
    if (ka->poly && ka->poly == kb->poly && !vp_shape_overlap_by_gjk(ka->shape))
        return vp_poly_separation(ka->poly, sa, qa, ta, kb->poly, sb, qb, tb) < 0;
    vp_convex A, B; /* both about a's centre */
    vp_convex_set(&A, ka->shape, ka->param, sa, qa, ta, ta);
    vp_convex_set(&B, kb->shape, kb->param, sb, qb, tb, ta);
    return vp_convex_overlap_state(&A, &B);
}
