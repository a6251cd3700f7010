/* veil — the 8-bit sRGB PNG preview (libpng), and its tone curve.
 *
 * Each channel: v = srgb_encode(tonemap(linear * 2^exposure)), stored as
 * round(v * 255). RGB only; the file carries an sRGB chunk (with the matching
 * gAMA and cHRM for older readers). Written to a temporary file beside the
 * target and renamed into place only when everything succeeded.
 * veil_write_png_rgb8 writes bytes that are already encoded (a heatmap's
 * colours) the same way.
 */
#define _POSIX_C_SOURCE 200809L

#include "image.h"
#include "tempfile.h"

#include <png.h>

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

float veil_tonemap(float x)
{
    if (!(x >= 0.0f)) return 0.0f; /* NaN and negatives */
    if (isinf(x)) return 1.0f;
    return x / (1.0f + x);
}

float veil_srgb_encode(float linear)
{
    if (!(linear > 0.0f)) return 0.0f; /* NaN, zero and negatives */
    if (linear >= 1.0f) return 1.0f;
    const double l = linear;
    double v = l < 0.0031308 ? 12.92 * l : 1.055 * pow(l, 1.0 / 2.4) - 0.055;
    if (v < 0.0) v = 0.0;
    if (v > 1.0) v = 1.0;
    return (float)v;
}

static unsigned char encode_channel(float linear, float scale)
{
    float v = veil_srgb_encode(veil_tonemap(linear * scale));
    return (unsigned char)floorf(v * 255.0f + 0.5f);
}

typedef struct png_msg {
    char text[512];
} png_msg;

static void on_png_error(png_structp png, png_const_charp msg)
{
    png_msg* m = png_get_error_ptr(png);
    if (m) snprintf(m->text, sizeof m->text, "%s", msg && *msg ? msg : "unknown libpng error");
    png_longjmp(png, 1);
}

static void on_png_warning(png_structp png, png_const_charp msg)
{
    (void)png; /* the library never prints */
    (void)msg;
}

/* libpng's own stdio writer reports only "Write Error"; this one says why. */
static void write_data(png_structp png, png_bytep data, size_t length)
{
    FILE* fp = png_get_io_ptr(png);
    if (fwrite(data, 1, length, fp) != length) {
        char text[256];
        snprintf(text, sizeof text, "write failed: %s", strerror(errno));
        png_error(png, text);
    }
}

static void flush_data(png_structp png)
{
    FILE* fp = png_get_io_ptr(png);
    if (fflush(fp) != 0) {
        char text[256];
        snprintf(text, sizeof text, "write failed: %s", strerror(errno));
        png_error(png, text);
    }
}

/* The preview is tone-mapped into 8-bit sRGB bytes first, then written by
 * veil_write_png_rgb8 (one PNG writer, one temp-file-and-rename path). */
veil_result veil_write_png(const char* path, int width, int height, const float* rgba, float exposure,
                           veil_error* err)
{
    if (!path || !*path) return veil_fail(err, VEIL_ERR_INVALID, "veil_write_png: no output path given");
    if (width <= 0 || height <= 0)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: invalid image size %dx%d (width and height must be positive)",
                         path, width, height);
    size_t bytes = 0;
    if (!veil_mul_sizes((size_t)width, (size_t)height, 4, sizeof(float), &bytes))
        return veil_fail(err, VEIL_ERR_INVALID, "%s: image size %dx%d is too large", path, width, height);
    if (!rgba) return veil_fail(err, VEIL_ERR_INVALID, "%s: no pixel data given", path);
    size_t n = (size_t)width * (size_t)height;
    unsigned char* rgb = malloc(n * 3);
    if (!rgb) return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory for a %dx%d preview", path, width, height);
    const float scale = exp2f(exposure);
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) rgb[i * 3 + (size_t)c] = encode_channel(rgba[i * 4 + (size_t)c], scale);
    veil_result r = veil_write_png_rgb8(path, width, height, rgb, err);
    free(rgb);
    return r;
}

/* Everything libpng may longjmp out of lives here; nothing that is modified
 * after setjmp is read after the jump. Rows of bytes are stored as given.
 * Returns 1 on success. */
static int encode_png_rgb8(FILE* fp, int width, int height, const unsigned char* rgb, png_msg* msg)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, msg, on_png_error, on_png_warning);
    if (!png) {
        snprintf(msg->text, sizeof msg->text, "cannot create the libpng write structure");
        return 0;
    }
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, NULL);
        snprintf(msg->text, sizeof msg->text, "cannot create the libpng info structure");
        return 0;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return 0;
    }
    png_set_write_fn(png, fp, write_data, flush_data);
    png_set_user_limits(png, 0x7fffffffu, 0x7fffffffu);
    png_set_IHDR(png, info, (png_uint_32)width, (png_uint_32)height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    for (int y = 0; y < height; ++y) png_write_row(png, rgb + (size_t)y * (size_t)width * 3);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    return 1;
}

veil_result veil_write_png_rgb8(const char* path, int width, int height, const unsigned char* rgb, veil_error* err)
{
    if (!path || !*path) return veil_fail(err, VEIL_ERR_INVALID, "veil_write_png_rgb8: no output path given");
    if (width <= 0 || height <= 0)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: invalid image size %dx%d (width and height must be positive)",
                         path, width, height);
    size_t bytes = 0;
    if (!veil_mul_sizes((size_t)width, (size_t)height, 3, 1, &bytes))
        return veil_fail(err, VEIL_ERR_INVALID, "%s: image size %dx%d is too large", path, width, height);
    if (!rgb) return veil_fail(err, VEIL_ERR_INVALID, "%s: no pixel data given", path);

    char* tmp = NULL;
    int fd = veil_open_temp_beside(path, &tmp);
    if (fd < 0) {
        int e = errno;
        if (e == 0)
            return veil_fail(err, VEIL_ERR_IO, "%s: exists and is not a regular file; not replacing it", path);
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot create a temporary file beside it: %s", path, strerror(e));
    }
    FILE* fp = fdopen(fd, "wb");
    if (!fp) {
        int e = errno;
        close(fd);
        unlink(tmp);
        veil_temp_forget(tmp);
        free(tmp);
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot open a stream on the temporary file: %s", path, strerror(e));
    }

    png_msg msg = {{0}};
    veil_result result = VEIL_OK;
    if (!encode_png_rgb8(fp, width, height, rgb, &msg)) {
        fclose(fp);
        result = veil_fail(err, VEIL_ERR_IO, "%s: cannot write PNG: %s", path, msg.text);
    } else {
        int failed = fflush(fp) != 0 || ferror(fp);
        int e = errno;
        if (fclose(fp) != 0 && !failed) {
            failed = 1;
            e = errno;
        }
        if (failed)
            result = veil_fail(err, VEIL_ERR_IO, "%s: cannot write PNG: writing %s failed: %s", path, tmp,
                               strerror(e));
        else if (rename(tmp, path) != 0)
            result = veil_fail(err, VEIL_ERR_IO, "%s: cannot move the temporary file %s into place: %s", path, tmp,
                               strerror(errno));
    }
    if (result != VEIL_OK) unlink(tmp);
    veil_temp_forget(tmp);
    free(tmp);
    return result;
}
