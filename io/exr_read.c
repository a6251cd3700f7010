/* veil — OpenEXR input through OpenEXRCore (the C API only); writing is
 * io/exr.c, what both share io/exr_io.c.
 *
 * Reading: the first part of a scanline or tiled file (level 0 of a mip/rip
 * map), some named half or float channels (R, G, B and optional A for
 * veil_read_exr, one channel for veil_read_exr_channel) into one interleaved
 * float buffer. OpenEXRCore reads and decompresses each chunk; the last step
 * (storage order to our float layout) is our own unpack routine, because the
 * specialised routines of OpenEXRCore 3.1.x get this layout wrong: its
 * "4 channel reversed interleave" half->float path writes A into R and R
 * into A (channels are stored A, B, G, R), and its 3/4-channel fast paths
 * assume that every channel of the file is wanted, so an extra channel
 * (Z, ...) makes them write through a NULL pointer.
 */
#define _POSIX_C_SOURCE 200809L

#include "image.h"
#include "exr_io.h"
#include "../core/progress.h"

#include <openexr.h>

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

/* ------------------------------------------------------------------------ */
/* Reading */

static float half_to_float(uint16_t h)
{
    uint32_t sign = (uint32_t)(h & 0x8000u) << 16;
    uint32_t exponent = (h >> 10) & 0x1fu;
    uint32_t mantissa = h & 0x3ffu;
    uint32_t bits;
    if (exponent == 0) {
        /* zero or subnormal: mantissa * 2^-24, exact in float */
        float f = (float)mantissa * 5.9604644775390625e-8f;
        return sign ? -f : f;
    }
    if (exponent == 31)
        bits = sign | 0x7f800000u | (mantissa << 13); /* inf / NaN */
    else
        bits = sign | ((exponent + 112u) << 23) | (mantissa << 13);
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

/* Storage order (per line: each channel's samples, little-endian) to our
 * output pointers, as float. Channels with no output pointer are skipped. */
static exr_result_t unpack_to_float(exr_decode_pipeline_t* d)
{
    const uint8_t* src = d->unpacked_buffer;
    const uint64_t avail = d->chunk.unpacked_size;
    uint64_t used = 0;

    /* Guards against chunks the pipeline "decodes" without filling the
     * buffer: an empty packed block, or a size mismatch with no compression. */
    if (avail && (!src || d->chunk.packed_size == 0)) return EXR_ERR_CORRUPT_CHUNK;
    if (d->chunk.compression == EXR_COMPRESSION_NONE && d->chunk.packed_size != avail)
        return EXR_ERR_CORRUPT_CHUNK;

    for (int y = 0; y < d->chunk.height; ++y) {
        const int cury = d->chunk.start_y + y;
        for (int c = 0; c < d->channel_count; ++c) {
            const exr_coding_channel_info_t* ch = &d->channels[c];
            if (ch->height == 0 || ch->width <= 0) continue;
            if (ch->y_samples > 1 && (cury % ch->y_samples) != 0) continue;
            const int bpe = ch->bytes_per_element;
            if (bpe != 2 && bpe != 4) return EXR_ERR_CORRUPT_CHUNK;
            const uint64_t nbytes = (uint64_t)ch->width * (uint64_t)bpe;
            if (nbytes > avail - used) return EXR_ERR_CORRUPT_CHUNK;
            if (ch->decode_to_ptr) {
                uint8_t* dst = ch->decode_to_ptr + (ptrdiff_t)y * ch->user_line_stride;
                const uint8_t* s = src + used;
                for (int x = 0; x < ch->width; ++x, dst += ch->user_pixel_stride) {
                    float v;
                    if (ch->data_type == EXR_PIXEL_HALF) {
                        v = half_to_float((uint16_t)(s[0] | (s[1] << 8)));
                        s += 2;
                    } else {
                        uint32_t u = (uint32_t)s[0] | ((uint32_t)s[1] << 8) | ((uint32_t)s[2] << 16) |
                                     ((uint32_t)s[3] << 24);
                        s += 4;
                        if (ch->data_type == EXR_PIXEL_FLOAT)
                            memcpy(&v, &u, sizeof v);
                        else
                            v = (float)u;
                    }
                    memcpy(dst, &v, sizeof v);
                }
            }
            used += nbytes;
        }
    }
    return EXR_ERR_SUCCESS;
}

#define EXR_READ_MAX 4 /* channels one read may want */

/* What a reader wants: named channels, interleaved in this order. */
typedef struct read_request {
    int n;
    const char* const* names;
    int optional;             /* index of the one that may be absent (read as 1), or -1 */
    veil_result missing_code; /* when another one is absent */
    const char* missing_note; /* said after the missing names */
    uint64_t max_pixels;      /* 0: VEIL_EXR_MAX_PIXELS */
    const char* what;         /* the progress reports' phrase ("reading sky.exr"); NULL: none */
} read_request;

typedef struct read_target {
    int n;
    const char* const* names;
    float* pixels; /* width*height*n; NULL: the chunks are only checked (below) */
    int width, height;
    int min_x, min_y; /* data window origin */
    uint64_t file_size;
    uint64_t* chunk_too_big; /* set to a chunk's unpacked bytes when over VEIL_EXR_MAX_CHUNK */
    const char* what;        /* progress reports (core/progress.h) as the pixels are decoded; NULL: none */
} read_target;

/* Between chunks, once VEIL_EXR_PART_PIXELS more pixels are decoded: the progress (done of all the image's
 * pixels) and the cancel flag; 1 when cancelled. */
static int between_chunks(const read_target* t, uint64_t done, uint64_t* reported)
{
    if (!t->pixels || !t->what || done - *reported < VEIL_EXR_PART_PIXELS) return 0;
    *reported = done;
    veil_progress(t->what, (double)done, (double)t->width * (double)t->height);
    return veil_progress_cancelled();
}

/* Decodes one chunk whose top-left pixel is (x0, y0) relative to the data
 * window into the target. *pipeline_ready tracks the shared pipeline. */
static exr_result_t decode_chunk(exr_const_context_t ctx, const exr_chunk_info_t* ci, int x0, int y0,
                                 const read_target* t, exr_decode_pipeline_t* dec, int* pipeline_ready)
{
    exr_result_t rv;
    if (x0 < 0 || y0 < 0 || ci->width <= 0 || ci->height <= 0 || (int64_t)x0 + ci->width > t->width ||
        (int64_t)y0 + ci->height > t->height)
        return EXR_ERR_INCORRECT_CHUNK;
    /* Before the image is allocated, every chunk is found in the file: a
     * header may claim 16384^2 pixels in a file of a few bytes. */
    if (!t->pixels) {
        if (ci->unpacked_size > VEIL_EXR_MAX_CHUNK) {
            *t->chunk_too_big = ci->unpacked_size;
            return EXR_ERR_INVALID_ARGUMENT;
        }
        return ci->data_offset <= t->file_size && ci->packed_size <= t->file_size - ci->data_offset
                   ? EXR_ERR_SUCCESS
                   : EXR_ERR_BAD_CHUNK_LEADER;
    }
    rv = *pipeline_ready ? exr_decoding_update(ctx, 0, ci, dec) : exr_decoding_initialize(ctx, 0, ci, dec);
    if (rv != EXR_ERR_SUCCESS) return rv;
    *pipeline_ready = 1;
    float* base = t->pixels + ((size_t)y0 * (size_t)t->width + (size_t)x0) * (size_t)t->n;
    for (int c = 0; c < dec->channel_count; ++c) {
        exr_coding_channel_info_t* ch = &dec->channels[c];
        int k = veil__exr_name_index(t->names, t->n, ch->channel_name);
        if (k >= 0 && ch->x_samples == 1 && ch->y_samples == 1) {
            ch->decode_to_ptr = (uint8_t*)(base + k);
            ch->user_pixel_stride = (int32_t)((size_t)t->n * sizeof(float));
            ch->user_line_stride = (int32_t)((size_t)t->width * (size_t)t->n * sizeof(float));
            ch->user_bytes_per_element = (int16_t)sizeof(float);
            ch->user_data_type = (uint16_t)EXR_PIXEL_FLOAT;
        } else {
            ch->decode_to_ptr = NULL;
        }
    }
    /* The default routines pick the read and decompress steps; the unpack
     * step is ours (see the top of the file). */
    rv = exr_decoding_choose_default_routines(ctx, 0, dec);
    if (rv != EXR_ERR_SUCCESS) return rv;
    dec->unpack_and_convert_fn = unpack_to_float;
    return exr_decoding_run(ctx, 0, dec);
}

static veil_result read_pixels(exr_const_context_t ctx, const char* path, exr_storage_t storage, const read_target* t,
                               exr_msgs* msgs, veil_error* err)
{
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    int ready = 0, cancelled = 0;
    uint64_t reported = 0;
    exr_result_t rv = EXR_ERR_SUCCESS;
    char where[96] = "";

    if (storage == EXR_STORAGE_SCANLINE) {
        int64_t y = t->min_y;
        const int64_t end = (int64_t)t->min_y + t->height;
        while (y < end) {
            exr_chunk_info_t ci;
            snprintf(where, sizeof where, "scanline %" PRId64, y);
            rv = exr_read_scanline_chunk_info(ctx, 0, (int)y, &ci);
            if (rv != EXR_ERR_SUCCESS) break;
            /* the chunk must hold line y and lie inside the data window */
            if (ci.start_y > y || (int64_t)ci.start_y + ci.height <= y || ci.start_y < t->min_y ||
                ci.start_x != t->min_x) {
                rv = EXR_ERR_INCORRECT_CHUNK;
                break;
            }
            rv = decode_chunk(ctx, &ci, 0, (int)(ci.start_y - t->min_y), t, &dec, &ready);
            if (rv != EXR_ERR_SUCCESS) break;
            y = (int64_t)ci.start_y + ci.height;
            if (between_chunks(t, (uint64_t)(y - t->min_y) * (uint64_t)t->width, &reported)) {
                cancelled = 1;
                break;
            }
        }
    } else {
        uint32_t tile_w = 0, tile_h = 0;
        exr_tile_level_mode_t level_mode;
        exr_tile_round_mode_t round_mode;
        int32_t level_w = 0, level_h = 0;
        snprintf(where, sizeof where, "tile description");
        rv = exr_get_tile_descriptor(ctx, 0, &tile_w, &tile_h, &level_mode, &round_mode);
        if (rv == EXR_ERR_SUCCESS) rv = exr_get_level_sizes(ctx, 0, 0, 0, &level_w, &level_h);
        if (rv == EXR_ERR_SUCCESS &&
            (tile_w == 0 || tile_h == 0 || tile_w > INT_MAX || tile_h > INT_MAX || level_w != t->width ||
             level_h != t->height))
            rv = EXR_ERR_INVALID_ATTR;
        const int64_t nx = rv == EXR_ERR_SUCCESS ? ((int64_t)level_w + tile_w - 1) / tile_w : 0;
        const int64_t ny = rv == EXR_ERR_SUCCESS ? ((int64_t)level_h + tile_h - 1) / tile_h : 0;
        for (int64_t ty = 0; ty < ny && rv == EXR_ERR_SUCCESS; ++ty) {
            for (int64_t tx = 0; tx < nx && rv == EXR_ERR_SUCCESS; ++tx) {
                exr_chunk_info_t ci;
                snprintf(where, sizeof where, "tile (%" PRId64 ", %" PRId64 ")", tx, ty);
                rv = exr_read_tile_chunk_info(ctx, 0, (int)tx, (int)ty, 0, 0, &ci);
                if (rv == EXR_ERR_SUCCESS)
                    rv = decode_chunk(ctx, &ci, (int)(tx * tile_w), (int)(ty * tile_h), t, &dec, &ready);
                if (rv == EXR_ERR_SUCCESS && between_chunks(t, (uint64_t)(ty * nx + tx + 1) * tile_w * tile_h, &reported)) {
                    cancelled = 1;
                    break;
                }
            }
            if (cancelled) break;
        }
    }
    if (ready) exr_decoding_destroy(ctx, &dec);
    if (cancelled)
        return veil_fail(err, VEIL_ERR_CANCELLED, "%s: cancelled while its pixels were read (at %s)", path, where);
    if (rv != EXR_ERR_SUCCESS && *t->chunk_too_big)
        return veil_fail(err, VEIL_ERR_LIMIT, "%s: the OpenEXR chunk at %s unpacks to %" PRIu64 " bytes, more than the "
                         "%d MiB veil reads in a chunk", path, where, *t->chunk_too_big, (int)(VEIL_EXR_MAX_CHUNK >> 20));
    if (rv != EXR_ERR_SUCCESS)
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot read OpenEXR pixel data (%s): %s [%s]", path, where,
                         veil__exr_reason(msgs, rv), exr_get_error_code_as_string(rv));
    return VEIL_OK;
}

/* Appends "item" (quoted) to a ", "-separated list in buf; a list that
 * does not fit ends in "...". */
static void list_append(char* buf, size_t cap, const char* item)
{
    size_t len = strlen(buf);
    if (len >= 3 && strcmp(buf + len - 3, "...") == 0) return;
    int n = snprintf(buf + len, cap - len, "%s\"%s\"", len ? ", " : "", item);
    if (n >= 0 && (size_t)n < cap - len) return;
    size_t at = len + 6 <= cap ? len : cap - 6;
    snprintf(buf + at, cap - at, "%s...", at ? ", " : "");
}

static veil_result read_channels(exr_const_context_t ctx, const char* path, uint64_t file_size,
                                 const read_request* req, int* width, int* height, float** out, exr_msgs* msgs,
                                 veil_error* err)
{
    int parts = 0;
    exr_storage_t storage = EXR_STORAGE_LAST_TYPE;
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t* chans = NULL;
    exr_result_t rv = exr_get_count(ctx, &parts);
    if (rv == EXR_ERR_SUCCESS && parts < 1) rv = EXR_ERR_INCORRECT_PART;
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_storage(ctx, 0, &storage);
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_data_window(ctx, 0, &dw);
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_channels(ctx, 0, &chans);
    if (rv == EXR_ERR_SUCCESS && !chans) rv = EXR_ERR_MISSING_REQ_ATTR;
    if (rv != EXR_ERR_SUCCESS)
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot read the OpenEXR header: %s [%s]", path,
                         veil__exr_reason(msgs, rv), exr_get_error_code_as_string(rv));

    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED)
        return veil_fail(err, VEIL_ERR_IO, "%s: deep OpenEXR images are not supported (only scanline or tiled)",
                         path);

    const int n = req->n;
    const int64_t w = (int64_t)dw.max.x - dw.min.x + 1;
    const int64_t h = (int64_t)dw.max.y - dw.min.y + 1;
    if (w <= 0 || h <= 0 || w > INT_MAX || h > INT_MAX)
        return veil_fail(err, VEIL_ERR_IO, "%s: invalid OpenEXR data window (%d, %d)-(%d, %d)", path, dw.min.x,
                         dw.min.y, dw.max.x, dw.max.y);
    /* a bound on what an untrusted header can make us allocate before any pixel is read */
    if ((uint64_t)w * (uint64_t)h > VEIL_EXR_MAX_PIXELS)
        return veil_fail(err, VEIL_ERR_LIMIT, "%s: OpenEXR image %" PRId64 "x%" PRId64 " has more than 2^28 pixels (a "
                         "16384x16384 image, the largest veil renders), the most veil reads", path, w, h);
    if (req->max_pixels && (uint64_t)w * (uint64_t)h > req->max_pixels) /* the caller's, from the header alone */
        return veil_fail(err, VEIL_ERR_LIMIT, "%s: OpenEXR image %" PRId64 "x%" PRId64 " has %" PRIu64 " pixels, "
                         "more than the %" PRIu64 " read here", path, w, h, (uint64_t)w * (uint64_t)h, req->max_pixels);
    size_t bytes = 0;
    if (!veil_mul_sizes((size_t)w, (size_t)h, (size_t)n, sizeof(float), &bytes) ||
        (uint64_t)w > (uint64_t)INT32_MAX / ((size_t)n * sizeof(float)))
        return veil_fail(err, VEIL_ERR_IO, "%s: OpenEXR image %" PRId64 "x%" PRId64 " is too large", path, w, h);

    int found[EXR_READ_MAX] = {0};
    for (int c = 0; c < chans->num_channels; ++c) {
        const exr_attr_chlist_entry_t* e = &chans->entries[c];
        int k = veil__exr_name_index(req->names, n, e->name.str);
        if (k < 0) continue; /* other channels are ignored */
        if (e->pixel_type != EXR_PIXEL_HALF && e->pixel_type != EXR_PIXEL_FLOAT)
            return veil_fail(err, VEIL_ERR_IO, "%s: channel %s has pixel type %s; only half and float are supported",
                             path, e->name.str, e->pixel_type == EXR_PIXEL_UINT ? "uint" : "unknown");
        if (e->x_sampling != 1 || e->y_sampling != 1)
            return veil_fail(err, VEIL_ERR_IO, "%s: channel %s is subsampled (%d, %d); that is not supported", path,
                             e->name.str, e->x_sampling, e->y_sampling);
        found[k] = 1;
    }
    char missing[512] = "";
    int nmissing = 0;
    for (int k = 0; k < n; ++k)
        if (!found[k] && k != req->optional) {
            list_append(missing, sizeof missing, req->names[k]);
            ++nmissing;
        }
    if (nmissing) {
        char have[1024] = "";
        for (int c = 0; c < chans->num_channels; ++c) list_append(have, sizeof have, chans->entries[c].name.str);
        return veil_fail(err, req->missing_code, "%s: OpenEXR image has no channel%s %s%s; its channels are %s", path,
                         nmissing > 1 ? "s" : "", missing, req->missing_note, have[0] ? have : "none");
    }

    /* each chunk of the image is where the chunk table says, inside the file, before the image is allocated */
    uint64_t too_big = 0;
    read_target t = {n, req->names, NULL, (int)w, (int)h, dw.min.x, dw.min.y, file_size, &too_big, req->what};
    veil_result r = read_pixels(ctx, path, storage, &t, msgs, err);
    if (r != VEIL_OK) return r;

    float* pixels = calloc(bytes / sizeof(float), sizeof(float));
    if (!pixels)
        return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory for a %" PRId64 "x%" PRId64 " image", path, w, h);
    if (req->optional >= 0 && !found[req->optional])
        for (size_t i = 0, count = (size_t)w * (size_t)h; i < count; ++i)
            pixels[i * (size_t)n + (size_t)req->optional] = 1.0f;

    t.pixels = pixels;
    r = read_pixels(ctx, path, storage, &t, msgs, err);
    if (r != VEIL_OK) {
        free(pixels);
        return r;
    }
    *width = (int)w;
    *height = (int)h;
    *out = pixels;
    return VEIL_OK;
}

/* Opens `path` and reads the channels `req` asks for; `fn` names the
 * public function in messages about its arguments. */
/* Opens path (a regular file) and starts OpenEXRCore reading it through
 * *stream (fd and size), the error messages going to *msgs (installed as
 * veil__exr_tls_msgs: the caller restores *saved after exr_finish and
 * closes stream->fd, both also on failure when stream->fd >= 0). */
static veil_result start_read(const char* path, fd_stream* stream, exr_context_t* ctx, exr_msgs* msgs,
                              exr_msgs** saved, veil_error* err)
{
    *ctx = NULL;
    stream->fd = open(path, O_RDONLY | O_CLOEXEC);
    if (stream->fd < 0) return veil_fail(err, VEIL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    const int stat_errno = fstat(stream->fd, &st) != 0 ? errno : 0;
    if (stat_errno || !S_ISREG(st.st_mode)) {
        close(stream->fd);
        stream->fd = -1;
        if (stat_errno) return veil_fail(err, VEIL_ERR_IO, "%s: cannot stat: %s", path, strerror(stat_errno));
        return veil_fail(err, VEIL_ERR_IO, "%s: not a regular file", path);
    }
    stream->size = (int64_t)st.st_size;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = veil__exr_on_error;
    init.user_data = stream;
    init.read_fn = veil__exr_fd_read;
    init.size_fn = veil__exr_fd_size;
    /* A damaged chunk table is an error, not something to search around. */
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
    *saved = veil__exr_tls_msgs;
    veil__exr_tls_msgs = msgs;
    exr_result_t rv = exr_start_read(ctx, path, &init);
    if (rv != EXR_ERR_SUCCESS)
        return veil_fail(err, VEIL_ERR_IO, "%s: not a readable OpenEXR file: %s [%s]", path, veil__exr_reason(msgs, rv),
                         exr_get_error_code_as_string(rv));
    return VEIL_OK;
}

static veil_result read_exr_file(const char* fn, const char* path, const read_request* req, int* width, int* height,
                                 float** out, veil_error* err)
{
    if (out) *out = NULL;
    if (width) *width = 0;
    if (height) *height = 0;
    if (!path || !*path) return veil_fail(err, VEIL_ERR_INVALID, "%s: no input path given", fn);
    if (!width || !height || !out)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: %s: missing output argument", path, fn);
    for (int k = 0; k < req->n; ++k)
        if (!req->names[k] || !req->names[k][0])
            return veil_fail(err, VEIL_ERR_INVALID, "%s: %s: no channel name given", path, fn);

    fd_stream stream = {-1, 0};
    exr_msgs msgs = {{0}, 0};
    exr_msgs* saved = veil__exr_tls_msgs;
    exr_context_t ctx = NULL;
    veil_result r = start_read(path, &stream, &ctx, &msgs, &saved, err);
    if (r == VEIL_OK) r = read_channels(ctx, path, (uint64_t)stream.size, req, width, height, out, &msgs, err);
    if (ctx) exr_finish(&ctx);
    veil__exr_tls_msgs = saved;
    if (stream.fd >= 0) close(stream.fd);
    return r;
}

veil_result veil_read_exr(const char* path, int* width, int* height, float** rgba, veil_error* err)
{
    const read_request req = {4, veil__exr_rgba_names, 3, VEIL_ERR_IO, " (R, G and B are required)", 0, NULL};
    return read_exr_file("veil_read_exr", path, &req, width, height, rgba, err);
}

veil_result veil_read_exr_within(const char* path, uint64_t max_pixels, const char* what, int* width, int* height,
                                 float** rgba, veil_error* err)
{
    const read_request req = {4, veil__exr_rgba_names, 3, VEIL_ERR_IO, " (R, G and B are required)", max_pixels, what};
    return read_exr_file("veil_read_exr_within", path, &req, width, height, rgba, err);
}

veil_result veil_read_exr_channel(const char* path, const char* name, int* width, int* height, float** plane,
                                  veil_error* err)
{
    const char* const names[1] = {name};
    const read_request req = {1, names, -1, VEIL_ERR_INVALID, "", 0, NULL};
    return read_exr_file("veil_read_exr_channel", path, &req, width, height, plane, err);
}

veil_result veil_read_exr_meta(const char* path, int* has_frame, int* frame, int* has_camera, float world_to_camera[16],
                               float world_to_ndc[16], const char* name, char* value, size_t n, veil_error* err)
{
    *has_frame = *has_camera = 0;
    if (value && n) value[0] = '\0';
    fd_stream stream = {-1, 0};
    exr_msgs msgs = {{0}, 0};
    exr_msgs* saved = veil__exr_tls_msgs;
    exr_context_t ctx = NULL;
    veil_result r = start_read(path, &stream, &ctx, &msgs, &saved, err);
    if (r == VEIL_OK) {
        int32_t f;
        if (exr_attr_get_int(ctx, 0, "frame", &f) == EXR_ERR_SUCCESS) *has_frame = 1, *frame = f;
        exr_attr_m44f_t wc, wn;
        if (exr_attr_get_m44f(ctx, 0, "worldToCamera", &wc) == EXR_ERR_SUCCESS &&
            exr_attr_get_m44f(ctx, 0, "worldToNDC", &wn) == EXR_ERR_SUCCESS) {
            *has_camera = 1;
            memcpy(world_to_camera, wc.m, sizeof wc.m);
            memcpy(world_to_ndc, wn.m, sizeof wn.m);
        }
        const char* s = NULL;
        int32_t len = 0;
        if (name && value && n && exr_attr_get_string(ctx, 0, name, &len, &s) == EXR_ERR_SUCCESS && s) {
            size_t k = (size_t)len < n - 1 ? (size_t)len : n - 1;
            memcpy(value, s, k);
            value[k] = '\0';
        }
    }
    if (ctx) exr_finish(&ctx);
    veil__exr_tls_msgs = saved;
    if (stream.fd >= 0) close(stream.fd);
    return r;
}
