/* Tests for io/exr.c and io/exr_read.c: EXR write/read, named planes and channels, foreign
 * inputs, failure cleanup. */
#define _POSIX_C_SOURCE 200809L

#include "support/check.h"
#include "io/image.h"
#include "io/exr_io.h"
#include "support/exr_core.h"
#include "support/temp_files.h"

#include <openexr.h>
#include <png.h>

#include <float.h>
#include <limits.h>
#include <signal.h>
#include <sys/resource.h>

/* ------------------------------------------------------------------------ */
/* EXR helpers built on OpenEXRCore directly, to check the files themselves
 * and to make inputs veil never writes (half, tiled, extra channels). */

/* Facts about a file as OpenEXRCore sees it, and one channel's float plane
 * (decoded by the library itself, planar, so independent of veil's reader). */
typedef struct exr_facts {
    int ok;
    exr_storage_t storage;
    exr_compression_t compression;
    exr_attr_box2i_t dw;
    int nchans;
    char names[8][32];
    exr_pixel_type_t types[8];
} exr_facts;

static exr_facts core_inspect(const char* path, const char* plane_name, float* plane)
{
    exr_facts f;
    memset(&f, 0, sizeof f);
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = quiet_exr_error;
    exr_context_t ctx = NULL;
    const exr_attr_chlist_t* cl = NULL;
    exr_result_t rv = exr_start_read(&ctx, path, &init);
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_storage(ctx, 0, &f.storage);
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_compression(ctx, 0, &f.compression);
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_data_window(ctx, 0, &f.dw);
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_channels(ctx, 0, &cl);
    if (rv == EXR_ERR_SUCCESS) {
        f.nchans = cl->num_channels;
        for (int c = 0; c < cl->num_channels && c < 8; ++c) {
            snprintf(f.names[c], sizeof f.names[c], "%s", cl->entries[c].name.str);
            f.types[c] = cl->entries[c].pixel_type;
        }
    }
    if (rv == EXR_ERR_SUCCESS && plane && f.storage == EXR_STORAGE_SCANLINE) {
        const int W = f.dw.max.x - f.dw.min.x + 1;
        exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
        int ready = 0;
        for (int y = f.dw.min.y; y <= f.dw.max.y && rv == EXR_ERR_SUCCESS;) {
            exr_chunk_info_t ci;
            rv = exr_read_scanline_chunk_info(ctx, 0, y, &ci);
            if (rv != EXR_ERR_SUCCESS) break;
            rv = ready ? exr_decoding_update(ctx, 0, &ci, &dec) : exr_decoding_initialize(ctx, 0, &ci, &dec);
            if (rv != EXR_ERR_SUCCESS) break;
            ready = 1;
            for (int c = 0; c < dec.channel_count; ++c) {
                exr_coding_channel_info_t* ch = &dec.channels[c];
                if (strcmp(ch->channel_name, plane_name) == 0) {
                    ch->decode_to_ptr = (uint8_t*)(plane + (size_t)(ci.start_y - f.dw.min.y) * W);
                    ch->user_pixel_stride = 4;
                    ch->user_line_stride = 4 * W;
                    ch->user_bytes_per_element = 4;
                    ch->user_data_type = (uint16_t)EXR_PIXEL_FLOAT;
                } else {
                    ch->decode_to_ptr = NULL;
                }
            }
            rv = exr_decoding_choose_default_routines(ctx, 0, &dec);
            if (rv == EXR_ERR_SUCCESS) rv = exr_decoding_run(ctx, 0, &dec);
            y = ci.start_y + ci.height;
        }
        if (ready) exr_decoding_destroy(ctx, &dec);
    }
    if (ctx) exr_finish(&ctx);
    f.ok = rv == EXR_ERR_SUCCESS;
    return f;
}

/* ------------------------------------------------------------------------ */
/* EXR */

static void test_exr_roundtrip(void)
{
    char path[256];
    path_in(path, sizeof path, "round.exr");
    const int w = 7, h = 37; /* several ZIP chunks (16 lines), the last one partial */
    const size_t n = (size_t)w * h * 4;
    float* px = malloc(n * sizeof *px);
    static const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, FLT_MAX, -FLT_MAX, FLT_MIN, -FLT_MIN,
                                    FLT_TRUE_MIN, 1e30f, 1e-30f, 3.14159265f, 65504.0f, 1e-45f, 123456.789f};
    const size_t ns = sizeof special / sizeof special[0];
    for (size_t i = 0; i < n; ++i) px[i] = i < ns ? special[i] : random_finite();

    veil_error err = {{0}};
    CHECK(veil_write_exr(path, w, h, px, &err) == VEIL_OK, "write %s: %s", path, err.msg);
    int temps = 0;
    CHECK(count_entries(g_dir, &temps) == 1 && temps == 0, "after writing %s the directory should hold just it",
          path);

    int rw = 0, rh = 0;
    float* back = NULL;
    CHECK(veil_read_exr(path, &rw, &rh, &back, &err) == VEIL_OK, "read %s: %s", path, err.msg);
    CHECK(rw == w && rh == h, "size %dx%d, expected %dx%d", rw, rh, w, h);
    if (back && rw == w && rh == h) {
        size_t bad = 0;
        for (size_t i = 0; i < n; ++i)
            if (!same_bits(back[i], px[i])) {
                if (bad++ < 5) fprintf(stderr, "  value %zu: %.9g read back as %.9g\n", i, px[i], back[i]);
            }
        CHECK(bad == 0, "%zu of %zu values not bit-exact after an EXR round trip", bad, n);
    }
    free(back);

    /* overwriting an existing file replaces it */
    for (size_t i = 0; i < n; ++i) px[i] = (float)i * 0.25f;
    CHECK(veil_write_exr(path, w, h, px, &err) == VEIL_OK, "rewrite %s: %s", path, err.msg);
    back = NULL;
    CHECK(veil_read_exr(path, &rw, &rh, &back, &err) == VEIL_OK && back && memcmp(back, px, n * sizeof *px) == 0,
          "rewritten %s does not read back: %s", path, err.msg);
    free(back);
    CHECK(count_entries(g_dir, &temps) == 1 && temps == 0, "rewriting %s left extra files", path);

    /* a 1x1 image */
    const float one[4] = {0.1f, 0.2f, 0.3f, 0.4f};
    CHECK(veil_write_exr(path, 1, 1, one, &err) == VEIL_OK, "write 1x1: %s", err.msg);
    back = NULL;
    CHECK(veil_read_exr(path, &rw, &rh, &back, &err) == VEIL_OK && rw == 1 && rh == 1 && back &&
              memcmp(back, one, sizeof one) == 0,
          "1x1 round trip: %s", err.msg);
    free(back);
    unlink(path);
    free(px);
}

static void test_exr_channels(void)
{
    char path[256];
    path_in(path, sizeof path, "channels.exr");
    const int w = 5, h = 3;
    float px[5 * 3 * 4];
    for (int i = 0; i < w * h; ++i)
        for (int c = 0; c < 4; ++c) px[i * 4 + c] = (float)(c + 1) + (float)i * 16.0f; /* R=1, G=2, B=3, A=4 */

    veil_error err = {{0}};
    CHECK(veil_write_exr(path, w, h, px, &err) == VEIL_OK, "write %s: %s", path, err.msg);

    int rw = 0, rh = 0;
    float* back = NULL;
    CHECK(veil_read_exr(path, &rw, &rh, &back, &err) == VEIL_OK, "read %s: %s", path, err.msg);
    if (back && rw == w && rh == h) {
        int bad = 0;
        for (int i = 0; i < w * h; ++i)
            for (int c = 0; c < 4; ++c)
                if (back[i * 4 + c] != px[i * 4 + c]) ++bad;
        CHECK(bad == 0, "%d channel values differ (swapped channels?)", bad);
    }
    free(back);

    /* the file itself, as OpenEXRCore reads it */
    float rplane[5 * 3], aplane[5 * 3];
    exr_facts f = core_inspect(path, "R", rplane);
    CHECK(f.ok, "OpenEXRCore cannot read %s", path);
    CHECK(f.storage == EXR_STORAGE_SCANLINE, "storage %d, expected scanline", (int)f.storage);
    CHECK(f.compression == EXR_COMPRESSION_ZIP, "compression %d, expected ZIP", (int)f.compression);
    CHECK(f.dw.min.x == 0 && f.dw.min.y == 0 && f.dw.max.x == w - 1 && f.dw.max.y == h - 1,
          "data window (%d,%d)-(%d,%d)", f.dw.min.x, f.dw.min.y, f.dw.max.x, f.dw.max.y);
    CHECK(f.nchans == 4 && strcmp(f.names[0], "A") == 0 && strcmp(f.names[1], "B") == 0 &&
              strcmp(f.names[2], "G") == 0 && strcmp(f.names[3], "R") == 0,
          "channels: %d (%s %s %s %s)", f.nchans, f.names[0], f.names[1], f.names[2], f.names[3]);
    CHECK(f.types[0] == EXR_PIXEL_FLOAT && f.types[1] == EXR_PIXEL_FLOAT && f.types[2] == EXR_PIXEL_FLOAT &&
              f.types[3] == EXR_PIXEL_FLOAT,
          "channels are not all float");
    int rbad = 0;
    for (int i = 0; i < w * h; ++i)
        if (rplane[i] != px[i * 4 + 0]) ++rbad;
    CHECK(rbad == 0, "the file's R channel does not hold R (%d differ; first %g)", rbad, rplane[0]);
    f = core_inspect(path, "A", aplane);
    int abad = 0;
    for (int i = 0; i < w * h; ++i)
        if (aplane[i] != px[i * 4 + 3]) ++abad;
    CHECK(f.ok && abad == 0, "the file's A channel does not hold A (%d differ; first %g)", abad, aplane[0]);
    unlink(path);
}

/* Named planes: veil_write_exr_planes, veil_read_exr_channel. The names
 * are given unsorted; the file stores them sorted. */
static const char* const g_seven[7] = {"stderr.B", "R", "A", "stderr.R", "G", "stderr.G", "B"};

static void expect_plane(const char* path, const char* name, int w, int h, const float* want)
{
    veil_error err = {{0}};
    int rw = 0, rh = 0;
    float* back = NULL;
    veil_result r = veil_read_exr_channel(path, name, &rw, &rh, &back, &err);
    CHECK(r == VEIL_OK && back && rw == w && rh == h, "%s: channel %s: %s, %dx%d (%s)", path, name,
          veil_result_name(r), rw, rh, err.msg);
    if (back && rw == w && rh == h) {
        size_t bad = 0, n = (size_t)w * h;
        for (size_t i = 0; i < n; ++i)
            if (!same_bits(back[i], want[i]) && bad++ < 3)
                fprintf(stderr, "  %s[%zu]: %.9g read back as %.9g\n", name, i, want[i], back[i]);
        CHECK(bad == 0, "%s: channel %s: %zu of %zu values not bit-exact", path, name, bad, n);
    }
    free(back);
}

static void test_exr_planes(void)
{
    char path[256];
    path_in(path, sizeof path, "planes.exr");
    const int w = 9, h = 35, n = 7; /* several ZIP chunks, the last one partial */
    const size_t count = (size_t)w * h;
    float* store = malloc(sizeof(float) * count * n);
    const float* planes[7];
    for (int c = 0; c < n; ++c) {
        float* p = store + (size_t)c * count;
        for (size_t i = 0; i < count; ++i)
            p[i] = i % 3 == 0 ? random_finite() : (float)(c + 1) * 1000.0f + (float)i * 0.5f;
        planes[c] = p;
    }
    const uint32_t nan_bits = 0x7fc12345u;
    store[1] = -0.0f;
    store[2] = INFINITY;
    memcpy(&store[count + 1], &nan_bits, sizeof nan_bits);

    veil_error err = {{0}};
    CHECK(veil_write_exr_planes(path, w, h, n, g_seven, planes, &err) == VEIL_OK, "write %s: %s", path, err.msg);
    int temps = 0;
    CHECK(count_entries(g_dir, &temps) == 1 && temps == 0, "after writing %s the directory should hold just it",
          path);

    /* the file as OpenEXRCore sees it, and one plane decoded by the library */
    static const char* const sorted[7] = {"A", "B", "G", "R", "stderr.B", "stderr.G", "stderr.R"};
    float* lib = calloc(count, sizeof(float));
    exr_facts f = core_inspect(path, "stderr.G", lib);
    int header_ok = f.ok && f.nchans == 7 && f.storage == EXR_STORAGE_SCANLINE && f.compression == EXR_COMPRESSION_ZIP;
    for (int c = 0; c < 7 && header_ok; ++c)
        header_ok = strcmp(f.names[c], sorted[c]) == 0 && f.types[c] == EXR_PIXEL_FLOAT;
    CHECK(header_ok, "%s: %d channels, first %s, last %s", path, f.nchans, f.names[0], f.names[6]);
    CHECK(f.ok && memcmp(lib, planes[5], count * sizeof(float)) == 0, "the file's stderr.G does not hold stderr.G");
    free(lib);

    for (int c = 0; c < n; ++c) expect_plane(path, g_seven[c], w, h, planes[c]);

    /* R, G, B, A through veil_read_exr */
    int rw = 0, rh = 0;
    float* back = NULL;
    CHECK(veil_read_exr(path, &rw, &rh, &back, &err) == VEIL_OK && rw == w && rh == h, "read %s: %s", path, err.msg);
    if (back && rw == w && rh == h) {
        const float* rgba[4] = {planes[1], planes[4], planes[6], planes[2]};
        size_t bad = 0;
        for (size_t i = 0; i < count; ++i)
            for (int c = 0; c < 4; ++c)
                if (!same_bits(back[i * 4 + (size_t)c], rgba[c][i])) ++bad;
        CHECK(bad == 0, "%s: %zu RGBA values wrong through veil_read_exr", path, bad);
    }
    free(back);

    /* a channel the file lacks: cleared outputs, a message naming the
     * file, the channel and the channels there are */
    rw = rh = -1;
    back = (float*)&rw;
    memset(&err, 0, sizeof err);
    veil_result r = veil_read_exr_channel(path, "stderr.A", &rw, &rh, &back, &err);
    CHECK(r == VEIL_ERR_INVALID && back == NULL && rw == 0 && rh == 0, "missing channel: %s (%s)",
          veil_result_name(r), err.msg);
    CHECK(strstr(err.msg, path) && strstr(err.msg, "\"stderr.A\"") && strstr(err.msg, "\"stderr.R\"") &&
              strstr(err.msg, "\"A\""),
          "missing channel: the message should name the file, the channel and the file's channels: %s", err.msg);
    r = veil_read_exr_channel(path, "r", &rw, &rh, &back, &err);
    CHECK(r == VEIL_ERR_INVALID && back == NULL, "channel names are case-sensitive: %s", veil_result_name(r));
    r = veil_read_exr_channel(path, "", &rw, &rh, &back, &err);
    CHECK(r == VEIL_ERR_INVALID && strstr(err.msg, path), "empty channel name: %s (%s)", veil_result_name(r), err.msg);
    r = veil_read_exr_channel(path, NULL, &rw, &rh, &back, &err);
    CHECK(r == VEIL_ERR_INVALID, "no channel name: %s", veil_result_name(r));
    r = veil_read_exr_channel(path, "R", &rw, NULL, &back, &err);
    CHECK(r == VEIL_ERR_INVALID, "no height pointer: %s", veil_result_name(r));
    char missing[256];
    path_in(missing, sizeof missing, "missing.exr");
    r = veil_read_exr_channel(missing, "R", &rw, &rh, &back, &err);
    CHECK(r == VEIL_ERR_IO && back == NULL && strstr(err.msg, missing), "missing file: %s (%s)", veil_result_name(r),
          err.msg);
    unlink(path);
    free(store);

    /* one 1x1 channel */
    const float one = 0.75f;
    const float* one_plane[1] = {&one};
    const char* const y_name[1] = {"Y"};
    CHECK(veil_write_exr_planes(path, 1, 1, 1, y_name, one_plane, &err) == VEIL_OK, "write 1x1: %s", err.msg);
    expect_plane(path, "Y", 1, 1, &one);
    r = veil_read_exr(path, &rw, &rh, &back, &err);
    CHECK(r == VEIL_ERR_IO && back == NULL && strstr(err.msg, "\"Y\""), "RGBA from a Y file: %s (%s)",
          veil_result_name(r), err.msg);
    unlink(path);

    /* 64 channels with 255-character names */
    {
        enum { N = 64, W = 3, H = 2 };
        static char names[N][256];
        const char* name_ptrs[N];
        float* values = malloc(sizeof(float) * N * W * H);
        const float* ps[N];
        for (int c = 0; c < N; ++c) {
            memset(names[c], 'a' + c % 26, 252);
            snprintf(names[c] + 252, 4, "%03u", (unsigned)c % 1000u);
            name_ptrs[c] = names[c];
            for (int i = 0; i < W * H; ++i) values[c * W * H + i] = (float)c * 10.0f + (float)i;
            ps[c] = values + c * W * H;
        }
        CHECK(strlen(names[0]) == 255, "test name length %zu", strlen(names[0]));
        CHECK(veil_write_exr_planes(path, W, H, N, name_ptrs, ps, &err) == VEIL_OK, "write 64 long-named channels: %s",
              err.msg);
        expect_plane(path, names[0], W, H, ps[0]);
        expect_plane(path, names[37], W, H, ps[37]);
        expect_plane(path, names[63], W, H, ps[63]);
        float* none = NULL;
        r = veil_read_exr_channel(path, "nope", &rw, &rh, &none, &err);
        CHECK(r == VEIL_ERR_INVALID && strstr(err.msg, "\"nope\"") && strstr(err.msg, "...") && strstr(err.msg, path),
              "a missing channel among 64 long names: %s (%s)", veil_result_name(r), err.msg);
        free(values);
        unlink(path);
    }
}

/* Half inputs, other data windows, an extra channel, no alpha, tiles. */
static void test_exr_foreign(void)
{
    static const struct {
        uint16_t bits;
        float value;
    } halves[] = {
        {0x0000, 0.0f},        {0x3C00, 1.0f},        {0x3800, 0.5f},          {0x4000, 2.0f},
        {0x3400, 0.25f},       {0xC300, -3.5f},       {0x7BFF, 65504.0f},      {0x0400, 6.103515625e-05f},
        {0x0001, 5.9604644775390625e-08f}, {0x8000, -0.0f}, {0x3555, 0.333251953125f}, {0x7C00, INFINITY},
    };
    const int nh = (int)(sizeof halves / sizeof halves[0]);
    char path[256];
    veil_error err = {{0}};
    int rw = 0, rh = 0;
    float* back = NULL;

    /* half RGBA, uncompressed, data window not at the origin */
    {
        path_in(path, sizeof path, "half_rgba.exr");
        exr_attr_box2i_t dw;
        dw.min.x = -5;
        dw.min.y = -3;
        dw.max.x = 4;
        dw.max.y = 20;
        const int W = 10, H = 24;
        uint16_t* planes[4];
        for (int c = 0; c < 4; ++c) {
            planes[c] = malloc(sizeof(uint16_t) * W * H);
            for (int i = 0; i < W * H; ++i) planes[c][i] = halves[(i + 3 * c) % nh].bits;
        }
        test_chan chans[4] = {{"R", EXR_PIXEL_HALF, planes[0]},
                              {"G", EXR_PIXEL_HALF, planes[1]},
                              {"B", EXR_PIXEL_HALF, planes[2]},
                              {"A", EXR_PIXEL_HALF, planes[3]}};
        CHECK(core_write(path, EXR_COMPRESSION_NONE, dw, 0, chans, 4), "cannot make %s", path);
        CHECK(veil_read_exr(path, &rw, &rh, &back, &err) == VEIL_OK, "read %s: %s", path, err.msg);
        CHECK(rw == W && rh == H, "%s: size %dx%d", path, rw, rh);
        if (back && rw == W && rh == H) {
            int bad = 0;
            for (int i = 0; i < W * H; ++i)
                for (int c = 0; c < 4; ++c)
                    if (!same_bits(back[i * 4 + c], halves[(i + 3 * c) % nh].value)) ++bad;
            CHECK(bad == 0, "%s: %d half values wrong after conversion to float", path, bad);
        }
        free(back);
        back = NULL;
        for (int c = 0; c < 4; ++c) free(planes[c]);
        unlink(path);
    }

    /* half RGB plus a float Z channel, ZIP, no alpha: A reads as 1 */
    {
        path_in(path, sizeof path, "half_rgbz.exr");
        exr_attr_box2i_t dw;
        dw.min.x = 0;
        dw.min.y = 0;
        dw.max.x = 6;
        dw.max.y = 40;
        const int W = 7, H = 41;
        uint16_t* planes[3];
        float* z = malloc(sizeof(float) * W * H);
        for (int c = 0; c < 3; ++c) {
            planes[c] = malloc(sizeof(uint16_t) * W * H);
            for (int i = 0; i < W * H; ++i) planes[c][i] = halves[(i * 5 + c) % nh].bits;
        }
        for (int i = 0; i < W * H; ++i) z[i] = 1000.0f + (float)i;
        test_chan chans[4] = {{"R", EXR_PIXEL_HALF, planes[0]},
                              {"G", EXR_PIXEL_HALF, planes[1]},
                              {"B", EXR_PIXEL_HALF, planes[2]},
                              {"Z", EXR_PIXEL_FLOAT, z}};
        CHECK(core_write(path, EXR_COMPRESSION_ZIP, dw, 0, chans, 4), "cannot make %s", path);
        CHECK(veil_read_exr(path, &rw, &rh, &back, &err) == VEIL_OK, "read %s: %s", path, err.msg);
        CHECK(rw == W && rh == H, "%s: size %dx%d", path, rw, rh);
        if (back && rw == W && rh == H) {
            int bad = 0, alpha = 0;
            for (int i = 0; i < W * H; ++i) {
                for (int c = 0; c < 3; ++c)
                    if (!same_bits(back[i * 4 + c], halves[(i * 5 + c) % nh].value)) ++bad;
                if (back[i * 4 + 3] != 1.0f) ++alpha;
            }
            CHECK(bad == 0, "%s: %d RGB values wrong", path, bad);
            CHECK(alpha == 0, "%s: %d alpha values are not 1 without an A channel", path, alpha);
        }
        free(back);
        back = NULL;
        for (int c = 0; c < 3; ++c) free(planes[c]);
        free(z);
        unlink(path);
    }

    /* tiled float RGBA, 4x4 tiles over 10x7 (partial tiles), offset window */
    {
        path_in(path, sizeof path, "tiled.exr");
        exr_attr_box2i_t dw;
        dw.min.x = 3;
        dw.min.y = -2;
        dw.max.x = 12;
        dw.max.y = 4;
        const int W = 10, H = 7;
        float* planes[4];
        for (int c = 0; c < 4; ++c) {
            planes[c] = malloc(sizeof(float) * W * H);
            for (int i = 0; i < W * H; ++i) planes[c][i] = (float)(c + 1) * 0.125f + (float)i;
        }
        test_chan chans[4] = {{"R", EXR_PIXEL_FLOAT, planes[0]},
                              {"G", EXR_PIXEL_FLOAT, planes[1]},
                              {"B", EXR_PIXEL_FLOAT, planes[2]},
                              {"A", EXR_PIXEL_FLOAT, planes[3]}};
        CHECK(core_write(path, EXR_COMPRESSION_ZIP, dw, 4, chans, 4), "cannot make %s", path);
        exr_facts f = core_inspect(path, NULL, NULL);
        CHECK(f.ok && f.storage == EXR_STORAGE_TILED, "%s is not a tiled file", path);
        CHECK(veil_read_exr(path, &rw, &rh, &back, &err) == VEIL_OK, "read %s: %s", path, err.msg);
        CHECK(rw == W && rh == H, "%s: size %dx%d", path, rw, rh);
        if (back && rw == W && rh == H) {
            int bad = 0;
            for (int i = 0; i < W * H; ++i)
                for (int c = 0; c < 4; ++c)
                    if (back[i * 4 + c] != planes[c][i]) ++bad;
            CHECK(bad == 0, "%s: %d values wrong", path, bad);
        }
        free(back);
        back = NULL;
        for (int c = 0; c < 4; ++c) free(planes[c]);
        unlink(path);
    }

    /* named half, float and uint channels, scanline (window off the origin)
     * and tiled (partial tiles), read one at a time */
    for (int tiled = 0; tiled <= 1; ++tiled) {
        path_in(path, sizeof path, tiled ? "named_tiled.exr" : "named_scan.exr");
        exr_attr_box2i_t dw;
        dw.min.x = -2;
        dw.min.y = 7;
        dw.max.x = 8;
        dw.max.y = 43;
        const int W = 11, H = 37;
        uint16_t* y = malloc(sizeof(uint16_t) * W * H);
        float* depth = malloc(sizeof(float) * W * H);
        uint32_t* id = malloc(sizeof(uint32_t) * W * H);
        for (int i = 0; i < W * H; ++i) {
            y[i] = halves[(i * 7 + tiled) % nh].bits;
            depth[i] = random_finite();
            id[i] = (uint32_t)i;
        }
        test_chan chans[3] = {{"Y", EXR_PIXEL_HALF, y}, {"depth", EXR_PIXEL_FLOAT, depth}, {"id", EXR_PIXEL_UINT, id}};
        CHECK(core_write(path, EXR_COMPRESSION_ZIP, dw, tiled ? 5 : 0, chans, 3), "cannot make %s", path);
        for (int c = 0; c < 2; ++c) {
            float* plane = NULL;
            rw = rh = 0;
            veil_result r = veil_read_exr_channel(path, chans[c].name, &rw, &rh, &plane, &err);
            CHECK(r == VEIL_OK && rw == W && rh == H, "%s: channel %s: %s, %dx%d (%s)", path, chans[c].name,
                  veil_result_name(r), rw, rh, err.msg);
            if (plane && rw == W && rh == H) {
                int bad = 0;
                for (int i = 0; i < W * H; ++i)
                    if (!same_bits(plane[i], c == 0 ? halves[(i * 7 + tiled) % nh].value : depth[i])) ++bad;
                CHECK(bad == 0, "%s: channel %s: %d values wrong", path, chans[c].name, bad);
            }
            free(plane);
        }
        float* plane = NULL;
        veil_result r = veil_read_exr_channel(path, "id", &rw, &rh, &plane, &err);
        CHECK(r == VEIL_ERR_IO && plane == NULL && strstr(err.msg, "id") && strstr(err.msg, "uint"),
              "%s: a uint channel: %s (%s)", path, veil_result_name(r), err.msg);
        free(plane);
        free(y);
        free(depth);
        free(id);
        unlink(path);
    }

    /* no R/G/B: a clear refusal */
    {
        path_in(path, sizeof path, "only_y.exr");
        exr_attr_box2i_t dw;
        dw.min.x = 0;
        dw.min.y = 0;
        dw.max.x = 3;
        dw.max.y = 3;
        float y[16] = {0};
        test_chan chans[1] = {{"Y", EXR_PIXEL_FLOAT, y}};
        CHECK(core_write(path, EXR_COMPRESSION_ZIP, dw, 0, chans, 1), "cannot make %s", path);
        veil_result r = veil_read_exr(path, &rw, &rh, &back, &err);
        CHECK(r == VEIL_ERR_IO && back == NULL && strstr(err.msg, path), "%s: %s: %s", path, veil_result_name(r),
              err.msg);
        unlink(path);
    }
}

/* A failed write leaves the directory as it was. */
static void expect_failed_write(const char* what, veil_result r, veil_result expected, const char* path,
                                const veil_error* err, int entries_before)
{
    int temps = 0;
    int entries = count_entries(g_dir, &temps);
    CHECK(r == expected, "%s: %s, expected %s (%s)", what, veil_result_name(r), veil_result_name(expected), err->msg);
    CHECK(strstr(err->msg, path) != NULL, "%s: message does not name %s: %s", what, path, err->msg);
    CHECK(entries == entries_before && temps == 0, "%s: directory has %d entries (%d temporary), expected %d", what,
          entries, temps, entries_before);
}

static void expect_invalid_planes(const char* what, const char* path, int w, int h, int n, const char* const* names,
                                  const float* const* planes, const char* in_msg)
{
    veil_error err = {{0}};
    veil_result r = veil_write_exr_planes(path, w, h, n, names, planes, &err);
    CHECK(r == VEIL_ERR_INVALID, "%s: %s, expected VEIL_ERR_INVALID (%s)", what, veil_result_name(r), err.msg);
    CHECK(strstr(err.msg, path) && (!in_msg || strstr(err.msg, in_msg)), "%s: the message should name %s and %s: %s",
          what, path, in_msg ? in_msg : "nothing else", err.msg);
    CHECK(!file_exists(path), "%s: %s exists", what, path);
}

static void test_exr_planes_failures(void)
{
    char path[256], dirpath[256];
    float a[4 * 4] = {0}, b[4 * 4] = {0};
    const float* ab[3] = {a, b, a};
    const char* const rgb[3] = {"R", "G", "B"};
    int base = count_entries(g_dir, NULL);

    path_in(path, sizeof path, "planes_bad.exr");
    const char* const dup[3] = {"R", "G", "R"};
    expect_invalid_planes("duplicate names", path, 4, 4, 3, dup, ab, "\"R\"");
    const char* const dup2[3] = {"stderr.R", "A", "stderr.R"};
    expect_invalid_planes("duplicate long names", path, 4, 4, 3, dup2, ab, "\"stderr.R\"");
    const char* const no_name[3] = {"R", NULL, "B"};
    expect_invalid_planes("a NULL name", path, 4, 4, 3, no_name, ab, "channel 2");
    const char* const empty[3] = {"R", "", "B"};
    expect_invalid_planes("an empty name", path, 4, 4, 3, empty, ab, "channel 2");
    char long_name[257];
    memset(long_name, 'x', 256);
    long_name[256] = '\0';
    const char* const too_long[3] = {"R", "G", long_name};
    expect_invalid_planes("a 256-character name", path, 4, 4, 3, too_long, ab, "256 characters");
    const float* no_plane[3] = {a, NULL, b};
    expect_invalid_planes("a NULL plane", path, 4, 4, 3, rgb, no_plane, "\"G\"");
    expect_invalid_planes("no names", path, 4, 4, 3, NULL, ab, "names");
    expect_invalid_planes("no planes", path, 4, 4, 3, rgb, NULL, "planes");
    expect_invalid_planes("0 channels", path, 4, 4, 0, rgb, ab, "0 channels");
    expect_invalid_planes("-1 channels", path, 4, 4, -1, rgb, ab, "-1 channels");
    {
        char names[65][16];
        const char* name_ptrs[65];
        const float* ps[65];
        for (int c = 0; c < 65; ++c) {
            snprintf(names[c], sizeof names[c], "c%d", c);
            name_ptrs[c] = names[c];
            ps[c] = a;
        }
        expect_invalid_planes("65 channels", path, 4, 4, 65, name_ptrs, ps, "65 channels");
    }
    static const int sizes[][2] = {{0, 4}, {4, 0}, {-1, 4}, {4, -7}, {INT_MAX, INT_MAX}};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; ++i)
        expect_invalid_planes("bad size", path, sizes[i][0], sizes[i][1], 3, rgb, ab, NULL);
    veil_error err = {{0}};
    CHECK(veil_write_exr_planes(NULL, 4, 4, 3, rgb, ab, &err) == VEIL_ERR_INVALID, "no path");
    CHECK(veil_write_exr_planes("", 4, 4, 3, rgb, ab, &err) == VEIL_ERR_INVALID, "empty path");
    CHECK(count_entries(g_dir, NULL) == base, "invalid plane writes created files");

    /* into a directory that does not exist; onto a directory */
    path_in(path, sizeof path, "no_such_dir/planes.exr");
    memset(&err, 0, sizeof err);
    expect_failed_write("planes into a missing directory", veil_write_exr_planes(path, 4, 4, 3, rgb, ab, &err),
                        VEIL_ERR_IO, path, &err, base);
    CHECK(!file_exists(path), "%s exists after a failed write", path);
    path_in(dirpath, sizeof dirpath, "planes_dir.exr");
    CHECK(mkdir(dirpath, 0700) == 0, "mkdir %s", dirpath);
    memset(&err, 0, sizeof err);
    expect_failed_write("planes onto a directory", veil_write_exr_planes(dirpath, 4, 4, 3, rgb, ab, &err),
                        VEIL_ERR_IO, dirpath, &err, base + 1);
    CHECK(count_entries(dirpath, NULL) == 0, "%s is not empty", dirpath);
    rmdir(dirpath);
    CHECK(count_entries(g_dir, NULL) == base, "failed plane writes left files");
}

static void test_write_failures(void)
{
    char path[256], dirpath[256];
    float px[4 * 4 * 4] = {0};
    veil_error err = {{0}};
    int base = count_entries(g_dir, NULL);

    /* into a directory that does not exist */
    path_in(path, sizeof path, "no_such_dir/out.exr");
    expect_failed_write("EXR into a missing directory", veil_write_exr(path, 4, 4, px, &err), VEIL_ERR_IO, path, &err,
                        base);
    CHECK(!file_exists(path), "%s exists after a failed write", path);
    memset(&err, 0, sizeof err);
    path_in(path, sizeof path, "no_such_dir/out.png");
    expect_failed_write("PNG into a missing directory", veil_write_png(path, 4, 4, px, 0.0f, &err), VEIL_ERR_IO, path,
                        &err, base);

    /* the target is a directory: the temporary is made, the rename fails,
     * and the temporary must go */
    path_in(dirpath, sizeof dirpath, "a_directory.exr");
    CHECK(mkdir(dirpath, 0700) == 0, "mkdir %s", dirpath);
    base = count_entries(g_dir, NULL);
    memset(&err, 0, sizeof err);
    expect_failed_write("EXR onto a directory", veil_write_exr(dirpath, 4, 4, px, &err), VEIL_ERR_IO, dirpath, &err,
                        base);
    memset(&err, 0, sizeof err);
    expect_failed_write("PNG onto a directory", veil_write_png(dirpath, 4, 4, px, 0.0f, &err), VEIL_ERR_IO, dirpath,
                        &err, base);
    CHECK(count_entries(dirpath, NULL) == 0, "%s is not empty", dirpath);
    rmdir(dirpath);
    base = count_entries(g_dir, NULL);

    /* a write that fails half way (the file size limit): the temporary is
     * made, a write fails, the temporary must go */
    {
        const int w = 96, h = 96;
        float* noisy = malloc(sizeof(float) * 4 * w * h);
        for (int i = 0; i < 4 * w * h; ++i) noisy[i] = (float)(rng() >> 8) / (float)(1 << 22);
        struct rlimit old, lim;
        void (*prev)(int) = signal(SIGXFSZ, SIG_IGN);
        if (getrlimit(RLIMIT_FSIZE, &old) == 0) {
            lim = old;
            lim.rlim_cur = 8192;
            if (setrlimit(RLIMIT_FSIZE, &lim) == 0) {
                veil_result rexr, rpng;
                veil_error eexr = {{0}}, epng = {{0}};
                path_in(path, sizeof path, "too_big.exr");
                rexr = veil_write_exr(path, w, h, noisy, &eexr);
                path_in(dirpath, sizeof dirpath, "too_big.png");
                rpng = veil_write_png(dirpath, w, h, noisy, 0.0f, &epng);
                setrlimit(RLIMIT_FSIZE, &old);
                expect_failed_write("EXR past the file size limit", rexr, VEIL_ERR_IO, path, &eexr, base);
                expect_failed_write("PNG past the file size limit", rpng, VEIL_ERR_IO, dirpath, &epng, base);
            }
        }
        signal(SIGXFSZ, prev);
        free(noisy);
    }

    /* invalid arguments */
    path_in(path, sizeof path, "invalid.exr");
    static const int sizes[][2] = {{0, 4}, {4, 0}, {-1, 4}, {4, -7}, {INT_MAX, INT_MAX}};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; ++i) {
        memset(&err, 0, sizeof err);
        veil_result r = veil_write_exr(path, sizes[i][0], sizes[i][1], px, &err);
        CHECK(r == VEIL_ERR_INVALID, "EXR %dx%d: %s", sizes[i][0], sizes[i][1], veil_result_name(r));
        r = veil_write_png(path, sizes[i][0], sizes[i][1], px, 0.0f, &err);
        CHECK(r == VEIL_ERR_INVALID, "PNG %dx%d: %s", sizes[i][0], sizes[i][1], veil_result_name(r));
    }
    CHECK(veil_write_exr(path, 4, 4, NULL, &err) == VEIL_ERR_INVALID, "EXR without pixels");
    CHECK(veil_write_png(path, 4, 4, NULL, 0.0f, &err) == VEIL_ERR_INVALID, "PNG without pixels");
    CHECK(count_entries(g_dir, NULL) == base, "invalid writes created files");
}

static void expect_bad_read(const char* what, const char* path)
{
    veil_error err = {{0}};
    int w = -1, h = -1;
    float* px = (float*)&w; /* must be reset to NULL */
    veil_result r = veil_read_exr(path, &w, &h, &px, &err);
    CHECK(r == VEIL_ERR_IO, "%s: %s, expected VEIL_ERR_IO (%s)", what, veil_result_name(r), err.msg);
    CHECK(px == NULL && w == 0 && h == 0, "%s: outputs not cleared", what);
    CHECK(strstr(err.msg, path) != NULL, "%s: message does not name %s: %s", what, path, err.msg);
    if (r == VEIL_OK) free(px);
}

static void test_read_failures(void)
{
    char good[256], bad[256];
    path_in(good, sizeof good, "good.exr");
    path_in(bad, sizeof bad, "bad.exr");
    const int w = 64, h = 64;
    float* px = malloc(sizeof(float) * 4 * w * h);
    for (int i = 0; i < 4 * w * h; ++i) px[i] = random_finite();
    veil_error err = {{0}};
    CHECK(veil_write_exr(good, w, h, px, &err) == VEIL_OK, "write %s: %s", good, err.msg);
    size_t size = 0;
    unsigned char* bytes = slurp(good, &size);
    CHECK(bytes && size > 4096, "%s: %zu bytes", good, size);
    if (!bytes) {
        free(px);
        return;
    }

    /* truncated at half its size, and elsewhere */
    spit(bad, bytes, size / 2);
    expect_bad_read("EXR truncated to half", bad);
    const size_t cuts[] = {0, 3, 4, 8, 20, 100, size / 4, size - size / 4, size - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; ++i) {
        char what[64];
        snprintf(what, sizeof what, "EXR truncated to %zu bytes", cuts[i]);
        spit(bad, bytes, cuts[i]);
        expect_bad_read(what, bad);
    }

    /* garbage, with and without the OpenEXR magic number */
    unsigned char* junk = malloc(8192);
    for (int i = 0; i < 8192; ++i) junk[i] = (unsigned char)(rng() >> 24);
    spit(bad, junk, 8192);
    expect_bad_read("garbage file", bad);
    junk[0] = 0x76;
    junk[1] = 0x2f;
    junk[2] = 0x31;
    junk[3] = 0x01;
    junk[4] = 2;
    junk[5] = junk[6] = junk[7] = 0;
    spit(bad, junk, 8192);
    expect_bad_read("garbage after the magic number", bad);
    spit(bad, "not an image\n", 13);
    expect_bad_read("text file", bad);
    free(junk);

    /* the header intact, the pixel data damaged: an error or some pixels,
     * never a crash */
    int survived = 1;
    for (int k = 0; k < 40; ++k) {
        unsigned char* copy = malloc(size);
        memcpy(copy, bytes, size);
        size_t at = size / 2 + rng() % (size / 2);
        for (int j = 0; j < 8 && at + j < size; ++j) copy[at + j] ^= (unsigned char)(rng() >> 24) | 1u;
        spit(bad, copy, size);
        free(copy);
        int rw = 0, rh = 0;
        float* back = NULL;
        memset(&err, 0, sizeof err);
        veil_result r = veil_read_exr(bad, &rw, &rh, &back, &err);
        if (!(r == VEIL_OK || (r == VEIL_ERR_IO && strstr(err.msg, bad)))) survived = 0;
        free(back);
    }
    CHECK(survived, "damaged pixel data gave something other than success or VEIL_ERR_IO naming the file");
    unlink(bad);

    /* missing file, a directory */
    char missing[256];
    path_in(missing, sizeof missing, "missing.exr");
    expect_bad_read("missing file", missing);
    expect_bad_read("a directory", g_dir);

    /* the good file still reads */
    int rw = 0, rh = 0;
    float* back = NULL;
    CHECK(veil_read_exr(good, &rw, &rh, &back, &err) == VEIL_OK && back &&
              memcmp(back, px, sizeof(float) * 4 * w * h) == 0,
          "%s: %s", good, err.msg);
    free(back);
    CHECK(veil_read_exr(good, NULL, &rh, &back, &err) == VEIL_ERR_INVALID, "read without a width pointer");
    unlink(good);
    free(bytes);
    free(px);
}


/* ------------------------------------------------------------------------ */
/* The output formats (issue 42): every compression OpenEXRCore encodes, float and half, on one and on
 * several threads. Bounds:
 *  - none, rle, zips, zip, piz: lossless: float channels bit for bit; a half channel is the float
 *    rounded to half, within 2^-11 relative for values in half's normal range (the image's are in
 *    [1e-3, 1e3]; Z's +infinity stays infinite);
 *  - pxr24: a float channel rounded to 24 bits (a 15-bit significand): within 2^-16 relative; half
 *    channels lossless (as above);
 *  - b44, b44a: float channels stored as they are (bit for bit); half channels are the codec's (not
 *    checked here beyond being finite, which a wrong channel order would still satisfy: the lossless
 *    codecs check that);
 *  - the chunks compressed on 1 and on 5 threads make the same bytes (the chunks are written in
 *    order, whichever thread compressed them).
 * The channels Z, depth and P stay float in a half file (veil_exr_keeps_float). */
#define FW 97
#define FH 83
#define FN 7
static const char* const g_fmt_names[FN] = {"R", "G", "B", "A", "Z", "depth", "P"};

static int read_bytes(const char* path, unsigned char** out, size_t* n)
{
    FILE* f = fopen(path, "rb");
    if (!f) return 0;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    *out = malloc(len > 0 ? (size_t)len : 1);
    *n = *out && len >= 0 ? fread(*out, 1, (size_t)len, f) : 0;
    fclose(f);
    return *out && *n == (size_t)len;
}

static void test_exr_formats(void)
{
    float* planes[FN];
    uint64_t seed = 4242;
    for (int c = 0; c < FN; ++c) {
        planes[c] = malloc(FW * FH * sizeof(float));
        for (int i = 0; i < FW * FH; ++i) /* log-uniform in [1e-3, 1e3] */
            planes[c][i] = (float)pow(10.0, -3.0 + 6.0 * ((double)((seed = seed * 6364136223846793005ULL + 1442695040888963407ULL) >> 11) / 9007199254740992.0));
    }
    planes[4][5] = INFINITY; /* Z where the ray met nothing */
    char a[512], b[512];
    path_in(a, sizeof a, "fmt1.exr");
    path_in(b, sizeof b, "fmt5.exr");
    static const int codecs[] = {VEIL_EXR_NONE, VEIL_EXR_RLE, VEIL_EXR_ZIPS, VEIL_EXR_ZIP, VEIL_EXR_PIZ, VEIL_EXR_PXR24,
                                 VEIL_EXR_B44, VEIL_EXR_B44A, VEIL_EXR_DEFAULT};
    float* got = malloc(FW * FH * sizeof(float));
    for (size_t k = 0; k < sizeof codecs / sizeof *codecs; ++k)
        for (int half = 0; half <= 1; ++half) {
            const int codec = codecs[k];
            const char* name = veil_exr_compression_name(codec);
            veil_exr_meta m1 = {.format = {.half = half, .compression = codec, .threads = 1}}, m5 = m1;
            m5.format.threads = 5;
            veil_error err = {0};
            CHECK(veil_write_exr_planes_meta(a, FW, FH, FN, g_fmt_names, (const float* const*)planes, &m1, &err) == VEIL_OK,
                  "%s %s, 1 thread: %s", name, half ? "half" : "float", err.msg);
            CHECK(veil_write_exr_planes_meta(b, FW, FH, FN, g_fmt_names, (const float* const*)planes, &m5, &err) == VEIL_OK,
                  "%s %s, 5 threads: %s", name, half ? "half" : "float", err.msg);
            unsigned char *ba = NULL, *bb = NULL;
            size_t na = 0, nb = 0;
            CHECK(read_bytes(a, &ba, &na) && read_bytes(b, &bb, &nb) && na == nb && !memcmp(ba, bb, na),
                  "%s %s: 1 and 5 threads wrote different files (%zu and %zu bytes)", name, half ? "half" : "float", na, nb);
            free(ba);
            free(bb);
            for (int c = 0; c < FN; ++c) {
                memset(got, 0, FW * FH * sizeof(float));
                exr_facts f = core_inspect(b, g_fmt_names[c], got);
                CHECK(f.ok && (int)f.compression == veil__exr_compression_of(codec), "%s: compression %d", name,
                      (int)f.compression);
                const int is_half = half && !veil_exr_keeps_float(g_fmt_names[c]);
                int type_ok = 0;
                for (int i = 0; i < f.nchans; ++i)
                    if (!strcmp(f.names[i], g_fmt_names[c])) type_ok = f.types[i] == (is_half ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT);
                CHECK(type_ok, "%s %s: channel %s is not %s", name, half ? "half" : "float", g_fmt_names[c],
                      is_half ? "half" : "float");
                const int lossy_half = is_half && (codec == VEIL_EXR_B44 || codec == VEIL_EXR_B44A);
                const double rel = is_half ? (lossy_half ? -1.0 : ldexp(1.0, -11)) : codec == VEIL_EXR_PXR24 ? ldexp(1.0, -16) : 0.0;
                int bad = 0, first = -1;
                for (int i = 0; i < FW * FH; ++i) {
                    const double want = planes[c][i], v = got[i];
                    const int ok = rel < 0.0 ? isfinite(v) || isinf(want) : isinf(want) ? v == want : fabs(v - want) <= rel * fabs(want);
                    if (!ok && !bad++) first = i;
                }
                CHECK(!bad, "%s %s, channel %s: %d values off (first at %d: %.9g for %.9g; bound %g relative)", name,
                      half ? "half" : "float", g_fmt_names[c], bad, first, first >= 0 ? (double)got[first] : 0.0,
                      first >= 0 ? (double)planes[c][first] : 0.0, rel);
            }
            unlink(a);
            unlink(b);
        }
    free(got);
    for (int c = 0; c < FN; ++c) free(planes[c]);
    CHECK(veil_exr_compression_parse("dwaa") == VEIL_EXR_DWAA && veil_exr_compression_parse("zip") == VEIL_EXR_ZIP &&
          veil_exr_compression_parse("ZIP") < 0 && veil_exr_compression_parse("") < 0, "%s", "compression names");
}

int main(void)
{
    if (!test_dir_begin("test_exr")) return 1;
    test_exr_formats();
    test_exr_roundtrip();
    test_exr_channels();
    test_exr_planes();
    test_exr_foreign();
    test_write_failures();
    test_exr_planes_failures();
    test_read_failures();
    CHECK(test_dir_end(), "the test folder %s was not left empty", g_dir);
    return check_finish();
}
