/* SPDX-License-Identifier: Apache-2.0 */
/* Independent verification of a packing; see check.h and docs/check.md.
 * Works from the particle set alone (positions, radii, orientations, shape)
 * and the container's distance: every pair of bounding spheres that may
 * touch is found with a cell grid and tested exactly (sphere distance, or
 * the separating-axis test for polyhedra). */
#include "core/container.h"
#include "core/context.h"
#include "core/geom.h"
#include "core/sgrid.h"
#include "core/mesh_shape.h"
#include "core/pair.h"
#include "core/shape.h"
#include "core/superball.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void vp_check_params_init(vp_check_params *p) {
    memset(p, 0, sizeof *p);
    p->fit = VP_FIT_INSIDE;
    p->overlap_tolerance = 1e-6;
    p->contact_tolerance = 1e-3;
    p->wall_tolerance = -1.0;
    p->position_tolerance = VP_POSITION_ERROR_LIMIT;
}

typedef struct chk {
    const vp_particles *p;
    const vp_polyhedron *poly;
    const vp_mesh_shape *mesh;
    double sb; /* superball exponent, or 0 */
    const vp_check_params *prm;
    double *r;    /* radii (double) */
    double slack; /* 2 x position error (world) */
    size_t i;
    vp_check_report *rep;
    const vp_kind *kinds; /* a mixed set: its shapes (else NULL) */
} chk;

static void orient_of(const vp_particles *p, size_t i, double q[4]) {
    vp_quat_from_float(p->orients ? p->orients + 4 * i : p->uniform_orient, q);
}

/* A pair of a mixed set: the gap (< 0: minus the overlap's depth; 0 a
 * contact; HUGE_VAL apart) from vp_kind_overlap, the one test of every
 * pairing, as the superballs' below: the largest common shrink g about
 * both centres that parts them gives the depth d (1 - g) / g. */
static double mixed_gap(const chk *q, size_t i, size_t j, double *scale) {
    const vp_particles *p = q->p;
    const int one = p->shape != VP_SHAPE_MIXED; /* a gap between solids of one shape */
    const vp_kind *ka = &q->kinds[one ? 0 : p->shape_index[i]],
                  *kb = &q->kinds[one ? 0 : p->shape_index[j]];
    const double G = q->prm->gap;
    const double *xi = p->positions + 3 * i, *xj = p->positions + 3 * j;
    double ri = q->r[i], rj = q->r[j], d2 = 0.0;
    for (int k = 0; k < 3; k++) d2 += (xi[k] - xj[k]) * (xi[k] - xj[k]);
    double d = sqrt(d2);
    if (!ka->poly && !ka->mesh && ka->shape == VP_SHAPE_SPHERE && kb->shape == VP_SHAPE_SPHERE) {
        *scale = ri + rj;
        return d - ri - rj - G;
    }
    double qa[4], qb[4], g = 1.0 + q->prm->contact_tolerance;
    orient_of(p, i, qa);
    orient_of(p, j, qb);
    *scale = ri < rj ? ri : rj;
    /* GJK undecided (within a hair of touching, smooth shapes): a contact */
    int st = vp_kind_overlap_state(ka, ri, qa, xi, kb, rj, qb, xj, G);
    if (st < 0) return 0.0;
    if (st) {
        /* closer than the gap: by how much, from the common shrink (of
         * the shapes and the gap) that parts them */
        double lo = 0.0, hi = 1.0;
        for (int it = 0; it < 60; it++) {
            double m = 0.5 * (lo + hi);
            if (vp_kind_overlap_state(ka, ri * m, qa, xi, kb, rj * m, qb, xj, G * m) > 0) hi = m;
            else lo = m;
        }
        return lo > 0 ? -d * (1.0 - lo) / lo : -(ri + rj);
    }
    return vp_kind_overlap_gap(ka, ri * g, qa, xi, kb, rj * g, qb, xj, G * g) ? 0.0 : HUGE_VAL;
}

static int pair_visit(void *user, uint32_t j) {
    chk *q = user;
    if (j <= q->i) return 0; /* each pair once */
    const double *xi = q->p->positions + 3 * q->i, *xj = q->p->positions + 3 * (size_t)j;
    double ri = q->r[q->i], rj = q->r[j], e = ri + rj;
    double dx = xi[0] - xj[0], dy = xi[1] - xj[1], dz = xi[2] - xj[2];
    double d2 = dx * dx + dy * dy + dz * dz;
    double reach = e * (1.0 + q->prm->contact_tolerance) + q->slack + q->prm->gap;
    if (d2 >= reach * reach) return 0;
    double gap, scale;
    if (q->kinds) {
        gap = mixed_gap(q, q->i, j, &scale);
    } else if (q->sb > 0) {
        /* GJK on the support functions; the depth of an overlap from the
         * largest common shrink g of both about their centres that parts
         * them: d (1 - g) / g, which is r_i + r_j - d for spheres */
        double qa[4], qb[4], d = sqrt(d2), g = 1.0 + q->prm->contact_tolerance;
        orient_of(q->p, q->i, qa);
        orient_of(q->p, j, qb);
        scale = ri < rj ? ri : rj;
        if (vp_superball_overlap(q->sb, ri, qa, xi, rj, qb, xj)) {
            double lo = 0.0, hi = 1.0;
            for (int it = 0; it < 60; it++) {
                double m = 0.5 * (lo + hi);
                if (vp_superball_overlap(q->sb, ri * m, qa, xi, rj * m, qb, xj)) hi = m;
                else lo = m;
            }
            gap = lo > 0 ? -d * (1.0 - lo) / lo : -e;
        } else if (vp_superball_overlap(q->sb, ri * g, qa, xi, rj * g, qb, xj)) {
            gap = 0.0;
        } else {
            gap = HUGE_VAL;
        }
    } else if (q->mesh) {
        /* no distance between meshes: the penetration depth when they
         * overlap; a contact when copies larger by the contact tolerance
         * would overlap */
        double qa[4], qb[4], depth = 0.0;
        orient_of(q->p, q->i, qa);
        orient_of(q->p, j, qb);
        scale = ri < rj ? ri : rj;
        double g = 1.0 + q->prm->contact_tolerance;
        if (vp_mesh_shape_overlap(q->mesh, ri, qa, xi, rj, qb, xj, &depth)) gap = -depth;
        else if (vp_mesh_shape_overlap(q->mesh, ri * g, qa, xi, rj * g, qb, xj, NULL)) gap = 0.0;
        else gap = HUGE_VAL;
    } else if (!q->poly) {
        gap = sqrt(d2) - e - q->prm->gap; /* (the gap asked for: 0 by default) */
        scale = e;
    } else {
        double qa[4], qb[4];
        orient_of(q->p, q->i, qa);
        orient_of(q->p, j, qb);
        gap = HUGE_VAL;
        scale = ri < rj ? ri : rj;
        /* The Archimedean solids: GJK first, on copies grown about their
         * centres by g. Growing moves every face out by at least
         * (g - 1) inradius r, so a plane that separates the grown copies
         * (GJK's "apart" is a proof) shows an axis with a gap above
         * contact_tolerance (ri + rj): the pair is neither a contact nor an
         * overlap, and the SAT (up to 6 ms a pair for the snub
         * dodecahedron, bench/bench_poly_overlap.c) is not needed. Every
         * other pair gets the SAT's exact gap, as the platonic solids do. */
        int apart = 0;
        if (vp_shape_overlap_by_gjk(q->p->shape)) {
            double g = 1.0 + 1.01 * q->prm->contact_tolerance / q->poly->inradius;
            vp_convex A, B;
            vp_convex_set(&A, q->p->shape, 0, ri * g, qa, xi, xi);
            vp_convex_set(&B, q->p->shape, 0, rj * g, qb, xj, xi);
            apart = !vp_convex_overlap(&A, &B);
        }
        if (!apart) gap = vp_poly_separation(q->poly, ri, qa, xi, q->poly, rj, qb, xj);
    }
    vp_check_report *rep = q->rep;
    if (gap <= q->prm->contact_tolerance * e) rep->contact_pairs++;
    if (gap < 0) {
        double rel = -gap / scale;
        if (rel > rep->max_overlap) rep->max_overlap = rel;
        if (-gap > rep->max_overlap_world) rep->max_overlap_world = -gap;
        if (-gap > q->prm->overlap_tolerance * scale + q->slack) rep->overlapping_pairs++;
    }
    return 0;
}

vp_result vp_check_particles(vp_context *ctx, const vp_container *c, const vp_particles *p,
                             const vp_check_params *params, vp_check_report *report) {
    double t0 = vp_seconds();
    if (!c || !p || !report)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "check: container, particles and report "
                       "are required");
    vp_check_params def;
    if (!params) {
        vp_check_params_init(&def);
        params = &def;
    }
    if (!(params->overlap_tolerance >= 0) || !(params->contact_tolerance >= 0) ||
        !(params->position_tolerance >= 0))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "check: tolerances must be >= 0");
    if (!(params->margin >= 0) || !(params->gap >= 0) || !isfinite(params->margin) ||
        !isfinite(params->gap))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "check: margin and gap must be finite and "
                       ">= 0");

    vp_check_report rep;
    memset(&rep, 0, sizeof rep);
    rep.count = p->count;
    rep.container_volume = c->info.volume;
    const vp_polyhedron *poly = vp_shape_polyhedron(p->shape);
    const vp_mesh_shape *mesh = p->shape == VP_SHAPE_MESH ? p->mesh : NULL;
    vp_kind kinds[VP_MAX_SHAPES];
    /* a gap between solids: every pair through vp_kind_overlap_gap (the
     * one-shape set as a table of one) */
    int generic = p->shape == VP_SHAPE_MIXED || (params->gap > 0 && p->shape != VP_SHAPE_SPHERE);
    if (generic && p->shape != VP_SHAPE_MIXED &&
        vp_kind_set(&kinds[0], vp_particles_shape_of(p, 0)) != 0)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       p->shape == VP_SHAPE_MESH
                           ? "check: the particles are of a mesh shape: the mesh is needed"
                           : "check: the particles' shape is not valid");
    if (p->shape == VP_SHAPE_MIXED) {
        if (!p->shape_index || p->shape_count < 1 || p->shape_count > VP_MAX_SHAPES)
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "check: a mixed set needs its shape indices and 1..%d shapes",
                           VP_MAX_SHAPES);
        for (unsigned k = 0; k < p->shape_count; k++)
            if (vp_kind_set(&kinds[k], p->shapes[k]) != 0)
                return vp_fail(
                    ctx, VP_ERR_INVALID_ARGUMENT,
                    p->shapes[k].shape == VP_SHAPE_MESH
                        ? "check: shape %u of the set is a mesh shape: the mesh is needed"
                        : "check: shape %u of the set is not a valid shape",
                    k);
        for (size_t i = 0; i < p->count; i++)
            if (p->shape_index[i] >= p->shape_count)
                return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                               "check: particle %zu has shape %u of %u", i,
                               (unsigned)p->shape_index[i], p->shape_count);
    }
    if (p->shape == VP_SHAPE_MESH && !mesh)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "check: the particles are of a mesh shape: the mesh is needed");
    for (unsigned k = 0;
         generic && params->gap > 0 && k < (p->shape == VP_SHAPE_MIXED ? p->shape_count : 1); k++)
        if (kinds[k].mesh)
            return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                           "check: a gap is checked between convex shapes (spheres, solids, "
                           "superballs) in this version, not mesh shapes");
    double sb = p->shape == VP_SHAPE_SUPERBALL ? p->shape_param : 0.0;
    if (p->shape == VP_SHAPE_SUPERBALL && !(sb >= VP_SUPERBALL_P_MIN && sb <= VP_SUPERBALL_P_MAX))
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                       "check: a superball's exponent must be in [0.5, 1000], not %g", sb);
    size_t n = p->count;
    if (p->count >= UINT32_MAX - 1)
        return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "check: more than 2^32 particles");
    double *r = malloc((n ? n : 1) * sizeof *r);
    if (!r) return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "check: out of memory");
    double rmin = HUGE_VAL, rmax = 0, lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL},
           hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (size_t i = 0; i < n; i++) {
        r[i] = p->radii ? p->radii[i] : p->uniform_radius;
        const double *x = p->positions + 3 * i;
        if (!(r[i] > 0) || !isfinite(r[i]) || !isfinite(x[0]) || !isfinite(x[1]) ||
            !isfinite(x[2])) {
            free(r);
            return vp_fail(ctx, VP_ERR_FORMAT,
                           "check: particle %zu has a non-finite position or a radius <= 0", i);
        }
        if (r[i] < rmin) rmin = r[i];
        if (r[i] > rmax) rmax = r[i];
        for (int k = 0; k < 3; k++) {
            if (x[k] < lo[k]) lo[k] = x[k];
            if (x[k] > hi[k]) hi[k] = x[k];
        }
    }
    double e = p->position_error > 0 ? p->position_error : 0.0;
    /* positions stored coarsely against the radii: the widened tolerances
     * below would let overlaps of that size pass, so the set cannot be
     * shown to be free of them */
    if (n > 0 && e > 0) {
        rep.position_error_ratio = e / rmin;
        rep.imprecise = !(rep.position_error_ratio <= params->position_tolerance);
    }
    double wall_tol = params->wall_tolerance;
    if (wall_tol < 0) wall_tol = c->info.voxel_size > 0 ? 0.1 * c->info.voxel_size : 1e-9;
    wall_tol += e;
    /* pairs */
    if (n > 1) {
        vp_sgrid g;
        if (vp_sgrid_init(&g, lo, hi, rmin, rmax, 2 * n + 4096) != 0) {
            free(r);
            return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "check: out of memory for the grid");
        }
        for (size_t i = 0; i < n; i++) {
            if (vp_sgrid_insert(&g, (uint32_t)i, p->positions + 3 * i, r[i]) != 0) {
                vp_sgrid_free(&g);
                free(r);
                return vp_fail(ctx, VP_ERR_OUT_OF_MEMORY, "check: out of memory for the grid");
            }
        }
        chk q = {p, poly, mesh, sb, params, r, 2.0 * e, 0, &rep, generic ? kinds : NULL};
        for (size_t i = 0; i < n; i++) {
            q.i = i;
            double reach = r[i] * (1.0 + params->contact_tolerance) + 2.0 * e +
                           rmax * params->contact_tolerance + params->gap;
            vp_sgrid_query(&g, p->positions + 3 * i, reach, pair_visit, &q);
            if ((i & 0xffff) == 0 && !vp_report_progress(ctx, 0.9 * (double)i / n, "check")) {
                vp_sgrid_free(&g);
                free(r);
                return vp_fail(ctx, VP_ERR_CANCELLED, "check: cancelled");
            }
        }
        vp_sgrid_free(&g);
    }
    /* the wall */
    for (size_t i = 0; i < n; i++) {
        if ((i & 0xffff) == 0xffff &&
            !vp_report_progress(ctx, 0.9 + 0.1 * (double)i / n, "check: wall")) {
            free(r);
            return vp_fail(ctx, VP_ERR_CANCELLED, "check: cancelled");
        }
        const double *x = p->positions + 3 * i;
        double v;
        if (p->shape == VP_SHAPE_MIXED) { /* this particle's shape */
            const vp_kind *k = &kinds[p->shape_index[i]];
            vp_shape_ref ref = p->shapes[p->shape_index[i]];
            sb = ref.shape == VP_SHAPE_SUPERBALL ? ref.param : 0.0;
            mesh = k->mesh;
            poly = k->poly;
        }
        if (params->fit == VP_FIT_CENTER) {
            v = vp_container_distance(c, x);
        } else if (sb > 0) {
            double q[4], d = vp_container_distance(c, x);
            orient_of(p, i, q);
            v = d + r[i] <= -params->margin
                    ? d + r[i]
                    : vp_superball_wall_distance(c, sb, r[i], q, x, HUGE_VAL);
        } else if (mesh) {
            /* the packer's own shortcut: a bounding sphere inside passes */
            double q[4], d = vp_container_distance(c, x);
            orient_of(p, i, q);
            v = d + r[i] <= -params->margin
                    ? d + r[i]
                    : vp_mesh_shape_wall_distance(c, mesh, r[i], q, x, HUGE_VAL);
        } else if (!poly) {
            v = vp_container_distance(c, x) + r[i];
        } else {
            double q[4];
            orient_of(p, i, q);
            v = vp_poly_wall_distance(c, poly, r[i], q, x, HUGE_VAL);
        }
        v += params->margin; /* (0 by default) */
        if (!(v <= wall_tol)) {
            rep.outside++;
            if (!(v <= rep.max_outside)) rep.max_outside = isfinite(v) ? v : HUGE_VAL;
        }
    }
    free(r);
    rep.particle_volume = vp_particles_volume(p);
    rep.fraction = rep.container_volume > 0 ? rep.particle_volume / rep.container_volume : 0.0;
    rep.mean_contacts = n ? 2.0 * (double)rep.contact_pairs / (double)n : 0.0;
    rep.seconds = vp_seconds() - t0;
    *report = rep;
    return VP_OK;
}
