/* veil reference SCENE.json -o REF.exr --spp N [--max-order K] [--width W]
 *                [--height H] [--seed N] [--threads T]
 *                [--light-sampling distance|mis] [--background backdrop|lights]
 *
 * Renders the scene with the CPU path tracer (reference/pathtracer.h) and
 * writes an EXR with R, G, B, A and the standard error of each mean
 * (stderr.R, stderr.G, stderr.B), and stderr.bound: 1 where that error is
 * a bound, not a sample estimate (reference/pathtracer.h). On a terminal,
 * stderr shows a progress bar with the estimated time left.
 */
#define _POSIX_C_SOURCE 200809L /* fileno, isatty */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli_util.h"
#include "commands.h"
#include "io/image.h"
#include "io/scene.h"
#include "reference/pathtracer.h"

typedef struct ref_args {
    const char *scene, *exr;
    long spp, max_order, width, height, seed, threads;
    int light_sampling; /* veil_pt_light_sampling */
    int environment;    /* --background lights: the background lights the medium (a constant sky) */
} ref_args;

static int parse_args(int argc, char** argv, ref_args* a)
{
    memset(a, 0, sizeof *a);
    for (int i = 2; i < argc; ++i) {
        const char* s = argv[i];
        int takes = s[0] == '-' && s[1];
        const char* v = takes && i + 1 < argc ? argv[i + 1] : NULL;
        if (!takes) {
            if (a->scene) return veil_cli_usage_error("unexpected argument '%s'", s);
            a->scene = s;
            continue;
        }
        if (!v) return veil_cli_usage_error("%s needs a value", s);
        ++i;
        if (!strcmp(s, "-o")) {
            a->exr = v;
        } else if (!strcmp(s, "--spp")) {
            if (!veil_cli_parse_int(v, 2, 1000000, &a->spp))
                return veil_cli_usage_error("--spp: expected samples per pixel in 2..1000000, got '%s'", v);
        } else if (!strcmp(s, "--max-order")) {
            if (!veil_cli_parse_int(v, 0, 1000000, &a->max_order))
                return veil_cli_usage_error("--max-order: expected 0 (unlimited) or an order in 1..1000000, got '%s'", v);
        } else if (!strcmp(s, "--width")) {
            if (!veil_cli_parse_int(v, 1, VEIL_SCENE_MAX_IMAGE, &a->width))
                return veil_cli_usage_error("--width: expected an integer in 1..16384, got '%s'", v);
        } else if (!strcmp(s, "--height")) {
            if (!veil_cli_parse_int(v, 1, VEIL_SCENE_MAX_IMAGE, &a->height))
                return veil_cli_usage_error("--height: expected an integer in 1..16384, got '%s'", v);
        } else if (!strcmp(s, "--seed")) {
            if (!veil_cli_parse_int(v, 0, 4294967295L, &a->seed))
                return veil_cli_usage_error("--seed: expected an integer in 0..4294967295, got '%s'", v);
        } else if (!strcmp(s, "--threads")) {
            if (!veil_cli_parse_int(v, 1, 256, &a->threads))
                return veil_cli_usage_error("--threads: expected an integer in 1..256, got '%s'", v);
        } else if (!strcmp(s, "--light-sampling")) {
            if (!strcmp(v, "distance"))
                a->light_sampling = VEIL_PT_LIGHT_SAMPLING_DISTANCE;
            else if (!strcmp(v, "mis"))
                a->light_sampling = VEIL_PT_LIGHT_SAMPLING_MIS;
            else
                return veil_cli_usage_error("--light-sampling: expected distance or mis, got '%s'", v);
        } else if (!strcmp(s, "--background")) {
            if (!strcmp(v, "backdrop"))
                a->environment = 0;
            else if (!strcmp(v, "lights"))
                a->environment = 1;
            else
                return veil_cli_usage_error("--background: expected backdrop or lights, got '%s'", v);
        } else {
            return veil_cli_usage_error("unknown option '%s'", s);
        }
    }
    if (!a->scene) return veil_cli_usage_error("%s", "reference: missing SCENE.json");
    if (!a->exr) return veil_cli_usage_error("%s", "reference: missing -o REF.exr");
    if (!a->spp) return veil_cli_usage_error("%s", "reference: missing --spp N (samples per pixel, at least 2)");
    return -1;
}

typedef struct progress {
    struct timespec start;
    int last_pct;
} progress;

static double seconds_since(const struct timespec* t0)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)(t.tv_sec - t0->tv_sec) + 1e-9 * (double)(t.tv_nsec - t0->tv_nsec);
}

static void format_duration(double s, char* out, size_t n)
{
    long v = (long)(s + 0.5);
    if (v >= 3600)
        snprintf(out, n, "%ldh%02ldm", v / 3600, v / 60 % 60);
    else if (v >= 60)
        snprintf(out, n, "%ldm%02lds", v / 60, v % 60);
    else
        snprintf(out, n, "%lds", v);
}

/* "[#########...........]  45%  12s elapsed, ETA 15s", redrawn in place. */
static void show_progress(void* user, int done, int total)
{
    progress* p = user;
    double el = seconds_since(&p->start);
    int pct = (int)(100.0 * done / total);
    char bar[41], e[32], left[32];
    int fill = (int)(40.0 * done / total);
    for (int i = 0; i < 40; ++i) bar[i] = i < fill ? '#' : '.';
    bar[40] = '\0';
    format_duration(el, e, sizeof e);
    if (done > 0)
        format_duration(el * (total - done) / done, left, sizeof left);
    else
        snprintf(left, sizeof left, "?");
    fprintf(stderr, "\r[%s] %3d%%  %s elapsed, ETA %s   ", bar, pct, e, left);
    if (done == total) fputc('\n', stderr);
    fflush(stderr);
    p->last_pct = pct;
}

int veil_cmd_reference(int argc, char** argv)
{
    ref_args a;
    int code = parse_args(argc, argv, &a);
    if (code >= 0) return code;
    veil_error err = {0};
    veil_scene scene;
    veil_result r = veil_scene_load(a.scene, &scene, &err);
    if (r != VEIL_OK) return veil_cli_fail(r, &err);
    /* -o against the scene and what it reads (cli/run_files.h), then its folder, made */
    int n_files = 0;
    veil_run_file* files = veil_cli_scene_inputs(a.scene, &scene, 0, 1, &n_files);
    if (!files) {
        veil_scene_free(&scene);
        return veil_cli_fail(veil_fail(&err, VEIL_ERR_OOM, "out of memory"), &err);
    }
    files[n_files++] = (veil_run_file){.what = "-o", .path = a.exr, .writes = 1};
    veil_cli_folders made = {0};
    code = veil_cli_check_run(files, n_files, NULL);
    if (code == EXIT_OK) {
        r = veil_cli_make_folders(files, n_files, NULL, &made, &err);
        if (r != VEIL_OK) code = veil_cli_fail(r, &err);
    }
    free(files);
    if (code != EXIT_OK) {
        veil_scene_free(&scene);
        return code;
    }
    veil_pt_medium* m = NULL;
    r = veil_pt_medium_from_scene(&scene, &m, &err);
    if (r != VEIL_OK) veil_cli_prefix_error(&err, a.scene);
    progress prog = {{0, 0}, -1};
    clock_gettime(CLOCK_MONOTONIC, &prog.start);
    veil_pt_opts o = {0};
    o.width = (int)a.width;
    o.height = (int)a.height;
    o.spp = (int)a.spp;
    o.max_order = (int)a.max_order;
    o.seed = (uint64_t)a.seed;
    o.threads = (int)a.threads;
    o.light_sampling = a.light_sampling;
    o.environment = a.environment;
    if (isatty(fileno(stderr))) {
        o.progress = show_progress;
        o.progress_user = &prog;
    }
    float *rgba = NULL, *se = NULL;
    veil_pt_stats st = {0};
    int w = a.width ? (int)a.width : scene.camera.width, h = a.height ? (int)a.height : scene.camera.height;
    unsigned char* bound = r == VEIL_OK ? calloc((size_t)w * (size_t)h, 1) : NULL;
    if (r == VEIL_OK && !bound) r = veil_fail(&err, VEIL_ERR_OOM, "out of memory for a %dx%d image", w, h);
    o.unresolved = bound;
    if (r == VEIL_OK) r = veil_pt_render(m, &scene, &o, &rgba, &se, &st, &err);
    if (r == VEIL_OK) {
        size_t n = (size_t)w * (size_t)h;
        enum { PLANES = 8 };
        float* planes[PLANES];
        for (int c = 0; c < PLANES; ++c) planes[c] = malloc(n * sizeof(float));
        int ok = 1;
        for (int c = 0; c < PLANES; ++c) ok &= planes[c] != NULL;
        if (!ok) {
            r = veil_fail(&err, VEIL_ERR_OOM, "out of memory for a %dx%d image", w, h);
        } else {
            for (size_t i = 0; i < n; ++i) {
                for (int c = 0; c < 4; ++c) planes[c][i] = rgba[4 * i + (size_t)c];
                for (int c = 0; c < 3; ++c) planes[4 + c][i] = se[3 * i + (size_t)c];
                planes[7][i] = bound[i] ? 1.0f : 0.0f;
            }
            static const char* const names[PLANES] = {"R", "G", "B", "A", "stderr.R", "stderr.G", "stderr.B",
                                                      "stderr.bound"};
            r = veil_write_exr_planes(a.exr, w, h, PLANES, names, (const float* const*)planes, &err);
        }
        for (int c = 0; c < PLANES; ++c) free(planes[c]);
    }
    free(bound);
    if (r == VEIL_OK) {
        /* the noise level: mean standard error over the mean value, per channel mean */
        double sum = 0.0, sum_se = 0.0;
        for (size_t i = 0; i < (size_t)w * (size_t)h; ++i)
            for (int c = 0; c < 3; ++c) {
                sum += rgba[4 * i + (size_t)c];
                sum_se += se[3 * i + (size_t)c];
            }
        printf("wrote %s (%dx%d, %ld spp, max order %ld%s, %s light sampling) in %.2f s\n", a.exr, w, h, a.spp,
               a.max_order, a.max_order == 0 ? " = unlimited" : "",
               st.light_sampling == VEIL_PT_LIGHT_SAMPLING_DISTANCE ? "distance" : "MIS", st.ms / 1000.0);
        printf("  mean standard error / mean value: %.3g\n", sum > 0.0 ? sum_se / sum : 0.0);
        printf("  %llu paths, %llu tentative collisions, %llu cut walks, %llu dropped samples\n",
               (unsigned long long)st.paths, (unsigned long long)st.collisions, (unsigned long long)st.cut_walks,
               (unsigned long long)st.dropped_samples);
        if (st.unresolved_pixels)
            printf("  %llu pixels with all samples equal: their standard error is a bound (reference/pathtracer.h)\n",
                   (unsigned long long)st.unresolved_pixels);
    }
    free(rgba);
    free(se);
    veil_pt_medium_free(m);
    veil_scene_free(&scene);
    veil_cli_folders_done(&made, r == VEIL_OK);
    return r == VEIL_OK ? EXIT_OK : veil_cli_fail(r, &err);
}
