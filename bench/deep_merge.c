/* veil bench — deep images (render/deep.h): their cost beside the flat
 * image, and what merging to a cap loses (docs/accuracy.md, "Deep images"):
 *
 *     build/bench/deep_merge SCENE.json [WxH] [OUT_DIR]
 *
 * Time: the march without and with deep samples (cap 8), alternating, 3
 * runs each, the median; the deep step's CPU time (spreading the flat
 * light, merging, measuring); the files' sizes (the flat EXR, R, G, B, A, ZIP;
 * the deep EXR, ZIPS), written to OUT_DIR (default /tmp) and removed.
 * Merge error: the frame marched once with 64 raw samples a pixel
 * (VEIL_DEEP_MAX_RAW, kept whole: cap 64), then merged to caps 1, 2, 4, 8
 * and 16 from those same samples: the holdout error of each against them,
 * at their depths (veil_deep_report), so every cap is measured against one
 * ruler. (veil render --stats measures each cap against its own 4 x cap raw
 * samples.) */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/clock.h"
#include "frame/renderer.h"
#include "io/exr_deep.h"
#include "io/scene.h"
#include "render/deep.h"

enum { RUNS = 3 };

static int cmp(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

static long long size_of(const char* path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long long)st.st_size : -1;
}

static veil_result copy_deep(const veil_deep_image* a, veil_deep_image* b, veil_error* err)
{
    const size_t pixels = (size_t)a->width * (size_t)a->height;
    *b = (veil_deep_image){.width = a->width, .height = a->height, .total = a->total};
    b->counts = malloc(pixels * sizeof *b->counts);
    b->samples = malloc(a->total * VEIL_DEEP_CHANNELS * sizeof *b->samples + 1);
    if (!b->counts || !b->samples) return veil_fail(err, VEIL_ERR_OOM, "out of memory copying a deep image");
    memcpy(b->counts, a->counts, pixels * sizeof *b->counts);
    memcpy(b->samples, a->samples, a->total * VEIL_DEEP_CHANNELS * sizeof *b->samples);
    return VEIL_OK;
}

int main(int argc, char** argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: deep_merge SCENE.json [WxH] [OUT_DIR]\n");
        return 2;
    }
    int w = 640, h = 480;
    if (argc > 2 && sscanf(argv[2], "%dx%d", &w, &h) != 2) return 2;
    const char* dir = argc > 3 ? argv[3] : "/tmp";
    veil_error err = {0};
    veil_scene s;
    veil_gl* gl = NULL;
    veil_renderer* r = NULL;
    veil_image_set im = {0};
    veil_render_stats st;
    veil_result res = veil_scene_load(argv[1], &s, &err);
    if (res == VEIL_OK) res = veil_gl_create(NULL, &gl, &err);
    if (res == VEIL_OK) res = veil_renderer_create(gl, &r, &err);
    /* once unmeasured: the volume, optical depths and light cache are kept for the runs after (they do not
     * depend on the deep image), and both march programs are compiled */
    for (int deep = 0; deep < 2 && res == VEIL_OK; ++deep)
        res = veil_render_scene_images(r, &s, &(veil_render_opts){.width = w, .height = h, .deep = deep}, &im, &st, &err);
    double march[2][RUNS], deep_ms[RUNS];
    for (int k = 0; k < RUNS && res == VEIL_OK; ++k)
        for (int deep = 0; deep < 2 && res == VEIL_OK; ++deep) {
            res = veil_render_scene_images(r, &s, &(veil_render_opts){.width = w, .height = h, .deep = deep}, &im, &st,
                                           &err);
            march[deep][k] = st.stage[VEIL_STAGE_RENDER].ms;
            if (deep) deep_ms[k] = st.deep.ms;
        }
    char flat_path[4096], deep_path[4096];
    snprintf(flat_path, sizeof flat_path, "%s/veil_deep_bench_%ld.exr", dir, (long)getpid());
    snprintf(deep_path, sizeof deep_path, "%s/veil_deep_bench_%ld_deep.exr", dir, (long)getpid());
    double t_flat = veil_now_ms();
    if (res == VEIL_OK) res = veil_write_exr(flat_path, w, h, im.rgba, &err);
    t_flat = veil_now_ms() - t_flat;
    double t_deep = veil_now_ms();
    if (res == VEIL_OK) res = veil_write_deep_exr(deep_path, &im.deep, NULL, &err);
    t_deep = veil_now_ms() - t_deep;
    const long long flat_bytes = size_of(flat_path), deep_bytes = size_of(deep_path);
    if (res == VEIL_OK) {
        qsort(march[0], RUNS, sizeof(double), cmp);
        qsort(march[1], RUNS, sizeof(double), cmp);
        qsort(deep_ms, RUNS, sizeof(double), cmp);
        printf("%dx%d, %s: median of %d runs\n", w, h, argv[1], RUNS);
        printf("march, flat             %9.0f ms\n", march[0][RUNS / 2]);
        printf("march, deep samples     %9.0f ms  (x%.2f; raw samples: %zu, at most %d a pixel)\n", march[1][RUNS / 2],
               march[1][RUNS / 2] / march[0][RUNS / 2], st.deep.raw, st.deep.max_raw);
        printf("deep step (CPU)         %9.0f ms  (spread flat light, merge to 8, measure)\n", deep_ms[RUNS / 2]);
        printf("flat EXR (RGBA, ZIP)    %9.2f MiB, written in %.0f ms\n", flat_bytes / 1048576.0, t_flat);
        printf("deep EXR (cap 8, ZIPS)  %9.2f MiB, written in %.0f ms; %zu samples (%.2f a pixel)\n",
               deep_bytes / 1048576.0, t_deep, im.deep.total, (double)im.deep.total / ((double)w * h));
    }
    unlink(flat_path);
    unlink(deep_path);
    /* the merge from one set of 64 raw samples a pixel */
    if (res == VEIL_OK)
        res = veil_render_scene_images(r, &s, &(veil_render_opts){.width = w, .height = h, .deep = 1, .deep_samples = 64},
                                       &im, &st, &err);
    if (res == VEIL_OK) {
        printf("\nmerged from %zu raw samples (at most %d a pixel), holdout error against them at their depths:\n",
               im.deep.total, st.deep.max_raw);
        printf("cap  samples  a pixel  deep EXR MiB  alpha max  alpha mean  colour mean  merge ms\n");
    }
    const int caps[] = {1, 2, 4, 8, 16};
    for (int i = 0; i < 5 && res == VEIL_OK; ++i) {
        veil_deep_image d;
        veil_deep_report rep;
        res = copy_deep(&im.deep, &d, &err);
        if (res == VEIL_OK) res = veil_deep_finish(&d, im.rgba, im.aov_t, s.background, im.behind, caps[i], &rep, &err);
        if (res == VEIL_OK) res = veil_write_deep_exr(deep_path, &d, NULL, &err);
        if (res == VEIL_OK)
            printf("%3d  %7zu  %7.2f  %12.2f  %9.4f  %10.5f  %11.4f  %8.0f\n", caps[i], d.total,
                   (double)d.total / ((double)w * h), size_of(deep_path) / 1048576.0, rep.holdout_alpha_max,
                   rep.holdout_alpha_mean, rep.holdout_color_mean, rep.ms);
        unlink(deep_path);
        veil_deep_image_free(&d);
    }
    veil_image_set_free(&im);
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
    veil_scene_free(&s);
    if (res != VEIL_OK) {
        fprintf(stderr, "deep_merge: %s\n", err.msg);
        return 1;
    }
    return 0;
}
