/* veil bench — the screen-space spread's MIP chains against the gathering
 * filter (reference/gather.h: the exact spatially varying Gaussian), on the
 * march's buffers of a real scene, apart from the model's error:
 *
 *     build/bench/spread_gather SCENE.json [WxH]
 *
 * The scene is rendered with the volumetric estimate off (so that the
 * spread moves single scattering's out-scattered light, L_sc with its W in
 * pixels). For each filter size and interpolation the spread runs on the
 * same buffers; its level 0 (L_sc, W) is spread again by the gathering
 * filter, with W clamped to c 2^K as the chains clamp it (level K is the
 * widest blur they hold). Printed: the median time of 3 runs of the MIP pass (ms, GPU work
 * and read-back included), the gathering filter's time, and the relative
 * RMSE and mean bias of the MIP result against the gathering result.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "frame/renderer.h"
#include "io/scene.h"
#include "reference/gather.h"
#include "render/spread.h"

static int cmp(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

int main(int argc, char** argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: spread_gather SCENE.json [WxH]\n");
        return 2;
    }
    int w = 160, h = 120;
    if (argc > 2 && sscanf(argv[2], "%dx%d", &w, &h) != 2) return 2;
    veil_error err = {0};
    veil_scene s;
    if (veil_scene_load(argv[1], &s, &err) != VEIL_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    s.multiple.volumetric = 0;
    s.multiple.screen_space = 0; /* the renderer's own spread off: we run it here */
    veil_gl* gl = NULL;
    veil_renderer* r = NULL;
    veil_spread* sp = NULL;
    veil_image_set im = {0};
    if (veil_gl_create(NULL, &gl, &err) != VEIL_OK || veil_renderer_create(gl, &r, &err) != VEIL_OK ||
        veil_spread_create(&sp, &err) != VEIL_OK ||
        veil_render_scene_images(r, &s, &(veil_render_opts){.width = w, .height = h}, &im, NULL, &err) != VEIL_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    size_t n = (size_t)w * (size_t)h;
    float* out = malloc(n * 4 * sizeof *out);
    float* level0 = malloc(n * 4 * sizeof *level0);
    float* Ws = malloc(n * sizeof *Ws);
    float* gathered = malloc(n * 4 * sizeof *gathered);
    static const char* const filters[] = {"2x2", "4x4", "6x6"};
    static const char* const interps[] = {"linear-bilinear", "linear-bicubic", "cubic-bicubic"};
    printf("# %s at %dx%d: MIP chains vs the gathering filter on the same L_sc and W\n", argv[1], w, h);
    printf("| filter | interpolation | MIP pass (ms) | gathering (ms) | rel. RMSE vs gathering | mean bias |\n"
           "|---|---|---:|---:|---:|---:|\n");
    for (int f = 0; f < 3; ++f)
        for (int m = 0; m < 3; ++m) {
            s.multiple.filter = (veil_spread_filter)f;
            veil_spread_default_weights(s.multiple.filter, s.multiple.weights);
            s.multiple.interp = m;
            veil_spread_input in = {.width = w, .height = h, .aov_t = im.aov_t, .aov_s = im.aov_s,
                                    .aov_q = im.aov_q, .fov_y_deg = s.camera.fov_y_deg};
            double t[3];
            for (int k = 0; k < 3; ++k) {
                veil_spread_report rep = {0};
                if (veil_spread_run(sp, &s, &in, out, level0, &rep, &err) != VEIL_OK) {
                    fprintf(stderr, "%s\n", err.msg);
                    return 1;
                }
                t[k] = rep.ms;
            }
            qsort(t, 3, sizeof *t, cmp);
            /* the chains end at level K: a wider spread reads level K, whose blur is about c 2^K; the
             * gathering filter gets the same clamp, so that only the approximation is compared */
            int K = veil_spread_levels(&s.multiple, w, h);
            float wmax = s.multiple.c * (float)(1 << K);
            for (size_t i = 0; i < n; ++i) Ws[i] = fminf(level0[4 * i + 3], wmax);
            double t0 = veil_now_ms();
            if (veil_gather_spread(w, h, level0, Ws, gathered, &err) != VEIL_OK) {
                fprintf(stderr, "%s\n", err.msg);
                return 1;
            }
            double tg = veil_now_ms() - t0;
            double num = 0, den = 0, sa = 0, sb = 0;
            for (size_t i = 0; i < n; ++i)
                for (int c = 0; c < 3; ++c) {
                    double d = out[4 * i + c] - gathered[4 * i + c];
                    num += d * d;
                    den += (double)gathered[4 * i + c] * gathered[4 * i + c];
                    sa += out[4 * i + c], sb += gathered[4 * i + c];
                }
            printf("| %s | %s | %.1f | %.0f | %.1f %% | %+.1f %% |\n", filters[f], interps[m], t[1], tg,
                   den > 0 ? 100.0 * sqrt(num / den) : 0.0, sb > 0 ? 100.0 * (sa / sb - 1.0) : 0.0);
        }
    free(out), free(level0), free(Ws), free(gathered);
    veil_image_set_free(&im);
    veil_spread_destroy(sp);
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
    veil_scene_free(&s);
    return 0;
}
