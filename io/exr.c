/* veil — OpenEXR output through OpenEXRCore (the C API only); reading is
 * io/exr_read.c, what both share io/exr_io.c.
 *
 * Writing: one scanline part of named channels, 32-bit float or 16-bit half
 * (veil_exr_format; the format stores them sorted by name: R, G, B, A as A,
 * B, G, R), ZIP compression unless the format names another, data window
 * (0,0)-(w-1,h-1); the chunks compressed on every core and written in order
 * (write_chunks). veil_write_exr writes the de-interleaved
 * R, G, B, A planes through veil_write_exr_planes: there is one writer. The
 * bytes go through a custom stream onto a temporary file beside the target,
 * which is renamed into place only when every step succeeded; on failure it
 * is removed.
 */
#define _POSIX_C_SOURCE 200809L

#include "image.h"
#include "exr_deep.h"
#include "exr_io.h"
#include "tempfile.h"

#include <openexr.h>

#include <errno.h>
#include <pthread.h>
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

/* The chunks are compressed on several threads and written in order by the calling thread
 * (OpenEXRCore encodes a chunk independently of the others; a scanline file's chunks go to the
 * file in increasing y): each worker claims the next chunk, packs and compresses it through its
 * own pipeline and leaves the bytes in the chunk's slot; the writer waits for slot k, writes it
 * and frees it. Workers stay within `window` chunks of the writer, so the compressed bytes held
 * at once are a few chunks a thread, not the image. */
typedef struct chunk_slot {
    void* bytes;
    uint64_t size;
    int ready;
} chunk_slot;

typedef struct encoder {
    exr_context_t ctx;
    int part, lines, chunks, window;
    const write_job* job;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int next, written, failed; /* the next chunk to claim; chunks written; 1 once anything failed */
    exr_result_t rv;           /* the first failure */
    exr_msgs msgs;             /* its text */
    const char* stage;
    chunk_slot* slots;
} encoder;

static void encoder_fail(encoder* e, exr_result_t rv, const char* stage, const exr_msgs* m)
{
    pthread_mutex_lock(&e->mu);
    if (!e->failed) {
        e->failed = 1, e->rv = rv, e->stage = stage;
        if (m) e->msgs = *m;
    }
    pthread_cond_broadcast(&e->cv);
    pthread_mutex_unlock(&e->mu);
}

/* Packs and compresses chunk i into its slot. */
static exr_result_t encode_chunk(encoder* e, int i, exr_encode_pipeline_t* enc, int* have_pipeline, const char** stage)
{
    const write_job* job = e->job;
    const int w = job->width, h = job->height;
    exr_chunk_info_t ci;
    *stage = "preparing a scanline chunk";
    exr_result_t rv = exr_write_scanline_chunk_info(e->ctx, e->part, i * e->lines, &ci);
    if (rv != EXR_ERR_SUCCESS) return rv;
    if (ci.start_y < 0 || ci.height <= 0 || ci.start_y + (int64_t)ci.height > h || ci.start_x != 0 || ci.width != w)
        return EXR_ERR_INCORRECT_CHUNK;
    rv = *have_pipeline ? exr_encoding_update(e->ctx, e->part, &ci, enc) : exr_encoding_initialize(e->ctx, e->part, &ci, enc);
    if (rv != EXR_ERR_SUCCESS) return rv;
    const int first = !*have_pipeline;
    *have_pipeline = 1;
    for (int c = 0; c < enc->channel_count; ++c) {
        exr_coding_channel_info_t* ch = &enc->channels[c];
        int k = veil__exr_name_index(job->names, job->n, ch->channel_name);
        if (k < 0) return EXR_ERR_INVALID_ARGUMENT;
        ch->encode_from_ptr = (const uint8_t*)(job->planes[k] + (size_t)ci.start_y * (size_t)w);
        ch->user_pixel_stride = (int32_t)sizeof(float);
        ch->user_line_stride = (int32_t)((size_t)w * sizeof(float));
        ch->user_bytes_per_element = (int16_t)sizeof(float);
        ch->user_data_type = (uint16_t)EXR_PIXEL_FLOAT; /* converted to the channel's type (half) by the packer */
    }
    if (first) {
        rv = exr_encoding_choose_default_routines(e->ctx, e->part, enc);
        if (rv != EXR_ERR_SUCCESS) return rv;
        enc->yield_until_ready_fn = NULL; /* the writer orders the chunks */
        enc->write_fn = NULL;             /* and writes them */
    }
    *stage = "compressing a scanline chunk";
    rv = exr_encoding_run(e->ctx, e->part, enc);
    if (rv != EXR_ERR_SUCCESS) return rv;
    void* bytes = malloc(enc->compressed_bytes ? enc->compressed_bytes : 1);
    if (!bytes) return EXR_ERR_OUT_OF_MEMORY;
    memcpy(bytes, enc->compressed_buffer, enc->compressed_bytes);
    pthread_mutex_lock(&e->mu);
    e->slots[i] = (chunk_slot){bytes, enc->compressed_bytes, 1};
    pthread_cond_broadcast(&e->cv);
    pthread_mutex_unlock(&e->mu);
    return EXR_ERR_SUCCESS;
}

static void* encode_worker(void* arg)
{
    encoder* e = arg;
    exr_msgs msgs = {{0}, 0};
    exr_msgs* saved = veil__exr_tls_msgs;
    veil__exr_tls_msgs = &msgs;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int have_pipeline = 0;
    for (;;) {
        pthread_mutex_lock(&e->mu);
        while (!e->failed && e->next < e->chunks && e->next - e->written >= e->window) pthread_cond_wait(&e->cv, &e->mu);
        const int i = e->failed || e->next >= e->chunks ? -1 : e->next++;
        pthread_mutex_unlock(&e->mu);
        if (i < 0) break;
        const char* stage = "";
        exr_result_t rv = encode_chunk(e, i, &enc, &have_pipeline, &stage);
        if (rv != EXR_ERR_SUCCESS) {
            encoder_fail(e, rv, stage, &msgs);
            break;
        }
    }
    if (have_pipeline) exr_encoding_destroy(e->ctx, &enc);
    veil__exr_tls_msgs = saved;
    return NULL;
}

int veil_exr_threads(void)
{
    static int cached = 0;
    if (cached) return cached;
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    const char* env = getenv("VEIL_EXR_THREADS");
    if (env && *env) {
        char* end = NULL;
        long v = strtol(env, &end, 10);
        if (end && !*end && v >= 1 && v <= 256) n = v;
    }
    cached = n < 1 ? 1 : n > VEIL_EXR_MAX_THREADS ? VEIL_EXR_MAX_THREADS : (int)n;
    return cached;
}

static exr_result_t write_chunks(exr_context_t ctx, int part, const write_job* job, const char** stage, exr_msgs* msgs)
{
    int32_t lines = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
    if (rv != EXR_ERR_SUCCESS) return rv;
    if (lines <= 0) return EXR_ERR_INVALID_ARGUMENT;
    const int chunks = (int)(((int64_t)job->height + lines - 1) / lines);
    int threads = job->meta && job->meta->format.threads > 0 ? job->meta->format.threads : veil_exr_threads();
    if (threads > chunks) threads = chunks;
    if (threads > VEIL_EXR_MAX_THREADS) threads = VEIL_EXR_MAX_THREADS;
    encoder e = {.ctx = ctx, .part = part, .lines = lines, .chunks = chunks, .window = 4 * threads, .job = job};
    e.slots = calloc((size_t)chunks, sizeof *e.slots);
    if (!e.slots) return EXR_ERR_OUT_OF_MEMORY;
    pthread_mutex_init(&e.mu, NULL);
    pthread_cond_init(&e.cv, NULL);
    pthread_t tid[VEIL_EXR_MAX_THREADS];
    int started = 0;
    for (; started < threads; ++started)
        if (pthread_create(&tid[started], NULL, encode_worker, &e) != 0) break;
    if (started == 0) encoder_fail(&e, EXR_ERR_OUT_OF_MEMORY, "starting the compressing threads", NULL);
    for (int k = 0; k < chunks; ++k) { /* the writer: chunk k once compressed */
        pthread_mutex_lock(&e.mu);
        while (!e.failed && !e.slots[k].ready) pthread_cond_wait(&e.cv, &e.mu);
        const int go = !e.failed;
        pthread_mutex_unlock(&e.mu);
        if (!go) break;
        *stage = "writing a scanline chunk";
        exr_result_t wrv = exr_write_scanline_chunk(ctx, part, k * lines, e.slots[k].bytes, e.slots[k].size);
        free(e.slots[k].bytes);
        e.slots[k].bytes = NULL;
        if (wrv != EXR_ERR_SUCCESS) {
            encoder_fail(&e, wrv, *stage, msgs);
            break;
        }
        pthread_mutex_lock(&e.mu);
        ++e.written;
        pthread_cond_broadcast(&e.cv);
        pthread_mutex_unlock(&e.mu);
    }
    for (int t = 0; t < started; ++t) pthread_join(tid[t], NULL);
    for (int k = 0; k < chunks; ++k) free(e.slots[k].bytes);
    free(e.slots);
    pthread_cond_destroy(&e.cv);
    pthread_mutex_destroy(&e.mu);
    if (e.failed) {
        *stage = e.stage;
        if (e.msgs.len && !msgs->len) *msgs = e.msgs;
        return e.rv;
    }
    return EXR_ERR_SUCCESS;
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

int veil__exr_compression_of(int c)
{
    static const int of[VEIL_EXR_COMPRESSIONS] = {EXR_COMPRESSION_ZIP,  EXR_COMPRESSION_NONE,  EXR_COMPRESSION_RLE,
                                                  EXR_COMPRESSION_ZIPS, EXR_COMPRESSION_ZIP,   EXR_COMPRESSION_PIZ,
                                                  EXR_COMPRESSION_PXR24, EXR_COMPRESSION_B44,  EXR_COMPRESSION_B44A,
                                                  EXR_COMPRESSION_DWAA, EXR_COMPRESSION_DWAB};
    return c >= 0 && c < VEIL_EXR_COMPRESSIONS ? of[c] : EXR_COMPRESSION_ZIP;
}

static const char* const COMPRESSION_NAMES[VEIL_EXR_COMPRESSIONS] = {"zip", "none", "rle", "zips", "zip", "piz",
                                                                     "pxr24", "b44", "b44a", "dwaa", "dwab"};

const char* veil_exr_compression_name(int c)
{
    return c >= 0 && c < VEIL_EXR_COMPRESSIONS ? COMPRESSION_NAMES[c] : "?";
}

int veil_exr_compression_parse(const char* name)
{
    for (int c = 1; name && c < VEIL_EXR_COMPRESSIONS; ++c)
        if (!strcmp(name, COMPRESSION_NAMES[c])) return c;
    return -1;
}

int veil_exr_keeps_float(const char* name)
{
    static const char* const distances[] = {"Z", "ZBack", "depth", "P"};
    for (size_t i = 0; i < sizeof distances / sizeof *distances; ++i)
        if (!strcmp(name, distances[i])) return 1;
    return 0;
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
    const veil_exr_format* fmt = job->meta ? &job->meta->format : NULL;
    const int compression = fmt ? fmt->compression : VEIL_EXR_DEFAULT;
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctx, part, job->width, job->height,
                                                 (exr_compression_t)veil__exr_compression_of(compression));
    if (rv == EXR_ERR_SUCCESS && fmt && fmt->dwa_level > 0.0f &&
        (compression == VEIL_EXR_DWAA || compression == VEIL_EXR_DWAB))
        rv = exr_set_dwa_compression_level(ctx, part, fmt->dwa_level);
    if (rv == EXR_ERR_SUCCESS) rv = write_meta(ctx, part, job->meta);
    for (int c = 0; c < job->n && rv == EXR_ERR_SUCCESS; ++c) {
        const exr_pixel_type_t type = fmt && fmt->half && !veil_exr_keeps_float(job->names[c]) ? EXR_PIXEL_HALF
                                                                                                : EXR_PIXEL_FLOAT;
        rv = exr_add_channel(ctx, part, job->names[c], type, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    }
    if (rv == EXR_ERR_SUCCESS) {
        *stage = "writing the header";
        rv = exr_write_header(ctx);
    }
    if (rv == EXR_ERR_SUCCESS) rv = write_chunks(ctx, part, job, stage, veil__exr_tls_msgs);
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
    const int dwa = meta && (meta->format.compression == VEIL_EXR_DWAA || meta->format.compression == VEIL_EXR_DWAB);
    exr_result_t rv = EXR_ERR_SUCCESS;
    if (dwa) /* OpenEXRCore 3.1 has no DWA encoder: the C++ library's (io/exr_deep.h) */
        result = veil__exr_write_imf(fd, path, width, height, n, names, planes, meta, err);
    else
        rv = write_exr_stream(path, fd, &job, &stage);
    veil__exr_tls_msgs = saved;

    int close_errno = 0;
    if (close(fd) != 0) close_errno = errno;

    if (result != VEIL_OK) {
        /* the C++ writer's message */
    } else if (rv != EXR_ERR_SUCCESS) {
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

