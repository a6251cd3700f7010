/* The light cache (volumetric/cache.h).
 * 1. The fixed point (CPU, the shared function the shader calls): each add
 *    floor(s u + xi) is within one unit of s u for every xi in [0, 1), and
 *    unbiased: over the M-point lattice xi = (k + 1/2) / M its mean is s u
 *    within 1 / (2M) (floor(s + xi) averaged over a uniform lattice counts
 *    the lattice points at or above 1 - frac(s): frac(s) M of them, within
 *    a half point); values past +-2^31 are clamped, never wrapped.
 * 2. Determinism: the same seed gives the same cache bit for bit (the sums
 *    are integers, so the order the GPU runs photons in does not matter);
 *    another seed gives another.
 * 3. No order counted twice: a homogeneous fog box (isotropic, albedo 0.95)
 *    under a sun, rendered with the march (order 1, exact) plus the cache
 *    (orders >= 2) against the reference path tracer at all orders. The
 *    image means must agree within
 *      4 sqrt(se_ref^2 + (noise M)^2) + (1 - exp(-sigma_t h)) M / 2
 *    with se_ref the standard error of the reference's mean (its pixels'
 *    standard errors, independent), M the mean of the cache's part and
 *    noise the cache's own estimate of its cells' relative noise (a
 *    positively weighted mean of noisy cells has at most their RMS relative
 *    noise), plus the cells' averaging: within one cell of edge h the
 *    fluence changes by at most a factor exp(sigma_t h) along the light
 *    (the steepest it can: no scattering gain), and the trilinear read of
 *    cell means is off by at most that change, half of it on a mean over
 *    a ray (the linear part cancels). Counting order 1 twice would add the
 *    single scattering's mean, which the test first checks is far above
 *    that bound. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "frame/renderer.h"
#include "reference/pathtracer.h"
#include "volumetric/volumetric.h"

static void fixed_point(void)
{
    const float s_values[] = {0.0f, 0.3f, 0.5f, 1.0f, 7.25f, -0.3f, -7.75f, 1234.567f, -98765.4f, 1e-6f, 1073741824.0f};
    const int M = 1000;
    int ok = 1;
    for (size_t i = 0; i < sizeof s_values / sizeof *s_values; ++i) {
        float s = s_values[i];
        double sum = 0.0;
        for (int k = 0; k < M; ++k) {
            float xi = ((float)k + 0.5f) / (float)M;
            int v = veil_cache_fixed(s, xi);
            ok &= fabs((double)v - (double)s) < 1.0 + 1e-6 * fabs(s); /* float s + xi rounds at 2^24 and up */
            sum += v;
        }
        double mean = sum / M;
        double tol = 0.5 / M + 1e-6 * fabs(s);
        CHECK(fabs(mean - s) <= tol, "fixed point: mean of floor(%g + xi) over %d points %.9g (tolerance %.3g)", s, M,
              mean, tol);
    }
    CHECK(ok, "fixed point: some add was a unit or more away from its score");
    CHECK(veil_cache_fixed(3e9f, 0.5f) == 2147483520 && veil_cache_fixed(-3e9f, 0.5f) == -2147483520,
          "fixed point: out-of-range scores clamped (%d, %d)", veil_cache_fixed(3e9f, 0.5f),
          veil_cache_fixed(-3e9f, 0.5f));
    printf("fixed point: unbiased within 1/(2M) and within one unit, clamped past 2^31\n");
}

static veil_source fog_box(void)
{
    return (veil_source){.type = VEIL_SOURCE_EXPONENTIAL,
                         .fog = {.density = 1.0f, .falloff = 0.0f, .direction = {0, 1, 0},
                                 .bounds = {{-1, -1, -1}, {1, 1, 1}}}};
}

static void determinism(veil_volumetric* d)
{
    veil_error err = {0};
    veil_source fog = fog_box();
    veil_light lights[2] = {{.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0.3f, -0.8f, 0.5f}, .color = {1, 2, 3}},
                            {.type = VEIL_LIGHT_POINT, .position = {0.2f, 0.1f, 0.0f}, .color = {2, 2, 1}}};
    float n = sqrtf(0.09f + 0.64f + 0.25f);
    for (int a = 0; a < 3; ++a) lights[0].direction[a] /= n;
    veil_scene s = {0};
    for (int c = 0; c < 3; ++c) s.medium.sigma_s[c] = 1.0f + 0.2f * (float)c, s.medium.sigma_a[c] = 0.1f;
    s.medium.phase = (veil_phase){.type = VEIL_PHASE_HG, .g = 0.5f};
    s.medium.sources = &fog;
    s.medium.source_count = 1;
    veil_multiple_defaults(&s.multiple);
    GLuint opv[VEIL_MAX_OPV_TEXTURES] = {0};
    veil_volumetric_desc vd = {.kind = VEIL_FIELD_CACHE,
                               .medium = {.scene = &s, .lights = lights, .light_count = 2, .opv = opv},
                               .cache = {.photons = 1 << 15, .cells = 12, .seed = 7}};
    float* out[3] = {NULL, NULL, NULL};
    int dims[3] = {0, 0, 0};
    for (int run = 0; run < 3; ++run) {
        vd.cache.seed = run < 2 ? 7u : 8u;
        veil_volumetric_field f;
        veil_volumetric_report rep;
        CHECK(veil_volumetric_update(d, &vd, 200 + (uint64_t)run, &f, &rep, &err) == VEIL_OK, "%s", err.msg);
        CHECK(rep.cache.photons >= (1 << 15) - 2 && rep.cache.sources == 2 && rep.cache.cut == 0 &&
                  rep.cache.clamped == 0 && rep.cache.misses == 0,
              "run %d: %lld photons from %d sources, %u cut, %u clamped, %u majorant misses", run, rep.cache.photons,
              rep.cache.sources, rep.cache.cut, rep.cache.clamped, rep.cache.misses);
        out[run] = veil_volumetric_readback(d, dims);
        CHECK(out[run] != NULL, "the cache was read back (run %d)", run);
        if (run == 0) {
            /* the flux: finite, and along the sun's travel on the whole (its mean against the sun's direction) */
            float* F = veil_volumetric_readback_flux(d, dims);
            CHECK(F != NULL, "the flux was read back");
            double along = 0.0;
            int finite = 1;
            for (size_t i = 0; F && i < (size_t)dims[0] * dims[1] * dims[2]; ++i) {
                finite &= isfinite(F[4 * i]) && isfinite(F[4 * i + 1]) && isfinite(F[4 * i + 2]);
                along += F[4 * i] * lights[0].direction[0] + F[4 * i + 1] * lights[0].direction[1] +
                         F[4 * i + 2] * lights[0].direction[2];
            }
            CHECK(finite && along > 0.0, "the flux is finite and runs with the sun (sum of F . sun %g)", along);
            free(F);
        }
    }
    if (out[0] && out[1] && out[2]) {
        size_t bytes = (size_t)dims[0] * dims[1] * dims[2] * 4 * sizeof(float);
        double sum = 0.0;
        int finite = 1;
        for (size_t i = 0; i < bytes / sizeof(float); ++i) {
            finite &= isfinite(out[0][i]) && out[0][i] >= 0.0f;
            sum += out[0][i];
        }
        CHECK(finite && sum > 0.0, "the fluence is finite, >= 0 and not all 0 (sum %g)", sum);
        CHECK(memcmp(out[0], out[1], bytes) == 0, "the same seed gave another cache");
        CHECK(memcmp(out[0], out[2], bytes) != 0, "another seed gave the same cache");
        printf("determinism: seed 7 twice bit-identical (%dx%dx%d cells), seed 8 differs\n", dims[0], dims[1], dims[2]);
    }
    for (int i = 0; i < 3; ++i) free(out[i]);
}

static double image_mean(const float* rgba, int n, int stride)
{
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += rgba[stride * i] + rgba[stride * i + 1] + rgba[stride * i + 2];
    return sum / (3.0 * n);
}

static void no_double_count(veil_gl* gl)
{
    veil_error err = {0};
    veil_source fog = fog_box();
    veil_light sun = {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0.3f, -0.8f, 0.5f}, .color = {3, 3, 3}};
    float n = sqrtf(0.09f + 0.64f + 0.25f);
    for (int a = 0; a < 3; ++a) sun.direction[a] /= n;
    veil_scene s = {0};
    s.camera = (veil_camera){.position = {0, 0.5f, 4.5f}, .look_at = {0, 0, 0}, .up = {0, 1, 0}, .fov_y_deg = 34,
                             .width = 24, .height = 18};
    for (int c = 0; c < 3; ++c) s.medium.sigma_s[c] = 1.0f, s.medium.sigma_a[c] = 0.05f;
    s.medium.phase = (veil_phase){.type = VEIL_PHASE_ISOTROPIC};
    s.medium.sources = &fog;
    s.medium.source_count = 1;
    s.lights = &sun;
    s.light_count = 1;
    veil_multiple_defaults(&s.multiple);
    s.multiple.screen_space = 0;
    s.multiple.volumetric_method = VEIL_VOLUMETRIC_CACHE;
    s.multiple.cache_photons = 1 << 19;
    s.multiple.cache_cells = 24;
    const int pixels = s.camera.width * s.camera.height;

    /* the reference, all orders */
    veil_pt_medium* m = NULL;
    float *ref = NULL, *se = NULL;
    CHECK(veil_pt_medium_from_scene(&s, &m, &err) == VEIL_OK, "%s", err.msg);
    veil_pt_opts o = {.spp = 256, .max_order = 0, .seed = 5};
    CHECK(m && veil_pt_render(m, &s, &o, &ref, &se, NULL, &err) == VEIL_OK, "%s", err.msg);
    veil_pt_medium_free(m);

    veil_renderer* r = NULL;
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    veil_image_set im = {0};
    veil_render_stats st = {0};
    CHECK(r && veil_render_scene_images(r, &s, &(veil_render_opts){.seed = 3}, &im, &st, &err) == VEIL_OK, "%s",
          err.msg);
    if (ref && se && im.rgba) {
        double want = image_mean(ref, pixels, 4), got = image_mean(im.rgba, pixels, 4);
        double single = image_mean(im.aov_s, pixels, 4), multi = image_mean(im.aov_v, pixels, 4);
        double var = 0.0;
        for (int i = 0; i < 3 * pixels; ++i) var += (double)se[i] * se[i];
        double se_mean = sqrt(var) / (3.0 * pixels);
        /* the cache's noise and cell, from its report (the volumetric stage's "why") */
        double noise = 0.0, cell = 0.0;
        const char* why = st.stage[VEIL_STAGE_VOLUMETRIC].why;
        const char* at = strstr(why, "cells of ");
        if (at) cell = atof(at + 9);
        at = strstr(why, "noise ");
        if (at) noise = atof(at + 6) / 100.0;
        CHECK(cell > 0.0 && noise > 0.0, "the volumetric stage reports the cache: %s", why);
        double tol = 4.0 * sqrt(se_mean * se_mean + noise * multi * noise * multi) +
                     0.5 * (1.0 - exp(-1.05 * cell)) * multi;
        CHECK(single > 3.0 * tol, "the single scattering (mean %.5g) is far above the bound %.3g", single, tol);
        CHECK(fabs(got - want) <= tol,
              "march + cache mean %.6g vs all orders %.6g: off by %.3g > %.3g (single %.5g, cache %.5g)", got, want,
              got - want, tol, single, multi);
        printf("no double counting: march + cache %.6g, reference %.6g (se %.2g), bound %.3g; single %.5g, cache "
               "%.5g (noise %.2g %% a cell, cells of %.3g m)\n",
               got, want, se_mean, tol, single, multi, 100 * noise, cell);
    }
    veil_image_set_free(&im);
    veil_renderer_destroy(r);
    free(ref);
    free(se);
}

int main(void)
{
    fixed_point();
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_volumetric* d = NULL;
    CHECK(veil_volumetric_create(&d, &err) == VEIL_OK, "%s", err.msg);
    if (d) determinism(d);
    veil_volumetric_destroy(d);
    no_double_count(gl);
    veil_gl_destroy(gl);
    return check_finish();
}
