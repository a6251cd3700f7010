/* veil — image comparison metrics (see compare.h for the definitions). */
#include "compare.h"

#include "../io/image.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

static const char* const channel_names[4] = {"R", "G", "B", "A"};

/* The first non-finite value in row order, image before reference at the
 * same pixel: VEIL_ERR_INVALID naming it, or VEIL_OK. */
static veil_result check_finite(const float* a, const float* b, int width, int height, veil_error* err)
{
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            size_t p = ((size_t)y * (size_t)width + (size_t)x) * 4;
            for (int which = 0; which < 2; ++which) {
                const float* px = (which ? b : a) + p;
                for (int c = 0; c < 4; ++c) {
                    if (isfinite(px[c])) continue;
                    char got[32];
                    return veil_fail(err, VEIL_ERR_INVALID,
                                     "%s has a non-finite value (%s) at pixel (%d, %d) channel %s",
                                     which ? "reference" : "image", veil_number_text(px[c], got, sizeof got), x, y,
                                     channel_names[c]);
                }
            }
        }
    }
    return VEIL_OK;
}

veil_result veil_compare_images(const float* a, const float* b, int width, int height, double floor,
                                veil_compare_stats* out, float* rel_err, veil_error* err)
{
    if (!a || !b || !out) return veil_fail(err, VEIL_ERR_INVALID, "veil_compare_images: missing image or output");
    if (width <= 0 || height <= 0)
        return veil_fail(err, VEIL_ERR_INVALID,
                         "veil_compare_images: invalid image size %dx%d (width and height must be positive)", width,
                         height);
    size_t bytes = 0;
    if (!veil_mul_sizes((size_t)width, (size_t)height, 4, sizeof(float), &bytes))
        return veil_fail(err, VEIL_ERR_LIMIT, "veil_compare_images: image size %dx%d is too large", width, height);
    if (isnan(floor) || isinf(floor))
        return veil_fail(err, VEIL_ERR_INVALID, "veil_compare_images: floor %g is not a finite number", floor);
    veil_result r = check_finite(a, b, width, height, err);
    if (r != VEIL_OK) return r;

    const size_t pixels = (size_t)width * (size_t)height;
    const double values = 3.0 * (double)pixels;

    /* The reference's mean |RGB| (the default floor) and peak (for PSNR). */
    double sum_ref = 0.0, peak = 0.0;
    for (size_t i = 0; i < pixels; ++i) {
        for (int c = 0; c < 3; ++c) {
            double v = fabs((double)b[i * 4 + (size_t)c]);
            sum_ref += v;
            if (v > peak) peak = v;
        }
    }
    if (!(floor > 0.0)) floor = VEIL_COMPARE_FLOOR_FRACTION * (sum_ref / values);
    if (floor < VEIL_COMPARE_TINY_FLOOR) floor = VEIL_COMPARE_TINY_FLOOR; /* all black; keeps ratios finite */
    if (!(peak > 0.0)) peak = 1.0; /* all-black reference: PSNR against a unit peak */

    double sum_sq = 0.0, sum_rel_sq = 0.0, max_abs = 0.0, alpha_max = 0.0;
    size_t off = 0;
    for (size_t i = 0; i < pixels; ++i) {
        const float* pa = a + i * 4;
        const float* pb = b + i * 4;
        double pixel_rel = 0.0;
        for (int c = 0; c < 3; ++c) {
            double d = fabs((double)pa[c] - (double)pb[c]);
            double ref = fabs((double)pb[c]);
            double rel = d / (ref > floor ? ref : floor);
            sum_sq += d * d;
            sum_rel_sq += rel * rel;
            if (d > max_abs) max_abs = d;
            if (rel > pixel_rel) pixel_rel = rel;
        }
        double da = fabs((double)pa[3] - (double)pb[3]);
        if (da > alpha_max) alpha_max = da;
        if (pixel_rel > VEIL_COMPARE_OFF_FRACTION) ++off;
        if (rel_err) rel_err[i] = pixel_rel < FLT_MAX ? (float)pixel_rel : FLT_MAX;
    }

    const double mse = sum_sq / values;
    out->width = width;
    out->height = height;
    out->floor = floor;
    out->rel_rmse = sqrt(sum_rel_sq / values);
    out->rmse = sqrt(mse);
    out->max_abs = max_abs;
    out->frac_off = (double)off / (double)pixels;
    out->psnr_db = mse > 0.0 ? 10.0 * log10(peak * peak / mse) : INFINITY;
    out->alpha_max_abs = alpha_max;
    return VEIL_OK;
}

/* The colour stops in linear RGB, one a decade of relative error. */
#define HEATMAP_STOPS 5
static const double heatmap_stops[HEATMAP_STOPS][3] = {
    {0.0, 0.0, 0.0}, /* black   1e-4 */
    {0.0, 0.0, 1.0}, /* blue    1e-3 */
    {1.0, 0.0, 1.0}, /* magenta 1e-2 */
    {1.0, 1.0, 0.0}, /* yellow  1e-1 */
    {1.0, 1.0, 1.0}, /* white   1    */
};

void veil_compare_heatmap_colour(double rel, unsigned char rgb[3])
{
    double t; /* position on the scale, 0 (black) .. 1 (white) */
    if (isnan(rel)) t = 1.0;
    else if (!(rel > VEIL_COMPARE_HEATMAP_MIN)) t = 0.0;
    else if (rel >= VEIL_COMPARE_HEATMAP_MAX) t = 1.0;
    else
        t = (log10(rel) - log10(VEIL_COMPARE_HEATMAP_MIN)) /
            (log10(VEIL_COMPARE_HEATMAP_MAX) - log10(VEIL_COMPARE_HEATMAP_MIN));
    double s = t * (HEATMAP_STOPS - 1);
    int k = (int)s;
    if (k > HEATMAP_STOPS - 2) k = HEATMAP_STOPS - 2;
    double f = s - k;
    for (int c = 0; c < 3; ++c) {
        double linear = heatmap_stops[k][c] + f * (heatmap_stops[k + 1][c] - heatmap_stops[k][c]);
        float v = veil_srgb_encode((float)linear);
        rgb[c] = (unsigned char)floorf(v * 255.0f + 0.5f);
    }
}

veil_result veil_compare_bin(const float* rgba, const float* se, int w, int h, int b, float** out, float** se_out,
                             veil_error* err)
{
    *out = NULL;
    if (se_out) *se_out = NULL;
    if (b < 1 || b > w || b > h)
        return veil_fail(err, VEIL_ERR_INVALID, "bin size %d: expected 1..%d (the smaller side)", b, w < h ? w : h);
    int bw = w / b, bh = h / b;
    float* o = malloc((size_t)bw * (size_t)bh * 4 * sizeof *o);
    float* so = se && se_out ? malloc((size_t)bw * (size_t)bh * 3 * sizeof *so) : NULL;
    if (!o || (se && se_out && !so)) {
        free(o);
        free(so);
        return veil_fail(err, VEIL_ERR_OOM, "out of memory binning a %dx%d image", w, h);
    }
    for (int by = 0; by < bh; ++by)
        for (int bx = 0; bx < bw; ++bx) {
            double sum[4] = {0, 0, 0, 0}, var[3] = {0, 0, 0};
            for (int y = by * b; y < (by + 1) * b; ++y)
                for (int x = bx * b; x < (bx + 1) * b; ++x) {
                    size_t i = (size_t)y * (size_t)w + (size_t)x;
                    for (int c = 0; c < 4; ++c) sum[c] += rgba[4 * i + (size_t)c];
                    if (so)
                        for (int c = 0; c < 3; ++c) var[c] += (double)se[3 * i + (size_t)c] * se[3 * i + (size_t)c];
                }
            size_t k = (size_t)by * (size_t)bw + (size_t)bx;
            double n = (double)b * b;
            for (int c = 0; c < 4; ++c) o[4 * k + (size_t)c] = (float)(sum[c] / n);
            if (so)
                for (int c = 0; c < 3; ++c) so[3 * k + (size_t)c] = (float)(sqrt(var[c]) / n);
        }
    *out = o;
    if (se_out) *se_out = so;
    return VEIL_OK;
}

double veil_compare_bias(const float* a, const float* b, int width, int height)
{
    double sa = 0.0, sb = 0.0;
    size_t n = (size_t)width * (size_t)height;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            sa += a[4 * i + (size_t)c];
            sb += b[4 * i + (size_t)c];
        }
    if (sb == 0.0) return sa == 0.0 ? 0.0 : NAN; /* no ratio to an all-black reference: undefined */
    return sa / sb - 1.0;
}

double veil_compare_bias_se(const float* a, const float* b, const float* se, int width, int height)
{
    double sa = 0.0, sb = 0.0, var = 0.0;
    size_t n = (size_t)width * (size_t)height;
    for (size_t i = 0; i < n; ++i) {
        double s = 0.0;
        for (int c = 0; c < 3; ++c) {
            sa += a[4 * i + (size_t)c];
            sb += b[4 * i + (size_t)c];
            s += se[3 * i + (size_t)c];
        }
        var += s * s;
    }
    if (sb == 0.0) return sa == 0.0 ? 0.0 : NAN;
    return sa / sb * sqrt(var) / fabs(sb);
}

double veil_compare_noise(const float* b, const float* se, int width, int height, double floor)
{
    double sum = 0.0;
    size_t n = (size_t)width * (size_t)height;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            double d = fmax(fabs((double)b[4 * i + (size_t)c]), floor);
            double r = se[3 * i + (size_t)c] / d;
            sum += r * r;
        }
    return n ? sqrt(sum / (3.0 * (double)n)) : 0.0;
}
