/* The OpenVDB reader (io/vdb.h) and the resampling onto veil's grid
 * (volume/vdb_volume.h), on the files that make_test_vdbs writes.
 *
 *   test_vdb DATA_DIR CASE
 *
 * One ctest per CASE (tests/io/CMakeLists.txt): open, select, level_set,
 * types, bad_files, empty, transform, threads, fast_path, mass, rotated,
 * limits, scene_volume. (Native resolution, NanoVDB files and the
 * filter by direction: tests/volume/test_vdb_import.c.)
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "support/check.h"
#include "support/vdb_util.h"
#include "io/scene.h"
#include "io/vdb.h"
#include "reference/optical_depth.h"
#include "volume/scene_volume.h"
#include "volume/vdb_volume.h"

/* The requirement for Σ density x voxel volume after resampling;
 * the box filter is exact for the 2x/3x/4x targets (a sample lattice that
 * refines the VDB's, see vdb_volume.h), so the measured error (printed)
 * is float rounding, far inside it. */
#define MASS_TOL 0.01
#define VEIL_PI_D 3.14159265358979323846

/* Opening fails with `code` and a message containing each of the strings. */
static void open_fails(const char* name, const char* grid, int to_fog, veil_result code, const char* const* has)
{
    veil_vdb* v = NULL;
    veil_error err = {0};
    veil_result r = veil_vdb_open(file(name), grid, to_fog, &v, NULL, 0, &err);
    CHECK(r == code && !v, "%s grid %s: got %s, expected %s: %s", name, grid ? grid : "(default)",
          veil_result_name(r), veil_result_name(code), err.msg);
    for (; *has; ++has) CHECK(strstr(err.msg, *has), "%s: message lacks '%s': %s", name, *has, err.msg);
    printf("%s: %s: %s\n", name, veil_result_name(r), err.msg);
    veil_vdb_close(v);
}

/* Σ values over the active index box (double), and the count. */
static double vdb_value_sum(const veil_vdb* v)
{
    int lo[3], hi[3];
    size_t active = 0;
    veil_vdb_index_bbox(v, lo, hi, &active);
    if (!active) return 0.0;
    size_t nx = (size_t)(hi[0] - lo[0] + 1), ny = (size_t)(hi[1] - lo[1] + 1), nz = (size_t)(hi[2] - lo[2] + 1);
    float* d = malloc(nx * ny * nz * sizeof *d);
    if (!d) return NAN;
    CHECK(veil_vdb_dense(v, lo, hi, d) == VEIL_OK, "dense");
    double s = 0.0;
    for (size_t i = 0; i < nx * ny * nz; ++i) s += d[i];
    free(d);
    return s;
}

static double det3(const double m[4][4])
{
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

/* A target grid of voxel `h` whose inner box (one voxel in from each face)
 * holds the field's support, origin moved by `shift` voxels (so that the
 * target's lattice does not line up with the VDB's). */
static double grid_sum(const veil_grid* g, const float* d)
{
    double s = 0.0;
    for (size_t i = 0; i < veil_grid_voxels(g); ++i) s += d[i];
    return s;
}

/* Resamples v onto g (from zero) and returns the relative mass error
 * against `mass` (density x m^3). */
static double resample_mass_error(const veil_vdb* v, const veil_grid* g, double mass, veil_vdb_resample_plan* plan,
                                  float** keep)
{
    veil_error err = {0};
    float* d = calloc(veil_grid_voxels(g), sizeof *d);
    CHECK(d != NULL, "calloc");
    if (!d) return INFINITY;
    CHECK(veil_vdb_plan_resample(v, g, plan, &err) == VEIL_OK, "plan: %s", err.msg);
    veil_result r = veil_vdb_to_grid(v, 1.0f, g, d, &err);
    CHECK(r == VEIL_OK, "to_grid: %s", err.msg);
    double h = g->voxel, got = grid_sum(g, d) * h * h * h;
    if (keep) *keep = d;
    else free(d);
    return fabs(got - mass) / mass;
}

static void test_open(void)
{
    char chosen[64] = "";
    veil_vdb* v = open_ok("fog_sphere.vdb", NULL, 0, chosen, sizeof chosen);
    CHECK(strcmp(chosen, "density") == 0, "chosen '%s'", chosen);
    CHECK(strcmp(veil_vdb_grid_name(v), "density") == 0, "name");
    CHECK(strstr(veil_vdb_path(v), "fog_sphere.vdb") != NULL, "path");
    int lo[3], hi[3];
    size_t active = 0;
    CHECK(veil_vdb_index_bbox(v, lo, hi, &active) == VEIL_OK, "bbox");
    /* a ball of radius 20 voxels: about 4/3 pi 20^3 = 33510 interior voxels */
    CHECK(active > 30000 && active < 37000, "active %zu", active);
    /* centre (0.1, -0.2, 0.3) m = index (2, -4, 6); radius 20 voxels */
    const int c[3] = {2, -4, 6};
    for (int a = 0; a < 3; ++a)
        CHECK(lo[a] >= c[a] - 21 && lo[a] <= c[a] - 18 && hi[a] <= c[a] + 21 && hi[a] >= c[a] + 18,
              "axis %d: [%d, %d]", a, lo[a], hi[a]);
    float wlo[3], whi[3];
    veil_error err = {0};
    CHECK(veil_vdb_world_bounds(v, wlo, whi, &err) == VEIL_OK, "%s", err.msg);
    for (int a = 0; a < 3; ++a)
        CHECK(check_close(wlo[a], lo[a] * 0.05, 1e-6, 1e-6) && check_close(whi[a], hi[a] * 0.05, 1e-6, 1e-6),
              "world bounds axis %d", a);
    /* the centre is inside: density 1 (sdfToFogVolume: 1 in the interior) */
    const double centre[3] = {0.1, -0.2, 0.3}, outside[3] = {2.0, 0.0, 0.0};
    float s[2];
    CHECK(veil_vdb_sample_world(v, centre, 1, &s[0], &err) == VEIL_OK, "%s", err.msg);
    CHECK(veil_vdb_sample_world(v, outside, 1, &s[1], &err) == VEIL_OK, "%s", err.msg);
    CHECK(s[0] == 1.0f && s[1] == 0.0f, "inside %g, outside %g", s[0], s[1]);
    veil_vdb_close(v);
    veil_vdb_close(NULL);
}

static void test_select(void)
{
    char chosen[64] = "";
    size_t active = 0;
    int lo[3], hi[3];
    /* default: "density" wins over the first grid, "temperature" */
    veil_vdb* v = open_ok("two_grids.vdb", NULL, 0, chosen, sizeof chosen);
    CHECK(strcmp(chosen, "density") == 0, "default chose '%s'", chosen);
    veil_vdb_index_bbox(v, lo, hi, &active);
    CHECK(active == 5, "density has 5 active voxels, got %zu", active);
    veil_vdb_close(v);
    /* by name */
    v = open_ok("two_grids.vdb", "temperature", 0, chosen, sizeof chosen);
    CHECK(strcmp(chosen, "temperature") == 0, "chose '%s'", chosen);
    veil_vdb_index_bbox(v, lo, hi, &active);
    CHECK(active == 3, "temperature has 3 active voxels, got %zu", active);
    veil_vdb_close(v);
    /* chosen_name truncates */
    char small[4];
    v = open_ok("two_grids.vdb", NULL, 0, small, sizeof small);
    CHECK(strcmp(small, "den") == 0, "truncated to '%s'", small);
    veil_vdb_close(v);
    /* a missing name lists the grids */
    open_fails("two_grids.vdb", "pressure", 0, VEIL_ERR_INVALID,
               (const char* const[]){"two_grids.vdb", "'pressure'", "'temperature' (float", "'density' (float", NULL});
    /* no "density": the first float grid */
    open_fails("level_set.vdb", NULL, 0, VEIL_ERR_INVALID, (const char* const[]){"'surface'", NULL});
}

static void test_level_set(void)
{
    open_fails("level_set.vdb", "surface", 0, VEIL_ERR_INVALID,
               (const char* const[]){"level_set.vdb", "'surface'", "level set", "\"level_set\": \"to_fog\"",
                                     "vdb_tool -ls2fog", NULL});
    char chosen[64] = "";
    veil_vdb* v = open_ok("level_set.vdb", NULL, 1, chosen, sizeof chosen);
    CHECK(strcmp(chosen, "surface") == 0, "chose '%s'", chosen);
    if (!v) return;
    /* converted: 1 deep inside, 0 outside, nothing negative, in [0, 1] */
    const double p[4][3] = {{0.1, -0.2, 0.3}, {0.1, -0.2, 0.3 + 0.5}, {0.1 + 1.2, -0.2, 0.3}, {-5.0, 0.0, 0.0}};
    float s[4];
    veil_error err = {0};
    CHECK(veil_vdb_sample_world(v, &p[0][0], 4, s, &err) == VEIL_OK, "%s", err.msg);
    CHECK(s[0] == 1.0f && s[1] == 1.0f && s[2] == 0.0f && s[3] == 0.0f, "samples %g %g %g %g", s[0], s[1], s[2],
          s[3]);
    double sum = vdb_value_sum(v);
    size_t active = 0;
    int lo[3], hi[3];
    veil_vdb_index_bbox(v, lo, hi, &active);
    /* Closed form: sdfToFogVolume maps the distance d inside the surface
     * to min(d / w, 1), w = the narrow band's inner width (3 voxels), so
     * the mass in voxels is 4/3 pi (R - w)^3 + 4 pi int_{R-w}^{R} r^2 (R - r) / w dr
     * with R = 20 voxels; the sum of the samples is that integral up to the
     * sampling of the ramp (1 % allowed). */
    const double R = 20.0, w = 3.0, a = R - w;
    const double shell = 4.0 * VEIL_PI_D / w * (R * (R * R * R - a * a * a) / 3.0 - (R * R * R * R - a * a * a * a) / 4.0);
    const double closed = 4.0 / 3.0 * VEIL_PI_D * a * a * a + shell;
    printf("level set to fog: sum of values %.1f voxels, closed form %.1f (%.2g relative)\n", sum, closed,
           fabs(sum - closed) / closed);
    CHECK(active > 30000 && check_close(sum, closed, 0.0, 0.01), "active %zu sum %g closed form %g", active, sum,
          closed);
    veil_vdb_close(v);
}

static void test_types(void)
{
    open_fails("vec3.vdb", NULL, 0, VEIL_ERR_INVALID, (const char* const[]){"vec3.vdb", "'velocity' (vec3s", NULL});
    open_fails("vec3.vdb", "velocity", 0, VEIL_ERR_INVALID,
               (const char* const[]){"vec3.vdb", "'velocity'", "value type vec3s", "float", NULL});
}

static void test_bad_files(void)
{
    open_fails("truncated.vdb", NULL, 0, VEIL_ERR_IO,
               (const char* const[]){"truncated.vdb", "truncated or corrupt OpenVDB file", "does not fit in its", NULL});
    open_fails("garbage.vdb", NULL, 0, VEIL_ERR_IO, (const char* const[]){"garbage.vdb", "OpenVDB said", NULL});
    open_fails("does_not_exist.vdb", NULL, 0, VEIL_ERR_IO,
               (const char* const[]){"does_not_exist.vdb", "No such file or directory", NULL});
    open_fails(".", NULL, 0, VEIL_ERR_IO, (const char* const[]){"Is a directory", NULL});
    veil_vdb_grid_info* gi = NULL;
    size_t n = 0;
    veil_error err = {0};
    CHECK(veil_vdb_file_info(file("garbage.vdb"), &gi, &n, &err) == VEIL_ERR_IO && !gi && n == 0, "info garbage");
    CHECK(strstr(err.msg, "garbage.vdb") != NULL, "%s", err.msg);
    char* json = NULL;
    CHECK(veil_vdb_info_json(file("does_not_exist.vdb"), &json, &err) == VEIL_ERR_IO && !json, "json missing");
}

static void test_empty(void)
{
    veil_vdb* v = open_ok("empty.vdb", NULL, 0, NULL, 0);
    if (!v) return;
    int lo[3], hi[3];
    size_t active = 99;
    CHECK(veil_vdb_index_bbox(v, lo, hi, &active) == VEIL_OK && active == 0, "active %zu", active);
    CHECK(lo[0] == 0 && hi[0] == -1, "empty box [%d, %d]", lo[0], hi[0]);
    float wlo[3], whi[3];
    veil_error err = {0};
    CHECK(veil_vdb_world_bounds(v, wlo, whi, &err) == VEIL_ERR_INVALID && strstr(err.msg, "no active voxels"),
          "%s", err.msg);
    veil_grid g = {.dims = {4, 4, 4}, .origin = {0, 0, 0}, .voxel = 0.1f};
    float d[64];
    for (int i = 0; i < 64; ++i) d[i] = 2.0f;
    CHECK(veil_vdb_to_grid(v, 1.0f, &g, d, &err) == VEIL_OK, "%s", err.msg);
    int same = 1;
    for (int i = 0; i < 64; ++i) same &= d[i] == 2.0f;
    CHECK(same, "an empty grid adds nothing");
    veil_vdb_close(v);
}

/* offset_scaled.vdb: voxel 0.25 m, index 0 at world (1, -2, 3), the
 * linear field f(i,j,k) = 1 + i/2 + j/4 + k/8 on [0, 15]^3. */
static double lin(double i, double j, double k) { return 1.0 + i / 2.0 + j / 4.0 + k / 8.0; }

static void test_transform(void)
{
    veil_vdb* v = open_ok("offset_scaled.vdb", NULL, 0, NULL, 0);
    if (!v) return;
    veil_error err = {0};
    double m[4][4];
    CHECK(veil_vdb_transform(v, m, &err) == VEIL_OK, "%s", err.msg);
    const double want[4][4] = {{0.25, 0, 0, 1}, {0, 0.25, 0, -2}, {0, 0, 0.25, 3}, {0, 0, 0, 1}};
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) CHECK(m[r][c] == want[r][c], "m[%d][%d] = %g, want %g", r, c, m[r][c], want[r][c]);
    int lo[3], hi[3];
    size_t active = 0;
    veil_vdb_index_bbox(v, lo, hi, &active);
    CHECK(active == 4096 && lo[0] == 0 && hi[0] == 15 && lo[2] == 0 && hi[2] == 15, "active %zu", active);

    /* The convention: voxel (3,4,5) is the sample at world M*(3,4,5) =
     * (1.75, -1, 4.25), not half a voxel off (Cycles 3.4 would put it at
     * (1.875, -0.875, 4.375), where this field is lin(3.5, 4.5, 5.5)). */
    const double p[4][3] = {{1.75, -1.0, 4.25}, {1.875, -0.875, 4.375}, {1.0 + 0.25 * 7.3, -2.0 + 0.25 * 2.6, 3.0 + 0.25 * 11.9},
                            {1.0 + 0.25 * 17.0, 0.0, 4.0}};
    float s[4];
    CHECK(veil_vdb_sample_world(v, &p[0][0], 4, s, &err) == VEIL_OK, "%s", err.msg);
    CHECK(s[0] == (float)lin(3, 4, 5), "voxel (3,4,5) at (1.75,-1,4.25): %g, want %g", s[0], lin(3, 4, 5));
    CHECK(check_close(s[1], lin(3.5, 4.5, 5.5), 1e-5, 1e-6), "half-voxel point: %g want %g", s[1], lin(3.5, 4.5, 5.5));
    CHECK(check_close(s[2], lin(7.3, 2.6, 11.9), 1e-5, 1e-6), "interior point: %g want %g", s[2], lin(7.3, 2.6, 11.9));
    CHECK(s[3] == 0.0f, "two voxels past the block: %g", s[3]);
    float wlo[3], whi[3];
    CHECK(veil_vdb_world_bounds(v, wlo, whi, &err) == VEIL_OK, "%s", err.msg);
    CHECK(wlo[0] == 1.0f && wlo[1] == -2.0f && wlo[2] == 3.0f && whi[0] == 4.75f && whi[1] == 1.75f &&
              whi[2] == 6.75f,
          "world bounds (%g %g %g)..(%g %g %g)", wlo[0], wlo[1], wlo[2], whi[0], whi[1], whi[2]);
    CHECK(veil_vdb_world_support(v, wlo, whi, &err) == VEIL_OK && wlo[0] == 0.75f && whi[2] == 7.0f, "support");

    /* dense: x fastest */
    const int dlo[3] = {2, 3, 4}, dhi[3] = {4, 4, 5};
    float d[12];
    CHECK(veil_vdb_dense(v, dlo, dhi, d) == VEIL_OK, "dense");
    int ok = 1;
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 3; ++i) ok &= d[(k * 2 + j) * 3 + i] == (float)lin(2 + i, 3 + j, 4 + k);
    CHECK(ok, "dense values, x fastest");
    CHECK(veil_vdb_dense(v, dhi, dlo, d) == VEIL_ERR_INVALID, "inverted box");
    veil_vdb_close(v);

    /* a frustum map is refused */
    v = open_ok("frustum.vdb", NULL, 0, NULL, 0);
    if (!v) return;
    veil_result r = veil_vdb_transform(v, m, &err);
    CHECK(r == VEIL_ERR_INVALID && strstr(err.msg, "non-affine") && strstr(err.msg, "Frustum") &&
              strstr(err.msg, "frustum.vdb"),
          "%s: %s", veil_result_name(r), err.msg);
    printf("frustum: %s\n", err.msg);
    veil_grid g = {.dims = {2, 2, 2}, .origin = {0, 0, 0}, .voxel = 1.0f};
    float dd[8] = {0};
    CHECK(veil_vdb_to_grid(v, 1.0f, &g, dd, &err) == VEIL_ERR_INVALID, "to_grid refuses a frustum");
    veil_vdb_close(v);
}

/* Several threads sample one veil_vdb at once; each matches a serial run. */
typedef struct sample_job {
    const veil_vdb* v;
    const double* xyz;
    size_t n;
    float* out;
    veil_result r;
} sample_job;

static void* sample_thread(void* arg)
{
    sample_job* j = arg;
    j->r = veil_vdb_sample_world(j->v, j->xyz, j->n, j->out, NULL);
    return NULL;
}

static void test_threads(void)
{
    enum { THREADS = 4, N = 200000 };
    veil_vdb* v = open_ok("smoke_plume.vdb", NULL, 0, NULL, 0);
    if (!v) return;
    float lo[3], hi[3];
    veil_error err = {0};
    veil_vdb_world_support(v, lo, hi, &err);
    double* xyz = malloc(sizeof(double) * 3 * N);
    float* ref = malloc(sizeof(float) * N);
    float* out = malloc(sizeof(float) * N * THREADS);
    if (!xyz || !ref || !out) return;
    uint32_t s = 12345u; /* LCG: fixed points over the support box */
    for (size_t i = 0; i < 3 * (size_t)N; ++i) {
        s = s * 1664525u + 1013904223u;
        int a = (int)(i % 3);
        xyz[i] = lo[a] + (hi[a] - lo[a]) * (s >> 8) / 16777216.0;
    }
    CHECK(veil_vdb_sample_world(v, xyz, N, ref, &err) == VEIL_OK, "%s", err.msg);
    size_t nonzero = 0;
    for (size_t i = 0; i < N; ++i) nonzero += ref[i] != 0.0f;
    CHECK(nonzero > N / 10, "only %zu of %d samples inside the plume", nonzero, N);
    pthread_t th[THREADS];
    sample_job jobs[THREADS];
    for (int t = 0; t < THREADS; ++t) {
        jobs[t] = (sample_job){v, xyz, N, out + (size_t)t * N, VEIL_ERR_INVALID};
        CHECK(pthread_create(&th[t], NULL, sample_thread, &jobs[t]) == 0, "pthread_create");
    }
    for (int t = 0; t < THREADS; ++t) {
        pthread_join(th[t], NULL);
        CHECK(jobs[t].r == VEIL_OK && memcmp(jobs[t].out, ref, sizeof(float) * N) == 0, "thread %d differs", t);
    }
    free(xyz);
    free(ref);
    free(out);
    veil_vdb_close(v);
}

static void test_fast_path(void)
{
    veil_vdb* v = open_ok("offset_scaled.vdb", NULL, 0, NULL, 0);
    if (!v) return;
    veil_error err = {0};
    /* centres on index points -2..17: origin = (1,-2,3) + (-2 - 0.5) * 0.25 */
    veil_grid g = {.dims = {20, 20, 20}, .origin = {1.0f - 0.625f, -2.0f - 0.625f, 3.0f - 0.625f}, .voxel = 0.25f};
    veil_vdb_resample_plan plan;
    CHECK(veil_vdb_plan_resample(v, &g, &plan, &err) == VEIL_OK && plan.exact_copy == 1 && plan.samples == 4096,
          "exact path: copy %d, %zu values", plan.exact_copy, plan.samples);
    float* d = malloc(sizeof(float) * 8000);
    if (!d) return;
    for (int i = 0; i < 8000; ++i) d[i] = 0.5f; /* added to */
    CHECK(veil_vdb_to_grid(v, 2.0f, &g, d, &err) == VEIL_OK, "%s", err.msg);
    int exact = 1;
    for (int k = 0; k < 20; ++k)
        for (int j = 0; j < 20; ++j)
            for (int i = 0; i < 20; ++i) {
                int in = i >= 2 && i < 18 && j >= 2 && j < 18 && k >= 2 && k < 18;
                float want = 0.5f + (in ? 2.0f * (float)lin(i - 2, j - 2, k - 2) : 0.0f);
                exact &= d[(k * 20 + j) * 20 + i] == want;
            }
    CHECK(exact, "the copy is exact (0.5 + 2 x value, 0.5 outside)");

    /* moved by 0.3 voxel, the same voxel size: not reducing, so the field at
     * each centre (k = 1; volume/vdb_volume.h), mass still kept */
    g.origin[0] += 0.3f * 0.25f;
    CHECK(veil_vdb_plan_resample(v, &g, &plan, &err) == VEIL_OK && plan.exact_copy == 0 && plan.k == 1,
          "misaligned: copy %d k %d", plan.exact_copy, plan.k);
    double mass = vdb_value_sum(v) * 0.25 * 0.25 * 0.25;
    double e = resample_mass_error(v, &g, mass, &plan, NULL);
    printf("offset_scaled, target moved 0.3 voxel (k=%d): mass error %.3g\n", plan.k, e);
    CHECK(e <= MASS_TOL, "mass error %g", e);
    free(d);
    veil_vdb_close(v);
}

/* Σ density x voxel volume after resampling onto coarser grids. */
static void mass_case(const char* name, const double* ratios, int nratios, double* worst)
{
    veil_vdb* v = open_ok(name, NULL, 0, NULL, 0);
    if (!v) return;
    double m[4][4];
    veil_error err = {0};
    CHECK(veil_vdb_transform(v, m, &err) == VEIL_OK, "%s", err.msg);
    const double vol = fabs(det3(m)), h = cbrt(vol);
    const double mass = vdb_value_sum(v) * vol;
    for (int i = 0; i < nratios; ++i) {
        veil_grid g = grid_around(v, (float)(ratios[i] * h), 0.37f);
        veil_vdb_resample_plan plan;
        double e = resample_mass_error(v, &g, mass, &plan, NULL);
        printf("%-16s %.2fx coarser (grid %dx%dx%d, k=%d, %zu samples): mass error %.3g\n", name, ratios[i],
               g.dims[0], g.dims[1], g.dims[2], plan.k, plan.samples, e);
        CHECK(e <= MASS_TOL, "%s %.2fx: mass error %g > %g", name, ratios[i], e, MASS_TOL);
        if (e > *worst) *worst = e;
    }
    veil_vdb_close(v);
}

static void test_mass(void)
{
    const double required[] = {2.0, 3.0, 4.0}, more[] = {1.0, 1.7, 2.5, 3.3, 6.0, 10.0};
    double worst = 0.0, worst_more = 0.0;
    mass_case("fog_sphere.vdb", required, 3, &worst);
    mass_case("smoke_plume.vdb", required, 3, &worst);
    /* ratios where the sample lattice does not refine the VDB's (1.7, 3.3)
     * or k is capped (10x: k = 16 < 20): measured, same requirement */
    mass_case("fog_sphere.vdb", more, 6, &worst_more);
    mass_case("smoke_plume.vdb", more, 6, &worst_more);
    printf("worst mass error: %.3g at 2x/3x/4x, %.3g at the other ratios (requirement %g)\n", worst, worst_more,
           MASS_TOL);
}

static void test_rotated(void)
{
    veil_vdb* v = open_ok("rotated.vdb", NULL, 0, NULL, 0);
    if (!v) return;
    double m[4][4];
    veil_error err = {0};
    CHECK(veil_vdb_transform(v, m, &err) == VEIL_OK, "%s", err.msg);
    CHECK(m[0][1] != 0.0 && m[2][1] != 0.0, "the map rotates");
    CHECK(check_close(fabs(det3(m)), 0.05 * 0.05 * 0.05, 1e-12, 1e-9), "det %g", det3(m));
    const double mass = vdb_value_sum(v) * fabs(det3(m));
    const double ratios[] = {1.0, 2.0, 3.0, 4.0};
    for (int i = 0; i < 4; ++i) {
        veil_grid g = grid_around(v, (float)(0.05 * ratios[i]), 0.21f);
        veil_vdb_resample_plan plan;
        float* d = NULL;
        double e = resample_mass_error(v, &g, mass, &plan, &d);
        printf("rotated.vdb      %.2fx (grid %dx%dx%d, k=%d): mass error %.3g\n", ratios[i], g.dims[0], g.dims[1],
               g.dims[2], plan.k, e);
        CHECK(plan.exact_copy == 0 && e <= MASS_TOL, "rotated %.0fx: mass error %g", ratios[i], e);
        if (!d) continue;
        /* a few voxels against the mean of OpenVDB's BoxSampler at the same
         * k^3 points: the C interpolation and inverse map agree with it */
        double worst = 0.0;
        for (int t = 0; t < 5; ++t) {
            int idx[3] = {g.dims[0] / 2 - 2 + t, g.dims[1] / 2 + (t % 2), g.dims[2] / 2 - t / 2};
            int k = plan.k;
            size_t n = (size_t)k * k * k;
            double* xyz = malloc(n * 3 * sizeof *xyz);
            float* s = malloc(n * sizeof *s);
            if (!xyz || !s) break;
            for (int c = 0, q = 0; c < k; ++c)
                for (int b = 0; b < k; ++b)
                    for (int a = 0; a < k; ++a, ++q) {
                        const int sub[3] = {a, b, c};
                        for (int ax = 0; ax < 3; ++ax)
                            xyz[3 * q + ax] = g.origin[ax] + (idx[ax] + (sub[ax] + 0.5) / k) * (double)g.voxel;
                    }
            CHECK(veil_vdb_sample_world(v, xyz, n, s, &err) == VEIL_OK, "%s", err.msg);
            double mean = 0.0;
            for (size_t q = 0; q < n; ++q) mean += s[q];
            mean /= (double)n;
            float got = d[((size_t)idx[2] * g.dims[1] + idx[1]) * g.dims[0] + idx[0]];
            CHECK(mean > 0.01 && check_close(got, mean, 1e-7, 1e-5), "voxel (%d,%d,%d): %.9g, BoxSampler mean %.9g",
                  idx[0], idx[1], idx[2], got, mean);
            worst = fmax(worst, fabs(got - mean) / mean);
            free(xyz);
            free(s);
        }
        printf("                 largest difference from OpenVDB's BoxSampler: %.2g relative\n", worst);
        /* the densest target voxel holds the blob's centre, world (0.5, 0.25, -1) */
        size_t best = 0;
        for (size_t j = 1; j < veil_grid_voxels(&g); ++j)
            if (d[j] > d[best]) best = j;
        int idx[3] = {(int)(best % (size_t)g.dims[0]), (int)(best / (size_t)g.dims[0] % (size_t)g.dims[1]),
                      (int)(best / ((size_t)g.dims[0] * (size_t)g.dims[1]))};
        const double centre[3] = {0.5, 0.25, -1.0};
        for (int a = 0; a < 3; ++a) {
            double c = g.origin[a] + (idx[a] + 0.5) * g.voxel;
            CHECK(fabs(c - centre[a]) <= g.voxel, "peak axis %d at %g, blob at %g", a, c, centre[a]);
        }
        free(d);
    }
    veil_vdb_close(v);
}

/* The size limits refuse before allocating, with the numbers. */
static void test_limits(void)
{
    veil_vdb* v = open_ok("far_apart.vdb", NULL, 0, NULL, 0);
    if (!v) return;
    veil_error err = {0};
    veil_vdb_resample_plan plan;
    /* a coarse target over both voxels: few samples, but the values it
     * reads span 1103^3 index points */
    veil_grid g = grid_around(v, 10.0f, 0.0f);
    veil_result r = veil_vdb_plan_resample(v, &g, &plan, &err);
    CHECK(r == VEIL_ERR_LIMIT && strstr(err.msg, "far_apart.vdb") && strstr(err.msg, "1103x1103x1103") &&
              strstr(err.msg, "over the limit of 1073741824 voxels"),
          "%s: %s", veil_result_name(r), err.msg);
    printf("dense limit: %s\n", err.msg);
    float d[8] = {0};
    veil_grid tiny = {.dims = {2, 2, 2}, .origin = {-10.0f, -10.0f, -10.0f}, .voxel = 100.0f};
    CHECK(veil_vdb_to_grid(v, 1.0f, &tiny, d, &err) == VEIL_ERR_LIMIT, "to_grid refuses too");
    /* a target around the first voxel only reads a small box */
    veil_grid near = {.dims = {4, 4, 4}, .origin = {-0.2f, -0.2f, -0.2f}, .voxel = 0.1f};
    float dn[64] = {0};
    CHECK(veil_vdb_plan_resample(v, &near, &plan, &err) == VEIL_OK && plan.dense_voxels < 1000, "%s", err.msg);
    CHECK(veil_vdb_to_grid(v, 1.0f, &near, dn, &err) == VEIL_OK, "%s", err.msg);
    double sum = 0.0;
    for (int i = 0; i < 64; ++i) sum += dn[i];
    CHECK(check_close(sum, 1.0, 1e-6, 1e-6), "the first voxel's mass: %g", sum);
    /* 2048^3 target voxels over the grid: over the sample budget even at
     * one sample each (plan only: nothing is allocated) */
    veil_grid huge = {.dims = {2048, 2048, 2048}, .origin = {-0.1f, -0.1f, -0.1f}, .voxel = 0.06f};
    r = veil_vdb_plan_resample(v, &huge, &plan, &err);
    CHECK(r == VEIL_ERR_LIMIT && strstr(err.msg, "2048x2048x2048") && strstr(err.msg, "4294967296"), "%s: %s",
          veil_result_name(r), err.msg);
    printf("sample limit: %s\n", err.msg);
    veil_vdb_close(v);
}

/* ---- a scene's VDB source: open with err == NULL, and the volume key ---- */

/* Writes n bytes to path in place (same inode), then sets its access and
 * modification times to sec seconds (utimensat), so that a test controls
 * the file's size and mtime exactly. */
static void write_file(const char* path, const char* bytes, size_t n, time_t sec)
{
    FILE* f = fopen(path, "wb");
    CHECK(f && fwrite(bytes, 1, n, f) == n, "write %s: %s", path, strerror(errno));
    if (f) CHECK(fclose(f) == 0, "close %s", path);
    const struct timespec t[2] = {{.tv_sec = sec}, {.tv_sec = sec}};
    CHECK(utimensat(AT_FDCWD, path, t, 0) == 0, "utimensat %s: %s", path, strerror(errno));
}

/* veil_scene_volume_open(..., err = NULL) fails cleanly (core/result.h lets
 * callers pass NULL; a failed veil_vdb_open once made it read *err), and
 * veil_scene_volume_key() of a VDB source is the file's identity: path,
 * size, mtime (and inode, device), never its bytes, so the key is formed
 * without opening the file. The chosen semantics, checked here: a missing
 * file keys differently from a present one; a new size or mtime changes
 * the key; the same file keys the same twice; new bytes with size and
 * mtime restored keep the key (the renderer's cache then reuses the old
 * volume: writers of VDB files change the mtime, as any rewrite does). */
static void test_scene_volume(void)
{
    char dir[4096], path[4200], json[8700];
    snprintf(dir, sizeof dir, "%s/scene_volume_XXXXXX", g_dir);
    if (!mkdtemp(dir)) {
        CHECK(0, "mkdtemp %s: %s", dir, strerror(errno));
        return;
    }
    snprintf(path, sizeof path, "%s/cloud.vdb", dir);
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0, 0, 4], \"look_at\": [0, 0, 0]},"
             " \"medium\": {\"sigma_s\": [1, 1, 1], \"sources\": [{\"type\": \"vdb\", \"file\": \"%s\"}]}}",
             path);
    /* the parser checks that the file exists; it goes away after */
    write_file(path, "not an OpenVDB file\n", 20, 1000000000);
    veil_scene s;
    veil_error err = {0};
    veil_result r = veil_scene_parse("scene_volume.json", json, strlen(json), &s, &err);
    CHECK(r == VEIL_OK, "scene: %s", err.msg);
    CHECK(unlink(path) == 0, "unlink %s: %s", path, strerror(errno));
    if (r != VEIL_OK) {
        rmdir(dir);
        return;
    }
    veil_scene_volume v;

    /* missing file (removed since the scene was read) */
    memset(&v, 0xA5, sizeof v);
    r = veil_scene_volume_open(&s, &v, NULL);
    CHECK(r == VEIL_ERR_IO, "missing file, err NULL: %s, expected VEIL_ERR_IO", veil_result_name(r));
    CHECK(v.vdb_count == 0 && !v.particles && !v.has_volume, "a failed open leaves *out closed");
    veil_scene_volume_close(&v);
    r = veil_scene_volume_open(&s, &v, &err); /* the same path with a buffer: it says why */
    CHECK(r == VEIL_ERR_IO && strstr(err.msg, "medium.sources[0]") && strstr(err.msg, "cloud.vdb"), "%s: %s",
          veil_result_name(r), err.msg);
    const uint64_t k_missing = veil_scene_volume_key(&s);
    CHECK(veil_scene_volume_key(&s) == k_missing, "the key of a missing file is not stable");

    /* a corrupt file (20 bytes, mtime 10^9 s) */
    write_file(path, "not an OpenVDB file\n", 20, 1000000000);
    memset(&v, 0xA5, sizeof v);
    r = veil_scene_volume_open(&s, &v, NULL);
    CHECK(r == VEIL_ERR_IO, "corrupt file, err NULL: %s, expected VEIL_ERR_IO", veil_result_name(r));
    CHECK(v.vdb_count == 0 && !v.particles && !v.has_volume, "a failed open leaves *out closed");
    r = veil_scene_volume_open(&s, &v, &err);
    CHECK(r == VEIL_ERR_IO && strstr(err.msg, "medium.sources[0]") && strstr(err.msg, "OpenVDB said"), "%s: %s",
          veil_result_name(r), err.msg);
    const uint64_t k1 = veil_scene_volume_key(&s);
    CHECK(k1 != k_missing, "the file appeared and the key stayed %016llx", (unsigned long long)k1);
    CHECK(veil_scene_volume_key(&s) == k1, "an unchanged file's key is not stable");

    /* another size, same mtime */
    write_file(path, "not an OpenVDB file either\n", 27, 1000000000);
    const uint64_t k2 = veil_scene_volume_key(&s);
    CHECK(k2 != k1, "a new size kept the key");
    /* same size, another mtime */
    write_file(path, "not an OpenVDB file either\n", 27, 1000000001);
    const uint64_t k3 = veil_scene_volume_key(&s);
    CHECK(k3 != k2 && k3 != k1, "a new mtime kept the key");
    /* other bytes, size and mtime restored: the same identity, the same key */
    write_file(path, "NOT AN OPENVDB FILE EITHER\n", 27, 1000000001);
    CHECK(veil_scene_volume_key(&s) == k3, "the key changed with the bytes alone: it must not read the file");
    /* unreadable (stat still works): the key is formed without opening. As
     * root the file stays readable, so this would prove nothing. */
    if (geteuid() != 0) {
        CHECK(chmod(path, 0) == 0, "chmod %s: %s", path, strerror(errno));
        CHECK(veil_scene_volume_key(&s) == k3, "the key of an unreadable file differs: it reads the file");
        r = veil_scene_volume_open(&s, &v, NULL);
        CHECK(r == VEIL_ERR_IO, "unreadable file, err NULL: %s", veil_result_name(r));
        chmod(path, 0600);
    } else {
        printf("running as root: the unreadable-file check is skipped\n");
    }
    printf("keys: missing %016llx, 20 B %016llx, 27 B %016llx, new mtime %016llx\n", (unsigned long long)k_missing,
           (unsigned long long)k1, (unsigned long long)k2, (unsigned long long)k3);
    veil_scene_free(&s);
    CHECK(unlink(path) == 0 && rmdir(dir) == 0, "cleaning %s: %s", dir, strerror(errno));
}

int main(int argc, char** argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: %s DATA_DIR CASE\n", argv[0]);
        return 2;
    }
    g_dir = argv[1];
    static const struct {
        const char* name;
        void (*fn)(void);
    } cases[] = {{"open", test_open},       {"select", test_select},       {"level_set", test_level_set},
                 {"types", test_types},     {"bad_files", test_bad_files}, {"empty", test_empty},
                 {"transform", test_transform}, {"threads", test_threads}, {"fast_path", test_fast_path},
                 {"mass", test_mass},       {"rotated", test_rotated},     {"limits", test_limits},
                 {"scene_volume", test_scene_volume}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i)
        if (strcmp(argv[2], cases[i].name) == 0) {
            cases[i].fn();
            return check_finish();
        }
    fprintf(stderr, "%s: unknown case '%s'\n", argv[0], argv[2]);
    return 2;
}
