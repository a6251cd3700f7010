/* Tests for reference/compare.c (the metrics of `veil compare` and its
 * heatmap colour map) and io/png.c's veil_write_png_rgb8. Expected values
 * are worked out here from the definitions in compare.h, not by calling
 * the code under test twice. */
#define _POSIX_C_SOURCE 200809L

#include "support/check.h"
#include "io/image.h"
#include "reference/compare.h"
#include "support/temp_files.h"

#include <float.h>
#include <png.h>

/* An RGBA image with a smooth, strictly positive RGB ramp in [0.2, 2.0]
 * and alpha 1: every value far above the default floor. */
static float* make_ramp(int w, int h)
{
    float* p = malloc((size_t)w * (size_t)h * 4 * sizeof *p);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* q = p + ((size_t)y * (size_t)w + (size_t)x) * 4;
            q[0] = 0.2f + 1.8f * (float)x / (float)(w - 1);
            q[1] = 0.2f + 1.8f * (float)y / (float)(h - 1);
            q[2] = 0.2f + 0.9f * (float)(x + y) / (float)(w + h - 2);
            q[3] = 1.0f;
        }
    return p;
}

static float* copy_image(const float* src, int w, int h)
{
    size_t n = (size_t)w * (size_t)h * 4 * sizeof *src;
    float* p = malloc(n);
    memcpy(p, src, n);
    return p;
}

/* The mean and the largest |RGB| of an image, and the mean of squares. */
static void rgb_moments(const float* p, int w, int h, double* mean, double* peak, double* mean_sq)
{
    double s = 0, s2 = 0, m = 0;
    size_t n = (size_t)w * (size_t)h;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            double v = fabs((double)p[i * 4 + (size_t)c]);
            s += v;
            s2 += v * v;
            if (v > m) m = v;
        }
    *mean = s / (3.0 * (double)n);
    *mean_sq = s2 / (3.0 * (double)n);
    *peak = m;
}

static void test_identical(void)
{
    const int w = 9, h = 7;
    float* ref = make_ramp(w, h);
    float* img = copy_image(ref, w, h);
    float rel[9 * 7];
    for (int i = 0; i < w * h; ++i) rel[i] = -1.0f;
    veil_compare_stats st;
    veil_error err = {0};
    veil_result r = veil_compare_images(img, ref, w, h, 0.0, &st, rel, &err);
    CHECK(r == VEIL_OK, "identical: %s", err.msg);
    double mean, peak, mean_sq;
    rgb_moments(ref, w, h, &mean, &peak, &mean_sq);
    CHECK(st.width == w && st.height == h, "size %dx%d", st.width, st.height);
    CHECK(check_close(st.floor, 0.01 * mean, 0, 1e-12), "default floor %.17g, expected 1%% of mean %.17g", st.floor,
          mean);
    CHECK(st.rel_rmse == 0.0, "rel_rmse %g", st.rel_rmse);
    CHECK(st.rmse == 0.0, "rmse %g", st.rmse);
    CHECK(st.max_abs == 0.0, "max_abs %g", st.max_abs);
    CHECK(st.frac_off == 0.0, "frac_off %g", st.frac_off);
    CHECK(isinf(st.psnr_db) && st.psnr_db > 0, "psnr %g, expected +inf", st.psnr_db);
    CHECK(st.alpha_max_abs == 0.0, "alpha_max_abs %g", st.alpha_max_abs);
    int zero = 1;
    for (int i = 0; i < w * h; ++i) zero = zero && rel[i] == 0.0f;
    CHECK(zero, "per-pixel relative errors of identical images are not all 0");

    /* alpha alone differs: RGB metrics stay 0, PSNR infinite */
    img[(3 * w + 2) * 4 + 3] = 0.375f;
    r = veil_compare_images(img, ref, w, h, 0.0, &st, NULL, &err);
    CHECK(r == VEIL_OK, "alpha: %s", err.msg);
    CHECK(st.alpha_max_abs == 0.625, "alpha_max_abs %.17g, expected 0.625", st.alpha_max_abs);
    CHECK(st.rel_rmse == 0.0 && st.max_abs == 0.0 && st.frac_off == 0.0, "alpha leaked into RGB metrics");
    CHECK(isinf(st.psnr_db), "psnr %g with identical RGB", st.psnr_db);
    free(img);
    free(ref);
}

/* image = reference * k: every relative error |k - 1| (up to float rounding
 * of the product), absolute errors |k - 1| |b|. */
static void test_scaled(double k, int expect_off)
{
    const int w = 16, h = 11;
    float* ref = make_ramp(w, h);
    float* img = copy_image(ref, w, h);
    for (int i = 0; i < w * h * 4; ++i)
        if (i % 4 != 3) img[i] = (float)(k * (double)ref[i]);
    float* rel = malloc((size_t)w * (size_t)h * sizeof *rel);
    veil_compare_stats st;
    veil_error err = {0};
    veil_result r = veil_compare_images(img, ref, w, h, 0.0, &st, rel, &err);
    CHECK(r == VEIL_OK, "scaled %g: %s", k, err.msg);
    double mean, peak, mean_sq;
    rgb_moments(ref, w, h, &mean, &peak, &mean_sq);
    /* k*b rounded to float is off by at most 2^-24 k|b|: relative to the
     * error e|b|, 2^-24 k / e (and the float per-pixel error adds 2^-24) */
    const double e = fabs(k - 1.0), tol = 2.0 * 0x1p-24 * k / e;
    CHECK(check_close(st.rel_rmse, e, 0, tol), "scaled %g: rel_rmse %.9g, expected %.9g", k, st.rel_rmse, e);
    CHECK(check_close(st.rmse, e * sqrt(mean_sq), 0, tol), "scaled %g: rmse %.9g, expected %.9g", k, st.rmse,
          e * sqrt(mean_sq));
    CHECK(check_close(st.max_abs, e * peak, 0, tol), "scaled %g: max_abs %.9g, expected %.9g", k, st.max_abs,
          e * peak);
    double psnr = 10.0 * log10(peak * peak / (e * e * mean_sq));
    CHECK(check_close(st.psnr_db, psnr, 1e-5, 0), "scaled %g: psnr %.9g, expected %.9g", k, st.psnr_db, psnr);
    CHECK(st.frac_off == (expect_off ? 1.0 : 0.0), "scaled %g: frac_off %g, expected %d", k, st.frac_off,
          expect_off);
    int all = 1;
    for (int i = 0; i < w * h; ++i) all = all && check_close(rel[i], e, 0, tol);
    CHECK(all, "scaled %g: per-pixel relative errors are not all %g", k, e);
    free(rel);
    free(img);
    free(ref);
}

/* One channel of one pixel changed by an exactly representable amount. */
static void test_one_pixel(void)
{
    const int w = 7, h = 5, n = w * h;
    float ref[7 * 5 * 4], img[7 * 5 * 4], rel[7 * 5];
    for (int i = 0; i < n * 4; ++i) ref[i] = img[i] = 0.5f;
    const int px = 4, py = 3, idx = py * w + px;
    img[idx * 4 + 1] = 0.625f; /* G up by 0.125 */
    veil_compare_stats st;
    veil_error err = {0};
    veil_result r = veil_compare_images(img, ref, w, h, 0.0, &st, rel, &err);
    CHECK(r == VEIL_OK, "one pixel: %s", err.msg);
    CHECK(st.floor == 0.005, "floor %.17g, expected 0.005", st.floor);
    CHECK(st.max_abs == 0.125, "max_abs %.17g, expected 0.125", st.max_abs);
    CHECK(st.frac_off == 1.0 / n, "frac_off %.17g, expected 1/%d", st.frac_off, n);
    CHECK(check_close(st.rmse, sqrt(0.125 * 0.125 / (3.0 * n)), 0, 1e-15), "rmse %.17g", st.rmse);
    CHECK(check_close(st.rel_rmse, sqrt(0.25 * 0.25 / (3.0 * n)), 0, 1e-15), "rel_rmse %.17g", st.rel_rmse);
    double psnr = 10.0 * log10(0.5 * 0.5 / (0.125 * 0.125 / (3.0 * n)));
    CHECK(check_close(st.psnr_db, psnr, 1e-12, 0), "psnr %.17g, expected %.17g", st.psnr_db, psnr);
    int others = 1;
    for (int i = 0; i < n; ++i) others = others && (i == idx || rel[i] == 0.0f);
    CHECK(rel[idx] == 0.25f && others, "per-pixel relative error %g at (%d, %d), others 0", rel[idx], px, py);

    /* a 4 % change is not "off", a 6 % change is (strictly more than 5 %) */
    img[idx * 4 + 1] = 0.52f;
    r = veil_compare_images(img, ref, w, h, 0.0, &st, NULL, &err);
    CHECK(r == VEIL_OK && st.frac_off == 0.0, "4%% off counted: frac_off %g", st.frac_off);
    img[idx * 4 + 1] = 0.53f;
    r = veil_compare_images(img, ref, w, h, 0.0, &st, NULL, &err);
    CHECK(r == VEIL_OK && st.frac_off == 1.0 / n, "6%% off not counted: frac_off %g", st.frac_off);
}

/* Black reference pixels: the denominator is the floor, not 0. */
static void test_floor(void)
{
    /* four pixels, the second black: mean |RGB| = 9/12, default floor 0.0075 */
    float ref[16] = {1, 1, 1, 1, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1};
    float img[16];
    memcpy(img, ref, sizeof img);
    img[4] = 0.003f; /* R of the black pixel */
    float rel[4];
    veil_compare_stats st;
    veil_error err = {0};
    veil_result r = veil_compare_images(img, ref, 4, 1, 0.0, &st, rel, &err);
    CHECK(r == VEIL_OK, "floor: %s", err.msg);
    CHECK(check_close(st.floor, 0.0075, 0, 1e-15), "default floor %.17g, expected 0.0075", st.floor);
    const double e = (double)0.003f / 0.0075;
    CHECK(check_close(rel[1], e, 0, 1e-7), "relative error on black %.9g, expected %.9g", rel[1], e);
    CHECK(check_close(st.rel_rmse, sqrt(e * e / 12.0), 0, 1e-12), "rel_rmse %.17g", st.rel_rmse);
    CHECK(st.frac_off == 0.25, "frac_off %g, expected 0.25", st.frac_off);

    /* a given floor replaces the default, and applies where |b| is below it */
    r = veil_compare_images(img, ref, 4, 1, 0.03, &st, rel, &err);
    CHECK(r == VEIL_OK && st.floor == 0.03, "given floor %.17g, expected 0.03", st.floor);
    CHECK(check_close(rel[1], (double)0.003f / 0.03, 0, 1e-7), "relative error %.9g with floor 0.03", rel[1]);
    CHECK(st.frac_off == 0.25, "frac_off %g with floor 0.03 (10%% off)", st.frac_off);
    img[4] = 0.0f;
    img[0] = 1.5f; /* R of pixel 0: |b| = 1 is below a floor of 2 */
    r = veil_compare_images(img, ref, 4, 1, 2.0, &st, rel, &err);
    CHECK(r == VEIL_OK && check_close(rel[0], 0.25, 0, 1e-15), "floor above |b|: relative error %g, expected 0.25",
          rel[0]);

    /* a floor below the least is raised to it; NaN and inf are refused */
    r = veil_compare_images(img, ref, 4, 1, 1e-300, &st, NULL, &err);
    CHECK(r == VEIL_OK && st.floor == VEIL_COMPARE_TINY_FLOOR, "floor 1e-300 became %g", st.floor);
    CHECK(veil_compare_images(img, ref, 4, 1, NAN, &st, NULL, &err) == VEIL_ERR_INVALID, "NaN floor accepted");
    CHECK(veil_compare_images(img, ref, 4, 1, INFINITY, &st, NULL, &err) == VEIL_ERR_INVALID, "inf floor accepted");

    /* an all-black reference: the tiny floor, and PSNR against a peak of 1 */
    float black[16] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    float dim[16];
    memcpy(dim, black, sizeof dim);
    r = veil_compare_images(dim, black, 4, 1, 0.0, &st, rel, &err);
    CHECK(r == VEIL_OK && st.floor == VEIL_COMPARE_TINY_FLOOR, "all black: floor %g", st.floor);
    CHECK(st.rel_rmse == 0.0 && isinf(st.psnr_db), "all black, identical: rel_rmse %g psnr %g", st.rel_rmse,
          st.psnr_db);
    dim[6] = 1e-6f;
    r = veil_compare_images(dim, black, 4, 1, 0.0, &st, rel, &err);
    double d = (double)1e-6f, psnr = 10.0 * log10(1.0 / (d * d / 12.0));
    CHECK(r == VEIL_OK && check_close(st.psnr_db, psnr, 1e-9, 0), "all black: psnr %.17g, expected %.17g",
          st.psnr_db, psnr);
    CHECK(check_close(rel[1], d / VEIL_COMPARE_TINY_FLOOR, 0, 1e-7), "all black: relative error %g", rel[1]);
    CHECK(isfinite(st.rel_rmse) && st.frac_off == 0.25, "all black: rel_rmse %g frac_off %g", st.rel_rmse,
          st.frac_off);
}

static int has(const char* msg, const char* what)
{
    return strstr(msg, what) != NULL;
}

static void test_non_finite(void)
{
    const int w = 5, h = 4;
    float* ref = make_ramp(w, h);
    float* img = copy_image(ref, w, h);
    veil_compare_stats st = {.rel_rmse = 42.0};
    veil_error err = {0};

    img[(1 * w + 2) * 4 + 1] = NAN;
    veil_result r = veil_compare_images(img, ref, w, h, 0.0, &st, NULL, &err);
    CHECK(r == VEIL_ERR_INVALID, "NaN in image: result %d", r);
    CHECK(has(err.msg, "image") && !has(err.msg, "reference") && has(err.msg, "(2, 1)") &&
              has(err.msg, "channel G"),
          "NaN in image: '%s'", err.msg);
    CHECK(st.rel_rmse == 42.0, "the stats were written on failure");

    /* an earlier pixel of the reference is named first (row order) */
    ref[(0 * w + 4) * 4 + 3] = INFINITY;
    memset(&err, 0, sizeof err);
    r = veil_compare_images(img, ref, w, h, 0.0, &st, NULL, &err);
    CHECK(r == VEIL_ERR_INVALID && has(err.msg, "reference") && has(err.msg, "(4, 0)") && has(err.msg, "channel A"),
          "inf alpha in reference: '%s'", err.msg);

    /* at the same pixel, the image is named before the reference */
    ref[(0 * w + 4) * 4 + 3] = 1.0f;
    ref[(1 * w + 2) * 4 + 0] = -INFINITY;
    memset(&err, 0, sizeof err);
    r = veil_compare_images(img, ref, w, h, 0.0, &st, NULL, &err);
    CHECK(r == VEIL_ERR_INVALID && has(err.msg, "image") && has(err.msg, "(2, 1)"), "both at (2, 1): '%s'",
          err.msg);

    /* bad arguments */
    CHECK(veil_compare_images(ref, ref, 0, h, 0.0, &st, NULL, &err) == VEIL_ERR_INVALID, "width 0 accepted");
    CHECK(veil_compare_images(NULL, ref, w, h, 0.0, &st, NULL, &err) == VEIL_ERR_INVALID, "NULL image accepted");
    CHECK(veil_compare_images(ref, ref, w, h, 0.0, NULL, NULL, &err) == VEIL_ERR_INVALID, "NULL output accepted");
    free(img);
    free(ref);
}

/* Any finite inputs, extremes included: every number finite but PSNR,
 * which is never NaN. */
static void test_random_extremes(void)
{
    const int w = 13, h = 9, n = w * h;
    float a[13 * 9 * 4], b[13 * 9 * 4], rel[13 * 9];
    int finite = 1, rel_ok = 1;
    for (int trial = 0; trial < 50; ++trial) {
        for (int i = 0; i < n * 4; ++i) {
            a[i] = random_finite();
            b[i] = random_finite();
        }
        if (trial == 0) a[0] = FLT_MAX, b[0] = -FLT_MAX;
        veil_compare_stats st;
        veil_error err = {0};
        veil_result r = veil_compare_images(a, b, w, h, 0.0, &st, rel, &err);
        finite = finite && r == VEIL_OK && isfinite(st.floor) && isfinite(st.rel_rmse) && isfinite(st.rmse) &&
                 isfinite(st.max_abs) && isfinite(st.frac_off) && !isnan(st.psnr_db) && isfinite(st.alpha_max_abs);
        for (int i = 0; i < n; ++i) rel_ok = rel_ok && isfinite(rel[i]) && rel[i] >= 0.0f;
    }
    CHECK(finite, "a non-finite metric from finite inputs");
    CHECK(rel_ok, "a non-finite or negative per-pixel relative error");
}

static double srgb_decode(unsigned char v)
{
    double s = v / 255.0;
    return s <= 0.04045 ? s / 12.92 : pow((s + 0.055) / 1.055, 2.4);
}

static double luminance(const unsigned char c[3])
{
    return 0.2126 * srgb_decode(c[0]) + 0.7152 * srgb_decode(c[1]) + 0.0722 * srgb_decode(c[2]);
}

static int colour_is(double rel, int r, int g, int b)
{
    unsigned char c[3];
    veil_compare_heatmap_colour(rel, c);
    if (c[0] == r && c[1] == g && c[2] == b) return 1;
    fprintf(stderr, "colour of %g: (%d, %d, %d), expected (%d, %d, %d)\n", rel, c[0], c[1], c[2], r, g, b);
    return 0;
}

static void test_heatmap_colour(void)
{
    CHECK(colour_is(0.0, 0, 0, 0), "0 is not black");
    CHECK(colour_is(-1.0, 0, 0, 0), "-1 is not black");
    CHECK(colour_is(1e-5, 0, 0, 0), "1e-5 is not black");
    CHECK(colour_is(1e-4, 0, 0, 0), "1e-4 is not black");
    CHECK(colour_is(1e-3, 0, 0, 255), "1e-3 is not blue");
    CHECK(colour_is(1e-2, 255, 0, 255), "1e-2 is not magenta");
    CHECK(colour_is(1e-1, 255, 255, 0), "1e-1 is not yellow");
    CHECK(colour_is(1.0, 255, 255, 255), "1 is not white");
    CHECK(colour_is(1e30, 255, 255, 255), "1e30 is not white");
    CHECK(colour_is(INFINITY, 255, 255, 255), "inf is not white");
    CHECK(colour_is(NAN, 255, 255, 255), "NaN is not white");

    /* luminance rises with the error: never falls by more than one 8-bit
     * step of blue (the channel that falls between magenta and yellow), and
     * rises strictly from each tenth of a decade to the next */
    const int steps = 4000;
    double prev = -1.0, prev_tenth = -1.0;
    int monotone = 1, strict = 1;
    for (int i = 0; i <= steps; ++i) {
        double rel = pow(10.0, -4.0 + 4.0 * i / steps);
        unsigned char c[3];
        veil_compare_heatmap_colour(rel, c);
        double y = luminance(c);
        if (y < prev - 0.0722 * (srgb_decode(255) - srgb_decode(254))) {
            monotone = 0;
            fprintf(stderr, "luminance falls at %g: %g after %g\n", rel, y, prev);
        }
        prev = y;
        if (i % (steps / 40) == 0) {
            if (i > 0 && !(y > prev_tenth)) strict = 0;
            prev_tenth = y;
        }
    }
    CHECK(monotone, "heatmap luminance is not monotone");
    CHECK(strict, "heatmap luminance does not rise from one tenth of a decade to the next");
}

static void test_png_rgb8(void)
{
    if (!test_dir_begin("compare")) {
        CHECK(0, "no temporary folder");
        return;
    }
    const int w = 3, h = 2;
    const unsigned char rgb[18] = {0, 0, 0, 255, 0, 255, 1, 2, 3, 255, 255, 255, 10, 200, 30, 128, 64, 32};
    char path[256];
    path_in(path, sizeof path, "heat.png");
    veil_error err = {0};
    veil_result r = veil_write_png_rgb8(path, w, h, rgb, &err);
    CHECK(r == VEIL_OK, "write: %s", err.msg);
    png_image im;
    memset(&im, 0, sizeof im);
    im.version = PNG_IMAGE_VERSION;
    unsigned char back[18] = {0};
    int ok = png_image_begin_read_from_file(&im, path);
    CHECK(ok && im.width == (png_uint_32)w && im.height == (png_uint_32)h, "read back: %s %ux%u", im.message,
          im.width, im.height);
    if (ok) {
        im.format = PNG_FORMAT_RGB;
        ok = png_image_finish_read(&im, NULL, back, w * 3, NULL);
        CHECK(ok && memcmp(back, rgb, sizeof rgb) == 0, "bytes changed in the round trip: %s", im.message);
    }
    png_image_free(&im);
    unlink(path);

    /* failures leave nothing: a missing folder, a folder in the way */
    char missing[256], dir[256];
    path_in(missing, sizeof missing, "no/such/heat.png");
    r = veil_write_png_rgb8(missing, w, h, rgb, &err);
    CHECK(r == VEIL_ERR_IO && has(err.msg, missing), "missing folder: %d '%s'", r, err.msg);
    path_in(dir, sizeof dir, "adir");
    mkdir(dir, 0777);
    r = veil_write_png_rgb8(dir, w, h, rgb, &err);
    CHECK(r == VEIL_ERR_IO && has(err.msg, "not a regular file"), "folder in the way: %d '%s'", r, err.msg);
    int temps = 0;
    CHECK(count_entries(g_dir, &temps) == 1 && temps == 0, "files left behind");
    rmdir(dir);
    CHECK(veil_write_png_rgb8(path, 0, h, rgb, &err) == VEIL_ERR_INVALID, "width 0 accepted");
    CHECK(!file_exists(path), "a file written for width 0");
    CHECK(test_dir_end(), "temporary folder not clean");
}

int main(void)
{
    test_identical();
    test_scaled(1.1, 1);
    test_scaled(1.04, 0);
    test_scaled(0.94, 1);
    test_one_pixel();
    test_floor();
    test_non_finite();
    test_random_extremes();
    test_heatmap_colour();
    test_png_rgb8();
    return check_finish();
}
