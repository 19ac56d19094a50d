/* SPDX-License-Identifier: Apache-2.0 */
/* Preview renders of a particle set (part of the public API, included from
 * vdbpack.h): a small ray tracer over spheres and the platonic solids with
 * their orientations, and image writers for OpenEXR and PNG.
 * See docs/render.md for what is drawn and what each channel holds. */
/* Self-contained: included first, it brings in vdbpack.h, which includes
 * this header where the declarations it needs are in place. */
#include "vdbpack/vdbpack.h"

#ifndef VDBPACK_RENDER_H
#define VDBPACK_RENDER_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum vp_render_view {
    VP_VIEW_ISO = 0, /* from (+1,+1,+1) towards the centre, +Y up (default) */
    VP_VIEW_FRONT,   /* from +Z looking along -Z, +Y up (Houdini's front) */
    VP_VIEW_TOP,     /* from +Y looking down, -Z up */
    VP_VIEW_CAMERA   /* eye, target and up of the params */
} vp_render_view;

typedef enum vp_render_colour {
    VP_COLOUR_PASS = 0, /* one colour per point group (pass) */
    VP_COLOUR_SIZE,     /* radius on a blue-to-yellow ramp, smallest to largest */
    VP_COLOUR_ID,       /* a pseudo-random colour per id */
    VP_COLOUR_CONTACTS  /* spheres: the number of neighbours each touches
                           (a gap below 1e-4 of r_i + r_j): grey below 4
                           (rattlers), then blue 4, cyan 5, green 6, yellow
                           7, red 8 or more */
} vp_render_colour;

/* Background values of the image channels where no particle projects. */
#define VP_RENDER_BACKGROUND_ID 0xFFFFFFFFu /* id channel */
/* Z is +infinity (IEEE) on the background, and A = R = G = B = 0. */

#define VP_RENDER_MAX_SIDE 16384
#define VP_RENDER_MAX_PIXELS (64u * 1024u * 1024u)

typedef struct vp_render_params {
    int width, height;        /* pixels; default 960 x 540; each side in
                                 1..VP_RENDER_MAX_SIDE, width * height <=
                                 VP_RENDER_MAX_PIXELS */
    vp_render_view view;      /* default VP_VIEW_ISO; the automatic views
                                 frame the bounds of the particles (centres
                                 +- radii) */
    double eye[3], target[3]; /* VP_VIEW_CAMERA: camera position and the
                                 point it looks at */
    double up[3];             /* VP_VIEW_CAMERA: up direction; zero = +Y (or
                                 -Z when looking along Y) */
    double fov_degrees;       /* vertical field of view; default 30 */
    vp_render_colour colour;  /* default VP_COLOUR_PASS */
    int cut_axis;             /* -1 (default): no cut; 0, 1, 2: remove all that
                                 lies where coordinate `cut_axis` > cut_value;
                                 particles crossing the plane show their cut
                                 face */
    double cut_value;
    int ao_samples; /* ambient-occlusion rays per pixel; default 8,
                                 0 = none, at most 64 */
    int shadows;    /* key-light shadow rays; default 1 */
} vp_render_params;
VP_API void vp_render_params_init(vp_render_params *p);

/* A rendered image, row 0 at the top. All arrays are owned by the image
 * (vp_image_destroy) and hold width * height pixels. */
typedef struct vp_image {
    int width, height;
    float *rgba;  /* 4 floats a pixel, linear, premultiplied by A (A is 0 or
                     1: one sample a pixel) */
    float *z;     /* distance from the eye to the visible surface along the
                     pixel's ray, world units; +inf on the background */
    uint32_t *id; /* id of the visible particle (its index in the set, as
                     vp_write_points writes the id attribute);
                     VP_RENDER_BACKGROUND_ID on the background */
} vp_image;

/* Renders p as seen with params (NULL = defaults) on
 * vp_context_set_threads() threads; the image does not depend on that
 * number. *out is owned by the caller (vp_image_destroy). Fails with
 * VP_ERR_INVALID_ARGUMENT for an empty set, a bad size or camera, and
 * VP_ERR_OUT_OF_MEMORY when the image and the acceleration grid would not
 * fit in the context's memory limit. Reports progress and may be
 * cancelled. */
VP_API vp_result vp_render(vp_context *ctx, const vp_particles *p, const vp_render_params *params,
                           vp_image **out);
VP_API void vp_image_destroy(vp_image *img);

/* Bytes vp_render needs beyond the particle set and the image, for a set of
 * `count` particles each overlapping `refs_per_particle` grid cells on
 * average (about 8 in dense packings): for estimates and the benchmark. */
VP_API uint64_t vp_render_grid_bytes(size_t count, double refs_per_particle);

/* Writes img to path, atomically: OpenEXR (".exr": scanlines, ZIP, channels
 * R, G, B, A, Z as 32-bit float and id as 32-bit uint) or PNG (".png": 8-bit
 * sRGB RGBA, straight alpha), chosen by the extension (case-insensitive);
 * other extensions fail with VP_ERR_INVALID_ARGUMENT. */
VP_API vp_result vp_image_write(vp_context *ctx, const vp_image *img, const char *path);
VP_API vp_result vp_image_write_exr(vp_context *ctx, const vp_image *img, const char *path);
VP_API vp_result vp_image_write_png(vp_context *ctx, const vp_image *img, const char *path);

#ifdef __cplusplus
}
#endif
#endif
