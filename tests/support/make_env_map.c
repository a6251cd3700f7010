/* Writes a lat-long environment map of any size without holding it (issue
 * 41's maps: 16384 x 8192 is 1.6 GB as float RGB):
 *
 *   make_env_map OUT.exr WIDTH HEIGHT
 *
 * half R, G, B, ZIP (16 lines a chunk), scanline; each row the same: a
 * horizon-lit sky, R = 0.2 + 0.3 u, G = 0.3, B = 0.5 - 0.2 u (u = x / W),
 * brighter by 1 + 4 (1 - v)^8 towards the top (v = y / H), so that its
 * median cut has work in both directions. One chunk's rows are held at a
 * time. */
#include <openexr.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int fail(const char* what, exr_result_t rv)
{
    fprintf(stderr, "make_env_map: %s: %s\n", what, exr_get_error_code_as_string(rv));
    return 1;
}

int main(int argc, char** argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: make_env_map OUT.exr WIDTH HEIGHT\n");
        return 2;
    }
    const int w = atoi(argv[2]), h = atoi(argv[3]);
    if (w < 2 || h < 1 || w > 65536 || h > 65536) {
        fprintf(stderr, "make_env_map: a size in 2..65536 x 1..65536\n");
        return 2;
    }
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t ctx = NULL;
    int part = 0;
    exr_result_t rv = exr_start_write(&ctx, argv[1], EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv != EXR_ERR_SUCCESS) return fail("start", rv);
    rv = exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS) rv = exr_initialize_required_attr_simple(ctx, part, w, h, EXR_COMPRESSION_ZIP);
    static const char* const names[3] = {"B", "G", "R"};
    for (int c = 0; c < 3 && rv == EXR_ERR_SUCCESS; ++c)
        rv = exr_add_channel(ctx, part, names[c], EXR_PIXEL_HALF, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (rv == EXR_ERR_SUCCESS) rv = exr_write_header(ctx);
    if (rv != EXR_ERR_SUCCESS) return fail("header", rv);
    int32_t lines = 0;
    exr_get_scanlines_per_chunk(ctx, part, &lines);
    /* each chunk's rows, channel by channel (float: OpenEXRCore converts to half) */
    float* rows = malloc((size_t)w * (size_t)lines * 3 * sizeof *rows);
    if (!rows) return fail("out of memory", EXR_ERR_OUT_OF_MEMORY);
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int ready = 0;
    for (int y = 0; y < h && rv == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t ci;
        rv = exr_write_scanline_chunk_info(ctx, part, y, &ci);
        if (rv != EXR_ERR_SUCCESS) break;
        for (int l = 0; l < ci.height; ++l) {
            const double v = (double)(ci.start_y + l) / h, up = 1.0 + 4.0 * pow(1.0 - v, 8.0);
            for (int x = 0; x < w; ++x) {
                const double u = (double)x / w;
                float* p = rows + (size_t)l * (size_t)w + (size_t)x;
                p[0] = (float)((0.5 - 0.2 * u) * up);                            /* B */
                p[(size_t)w * (size_t)lines] = (float)(0.3 * up);                  /* G */
                p[2 * (size_t)w * (size_t)lines] = (float)((0.2 + 0.3 * u) * up); /* R */
            }
        }
        rv = ready ? exr_encoding_update(ctx, part, &ci, &enc) : exr_encoding_initialize(ctx, part, &ci, &enc);
        if (rv != EXR_ERR_SUCCESS) break;
        ready = 1;
        for (int c = 0; c < enc.channel_count; ++c) {
            exr_coding_channel_info_t* ch = &enc.channels[c];
            int k = ch->channel_name[0] == 'B' ? 0 : ch->channel_name[0] == 'G' ? 1 : 2;
            ch->encode_from_ptr = (const uint8_t*)(rows + (size_t)k * (size_t)w * (size_t)lines);
            ch->user_pixel_stride = (int32_t)sizeof(float);
            ch->user_line_stride = (int32_t)((size_t)w * sizeof(float));
            ch->user_bytes_per_element = (int16_t)sizeof(float);
            ch->user_data_type = (uint16_t)EXR_PIXEL_FLOAT;
        }
        if (y == 0) rv = exr_encoding_choose_default_routines(ctx, part, &enc);
        if (rv == EXR_ERR_SUCCESS) rv = exr_encoding_run(ctx, part, &enc);
    }
    if (ready) exr_encoding_destroy(ctx, &enc);
    free(rows);
    exr_result_t frv = exr_finish(&ctx);
    if (rv != EXR_ERR_SUCCESS) return fail("chunks", rv);
    if (frv != EXR_ERR_SUCCESS) return fail("finish", frv);
    return 0;
}
