/* veil — OpenEXR output through OpenEXRCore (the C API only); reading is
 * io/exr_read.c, what both share io/exr_io.c.
 *
 * Writing: one scanline part of named 32-bit float channels (the format
 * stores them sorted by name: R, G, B, A as A, B, G, R), ZIP compression,
 * data window (0,0)-(w-1,h-1). veil_write_exr writes the de-interleaved
 * R, G, B, A planes through veil_write_exr_planes: there is one writer. The
 * bytes go through a custom stream onto a temporary file beside the target,
 * which is renamed into place only when every step succeeded; on failure it
 * is removed.
 */
#define _POSIX_C_SOURCE 200809L

#include "image.h"
#include "exr_io.h"
#include "tempfile.h"

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
/* Writing */

#define EXR_MAX_CHANNELS 64   /* veil_write_exr_planes' limit */
#define EXR_LONG_NAME_MAX 255 /* OpenEXR's limit on a name with long names on */
#define EXR_SHORT_NAME_MAX 31 /* ... and without (readable by older readers) */

/* Width and height positive, and the image addressable with `per_pixel`
 * floats a pixel (a line of them within OpenEXRCore's int32 strides). */
static veil_result check_size(const char* path, int width, int height, size_t per_pixel, veil_error* err)
{
    size_t bytes = 0;
    if (width <= 0 || height <= 0)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: invalid image size %dx%d (width and height must be positive)",
                         path, width, height);
    if (!veil_mul_sizes((size_t)width, (size_t)height, per_pixel, sizeof(float), &bytes) ||
        (size_t)width > (size_t)INT32_MAX / (per_pixel * sizeof(float)))
        return veil_fail(err, VEIL_ERR_INVALID, "%s: image size %dx%d is too large", path, width, height);
    return VEIL_OK;
}

typedef struct write_job {
    int width, height, n;
    const char* const* names;
    const float* const* planes; /* n planes of width*height */
    const veil_exr_meta* meta;  /* header attributes, or NULL */
} write_job;

static exr_result_t write_chunks(exr_context_t ctx, int part, const write_job* job, const char** stage)
{
    const int w = job->width, h = job->height;
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
        rv = have_pipeline ? exr_encoding_update(ctx, part, &ci, &enc) : exr_encoding_initialize(ctx, part, &ci, &enc);
        if (rv != EXR_ERR_SUCCESS) break;
        have_pipeline = 1;
        for (int c = 0; c < enc.channel_count; ++c) {
            exr_coding_channel_info_t* ch = &enc.channels[c];
            int k = veil__exr_name_index(job->names, job->n, ch->channel_name);
            if (k < 0) {
                rv = EXR_ERR_INVALID_ARGUMENT;
                break;
            }
            ch->encode_from_ptr = (const uint8_t*)(job->planes[k] + (size_t)ci.start_y * (size_t)w);
            ch->user_pixel_stride = (int32_t)sizeof(float);
            ch->user_line_stride = (int32_t)((size_t)w * sizeof(float));
            ch->user_bytes_per_element = (int16_t)sizeof(float);
            ch->user_data_type = (uint16_t)EXR_PIXEL_FLOAT;
        }
        if (rv == EXR_ERR_SUCCESS && y == 0) rv = exr_encoding_choose_default_routines(ctx, part, &enc);
        if (rv != EXR_ERR_SUCCESS) break;
        *stage = "compressing and writing a scanline chunk";
        rv = exr_encoding_run(ctx, part, &enc);
    }
    if (have_pipeline) {
        exr_result_t drv = exr_encoding_destroy(ctx, &enc);
        if (rv == EXR_ERR_SUCCESS) rv = drv;
    }
    return rv;
}

static exr_result_t write_meta(exr_context_t ctx, int part, const veil_exr_meta* m)
{
    exr_result_t rv = EXR_ERR_SUCCESS;
    if (!m) return rv;
    if (m->has_frame) rv = exr_attr_set_int(ctx, part, "frame", m->frame);
    if (rv == EXR_ERR_SUCCESS && m->has_camera) {
        exr_attr_m44f_t wc, wn;
        memcpy(wc.m, m->world_to_camera, sizeof wc.m);
        memcpy(wn.m, m->world_to_ndc, sizeof wn.m);
        rv = exr_attr_set_m44f(ctx, part, "worldToCamera", &wc);
        if (rv == EXR_ERR_SUCCESS) rv = exr_attr_set_m44f(ctx, part, "worldToNDC", &wn);
    }
    for (int i = 0; i < m->n_strings && i < VEIL_EXR_META_STRINGS && rv == EXR_ERR_SUCCESS; ++i)
        if (m->strings[i][0] && m->strings[i][1]) rv = exr_attr_set_string(ctx, part, m->strings[i][0], m->strings[i][1]);
    return rv;
}

static exr_result_t write_exr_stream(const char* path, int fd, const write_job* job, const char** stage)
{
    fd_stream stream = {fd, -1};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = veil__exr_on_error;
    init.user_data = &stream;
    init.write_fn = veil__exr_fd_write;

    exr_context_t ctx = NULL;
    int part = 0;
    *stage = "starting the file";
    exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    int long_names = 0;
    for (int c = 0; c < job->n; ++c)
        if (strlen(job->names[c]) > EXR_SHORT_NAME_MAX) long_names = 1;
    if (rv == EXR_ERR_SUCCESS && long_names) rv = exr_set_longname_support(ctx, 1);
    if (rv == EXR_ERR_SUCCESS) {
        *stage = "defining the header";
        rv = exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, &part);
    }
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctx, part, job->width, job->height, EXR_COMPRESSION_ZIP);
    if (rv == EXR_ERR_SUCCESS) rv = write_meta(ctx, part, job->meta);
    for (int c = 0; c < job->n && rv == EXR_ERR_SUCCESS; ++c)
        rv = exr_add_channel(ctx, part, job->names[c], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (rv == EXR_ERR_SUCCESS) {
        *stage = "writing the header";
        rv = exr_write_header(ctx);
    }
    if (rv == EXR_ERR_SUCCESS) rv = write_chunks(ctx, part, job, stage);
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

static veil_result check_channels(const char* path, int n, const char* const* names, const float* const* planes,
                                  veil_error* err)
{
    if (n < 1 || n > EXR_MAX_CHANNELS)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: %d channels given; an EXR needs 1 to %d", path, n,
                         EXR_MAX_CHANNELS);
    if (!names || !planes)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: no channel %s given", path, names ? "planes" : "names");
    for (int c = 0; c < n; ++c) {
        if (!names[c] || !names[c][0])
            return veil_fail(err, VEIL_ERR_INVALID, "%s: channel %d of %d has no name", path, c + 1, n);
        const size_t len = strlen(names[c]);
        if (len > EXR_LONG_NAME_MAX)
            return veil_fail(err, VEIL_ERR_INVALID,
                             "%s: channel %d's name is %zu characters long (OpenEXR allows %d): \"%.40s...\"", path,
                             c + 1, len, EXR_LONG_NAME_MAX, names[c]);
        const int first = veil__exr_name_index(names, c, names[c]);
        if (first >= 0)
            return veil_fail(err, VEIL_ERR_INVALID, "%s: channel name \"%s\" is given twice (channels %d and %d)",
                             path, names[c], first + 1, c + 1);
        if (!planes[c])
            return veil_fail(err, VEIL_ERR_INVALID, "%s: no pixel data given for channel \"%s\"", path, names[c]);
    }
    return VEIL_OK;
}

veil_result veil_write_exr_planes(const char* path, int width, int height, int n, const char* const* names,
                                  const float* const* planes, veil_error* err)
{
    return veil_write_exr_planes_meta(path, width, height, n, names, planes, NULL, err);
}

veil_result veil_write_exr_planes_meta(const char* path, int width, int height, int n, const char* const* names,
                                       const float* const* planes, const veil_exr_meta* meta, veil_error* err)
{
    if (!path || !*path) return veil_fail(err, VEIL_ERR_INVALID, "veil_write_exr_planes: no output path given");
    veil_result result = check_size(path, width, height, 1, err);
    if (result == VEIL_OK) result = check_channels(path, n, names, planes, err);
    if (result != VEIL_OK) return result;

    char* tmp = NULL;
    int fd = veil_open_temp_beside(path, &tmp);
    if (fd < 0 && errno == 0)
        return veil_fail(err, VEIL_ERR_IO, "%s: exists and is not a regular file; not replacing it", path);
    if (fd < 0)
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot create a temporary file beside it: %s", path,
                         strerror(errno));

    exr_msgs msgs = {{0}, 0};
    exr_msgs* saved = veil__exr_tls_msgs;
    veil__exr_tls_msgs = &msgs;
    const char* stage = "";
    const write_job job = {width, height, n, names, planes, meta};
    exr_result_t rv = write_exr_stream(path, fd, &job, &stage);
    veil__exr_tls_msgs = saved;

    int close_errno = 0;
    if (close(fd) != 0) close_errno = errno;

    if (rv != EXR_ERR_SUCCESS) {
        result = veil_fail(err, VEIL_ERR_IO, "%s: cannot write OpenEXR file (%s): %s [%s]", path, stage,
                           veil__exr_reason(&msgs, rv), exr_get_error_code_as_string(rv));
    } else if (close_errno) {
        result = veil_fail(err, VEIL_ERR_IO, "%s: cannot write OpenEXR file: closing %s failed: %s", path, tmp,
                           strerror(close_errno));
    } else if (rename(tmp, path) != 0) {
        result = veil_fail(err, VEIL_ERR_IO, "%s: cannot move the temporary file %s into place: %s", path, tmp,
                           strerror(errno));
    }
    if (result != VEIL_OK) unlink(tmp);
    veil_temp_forget(tmp);
    free(tmp);
    return result;
}

veil_result veil_write_exr(const char* path, int width, int height, const float* rgba, veil_error* err)
{
    if (!path || !*path) return veil_fail(err, VEIL_ERR_INVALID, "veil_write_exr: no output path given");
    veil_result r = check_size(path, width, height, 4, err);
    if (r != VEIL_OK) return r;
    if (!rgba) return veil_fail(err, VEIL_ERR_INVALID, "%s: no pixel data given", path);

    const size_t count = (size_t)width * (size_t)height;
    float* planar = malloc(count * 4 * sizeof *planar);
    if (!planar)
        return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory for a %dx%d image", path, width, height);
    const float* planes[4];
    for (int c = 0; c < 4; ++c) {
        float* dst = planar + (size_t)c * count;
        for (size_t i = 0; i < count; ++i) dst[i] = rgba[i * 4 + (size_t)c];
        planes[c] = dst;
    }
    r = veil_write_exr_planes(path, width, height, 4, veil__exr_rgba_names, planes, err);
    free(planar);
    return r;
}

