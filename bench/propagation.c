/* veil — run time against error of the optical-depth propagation methods.
 *
 *   propagation [--quick] [--runs N] [--sizes 64,128,256] [--methods a,b]
 *               [--media homogeneous,rbf-fog,smoke,smoke-vdb] [--methods-only]
 *               [--jacobi-256] [--csv FILE]
 *
 * For every grid size N (an N^3 grid over the same 2 m box), medium and
 * light, each method fills one optical-depth volume on the GPU; we time
 * veil_opv_gpu() alone (the density texture and the output texture exist
 * beforehand; glFinish() on both sides of the clock) and compare the result
 * at a fixed seeded sample of voxel centres with the exact optical depth of
 * reference/optical_depth.h. Then: the cost per light of the default method
 * (1, 4, 8, 16 lights in one call) and the semi-Lagrangian quality knobs
 * (characteristic length, exit_steps).
 *
 * Media (all deterministic):
 *  - homogeneous: density 1 everywhere;
 *  - rbf-fog: a seeded RBF particle cloud splatted on the grid on the CPU;
 *  - smoke: a procedural smoke plume (a bent rising column, radius growing
 *    with height, modulated by seeded value-noise fBm) — a STAND-IN for a
 *    real OpenVDB smoke volume until the OpenVDB reader lands.
 *
 * Errors, per (medium, grid): sigma_t = 4 / (box width * max density), so
 * that a path across the box at full density has tau = 4; tau = sigma_t * D.
 *  - rms_rel_D_%: rms of (D - D_ref) / D_ref over the sampled voxels with
 *    tau_ref >= TAU_FLOOR (0.05);
 *  - max_abs_exp(-tau): max |exp(-sigma_t D) - exp(-sigma_t D_ref)| over all
 *    sampled voxels (the transmittance error a renderer would see).
 * The Jacobi methods stop at the renderer's tolerance: a checked step
 * changes no tau by more than VEIL_OPV_TAU_TOLERANCE.
 *
 * Tables go to stdout (rows as they are measured), progress to stderr.
 * Exit status: 0, 77 when no GL 4.5 context can be made, 1 on errors. */
#include <epoxy/gl.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "propagate/opv.h"
#include "propagate/opv_gpu.h"
#include "reference/optical_depth.h"
#include "gpu/gl_context.h"
#include "gpu/gl_util.h"
#include "frame/renderer.h"
#include "volume/rbf.h"
#include "volume/volume.h"

#include "media.h"

/* ---- fixed choices -------------------------------------------------------- */

#define SAMPLE_COUNT 3000
/* Relative errors count where the reference attenuates by at least 5 %:
 * a floor fixed in tau, so it does not admit more near-empty voxels as
 * the grid gets finer. */
#define TAU_FLOOR 0.05
#define SAMPLE_SEED 0x5eed0f0bULL
#define MAX_SIZES 8
#define REPEAT_LIMIT_MS 15000.0 /* a case whose first run takes longer is not repeated */

static const char* const medium_names[MEDIUM_COUNT] = {"homogeneous", "rbf-fog", "smoke", "smoke-vdb"};

enum { LIGHT_INSIDE, LIGHT_OUTSIDE, LIGHT_DIRECTIONAL, LIGHT_COUNT };
static const char* const light_names[LIGHT_COUNT] = {"inside", "outside", "directional"};

/* inside: off-centre, inside the smoke column, on no voxel centre of the
 * 64/128/256 grids; outside: ~1 box width beyond the -x face, off-axis;
 * directional: travelling along (0.48, -0.8, 0.36) (unit length). */
static const veil_light bench_lights[LIGHT_COUNT] = {
    {.type = VEIL_LIGHT_POINT, .position = {0.0637f, 0.1437f, -0.0533f}, .color = {1, 1, 1}},
    {.type = VEIL_LIGHT_POINT, .position = {-2.83f, 1.61f, 1.17f}, .color = {1, 1, 1}},
    {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0.48f, -0.8f, 0.36f}, .color = {1, 1, 1}},
};

/* ---- deterministic random numbers ---------------------------------------- */

static double uniform01(uint64_t* s) { return veil_rng_double53(s); }

typedef struct medium_stats {
    double max, mean, empty_fraction;
    double sigma_t;   /* 4 / (box width * max density), m^-1 */
    double floor_d;   /* TAU_FLOOR / sigma_t: D of tau 0.05 (density * m) */
    float tolerance;  /* Jacobi: VEIL_OPV_TAU_TOLERANCE / sigma_t */
} medium_stats;

static medium_stats medium_stats_of(const veil_grid* g, const float* rho)
{
    medium_stats s = {0};
    size_t nv = veil_grid_voxels(g), empty = 0;
    double sum = 0.0;
    for (size_t v = 0; v < nv; ++v) {
        s.max = rho[v] > s.max ? rho[v] : s.max;
        sum += rho[v];
        empty += rho[v] <= 0.0f;
    }
    s.mean = sum / (double)nv;
    s.empty_fraction = (double)empty / (double)nv;
    s.sigma_t = s.max > 0.0 ? 4.0 / (BOX_WIDTH * s.max) : 1.0;
    s.floor_d = TAU_FLOOR / s.sigma_t;
    s.tolerance = (float)(VEIL_OPV_TAU_TOLERANCE / s.sigma_t);
    return s;
}

/* ---- samples and reference ------------------------------------------------ */

static int cmp_size(const void* a, const void* b)
{
    size_t x = *(const size_t*)a, y = *(const size_t*)b;
    return x < y ? -1 : x > y;
}

/* Up to SAMPLE_COUNT distinct voxel indices (all voxels when fewer), sorted. */
static size_t* make_samples(const veil_grid* g, size_t* count)
{
    size_t nv = veil_grid_voxels(g), n = nv < SAMPLE_COUNT ? nv : SAMPLE_COUNT;
    size_t* s = malloc(n * sizeof(size_t));
    if (!s) return NULL;
    if (n == nv) {
        for (size_t v = 0; v < nv; ++v) s[v] = v;
    } else {
        uint64_t rng = SAMPLE_SEED ^ (uint64_t)g->dims[0];
        size_t have = 0;
        while (have < n) {
            while (have < n) s[have++] = (size_t)(veil_splitmix64(&rng) % nv);
            qsort(s, have, sizeof(size_t), cmp_size);
            size_t u = 0;
            for (size_t i = 0; i < have; ++i)
                if (u == 0 || s[i] != s[u - 1]) s[u++] = s[i];
            have = u;
        }
    }
    *count = n;
    return s;
}

static void voxel_center_d(const veil_grid* g, size_t v, double x[3])
{
    int i = (int)(v % (size_t)g->dims[0]), j = (int)(v / (size_t)g->dims[0] % (size_t)g->dims[1]),
        k = (int)(v / ((size_t)g->dims[0] * g->dims[1]));
    float xf[3];
    veil_grid_center(g, i, j, k, xf);
    for (int a = 0; a < 3; ++a) x[a] = xf[a];
}

static void reference_depths(const veil_grid* g, const float* rho, const veil_light* l, const size_t* samples,
                             size_t n, double* out)
{
    for (size_t s = 0; s < n; ++s) {
        double x[3];
        voxel_center_d(g, samples[s], x);
        out[s] = veil_ref_optical_depth(g, rho, l, x, 1.0);
    }
}

/* ---- rows ----------------------------------------------------------------- */

typedef struct row {
    const char* table; /* "methods", "per-light", "exit-steps" */
    const char* method;
    int grid;
    const char* medium;
    const char* light;
    int lights;
    float exit_steps; /* 0: not applicable */
    int characteristic; /* 0: not applicable */
    int runs;         /* 0: skipped */
    double time_ms;   /* median */
    int passes;
    double rms_rel_pct; /* NAN: not measured */
    double max_abs_T;
    size_t samples, samples_rel;
    size_t worst_voxel; /* sample with the largest transmittance error */
    double worst_d, worst_ref;
    const char* note;
} row;

static FILE* csv_file;

static void csv_row(const row* r)
{
    if (!csv_file) return;
    fprintf(csv_file, "%s,%s,%d,%s,%s,%d,%d,%g,%d,%.4f,%d,", r->table, r->method, r->grid, r->medium, r->light,
            r->lights, r->characteristic, r->exit_steps, r->runs, r->runs ? r->time_ms : NAN, r->passes);
    if (isnan(r->rms_rel_pct))
        fprintf(csv_file, ",,");
    else
        fprintf(csv_file, "%.6g,%.6g,", r->rms_rel_pct, r->max_abs_T);
    fprintf(csv_file, "%zu,%zu,%s\n", r->samples, r->samples_rel, r->note ? r->note : "");
    fflush(csv_file);
}

static void grid_label(int n, char* buf, size_t len) { snprintf(buf, len, "%d^3", n); }

static void print_methods_header(void)
{
    printf("%-17s %-6s %-12s %-12s %11s %7s %12s %17s %5s %6s\n", "method", "grid", "medium", "light",
           "time_ms", "passes", "rms_rel_D_%", "max_abs_exp(-tau)", "runs", "n_rel");
}

static void print_methods_row(const row* r)
{
    char gl[16];
    grid_label(r->grid, gl, sizeof gl);
    if (!r->runs)
        printf("%-17s %-6s %-12s %-12s %s\n", r->method, gl, r->medium, r->light, r->note);
    else
        printf("%-17s %-6s %-12s %-12s %11.1f %7d %12.4f %17.3e %5d %6zu\n", r->method, gl, r->medium, r->light,
               r->time_ms, r->passes, r->rms_rel_pct, r->max_abs_T, r->runs, r->samples_rel);
    csv_row(r);
}

/* ---- timing ----------------------------------------------------------------- */

typedef struct bench {
    veil_opv_programs progs;
    int runs;          /* --runs (0: default) */
    int quick;
} bench;

static int cmp_double(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return x < y ? -1 : x > y;
}

/* Runs veil_opv_gpu `runs` times (once when the first run exceeds
 * REPEAT_LIMIT_MS); *median_ms, *passes, *runs_done. */
static veil_result time_opv(bench* b, const veil_grid* g, GLuint ev, const veil_index_light* lights, int n_lights,
                            const veil_opv_params* params, const GLuint* opv, int runs, double* median_ms,
                            int* passes, int* runs_done, veil_error* err)
{
    double t[64];
    int done = 0;
    if (runs > 64) runs = 64;
    for (int r = 0; r < runs; ++r) {
        int it = 0;
        glFinish();
        double t0 = veil_now_ms();
        veil_result res = veil_opv_gpu(&b->progs, g, ev, lights, n_lights, params, opv, &it, err);
        glFinish();
        double t1 = veil_now_ms();
        if (res != VEIL_OK) return res;
        t[done++] = t1 - t0;
        *passes = it;
        if (r == 0 && t[0] > REPEAT_LIMIT_MS) break;
    }
    qsort(t, (size_t)done, sizeof(double), cmp_double);
    *median_ms = done % 2 ? t[done / 2] : 0.5 * (t[done / 2 - 1] + t[done / 2]);
    *runs_done = done;
    return VEIL_OK;
}

/* Reads channel 0 of an RGBA32F OPV back (readback: 4 * voxels floats). */
static veil_result read_opv(GLuint tex, const veil_grid* g, float* readback, veil_error* err)
{
    size_t bytes = veil_grid_voxels(g) * 4 * sizeof(float);
    if (bytes > (size_t)INT32_MAX) return veil_fail(err, VEIL_ERR_LIMIT, "OPV of %zu bytes is too large to read", bytes);
    glGetTextureImage(tex, 0, GL_RGBA, GL_FLOAT, (GLsizei)bytes, readback);
    return veil_gl_check("reading back the OPV", err);
}

static void errors_vs_reference(const float* readback, const size_t* samples, size_t n, const double* dref,
                                const medium_stats* ms, row* r)
{
    double sum2 = 0.0, worst = 0.0;
    size_t nrel = 0;
    for (size_t s = 0; s < n; ++s) {
        double d = readback[4 * samples[s]], e = dref[s];
        double dt = fabs(exp(-ms->sigma_t * d) - exp(-ms->sigma_t * e));
        if (!(dt <= worst)) { /* NaN propagates */
            worst = dt;
            r->worst_voxel = samples[s];
            r->worst_d = d;
            r->worst_ref = e;
        }
        if (e > ms->floor_d) {
            double rel = (d - e) / e;
            sum2 += rel * rel;
            ++nrel;
        }
    }
    r->rms_rel_pct = nrel ? 100.0 * sqrt(sum2 / (double)nrel) : NAN;
    r->max_abs_T = worst;
    r->samples = n;
    r->samples_rel = nrel;
}

/* Progress line (stderr): time and where the transmittance error peaks. */
static void progress_done(const veil_grid* g, const row* r)
{
    size_t v = r->worst_voxel, nx = (size_t)g->dims[0], ny = (size_t)g->dims[1];
    fprintf(stderr, " %.1f ms; worst |dT| %.3g at voxel (%zu,%zu,%zu): D %.5g, D_ref %.5g\n", r->time_ms,
            r->max_abs_T, v % nx, v / nx % ny, v / (nx * ny), r->worst_d, r->worst_ref);
}

/* One medium on one grid, ready on the GPU. */
typedef struct prepared {
    veil_grid g;
    float* rho;
    medium_stats ms;
    GLuint ev;
    GLuint opv[VEIL_MAX_OPV_TEXTURES];
    int n_tex;
} prepared;

static void prepared_free(prepared* p)
{
    free(p->rho);
    p->rho = NULL;
    glDeleteTextures(1, &p->ev);
    glDeleteTextures(VEIL_MAX_OPV_TEXTURES, p->opv);
    memset(p->opv, 0, sizeof p->opv);
    p->ev = 0;
}

static veil_result prepare(int medium, int n, int n_tex, prepared* p, veil_error* err)
{
    memset(p, 0, sizeof *p);
    p->g = bench_grid(n);
    p->n_tex = n_tex;
    p->rho = make_medium(medium, &p->g, err);
    if (!p->rho) return VEIL_ERR_OOM;
    p->ms = medium_stats_of(&p->g, p->rho);
    veil_result res = veil_gl_texture3d(GL_R32F, p->g.dims, "bench extinction volume", &p->ev, err);
    if (res == VEIL_OK) {
        glTextureSubImage3D(p->ev, 0, 0, 0, 0, n, n, n, GL_RED, GL_FLOAT, p->rho);
        res = veil_gl_check("uploading the extinction volume", err);
    }
    for (int t = 0; t < n_tex && res == VEIL_OK; ++t)
        res = veil_gl_texture3d(GL_RGBA32F, p->g.dims, "bench optical-depth volume", &p->opv[t], err);
    if (res != VEIL_OK) prepared_free(p);
    return res;
}

static void print_medium_note(int medium, const prepared* p)
{
    printf("# %-11s %4d^3: max density %.4g, mean %.4g, empty %.1f %%, sigma_t %.4g /m, floor D %.4g, "
           "Jacobi tolerance %.3g\n",
           medium_names[medium], p->g.dims[0], p->ms.max, p->ms.mean, 100.0 * p->ms.empty_fraction, p->ms.sigma_t,
           p->ms.floor_d, (double)p->ms.tolerance);
}

/* ---- argument parsing ------------------------------------------------------- */

static void usage(FILE* f)
{
    fprintf(f, "usage: propagation [--quick] [--runs N] [--sizes 64,128,256] [--methods a,b] [--media a,b] [--methods-only] [--jacobi-256] "
               "[--csv FILE]\n  methods: jacobi, jacobi-corrected, sweep, semi-lagrangian\n");
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

/* Marks use[i] for each comma-separated name in `list` found in names[];
 * 0 when one is not found. */
static int select_names(const char* list, const char* const* names, int count, int* use)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", list);
    memset(use, 0, (size_t)count * sizeof *use);
    for (char* tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        int found = 0;
        for (int i = 0; i < count; ++i)
            if (strcmp(tok, names[i]) == 0) use[i] = found = 1;
        if (!found) return 0;
    }
    return 1;
}

int main(int argc, char** argv)
{
    const char* method_names[VEIL_OPV_METHOD_COUNT];
    for (int m = 0; m < VEIL_OPV_METHOD_COUNT; ++m) method_names[m] = veil_opv_method_name((veil_opv_method)m);
    int sizes[MAX_SIZES] = {64, 128, 256}, n_sizes = 3, runs_opt = 0, quick = 0, jacobi256 = 0;
    int use_method[VEIL_OPV_METHOD_COUNT] = {0, 1, 1, 1, 1};
    int use_medium[MEDIUM_COUNT] = {1, 1, 1, 1};
    int methods_only = 0; /* --methods-only: skip the per-light and knob tables */
    const char* csv_path = NULL;
    int sizes_given = 0;
    for (int a = 1; a < argc; ++a) {
        const char* arg = argv[a];
        const char* val = a + 1 < argc ? argv[a + 1] : NULL;
        if (strcmp(arg, "--quick") == 0) {
            quick = 1;
        } else if (strcmp(arg, "--jacobi-256") == 0) {
            jacobi256 = 1;
        } else if (strcmp(arg, "--runs") == 0 && val) {
            if (!parse_int(val, 1, 64, &runs_opt)) {
                fprintf(stderr, "propagation: --runs %s: expected 1..64\n", val);
                return 2;
            }
            ++a;
        } else if (strcmp(arg, "--sizes") == 0 && val) {
            char buf[256];
            snprintf(buf, sizeof buf, "%s", val);
            n_sizes = 0;
            for (char* tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
                if (n_sizes == MAX_SIZES || !parse_int(tok, 2, 1024, &sizes[n_sizes])) {
                    fprintf(stderr, "propagation: --sizes %s: expected up to %d sizes in 2..1024\n", val,
                            MAX_SIZES);
                    return 2;
                }
                ++n_sizes;
            }
            if (n_sizes == 0) {
                fprintf(stderr, "propagation: --sizes: empty list\n");
                return 2;
            }
            sizes_given = 1;
            ++a;
        } else if ((strcmp(arg, "--methods") == 0 || strcmp(arg, "--media") == 0) && val) {
            int media = strcmp(arg, "--media") == 0;
            if (!select_names(val, media ? medium_names : method_names, media ? MEDIUM_COUNT : VEIL_OPV_METHOD_COUNT,
                              media ? use_medium : use_method)) {
                fprintf(stderr, "propagation: %s %s: unknown name\n", arg, val);
                usage(stderr);
                return 2;
            }
            ++a;
        } else if (strcmp(arg, "--methods-only") == 0) {
            methods_only = 1;
        } else if (strcmp(arg, "--csv") == 0 && val) {
            csv_path = val;
            ++a;
        } else if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0) {
            usage(stdout);
            return 0;
        } else {
            fprintf(stderr, "propagation: unknown or incomplete argument '%s'\n", arg);
            usage(stderr);
            return 2;
        }
    }
    if (quick) {
        if (!sizes_given) {
            sizes[0] = 64;
            n_sizes = 1;
        }
        if (!runs_opt) runs_opt = 1;
    }
    int side = quick ? 64 : 128; /* grid of the per-light and exit_steps tables */

    veil_gl* gl = NULL;
    veil_error err = {0};
    if (veil_gl_create(&(veil_gl_desc){0}, &gl, &err) != VEIL_OK) {
        fprintf(stderr, "propagation: no GL 4.5 context: %s\n", err.msg);
        return 77;
    }
    bench b = {.runs = runs_opt, .quick = quick};
    if (veil_opv_programs_create(&b.progs, &err) != VEIL_OK) {
        fprintf(stderr, "propagation: %s\n", err.msg);
        veil_gl_destroy(gl);
        return 1;
    }
    if (csv_path) {
        csv_file = fopen(csv_path, "w");
        if (!csv_file) {
            fprintf(stderr, "propagation: %s: %s\n", csv_path, strerror(errno));
            return 1;
        }
        fprintf(csv_file, "table,method,grid,medium,light,lights,characteristic,exit_steps,runs,time_ms,passes,rms_rel_D_pct,"
                          "max_abs_exp_neg_tau,samples,samples_rel,note\n");
    }
    setvbuf(stdout, NULL, _IOLBF, 0);

    const veil_gl_info* info = veil_gl_get_info(gl);
    printf("# veil propagation benchmark: run time against error of the optical-depth methods\n");
    printf("# machine: %s | %s | %s (%s)\n", info->renderer, info->version, info->platform,
           info->hardware ? "hardware" : "software");
    printf("# grid: N^3 voxels over the box [%g, %g]^3 m (voxel %g/N m); lights: inside (%g, %g, %g), "
           "outside (%g, %g, %g), directional travelling (%g, %g, %g)\n",
           BOX_LO, BOX_LO + BOX_WIDTH, BOX_WIDTH, bench_lights[0].position[0], bench_lights[0].position[1],
           bench_lights[0].position[2], bench_lights[1].position[0], bench_lights[1].position[1],
           bench_lights[1].position[2], bench_lights[2].direction[0], bench_lights[2].direction[1],
           bench_lights[2].direction[2]);
    printf("# smoke: procedural plume, a STAND-IN for an OpenVDB smoke volume until the OpenVDB reader lands\n");
    printf("# time_ms: veil_opv_gpu() alone, glFinish() before and after, median of the runs (runs column; a case\n"
           "#   whose first run exceeds %.0f s is not repeated); passes: Jacobi steps or ordered-method dispatches\n",
           REPEAT_LIMIT_MS / 1000.0);
    printf("# errors vs reference/optical_depth.h (exact to rounding) at up to %d seeded random voxel centres:\n"
           "#   sigma_t = 4 / (box width %g m * max density of the medium on that grid); tau = sigma_t * D\n"
           "#   rms_rel_D_%%: rms of (D - D_ref)/D_ref over samples with tau_ref > 0.05 (D_ref > floor D; n_rel of them)\n"
           "#   max_abs_exp(-tau): max |exp(-tau) - exp(-tau_ref)| over all samples\n"
           "# Jacobi methods: tolerance = %g / sigma_t (the renderer's), max_iterations 0 (3N+1)\n",
           SAMPLE_COUNT, BOX_WIDTH, (double)VEIL_OPV_TAU_TOLERANCE);

    int status = 0;
    char ref_line[512] = "";
    /* ---- table 1: every method, grid, medium, light ---------------------- */
    printf("\n## methods (sampled voxels per case: min(%d, N^3))\n", SAMPLE_COUNT);
    print_methods_header();
    for (int si = 0; si < n_sizes && status == 0; ++si) {
        int n = sizes[si];
        veil_grid g = bench_grid(n);
        size_t n_samples = 0;
        size_t* samples = make_samples(&g, &n_samples);
        double* dref = malloc(n_samples * sizeof(double));
        float* readback = malloc(veil_grid_voxels(&g) * 4 * sizeof(float));
        if (!samples || !dref || !readback) {
            fprintf(stderr, "propagation: out of memory at %d^3\n", n);
            status = 1;
        }
        int runs = b.runs ? b.runs : (n >= 256 ? 1 : 3);
        for (int m = 0; m < MEDIUM_COUNT && status == 0; ++m) {
            fprintf(stderr, "[%d^3 %s] building the medium\n", n, medium_names[m]);
            if (!use_medium[m]) continue;
            prepared p;
            veil_result pr = prepare(m, n, 1, &p, &err);
            if (pr == VEIL_ERR_IO && m == MEDIUM_VDB_SMOKE) { /* a third-party file: optional */
                printf("# %-11s %4d^3: skipped: %s\n", medium_names[m], n, err.msg);
                continue;
            }
            if (pr != VEIL_OK) {
                fprintf(stderr, "propagation: %d^3 %s: %s\n", n, medium_names[m], err.msg);
                status = 1;
                break;
            }
            print_medium_note(m, &p);
            for (int l = 0; l < LIGHT_COUNT && status == 0; ++l) {
                double t0 = veil_now_ms();
                reference_depths(&g, p.rho, &bench_lights[l], samples, n_samples, dref);
                fprintf(stderr, "[%d^3 %s %s] reference at %zu voxels: %.0f ms\n", n, medium_names[m], light_names[l],
                        n_samples, veil_now_ms() - t0);
                if (!ref_line[0] && m == MEDIUM_SMOKE && l == LIGHT_INSIDE) {
                    /* the reference's own error: against the midpoint rule */
                    double worst = 0.0, worst_rel = 0.0, dmax = 0.0;
                    int k = 0;
                    for (size_t s = 0; s < n_samples && k < 8; s += n_samples / 8 ? n_samples / 8 : 1, ++k) {
                        double x[3];
                        voxel_center_d(&g, samples[s], x);
                        double mid = veil_ref_optical_depth_midpoint(&g, p.rho, &bench_lights[l], x, 64.0);
                        double e = fabs(mid - dref[s]);
                        worst = fmax(worst, e);
                        dmax = fmax(dmax, dref[s]);
                        if (dref[s] > 0.0) worst_rel = fmax(worst_rel, e / dref[s]);
                    }
                    snprintf(ref_line, sizeof ref_line,
                             "# reference check (%s %d^3, light %s, %d voxels): |exact - midpoint(64 steps/voxel)| "
                             "<= %.3g (relative %.3g; D up to %.4g): the midpoint rule's O(h^2) error; the exact "
                             "reference is exact to rounding by construction",
                             medium_names[m], n, light_names[l], k, worst, worst_rel, dmax);
                }
                veil_index_light L;
                veil_light_to_index(&bench_lights[l], g.dims, g.origin, g.voxel, &L);
                for (int meth = VEIL_OPV_JACOBI; meth < VEIL_OPV_METHOD_COUNT && status == 0; ++meth) {
                    if (!use_method[meth]) continue;
                    row r = {.table = "methods", .method = veil_opv_method_name((veil_opv_method)meth), .grid = n,
                             .medium = medium_names[m], .light = light_names[l], .lights = 1,
                             .rms_rel_pct = NAN, .max_abs_T = NAN};
                    int jac = meth == VEIL_OPV_JACOBI || meth == VEIL_OPV_JACOBI_CORRECTED;
                    if (jac && n >= 256 && !jacobi256) {
                        r.note = "skipped (too slow on llvmpipe; --jacobi-256 runs it)";
                        print_methods_row(&r);
                        continue;
                    }
                    veil_opv_params params = {.method = (veil_opv_method)meth, .tolerance = p.ms.tolerance};
                    fprintf(stderr, "[%d^3 %s %s] %s ...", n, medium_names[m], light_names[l], r.method);
                    if (time_opv(&b, &g, p.ev, &L, 1, &params, p.opv, runs, &r.time_ms, &r.passes, &r.runs, &err) !=
                            VEIL_OK ||
                        read_opv(p.opv[0], &g, readback, &err) != VEIL_OK) {
                        fprintf(stderr, "\npropagation: %s\n", err.msg);
                        status = 1;
                        break;
                    }
                    errors_vs_reference(readback, samples, n_samples, dref, &p.ms, &r);
                    progress_done(&g, &r);
                    print_methods_row(&r);
                }
            }
            prepared_free(&p);
        }
        free(samples);
        free(dref);
        free(readback);
    }
    if (ref_line[0]) printf("%s\n", ref_line);

    /* ---- table 2: cost per light, default method, rbf-fog ----------------- */
    if (status == 0 && !methods_only) {
        veil_opv_method def = veil_opv_method_resolve(VEIL_OPV_DEFAULT);
        int runs = b.runs ? b.runs : 3;
        printf("\n## per-light cost: %s (the default), %d^3, rbf-fog, point lights at seeded positions in "
               "[-1.6, 1.6]^3 m, one veil_opv_gpu call, ceil(n/4) RGBA32F textures\n",
               veil_opv_method_name(def), side);
        printf("%-17s %-6s %-12s %6s %8s %11s %13s %7s %5s\n", "method", "grid", "medium", "lights", "textures",
               "time_ms", "ms_per_light", "passes", "runs");
        fprintf(stderr, "[per-light %d^3 rbf-fog] building the medium\n", side);
        prepared p;
        if (prepare(MEDIUM_RBF_FOG, side, VEIL_MAX_OPV_TEXTURES, &p, &err) != VEIL_OK) {
            fprintf(stderr, "propagation: per-light: %s\n", err.msg);
            status = 1;
        } else {
            veil_index_light L[VEIL_MAX_LIGHTS];
            uint64_t rng = 0x11647ULL;
            for (int i = 0; i < VEIL_MAX_LIGHTS; ++i) {
                veil_light w = {.type = VEIL_LIGHT_POINT, .color = {1, 1, 1}};
                for (int a = 0; a < 3; ++a) w.position[a] = (float)(-1.6 + 3.2 * uniform01(&rng));
                veil_light_to_index(&w, p.g.dims, p.g.origin, p.g.voxel, &L[i]);
            }
            static const int counts[] = {1, 4, 8, 16};
            veil_opv_params params = {.method = def, .tolerance = p.ms.tolerance};
            for (int c = 0; c < 4 && status == 0; ++c) {
                row r = {.table = "per-light", .method = veil_opv_method_name(def), .grid = side,
                         .medium = "rbf-fog", .light = "seeded-points", .lights = counts[c],
                         .rms_rel_pct = NAN, .max_abs_T = NAN};
                fprintf(stderr, "[per-light %d^3] %d lights ...", side, counts[c]);
                if (time_opv(&b, &p.g, p.ev, L, counts[c], &params, p.opv, runs, &r.time_ms, &r.passes, &r.runs,
                             &err) != VEIL_OK) {
                    fprintf(stderr, "\npropagation: %s\n", err.msg);
                    status = 1;
                    break;
                }
                fprintf(stderr, " %.1f ms\n", r.time_ms);
                char gl_[16];
                grid_label(side, gl_, sizeof gl_);
                printf("%-17s %-6s %-12s %6d %8d %11.1f %13.1f %7d %5d\n", r.method, gl_, r.medium, r.lights,
                       (r.lights + 3) / 4, r.time_ms, r.time_ms / r.lights, r.passes, r.runs);
                csv_row(&r);
            }
            prepared_free(&p);
        }
    }

    /* ---- table 3: semi-Lagrangian quality knobs ----------------------------- */
    if (status == 0 && !methods_only) {
        /* (characteristic, exit_steps): each knob around the defaults (16, 8) */
        static const int chars[] = {1, 2, 4, 8, 16, 16, 16, 16};
        static const float steps[] = {8, 8, 8, 8, 8, 1, 16, 32};
        enum { KNOBS = 8 };
        static const int media[] = {MEDIUM_HOMOGENEOUS, MEDIUM_SMOKE};
        int runs = b.runs ? b.runs : 3;
        printf("\n## semi-lagrangian characteristic length and exit_steps (defaults %d and %g), %d^3\n",
               VEIL_SL_DEFAULT_CHARACTERISTIC, (double)VEIL_SL_DEFAULT_EXIT_STEPS, side);
        printf("%-4s %-5s %-6s %-12s %-12s %11s %7s %12s %17s %5s %6s\n", "char", "exit", "grid", "medium", "light",
               "time_ms", "passes", "rms_rel_D_%", "max_abs_exp(-tau)", "runs", "n_rel");
        veil_grid g = bench_grid(side);
        size_t n_samples = 0;
        size_t* samples = make_samples(&g, &n_samples);
        double* dref = malloc(n_samples * sizeof(double));
        float* readback = malloc(veil_grid_voxels(&g) * 4 * sizeof(float));
        if (!samples || !dref || !readback) {
            fprintf(stderr, "propagation: out of memory for the exit_steps table\n");
            status = 1;
        }
        for (int mi = 0; mi < 2 && status == 0; ++mi) {
            int m = media[mi];
            fprintf(stderr, "[exit_steps %d^3 %s] building the medium\n", side, medium_names[m]);
            prepared p;
            if (prepare(m, side, 1, &p, &err) != VEIL_OK) {
                fprintf(stderr, "propagation: exit_steps: %s\n", err.msg);
                status = 1;
                break;
            }
            for (int l = 0; l < LIGHT_COUNT && status == 0; ++l) {
                reference_depths(&g, p.rho, &bench_lights[l], samples, n_samples, dref);
                veil_index_light L;
                veil_light_to_index(&bench_lights[l], g.dims, g.origin, g.voxel, &L);
                for (int s = 0; s < KNOBS && status == 0; ++s) {
                    row r = {.table = "sl-knobs", .method = "semi-lagrangian", .grid = side,
                             .medium = medium_names[m], .light = light_names[l], .lights = 1,
                             .exit_steps = steps[s], .characteristic = chars[s]};
                    veil_opv_params params = {.method = VEIL_OPV_SEMI_LAGRANGIAN, .exit_steps = steps[s],
                                              .characteristic = chars[s]};
                    fprintf(stderr, "[knobs %d^3 %s %s] %d %g ...", side, medium_names[m], light_names[l], chars[s],
                            (double)steps[s]);
                    if (time_opv(&b, &g, p.ev, &L, 1, &params, p.opv, runs, &r.time_ms, &r.passes, &r.runs,
                                 &err) != VEIL_OK ||
                        read_opv(p.opv[0], &g, readback, &err) != VEIL_OK) {
                        fprintf(stderr, "\npropagation: %s\n", err.msg);
                        status = 1;
                        break;
                    }
                    errors_vs_reference(readback, samples, n_samples, dref, &p.ms, &r);
                    progress_done(&g, &r);
                    char gl_[16];
                    grid_label(side, gl_, sizeof gl_);
                    printf("%-4d %-5g %-6s %-12s %-12s %11.1f %7d %12.4f %17.3e %5d %6zu\n", r.characteristic,
                           (double)r.exit_steps, gl_,
                           r.medium, r.light, r.time_ms, r.passes, r.rms_rel_pct, r.max_abs_T, r.runs,
                           r.samples_rel);
                    csv_row(&r);
                }
            }
            prepared_free(&p);
        }
        free(samples);
        free(dref);
        free(readback);
    }

    if (csv_file) fclose(csv_file);
    veil_opv_programs_destroy(&b.progs);
    veil_gl_destroy(gl);
    return status;
}
