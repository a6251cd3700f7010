/* The environment light (scene/environment.h): the lat-long convention and rotation as documented, the
 * texels' solid angles, the median cut's lights (their irradiance is the map's integral; a sun's light
 * points at the sun), the importance sampling's pdf (consistent with its samples, normalised, and
 * proportional to luminance: luminance / pdf is the same for every sample), the split into a bright part
 * and a rest (test_split says what is checked), and the scene reader
 * (a constant sky, a map from an EXR, every bad field refused with its path). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "core/rng.h"
#include "support/temp_files.h"
#include "io/image.h"
#include "io/scene.h"
#include "scene/environment.h"

#define PI 3.14159265358979323846

static double lum(const double c[3]) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

/* A w x h map of "lights": 1, its texels to be filled (malloc'd). */
static veil_environment blank_map(int w, int h)
{
    veil_environment e;
    memset(&e, 0, sizeof e);
    e.present = 1, e.width = w, e.height = h, e.lights = 1;
    e.rgb = malloc((size_t)w * h * 3 * sizeof *e.rgb);
    if (!e.rgb) exit(2); /* (a test's few kB) */
    return e;
}

/* A w x h map whose texel (i, j) holds (i, j, 1 + i + w j). */
static veil_environment indexed(int w, int h)
{
    veil_environment e = blank_map(w, h);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            float* t = e.rgb + 3 * ((size_t)j * w + i);
            t[0] = (float)i, t[1] = (float)j, t[2] = (float)(1 + i + w * j);
        }
    return e;
}

static void seen(const veil_environment* e, double x, double y, double z, int* i, int* j)
{
    double n = sqrt(x * x + y * y + z * z), d[3] = {x / n, y / n, z / n}, c[3];
    veil_env_radiance(e, d, c);
    *i = (int)c[0], *j = (int)c[1];
}

static void test_convention(void)
{
    veil_environment e = indexed(8, 4);
    int i, j;
    seen(&e, 0, 1, 0, &i, &j);
    CHECK(j == 0, "+Y is the top row: row %d", j);
    seen(&e, 0, -1, 0, &i, &j);
    CHECK(j == 3, "-Y is the bottom row: row %d", j);
    seen(&e, 1, 0.01, 0.001, &i, &j); /* just above the horizon, along +X: the middle column */
    CHECK(i == 4 && j == 1, "+X: texel (%d, %d), expected (4, 1)", i, j);
    seen(&e, 1, -0.01, -0.001, &i, &j); /* just below, the column before the middle */
    CHECK(i == 3 && j == 2, "+X below: texel (%d, %d), expected (3, 2)", i, j);
    seen(&e, 0.001, 0, -1, &i, &j); /* -Z: a quarter in */
    CHECK(i == 2, "-Z: column %d, expected 2", i);
    seen(&e, 0.001, 0, 1, &i, &j); /* +Z: three quarters in */
    CHECK(i == 5, "+Z (x > 0): column %d, expected 5", i);
    seen(&e, -1, 0, 0.001, &i, &j); /* -X: the seam, the last column on one side and the first on the other */
    CHECK(i == 7, "-X, z > 0: column %d, expected 7", i);
    seen(&e, -1, 0, -0.001, &i, &j);
    CHECK(i == 0, "-X, z < 0: column %d, expected 0", i);
    /* rotation +90 about +Y brings what was along +X to -Z */
    e.rotation_deg = 90.0f;
    seen(&e, 0.001, 0.01, -1, &i, &j);
    CHECK(i == 4 && j == 1, "rotated: -Z sees texel (%d, %d), +X's (4, 1) before", i, j);
    /* up "z": Blender's axes, its equirectangular convention: +Z the top row, +X the middle column, +Y a
     * quarter in; a rotation of +90 about +Z brings +X to +Y */
    e.rotation_deg = 0.0f;
    e.up_z = 1;
    seen(&e, 0, 0, 1, &i, &j);
    CHECK(j == 0, "up z: +Z is the top row: row %d", j);
    seen(&e, 1, -0.001, 0.01, &i, &j);
    CHECK(i == 4 && j == 1, "up z: +X: texel (%d, %d), expected (4, 1)", i, j);
    seen(&e, 0.001, 1, 0, &i, &j);
    CHECK(i == 2, "up z: +Y: column %d, expected 2", i);
    e.rotation_deg = 90.0f;
    seen(&e, 0.001, 1, 0.01, &i, &j); /* (1, -0.001, 0.01) turned by +90 about +Z */
    CHECK(i == 4 && j == 1, "up z, rotated: +Y sees texel (%d, %d), +X's (4, 1) before", i, j);
    veil_env_free(&e);
    CHECK(e.rgb == NULL && !e.present, "veil_env_free zeroes");
}

static void test_solid_angles(void)
{
    /* the rows' solid angles telescope to 4 pi: exact up to rounding (1e-12) */
    const int dims[][2] = {{2, 1}, {64, 32}, {512, 256}, {7, 5}};
    for (size_t k = 0; k < sizeof dims / sizeof dims[0]; ++k) {
        double sum = 0.0;
        for (int j = 0; j < dims[k][1]; ++j) sum += dims[k][0] * veil_env_texel_solid_angle(dims[k][0], dims[k][1], j);
        CHECK(fabs(sum - 4.0 * PI) <= 1e-12 * 4.0 * PI, "%dx%d: solid angles sum to %.15g", dims[k][0], dims[k][1], sum);
    }
}

/* A map black but for a disc of `deg` around unit direction s (radiance sun) and, with sky > 0, a sky. */
static veil_environment sun_map(int w, int h, const double s[3], double deg, float sun, float sky)
{
    veil_environment e = blank_map(w, h);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            double t = PI * (j + 0.5) / h, p = 2 * PI * (i + 0.5) / w;
            double d[3] = {-sin(t) * cos(p), cos(t), -sin(t) * sin(p)};
            int in = d[0] * s[0] + d[1] * s[1] + d[2] * s[2] > cos(deg * PI / 180.0);
            float* x = e.rgb + 3 * ((size_t)j * w + i);
            x[0] = in ? sun : sky * (float)(0.5 + 0.5 * d[1]);
            x[1] = in ? 0.9f * sun : sky * 0.8f;
            x[2] = in ? 0.8f * sun : sky;
        }
    return e;
}

static void test_median_cut(void)
{
    veil_light L[VEIL_MAX_LIGHTS];
    /* a constant sky: K lights whose irradiances sum to 4 pi L (float sums of 2048 texels: 1e-5) */
    veil_environment c;
    memset(&c, 0, sizeof c);
    float one[3] = {0.5f, 0.25f, 2.0f};
    c.present = 1, c.width = c.height = 1, c.rgb = one;
    for (int k = 1; k <= VEIL_MAX_LIGHTS; k *= 2) {
        int n = veil_env_median_cut(&c, k, L);
        CHECK(n == k, "constant sky: %d lights of %d", n, k);
        double sum[3] = {0, 0, 0};
        for (int l = 0; l < n; ++l)
            for (int a = 0; a < 3; ++a) sum[a] += L[l].color[a];
        for (int a = 0; a < 3; ++a)
            CHECK(fabs(sum[a] - 4 * PI * one[a]) <= 1e-5 * 4 * PI * one[a], "constant sky, K %d: irradiance %g, "
                  "expected 4 pi L = %g", k, sum[a], 4 * PI * one[a]);
        for (int l = 0; l < n; ++l)
            CHECK(L[l].type == VEIL_LIGHT_DIRECTIONAL && fabs(L[l].direction[0] * L[l].direction[0] +
                  L[l].direction[1] * L[l].direction[1] + L[l].direction[2] * L[l].direction[2] - 1.0) < 1e-5,
                  "constant sky, K %d: light %d is not a unit directional light", k, l);
    }
    /* a sun alone, K 1: the light points from the sun (travels along -s) within the disc's radius plus a
     * texel's diagonal (the centroid of the disc's texels lies within the disc); its irradiance the
     * disc's sum */
    const double s[3] = {0.48, 0.6, -0.64};
    veil_environment e = sun_map(256, 128, s, 3.0, 1000.0f, 0.0f);
    double total[3];
    veil_env_integral(&e, total);
    int n = veil_env_median_cut(&e, 1, L);
    double cosang = -(L[0].direction[0] * s[0] + L[0].direction[1] * s[1] + L[0].direction[2] * s[2]);
    double texel = sqrt(2.0) * 2 * PI / 256;
    CHECK(n == 1 && cosang >= cos(3.0 * PI / 180 + texel), "sun: %d lights, %.3f degrees off", n,
          acos(fmin(1, cosang)) * 180 / PI);
    CHECK(fabs(L[0].color[0] - total[0]) <= 1e-5 * total[0], "sun: irradiance %g, the map's %g", L[0].color[0], total[0]);
    /* with e rotated by 90 degrees the light turns with it: s = (x, y, z) -> (z, y, -x) */
    e.rotation_deg = 90.0f;
    n = veil_env_median_cut(&e, 1, L);
    const double r[3] = {s[2], s[1], -s[0]};
    cosang = -(L[0].direction[0] * r[0] + L[0].direction[1] * r[1] + L[0].direction[2] * r[2]);
    CHECK(n == 1 && cosang >= cos(3.0 * PI / 180 + texel), "rotated sun: %.3f degrees off", acos(fmin(1, cosang)) * 180 / PI);
    /* up "z": the sun at map direction s is at world (s.x, -s.z, s.y) */
    e.rotation_deg = 0.0f;
    e.up_z = 1;
    n = veil_env_median_cut(&e, 1, L);
    const double z[3] = {s[0], -s[2], s[1]};
    cosang = -(L[0].direction[0] * z[0] + L[0].direction[1] * z[1] + L[0].direction[2] * z[2]);
    CHECK(n == 1 && cosang >= cos(3.0 * PI / 180 + texel), "up z sun: %.3f degrees off", acos(fmin(1, cosang)) * 180 / PI);
    veil_env_free(&e);
    /* a sun and a sky, K 8: the sum is the integral; the brightest light is the sun's */
    e = sun_map(256, 128, s, 2.0, 2000.0f, 0.4f);
    veil_env_integral(&e, total);
    n = veil_env_median_cut(&e, 8, L);
    double sum = 0.0, best = -1.0;
    int bright = 0;
    for (int l = 0; l < n; ++l) {
        sum += L[l].color[2];
        if (L[l].color[0] > best) best = L[l].color[0], bright = l;
    }
    CHECK(n == 8 && fabs(sum - total[2]) <= 1e-5 * total[2], "sun and sky: %d lights, irradiance %g of %g", n, sum,
          total[2]);
    cosang = -(L[bright].direction[0] * s[0] + L[bright].direction[1] * s[1] + L[bright].direction[2] * s[2]);
    CHECK(cosang >= cos(2.0 * PI / 180 + texel), "sun and sky: the brightest light %.3f degrees off the sun",
          acos(fmin(1, cosang)) * 180 / PI);
    /* black: no light */
    veil_env_free(&e);
    e = sun_map(16, 8, s, 2.0, 0.0f, 0.0f);
    CHECK(veil_env_median_cut(&e, 8, L) == 0, "a black map makes no light");
    veil_env_free(&e);
}

static void test_sampling(void)
{
    veil_error err = {0};
    const double s[3] = {0.48, 0.6, -0.64};
    veil_environment e = sun_map(128, 64, s, 4.0, 500.0f, 0.3f);
    e.rotation_deg = 30.0f;
    e.up_z = 1; /* (the normalisation below walks the texels in the +Y-up frame: turned into the world's) */
    CHECK(veil_env_dist_make(&e, &err) == VEIL_OK, "dist: %s", err.msg);
    /* normalised: sum over texels of pdf x solid angle = 1 (rounding: 1e-9) */
    double norm = 0.0;
    for (int j = 0; j < 64; ++j)
        for (int i = 0; i < 128; ++i) {
            double t = PI * (j + 0.5) / 64, p = 2 * PI * (i + 0.5) / 128, r = 30.0 * PI / 180;
            double m[3] = {-sin(t) * cos(p), cos(t), -sin(t) * sin(p)};
            double y[3] = {m[0] * cos(r) + m[2] * sin(r), m[1], -m[0] * sin(r) + m[2] * cos(r)};
            double d[3] = {y[0], -y[2], y[1]};
            norm += veil_env_pdf(&e, d) * veil_env_texel_solid_angle(128, 64, j);
        }
    CHECK(fabs(norm - 1.0) <= 1e-9, "pdf integrates to %.12f", norm);
    /* each sample: a unit vector whose pdf is veil_env_pdf's, and luminance / pdf the map's luminance
     * integral (pdf proportional to luminance: an estimator of zero variance), up to rounding (1e-9),
     * except on texel boundaries, where the two may name neighbouring texels (measure zero: allowed in
     * at most 1 in 1000) */
    double total[3];
    veil_env_integral(&e, total);
    const double want = lum(total);
    uint64_t x = 26;
    int off = 0, bad_unit = 0;
    const int N = 20000;
    for (int k = 0; k < N; ++k) {
        double u[3];
        for (int a = 0; a < 3; ++a) u[a] = veil_rng_double53(&x);
        double d[3], L[3];
        double pdf = veil_env_sample(&e, u[0], u[1], u[2], d);
        bad_unit += fabs(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - 1.0) > 1e-12;
        veil_env_radiance(&e, d, L);
        double p2 = veil_env_pdf(&e, d);
        off += !(fabs(p2 - pdf) <= 1e-9 * pdf && fabs(lum(L) / pdf - want) <= 1e-6 * want);
    }
    CHECK(bad_unit == 0, "%d samples not unit vectors", bad_unit);
    CHECK(off <= N / 1000, "%d of %d samples: pdf inconsistent or not proportional to luminance", off, N);
    veil_env_free(&e);
    /* a black map samples the sphere uniformly: pdf 1 / (4 pi) */
    e = sun_map(32, 16, s, 4.0, 0.0f, 0.0f);
    CHECK(veil_env_dist_make(&e, &err) == VEIL_OK, "dist: %s", err.msg);
    double d[3], pdf = veil_env_sample(&e, 0.3, 0.6, 0.2, d);
    CHECK(fabs(pdf - 1.0 / (4 * PI)) <= 1e-9, "black map: pdf %g, expected 1/(4 pi)", pdf);
    veil_env_free(&e);
}

/* The split (scene/environment.h): the bright part and the rest sum to the map; the rest is the map with
 * each texel's luminance capped at the clip (computed here from the texels, independently); a constant sky
 * has no bright part; a sun under VEIL_ENV_POINT_DEG across is one light carrying the bright part, along
 * it; two suns far apart are two lights (the regions shrink to their lit texels); the photons' table holds
 * the rest's luminance integral, with a CDF that rises to 1, in blocks or not. */
static void test_split(void)
{
    veil_light L[VEIL_MAX_LIGHTS];
    const double s[3] = {0.48, 0.6, -0.64};
    static const int rungs[1] = {8};
    veil_environment e = sun_map(256, 128, s, 1.5, 2000.0f, 0.3f); /* a disc of 1.5 degrees' radius: 3 across */
    e.lights = 0;
    veil_env_make_cuts(&e, 16, rungs, 1);
    double all[3], bright[3], rest[3], mine[3] = {0, 0, 0}, total[3];
    veil_env_integral(&e, all);
    veil_env_part_integral(&e, 1, bright);
    veil_env_part_integral(&e, 0, rest);
    CHECK(fabs(e.clip - 8.0 * lum(all) / (4 * PI)) <= 1e-12 * e.clip, "the clip %.9g is not 8 times the mean", e.clip);
    for (int j = 0; j < 128; ++j)
        for (int i = 0; i < 256; ++i) {
            const float* t = e.rgb + 3 * ((size_t)j * 256 + i);
            double c[3] = {t[0], t[1], t[2]}, l = lum(c), dw = veil_env_texel_solid_angle(256, 128, j);
            for (int k = 0; k < 3; ++k) mine[k] += (l > e.clip ? c[k] * e.clip / l : c[k]) * dw;
        }
    int parts = 1;
    for (int k = 0; k < 3; ++k)
        parts &= fabs(bright[k] + rest[k] - all[k]) <= 1e-9 * all[k] && fabs(rest[k] - mine[k]) <= 1e-9 * mine[k];
    CHECK(parts, "bright %.9g + rest %.9g is not the map %.9g, or the rest is not the clipped map %.9g", bright[1],
          rest[1], all[1], mine[1]);
    CHECK(bright[1] > 0.5 * all[1], "the sun is the bright part: %.4g of %.4g", bright[1], all[1]);
    int n = veil_env_bright_cut(&e, 8, L);
    const double ns = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    double cosd = n == 1 ? -(L[0].direction[0] * s[0] + L[0].direction[1] * s[1] + L[0].direction[2] * s[2]) / ns : 0.0;
    CHECK(n == 1 && cosd > cos(0.2 * PI / 180.0) && fabs(L[0].color[1] - bright[1]) <= 1e-5 * bright[1],
          "a 3-degree sun: %d bright lights (1), along the sun within %.3g degrees (0.2), irradiance %.6g of %.6g", n,
          acos(fmin(1.0, cosd)) * 180.0 / PI, n ? L[0].color[1] : 0.0, bright[1]);
    const veil_env_cut* cut = veil_env_cut_for(&e, 8);
    CHECK(cut && cut->bright_count == 1 && cut->count == 8, "the kept cut: %d bright lights (1), %d whole (8)",
          cut ? cut->bright_count : -1, cut ? cut->count : -1);
    /* the table: the rest's luminance integral, its CDF rising to 1; in blocks of 4 (a table of 1/16 the
     * texels) the same total, up to rounding */
    veil_error err = {0};
    for (int f = 1; f <= 4; f *= 4) {
        veil_env_table t;
        CHECK(veil_env_rest_table(&e, (size_t)256 * 128 / (size_t)(f * f), &t, &err) == VEIL_OK, "%s", err.msg);
        int rising = t.n > 0 && t.entries[8 * (size_t)(t.n - 1) + 1] == 1.0f, chroma = 1;
        for (int k = 1; k < t.n; ++k) rising &= t.entries[8 * (size_t)k + 1] >= t.entries[8 * (size_t)k - 7];
        for (int k = 0; k < t.n; ++k) {
            const float* q = t.entries + 8 * (size_t)k;
            double c[3] = {q[4], q[5], q[6]};
            chroma &= fabs(lum(c) - 1.0) <= 1e-6 && q[0] >= 0.0f && q[0] < (float)(t.w * t.h);
        }
        CHECK(t.block == f && t.w == 256 / f && t.h == 128 / f && t.n == t.w * t.h && rising && chroma &&
                  fabs(t.total - lum(rest)) <= 1e-9 * lum(rest) && t.bound >= 1.0,
              "table in blocks of %d: %dx%d (block %d), %d entries, CDF rising to 1: %d, rgb / lum of luminance 1: "
              "%d, total %.9g of %.9g", f, t.w, t.h, t.block, t.n, rising, chroma, t.total, lum(rest));
        veil_env_table_free(&t);
    }
    veil_env_free(&e);
    /* a constant sky: no bright part */
    memset(&e, 0, sizeof e);
    e.present = 1, e.width = e.height = 1;
    e.rgb = malloc(3 * sizeof *e.rgb);
    e.rgb[0] = 0.5f, e.rgb[1] = 0.6f, e.rgb[2] = 0.9f;
    veil_env_make_cuts(&e, 16, rungs, 1);
    veil_env_part_integral(&e, 0, rest);
    veil_env_integral(&e, total);
    CHECK(veil_env_bright_cut(&e, 8, L) == 0 && fabs(rest[2] - total[2]) <= 1e-12 * total[2],
          "a constant sky: %d bright lights, rest %.9g of %.9g", veil_env_bright_cut(&e, 8, L), rest[2], total[2]);
    veil_env_free(&e);
    /* two suns a right angle apart: two lights, one along each */
    const double s2[3] = {-0.64, 0.6, 0.48};
    e = sun_map(256, 128, s, 1.5, 2000.0f, 0.3f);
    veil_environment e2 = sun_map(256, 128, s2, 1.5, 2000.0f, 0.3f);
    for (size_t k = 0; k < (size_t)256 * 128 * 3; ++k) e.rgb[k] = fmaxf(e.rgb[k], e2.rgb[k]);
    veil_env_free(&e2);
    veil_env_make_cuts(&e, 16, rungs, 1);
    n = veil_env_bright_cut(&e, 8, L);
    int along = 0;
    for (int l = 0; l < n; ++l)
        for (int q = 0; q < 2; ++q) {
            const double* d = q ? s2 : s;
            along += -(L[l].direction[0] * d[0] + L[l].direction[1] * d[1] + L[l].direction[2] * d[2]) / ns >
                     cos(0.2 * PI / 180.0);
        }
    CHECK(n == 2 && along == 2, "two suns: %d bright lights (2), %d along a sun (2)", n, along);
    veil_env_free(&e);
}

/* JSON with single quotes (turned into double) parsed with base folder g_dir. */
static veil_result parse(const char* text, veil_scene* s, veil_error* e)
{
    static char buf[8192];
    size_t n = strlen(text);
    for (size_t i = 0; i <= n; ++i) buf[i] = text[i] == '\'' ? '"' : text[i];
    memset(e, 0, sizeof *e);
    return veil_scene_parse_in("env.json", buf, n, g_dir, s, e);
}

#define HEAD "{'camera':{'position':[0,0,5],'look_at':[0,0,0]},'medium':{'sigma_s':[1,1,1],'sources':[]},'lights':["
#define POINT "{'type':'point','position':[0,0,0],'intensity':[1,1,1]}"

static void expect_bad(const char* text, const char* want)
{
    veil_scene s;
    veil_error e;
    veil_result r = parse(text, &s, &e);
    CHECK(r != VEIL_OK && strstr(e.msg, want) != NULL, "expected '%s', got %s: %s", want, veil_result_name(r), e.msg);
    if (r == VEIL_OK) veil_scene_free(&s);
}

static void write_map(const char* name, int w, int h, float value, float bad)
{
    char path[256];
    path_in(path, sizeof path, name);
    float* p[3];
    for (int c = 0; c < 3; ++c) {
        p[c] = malloc((size_t)w * h * sizeof(float));
        for (int i = 0; i < w * h; ++i) p[c][i] = value;
    }
    if (w > 2 && h > 1) p[1][w + 2] = bad; /* texel (2, 1), G (a map too small to have it has none) */
    const char* names[3] = {"R", "G", "B"};
    veil_error e = {0};
    CHECK(veil_write_exr_planes(path, w, h, 3, names, (const float* const*)p, &e) == VEIL_OK, "%s", e.msg);
    for (int c = 0; c < 3; ++c) free(p[c]);
}

static void test_scene(void)
{
    veil_scene s;
    veil_error e;
    veil_result r = parse(HEAD POINT ",{'type':'environment','color':[0.5,0.6,0.7],'intensity':2,'rotation_deg':45}]}",
                          &s, &e);
    CHECK(r == VEIL_OK, "constant sky: %s", e.msg);
    if (r == VEIL_OK) {
        CHECK(s.light_count == 1 && s.environment.present && s.environment.width == 1 &&
              fabsf(s.environment.rgb[2] - 1.4f) < 1e-6f && s.environment.rotation_deg == 45.0f &&
              s.environment.lights == 0 && s.environment.cut_sets == 3 && s.environment.room == 15 &&
              s.environment.light_index == 1 && veil_scene_light_total(&s) == 1 + 15,
              "constant sky read wrong");
        /* no "lights": a cut for each rung's count, at most the room (15) */
        const veil_env_cut* c8 = veil_env_cut_for(&s.environment, VEIL_ENV_LIGHTS_DEFAULT);
        const veil_env_cut* c4 = veil_env_cut_for(&s.environment, VEIL_ENV_LIGHTS_DRAFT);
        const veil_env_cut* c16 = veil_env_cut_for(&s.environment, VEIL_ENV_LIGHTS_HIGH);
        CHECK(c8 && c8->k == 8 && c8->count == 8 && c4 && c4->count == 4 && c16 && c16->k == 15 && c16->count == 15,
              "the rungs' cuts: %d, %d, %d lights", c8 ? c8->count : -1, c4 ? c4->count : -1, c16 ? c16->count : -1);
        veil_scene_free(&s);
    }
    write_map("sky.exr", 16, 8, 0.25f, 0.25f);
    r = parse(HEAD "{'type':'environment','file':'sky.exr','color':[1,2,4],'lights':3,'up':'z'}]}", &s, &e);
    CHECK(r == VEIL_OK, "map: %s", e.msg);
    if (r == VEIL_OK) {
        CHECK(s.light_count == 0 && s.environment.width == 16 && s.environment.height == 8 &&
              s.environment.rgb[3 * 17 + 2] == 1.0f && s.environment.cut_sets == 1 &&
              veil_env_cut_for(&s.environment, VEIL_ENV_LIGHTS_HIGH)->count == 3 && s.environment.up_z == 1 &&
              strstr(s.environment.file, "sky.exr") != NULL, "map read wrong");
        veil_scene_free(&s);
    }
    /* 15 lights leave the environment one */
    char many[4096] = HEAD;
    for (int l = 0; l < 15; ++l) strcat(many, POINT ",");
    strcat(many, "{'type':'environment','color':[1,1,1]}]}");
    r = parse(many, &s, &e);
    CHECK(r == VEIL_OK && s.environment.room == 1 && s.environment.cut_sets == 1 &&
          veil_env_cut_for(&s.environment, VEIL_ENV_LIGHTS_HIGH)->count == 1, "15 lights: %s", e.msg);
    if (r == VEIL_OK) veil_scene_free(&s);
    write_map("nan.exr", 16, 8, 0.25f, NAN);
    write_map("small.exr", 1, 1, 0.25f, 0.25f);
    expect_bad(HEAD "{'type':'environment'}]}", "lights[0]: missing required field: \"color\"");
    expect_bad(HEAD "{'type':'environment','color':[1,1,1]},{'type':'environment','color':[1,1,1]}]}",
               "lights[1]: a second environment light (lights[0] is one)");
    expect_bad(HEAD "{'type':'environment','color':[1,1,1],'lights':0}]}", "lights[0].lights: expected an integer in [1, 16]");
    expect_bad(HEAD "{'type':'environment','color':[1,1,1],'lights':17}]}", "lights[0].lights: expected an integer in [1, 16]");
    expect_bad(HEAD "{'type':'environment','color':[1,1,1],'intensity':-1}]}", "lights[0].intensity");
    expect_bad(HEAD "{'type':'environment','color':[1,1,1],'rotation_deg':'x'}]}", "lights[0].rotation_deg");
    expect_bad(HEAD "{'type':'environment','color':[1,1,1],'sun':1}]}", "lights[0].sun: unknown key");
    expect_bad(HEAD "{'type':'environment','color':[1,1,1],'up':'x'}]}", "lights[0].up: expected one of");
    expect_bad(HEAD "{'type':'environment','color':[1,1,1],'remainder':'photons'}]}",
               "lights[0].remainder: expected one of");
    r = parse(HEAD "{'type':'environment','color':[1,1,1],'remainder':'lights'}]}", &s, &e);
    CHECK(r == VEIL_OK && s.environment.remainder_lights == 1, "remainder lights: %s", e.msg);
    if (r == VEIL_OK) veil_scene_free(&s);
    r = parse(HEAD "{'type':'environment','color':[1,1,1]}]}", &s, &e);
    CHECK(r == VEIL_OK && s.environment.remainder_lights == 0, "remainder cache by default: %s", e.msg);
    if (r == VEIL_OK) veil_scene_free(&s);
    expect_bad(HEAD "{'type':'environment','file':'missing.exr'}]}", "lights[0].file: cannot open");
    expect_bad(HEAD "{'type':'environment','file':'nan.exr'}]}", "nan.exr': texel (2, 1) has G NaN");
    expect_bad(HEAD "{'type':'environment','file':'small.exr'}]}", "an environment map of 1x1 texels");
    expect_bad(HEAD "{'type':'environment','color':[1e19,1,1]}]}", "integrates to 1.25664e+20 W/m^2");
    expect_bad(HEAD "{'type':'environment','color':[1e19,1,1],'intensity':100}]}", "color x intensity is");
    char full[4096] = HEAD;
    for (int l = 0; l < 16; ++l) strcat(full, POINT ",");
    strcat(full, "{'type':'environment','color':[1,1,1]}]}");
    expect_bad(full, "lights: too many elements (17, at most 16)"); /* the environment is one of the 16 */
    /* a file that is not an EXR: the reader's message, under the field */
    char path[256];
    path_in(path, sizeof path, "text.exr");
    spit(path, "not an exr", 10);
    expect_bad(HEAD "{'type':'environment','file':'text.exr'}]}", "lights[0].file: cannot read the environment map");
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/veil_env_XXXXXX");
    if (!mkdtemp(g_dir)) return 1;
    test_convention();
    test_solid_angles();
    test_median_cut();
    test_sampling();
    test_split();
    test_scene();
    const char* names[] = {"sky.exr", "nan.exr", "small.exr", "text.exr"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i) {
        char p[256];
        path_in(p, sizeof p, names[i]);
        remove(p);
    }
    rmdir(g_dir);
    return check_finish();
}
