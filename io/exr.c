/* veil — OpenEXR output and input through OpenEXRCore (the C API only).
 *
 * Writing: one scanline part, channels R, G, B, A (stored A, B, G, R: the
 * format sorts channel names) as 32-bit float, ZIP compression, data window
 * (0,0)-(w-1,h-1). The bytes go through a custom stream onto a temporary
 * file beside the target, which is renamed into place only when every step
 * succeeded; on failure it is removed.
 *
 * Reading: the first part of a scanline or tiled file (level 0 of a mip/rip
 * map), half or float R, G, B and optional A. OpenEXRCore reads and
 * decompresses each chunk; the last step (storage order to interleaved
 * RGBA float) is our own unpack routine, because the specialised routines of
 * OpenEXRCore 3.1.x get this layout wrong: its "4 channel reversed
 * interleave" half->float path writes A into R and R into A (channels are
 * stored A, B, G, R), and its 3/4-channel fast paths assume that every
 * channel of the file is wanted, so an extra channel (Z, ...) makes them
 * write through a NULL pointer.
 */
#define _POSIX_C_SOURCE 200809L

#include "image.h"
#include "tempfile.h"

#include <openexr.h>

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <limits.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

/* ------------------------------------------------------------------------ */
/* Error messages from OpenEXRCore.
 *
 * The library reports errors through a callback on the thread that caused
 * them. The callback must not call back into the library (some errors are
 * reported while the context's lock is held), so the messages are collected
 * in a thread-local sink set up around each of our calls. */

typedef struct exr_msgs {
    char text[1024];
    size_t len;
} exr_msgs;

static _Thread_local exr_msgs* tls_msgs;

static void msgs_append(exr_msgs* m, const char* s)
{
    if (!m || !s || !*s) return;
    size_t cap = sizeof m->text;
    if (m->len + 1 >= cap) return;
    int n = snprintf(m->text + m->len, cap - m->len, "%s%s", m->len ? "; " : "", s);
    if (n < 0) return;
    m->len += (size_t)n;
    if (m->len >= cap) m->len = cap - 1;
}

static void on_exr_error(exr_const_context_t ctxt, exr_result_t code, const char* msg)
{
    (void)ctxt;
    msgs_append(tls_msgs, msg && *msg ? msg : exr_get_default_error_message(code));
}

/* The collected text, or OpenEXRCore's generic text for `code`. */
static const char* exr_reason(const exr_msgs* m, exr_result_t code)
{
    if (m->len) return m->text;
    return exr_get_default_error_message(code);
}

/* ------------------------------------------------------------------------ */
/* Streams over a file descriptor we own. */

typedef struct fd_stream {
    int fd;
    int64_t size; /* reading: file size */
} fd_stream;

static int offset_fits(uint64_t off, uint64_t len)
{
    /* off + len must be representable as a non-negative off_t */
    const uint64_t max = (sizeof(off_t) >= 8) ? (uint64_t)INT64_MAX : (uint64_t)INT32_MAX;
    return off <= max && len <= max - off;
}

static int64_t fd_write(exr_const_context_t ctxt, void* userdata, const void* buffer, uint64_t sz,
                        uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    fd_stream* s = userdata;
    const unsigned char* p = buffer;
    uint64_t done = 0;
    if (!offset_fits(offset, sz)) {
        if (error_cb) error_cb(ctxt, EXR_ERR_WRITE_IO, "write past the largest file offset");
        return -1;
    }
    while (done < sz) {
        uint64_t left = sz - done;
        size_t n = left > (1u << 30) ? (size_t)(1u << 30) : (size_t)left;
        ssize_t w = pwrite(s->fd, p + done, n, (off_t)(offset + done));
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            if (error_cb)
                error_cb(ctxt, EXR_ERR_WRITE_IO, "cannot write %" PRIu64 " bytes at offset %" PRIu64 ": %s",
                         sz, offset, w < 0 ? strerror(errno) : "no progress");
            return -1;
        }
        done += (uint64_t)w;
    }
    return (int64_t)done;
}

/* pread semantics: a short count only at end of file. */
static int64_t fd_read(exr_const_context_t ctxt, void* userdata, void* buffer, uint64_t sz,
                       uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    fd_stream* s = userdata;
    unsigned char* p = buffer;
    uint64_t done = 0;
    if (!offset_fits(offset, sz)) {
        if (error_cb) error_cb(ctxt, EXR_ERR_READ_IO, "read past the largest file offset");
        return -1;
    }
    while (done < sz) {
        uint64_t left = sz - done;
        size_t n = left > (1u << 30) ? (size_t)(1u << 30) : (size_t)left;
        ssize_t r = pread(s->fd, p + done, n, (off_t)(offset + done));
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) {
            if (error_cb)
                error_cb(ctxt, EXR_ERR_READ_IO, "cannot read %" PRIu64 " bytes at offset %" PRIu64 ": %s",
                         sz, offset, strerror(errno));
            return -1;
        }
        if (r == 0) break; /* end of file: the library decides whether that is an error */
        done += (uint64_t)r;
    }
    return (int64_t)done;
}

static int64_t fd_size(exr_const_context_t ctxt, void* userdata)
{
    (void)ctxt;
    return ((fd_stream*)userdata)->size;
}

/* ------------------------------------------------------------------------ */
/* Writing */

/* Offset of a channel within an RGBA pixel, or -1. */
static int rgba_slot(const char* name)
{
    if (!name || !name[0] || name[1]) return -1;
    switch (name[0]) {
    case 'R': return 0;
    case 'G': return 1;
    case 'B': return 2;
    case 'A': return 3;
    default: return -1;
    }
}

static exr_result_t write_chunks(exr_context_t ctx, int part, int w, int h, const float* rgba,
                                 const char** stage)
{
    int32_t lines = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
    if (rv != EXR_ERR_SUCCESS) return rv;
    if (lines <= 0) return EXR_ERR_INVALID_ARGUMENT;

    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int have_pipeline = 0;
    for (int64_t y = 0; y < h && rv == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t ci;
        *stage = "preparing a scanline chunk";
        rv = exr_write_scanline_chunk_info(ctx, part, (int)y, &ci);
        if (rv != EXR_ERR_SUCCESS) break;
        if (ci.start_y < 0 || ci.height <= 0 || ci.start_y + (int64_t)ci.height > h || ci.start_x != 0 ||
            ci.width != w) {
            rv = EXR_ERR_INCORRECT_CHUNK;
            break;
        }
        if (!have_pipeline) {
            rv = exr_encoding_initialize(ctx, part, &ci, &enc);
            if (rv != EXR_ERR_SUCCESS) break;
            have_pipeline = 1;
        } else {
            rv = exr_encoding_update(ctx, part, &ci, &enc);
            if (rv != EXR_ERR_SUCCESS) break;
        }
        const float* row = rgba + (size_t)ci.start_y * (size_t)w * 4;
        for (int c = 0; c < enc.channel_count; ++c) {
            exr_coding_channel_info_t* ch = &enc.channels[c];
            int slot = rgba_slot(ch->channel_name);
            if (slot < 0) {
                rv = EXR_ERR_INVALID_ARGUMENT;
                break;
            }
            ch->encode_from_ptr = (const uint8_t*)(row + slot);
            ch->user_pixel_stride = (int32_t)(4 * sizeof(float));
            ch->user_line_stride = (int32_t)((size_t)w * 4 * sizeof(float));
            ch->user_bytes_per_element = (int16_t)sizeof(float);
            ch->user_data_type = (uint16_t)EXR_PIXEL_FLOAT;
        }
        if (rv != EXR_ERR_SUCCESS) break;
        if (y == 0) {
            rv = exr_encoding_choose_default_routines(ctx, part, &enc);
            if (rv != EXR_ERR_SUCCESS) break;
        }
        *stage = "compressing and writing a scanline chunk";
        rv = exr_encoding_run(ctx, part, &enc);
    }
    if (have_pipeline) {
        exr_result_t drv = exr_encoding_destroy(ctx, &enc);
        if (rv == EXR_ERR_SUCCESS) rv = drv;
    }
    return rv;
}

static exr_result_t write_exr_stream(const char* path, int fd, int w, int h, const float* rgba,
                                     const char** stage)
{
    fd_stream stream = {fd, -1};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_exr_error;
    init.user_data = &stream;
    init.write_fn = fd_write;

    exr_context_t ctx = NULL;
    int part = 0;
    *stage = "starting the file";
    exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS) {
        *stage = "defining the header";
        rv = exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, &part);
    }
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctx, part, w, h, EXR_COMPRESSION_ZIP);
    static const char* const names[4] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4 && rv == EXR_ERR_SUCCESS; ++c)
        rv = exr_add_channel(ctx, part, names[c], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (rv == EXR_ERR_SUCCESS) {
        *stage = "writing the header";
        rv = exr_write_header(ctx);
    }
    if (rv == EXR_ERR_SUCCESS) rv = write_chunks(ctx, part, w, h, rgba, stage);
    if (ctx) {
        const char* before = *stage;
        *stage = "finishing the file";
        exr_result_t frv = exr_finish(&ctx);
        if (rv == EXR_ERR_SUCCESS)
            rv = frv;
        else
            *stage = before;
    }
    return rv;
}

veil_result veil_write_exr(const char* path, int width, int height, const float* rgba, veil_error* err)
{
    if (!path || !*path) return veil_fail(err, VEIL_ERR_INVALID, "veil_write_exr: no output path given");
    if (width <= 0 || height <= 0)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: invalid image size %dx%d (width and height must be positive)",
                         path, width, height);
    size_t bytes = 0;
    if (!veil_mul_sizes((size_t)width, (size_t)height, 4, sizeof(float), &bytes) ||
        (size_t)width > (size_t)INT32_MAX / (4 * sizeof(float)))
        return veil_fail(err, VEIL_ERR_INVALID, "%s: image size %dx%d is too large", path, width, height);
    if (!rgba) return veil_fail(err, VEIL_ERR_INVALID, "%s: no pixel data given", path);

    char* tmp = NULL;
    int fd = veil_open_temp_beside(path, &tmp);
    if (fd < 0 && errno == 0)
        return veil_fail(err, VEIL_ERR_IO, "%s: exists and is not a regular file; not replacing it", path);
    if (fd < 0)
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot create a temporary file beside it: %s", path,
                         strerror(errno));

    exr_msgs msgs = {{0}, 0};
    exr_msgs* saved = tls_msgs;
    tls_msgs = &msgs;
    const char* stage = "";
    exr_result_t rv = write_exr_stream(path, fd, width, height, rgba, &stage);
    tls_msgs = saved;

    int close_errno = 0;
    if (close(fd) != 0) close_errno = errno;

    veil_result result = VEIL_OK;
    if (rv != EXR_ERR_SUCCESS) {
        result = veil_fail(err, VEIL_ERR_IO, "%s: cannot write OpenEXR file (%s): %s [%s]", path, stage,
                           exr_reason(&msgs, rv), exr_get_error_code_as_string(rv));
    } else if (close_errno) {
        result = veil_fail(err, VEIL_ERR_IO, "%s: cannot write OpenEXR file: closing %s failed: %s", path, tmp,
                           strerror(close_errno));
    } else if (rename(tmp, path) != 0) {
        result = veil_fail(err, VEIL_ERR_IO, "%s: cannot move the temporary file %s into place: %s", path, tmp,
                           strerror(errno));
    }
    if (result != VEIL_OK) unlink(tmp);
    free(tmp);
    return result;
}

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

typedef struct read_target {
    float* pixels; /* W*H*4 */
    int width, height;
    int min_x, min_y; /* data window origin */
} read_target;

/* Decodes one chunk whose top-left pixel is (x0, y0) relative to the data
 * window into the target. *pipeline_ready tracks the shared pipeline. */
static exr_result_t decode_chunk(exr_const_context_t ctx, const exr_chunk_info_t* ci, int x0, int y0,
                                 const read_target* t, exr_decode_pipeline_t* dec, int* pipeline_ready)
{
    exr_result_t rv;
    if (x0 < 0 || y0 < 0 || ci->width <= 0 || ci->height <= 0 || (int64_t)x0 + ci->width > t->width ||
        (int64_t)y0 + ci->height > t->height)
        return EXR_ERR_INCORRECT_CHUNK;
    if (!*pipeline_ready) {
        rv = exr_decoding_initialize(ctx, 0, ci, dec);
        if (rv != EXR_ERR_SUCCESS) return rv;
        *pipeline_ready = 1;
    } else {
        rv = exr_decoding_update(ctx, 0, ci, dec);
        if (rv != EXR_ERR_SUCCESS) return rv;
    }
    float* base = t->pixels + ((size_t)y0 * (size_t)t->width + (size_t)x0) * 4;
    for (int c = 0; c < dec->channel_count; ++c) {
        exr_coding_channel_info_t* ch = &dec->channels[c];
        int slot = rgba_slot(ch->channel_name);
        if (slot >= 0 && ch->x_samples == 1 && ch->y_samples == 1) {
            ch->decode_to_ptr = (uint8_t*)(base + slot);
            ch->user_pixel_stride = (int32_t)(4 * sizeof(float));
            ch->user_line_stride = (int32_t)((size_t)t->width * 4 * sizeof(float));
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
    int ready = 0;
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
            }
        }
    }
    if (ready) exr_decoding_destroy(ctx, &dec);
    if (rv != EXR_ERR_SUCCESS)
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot read OpenEXR pixel data (%s): %s [%s]", path, where,
                         exr_reason(msgs, rv), exr_get_error_code_as_string(rv));
    return VEIL_OK;
}

static const char* pixel_type_name(exr_pixel_type_t t)
{
    switch (t) {
    case EXR_PIXEL_UINT: return "uint";
    case EXR_PIXEL_HALF: return "half";
    case EXR_PIXEL_FLOAT: return "float";
    default: return "unknown";
    }
}

static veil_result read_image(exr_const_context_t ctx, const char* path, int* width, int* height, float** rgba,
                              exr_msgs* msgs, veil_error* err)
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
                         exr_reason(msgs, rv), exr_get_error_code_as_string(rv));

    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED)
        return veil_fail(err, VEIL_ERR_IO, "%s: deep OpenEXR images are not supported (only scanline or tiled)",
                         path);

    const int64_t w = (int64_t)dw.max.x - dw.min.x + 1;
    const int64_t h = (int64_t)dw.max.y - dw.min.y + 1;
    if (w <= 0 || h <= 0 || w > INT_MAX || h > INT_MAX)
        return veil_fail(err, VEIL_ERR_IO, "%s: invalid OpenEXR data window (%d, %d)-(%d, %d)", path, dw.min.x,
                         dw.min.y, dw.max.x, dw.max.y);
    size_t bytes = 0;
    if (!veil_mul_sizes((size_t)w, (size_t)h, 4, sizeof(float), &bytes) ||
        (uint64_t)w > (uint64_t)INT32_MAX / (4 * sizeof(float)))
        return veil_fail(err, VEIL_ERR_IO, "%s: OpenEXR image %" PRId64 "x%" PRId64 " is too large", path, w, h);

    int found[4] = {0, 0, 0, 0};
    for (int c = 0; c < chans->num_channels; ++c) {
        const exr_attr_chlist_entry_t* e = &chans->entries[c];
        int slot = rgba_slot(e->name.str);
        if (slot < 0) continue; /* other channels are ignored */
        if (e->pixel_type != EXR_PIXEL_HALF && e->pixel_type != EXR_PIXEL_FLOAT)
            return veil_fail(err, VEIL_ERR_IO, "%s: channel %s has pixel type %s; only half and float are supported",
                             path, e->name.str, pixel_type_name(e->pixel_type));
        if (e->x_sampling != 1 || e->y_sampling != 1)
            return veil_fail(err, VEIL_ERR_IO, "%s: channel %s is subsampled (%d, %d); that is not supported", path,
                             e->name.str, e->x_sampling, e->y_sampling);
        found[slot] = 1;
    }
    if (!found[0] || !found[1] || !found[2])
        return veil_fail(err, VEIL_ERR_IO, "%s: OpenEXR image lacks channel%s%s%s%s (R, G and B are required)", path,
                         (!found[0] + !found[1] + !found[2]) > 1 ? "s" : "", found[0] ? "" : " R",
                         found[1] ? "" : " G", found[2] ? "" : " B");

    float* pixels = calloc(bytes / sizeof(float), sizeof(float));
    if (!pixels)
        return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory for a %" PRId64 "x%" PRId64 " image", path, w, h);
    if (!found[3])
        for (size_t i = 0, n = (size_t)w * (size_t)h; i < n; ++i) pixels[i * 4 + 3] = 1.0f;

    read_target t = {pixels, (int)w, (int)h, dw.min.x, dw.min.y};
    veil_result r = read_pixels(ctx, path, storage, &t, msgs, err);
    if (r != VEIL_OK) {
        free(pixels);
        return r;
    }
    *width = (int)w;
    *height = (int)h;
    *rgba = pixels;
    return VEIL_OK;
}

veil_result veil_read_exr(const char* path, int* width, int* height, float** rgba, veil_error* err)
{
    if (rgba) *rgba = NULL;
    if (width) *width = 0;
    if (height) *height = 0;
    if (!path || !*path) return veil_fail(err, VEIL_ERR_INVALID, "veil_read_exr: no input path given");
    if (!width || !height || !rgba)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: veil_read_exr: missing output argument", path);

    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return veil_fail(err, VEIL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fd, &st) != 0) {
        int e = errno;
        close(fd);
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot stat: %s", path, strerror(e));
    }
    if (!S_ISREG(st.st_mode)) {
        close(fd);
        return veil_fail(err, VEIL_ERR_IO, "%s: not a regular file", path);
    }

    fd_stream stream = {fd, (int64_t)st.st_size};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_exr_error;
    init.user_data = &stream;
    init.read_fn = fd_read;
    init.size_fn = fd_size;
    /* A damaged chunk table is an error, not something to search around. */
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;

    exr_msgs msgs = {{0}, 0};
    exr_msgs* saved = tls_msgs;
    tls_msgs = &msgs;

    veil_result r;
    exr_context_t ctx = NULL;
    exr_result_t rv = exr_start_read(&ctx, path, &init);
    if (rv != EXR_ERR_SUCCESS) {
        r = veil_fail(err, VEIL_ERR_IO, "%s: not a readable OpenEXR file: %s [%s]", path, exr_reason(&msgs, rv),
                      exr_get_error_code_as_string(rv));
    } else {
        r = read_image(ctx, path, width, height, rgba, &msgs, err);
    }
    if (ctx) exr_finish(&ctx);
    tls_msgs = saved;
    close(fd);
    return r;
}
