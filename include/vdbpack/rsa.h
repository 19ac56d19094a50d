/* SPDX-License-Identifier: Apache-2.0 */
/* Random sequential addition of spheres (part of vdbpack.h): one or more
 * passes, each a count (or "maximal": until no room is left), a radius
 * distribution, a retry limit and an optional grow step. Pass k's particles
 * form group "passk" (or the pass's name). */
/* Self-contained: included first, it brings in vdbpack.h, which includes
 * this header where the declarations it needs are in place. */
#include "vdbpack/vdbpack.h"

#ifndef VDBPACK_RSA_H
#define VDBPACK_RSA_H

#ifdef __cplusplus
extern "C" {
#endif


#define VP_RSA_DEFAULT_RETRIES 5000

typedef struct vp_rsa_pass {
    size_t count;                 /* particles wanted (ignored when maximal) */
    int maximal;                  /* 1: fill until no centre of this pass's radius fits
                              anywhere (a maximal set). With a distribution
                              (spheres): until none of its smallest radius
                              fits; each try draws from the distribution, cut
                              at the room where it lands. Solids: the retry
                              limit ends it */
    vp_size_dist radius;          /* bounding-sphere radius */
    int retries;                  /* consecutive failed tries after which the pass
                              ends; 0 = VP_RSA_DEFAULT_RETRIES */
    int grow;                     /* after the pass, grow its particles until each
                              touches a neighbour (or the wall with fit inside) */
    char name[VP_GROUP_NAME_MAX]; /* group name; "" = "passK" (K from 1) */
    int own_shape;                /* 1: this pass packs `shape`; 0 (default): the
                              params' shape. Passes of different shapes make
                              a mixed set (VP_SHAPE_MIXED, at most
                              VP_MAX_SHAPES shapes; no margin, gap, fields
                              or bounding-box test) */
    vp_shape_ref shape;
} vp_rsa_pass;
VP_API void vp_rsa_pass_init(vp_rsa_pass *p);

typedef enum vp_orient_mode {
    VP_ORIENT_RANDOM = 0, /* uniform random rotations (Marsaglia), per particle */
    VP_ORIENT_FIXED       /* every particle in the shape's canonical orientation */
} vp_orient_mode;

typedef enum vp_overlap_mode {
    VP_OVERLAP_EXACT = 0, /* separating-axis test of the solids */
    VP_OVERLAP_BBOX       /* axis-aligned bounding boxes (needs VP_ORIENT_FIXED):
                             the original design's test */
} vp_overlap_mode;

typedef struct vp_rsa_params {
    vp_fit fit;
    vp_shape shape;            /* VP_SHAPE_SPHERE (default), a platonic solid or
                                  VP_SHAPE_MESH; radii are bounding-sphere radii */
    const vp_mesh_shape *mesh; /* the shape for VP_SHAPE_MESH; not owned, must
                                  outlive the particle set (which points to it) */
    vp_orient_mode orient;     /* solids only; default random */
    vp_overlap_mode overlap;   /* solids only; default exact */
    const vp_rsa_pass *passes; /* not owned; npasses in 1..VP_MAX_GROUPS */
    size_t npasses;
    uint64_t seed;
    size_t max_cells;   /* most active cells a refinement may make (memory:
                                  8 to 16 bytes each for spheres, 5 to 13 for
                                  solids); 0 = automatic, 32 x the
                                  expected count of the pass (at least 65536) */
    double shape_param; /* VP_SHAPE_SUPERBALL: the exponent p */
    double margin;      /* spheres: world distance each keeps from the
                                  wall (its surface with fit inside, its centre
                                  with fit center); default 0 */
    double gap;         /* spheres: world distance between the surfaces
                                  of any two (< the smallest radius); default 0 */
    /* Fields (field.h, docs/fields.md; spheres only, not owned, NULL =
     * none). With either, the passes run the field packer: darts uniform in
     * the container, each given the radius at its centre and kept with the
     * density's probability; a pass ends at its count or its retry limit
     * (count=max included; grow is refused). The fields must cover the
     * container (vp_field_check), or VP_ERR_INVALID_ARGUMENT. */
    const vp_field *radius_field; /* the radius at each centre: with
                                       VP_FIELD_SCALE (default) times a radius
                                       drawn from the pass's distribution,
                                       with VP_FIELD_ABSOLUTE the radius itself
                                       (the pass's radius is then ignored) */
    vp_field_mode radius_field_mode;
    const vp_field *density_field; /* relative number density: a dart at x is
                                       kept with probability f(x) / max f over
                                       the container (>= 0, not all 0) */
} vp_rsa_params;
VP_API void vp_rsa_params_init(vp_rsa_params *p);

typedef enum vp_rsa_stop {
    VP_RSA_STOP_COUNT = 0, /* placed every particle asked for */
    VP_RSA_STOP_RETRIES,   /* a particle failed `retries` times in a row */
    VP_RSA_STOP_MAXIMAL    /* maximal mode: no room left */
} vp_rsa_stop;

typedef struct vp_rsa_pass_report {
    size_t requested; /* count (0 for maximal) */
    size_t placed;
    vp_rsa_stop stop;
    uint64_t tries;     /* candidate centres tested */
    uint64_t pretested; /* solids: tries whose exact tests against the particles
                              placed before their batch ran in parallel while the
                              darts were made (every try of a one-radius pass) */
    int budget_hit;     /* 1 when a refinement of the empty space would have
                              made more than max_cells cells: the pass went on
                              with plain darts in the cells it had */
    double grow_mean;   /* with grow: mean final/initial radius; else 1 */
    double seconds;
} vp_rsa_pass_report;

typedef struct vp_rsa_report {
    size_t npasses;
    vp_rsa_pass_report passes[VP_MAX_GROUPS];
    double particle_volume;
    double seconds;
} vp_rsa_report;

/* Fills container c; *out (owned by the caller) has radii, groups and,
 * for solids, one orient per particle. Deterministic in params->seed whatever the thread count. report
 * may be NULL. */
VP_API vp_result vp_pack_rsa(vp_context *ctx, const vp_container *c, const vp_rsa_params *params,
                             vp_particles **out, vp_rsa_report *report);
/* The container's load parameters for this job (as
 * vp_container_params_for_lattice in vdbpack.h): the largest radius of the
 * passes sizes the level set's interior band. */
VP_API void vp_container_params_for_rsa(vp_container_params *cp, const vp_rsa_params *params);
#ifdef __cplusplus
}
#endif
#endif
