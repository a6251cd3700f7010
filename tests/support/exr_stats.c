/* exr_stats — a test tool: what an image file the CLI wrote holds.
 *
 *   exr_stats FILE.exr            every channel (listed by OpenEXRCore, read
 *                                 by veil_read_exr_channel): its min, max and
 *                                 count of non-finite values; exit 1 when any
 *                                 value is NaN or infinite
 *   exr_stats --rgba FILE.exr     the same, and R, G, B, A must exist with
 *                                 R, G, B >= 0 and A in [0, 1] (io/image.h:
 *                                 linear radiance, A = 1 - mean transmittance)
 *   exr_stats --png FILE.png W H  the PNG decodes (libpng) to W x H pixels
 *   exr_stats --extent FILE.exr T the box of the pixels whose A is above T,
 *                                 "extent x0 x1 y0 y1 n" (columns, rows, inclusive; y
 *                                 0 the top row; n the pixels), or "extent none"
 *   exr_stats --write-bad KIND FILE.exr
 *                                 writes a 4x3 R, G, B, A EXR that --rgba
 *                                 accepts, except for one value by KIND:
 *                                 nan (a G), inf (a B), negative (an R < 0),
 *                                 alpha (an A = 1.5), none (nothing wrong), so
 *                                 that tests/cli/cli_end_to_end.sh can show each
 *                                 check fails when it should
 * Exit 0: all good; 1: a value or the PNG is wrong; 2: usage, or a file that
 * cannot be read or written.
 */
#include <math.h>
#include <openexr.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/image.h"

enum { MAX_CHANNELS = 64 };

static void quiet(exr_const_context_t ctxt, exr_result_t code, const char* msg) {}

/* The channel names of path's first part, in file order, into names. */
static int list_channels(const char* path, char names[][256], int max)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = quiet;
    exr_context_t ctx = NULL;
    if (exr_start_read(&ctx, path, &init) != EXR_ERR_SUCCESS) {
        exr_finish(&ctx);
        return -1;
    }
    const exr_attr_chlist_t* ch = NULL;
    int n = -1;
    if (exr_get_channels(ctx, 0, &ch) == EXR_ERR_SUCCESS && ch && ch->num_channels <= max) {
        n = ch->num_channels;
        for (int c = 0; c < n; ++c) snprintf(names[c], 256, "%s", ch->entries[c].name.str);
    }
    exr_finish(&ctx);
    return n;
}

static int exr_check(const char* path, int rgba)
{
    static char names[MAX_CHANNELS][256];
    int n = list_channels(path, names, MAX_CHANNELS);
    if (n < 0) {
        fprintf(stderr, "exr_stats: %s: OpenEXRCore cannot read its channel list\n", path);
        return 2;
    }
    int bad = 0, w = 0, h = 0, seen_rgba = 0;
    for (int c = 0; c < n; ++c) {
        float* p = NULL;
        veil_error err = {0};
        if (veil_read_exr_channel(path, names[c], &w, &h, &p, &err) != VEIL_OK) {
            fprintf(stderr, "exr_stats: %s\n", err.msg);
            return 2;
        }
        size_t count = (size_t)w * (size_t)h, nonfinite = 0, below = 0, above = 0;
        double lo = INFINITY, hi = -INFINITY;
        /* the range a channel must keep under --rgba: A in [0, 1], R, G, B >= 0 */
        const int is_a = !strcmp(names[c], "A");
        const int ranged = rgba && (is_a || !strcmp(names[c], "R") || !strcmp(names[c], "G") || !strcmp(names[c], "B"));
        seen_rgba += ranged;
        for (size_t i = 0; i < count; ++i) {
            const double v = p[i];
            if (!isfinite(v)) {
                ++nonfinite;
                continue;
            }
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
            below += ranged && v < 0.0;
            above += ranged && is_a && v > 1.0;
        }
        free(p);
        printf("%-12s min %-12.6g max %-12.6g non-finite %zu", names[c], lo, hi, nonfinite);
        if (ranged) printf("  out of range %zu", below + above);
        printf("\n");
        bad |= nonfinite > 0 || below > 0 || above > 0;
    }
    printf("%s: %dx%d, %d channels\n", path, w, h, n);
    if (rgba && seen_rgba != 4) {
        fprintf(stderr, "exr_stats: %s: lacks one of R, G, B, A\n", path);
        bad = 1;
    }
    return bad;
}

static int png_check(const char* path, int w, int h)
{
    png_image im;
    memset(&im, 0, sizeof im);
    im.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&im, path)) {
        fprintf(stderr, "exr_stats: %s: %s\n", path, im.message);
        return 1;
    }
    im.format = PNG_FORMAT_RGB;
    unsigned char* px = malloc(PNG_IMAGE_SIZE(im));
    int ok = px && png_image_finish_read(&im, NULL, px, 0, NULL);
    if (!ok) fprintf(stderr, "exr_stats: %s: %s\n", path, px ? im.message : "out of memory");
    png_image_free(&im);
    free(px);
    printf("%s: %ux%u PNG, %s\n", path, im.width, im.height, ok ? "decoded" : "does not decode");
    if (ok && (im.width != (png_uint_32)w || im.height != (png_uint_32)h)) {
        fprintf(stderr, "exr_stats: %s: %ux%u, expected %dx%d\n", path, im.width, im.height, w, h);
        ok = 0;
    }
    return !ok;
}

static int extent(const char* path, double threshold)
{
    int w = 0, h = 0, box[4] = {0, -1, 0, -1};
    float* a = NULL;
    veil_error err = {0};
    if (veil_read_exr_channel(path, "A", &w, &h, &a, &err) != VEIL_OK) {
        fprintf(stderr, "exr_stats: %s\n", err.msg);
        return 2;
    }
    size_t n = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (a[(size_t)y * (size_t)w + (size_t)x] > threshold) {
                if (!n++) box[0] = box[1] = x, box[2] = box[3] = y;
                box[0] = x < box[0] ? x : box[0], box[1] = x > box[1] ? x : box[1];
                box[2] = y < box[2] ? y : box[2], box[3] = y > box[3] ? y : box[3];
            }
    free(a);
    if (n) printf("extent %d %d %d %d %zu\n", box[0], box[1], box[2], box[3], n);
    else printf("extent none\n");
    return 0;
}

static int write_bad(const char* kind, const char* path)
{
    enum { W = 4, H = 3, N = W * H };
    float r[N], g[N], b[N], a[N];
    for (int i = 0; i < N; ++i) r[i] = 0.5f, g[i] = 0.25f, b[i] = 2.0f, a[i] = 0.75f;
    if (!strcmp(kind, "nan")) g[5] = NAN;
    else if (!strcmp(kind, "inf")) b[7] = INFINITY;
    else if (!strcmp(kind, "negative")) r[2] = -0.125f;
    else if (!strcmp(kind, "alpha")) a[9] = 1.5f;
    else if (strcmp(kind, "none") != 0) {
        fprintf(stderr, "exr_stats: --write-bad: unknown kind '%s'\n", kind);
        return 2;
    }
    const char* names[4] = {"R", "G", "B", "A"};
    const float* planes[4] = {r, g, b, a};
    veil_error err = {0};
    if (veil_write_exr_planes(path, W, H, 4, names, planes, &err) != VEIL_OK) {
        fprintf(stderr, "exr_stats: %s\n", err.msg);
        return 2;
    }
    return 0;
}

int main(int argc, char** argv)
{
    if (argc == 2) return exr_check(argv[1], 0);
    if (argc == 3 && !strcmp(argv[1], "--rgba")) return exr_check(argv[2], 1);
    if (argc == 5 && !strcmp(argv[1], "--png")) return png_check(argv[2], atoi(argv[3]), atoi(argv[4]));
    if (argc == 4 && !strcmp(argv[1], "--write-bad")) return write_bad(argv[2], argv[3]);
    if (argc == 4 && !strcmp(argv[1], "--extent")) return extent(argv[2], atof(argv[3]));
    fprintf(stderr, "usage: exr_stats [--rgba] FILE.exr | --png FILE.png W H | --write-bad KIND FILE.exr | "
                    "--extent FILE.exr T\n");
    return 2;
}
