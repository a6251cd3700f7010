/* The screen-space spread on the GPU (render/spread.h) on synthetic
 * inputs: a medium with sigma_a = 0 and the same density integral P and
 * depth at every pixel, so that W (pixels) is one number w everywhere
 * (computed here with the same veil_spread_width), and the input radiance
 * L is a test image: then L_sc = (1 - exp(-sigma_s P)) L exactly.
 *
 * 1. Energy. A pure blur (no leak mask, no density blur) moves light and
 *    makes none: for every filter size and interpolation, the sum of the
 *    output equals the sum of L_sc while the light stays inside the image
 *    (the test image's bright pixels sit more than the coarsest level's
 *    footprint, 3 texels of level K = 3 plus the fetch's 2, from the
 *    edges). Each output value is a sum of at most 36 x K + 16 positive
 *    float products, relative rounding <= (36 K + 20) 2^-24 = 7.6e-6; the
 *    totals are summed in double. The cubic fetch reads merged taps
 *    through hardware bilinear filtering, whose sub-texel position has 8
 *    fractional bits on llvmpipe (and most GPUs): a merged tap's weight
 *    split is off by up to 2^-9, which moves light between neighbours
 *    but keeps each pair's total; we allow 1e-5 relative.
 * 2. The MIP approximation against the gathering filter (reference/
 *    gather.h: the exact spatially varying Gaussian) with the paper's
 *    settings (mask, luminance weighting, density blur; 4x4, linear-
 *    bicubic), on an image smooth on the scale of w (Gaussian blobs of
 *    standard deviation 2 w): the relative RMSE must stay below 6.5 %.
 *    Why: the MIP kernel of level k has variance 0.77 (4^k - 1)/3 px^2
 *    from the chain of 4-tap filters (each adds 2 (0.13 1.5^2 + 0.37
 *    0.5^2) = 0.77 texels^2 of its level) plus 4^k / 3 from the cubic
 *    B-spline fetch; against W = c 2^k (c = 0.86) its standard deviation
 *    is within 15 % of W at every level (k = 2: 3.03 vs 3.44 px; k = 3:
 *    6.1 vs 6.9; between levels the linear mix lands closer). A Gaussian
 *    blob of variance (2w)^2 convolved with a kernel of variance
 *    ((1 +- 0.15) w)^2 instead of w^2 has its 2D peak (which scales as 1 /
 *    total variance) off by at most 1 - 5 / 5.3225 = 6.1 %, and less
 *    elsewhere. (Measured: 1.2 %.) Single impulses are no smooth image:
 *    the kernel's shape shows there, and the test only reports it.
 *    The leak mask must not change a constant-W image (every pixel is
 *    whole in the levels it is read from): this runs with it on.
 * 3. P -> 0 everywhere: the output is 0 (no spread where nothing scatters),
 *    and no NaN for absurd densities (P = 1e30).
 * 4. No popping in a turntable: the result is continuous across a level
 *    boundary (below). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "reference/gather.h"
#include "render/spread.h"

enum { W = 96, H = 80 };

typedef struct setup {
    veil_scene sc;
    float *L, *aov_t, *aov_s, *out, *level0, *gathered;
    float w_px;
} setup;

/* P, depth and fov give w pixels: s = 1 / (depth * 2 tan(fov/2) / H). */
static void make(setup* t, float P, const float* image)
{
    memset(&t->sc, 0, sizeof t->sc);
    veil_multiple_defaults(&t->sc.multiple);
    t->sc.multiple.levels = 3;
    t->sc.medium.sigma_s[0] = t->sc.medium.sigma_s[1] = t->sc.medium.sigma_s[2] = 1.0f;
    t->sc.medium.phase.type = VEIL_PHASE_HG;
    t->sc.medium.phase.g = 0.3f;
    size_t n = (size_t)W * H;
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 4; ++c) t->L[4 * i + c] = image[4 * i + c];
        t->aov_t[4 * i + 0] = t->aov_t[4 * i + 1] = t->aov_t[4 * i + 2] = expf(-P);
        t->aov_t[4 * i + 3] = P;
        t->aov_s[4 * i + 0] = t->aov_s[4 * i + 1] = t->aov_s[4 * i + 2] = 0.0f;
        t->aov_s[4 * i + 3] = 10.0f; /* depth (m) */
    }
    double px_per_m = 1.0 / (10.0 * 2.0 * tan(0.5 * 40.0 * VEIL_PI / 180.0) / H);
    t->w_px = (float)(veil_spread_width(P, 0.0f, 1.0f, 0.3f) * px_per_m);
}

static veil_result run(veil_spread* sp, setup* t, veil_error* err)
{
    veil_spread_input in = {.width = W, .height = H, .L = t->L, .aov_t = t->aov_t, .aov_s = t->aov_s,
                            .aov_q = NULL, .fov_y_deg = 40.0f};
    return veil_spread_run(sp, &t->sc, &in, t->out, t->level0, NULL, err);
}

static double rgb_sum(const float* img)
{
    double s = 0.0;
    for (size_t i = 0; i < (size_t)W * H; ++i) s += (double)img[4 * i] + img[4 * i + 1] + img[4 * i + 2];
    return s;
}

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_spread* sp = NULL;
    CHECK(veil_spread_create(&sp, &err) == VEIL_OK, "%s", err.msg);
    if (!sp) return check_finish();
    setup t;
    size_t floats = (size_t)W * H * 4;
    float* impulses = calloc(floats, sizeof(float));
    float* blobs = calloc(floats, sizeof(float));
    t.L = malloc(floats * sizeof(float)), t.aov_t = malloc(floats * sizeof(float));
    t.aov_s = malloc(floats * sizeof(float)), t.out = malloc(floats * sizeof(float));
    t.level0 = malloc(floats * sizeof(float)), t.gathered = malloc(floats * sizeof(float));
    /* impulses inside [24, W - 24) x [24, H - 24): level 3 texels are 8 px, 3 + 2 of them 40 px... the
     * footprint reaches 1.5 texels of level 3 (12 px) beyond the chain plus the fetch's 2 texels (16 px) */
    uint32_t seed = 99u;
    for (int k = 0; k < 40; ++k) {
        seed = seed * 1664525u + 1013904223u;
        int x = 30 + (int)((seed >> 8) % (W - 60)), y = 30 + (int)((seed >> 16) % (H - 60));
        for (int c = 0; c < 3; ++c) impulses[4 * (y * W + x) + c] += 1.0f + (float)c;
    }
    /* P for w ~ 4.6 pixels: level log2(4.6 / 0.86) = 2.4 */
    float P = 0.2f;
    make(&t, P, impulses);
    for (int it = 0; it < 40 && t.w_px < 4.6f; ++it) make(&t, P *= 1.05f, impulses);
    const char* filters[] = {"2x2", "4x4", "6x6"};
    const char* interps[] = {"linear-bilinear", "linear-bicubic", "cubic-bicubic"};
    for (int f = 0; f < 3; ++f)
        for (int m = 0; m < 3; ++m) {
            make(&t, P, impulses);
            t.sc.multiple.mask = 0;
            t.sc.multiple.density_blur = 0;
            t.sc.multiple.filter = (veil_spread_filter)f;
            veil_spread_default_weights(t.sc.multiple.filter, t.sc.multiple.weights);
            t.sc.multiple.interp = m;
            CHECK(run(sp, &t, &err) == VEIL_OK, "%s", err.msg);
            double in = rgb_sum(t.level0), out = rgb_sum(t.out);
            double want = (1.0 - exp(-(double)P)) * rgb_sum(impulses);
            CHECK(fabs(in - want) <= 1e-6 * want, "%s %s: L_sc sums to %.9g, (1 - e^-P) L to %.9g", filters[f],
                  interps[m], in, want);
            CHECK(fabs(out - in) <= 1e-5 * in, "%s %s (w = %.2f px): the blur's output sums to %.9g, its input to %.9g "
                  "(rel %.3g)", filters[f], interps[m], t.w_px, out, in, (out - in) / in);
        }

    /* 2. MIP chains against the gathering filter, the paper's settings */
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            double v = 0.0;
            const double cx[3] = {30, 60, 48}, cy[3] = {30, 44, 52}, amp[3] = {3, 1.5, 2};
            double s2 = 2.0 * 4.6 * 2.0 * 4.6;
            for (int b = 0; b < 3; ++b)
                v += amp[b] * exp(-((x - cx[b]) * (x - cx[b]) + (y - cy[b]) * (y - cy[b])) / (2.0 * s2));
            for (int c = 0; c < 3; ++c) blobs[4 * (y * W + x) + c] = (float)(v * (1.0 + 0.3 * c));
        }
    const double bound = 0.065;
    for (int pass = 0; pass < 2; ++pass) {
        make(&t, P, pass == 0 ? blobs : impulses);
        CHECK(run(sp, &t, &err) == VEIL_OK, "%s", err.msg);
        float* Ws = malloc((size_t)W * H * sizeof(float));
        for (size_t i = 0; i < (size_t)W * H; ++i) Ws[i] = t.level0[4 * i + 3];
        CHECK(veil_gather_spread(W, H, t.level0, Ws, t.gathered, &err) == VEIL_OK, "%s", err.msg);
        free(Ws);
        double num = 0.0, den = 0.0;
        for (size_t i = 0; i < (size_t)W * H; ++i)
            for (int c = 0; c < 3; ++c) {
                double d = t.out[4 * i + c] - t.gathered[4 * i + c];
                num += d * d;
                den += (double)t.gathered[4 * i + c] * t.gathered[4 * i + c];
            }
        double rel = sqrt(num / den);
        printf("MIP chains vs gathering, %s, w = %.2f px: relative RMSE %.4f\n", pass == 0 ? "smooth blobs" : "impulses",
               t.w_px, rel);
        if (pass == 0) CHECK(rel < bound, "MIP vs gathering on smooth blobs: %.4f >= %.2f", rel, bound);
    }

    /* 4. no popping: across a level boundary (w = c 2^3, level 3.0) the result moves
     * continuously. P -> P (1 +- 1e-3) moves w by about 1.5e-3 relative and the level by
     * 2e-3 (k = log2 w + const); with interpolation between levels the image moves by at
     * most that fraction of the difference between levels 2 and 3 (< 100 %), so well under 1 %
     * (the linear transmittance factor 1 - e^-P moves it by 1e-3 more); reading the nearest
     * level would jump by the whole difference. */
    {
        float Pb = 0.05f;
        make(&t, Pb, blobs);
        for (int it = 0; it < 400 && t.w_px < 0.86f * 8.0f; ++it) make(&t, Pb *= 1.01f, blobs);
        for (int it = 0; it < 60; ++it) { /* bisect to the boundary */
            float lo = Pb / 1.01f, hi = Pb, mid = 0.5f * (lo + hi);
            make(&t, mid, blobs);
            if (t.w_px < 0.86f * 8.0f) lo = mid; else hi = mid;
            Pb = hi;
            if (hi - lo < 1e-6f * hi) break;
        }
        float* below = malloc(floats * sizeof(float));
        make(&t, Pb * (1.0f - 1e-3f), blobs);
        CHECK(run(sp, &t, &err) == VEIL_OK, "%s", err.msg);
        memcpy(below, t.out, floats * sizeof(float));
        make(&t, Pb * (1.0f + 1e-3f), blobs);
        CHECK(run(sp, &t, &err) == VEIL_OK, "%s", err.msg);
        double num = 0.0, den = 0.0;
        for (size_t i = 0; i < floats; ++i)
            if (i % 4 != 3) num += (t.out[i] - below[i]) * (double)(t.out[i] - below[i]), den += (double)below[i] * below[i];
        double rel = sqrt(num / den);
        printf("level boundary (w = %.3f px): the image moves by %.2g relative\n", t.w_px, rel);
        CHECK(rel < 0.01, "across the level-3 boundary the spread jumps by %.3g (>= 1 %%)", rel);
        free(below);
    }

    /* 3. nothing scatters: nothing spreads; absurd P: no NaN */
    make(&t, 0.0f, blobs);
    CHECK(run(sp, &t, &err) == VEIL_OK, "%s", err.msg);
    CHECK(rgb_sum(t.out) == 0.0, "P = 0: the spread must be 0, sums to %g", rgb_sum(t.out));
    make(&t, 1e30f, blobs);
    CHECK(run(sp, &t, &err) == VEIL_OK, "%s", err.msg);
    int finite = 1;
    for (size_t i = 0; i < floats; ++i) finite &= isfinite(t.out[i]) != 0;
    CHECK(finite, "P = 1e30: the spread must stay finite");

    free(impulses), free(blobs), free(t.L), free(t.aov_t), free(t.aov_s), free(t.out), free(t.level0), free(t.gathered);
    veil_spread_destroy(sp);
    veil_gl_destroy(gl);
    return check_finish();
}
