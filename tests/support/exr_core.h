/* Writing EXRs with OpenEXRCore directly, for inputs veil never writes:
 * half and uint channels, tiled files, windows off the origin (io/test_exr.c,
 * support/make_fog_frames.c). Header-only: link OpenEXRCore. */
#ifndef VEIL_TEST_EXR_CORE_H
#define VEIL_TEST_EXR_CORE_H

#include <openexr.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

static inline void quiet_exr_error(exr_const_context_t ctxt, exr_result_t code, const char* msg)
{
    (void)ctxt;
    (void)code;
    (void)msg;
}

typedef struct test_chan {
    const char* name;
    exr_pixel_type_t type;
    const void* plane; /* W*H values of `type`, rows top first */
} test_chan;

/* Writes a single-part file; tile > 0 makes it tiled (one level). */
static inline int core_write(const char* path, exr_compression_t comp, exr_attr_box2i_t dw, int tile, const test_chan* chans,
                      int nchans)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = quiet_exr_error;
    exr_context_t ctx = NULL;
    int part = 0;
    exr_attr_v2f_t center;
    center.x = 0.0f;
    center.y = 0.0f;
    const int W = dw.max.x - dw.min.x + 1, H = dw.max.y - dw.min.y + 1;
    exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS) rv = exr_add_part(ctx, NULL, tile > 0 ? EXR_STORAGE_TILED : EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr(ctx, part, &dw, &dw, 1.0f, &center, 1.0f, EXR_LINEORDER_INCREASING_Y, comp);
    for (int c = 0; c < nchans && rv == EXR_ERR_SUCCESS; ++c)
        rv = exr_add_channel(ctx, part, chans[c].name, chans[c].type, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (rv == EXR_ERR_SUCCESS && tile > 0)
        rv = exr_set_tile_descriptor(ctx, part, (uint32_t)tile, (uint32_t)tile, EXR_TILE_ONE_LEVEL,
                                     EXR_TILE_ROUND_DOWN);
    if (rv == EXR_ERR_SUCCESS) rv = exr_write_header(ctx);

    int32_t lines = 1;
    if (rv == EXR_ERR_SUCCESS && tile <= 0) rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
    const int nx = tile > 0 ? (W + tile - 1) / tile : 1;
    const int ny = tile > 0 ? (H + tile - 1) / tile : (H + lines - 1) / lines;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int ready = 0;
    for (int j = 0; j < ny && rv == EXR_ERR_SUCCESS; ++j) {
        for (int i = 0; i < nx && rv == EXR_ERR_SUCCESS; ++i) {
            exr_chunk_info_t ci;
            int x0, y0;
            if (tile > 0) {
                rv = exr_write_tile_chunk_info(ctx, part, i, j, 0, 0, &ci);
                x0 = i * tile;
                y0 = j * tile;
            } else {
                rv = exr_write_scanline_chunk_info(ctx, part, dw.min.y + j * lines, &ci);
                x0 = 0;
                y0 = j * lines;
            }
            if (rv != EXR_ERR_SUCCESS) break;
            rv = ready ? exr_encoding_update(ctx, part, &ci, &enc) : exr_encoding_initialize(ctx, part, &ci, &enc);
            if (rv != EXR_ERR_SUCCESS) break;
            for (int c = 0; c < enc.channel_count; ++c) {
                exr_coding_channel_info_t* ch = &enc.channels[c];
                for (int k = 0; k < nchans; ++k) {
                    if (strcmp(chans[k].name, ch->channel_name) != 0) continue;
                    const int bpe = chans[k].type == EXR_PIXEL_HALF ? 2 : 4;
                    ch->encode_from_ptr = (const uint8_t*)chans[k].plane + ((size_t)y0 * W + x0) * bpe;
                    ch->user_pixel_stride = bpe;
                    ch->user_line_stride = W * bpe;
                    ch->user_bytes_per_element = (int16_t)bpe;
                    ch->user_data_type = (uint16_t)chans[k].type;
                }
            }
            if (!ready) rv = exr_encoding_choose_default_routines(ctx, part, &enc);
            ready = 1;
            if (rv == EXR_ERR_SUCCESS) rv = exr_encoding_run(ctx, part, &enc);
        }
    }
    if (ready) exr_encoding_destroy(ctx, &enc);
    if (ctx) {
        exr_result_t frv = exr_finish(&ctx);
        if (rv == EXR_ERR_SUCCESS) rv = frv;
    }
    if (rv != EXR_ERR_SUCCESS)
        fprintf(stderr, "core_write %s: %s\n", path, exr_get_default_error_message(rv));
    return rv == EXR_ERR_SUCCESS;
}

#endif
