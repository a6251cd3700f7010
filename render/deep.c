#include "deep.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/clock.h"
#include "../core/progress.h"
#include "../core/shared.glsl.h"

_Static_assert(VEIL_DEEP_SAMPLE_FLOATS == VEIL_DEEP_CHANNELS, "the march's deep samples are io/exr_deep.h's");
_Static_assert(VEIL_DEEP_MAX_RAW >= VEIL_DEEP_MAX_SAMPLES, "a cap's raw samples are at least the cap");

enum { F = VEIL_DEEP_CHANNELS };

double veil_deep_bytes(int width, int height, int cap)
{
    const double raw = veil_deep_raw_samples(cap) * (double)VEIL_DEEP_CHANNELS * sizeof(float);
    return (double)width * (double)height * (raw + sizeof(uint32_t) + VEIL_DEEP_WRITER_BYTES);
}

int veil_deep_raw_samples(int cap)
{
    if (cap < 1) cap = 1;
    long r = (long)cap * VEIL_DEEP_RAW_FACTOR;
    if (r > VEIL_DEEP_MAX_RAW) r = VEIL_DEEP_MAX_RAW;
    return r < cap ? cap : (int)r;
}

veil_result veil_deep_append_band(veil_deep_image* d, int first_row, int rows, int R, const uint32_t* counts,
                                  const float* samples, veil_error* err)
{
    const size_t w = (size_t)d->width, pixels = w * (size_t)d->height;
    if (!d->counts && !(d->counts = calloc(pixels ? pixels : 1, sizeof *d->counts)))
        return veil_fail(err, VEIL_ERR_OOM, "out of memory for a %dx%d deep image", d->width, d->height);
    size_t add = 0;
    for (size_t i = 0; i < w * (size_t)rows; ++i) {
        if (counts[i] > (uint32_t)R)
            return veil_fail(err, VEIL_ERR_GPU, "the deep march wrote %u samples for pixel %zu of row %d (at most %d)",
                             counts[i], i % w, first_row + (int)(i / w), R);
        add += counts[i];
    }
    if (add) {
        float* grown = realloc(d->samples, (d->total + add) * F * sizeof *grown);
        if (!grown) return veil_fail(err, VEIL_ERR_OOM, "out of memory for %zu deep samples", d->total + add);
        d->samples = grown;
    }
    float* out = d->samples + d->total * F;
    for (size_t i = 0; i < w * (size_t)rows; ++i) {
        const float* s = samples + i * (size_t)R * F;
        for (uint32_t k = 0; k < counts[i]; ++k, out += F) {
            memcpy(out, s + (size_t)k * F, F * sizeof *out);
            /* a stretch of one step too short for its planar depths to differ in float: still Z < ZBack */
            if (!(out[VEIL_DEEP_ZBACK] > out[VEIL_DEEP_Z]))
                out[VEIL_DEEP_ZBACK] = nextafterf(out[VEIL_DEEP_Z], INFINITY);
        }
        d->counts[(size_t)first_row * w + i] = counts[i];
    }
    d->total += add;
    return VEIL_OK;
}

void veil_deep_flatten(const float* s, uint32_t n, double out[4])
{
    out[0] = out[1] = out[2] = out[3] = 0.0;
    for (uint32_t k = 0; k < n; ++k, s += F) {
        const double t = 1.0 - out[3];
        for (int c = 0; c < 3; ++c) out[c] += t * s[c];
        out[3] += t * s[VEIL_DEEP_A];
    }
}

/* The part of sample s in front of depth d: alpha and colour (the holdout rule, render/deep.h). */
static void split(const float* s, double d, double* a, double c[3])
{
    const double z = s[VEIL_DEEP_Z], zb = s[VEIL_DEEP_ZBACK], A = s[VEIL_DEEP_A];
    double x = d >= zb ? 1.0 : d <= z ? 0.0 : (d - z) / (zb - z);
    *a = x >= 1.0 ? A : A >= 1.0 ? (x > 0.0 ? 1.0 : 0.0) : -expm1(x * log1p(-A));
    const double f = x >= 1.0 ? 1.0 : A > 0.0 ? *a / A : x;
    for (int k = 0; k < 3; ++k) c[k] = s[k] * f;
}

void veil_deep_holdout(const float* s, uint32_t n, double d, double out[4])
{
    out[0] = out[1] = out[2] = out[3] = 0.0;
    for (uint32_t k = 0; k < n && d > s[(size_t)k * F + VEIL_DEEP_Z]; ++k) {
        double a, c[3];
        split(s + (size_t)k * F, d, &a, c);
        const double t = 1.0 - out[3];
        for (int j = 0; j < 3; ++j) out[j] += t * c[j];
        out[3] += t * a;
    }
}

/* Makes a pixel's samples flatten to `target` (rgb, alpha): the alpha of its most opaque sample so that the
 * flattened alpha is target[3] (the march's alphas are each rounded by up to 2^-24 absolutely, which a thin
 * sample cannot take up: one of alpha 0 would have to go negative), then the colour left over, added to each sample in proportion to its share of the
 * pixel's opacity (A_k / alpha: sum_k T_k A_k / alpha = 1 with T_k the transmittance in front of sample
 * k; equal shares when every sample is transparent). Returns the largest |colour left over|. */
static double fix_pixel(float* s, uint32_t n, const double target[4])
{
    uint32_t j = 0;
    for (uint32_t k = 1; k < n; ++k)
        if (s[(size_t)k * F + VEIL_DEEP_A] > s[(size_t)j * F + VEIL_DEEP_A]) j = k;
    double P = 1.0; /* the transmittance of the others */
    for (uint32_t k = 0; k < n; ++k)
        if (k != j) P *= 1.0 - s[(size_t)k * F + VEIL_DEEP_A];
    if (n && P > 0.0) {
        double a = 1.0 - (1.0 - target[3]) / P;
        s[(size_t)j * F + VEIL_DEEP_A] = (float)(a < 0.0 ? 0.0 : a > 1.0 ? 1.0 : a);
    }
    double f[4], worst = 0.0;
    veil_deep_flatten(s, n, f);
    for (int c = 0; c < 3; ++c) {
        const double r = target[c] - f[c];
        worst = fmax(worst, fabs(r));
        if (r == 0.0) continue;
        for (uint32_t k = 0; k < n; ++k) {
            const double share = f[3] > 0.0 ? s[(size_t)k * F + VEIL_DEEP_A] / f[3] : 1.0 / n;
            s[(size_t)k * F + c] = (float)(s[(size_t)k * F + c] + r * share);
        }
    }
    return worst;
}

/* Merges adjacent samples until at most cap remain: each time the pair whose merged sample holds the least
 * of the pixel's opacity (T in front of it x its alpha). Returns the count. */
static uint32_t merge_pixel(float* s, uint32_t n, int cap)
{
    while (n > (uint32_t)cap) {
        uint32_t best = 0;
        double best_cost = INFINITY, P = 1.0;
        for (uint32_t i = 0; i + 1 < n; ++i) {
            const double a1 = s[(size_t)i * F + VEIL_DEEP_A], a2 = s[(size_t)(i + 1) * F + VEIL_DEEP_A];
            const double cost = P * (1.0 - (1.0 - a1) * (1.0 - a2));
            if (cost < best_cost) best_cost = cost, best = i;
            P *= 1.0 - a1;
        }
        float* a = s + (size_t)best * F;
        const float* b = a + F;
        const double a1 = a[VEIL_DEEP_A], a2 = b[VEIL_DEEP_A];
        for (int c = 0; c < 3; ++c) a[c] = (float)(a[c] + (1.0 - a1) * b[c]);
        a[VEIL_DEEP_A] = (float)(a1 + a2 - a1 * a2);
        a[VEIL_DEEP_ZBACK] = b[VEIL_DEEP_ZBACK];
        memmove(a + F, b + F, (size_t)(n - best - 2) * F * sizeof *a);
        --n;
    }
    return n;
}

static double luminance(const double c[4]) { return VEIL_LUM_R * c[0] + VEIL_LUM_G * c[1] + VEIL_LUM_B * c[2]; }

/* The holdout error of m merged samples against n raw ones at each raw sample's Z and ZBack, in one
 * sweep (both front to back; the merged boundaries are raw ones). */
static void measure_pixel(const float* raw, uint32_t n, const float* mer, uint32_t m, veil_deep_report* rep,
                          size_t* lit)
{
    double total[4];
    veil_deep_flatten(raw, n, total);
    const double y = luminance(total);
    double pr[4] = {0, 0, 0, 0}, pm[4] = {0, 0, 0, 0}; /* the raw and merged samples wholly in front */
    uint32_t j = 0;
    for (uint32_t k = 0; k < n; ++k)
        for (int side = 0; side < 2; ++side) {
            const double d = raw[(size_t)k * F + (side ? VEIL_DEEP_ZBACK : VEIL_DEEP_Z)];
            if (side) { /* raw sample k now wholly in front */
                const double t = 1.0 - pr[3];
                for (int c = 0; c < 3; ++c) pr[c] += t * raw[(size_t)k * F + c];
                pr[3] += t * raw[(size_t)k * F + VEIL_DEEP_A];
            }
            while (j < m && mer[(size_t)j * F + VEIL_DEEP_ZBACK] <= d) {
                const double t = 1.0 - pm[3];
                for (int c = 0; c < 3; ++c) pm[c] += t * mer[(size_t)j * F + c];
                pm[3] += t * mer[(size_t)j * F + VEIL_DEEP_A];
                ++j;
            }
            double q[4] = {pm[0], pm[1], pm[2], pm[3]};
            if (j < m && mer[(size_t)j * F + VEIL_DEEP_Z] < d) {
                double a, c[3];
                split(mer + (size_t)j * F, d, &a, c);
                const double t = 1.0 - q[3];
                for (int i = 0; i < 3; ++i) q[i] += t * c[i];
                q[3] += t * a;
            }
            const double ea = fabs(q[3] - pr[3]);
            rep->holdout_alpha_max = fmax(rep->holdout_alpha_max, ea);
            rep->holdout_alpha_mean += ea;
            if (y > 0.0) {
                const double ec = fabs(luminance(q) - luminance(pr)) / y;
                rep->holdout_color_max = fmax(rep->holdout_color_max, ec);
                rep->holdout_color_mean += ec;
                ++*lit;
            }
            ++rep->holdout_points;
        }
}

/* What pixel i's samples must flatten to (the flat image less T x what lies behind) into target; 1 when
 * its colour is not all 0 (light a pixel without samples gets as one transparent sample). */
static int pixel_target(size_t i, const float* rgba, const float* aov_t, const float background[3],
                        const float* behind, double target[4])
{
    const float* bg = behind ? behind + 3 * i : background;
    for (int c = 0; c < 3; ++c) target[c] = (double)rgba[4 * i + c] - (double)aov_t[4 * i + c] * bg[c];
    target[3] = rgba[4 * i + 3];
    return !(target[0] == 0.0 && target[1] == 0.0 && target[2] == 0.0);
}

veil_result veil_deep_finish(veil_deep_image* d, const float* rgba, const float* aov_t, const float background[3],
                             const float* behind, int cap, veil_deep_report* rep, veil_error* err)
{
    const double t0 = veil_now_ms();
    veil_deep_report local;
    if (!rep) rep = &local;
    memset(rep, 0, sizeof *rep);
    rep->cap = cap;
    if (cap < 1 || cap > VEIL_DEEP_MAX_SAMPLES)
        return veil_fail(err, VEIL_ERR_INVALID, "deep samples: expected a cap in 1..%d, got %d", VEIL_DEEP_MAX_SAMPLES, cap);
    const size_t pixels = (size_t)d->width * (size_t)d->height;
    if (!d->counts) return veil_fail(err, VEIL_ERR_INVALID, "no deep samples to finish");
    /* the frame's medium depth: where a pixel without samples gets its transparent one (spread light) */
    float front = INFINITY, back = -INFINITY;
    size_t empty = 0;
    for (size_t k = 0; k < d->total; ++k) {
        front = fminf(front, d->samples[k * F + VEIL_DEEP_Z]);
        back = fmaxf(back, d->samples[k * F + VEIL_DEEP_ZBACK]);
    }
    for (size_t i = 0; i < pixels; ++i) {
        empty += d->counts[i] == 0;
        if (d->counts[i] > (uint32_t)rep->max_raw) rep->max_raw = (int)d->counts[i];
    }
    if (rep->max_raw > VEIL_DEEP_MAX_RAW)
        return veil_fail(err, VEIL_ERR_INVALID, "a pixel has %d deep samples (at most %d)", rep->max_raw, VEIL_DEEP_MAX_RAW);
    /* merged in place (issue 41: a second copy doubled the peak): the raw samples moved up by the pixels
     * that gain a sample (none, but for spread light over an empty pixel), so that the merged ones written
     * from the start never pass the raw ones still to be read: after k pixels, written <= sum(n) + gained
     * <= read + gained (each pixel keeps at most its samples, or one) */
    size_t gain = 0;
    for (size_t i = 0; i < pixels && front < back; ++i) {
        double target[4];
        if (d->counts[i] == 0) gain += pixel_target(i, rgba, aov_t, background, behind, target);
    }
    if (gain) {
        float* grown = realloc(d->samples, (d->total + gain) * F * sizeof *grown);
        if (!grown) return veil_fail(err, VEIL_ERR_OOM, "out of memory for %zu deep samples", d->total + gain);
        d->samples = grown;
        memmove(d->samples + gain * F, d->samples, d->total * F * sizeof *d->samples);
    }
    rep->raw = d->total;
    float raw[VEIL_DEEP_MAX_RAW * F], mer[VEIL_DEEP_MAX_RAW * F];
    const float* src = d->samples + gain * F;
    float* dst = d->samples;
    size_t lit = 0, read = 0; /* holdout points of pixels with light (the colour error's mean); raw samples read */
    for (size_t i = 0; i < pixels; ++i) {
        if (read >= VEIL_DEEP_PART_SAMPLES) { /* progress, and a cancel honoured, between parts */
            read = 0;
            veil_progress("deep merge", (double)i, (double)pixels);
            if (veil_progress_cancelled())
                return veil_fail(err, VEIL_ERR_CANCELLED, "cancelled by the progress callback while the deep "
                                 "samples were merged (pixel %zu of %zu)", i, pixels);
        }
        uint32_t n = d->counts[i];
        read += n + 1;
        memcpy(raw, src, (size_t)n * F * sizeof *raw);
        src += (size_t)n * F;
        double target[4];
        const int light = pixel_target(i, rgba, aov_t, background, behind, target);
        if (n == 0) {
            if (!light || !(front < back)) continue;
            const float one[F] = {0, 0, 0, 0, front, back};
            memcpy(raw, one, sizeof one);
            n = 1;
        }
        rep->residual_max = fmax(rep->residual_max, fix_pixel(raw, n, target));
        memcpy(mer, raw, (size_t)n * F * sizeof *mer);
        uint32_t m = merge_pixel(mer, n, cap);
        if (m < n) fix_pixel(mer, m, target); /* the merges' rounding */
        measure_pixel(raw, n, mer, m, rep, &lit);
        memcpy(dst, mer, (size_t)m * F * sizeof *dst);
        dst += (size_t)m * F;
        d->counts[i] = m;
    }
    d->total = (size_t)(dst - d->samples) / F;
    float* shrunk = realloc(d->samples, d->total * F * sizeof *shrunk + 1);
    if (shrunk) d->samples = shrunk;
    rep->kept = d->total;
    if (rep->holdout_points) rep->holdout_alpha_mean /= (double)rep->holdout_points;
    if (lit) rep->holdout_color_mean /= (double)lit;
    rep->ms = veil_now_ms() - t0;
    return VEIL_OK;
}
