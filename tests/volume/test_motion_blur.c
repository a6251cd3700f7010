/* Motion blur's blurred grids on the CPU (volume/motion_blur.h, io/vdb.h's
 * veil_vdb_advect_mean), on make_test_vdbs's blur.vdb (voxel h = 0.125 m:
 * a Gaussian puff "density", a value-0 "anchor" that fixes the volume's
 * box, velocities "vel" = (1, 0, 0), "vel_d" (the same as vec3d),
 * "wind.x/.y/.z" (the same as three float grids), "vel_zero", and a float
 * grid "speed"):
 *
 *   test_motion_blur DATA_DIR
 *
 * - the samples and times: N = ceil(D) within [2, 64], midpoints;
 * - a constant velocity: "vel" at 1 m a frame over the shutter [1/16, 9/16]
 *   moves the puff D = 4 voxels, so N = 4 and t_k = 1/8, 2/8, 3/8, 4/8:
 *   shifts of 1, 2, 3, 4 whole voxels, exact in binary. The blurred volume
 *   must equal the mean of the four volumes whose source is moved by those
 *   shifts (a "transform"), voxel by voxel: each value of a shifted volume
 *   is a copy of the grid's (native lattice), the blur's samples land on
 *   index points (trilinear weights 0 and 1), so the only difference is the
 *   blur's rounding of its double mean to float, half an ulp (a float ulp,
 *   FLT_EPSILON |mean|, is the bound);
 * - the same field as vec3d, as a float triple, and in units per second at
 *   another frame rate give the same volume bit for bit;
 * - a zero velocity (or a scale of 0, or a shutter of no length at the
 *   frame) leaves the volume as it is, bit for bit;
 * - a rotation ("swirl": 1 rad a frame about the z axis through world
 *   (-1, 0, 0), a linear field, so trilinear reads it exactly) over four
 *   times: the blurred grid against the grid's own trilinear field read at
 *   the exactly rotated points (veil_vdb_sample_world), for path steps of
 *   at most 4, 2 and 1 voxels: the paths' integrator is second order, so
 *   halving the step must cut the largest error by about 4 (at least 3
 *   asserted), and the coarsest error must stand far above float rounding;
 * - the stage key follows the shutter, the velocity and the frame rate;
 * - bad input: each refused with its field and the file and grid;
 * - the budget and the cancel (issue 41, items 4 and 5): the work counted
 *   before a blur (veil_vdb_advect_work_of) has the blur's own reads a
 *   voxel and bounds its region from above within the block rounding;
 *   displacements of 417 and 4 167 voxels (the issue's) refused with the
 *   numbers before any region is made (resident memory grows by under
 *   64 MiB: the old code grew 6 GB); the blur reports its progress in
 *   parts of at most VEIL_VDB_ADVECT_PART_READS reads plus a leaf's, and a
 *   cancel asked for at a report ends it there, the grid as it was. */
#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <sys/resource.h>

#include "support/check.h"
#include "core/progress.h"
#include "io/scene.h"
#include "io/vdb.h"
#include "volume/motion_blur.h"
#include "volume/scene_volume.h"

static const char* g_dir;

/* The scene of blur.vdb's puff (source 0, its keys `puff`) and its anchor
 * (source 1), with the camera's extra keys `camera` and the root's `root`. */
static void scene_json(char* json, size_t n, const char* file, const char* puff, const char* camera, const char* root)
{
    snprintf(json, n,
             "{\"camera\": {\"position\": [0, 0, 9], \"look_at\": [0, 0, 0]%s}%s,"
             " \"medium\": {\"sigma_s\": [1, 1, 1], \"sources\": ["
             "{\"type\": \"vdb\", \"file\": \"%s/%s\"%s},"
             " {\"type\": \"vdb\", \"file\": \"%s/blur.vdb\", \"grid\": \"anchor\"}]}}",
             camera, root, g_dir, file, puff, g_dir);
}

/* The dense volume of that scene (NULL on error, with the message in err). */
static float* volume_of(const char* puff, const char* camera, const char* root, veil_grid* g, char* note, size_t n,
                        veil_error* err)
{
    char json[8192];
    scene_json(json, sizeof json, "blur.vdb", puff, camera, root);
    veil_scene s;
    veil_scene_volume v;
    memset(&v, 0, sizeof v);
    float* d = NULL;
    veil_result r = veil_scene_parse("blur.json", json, strlen(json), &s, err);
    if (r != VEIL_OK) return NULL;
    r = veil_scene_volume_open(&s, &v, err);
    if (r == VEIL_OK) r = veil_scene_volume_density(&v, &d, err);
    if (r == VEIL_OK) {
        *g = v.grid;
        if (note) snprintf(note, n, "%s", v.resolution);
    }
    veil_scene_volume_close(&v);
    veil_scene_free(&s);
    return d;
}

static int same_grid(const veil_grid* a, const veil_grid* b)
{
    return !memcmp(a->dims, b->dims, sizeof a->dims) && !memcmp(a->origin, b->origin, sizeof a->origin) &&
           a->voxel == b->voxel;
}

static void test_times(void)
{
    CHECK(veil_motion_blur_samples(0.0) == 2 && veil_motion_blur_samples(NAN) == 2, "at least 2 samples");
    CHECK(veil_motion_blur_samples(3.2) == 4 && veil_motion_blur_samples(4.0) == 4, "one a voxel of displacement");
    CHECK(veil_motion_blur_samples(1e9) == VEIL_BLUR_MAX_SAMPLES, "capped");
    double t[4];
    veil_motion_blur_times((const float[2]){0.0625f, 0.5625f}, 4, t);
    CHECK(t[0] == 0.125 && t[1] == 0.25 && t[2] == 0.375 && t[3] == 0.5, "midpoints: %g %g %g %g", t[0], t[1], t[2],
          t[3]);
}

static const char* const SHUTTER = ", \"shutter\": [0.0625, 0.5625]";

static void test_constant(void)
{
    veil_error err = {0};
    veil_grid gb, gs, g0;
    char note[416];
    float* blurred = volume_of(", \"velocity\": {\"grid\": \"vel\", \"unit\": \"frame\"}", SHUTTER, "", &gb, note,
                               sizeof note, &err);
    CHECK(blurred, "%s", err.msg);
    float* still = volume_of("", "", "", &g0, NULL, 0, &err);
    CHECK(still, "%s", err.msg);
    if (!blurred || !still) {
        free(blurred), free(still);
        return;
    }
    printf("blurred: %s\n", note);
    CHECK(strstr(note, "blurred by 'vel': 4 samples, 4 voxels over the shutter"), "the note: %s", note);
    CHECK(same_grid(&gb, &g0), "the anchor keeps the grid: %dx%dx%d vs %dx%dx%d", gb.dims[0], gb.dims[1], gb.dims[2],
          g0.dims[0], g0.dims[1], g0.dims[2]);
    const size_t n = veil_grid_voxels(&gb);
    double* mean = calloc(n, sizeof *mean);
    for (int k = 1; k <= 4 && mean; ++k) {
        char puff[256];
        snprintf(puff, sizeof puff, ", \"transform\": [[1, 0, 0, %g], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]",
                 0.125 * k);
        float* shifted = volume_of(puff, "", "", &gs, NULL, 0, &err);
        CHECK(shifted && same_grid(&gs, &gb), "shift %d: %s", k, shifted ? "another grid" : err.msg);
        if (shifted && same_grid(&gs, &gb))
            for (size_t i = 0; i < n; ++i) mean[i] += 0.25 * shifted[i];
        free(shifted);
    }
    size_t bad = 0, moved = 0;
    double worst = 0.0, sum_b = 0.0, sum_0 = 0.0;
    for (size_t i = 0; mean && i < n; ++i) {
        const double diff = fabs(blurred[i] - mean[i]);
        bad += diff > FLT_EPSILON * mean[i];
        worst = fmax(worst, diff);
        moved += fabs((double)blurred[i] - still[i]) > 0.1;
        sum_b += blurred[i], sum_0 += still[i];
    }
    printf("constant velocity: %zu voxels, worst |blurred - mean of shifts| %.3g, %zu voxels moved by > 0.1\n", n,
           worst, moved);
    CHECK(bad == 0, "%zu voxels differ from the mean of the shifted volumes by more than an ulp (worst %.3g)", bad,
          worst);
    CHECK(moved > 100, "the blur moved only %zu voxels: the comparison is vacuous", moved);
    /* the puff stays inside the box, so every shift keeps its mass: so does the mean */
    CHECK(check_close(sum_b, sum_0, 0.0, 1e-6), "mass %.9g blurred, %.9g still", sum_b, sum_0);
    free(mean);

    /* the same field otherwise given: bit for bit */
    static const char* const same[] = {
        ", \"velocity\": {\"grid\": \"vel_d\", \"unit\": \"frame\"}",
        ", \"velocity\": {\"grid\": \"wind\", \"unit\": \"frame\"}",
        ", \"velocity\": {\"grid\": \"vel\", \"unit\": \"second\", \"scale\": 48}", /* at 48 fps: 1 m a frame */
        ", \"velocity\": {\"unit\": \"frame\"}",                                  /* found by name: "vel" */
    };
    for (size_t c = 0; c < sizeof same / sizeof *same; ++c) {
        float* other = volume_of(same[c], SHUTTER, c == 2 ? ", \"fps\": 48" : "", &gs, note, sizeof note, &err);
        CHECK(other && same_grid(&gs, &gb) && !memcmp(other, blurred, n * sizeof *other), "%s: %s", same[c],
              other ? "another volume" : err.msg);
        if (c == 1) CHECK(strstr(note, "blurred by 'wind.x/.y/.z'"), "the triple's note: %s", note);
        const char* unread = strstr(note, "not read: ");
        if (c == 1) CHECK(!unread || !strstr(unread, "wind.x ("), "the triple read, not unread: %s", note);
        free(other);
    }
    free(blurred);

    /* a zero velocity, and a shutter of no length: the volume as it is */
    static const char* const none[][2] = {
        {", \"velocity\": {\"grid\": \"vel_zero\", \"unit\": \"frame\"}", ", \"shutter\": [-0.5, 0.5]"},
        {", \"velocity\": {\"grid\": \"vel\", \"unit\": \"frame\"}", ", \"shutter\": [0, 0]"},
        {", \"velocity\": {\"grid\": \"vel\", \"scale\": 0}", ", \"shutter\": [-0.5, 0.5]"},
    };
    for (size_t c = 0; c < sizeof none / sizeof *none; ++c) {
        float* same0 = volume_of(none[c][0], none[c][1], "", &gs, note, sizeof note, &err);
        CHECK(same0 && same_grid(&gs, &g0) && !memcmp(same0, still, n * sizeof *same0), "%s%s: %s", none[c][0],
              none[c][1], same0 ? "changed the volume" : err.msg);
        CHECK(strstr(note, "(no motion)"), "the note of no motion: %s", note);
        free(same0);
    }
    free(still);
}

/* The rotation's convergence (above). */
static void test_rotation(void)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/blur.vdb", g_dir);
    veil_error err = {0};
    veil_vdb_velocity* vel = NULL;
    veil_vdb* grid = NULL;
    CHECK(veil_vdb_velocity_open(path, "swirl", &vel, NULL, 0, &err) == VEIL_OK, "%s", err.msg);
    CHECK(veil_vdb_open(path, "density", 0, &grid, NULL, 0, &err) == VEIL_OK, "%s", err.msg);
    if (!vel || !grid) {
        veil_vdb_velocity_close(vel), veil_vdb_close(grid);
        return;
    }
    enum { T = 4 };
    const double t[T] = {0.0625, 0.1875, 0.3125, 0.4375}, h = 0.125, c[2] = {-1.0, 0.0};
    /* the puff (radius 9 voxels about index 0) turns about index (-8, 0) by at most 0.5 rad: this box
     * holds every voxel it reaches */
    const int lo[3] = {-28, -20, -12}, hi[3] = {12, 20, 12};
    const size_t n = (size_t)(hi[0] - lo[0] + 1) * (size_t)(hi[1] - lo[1] + 1) * (size_t)(hi[2] - lo[2] + 1);
    double* xyz = malloc(n * T * 3 * sizeof *xyz);
    float* exact_k = malloc(n * T * sizeof *exact_k);
    float* got = malloc(n * sizeof *got);
    if (!xyz || !exact_k || !got) {
        CHECK(0, "out of memory");
        free(xyz), free(exact_k), free(got);
        veil_vdb_velocity_close(vel), veil_vdb_close(grid);
        return;
    }
    size_t i = 0;
    for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
            for (int x = lo[0]; x <= hi[0]; ++x, ++i)
                for (int k = 0; k < T; ++k) { /* the point whose density the flow brings here in t_k: R(-t_k) */
                    const double px = x * h - c[0], py = y * h - c[1], a = -t[k];
                    double* q = xyz + 3 * (i * T + (size_t)k);
                    q[0] = c[0] + cos(a) * px - sin(a) * py, q[1] = c[1] + sin(a) * px + cos(a) * py, q[2] = z * h;
                }
    CHECK(veil_vdb_sample_world(grid, xyz, n * T, exact_k, &err) == VEIL_OK, "%s", err.msg);
    double e[3] = {0, 0, 0}, most = 0.0;
    for (int s = 0; s < 3; ++s) {
        veil_vdb* b = NULL;
        CHECK(veil_vdb_open(path, "density", 0, &b, NULL, 0, &err) == VEIL_OK, "%s", err.msg);
        const veil_vdb_advect_desc d = {t, T, 1.0, 4.0 / (1 << s), 0};
        if (b && veil_vdb_advect_mean(b, vel, &d, NULL, &err) == VEIL_OK && veil_vdb_dense(b, lo, hi, got) == VEIL_OK)
            for (size_t j = 0; j < n; ++j) {
                double exact = 0.0;
                for (int k = 0; k < T; ++k) exact += exact_k[j * T + (size_t)k] / T;
                e[s] = fmax(e[s], fabs(got[j] - exact));
                most = fmax(most, exact);
            }
        else
            CHECK(0, "step %g: %s", d.max_step_voxels, err.msg);
        veil_vdb_close(b);
    }
    printf("rotation: largest error %.3g, %.3g, %.3g for steps of 4, 2, 1 voxels (ratios %.2f, %.2f; density up to "
           "%.3g)\n", e[0], e[1], e[2], e[0] / e[1], e[1] / e[2], most);
    CHECK(e[0] >= 3.0 * e[1] && e[1] >= 3.0 * e[2], "not second order: errors %.3g, %.3g, %.3g", e[0], e[1], e[2]);
    /* float rounding of the blurred mean: half an ulp of values up to `most` */
    CHECK(e[2] > 100.0 * FLT_EPSILON * most, "the finest error %.3g is at rounding's level: the slope is vacuous",
          e[2]);
    free(xyz), free(exact_k), free(got);
    veil_vdb_velocity_close(vel), veil_vdb_close(grid);
}

/* The stage key: the shutter, the velocity and the frame rate make the grids. */
static void test_key(void)
{
    static const char* const scenes[][3] = {
        {"", "", ""},
        {", \"velocity\": {}", "", ""}, /* no shutter: no blur, the same key as none */
        {", \"velocity\": {}", ", \"shutter\": [0, 0.5]", ""},
        {", \"velocity\": {}", ", \"shutter\": [0, 0.25]", ""},
        {", \"velocity\": {}", ", \"shutter\": [0, 0.25]", ", \"fps\": 30"},
        {", \"velocity\": {\"scale\": 2}", ", \"shutter\": [0, 0.25]", ", \"fps\": 30"},
        {", \"velocity\": {\"unit\": \"frame\"}", ", \"shutter\": [0, 0.25]", ", \"fps\": 30"},
        {", \"velocity\": {\"grid\": \"wind\"}", ", \"shutter\": [0, 0.25]", ", \"fps\": 30"},
        {"", ", \"shutter\": [0, 0.25]", ""}, /* a shutter without a velocity: no blur */
    };
    enum { N = sizeof scenes / sizeof *scenes };
    uint64_t key[N];
    for (int i = 0; i < N; ++i) {
        char json[8192];
        veil_scene s;
        veil_error err = {0};
        scene_json(json, sizeof json, "blur.vdb", scenes[i][0], scenes[i][1], scenes[i][2]);
        key[i] = 0;
        CHECK(veil_scene_parse("key.json", json, strlen(json), &s, &err) == VEIL_OK, "%s", err.msg);
        key[i] = veil_scene_volume_key(&s);
        veil_scene_free(&s);
    }
    CHECK(key[0] == key[1] && key[0] == key[8], "a scene that blurs nothing keys as one without blur");
    for (int i = 1; i < N - 1; ++i)
        for (int j = i + 1; j < N - 1; ++j) CHECK(key[i] != key[j], "scenes %d and %d share a key", i, j);
}

/* A scene refused: at parse (parse 1) or when the volume is opened, with `want` in the message. */
static void refused(const char* file, const char* puff, const char* camera, const char* root, int parse,
                    const char* want)
{
    char json[8192];
    scene_json(json, sizeof json, file, puff, camera, root);
    veil_scene s;
    veil_scene_volume v;
    memset(&v, 0, sizeof v);
    veil_error err = {0};
    veil_result r = veil_scene_parse("bad.json", json, strlen(json), &s, &err);
    if (r == VEIL_OK) {
        CHECK(!parse, "%s%s%s: parsed, expected '%s'", puff, camera, root, want);
        r = veil_scene_volume_open(&s, &v, &err);
        veil_scene_volume_close(&v);
        veil_scene_free(&s);
    }
    CHECK(r == VEIL_ERR_INVALID && strstr(err.msg, want), "%s%s%s: result %d, '%s', expected '%s'", puff, camera,
          root, (int)r, err.msg, want);
    if (r != VEIL_OK) printf("refused: %s\n", err.msg);
}

static void test_bad_input(void)
{
    const char* vel = ", \"velocity\": {}";
    refused("blur.vdb", ", \"velocity\": {\"unit\": \"minute\"}", SHUTTER, "", 1,
            "bad.json: medium.sources[0].velocity.unit: expected one of \"second\", \"frame\", got a string (\"minute\")");
    refused("blur.vdb", ", \"velocity\": {\"scale\": -1}", SHUTTER, "", 1, "medium.sources[0].velocity.scale: expected "
            "a number in [0, 1e6]");
    refused("blur.vdb", ", \"velocity\": {\"speed\": 1}", SHUTTER, "", 1, "medium.sources[0].velocity.speed: unknown key");
    refused("blur.vdb", ", \"velocity\": \"vel\"", SHUTTER, "", 1, "medium.sources[0].velocity: expected an object");
    refused("blur.vdb", vel, ", \"shutter\": [0.5, -0.5]", "", 1,
            "bad.json: camera.shutter: expected [open, close] with open <= close (frames relative to the frame), got "
            "[0.5, -0.5]");
    refused("blur.vdb", vel, ", \"shutter\": [0, 10]", "", 1, "camera.shutter[1]: expected a number of frames in [-4, 4]");
    refused("blur.vdb", vel, ", \"shutter\": [0]", "", 1, "camera.shutter: expected an array of 2");
    refused("blur.vdb", vel, SHUTTER, ", \"fps\": 0", 1, "bad.json: fps: expected a number of frames per second in "
            "(0, 1000], got 0");
    refused("blur.vdb", vel, SHUTTER, ", \"fps\": 1e9", 1, "fps: expected a number of frames per second in (0, 1000]");
    char want[4400];
    snprintf(want, sizeof want, "medium.sources[0].velocity.grid: %s/blur.vdb: no velocity grid named 'nope' (a vec3 "
             "grid, or three float grids 'nope.x', .y, .z); the file has 'anchor' (float", g_dir);
    refused("blur.vdb", ", \"velocity\": {\"grid\": \"nope\"}", SHUTTER, "", 0, want);
    snprintf(want, sizeof want, "medium.sources[0].velocity.grid: %s/blur.vdb: grid 'speed' has value type float, "
             "not a vector", g_dir);
    refused("blur.vdb", ", \"velocity\": {\"grid\": \"speed\"}", SHUTTER, "", 0, want);
    snprintf(want, sizeof want, "medium.sources[0].velocity: %s/fog_sphere.vdb: no velocity grid: looked for 'vel', "
             "'v' and 'velocity'", g_dir);
    refused("fog_sphere.vdb", vel, SHUTTER, "", 0, want);

    /* without a shutter the velocity is not read: a missing one is no error */
    char json[8192];
    veil_scene s;
    veil_scene_volume v;
    memset(&v, 0, sizeof v);
    veil_error err = {0};
    scene_json(json, sizeof json, "fog_sphere.vdb", vel, "", "");
    veil_result r = veil_scene_parse("ok.json", json, strlen(json), &s, &err);
    if (r == VEIL_OK) r = veil_scene_volume_open(&s, &v, &err), veil_scene_free(&s);
    CHECK(r == VEIL_OK, "no shutter, no velocity read: %s", err.msg);
    veil_scene_volume_close(&v);
}

/* ---- the budget and the cancel (issue 41) ------------------------------------------------------------- */

static double max_rss_mib(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)u.ru_maxrss / 1024.0;
}

/* The work counted before a blur against the blur's own report, for the puff under "vel" (scale s) over
 * the four times of SHUTTER. */
static void work_against_blur(const char* path, const char* velocity, double scale)
{
    veil_error err = {0};
    veil_vdb_velocity* vel = NULL;
    veil_vdb* g = NULL;
    CHECK(veil_vdb_velocity_open(path, velocity, &vel, NULL, 0, &err) == VEIL_OK, "%s", err.msg);
    CHECK(veil_vdb_open(path, "density", 0, &g, NULL, 0, &err) == VEIL_OK, "%s", err.msg);
    const double t[4] = {0.125, 0.25, 0.375, 0.5};
    const veil_vdb_advect_desc d = {t, 4, scale, 1.0, 1};
    veil_vdb_advect_work w;
    veil_vdb_advect_report rep;
    if (g && vel && veil_vdb_advect_work_of(g, vel, &d, &w, &err) == VEIL_OK &&
        veil_vdb_advect_mean(g, vel, &d, &rep, &err) == VEIL_OK) {
        const double region = rep.reads / w.reads_per_voxel; /* the grown region's voxels, as made */
        /* the mask rounds each grown box out to blocks of b voxels: at most 2b more a side */
        const double b = w.reach / 32 > 8 ? pow(2.0, ceil(log2(w.reach / 32.0))) : 8.0, side = 19.0 + 2 * w.reach;
        const double bound = pow((side + 2 * b) / side, 3.0);
        printf("work: %s x %g: reach %d, %.0f reads a voxel, %.4g voxels counted, %.4g made (%.3f; bound %.3f)\n",
               velocity, scale, w.reach, w.reads_per_voxel, w.voxels, region, w.voxels / region, bound);
        CHECK(w.reach == rep.reach && !w.at_least, "%s x %g: reach %d, blur's %d", velocity, scale, w.reach, rep.reach);
        CHECK(region == floor(region) && w.reads_per_voxel >= 4 + 1, "%s x %g: reads a voxel %g do not divide the "
              "blur's %g", velocity, scale, w.reads_per_voxel, rep.reads);
        CHECK(w.voxels >= region && w.voxels <= bound * region, "%s x %g: counted %.4g voxels, made %.4g (bound %.3f)",
              velocity, scale, w.voxels, region, bound);
    } else {
        CHECK(0, "%s x %g: %s", velocity, scale, err.msg);
    }
    veil_vdb_close(g);
    veil_vdb_velocity_close(vel);
}

typedef struct cancel_log {
    int reports, after_cancel, cancel_at; /* cancel at this report (0: never) */
    double last_done, last_total, bad_order;
} cancel_log;

static void on_blur_progress(void* user, const char* what, double done, double total)
{
    cancel_log* c = user;
    if (strcmp(what, "motion blur") != 0) return;
    if (c->cancel_at && c->reports >= c->cancel_at) ++c->after_cancel;
    if (done < c->last_done || done > total) ++c->bad_order;
    c->last_done = done, c->last_total = total;
    if (++c->reports == c->cancel_at) veil_progress_cancel();
}

static void test_budget(void)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/blur.vdb", g_dir);
    work_against_blur(path, "vel", 1.0);
    work_against_blur(path, "vel", 6.0);   /* reach 25 */
    work_against_blur(path, "swirl", 1.5); /* a rotation: the region is still every leaf's box grown */

    /* refusals before any region is made: "vel" 1 m a frame over [-0.5, 0.5] frames moves the puff 8 s
     * voxels; 417 and 4 167 voxels are the (45 min of CPU, and 6 GB before any voxel, before) */
    const double rss0 = max_rss_mib();
    const double scales[2] = {417.0 / 8.0, 4167.0 / 8.0};
    for (int i = 0; i < 2; ++i) {
        char puff[160];
        snprintf(puff, sizeof puff, ", \"velocity\": {\"grid\": \"vel\", \"unit\": \"frame\", \"scale\": %.17g}",
                 scales[i]);
        char json[8192];
        scene_json(json, sizeof json, "blur.vdb", puff, ", \"shutter\": [-0.5, 0.5]", "");
        veil_scene s;
        veil_scene_volume v;
        memset(&v, 0, sizeof v);
        veil_error err = {0};
        veil_result r = veil_scene_parse("budget.json", json, strlen(json), &s, &err);
        if (r == VEIL_OK) r = veil_scene_volume_open(&s, &v, &err), veil_scene_free(&s);
        veil_scene_volume_close(&v);
        printf("refused: %s\n", err.msg);
        int digits = 0, run = 0; /* a number printed whole (the old "78749999750277699697348859396096.000000") */
        for (const char* c = err.msg; *c; ++c) run = (*c >= '0' && *c <= '9') ? run + 1 : 0, digits = run > digits ? run : digits;
        CHECK(r == VEIL_ERR_LIMIT && strstr(err.msg, "medium.sources[0]: motion blur") &&
                  strstr(err.msg, "grid 'density'") && strstr(err.msg, "s of CPU time, over the budget of 40 s") &&
                  strstr(err.msg, "unit and scale") && digits < 8,
              "displacement %.0f: %s: %s", 8 * scales[i], veil_result_name(r), err.msg);
    }
    CHECK(max_rss_mib() - rss0 < 64.0, "the refusals grew resident memory by %.0f MiB", max_rss_mib() - rss0);

    /* progress in parts, and a cancel at a report: "vel" x 12 moves the puff 36 voxels from t = 0 (6e7
     * reads: about 3 s of CPU) */
    veil_error err = {0};
    veil_vdb_velocity* vel = NULL;
    veil_vdb* g = NULL;
    CHECK(veil_vdb_velocity_open(path, "vel", &vel, NULL, 0, &err) == VEIL_OK, "%s", err.msg);
    const double t[4] = {-0.375, -0.125, 0.125, 0.375};
    const veil_vdb_advect_desc d = {t, 4, 12.0, 1.0, 1};
    for (int cancel_at = 0; cancel_at <= 2 && vel; cancel_at += 2) {
        CHECK(veil_vdb_open(path, "density", 0, &g, NULL, 0, &err) == VEIL_OK, "%s", err.msg);
        if (!g) break;
        int lo[3], hi[3];
        size_t before = 0, after = 0;
        veil_vdb_index_bbox(g, lo, hi, &before);
        veil_vdb_advect_work w = {0};
        veil_vdb_advect_report rep = {0};
        CHECK(veil_vdb_advect_work_of(g, vel, &d, &w, &err) == VEIL_OK, "%s", err.msg);
        cancel_log log = {.cancel_at = cancel_at};
        void* old_user = NULL;
        veil_progress_fn old = veil_progress_sink(on_blur_progress, &log, &old_user);
        veil_result r = veil_vdb_advect_mean(g, vel, &d, &rep, &err);
        veil_progress_sink(old, old_user, NULL);
        /* a part is at most PART_READS reads, plus one leaf's (a part holds whole leaves) */
        const double part = VEIL_VDB_ADVECT_PART_READS + 512.0 * w.reads_per_voxel;
        if (!cancel_at) {
            printf("progress: %d reports over %.3g reads (parts of at most %.3g)\n", log.reports, rep.reads, part);
            CHECK(r == VEIL_OK && log.bad_order == 0 && log.last_done == log.last_total && log.last_total > 0,
                  "progress: %s: %s, %g of %g", veil_result_name(r), err.msg, log.last_done, log.last_total);
            CHECK(log.reports >= 3 && (log.reports - 1) * part >= rep.reads, "%d reports for %.3g reads", log.reports,
                  rep.reads);
        } else {
            veil_vdb_index_bbox(g, lo, hi, &after);
            CHECK(r == VEIL_ERR_CANCELLED && log.after_cancel == 0 && strstr(err.msg, "motion blur cancelled") &&
                      after == before,
                  "cancel at report %d: %s: %s, %d reports after it", cancel_at, veil_result_name(r), err.msg,
                  log.after_cancel);
        }
        veil_vdb_close(g);
        g = NULL;
    }
    veil_vdb_velocity_close(vel);
}

int main(int argc, char** argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_motion_blur DATA_DIR\n");
        return 2;
    }
    g_dir = argv[1];
    test_times();
    test_constant();
    test_rotation();
    test_key();
    test_bad_input();
    test_budget();
    return check_finish();
}
