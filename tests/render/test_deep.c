/* Deep images (render/deep.h) against closed forms.
 *
 * 1. A homogeneous box of fog [0,1]^3 (falloff 0, grey extinction k =
 *    sigma_t rho), seen head-on from z = -2 as test_image_set sees it, a sun
 *    from above, a background. For caps 1, 3 and 8:
 *    - every pixel: at most cap samples, Z < ZBack, sorted and not
 *      overlapping, 0 <= A <= 1; a ray that misses the box has none;
 *    - flatten(samples) = rgb - T background and the flat alpha. The
 *      samples are made (veil_deep_finish) so that their flatten in exact
 *      arithmetic is the target computed in double; what remains is storing
 *      each finished colour and one alpha as float, at most 2^-24 of
 *      each, so |flatten - target| <= 2^-24 sum_k T_k |C_k| for colour
 *      (T_k: the transmittance in front of sample k), 2^-24 for alpha, plus
 *      the double arithmetic (n 2^-52 of the same sum);
 *    - the holdout: a surface at planar depth d inside the box (fractions
 *      0.1 .. 0.9 of the chord) sees alpha 1 - exp(-k s) in front of it, s
 *      the distance from the entry along the ray. The fog's integral is exact
 *      per step and the medium is homogeneous, so the split rule (1 - A)^x
 *      is exact inside a sample, raw or merged (a merged sample of a
 *      homogeneous slab is homogeneous): only rounding remains. The
 *      transmittance at a step boundary is within 8 (N + 4) 2^-23 of its
 *      closed form relatively (test_image_set's bound, N steps); each
 *      sample's 1 - A = Tm(back) / Tm(front) is rounded twice (the quotient
 *      and 1 - A), 2^-23 absolutely, n + 1 of them (the most opaque one's alpha set
 *      by the finish); the planar depths are t x cos rounded, the cosine from
 *      a normalised float direction: 6 2^-24 t1 of position, k times that in
 *      optical depth. Bound: T (8 (N + 4) 2^-23 + 6 2^-24 k t1) + (n + 1) 2^-23.
 *    - the merge's holdout error (the report) is 0 up to that rounding for
 *      the slab (homogeneous: nothing is lost), and all samples flatten.
 *    - the flat image is the one rendered without deep samples, bit for bit.
 * 2. veil_deep_finish on a hand-made pixel of two wisps with a gap: merged
 *    to one sample, the holdout at the gap reads the merged sample's
 *    split, and the report gives that error exactly (the anti-vacuity case:
 *    a merge that loses depth shows); the spread light of a pixel without
 *    samples lands on a transparent sample over the frame's medium depth.
 * 3. The merge of 2^19 raw samples (issue 41, item 6): its progress in
 *    parts of at most VEIL_DEEP_PART_SAMPLES raw samples (plus a pixel's),
 *    a cancel asked for at its first report ending it there
 *    (VEIL_ERR_CANCELLED, no report after), and the memory estimate's
 *    arithmetic. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "frame/renderer.h"
#include "core/progress.h"
#include "render/deep.h"
#include "scene/camera.h"

enum { W = 31, H = 23, F = VEIL_DEEP_CHANNELS };
static const double U = 0x1p-24;

static void slab(veil_renderer* r, int cap)
{
    const double rho = 1.0, y = 0.55, sigma_a = 0.5, sigma_s = 1.0, k = (sigma_a + sigma_s) * rho;
    veil_source fog = {.type = VEIL_SOURCE_EXPONENTIAL,
                       .fog = {.density = (float)rho, .falloff = 0.0f, .direction = {0, 1, 0},
                               .bounds = {{0, 0, 0}, {1, 1, 1}}}};
    veil_light sun = {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0, -1, 0}, .color = {2, 3, 4}};
    veil_scene s = {0};
    s.camera = (veil_camera){.position = {0.5f, (float)y, -2.0f}, .look_at = {0.5f, (float)y, 0.0f},
                             .up = {0, 1, 0}, .fov_y_deg = 40.0f, .width = W, .height = H};
    for (int c = 0; c < 3; ++c) s.medium.sigma_a[c] = (float)sigma_a, s.medium.sigma_s[c] = (float)sigma_s;
    s.medium.sources = &fog;
    s.medium.source_count = 1;
    s.lights = &sun;
    s.light_count = 1;
    s.background[0] = 0.2f, s.background[1] = 0.1f, s.background[2] = 0.05f;
    veil_image_set im = {0};
    veil_render_stats st;
    veil_error err = {0};
    veil_render_opts o = {.seed = 5, .deep = 1, .deep_samples = cap};
    CHECK(veil_render_scene_images(r, &s, &o, &im, &st, &err) == VEIL_OK, "cap %d: %s", cap, err.msg);
    /* the flat image is the march's without deep samples, bit for bit (the same arithmetic, other bands) */
    veil_image_set plain = {0};
    o.deep = 0;
    CHECK(veil_render_scene_images(r, &s, &o, &plain, NULL, &err) == VEIL_OK, "cap %d: %s", cap, err.msg);
    CHECK(plain.rgba && im.rgba && memcmp(plain.rgba, im.rgba, sizeof(float) * 4 * W * H) == 0 && !plain.deep.counts,
          "cap %d: the flat image differs with deep samples", cap);
    veil_image_set_free(&plain);
    const veil_deep_image* d = &im.deep;
    CHECK(d->counts && d->width == W && d->height == H, "cap %d: no deep image", cap);
    if (!d->counts) return;
    veil_camera_basis cam;
    veil_camera_make_basis(&s.camera, W, H, &cam, &err);
    int bad = 0, hits = 0, misses = 0, split_pixels = 0;
    double worst_flat = 0.0, worst_hold = 0.0;
    const float* smp = d->samples;
    size_t seen = 0;
    for (int py = 0; py < H; ++py)
        for (int px = 0; px < W; ++px) {
            const size_t i = (size_t)py * W + (size_t)px;
            const uint32_t n = d->counts[i];
            const float* p = smp;
            smp += (size_t)n * F;
            seen += n;
            /* the samples' shape */
            if (n > (uint32_t)cap && bad++ < 5) fprintf(stderr, "cap %d: pixel %d,%d has %u samples\n", cap, px, py, n);
            for (uint32_t j = 0; j < n; ++j) {
                const float* q = p + (size_t)j * F;
                int ok = q[VEIL_DEEP_Z] < q[VEIL_DEEP_ZBACK] && q[VEIL_DEEP_A] >= 0.0f && q[VEIL_DEEP_A] <= 1.0f &&
                         (j == 0 || q[VEIL_DEEP_Z] >= q[VEIL_DEEP_ZBACK - F]);
                if (!ok && bad++ < 5)
                    fprintf(stderr, "cap %d: pixel %d,%d sample %u: A %g Z %.9g ZBack %.9g (previous ZBack %.9g)\n", cap,
                            px, py, j, q[VEIL_DEEP_A], q[VEIL_DEEP_Z], q[VEIL_DEEP_ZBACK], j ? q[VEIL_DEEP_ZBACK - F] : 0.0);
            }
            split_pixels += n > 1;
            /* flatten = the flat image less T background */
            double f[4], sum = 0.0, T = 1.0;
            veil_deep_flatten(p, n, f);
            for (uint32_t j = 0; j < n; ++j) {
                for (int c = 0; c < 3; ++c) sum += T * fabs(p[(size_t)j * F + c]);
                T *= 1.0 - p[(size_t)j * F + VEIL_DEEP_A];
            }
            for (int c = 0; c < 4; ++c) {
                const double target = c < 3 ? (double)im.rgba[4 * i + c] - (double)im.aov_t[4 * i + c] * s.background[c]
                                            : im.rgba[4 * i + 3];
                const double bound = c < 3 ? (U + n * 0x1p-52) * sum : U + n * 0x1p-52;
                const double e = fabs(f[c] - target);
                worst_flat = fmax(worst_flat, bound > 0 ? e / bound : e > 0 ? INFINITY : 0);
                if (!(e <= bound) && bad++ < 5)
                    fprintf(stderr, "cap %d: pixel %d,%d channel %d: flatten %.9g, flat %.9g (bound %.3g)\n", cap, px, py,
                            c, f[c], target, bound);
            }
            /* the holdout against the closed form */
            float df[3];
            veil_camera_ray(&cam, W, H, px, py, df);
            double t0 = 0, t1 = INFINITY, len = sqrt((double)df[0] * df[0] + (double)df[1] * df[1] + (double)df[2] * df[2]);
            for (int a = 0; a < 3; ++a) {
                if (df[a] == 0) continue;
                double ta = (0 - cam.pos[a]) / df[a], tb = (1 - cam.pos[a]) / df[a];
                t0 = fmax(t0, fmin(ta, tb));
                t1 = fmin(t1, fmax(ta, tb));
            }
            t0 *= len, t1 *= len; /* distances along the unit ray */
            if (t1 <= t0) {
                ++misses;
                if (n != 0 && bad++ < 5) fprintf(stderr, "cap %d: pixel %d,%d misses the box yet has %u samples\n", cap, px, py, n);
                continue;
            }
            if (!(t1 > t0 + 1e-3)) continue; /* a graze too thin to judge */
            ++hits;
            const double cz = df[2] / len, C = t1 - t0, N = C / 0.01 + 1;
            for (int q = 1; q <= 9; q += 2) {
                const double frac = q / 10.0, dist = t0 + frac * C, depth = dist * cz;
                double h[4];
                veil_deep_holdout(p, n, depth, h);
                const double Td = exp(-k * frac * C), want = 1.0 - Td;
                const double bound = Td * (8.0 * (N + 4) * 0x1p-23 + 6.0 * U * k * t1) + (n + 1) * 0x1p-23;
                const double e = fabs(h[3] - want);
                worst_hold = fmax(worst_hold, e / bound);
                if (!(e <= bound) && bad++ < 5)
                    fprintf(stderr, "cap %d: pixel %d,%d holdout at %.3f of the chord: alpha %.9g, closed form %.9g "
                            "(bound %.3g, %u samples)\n", cap, px, py, frac, h[3], want, bound, n);
            }
        }
    printf("cap %d: %d hits, %d misses, %zu raw samples (at most %d a pixel) -> %zu; flatten error at most %.3f of its "
           "bound, holdout %.3f; merge's holdout error alpha max %.3g\n", cap, hits, misses, st.deep.raw, st.deep.max_raw,
           st.deep.kept, worst_flat, worst_hold, st.deep.holdout_alpha_max);
    CHECK(seen == d->total, "cap %d: the counts add up to %zu samples, the image holds %zu", cap, seen, d->total);
    CHECK(hits > W * H / 4 && misses > 0, "cap %d: %d hits, %d misses: a case is untested", cap, hits, misses);
    CHECK(cap == 1 || split_pixels > hits / 2, "cap %d: only %d pixels have more than one sample", cap, split_pixels);
    CHECK(st.deep.raw >= st.deep.kept && (cap > 1 || st.deep.raw > st.deep.kept), "cap %d: %zu raw samples, %zu kept",
          cap, st.deep.raw, st.deep.kept);
    /* the slab is homogeneous: a merge loses nothing beyond rounding, the holdout bound's at T <= 1, a chord
     * of at most t1 < 3.5 m (N < 351 steps) and the raw samples' count */
    const double merge_bound = 8.0 * (351 + 4) * 0x1p-23 + 6.0 * U * k * 3.5 + (st.deep.max_raw + 1) * 0x1p-23;
    CHECK(st.deep.holdout_alpha_max <= merge_bound, "cap %d: the merge's holdout error %.3g in a homogeneous slab "
          "(bound %.3g)", cap, st.deep.holdout_alpha_max, merge_bound);
    CHECK(bad == 0, "cap %d: %d deep values off", cap, bad);
    veil_image_set_free(&im);
}

/* Two wisps on one ray: [1, 2] with alpha 0.5, [3, 4] with alpha 0.5, colours 0.25 and 0.5 (the second's
 * as seen at its front). Merged to one sample [1, 4] of alpha 0.75. At depth 2 (the first's back) the raw
 * samples hold out alpha 0.5; the merged one 1 - 0.25^(1/3). A second pixel has no samples but flat
 * light (spread): it gets a transparent sample over the frame's depth [1, 4] carrying it. */
static void gap(void)
{
    float samples[2 * F] = {0.25f, 0.25f, 0.25f, 0.5f, 1.0f, 2.0f, 0.5f, 0.5f, 0.5f, 0.5f, 3.0f, 4.0f};
    uint32_t counts[2] = {2, 0};
    veil_deep_image d = {.width = 2, .height = 1, .total = 2};
    d.counts = malloc(sizeof counts);
    d.samples = malloc(sizeof samples);
    memcpy(d.counts, counts, sizeof counts);
    memcpy(d.samples, samples, sizeof samples);
    /* the flat image: exactly the raw flatten (0.25 + 0.5 x 0.5 = 0.5, alpha 0.75), background 0; the
     * second pixel 0.125 of spread light and alpha 0 */
    const float rgba[8] = {0.5f, 0.5f, 0.5f, 0.75f, 0.125f, 0.125f, 0.125f, 0.0f};
    const float aov_t[8] = {0.25f, 0.25f, 0.25f, 0, 1, 1, 1, 0}, bg[3] = {0, 0, 0};
    veil_deep_report rep;
    veil_error err = {0};
    CHECK(veil_deep_finish(&d, rgba, aov_t, bg, NULL, 1, &rep, &err) == VEIL_OK, "%s", err.msg);
    CHECK(d.counts[0] == 1 && d.counts[1] == 1 && d.total == 2, "counts %u, %u", d.counts[0], d.counts[1]);
    const float* m = d.samples;
    CHECK(m[VEIL_DEEP_Z] == 1.0f && m[VEIL_DEEP_ZBACK] == 4.0f && check_close(m[VEIL_DEEP_A], 0.75, 0, U) &&
          check_close(m[0], 0.5, 0, U), "merged: %g %g %g %g %g", m[0], m[VEIL_DEEP_A], m[VEIL_DEEP_Z],
          m[VEIL_DEEP_ZBACK], m[1]);
    /* the error at the raw depths 1, 2, 3, 4: 0, |0.5 - (1 - 0.25^(1/3))|, |0.5 - (1 - 0.25^(2/3))|, 0 */
    const double e2 = fabs(0.5 - (1.0 - pow(0.25, 1.0 / 3.0))), e3 = fabs(0.5 - (1.0 - pow(0.25, 2.0 / 3.0)));
    CHECK(check_close(rep.holdout_alpha_max, fmax(e2, e3), 0, 1e-6), "holdout error %.9g, expected %.9g",
          rep.holdout_alpha_max, fmax(e2, e3));
    /* the mean over the first pixel's four depths and the second's two (its own sample, exact) */
    CHECK(rep.holdout_points == 6 && check_close(rep.holdout_alpha_mean, (e2 + e3) / 6.0, 0, 1e-6),
          "%zu points, mean %.9g (expected %.9g)", rep.holdout_points, rep.holdout_alpha_mean, (e2 + e3) / 6.0);
    const float* t = d.samples + F;
    CHECK(t[VEIL_DEEP_A] == 0.0f && t[0] == 0.125f && t[VEIL_DEEP_Z] == 1.0f && t[VEIL_DEEP_ZBACK] == 4.0f,
          "the spread light's sample: %g %g [%g, %g]", t[0], t[VEIL_DEEP_A], t[VEIL_DEEP_Z], t[VEIL_DEEP_ZBACK]);
    /* a bad cap is refused, naming what */
    CHECK(veil_deep_finish(&d, rgba, aov_t, bg, NULL, 0, NULL, &err) == VEIL_ERR_INVALID && strstr(err.msg, "deep samples"),
          "cap 0: %s", err.msg);
    veil_deep_image_free(&d);
}

typedef struct merge_log {
    int reports, cancel_at, after;
    double last;
} merge_log;

static void on_merge(void* user, const char* what, double done, double total)
{
    merge_log* m = user;
    if (strcmp(what, "deep merge") != 0) return;
    if (m->cancel_at && m->reports >= m->cancel_at) ++m->after;
    m->last = done / total;
    if (++m->reports == m->cancel_at) veil_progress_cancel();
}

/* 512 x 64 pixels of 16 thin samples each (2^19 raw samples), merged to 4 */
static void merge_parts(void)
{
    enum { MW = 512, MH = 64, N = 16 };
    const size_t pixels = (size_t)MW * MH;
    float* rgba = calloc(pixels * 4, sizeof *rgba);
    float* aov_t = calloc(pixels * 4, sizeof *aov_t);
    const float bg[3] = {0, 0, 0};
    for (int cancel_at = 0; cancel_at <= 1 && rgba && aov_t; ++cancel_at) {
        veil_deep_image d = {.width = MW, .height = MH, .total = pixels * N};
        d.counts = malloc(pixels * sizeof *d.counts);
        d.samples = malloc(d.total * F * sizeof *d.samples);
        if (!d.counts || !d.samples) {
            CHECK(0, "out of memory");
            veil_deep_image_free(&d);
            break;
        }
        for (size_t i = 0; i < pixels; ++i) {
            d.counts[i] = N;
            for (int k = 0; k < N; ++k) {
                float* x = d.samples + (i * N + (size_t)k) * F;
                x[0] = x[1] = x[2] = 0.01f, x[VEIL_DEEP_A] = 0.05f, x[VEIL_DEEP_Z] = 1.0f + (float)k;
                x[VEIL_DEEP_ZBACK] = 1.5f + (float)k;
            }
            double f[4];
            veil_deep_flatten(d.samples + i * N * F, N, f);
            for (int c = 0; c < 4; ++c) rgba[4 * i + (size_t)c] = (float)f[c];
        }
        merge_log log = {.cancel_at = cancel_at};
        void* old_user = NULL;
        veil_progress_fn old = veil_progress_sink(on_merge, &log, &old_user);
        veil_error err = {0};
        veil_result r = veil_deep_finish(&d, rgba, aov_t, bg, NULL, 4, NULL, &err);
        veil_progress_sink(old, old_user, NULL);
        /* a part ends at the first pixel that passes VEIL_DEEP_PART_SAMPLES (n + 1 counted a pixel) */
        const double part = (double)VEIL_DEEP_PART_SAMPLES + N + 1, raw = (double)pixels * (N + 1);
        if (!cancel_at)
            CHECK(r == VEIL_OK && d.total == pixels * 4 && log.reports >= (int)(raw / part) &&
                      log.reports <= (int)(raw / VEIL_DEEP_PART_SAMPLES),
                  "merge: %s: %s, %zu kept, %d reports", veil_result_name(r), err.msg, d.total, log.reports);
        else
            CHECK(r == VEIL_ERR_CANCELLED && log.after == 0 && strstr(err.msg, "deep samples were merged"),
                  "cancel: %s: %s, %d reports after", veil_result_name(r), err.msg, log.after);
        veil_deep_image_free(&d);
    }
    free(rgba), free(aov_t);
    /* the estimate: R = min(4 cap, 64) raw samples of 24 bytes, a count and the writer's 56 bytes a pixel */
    CHECK(veil_deep_bytes(1024, 768, 64) == 1024.0 * 768 * (64 * 24 + 4 + 56) &&
              veil_deep_bytes(3840, 2160, 8) == 3840.0 * 2160 * (32 * 24 + 4 + 56) &&
              veil_deep_bytes(3840, 2160, 8) < VEIL_DEEP_MAX_BYTES && veil_deep_bytes(4096, 4096, 64) > VEIL_DEEP_MAX_BYTES,
          "deep bytes: %g, %g", veil_deep_bytes(1024, 768, 64), veil_deep_bytes(3840, 2160, 8));
}

int main(void)
{
    gap();
    merge_parts();
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_renderer* r = NULL;
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    const int caps[] = {1, 3, 8};
    for (int i = 0; r && i < 3; ++i) slab(r, caps[i]);
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
    return check_finish();
}
