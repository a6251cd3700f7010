/* Tests for io/png.c: the PNG preview and its tone curve. */
#define _POSIX_C_SOURCE 200809L

#include "support/check.h"
#include "io/image.h"
#include "support/temp_files.h"

#include <openexr.h>
#include <png.h>

#include <float.h>
#include <limits.h>
#include <signal.h>
#include <sys/resource.h>

/* ------------------------------------------------------------------------ */
/* Tone curve */

static double srgb_ref(double l)
{
    if (!(l > 0)) return 0;
    if (l >= 1) return 1;
    return l < 0.0031308 ? 12.92 * l : 1.055 * pow(l, 1 / 2.4) - 0.055;
}

static void test_curves(void)
{
    CHECK(veil_tonemap(0.0f) == 0.0f, "tonemap(0) = %g", veil_tonemap(0.0f));
    CHECK(veil_tonemap(1.0f) == 0.5f, "tonemap(1) = %g", veil_tonemap(1.0f));
    CHECK(check_close(veil_tonemap(3.0f), 0.75, 1e-7, 0), "tonemap(3) = %g", veil_tonemap(3.0f));
    CHECK(check_close(veil_tonemap(1e-30f), 1e-30, 0, 1e-6), "tonemap(1e-30) = %g", veil_tonemap(1e-30f));
    CHECK(veil_tonemap(INFINITY) == 1.0f, "tonemap(inf) = %g", veil_tonemap(INFINITY));
    CHECK(veil_tonemap(FLT_MAX) == 1.0f, "tonemap(FLT_MAX) = %g", veil_tonemap(FLT_MAX));
    CHECK(veil_tonemap(NAN) == 0.0f, "tonemap(NaN) = %g", veil_tonemap(NAN));
    CHECK(veil_tonemap(-1.0f) == 0.0f, "tonemap(-1) = %g", veil_tonemap(-1.0f));
    CHECK(veil_tonemap(-INFINITY) == 0.0f, "tonemap(-inf) = %g", veil_tonemap(-INFINITY));

    CHECK(veil_srgb_encode(0.0f) == 0.0f, "srgb(0) = %g", veil_srgb_encode(0.0f));
    CHECK(veil_srgb_encode(1.0f) == 1.0f, "srgb(1) = %g", veil_srgb_encode(1.0f));
    CHECK(veil_srgb_encode(INFINITY) == 1.0f, "srgb(inf) = %g", veil_srgb_encode(INFINITY));
    CHECK(veil_srgb_encode(2.0f) == 1.0f, "srgb(2) = %g", veil_srgb_encode(2.0f));
    CHECK(veil_srgb_encode(NAN) == 0.0f, "srgb(NaN) = %g", veil_srgb_encode(NAN));
    CHECK(veil_srgb_encode(-0.5f) == 0.0f, "srgb(-0.5) = %g", veil_srgb_encode(-0.5f));
    CHECK(check_close(veil_srgb_encode(0.001f), 0.01292, 1e-7, 0), "srgb(0.001) = %.9g", veil_srgb_encode(0.001f));
    CHECK(check_close(veil_srgb_encode(0.5f), 0.735356983052449, 1e-6, 0), "srgb(0.5) = %.9g",
          veil_srgb_encode(0.5f));
    CHECK(check_close(veil_srgb_encode(0.18f), 0.461356129, 1e-6, 0), "srgb(0.18) = %.9g", veil_srgb_encode(0.18f));

    /* the two pieces meet at 0.0031308 */
    const float edge = 0.0031308f;
    const float below = veil_srgb_encode(nextafterf(edge, 0.0f));
    const float at = veil_srgb_encode(edge);
    const float above = veil_srgb_encode(nextafterf(edge, 1.0f));
    CHECK(fabsf(at - below) < 1e-6f && fabsf(above - at) < 1e-6f, "srgb near 0.0031308: %.9g %.9g %.9g", below, at,
          above);
    /* (the exact IEC pieces differ by ~3e-8 at the joint, so monotonicity is
     * not asked of these three) */
    CHECK(fabs(12.92 * 0.0031308 - (1.055 * pow(0.0031308, 1 / 2.4) - 0.055)) < 1e-6,
          "the pieces of the sRGB curve do not meet");

    /* whole range: monotonic and within float rounding of the definition */
    int mono = 1, close = 1;
    float prev = 0.0f;
    for (int i = 0; i <= 100000; ++i) {
        float x = (float)i / 100000.0f;
        float v = veil_srgb_encode(x);
        if (v < prev) mono = 0;
        if (fabs(v - srgb_ref(x)) > 1e-6) close = 0;
        prev = v;
    }
    CHECK(mono, "srgb_encode is not monotonic on [0, 1]");
    CHECK(close, "srgb_encode differs from IEC 61966-2-1 by more than 1e-6");
}

/* ------------------------------------------------------------------------ */
/* PNG */

/* Chunk types in file order; returns how many (0 when not a PNG). */
static int png_chunks(const unsigned char* b, size_t n, char types[][5], int max, unsigned char* ihdr)
{
    static const unsigned char sig[8] = {137, 80, 78, 71, 13, 10, 26, 10};
    if (n < 8 || memcmp(b, sig, 8) != 0) return 0;
    size_t at = 8;
    int count = 0;
    while (at + 12 <= n && count < max) {
        size_t len = ((size_t)b[at] << 24) | ((size_t)b[at + 1] << 16) | ((size_t)b[at + 2] << 8) | b[at + 3];
        memcpy(types[count], b + at + 4, 4);
        types[count][4] = 0;
        if (strcmp(types[count], "IHDR") == 0 && len == 13 && at + 8 + 13 <= n) memcpy(ihdr, b + at + 8, 13);
        ++count;
        if (len > n - at - 12) break;
        at += 12 + len;
    }
    return count;
}

static void test_png(void)
{
    char path[256];
    path_in(path, sizeof path, "preview.png");
    /* linear inputs and their 8-bit codes at exposure 0, 1 and -2 */
    static const struct {
        float linear;
        unsigned char e0, e1, em2;
    } known[] = {
        {0.0f, 0, 0, 0},       {1.0f, 188, 213, 124},   {3.0f, 225, 238, 175},  {0.01f, 25, 38, 8},
        {0.18f, 109, 141, 59}, {0.001f, 3, 7, 1},       {10.0f, 245, 250, 220}, {1e30f, 255, 255, 255},
        {-1.0f, 0, 0, 0},      {0.5f, 156, 188, 94},    {2.5f, 220, 235, 167},  {0.05f, 62, 85, 29},
    };
    const int nk = (int)(sizeof known / sizeof known[0]);
    const int w = 4, h = 3; /* 12 pixels; channel c of pixel i gets known[(i + 5c) % nk] */
    float px[4 * 3 * 4];
    for (int i = 0; i < w * h; ++i) {
        for (int c = 0; c < 3; ++c) px[i * 4 + c] = known[(i + 5 * c) % nk].linear;
        px[i * 4 + 3] = 0.5f;
    }
    static const float exposures[3] = {0.0f, 1.0f, -2.0f};
    for (int e = 0; e < 3; ++e) {
        veil_error err = {{0}};
        CHECK(veil_write_png(path, w, h, px, exposures[e], &err) == VEIL_OK, "write %s: %s", path, err.msg);
        int temps = 0;
        CHECK(count_entries(g_dir, &temps) == 1 && temps == 0, "after writing %s the directory should hold just it",
              path);

        size_t size = 0;
        unsigned char* bytes = slurp(path, &size);
        char types[16][5];
        unsigned char ihdr[13] = {0};
        int nchunks = bytes ? png_chunks(bytes, size, types, 16, ihdr) : 0;
        CHECK(bytes && size >= 8 && png_sig_cmp(bytes, 0, 8) == 0, "%s lacks the PNG signature", path);
        int srgb = -1, idat = -1;
        for (int i = 0; i < nchunks; ++i) {
            if (srgb < 0 && strcmp(types[i], "sRGB") == 0) srgb = i;
            if (idat < 0 && strcmp(types[i], "IDAT") == 0) idat = i;
        }
        CHECK(srgb > 0 && idat > srgb, "%s: no sRGB chunk before the image data", path);
        CHECK(ihdr[8] == 8 && ihdr[9] == 2, "%s: bit depth %d colour type %d, expected 8-bit RGB", path, ihdr[8],
              ihdr[9]);
        free(bytes);

        png_image image;
        memset(&image, 0, sizeof image);
        image.version = PNG_IMAGE_VERSION;
        int ok = png_image_begin_read_from_file(&image, path);
        CHECK(ok && image.width == (png_uint_32)w && image.height == (png_uint_32)h, "%s: %s (%ux%u)", path,
              image.message, image.width, image.height);
        if (!ok) continue;
        image.format = PNG_FORMAT_RGB;
        unsigned char* rgb = malloc(PNG_IMAGE_SIZE(image));
        ok = png_image_finish_read(&image, NULL, rgb, 0, NULL);
        CHECK(ok, "%s: %s", path, image.message);
        if (ok) {
            int bad = 0;
            for (int i = 0; i < w * h; ++i) {
                for (int c = 0; c < 3; ++c) {
                    int k = (i + 5 * c) % nk;
                    int want = e == 0 ? known[k].e0 : e == 1 ? known[k].e1 : known[k].em2;
                    int got = rgb[i * 3 + c];
                    if (got != want) {
                        if (bad++ < 5)
                            fprintf(stderr, "  exposure %g: linear %g gave %d, expected %d\n", exposures[e],
                                    known[k].linear, got, want);
                    }
                }
            }
            CHECK(bad == 0, "%s at exposure %g: %d pixel values differ", path, exposures[e], bad);
        }
        png_image_free(&image);
        free(rgb);
    }

    /* a ramp: every code equals round(255 * srgb(tonemap(x))) */
    {
        const int rw = 256;
        float* ramp = malloc(sizeof(float) * 4 * rw);
        for (int i = 0; i < rw; ++i)
            for (int c = 0; c < 4; ++c) ramp[i * 4 + c] = (float)i / 32.0f + (float)c * 0.001f;
        veil_error err = {{0}};
        CHECK(veil_write_png(path, rw, 1, ramp, 0.0f, &err) == VEIL_OK, "write ramp: %s", err.msg);
        png_image image;
        memset(&image, 0, sizeof image);
        image.version = PNG_IMAGE_VERSION;
        unsigned char rgb[256 * 3];
        int ok = png_image_begin_read_from_file(&image, path);
        if (ok) {
            image.format = PNG_FORMAT_RGB;
            ok = image.width == (png_uint_32)rw && image.height == 1 &&
                 png_image_finish_read(&image, NULL, rgb, 0, NULL);
        }
        int bad = 0;
        for (int i = 0; ok && i < rw; ++i)
            for (int c = 0; c < 3; ++c) {
                double v = 255.0 * srgb_ref(veil_tonemap(ramp[i * 4 + c]));
                if (fabs(rgb[i * 3 + c] - v) > 0.5 + 1e-3) ++bad;
            }
        CHECK(ok && bad == 0, "ramp: %d codes are not the rounded curve (%s)", bad, image.message);
        png_image_free(&image);
        free(ramp);
    }
    unlink(path);
}

int main(void)
{
    if (!test_dir_begin("test_png")) return 1;
    test_curves();
    test_png();
    CHECK(test_dir_end(), "the test folder %s was not left empty", g_dir);
    return check_finish();
}
