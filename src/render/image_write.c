/* SPDX-License-Identifier: Apache-2.0 */
/* A rendered image as PNG (libpng: 8-bit sRGB RGBA, straight alpha), and the
 * choice between PNG and OpenEXR by extension. Written atomically. */
#include "vdbpack/vdbpack.h"

#include <ctype.h>
#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/atomic.h"
#include "core/context.h"

static int has_ext(const char *path, const char *ext) {
    size_t n = strlen(path), e = strlen(ext);
    if (n <= e) return 0;
    for (size_t i = 0; i < e; i++)
        if (tolower((unsigned char)path[n - e + i]) != ext[i]) return 0;
    return 1;
}

vp_result vp_image_write(vp_context *ctx, const vp_image *img, const char *path) {
    if (!path || !*path) return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "no output path given");
    if (has_ext(path, ".exr")) return vp_image_write_exr(ctx, img, path);
    if (has_ext(path, ".png")) return vp_image_write_png(ctx, img, path);
    return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT,
                   "%s: unknown image type (the name must end in .exr or .png)", path);
}

static uint8_t srgb8(double linear) {
    if (!(linear > 0)) return 0;
    if (linear >= 1) return 255;
    double s = linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1 / 2.4) - 0.055;
    return (uint8_t)lround(s * 255.0);
}

typedef struct png_err {
    char msg[256];
} png_err;

static void on_png_error(png_structp png, png_const_charp msg) {
    png_err *e = png_get_error_ptr(png);
    if (e) snprintf(e->msg, sizeof e->msg, "%s", msg);
    png_longjmp(png, 1);
}

static void on_png_warning(png_structp png, png_const_charp msg) {
    (void)png;
    (void)msg;
}

/* Everything libpng touches lives here so that longjmp leaves no
 * indeterminate locals behind. */
typedef struct png_state {
    FILE *f;
    png_structp png;
    png_infop info;
    uint8_t *row;
} png_state;

static int png_run(png_state *s, const vp_image *img, png_err *err) {
    s->png = png_create_write_struct(PNG_LIBPNG_VER_STRING, err, on_png_error, on_png_warning);
    if (!s->png) return -1;
    s->info = png_create_info_struct(s->png);
    if (!s->info) return -1;
    if (setjmp(png_jmpbuf(s->png))) return -1;
    png_init_io(s->png, s->f);
    png_set_compression_level(s->png, 9);
    png_set_IHDR(s->png, s->info, (png_uint_32)img->width, (png_uint_32)img->height, 8,
                 PNG_COLOR_TYPE_RGB_ALPHA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(s->png, s->info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(s->png, s->info);
    for (int y = 0; y < img->height; y++) {
        const float *src = img->rgba + 4 * (size_t)y * (size_t)img->width;
        for (int x = 0; x < img->width; x++) {
            double a = src[4 * x + 3];
            uint8_t *d = s->row + 4 * x;
            for (int k = 0; k < 3; k++) d[k] = srgb8(a > 0 ? src[4 * x + k] / a : 0.0);
            d[3] = (uint8_t)lround(fmin(fmax(a, 0.0), 1.0) * 255.0);
        }
        png_write_row(s->png, s->row);
    }
    png_write_end(s->png, NULL);
    return 0;
}

vp_result vp_image_write_png(vp_context *ctx, const vp_image *img, const char *path) {
    if (!img || !img->rgba || img->width < 1 || img->height < 1)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: no image to write", path ? path : "");
    vp_atomic at;
    vp_result r = vp_atomic_begin(ctx, path, &at);
    if (r != VP_OK) return r;
    png_err err;
    memset(&err, 0, sizeof err);
    png_state s;
    memset(&s, 0, sizeof s);
    s.f = fopen(at.tmp_path, "wb");
    s.row = malloc(4 * (size_t)img->width);
    int rc = (s.f && s.row) ? png_run(&s, img, &err) : -1;
    if (s.png) png_destroy_write_struct(&s.png, s.info ? &s.info : NULL);
    free(s.row);
    if (s.f && fclose(s.f) != 0) rc = -1;
    if (rc != 0) {
        vp_atomic_abort(&at);
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot write PNG%s%s", path, err.msg[0] ? ": " : "",
                       err.msg);
    }
    return vp_atomic_commit(ctx, &at);
}
