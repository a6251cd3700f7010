/* veil — run time against error of the fast GPU path (single scattering:
 * inject, propagate, march), against the CPU reference path tracer.
 *
 *   accuracy [--quick] [--out DIR] [--runs N] [--spp N] [--scenes a,b,c]
 *            [--size WxH] [--ref-res N] [--metric pixel|bin] [--cache DIR | --no-cache]
 *
 * Per scene (bench/accuracy_scenes.h: homogeneous, rbf-fog, vdb-smoke) the
 * fast path's quality settings are swept one knob at a time around the
 * default (march step 0.5 voxel, the scene's max_resolution,
 * semi-Lagrangian propagation), plus a few combinations:
 *  - step_voxels (veil_render_opts.step_voxels);
 *  - the EV resolution (medium.max_resolution; for the homogeneous cube the
 *    side of its given grid);
 *  - the propagation method (Jacobi, slow on llvmpipe, only on coarse grids).
 * Time: wall time of veil_render_scene / veil_render_density for one whole
 * frame with nothing cached (before each timed run the renderer's caches
 * are evicted by a 1-pixel render of a 2^3 volume; shaders are warmed up
 * once at start), median of the runs (a setting whose first run takes over
 * REPEAT_LIMIT_MS is not repeated).
 * Error: veil_compare_images(fast, reference) (reference/compare.h): rel_rmse
 * (default floor: 1 % of the reference's mean), max_abs, PSNR. ref_noise is
 * the reference's own noise on the same scale: the rms over pixels and
 * channels of stderr / max(|ref|, floor), so that rel_rmse^2 ~ (true
 * error)^2 + ref_noise^2; rel_rmse_excess is sqrt(rel_rmse^2 - ref_noise^2).
 *
 * Output (DIR default docs/results): accuracy[-quick].csv, .gp (gnuplot
 * script, data inline), .png (when gnuplot is installed), .txt (a copy of
 * stdout: the rows and the per-scene Markdown tables of the Pareto front).
 * Progress on stderr. Exit status: 0, 77 when no GL 4.5 context can be
 * made, 1 on errors (a missing generated VDB says to run `make data`), 2
 * on bad usage. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "reference/compare.h"
#include "gpu/gl_context.h"
#include "gpu/gl_util.h"
#include "frame/renderer.h"

#include "accuracy_report.h"
#include "accuracy_scenes.h"

#ifndef VEIL_SOURCE_DIR
#define VEIL_SOURCE_DIR "."
#endif
#ifndef VEIL_BINARY_DIR
#define VEIL_BINARY_DIR "build"
#endif

#define REPEAT_LIMIT_MS 20000.0
#define MAX_POINTS 48
#define MAX_RUNS 20
#define REF_SEED 0xacc0ffeeULL
#define FAST_SEED 1u

/* Reference samples per pixel by scene (homogeneous, rbf-fog, vdb-smoke),
 * --quick and full: what a few tens of seconds (quick) or a few minutes
 * (full) buy on 2 cores. --spp overrides them. */
static const int default_spp[2][ACC_SCENE_COUNT] = {{16384, 4096, 8192}, {8192, 1024, 2048}};

typedef struct options {
    int quick, runs, spp, width, height, ref_res, no_cache, metric;
    int use[ACC_SCENE_COUNT];
    const char* out_dir;
    const char* cache_dir;
} options;

/* ---- the sweep -------------------------------------------------------------- */

typedef struct point {
    char setting[64];
    float step;
    int res;
    veil_opv_method method;
} point;

static void add_point(point* p, int* n, int default_res, float step, int res, veil_opv_method method)
{
    for (int i = 0; i < *n; ++i)
        if (p[i].step == step && p[i].res == res && p[i].method == method) return;
    if (*n == MAX_POINTS) return;
    point* q = &p[(*n)++];
    q->step = step;
    q->res = res;
    q->method = method;
    char buf[64] = "";
    size_t k = 0;
    if (step != VEIL_DEFAULT_STEP_VOXELS) k += (size_t)snprintf(buf + k, sizeof buf - k, "step=%g", (double)step);
    if (res != default_res) k += (size_t)snprintf(buf + k, sizeof buf - k, "%sres=%d", k ? "+" : "", res);
    if (method != VEIL_OPV_DEFAULT_METHOD)
        snprintf(buf + k, sizeof buf - k, "%s%s", k ? "+" : "", veil_opv_method_name(method));
    snprintf(q->setting, sizeof q->setting, "%s", buf[0] ? buf : "default");
}

/* Each knob around the default, then a few combinations. Jacobi (tens of
 * seconds a light at 128^3 on llvmpipe) only on coarse grids. */
static int make_points(int default_res, int quick, point* p)
{
    const veil_opv_method SL = VEIL_OPV_DEFAULT_METHOD; /* light-space: suns in their grids, the rest semi-Lagrangian */
    const float d = VEIL_DEFAULT_STEP_VOXELS;
    int n = 0;
    add_point(p, &n, default_res, d, default_res, SL);
    add_point(p, &n, default_res, d, default_res, VEIL_OPV_SEMI_LAGRANGIAN); /* the default before issue 13 */
    static const float steps_full[] = {16, 8, 4, 2, 1, 0.25f, 0.125f}, steps_quick[] = {4, 1, 0.25f};
    static const int res_full[] = {32, 64, 128, 256}, res_quick[] = {32, 64};
    const float* steps = quick ? steps_quick : steps_full;
    const int* res = quick ? res_quick : res_full;
    int n_steps = quick ? 3 : 7, n_res = quick ? 2 : 4;
    for (int i = 0; i < n_steps; ++i) add_point(p, &n, default_res, steps[i], default_res, SL);
    for (int i = 0; i < n_res; ++i) add_point(p, &n, default_res, d, res[i], SL);
    add_point(p, &n, default_res, d, default_res, VEIL_OPV_SWEEP);
    if (quick) {
        add_point(p, &n, default_res, d, 32, VEIL_OPV_JACOBI_CORRECTED);
        add_point(p, &n, default_res, 1, 64, SL);
        return n;
    }
    add_point(p, &n, default_res, d, 32, VEIL_OPV_JACOBI);
    add_point(p, &n, default_res, d, 64, VEIL_OPV_JACOBI);
    add_point(p, &n, default_res, d, 64, VEIL_OPV_JACOBI_CORRECTED);
    static const struct {
        float step;
        int res;
    } combos[] = {{2, 32}, {1, 64}, {2, 256}};
    for (size_t i = 0; i < sizeof combos / sizeof *combos; ++i)
        add_point(p, &n, default_res, combos[i].step, combos[i].res, SL);
    return n;
}

/* ---- timing ----------------------------------------------------------------- */

typedef struct bench {
    veil_gl* gl;
    veil_renderer* r;
    veil_grid tiny_g; /* the 2^3 volume that evicts the renderer's caches */
    float tiny_rho[8];
} bench;

/* The 1-minute load average (other work on the machine slows the timings). */
static double load_average(void)
{
    double l = NAN;
    FILE* f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf", &l) != 1) l = NAN;
        fclose(f);
    }
    return l;
}

/* CPU time of the whole process, all threads (llvmpipe's workers too), ms. */
static double cpu_ms(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0) return NAN;
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static veil_result evict(bench* b, const veil_scene* s, veil_error* err)
{
    float* img = NULL;
    veil_render_opts o = {.width = 1, .height = 1};
    veil_result res = veil_render_density(b->r, s, &b->tiny_g, b->tiny_rho, &o, &img, NULL, err);
    free(img);
    return res;
}

/* Compiles (on llvmpipe: JITs) every program once, outside the timings. */
static veil_result warm_up(bench* b, const veil_scene* s, veil_error* err)
{
    veil_grid g;
    float* rho = acc_box_density(8, &g);
    if (!rho) return veil_fail(err, VEIL_ERR_OOM, "out of memory");
    veil_result res = VEIL_OK;
    for (int m = VEIL_OPV_JACOBI; m < VEIL_OPV_METHOD_COUNT && res == VEIL_OK; ++m) {
        float* img = NULL;
        veil_render_opts o = {.width = 4, .height = 3, .method = (veil_opv_method)m};
        res = veil_render_density(b->r, s, &g, rho, &o, &img, NULL, err);
        free(img);
        if (res == VEIL_OK) res = evict(b, s, err);
    }
    free(rho);
    return res;
}

static int cmp_double(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return x < y ? -1 : x > y;
}

/* Renders point p of scene sc `runs` times, each uncached: the row's
 * timings and grid, and *img from the first run. */
static veil_result time_point(bench* b, acc_scene* sc, const point* p, const options* o, int runs, acc_row* row,
                              float** img, veil_error* err)
{
    veil_grid g;
    float* rho = NULL;
    if (sc->given_density) {
        rho = acc_box_density(p->res, &g);
        if (!rho) return veil_fail(err, VEIL_ERR_OOM, "out of memory for a %d^3 grid", p->res);
    }
    sc->scene.medium.max_resolution = p->res;
    veil_render_opts ro = {.width = o->width, .height = o->height, .step_voxels = p->step, .seed = FAST_SEED,
                           .method = p->method};
    double t[MAX_RUNS], cpu[MAX_RUNS], stage[MAX_RUNS][3];
    int done = 0;
    veil_result res = VEIL_OK;
    *img = NULL;
    for (int r = 0; r < runs && res == VEIL_OK; ++r) {
        res = evict(b, &sc->scene, err);
        if (res != VEIL_OK) break;
        float* out = NULL;
        veil_render_stats st = {0};
        double c0 = cpu_ms(), t0 = veil_now_ms();
        res = sc->given_density ? veil_render_density(b->r, &sc->scene, &g, rho, &ro, &out, &st, err)
                                : veil_render_scene(b->r, &sc->scene, &ro, &out, &st, err);
        double t1 = veil_now_ms(), c1 = cpu_ms();
        if (res != VEIL_OK) break;
        if (st.inject_cached || st.opv_cached) {
            free(out);
            res = veil_fail(err, VEIL_ERR_INVALID, "a timed frame reused a cached stage (eviction failed)");
            break;
        }
        t[done] = t1 - t0;
        cpu[done] = c1 - c0;
        stage[done][0] = st.inject_ms;
        stage[done][1] = st.propagate_ms;
        stage[done][2] = st.render_ms;
        ++done;
        memcpy(row->dims, st.grid.dims, sizeof row->dims);
        if (!*img)
            *img = out;
        else
            free(out);
        if (r == 0 && t[0] > REPEAT_LIMIT_MS) break;
    }
    sc->scene.medium.max_resolution = sc->default_res;
    free(rho);
    if (res != VEIL_OK) {
        free(*img);
        *img = NULL;
        return res;
    }
    double sorted[MAX_RUNS];
    memcpy(sorted, t, (size_t)done * sizeof(double));
    qsort(sorted, (size_t)done, sizeof(double), cmp_double);
    double med = sorted[(done - 1) / 2]; /* lower median: an actual run */
    for (int r = 0; r < done; ++r)
        if (t[r] == med) {
            row->inject_ms = stage[r][0];
            row->propagate_ms = stage[r][1];
            row->render_ms = stage[r][2];
            break;
        }
    row->time_ms = med;
    row->time_min_ms = sorted[0];
    qsort(cpu, (size_t)done, sizeof(double), cmp_double);
    row->cpu_ms = cpu[(done - 1) / 2];
    row->runs = done;
    return VEIL_OK;
}

static double excess(double measured, double noise)
{
    double ex = measured * measured - noise * noise;
    return ex > 0.0 ? sqrt(ex) : 0.0;
}

/* ---- arguments ------------------------------------------------------------------ */

static void usage(FILE* f)
{
    fprintf(f,
            "usage: accuracy [--quick] [--out DIR] [--runs N] [--spp N] [--scenes a,b,c] [--size WxH]\n"
            "                [--ref-res N] [--metric pixel|bin] [--cache DIR | --no-cache]\n"
            "  --quick        fewer settings, smaller images, fewer samples, one run (under 2 minutes)\n"
            "  --out DIR      where accuracy[-quick].csv/.gp/.png/.txt go (default %s/docs/results)\n"
            "  --runs N       timed runs per setting, median reported (1..%d; default 3, --quick 1)\n"
            "  --spp N        reference samples per pixel, even, >= 4 (default per scene: homogeneous,\n"
            "                 rbf-fog, vdb-smoke %d, %d, %d; --quick %d, %d, %d)\n"
            "  --scenes LIST  of homogeneous, rbf-fog, vdb-smoke (default all)\n"
            "  --size WxH     image size (default 96x72, --quick 64x48)\n"
            "  --ref-res N    reference EV resolution (default twice the finest swept)\n"
            "  --metric M     what the Pareto front and the plot rank by: pixel (rel_rmse, default) or\n"
            "                 bin (rel_rmse of %dx%d-pixel means)\n"
            "  --cache DIR    reference cache (default %s/bench-cache); --no-cache: none\n"
            "vdb-smoke needs data/generated/smoke_plume.vdb: run `make data` first.\n",
            VEIL_SOURCE_DIR, MAX_RUNS, default_spp[0][0], default_spp[0][1], default_spp[0][2], default_spp[1][0],
            default_spp[1][1], default_spp[1][2], ACC_BIN, ACC_BIN, VEIL_BINARY_DIR);
}

static int parse_int(const char* s, int lo, int hi, int* out)
{
    char* end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi) return 0;
    *out = (int)v;
    return 1;
}

static int parse_args(int argc, char** argv, options* o)
{
    memset(o, 0, sizeof *o);
    int any_scene = 0;
    for (int a = 1; a < argc; ++a) {
        const char* arg = argv[a];
        const char* val = a + 1 < argc ? argv[a + 1] : NULL;
        int takes = strcmp(arg, "--out") == 0 || strcmp(arg, "--runs") == 0 || strcmp(arg, "--spp") == 0 ||
                    strcmp(arg, "--scenes") == 0 || strcmp(arg, "--size") == 0 || strcmp(arg, "--ref-res") == 0 ||
                    strcmp(arg, "--cache") == 0 || strcmp(arg, "--metric") == 0;
        if (takes && !val) {
            fprintf(stderr, "accuracy: %s needs a value\n", arg);
            return 2;
        }
        if (strcmp(arg, "--quick") == 0) {
            o->quick = 1;
        } else if (strcmp(arg, "--metric") == 0) {
            if (strcmp(val, "pixel") == 0)
                o->metric = ACC_METRIC_PIXEL;
            else if (strcmp(val, "bin") == 0)
                o->metric = ACC_METRIC_BIN;
            else {
                fprintf(stderr, "accuracy: --metric %s: expected pixel or bin\n", val);
                return 2;
            }
        } else if (strcmp(arg, "--no-cache") == 0) {
            o->no_cache = 1;
        } else if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0) {
            usage(stdout);
            exit(0);
        } else if (strcmp(arg, "--out") == 0) {
            o->out_dir = val;
        } else if (strcmp(arg, "--cache") == 0) {
            o->cache_dir = val;
        } else if (strcmp(arg, "--runs") == 0) {
            if (!parse_int(val, 1, MAX_RUNS, &o->runs)) {
                fprintf(stderr, "accuracy: --runs %s: expected an integer in 1..%d\n", val, MAX_RUNS);
                return 2;
            }
        } else if (strcmp(arg, "--spp") == 0) {
            if (!parse_int(val, 4, 1 << 24, &o->spp) || o->spp % 2) {
                fprintf(stderr, "accuracy: --spp %s: expected an even integer in 4..%d (two halves)\n", val,
                        1 << 24);
                return 2;
            }
        } else if (strcmp(arg, "--ref-res") == 0) {
            if (!parse_int(val, 2, VEIL_SCENE_MAX_RESOLUTION, &o->ref_res)) {
                fprintf(stderr, "accuracy: --ref-res %s: expected an integer in 2..%d\n", val,
                        VEIL_SCENE_MAX_RESOLUTION);
                return 2;
            }
        } else if (strcmp(arg, "--size") == 0) {
            char w[32], h[32];
            const char* x = strchr(val, 'x');
            size_t lw = x ? (size_t)(x - val) : 0;
            if (!x || lw == 0 || lw >= sizeof w || strlen(x + 1) >= sizeof h) {
                fprintf(stderr, "accuracy: --size %s: expected WxH, e.g. 128x96\n", val);
                return 2;
            }
            memcpy(w, val, lw);
            w[lw] = '\0';
            snprintf(h, sizeof h, "%s", x + 1);
            if (!parse_int(w, 2 * ACC_BIN, 4096, &o->width) || !parse_int(h, 2 * ACC_BIN, 4096, &o->height)) {
                fprintf(stderr, "accuracy: --size %s: width and height must be integers in %d..4096\n", val, 2 * ACC_BIN);
                return 2;
            }
        } else if (strcmp(arg, "--scenes") == 0) {
            char buf[256];
            snprintf(buf, sizeof buf, "%s", val);
            for (char* tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
                int found = 0;
                for (int s = 0; s < ACC_SCENE_COUNT; ++s)
                    if (strcmp(tok, acc_scene_names[s]) == 0) o->use[s] = found = any_scene = 1;
                if (!found) {
                    fprintf(stderr, "accuracy: --scenes: unknown scene '%s' (homogeneous, rbf-fog, vdb-smoke)\n", tok);
                    return 2;
                }
            }
        } else {
            fprintf(stderr, "accuracy: unknown argument '%s'\n", arg);
            usage(stderr);
            return 2;
        }
        if (takes) ++a;
    }
    if (!any_scene)
        for (int s = 0; s < ACC_SCENE_COUNT; ++s) o->use[s] = 1;
    if (!o->runs) o->runs = o->quick ? 1 : 3;
    if (!o->width) {
        o->width = o->quick ? 64 : 96;
        o->height = o->quick ? 48 : 72;
    }
    if (!o->out_dir) o->out_dir = VEIL_SOURCE_DIR "/docs/results";
    if (!o->cache_dir) o->cache_dir = VEIL_BINARY_DIR "/bench-cache";
    if (o->no_cache) o->cache_dir = NULL;
    return 0;
}

/* ---- main --------------------------------------------------------------------------- */

int main(int argc, char** argv)
{
    options o;
    int rc = parse_args(argc, argv, &o);
    if (rc) return rc;
    acc_set_metric(o.metric);
    struct stat sd;
    if (stat(o.out_dir, &sd) != 0 || !S_ISDIR(sd.st_mode)) {
        fprintf(stderr, "accuracy: --out %s: not an existing folder\n", o.out_dir);
        return 2;
    }
    const char* suffix = o.quick ? "-quick" : "";
    char csv_path[1100], gp_path[1100], png_path[1100], txt_path[1100];
    snprintf(csv_path, sizeof csv_path, "%s/accuracy%s.csv", o.out_dir, suffix);
    snprintf(gp_path, sizeof gp_path, "%s/accuracy%s.gp", o.out_dir, suffix);
    snprintf(png_path, sizeof png_path, "%s/accuracy%s.png", o.out_dir, suffix);
    snprintf(txt_path, sizeof txt_path, "%s/accuracy%s.txt", o.out_dir, suffix);
    setvbuf(stdout, NULL, _IOLBF, 0);

    /* scenes first: a missing input is reported before any GPU work */
    acc_scene scenes[ACC_SCENE_COUNT];
    memset(scenes, 0, sizeof scenes);
    veil_error err = {0};
    for (int s = 0; s < ACC_SCENE_COUNT; ++s) {
        if (!o.use[s]) continue;
        if (acc_scene_load(s, &scenes[s], &err) != VEIL_OK) {
            fprintf(stderr, "accuracy: %s: %s\n", acc_scene_names[s], err.msg);
            for (int t = 0; t < s; ++t) acc_scene_free(&scenes[t]);
            return 1;
        }
    }

    bench b = {.tiny_g = {.dims = {2, 2, 2}, .origin = {0, 0, 0}, .voxel = 1e-3f}};
    if (veil_gl_create(&(veil_gl_desc){0}, &b.gl, &err) != VEIL_OK) {
        fprintf(stderr, "accuracy: no GL 4.5 context: %s\n", err.msg);
        return 77;
    }
    FILE* txt = fopen(txt_path, "w");
    if (!txt) fprintf(stderr, "accuracy: %s: %s (continuing without it)\n", txt_path, strerror(errno));
    acc_out_set_copy(txt);
    int status = 0;
    double t_start = veil_now_ms();
    const veil_gl_info* info = veil_gl_get_info(b.gl);
    acc_out("# veil accuracy benchmark: run time against error of the fast GPU path (single scattering)\n");
    acc_out("# machine: %s | %s | %s (%s)\n", info->renderer, info->version, info->platform,
            info->hardware ? "hardware" : "software");
    acc_out("# mode: %s; image %dx%d; timed runs per setting %d (median; a first run over %.0f s is not repeated)\n",
            o.quick ? "--quick" : "full", o.width, o.height, o.runs, REPEAT_LIMIT_MS / 1000.0);
    acc_out("# time: one whole frame (inject + propagate + march + readback), nothing cached, shaders warmed up;\n"
            "#   %d cores, 1-minute load average at the start %.2f (other work on the machine slows the timings;\n"
            "#   the CSV also has the fastest run, time_min_ms, and the process's CPU time, cpu_ms, all threads)\n",
            (int)sysconf(_SC_NPROCESSORS_ONLN), load_average());
    acc_out("# reference: CPU path tracer (reference/pathtracer.h), max_order 1, two independent halves (seeds\n"
            "#   %#llx, +1); medium fixed per scene (below), independent of the swept settings\n",
            (unsigned long long)REF_SEED);
    acc_out("# errors (RGB): rel_rmse = veil_compare_images(fast, reference).rel_rmse, floor 1 %% of the reference\n"
            "#   mean; noise_se: rms of stderr/max(|ref|, floor); noise_sp: the same with |half0 - half1|/2 for\n"
            "#   stderr (does not trust the per-pixel variance estimates); excess = sqrt(rel_rmse^2 - noise_sp^2);\n"
            "#   bin_*: the same on means of %dx%d pixels (the noise falls %dx, systematic errors stay)\n"
            "# Pareto front and plot: by %s (errors within %.0f %% of each other count as equal)\n",
            ACC_BIN, ACC_BIN, ACC_BIN, acc_metric_name(), 100.0 * ACC_PARETO_TOLERANCE);

    int first = 0;
    while (!o.use[first]) ++first;
    if (veil_renderer_create(b.gl, &b.r, &err) != VEIL_OK || warm_up(&b, &scenes[first].scene, &err) != VEIL_OK) {
        fprintf(stderr, "accuracy: %s\n", err.msg);
        status = 1;
    }

    acc_row* rows = calloc((size_t)ACC_SCENE_COUNT * MAX_POINTS, sizeof *rows);
    size_t n_rows = 0;
    const char* names[ACC_SCENE_COUNT];
    double noise[ACC_SCENE_COUNT];
    int n_names = 0;
    if (!rows) status = 1;
    for (int s = 0; s < ACC_SCENE_COUNT && status == 0; ++s) {
        if (!o.use[s]) continue;
        acc_scene* sc = &scenes[s];
        point pts[MAX_POINTS];
        int n_pts = make_points(sc->default_res, o.quick, pts), max_res = 0;
        for (int i = 0; i < n_pts; ++i) max_res = pts[i].res > max_res ? pts[i].res : max_res;
        acc_ref_settings rs = {.width = o.width, .height = o.height, .seed = REF_SEED,
                               .spp = o.spp ? o.spp : default_spp[o.quick][s],
                               .ref_res = sc->given_density ? 0 : (o.ref_res ? o.ref_res : 2 * max_res)};
        acc_reference ref;
        acc_ref_view rv;
        double t_ref = veil_now_ms();
        if (acc_reference_get(sc, &rs, o.cache_dir, &ref, &err) != VEIL_OK) {
            fprintf(stderr, "accuracy: %s: reference: %s\n", sc->name, err.msg);
            status = 1;
            break;
        }
        if (!acc_ref_view_make(&ref, ACC_BIN, &rv)) {
            fprintf(stderr, "accuracy: out of memory\n");
            acc_reference_free(&ref);
            status = 1;
            break;
        }
        noise[n_names] = o.metric == ACC_METRIC_BIN ? rv.noise_bin : rv.noise_split;
        names[n_names++] = sc->name;
        acc_out("\n## %s: %s\n", sc->name, sc->source);
        if (sc->given_density)
            acc_out("# reference medium: the exact cube (constant density on a %d^3 grid spanning the same box)\n",
                    ACC_BOX_REF_N);
        else
            acc_out("# reference medium: the sources voxelised at max_resolution %d (grid %dx%dx%d); swept up to %d\n",
                    rs.ref_res, ref.grid_dims[0], ref.grid_dims[1], ref.grid_dims[2], max_res);
        acc_out("# reference: %d spp, %s%s, %.1f s to make%s\n", rs.spp, ref.from_cache ? "cached in " : "",
                ref.path[0] ? ref.path : "(not cached)", ref.ms / 1000.0, ref.from_cache ? " when it was made" : "");
        acc_out("# reference noise: noise_se %.3f %%, noise_sp %.3f %%, %dx%d bins %.3f %%; mean RGB %.4g\n",
                100.0 * rv.noise_se, 100.0 * rv.noise_split, ACC_BIN, ACC_BIN, 100.0 * rv.noise_bin,
                rv.floor / VEIL_COMPARE_FLOOR_FRACTION);
        fprintf(stderr, "[%s] reference ready (%.1f s this run)\n", sc->name, (veil_now_ms() - t_ref) / 1000.0);
        acc_print_row_header();
        for (int i = 0; i < n_pts && status == 0; ++i) {
            acc_row* r = &rows[n_rows];
            memset(r, 0, sizeof *r);
            r->scene = sc->name;
            memcpy(r->setting, pts[i].setting, sizeof r->setting);
            r->step_voxels = pts[i].step;
            r->max_resolution = pts[i].res;
            r->method = pts[i].method;
            fprintf(stderr, "[%s] %s ...", sc->name, r->setting);
            float *img = NULL, *img_bin = NULL;
            veil_compare_stats cs, cb;
            veil_result res = time_point(&b, sc, &pts[i], &o, o.runs, r, &img, &err);
            if (res == VEIL_OK) res = veil_compare_images(img, ref.rgba, o.width, o.height, 0.0, &cs, NULL, &err);
            if (res == VEIL_OK && !(img_bin = acc_bin_image(img, o.width, o.height, ACC_BIN)))
                res = veil_fail(&err, VEIL_ERR_OOM, "out of memory");
            if (res == VEIL_OK) res = veil_compare_images(img_bin, rv.bin, rv.bw, rv.bh, 0.0, &cb, NULL, &err);
            free(img);
            free(img_bin);
            if (res != VEIL_OK) {
                fprintf(stderr, "\naccuracy: %s %s: %s\n", sc->name, r->setting, err.msg);
                status = 1;
                break;
            }
            if (fabs(cs.floor - rv.floor) > 1e-5 * rv.floor)
                fprintf(stderr, "\naccuracy: note: compare floor %.6g differs from ours %.6g\n", cs.floor, rv.floor);
            r->rel_rmse = cs.rel_rmse;
            r->ref_noise = rv.noise_se;
            r->ref_noise_split = rv.noise_split;
            r->rel_excess = excess(cs.rel_rmse, rv.noise_split);
            r->max_abs = cs.max_abs;
            r->psnr_db = cs.psnr_db;
            r->frac_off = cs.frac_off;
            r->rel_rmse_bin = cb.rel_rmse;
            r->ref_noise_bin = rv.noise_bin;
            r->rel_excess_bin = excess(cb.rel_rmse, rv.noise_bin);
            fprintf(stderr, " %.0f ms, rel_rmse %.4f, binned %.4f\n", r->time_ms, r->rel_rmse, r->rel_rmse_bin);
            acc_print_row(r);
            ++n_rows;
        }
        acc_ref_view_free(&rv);
        acc_reference_free(&ref);
    }

    if (status == 0 && n_rows > 0) {
        acc_mark_pareto(rows, n_rows);
        if (!acc_write_csv(csv_path, rows, n_rows)) {
            fprintf(stderr, "accuracy: %s: %s\n", csv_path, strerror(errno));
            status = 1;
        }
        acc_print_pareto_tables(rows, n_rows, names, n_names);
        acc_print_summary(rows, n_rows, names, n_names);
        char title[256];
        snprintf(title, sizeof title, "veil fast path vs CPU reference (single scattering), %dx%d, %s%s", o.width,
                 o.height, info->renderer, o.quick ? ", --quick" : "");
        int plotted = acc_plot(o.out_dir, strrchr(gp_path, '/') + 1, strrchr(png_path, '/') + 1, title, rows, n_rows,
                               names, noise, n_names);
        acc_out("\n# wrote %s, %s%s%s\n", csv_path, gp_path, plotted ? ", " : "", plotted ? png_path : "");
        acc_out("# total %.1f s; 1-minute load average at the end %.2f\n", (veil_now_ms() - t_start) / 1000.0,
                load_average());
    }
    acc_out_set_copy(NULL);
    if (txt) fclose(txt);
    free(rows);
    veil_renderer_destroy(b.r);
    veil_gl_destroy(b.gl);
    for (int s = 0; s < ACC_SCENE_COUNT; ++s) acc_scene_free(&scenes[s]);
    return status;
}
