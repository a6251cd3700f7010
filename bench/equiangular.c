/* veil benchmark — equiangular sampling with MIS against distance sampling
 * alone in the reference path tracer (reference/pathtracer.h), at equal
 * time. Not part of ctest (docs/accuracy.md has its numbers).
 *
 *   equiangular [--spp N] [--size WxH] [--max-order K] [--threads T]
 *               [--runs R] [--ref-factor F] [--scenes demo,cloud]
 *               [--source-dir DIR]
 *
 * Scenes: `demo` is data/scenes/demo.json (two point lights inside an RBF
 * cloud, a sun); `cloud` is a sunlit Gaussian blob (albedo 0.976, HG
 * g = 0.5, optical depth ~4.6 through its centre) with a point light inside
 * it, defined below.
 *
 * Per scene: a reference (MIS, F x N samples, seed 7), then R renders of N
 * samples per strategy (distance: light_sampling DISTANCE; mis: the
 * default), seeds 1000 + i, the strategies alternating so that they see the
 * same load. Measured, over all pixels and channels:
 *  - time: the median wall time of one render (ms);
 *  - MSE(ref): the mean squared difference from the reference, averaged
 *    over the runs (the reference's own variance, printed, is part of it);
 *    max MSE: the worst run; the median run's MSE: the typical image. The
 *    estimators are unbiased, so this is their variance; distance
 *    sampling's is infinite at orders >= 2 near a point light inside a
 *    medium (next-event 1/r^2 at vertices near the light), so its MSE is
 *    heavy-tailed: most runs are low, a few are huge, and the mean over a
 *    few runs is itself a rough number;
 *  - var_split: the mean of (A - B)^2 / 2 over pairs of runs, the same
 *    variance without the reference;
 *  - efficiency = 1 / (variance * time), so the ratio mis / distance is
 *    the variance reduction at equal time (> 1: MIS wins);
 *  - mean se / mean value (as `veil reference` prints; unresolved pixels'
 *    bounds included), the brightest pixel over all runs (max over
 *    channels) with its standard error, where a firefly shows, and the
 *    unresolved pixels (all samples equal) a run.
 * Wall times on a shared machine move by tens of per cent from run to run.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/scene.h"
#include "reference/pathtracer.h"

#ifndef VEIL_SOURCE_DIR
#define VEIL_SOURCE_DIR "."
#endif

/* The sunlit cloud: one Gaussian particle, amplitude 2, sharpness 1.6 m^-1
 * (1/e radius 0.63 m), sigma_t 2.05-2.25 m^-1 per unit density: optical
 * depth sigma_t c sqrt(pi) / s ~ 4.6 through the centre; a point light
 * 0.2 m off the centre, a sun from the upper right. */
static const char* const cloud_json =
    "{\"camera\":{\"position\":[0,0.3,3.2],\"look_at\":[0,0,0],\"fov_y_deg\":40,\"width\":64,\"height\":48},"
    "\"medium\":{\"sigma_a\":[0.05,0.05,0.05],\"sigma_s\":[2.0,2.1,2.2],\"phase\":{\"type\":\"hg\",\"g\":0.5},"
    "\"max_resolution\":64,\"sources\":[{\"type\":\"rbf\",\"particles\":[{\"center\":[0,0,0],\"amplitude\":2.0,"
    "\"sharpness\":1.6}]}]},"
    "\"lights\":[{\"type\":\"directional\",\"direction\":[0.3,-0.8,0.5],\"irradiance\":[3,3,2.8]},"
    "{\"type\":\"point\",\"position\":[0.15,-0.1,0.1],\"intensity\":[4,2.5,1.2]}],"
    "\"background\":{\"color\":[0.05,0.07,0.1]}}";

#define MAX_RUNS 32

typedef struct run {
    double ms[MAX_RUNS], mse[MAX_RUNS];
    double time_ms, mean, mean_se, var_split, mse_ref, mse_median, mse_max, max_v, max_se;
    int max_x, max_y;
    unsigned long long unresolved;
} run;

typedef struct bench_opts {
    int spp, w, h, max_order, threads, ref_factor, runs;
    const char* scenes;
    const char* source_dir;
} bench_opts;

static int render(const veil_pt_medium* m, const veil_scene* s, const bench_opts* b, int spp, int sampling,
                  uint64_t seed, float** rgba, float** se, veil_pt_stats* st)
{
    veil_pt_opts o = {0};
    o.width = b->w;
    o.height = b->h;
    o.spp = spp;
    o.max_order = b->max_order;
    o.seed = seed;
    o.threads = b->threads;
    o.light_sampling = sampling;
    veil_error err = {0};
    if (veil_pt_render(m, s, &o, rgba, se, st, &err) != VEIL_OK) {
        fprintf(stderr, "equiangular: %s\n", err.msg);
        return 0;
    }
    if (st->cut_walks || st->dropped_samples || st->majorant_misses)
        fprintf(stderr, "equiangular: %llu cut walks, %llu dropped samples, %llu majorant misses\n",
                (unsigned long long)st->cut_walks, (unsigned long long)st->dropped_samples,
                (unsigned long long)st->majorant_misses);
    return 1;
}

static int cmp_double(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

/* Both strategies on one scene: the reference, then `runs` renders per
 * strategy with seeds 1000 + i, the strategies alternating. */
static int bench_scene(const char* name, const veil_scene* s, const bench_opts* b)
{
    veil_pt_medium* m = NULL;
    veil_error err = {0};
    if (veil_pt_medium_from_scene(s, &m, &err) != VEIL_OK) {
        fprintf(stderr, "equiangular: %s: %s\n", name, err.msg);
        return 0;
    }
    static const int sampling[2] = {VEIL_PT_LIGHT_SAMPLING_DISTANCE, VEIL_PT_LIGHT_SAMPLING_MIS};
    static const char* const label[2] = {"distance", "mis"};
    const size_t n = (size_t)b->w * (size_t)b->h;
    const double cnt = 3.0 * (double)n;
    float *ref = NULL, *ref_se = NULL, *prev[2] = {NULL, NULL};
    run r[2];
    memset(r, 0, sizeof r);
    r[0].max_v = r[1].max_v = -1.0;
    veil_pt_stats st = {0};
    int ok = render(m, s, b, b->spp * b->ref_factor, VEIL_PT_LIGHT_SAMPLING_MIS, 7, &ref, &ref_se, &st);
    double ref_ms = st.ms, ref_var = 0.0, ref_mean = 0.0;
    for (size_t i = 0; ok && i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            ref_var += (double)ref_se[3 * i + (size_t)c] * ref_se[3 * i + (size_t)c] / cnt;
            ref_mean += ref[4 * i + (size_t)c] / cnt;
        }
    for (int run_i = 0; run_i < b->runs && ok; ++run_i)
        for (int k = 0; k < 2 && ok; ++k) {
            float *img = NULL, *se = NULL;
            ok = render(m, s, b, b->spp, sampling[k], 1000 + (uint64_t)run_i, &img, &se, &st);
            if (!ok) break;
            run* q = &r[k];
            q->ms[run_i] = st.ms;
            q->unresolved += (unsigned long long)st.unresolved_pixels;
            double mse = 0.0;
            for (size_t i = 0; i < n; ++i)
                for (int c = 0; c < 3; ++c) {
                    size_t at = 4 * i + (size_t)c;
                    double v = img[at], e = se[3 * i + (size_t)c];
                    mse += (v - ref[at]) * (v - ref[at]) / cnt;
                    q->mean += v / cnt / b->runs;
                    q->mean_se += e / cnt / b->runs;
                    if (prev[k] && run_i % 2 == 1) /* independent pairs: E (A - B)^2 / 2 = variance */
                        q->var_split += 0.5 * (v - prev[k][at]) * (v - prev[k][at]) / cnt / (b->runs / 2);
                    if (v > q->max_v) {
                        q->max_v = v;
                        q->max_se = e;
                        q->max_x = (int)(i % (size_t)b->w);
                        q->max_y = (int)(i / (size_t)b->w);
                    }
                }
            q->mse[run_i] = mse;
            q->mse_ref += mse / b->runs;
            q->mse_max = mse > q->mse_max ? mse : q->mse_max;
            free(prev[k]);
            prev[k] = img;
            free(se);
        }
    if (ok) {
        for (int k = 0; k < 2; ++k) { /* the median time: robust to a busy moment of a shared machine */
            double t[MAX_RUNS];
            memcpy(t, r[k].ms, sizeof t);
            qsort(t, (size_t)b->runs, sizeof t[0], cmp_double);
            r[k].time_ms = b->runs % 2 ? t[b->runs / 2] : 0.5 * (t[b->runs / 2 - 1] + t[b->runs / 2]);
            memcpy(t, r[k].mse, sizeof t);
            qsort(t, (size_t)b->runs, sizeof t[0], cmp_double);
            r[k].mse_median = b->runs % 2 ? t[b->runs / 2] : 0.5 * (t[b->runs / 2 - 1] + t[b->runs / 2]);
        }
        printf("%s (%dx%d, %d spp, max order %d%s, %d threads, %d runs a strategy):\n", name, b->w, b->h, b->spp,
               b->max_order, b->max_order == 0 ? " = all" : "", b->threads, b->runs);
        printf("  reference: MIS, %d spp, %.1f s; mean %.4g, mean se^2 %.3g (part of every MSE below)\n",
               b->spp * b->ref_factor, ref_ms / 1e3, ref_mean, ref_var);
        printf("  %-9s %8s %8s %8s %8s %10s %10s %10s %9s %9s  %s\n", "strategy", "time ms", "mean", "mean se",
               "se/mean", "var_split", "MSE(ref)", "max MSE", "eff_split", "eff_ref",
               "brightest pixel +- se (all runs), unresolved pixels a run");
        for (int k = 0; k < 2; ++k)
            printf("  %-9s %8.0f %8.4g %8.3g %8.3g %10.4g %10.4g %10.4g %9.3g %9.3g  %.4g +- %.3g at (%d, %d), %.0f\n",
                   label[k], r[k].time_ms, r[k].mean, r[k].mean_se, r[k].mean_se / r[k].mean, r[k].var_split,
                   r[k].mse_ref, r[k].mse_max, 1e3 / (r[k].var_split * r[k].time_ms),
                   1e3 / (r[k].mse_ref * r[k].time_ms), r[k].max_v, r[k].max_se, r[k].max_x, r[k].max_y,
                   (double)r[k].unresolved / b->runs);
        printf("  MSE per run:");
        for (int k = 0; k < 2; ++k) {
            printf(" %s", label[k]);
            for (int i = 0; i < b->runs; ++i) printf(" %.3g", r[k].mse[i]);
            printf(k ? "\n" : ";");
        }
        printf("  mis / distance: time %.2fx; efficiency 1 / (variance * time): %.2fx by the A-B split, %.2fx by the "
               "MSE against the reference, %.2fx by the median run's MSE\n",
               r[1].time_ms / r[0].time_ms, (r[0].var_split * r[0].time_ms) / (r[1].var_split * r[1].time_ms),
               (r[0].mse_ref * r[0].time_ms) / (r[1].mse_ref * r[1].time_ms),
               (r[0].mse_median * r[0].time_ms) / (r[1].mse_median * r[1].time_ms));
    }
    free(prev[0]);
    free(prev[1]);
    free(ref);
    free(ref_se);
    veil_pt_medium_free(m);
    return ok;
}

static void usage(FILE* f)
{
    fprintf(f, "usage: equiangular [--spp N] [--size WxH] [--max-order K] [--threads T] [--runs R] [--ref-factor F]\n"
               "                   [--scenes demo,cloud] [--source-dir DIR]\n");
}

int main(int argc, char** argv)
{
    bench_opts b = {64, 64, 48, 0, 2, 16, 4, "demo,cloud", VEIL_SOURCE_DIR};
    for (int i = 1; i < argc; ++i) {
        const char* a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage(stdout);
            return 0;
        }
        if (i + 1 >= argc) {
            usage(stderr);
            return 2;
        }
        const char* v = argv[++i];
        if (!strcmp(a, "--spp")) {
            b.spp = atoi(v);
        } else if (!strcmp(a, "--size")) {
            if (sscanf(v, "%dx%d", &b.w, &b.h) != 2) b.w = 0;
        } else if (!strcmp(a, "--max-order")) {
            b.max_order = atoi(v);
        } else if (!strcmp(a, "--threads")) {
            b.threads = atoi(v);
        } else if (!strcmp(a, "--runs")) {
            b.runs = atoi(v);
        } else if (!strcmp(a, "--ref-factor")) {
            b.ref_factor = atoi(v);
        } else if (!strcmp(a, "--scenes")) {
            b.scenes = v;
        } else if (!strcmp(a, "--source-dir")) {
            b.source_dir = v;
        } else {
            usage(stderr);
            return 2;
        }
    }
    if (b.spp < 2 || b.w < 1 || b.h < 1 || b.w > 4096 || b.h > 4096 || b.max_order < 0 || b.threads < 1 ||
        b.ref_factor < 1 || b.spp > 1000000 / b.ref_factor || b.runs < 2 || b.runs > MAX_RUNS) {
        fprintf(stderr, "equiangular: expected spp >= 2, a size in 1..4096, max order >= 0, threads >= 1, "
                        "ref factor >= 1, spp * ref factor <= 1e6, runs in 2..32\n");
        return 2;
    }
    int ok = 1;
    if (strstr(b.scenes, "demo")) {
        char path[4096];
        snprintf(path, sizeof path, "%s/data/scenes/demo.json", b.source_dir);
        veil_scene s;
        veil_error err = {0};
        if (veil_scene_load(path, &s, &err) != VEIL_OK) {
            fprintf(stderr, "equiangular: %s\n", err.msg);
            return 1;
        }
        ok &= bench_scene("demo (data/scenes/demo.json)", &s, &b);
        veil_scene_free(&s);
    }
    if (strstr(b.scenes, "cloud")) {
        veil_scene s;
        veil_error err = {0};
        if (veil_scene_parse("cloud.json", cloud_json, strlen(cloud_json), &s, &err) != VEIL_OK) {
            fprintf(stderr, "equiangular: %s\n", err.msg);
            return 1;
        }
        ok &= bench_scene("sunlit cloud (Gaussian blob, point light inside)", &s, &b);
        veil_scene_free(&s);
    }
    return ok ? 0 : 1;
}
