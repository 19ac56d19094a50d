/* SPDX-License-Identifier: Apache-2.0 */
/* A rendered image as an OpenEXR file through OpenEXR's C API (OpenEXRCore):
 * one scanline part, ZIP compression, channels R, G, B, A, Z (32-bit float)
 * and id (32-bit uint). Written to a temporary file and renamed. */
#include "vdbpack/vdbpack.h"

#include <stdio.h>
#include <string.h>

#include <OpenEXR/openexr.h>

#include "api/atomic.h"
#include "core/context.h"

typedef struct exr_errbuf {
    char msg[512];
} exr_errbuf;

/* OpenEXRCore prints errors on stderr by default; keep the first one for
 * the context's message instead. */
static void on_exr_error(exr_const_context_t ectx, exr_result_t code, const char *msg) {
    void *ud = NULL;
    if (exr_get_user_data(ectx, &ud) != EXR_ERR_SUCCESS || !ud) return;
    exr_errbuf *e = ud;
    if (!e->msg[0])
        snprintf(e->msg, sizeof e->msg, "%s (%s)", msg ? msg : "",
                 exr_get_error_code_as_string(code));
}

typedef struct exr_chan {
    const char *name;
    exr_pixel_type_t type;
    const uint8_t *base; /* first pixel of row 0 */
    int pixel_stride;    /* bytes */
} exr_chan;

vp_result vp_image_write_exr(vp_context *ctx, const vp_image *img, const char *path) {
    if (!img || !img->rgba || !img->z || !img->id || img->width < 1 || img->height < 1)
        return vp_fail(ctx, VP_ERR_INVALID_ARGUMENT, "%s: no image to write", path ? path : "");
    vp_atomic at;
    vp_result r = vp_atomic_begin(ctx, path, &at);
    if (r != VP_OK) return r;

    const exr_chan chans[6] = {
        {"R", EXR_PIXEL_FLOAT, (const uint8_t *)(img->rgba + 0), 16},
        {"G", EXR_PIXEL_FLOAT, (const uint8_t *)(img->rgba + 1), 16},
        {"B", EXR_PIXEL_FLOAT, (const uint8_t *)(img->rgba + 2), 16},
        {"A", EXR_PIXEL_FLOAT, (const uint8_t *)(img->rgba + 3), 16},
        {"Z", EXR_PIXEL_FLOAT, (const uint8_t *)img->z, 4},
        {"id", EXR_PIXEL_UINT, (const uint8_t *)img->id, 4},
    };
    exr_errbuf eb;
    memset(&eb, 0, sizeof eb);
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_exr_error;
    init.user_data = &eb;
    exr_context_t ex = NULL;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int enc_init = 0;
    int part = 0;
    exr_result_t er = exr_start_write(&ex, at.tmp_path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (er == EXR_ERR_SUCCESS) er = exr_add_part(ex, "preview", EXR_STORAGE_SCANLINE, &part);
    if (er == EXR_ERR_SUCCESS)
        er = exr_initialize_required_attr_simple(ex, part, img->width, img->height,
                                                 EXR_COMPRESSION_ZIP);
    for (int c = 0; c < 6 && er == EXR_ERR_SUCCESS; c++)
        er = exr_add_channel(ex, part, chans[c].name, chans[c].type,
                             c < 3 ? EXR_PERCEPTUALLY_LOGARITHMIC : EXR_PERCEPTUALLY_LINEAR, 1, 1);
    if (er == EXR_ERR_SUCCESS)
        er = exr_attr_set_string(ex, part, "software", "vdbpack " VP_VERSION_STRING);
    if (er == EXR_ERR_SUCCESS) er = exr_write_header(ex);
    int32_t lines = 1;
    if (er == EXR_ERR_SUCCESS) er = exr_get_scanlines_per_chunk(ex, part, &lines);
    for (int y = 0; y < img->height && er == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t ci;
        er = exr_write_scanline_chunk_info(ex, part, y, &ci);
        if (er != EXR_ERR_SUCCESS) break;
        er = enc_init ? exr_encoding_update(ex, part, &ci, &enc)
                      : exr_encoding_initialize(ex, part, &ci, &enc);
        if (er != EXR_ERR_SUCCESS) break;
        /* the pipeline lists the channels in the file's (sorted) order */
        for (int k = 0; k < enc.channel_count; k++) {
            exr_coding_channel_info_t *cc = &enc.channels[k];
            const exr_chan *src = NULL;
            for (int c = 0; c < 6; c++)
                if (!strcmp(cc->channel_name, chans[c].name)) src = &chans[c];
            if (!src) {
                er = EXR_ERR_INVALID_ARGUMENT;
                break;
            }
            cc->user_bytes_per_element = 4;
            cc->user_data_type = (uint16_t)src->type;
            cc->user_pixel_stride = src->pixel_stride;
            cc->user_line_stride = src->pixel_stride * img->width;
            cc->encode_from_ptr = src->base + (size_t)y * (size_t)cc->user_line_stride;
        }
        if (er != EXR_ERR_SUCCESS) break;
        if (!enc_init) {
            er = exr_encoding_choose_default_routines(ex, part, &enc);
            enc_init = 1;
            if (er != EXR_ERR_SUCCESS) break;
        }
        er = exr_encoding_run(ex, part, &enc);
    }
    if (enc_init || enc.channels) exr_encoding_destroy(ex, &enc);
    exr_result_t fr = ex ? exr_finish(&ex) : EXR_ERR_SUCCESS;
    if (er == EXR_ERR_SUCCESS) er = fr;
    if (er != EXR_ERR_SUCCESS) {
        vp_atomic_abort(&at);
        return vp_fail(ctx, VP_ERR_IO, "%s: cannot write OpenEXR: %s", path,
                       eb.msg[0] ? eb.msg : exr_get_default_error_message(er));
    }
    return vp_atomic_commit(ctx, &at);
}
