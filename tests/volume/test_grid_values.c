/* Grid values (issue 22, items 5 and 6; scene/limits.h), on values.vdb of
 * make_test_vdbs: 8^3-voxel grids, voxel 0.1 m, each with one value the
 * float pipeline cannot carry, beside good ones.
 *
 *   test_grid_values VDB_DATA open     a voxel or active tile that is not a number or infinite
 *                                      is refused when the grid is opened (OpenVDB and
 *                                      NanoVDB), naming the file, the grid, how many voxels
 *                                      and where the first is; the good grids' value ranges
 *   test_grid_values VDB_DATA volume   what a source makes of its values: a density of 3e38,
 *                                      an emission of 3e38 and a temperature of 3e38 K (or
 *                                      of 1.5e5 K through its scale) refused with the count,
 *                                      the bounds themselves accepted; density and emission
 *                                      below 0 read as 0 in the copied, the resampled and the
 *                                      sparse volume and in the emission (--stats says how
 *                                      many), a temperature below 0 kept (its offset may
 *                                      make it hot)
 *   test_grid_values VDB_DATA render   16x16 renders at every bound of scene/limits.h at once
 *                                      (sigma 1e10, density 1e10, lights 1e20, emission 1e21,
 *                                      temperature 1e5 K, fog falloff 1e20, background 1e20;
 *                                      dense, sparse, fog, each volumetric method): every
 *                                      pixel of every AOV finite and >= 0; negative heat
 *                                      gives no negative radiance
 *
 * Before the fix: the NaN and infinite grids opened (and rendered NaN
 * pixels, or ran for minutes in the emission light's shells), the 3e38
 * grids were read, negative density and heat gave negative radiance, and
 * a light of exactly 1e20 W/sr was refused (the bound was compared with
 * the float it rounds to). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "frame/renderer.h"
#include "io/scene.h"
#include "io/vdb.h"
#include "volume/scene_volume.h"
#include "volume/sparse.h"

static const char* g_data;

static const char* values_file(const char* name)
{
    static char buf[2][4096];
    static int slot;
    char* p = buf[slot++ & 1];
    snprintf(p, sizeof buf[0], "%s/%s", g_data, name);
    return p;
}

/* ---- open ----------------------------------------------------------------- */

static void refused_at_open(const char* file, const char* grid, const char* what)
{
    veil_vdb* v = NULL;
    veil_error err = {0};
    const char* path = values_file(file);
    veil_result r = veil_vdb_open(path, grid, 0, &v, NULL, 0, &err);
    char want[4200];
    snprintf(want, sizeof want, "%s: grid '%s': %s", path, grid, what);
    CHECK(r == VEIL_ERR_INVALID && v == NULL, "%s grid %s: %s (%s)", file, grid, veil_result_name(r), err.msg);
    CHECK(strstr(err.msg, want) == err.msg, "%s grid %s: message \"%s\" should start with \"%s\"", file, grid, err.msg,
          want);
    CHECK(strstr(err.msg, ": nan)") == NULL && strstr(err.msg, ": inf)") == NULL && strstr(err.msg, ": -inf)") == NULL,
          "no C spelling of a value: %s", err.msg);
    veil_vdb_close(v);
}

static void test_open(void)
{
    refused_at_open("values.vdb", "density_nan", "1 voxel is not a number or infinite (at index [3, 3, 3]: not a number)");
    refused_at_open("values.vdb", "density_neg_inf", "1 voxel is not a number or infinite (at index [3, 3, 3]: -infinity)");
    refused_at_open("values.vdb", "heat_inf", "1 voxel is not a number or infinite (at index [3, 3, 3]: infinity)");
    refused_at_open("values.vdb", "temperature_inf", "1 voxel is not a number or infinite");
    /* an active tile counts its 8^3 voxels */
    refused_at_open("values.vdb", "density_tile_nan",
                    "512 voxels are not a number or infinite (the first at index [8, 0, 0]: not a number)");
    /* NanoVDB goes through the same check */
    refused_at_open("values_nan.nvdb", "density_nan", "1 voxel is not a number or infinite (at index [3, 3, 3]");

    /* the grids that open: their ranges (0 included: inactive voxels read 0) */
    static const struct {
        const char* grid;
        double min, max;
        uint64_t negative;
    } good[] = {{"density", 0.0, 1.0, 0},     {"density_negative", -0.5, 1.0, 64}, {"density_big", 0.0, 3e38, 0},
                {"heat_negative", -1.0, 0.0, 512}, {"temperature", 0.0, 1500.0, 0}};
    for (size_t i = 0; i < sizeof good / sizeof good[0]; ++i) {
        veil_vdb* v = NULL;
        veil_error err = {0};
        CHECK(veil_vdb_open(values_file("values.vdb"), good[i].grid, 0, &v, NULL, 0, &err) == VEIL_OK, "%s: %s",
              good[i].grid, err.msg);
        if (!v) continue;
        veil_vdb_values x;
        veil_vdb_value_range(v, &x);
        CHECK(x.min == good[i].min && x.max == (double)(float)good[i].max && x.negative == good[i].negative,
              "%s: range [%g, %g], %llu negative; expected [%g, %g], %llu", good[i].grid, x.min, x.max,
              (unsigned long long)x.negative, good[i].min, good[i].max, (unsigned long long)good[i].negative);
        veil_vdb_close(v);
    }
    veil_vdb* v = NULL;
    veil_error err = {0};
    if (veil_vdb_open(values_file("values.vdb"), "density_negative", 0, &v, NULL, 0, &err) == VEIL_OK) {
        CHECK(veil_vdb_count_outside(v, 0.0, 1.0) == 64 && veil_vdb_count_outside(v, -1.0, 0.5) == 448,
              "counts outside [0, 1]: %llu, outside [-1, 0.5]: %llu", (unsigned long long)veil_vdb_count_outside(v, 0.0, 1.0),
              (unsigned long long)veil_vdb_count_outside(v, -1.0, 0.5));
        veil_vdb_close(v);
    }
}

/* ---- volume --------------------------------------------------------------- */

/* A scene of one vdb source of values.vdb: `source` are the source's other
 * keys, `medium` the medium's (after sigma_s). */
static veil_scene scene_of(const char* source, const char* medium)
{
    char json[4096];
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0.35, 0.35, 3], \"look_at\": [0.35, 0.35, 0.35], \"width\": 16, \"height\": 16},"
             " \"medium\": {\"sigma_a\": [0.5, 0.5, 0.5], \"sigma_s\": [1, 1, 1]%s,"
             "  \"sources\": [{\"type\": \"vdb\", \"file\": \"%s\"%s}]},"
             " \"lights\": [{\"type\": \"point\", \"position\": [0.35, 2, 0.35], \"intensity\": [1, 1, 1]}]}",
             medium, values_file("values.vdb"), source);
    veil_scene s;
    veil_error err = {0};
    if (veil_scene_parse("values.json", json, strlen(json), &s, &err) != VEIL_OK) {
        fprintf(stderr, "scene: %s\n", err.msg);
        exit(1);
    }
    return s;
}

static void refused_by_volume(const char* source, const char* field, const char* grid, const char* what)
{
    veil_scene s = scene_of(source, "");
    veil_scene_volume v;
    veil_error err = {0};
    veil_result r = veil_scene_volume_open(&s, &v, &err);
    char want[4200];
    snprintf(want, sizeof want, "%s: %s: grid '%s': %s", field, values_file("values.vdb"), grid, what);
    CHECK(r == VEIL_ERR_INVALID, "%s: %s (%s)", source, veil_result_name(r), err.msg);
    CHECK(strstr(err.msg, want) == err.msg, "message \"%s\" should start with \"%s\"", err.msg, want);
    if (r == VEIL_OK) veil_scene_volume_close(&v);
    veil_scene_free(&s);
}

static int opened(veil_scene* s, veil_scene_volume* v)
{
    veil_error err = {0};
    veil_result r = veil_scene_volume_open(s, v, &err);
    CHECK(r == VEIL_OK, "%s", err.msg);
    return r == VEIL_OK;
}

/* min and sum of n floats (every k-th from `first`) */
static void min_sum(const float* x, size_t n, size_t k, size_t first, double* lo, double* sum)
{
    *lo = INFINITY, *sum = 0.0;
    for (size_t i = first; i < n; i += k) *lo = fmin(*lo, x[i]), *sum += x[i];
}

static void test_volume(void)
{
    refused_by_volume(", \"grid\": \"density_big\"", "medium.sources[0]", "density_big",
                      "1 voxel is too large: value x density_scale up to 3e+38, over the bound of 1e+10 (scene/limits.h)");
    /* the bounds hold for the scaled values: 1500 x 1e8 */
    refused_by_volume(", \"grid\": \"temperature\", \"density_scale\": 1e8", "medium.sources[0]", "temperature",
                      "512 voxels are too large: value x density_scale up to 1.5e+11, over the bound of 1e+10");
    refused_by_volume(", \"emission\": {\"grid\": \"heat_big\"}", "medium.sources[0].emission.grid", "heat_big",
                      "1 voxel emits too much: value x emission.scale x color up to 3e+38 W m^-3 sr^-1, over the bound "
                      "of 1e+21 W m^-3 sr^-1 (scene/limits.h)");
    refused_by_volume(", \"emission\": {\"grid\": \"temperature\", \"scale\": 1e19, \"color\": [0.5, 1, 0]}",
                      "medium.sources[0].emission.grid", "temperature",
                      "512 voxels emit too much: value x emission.scale x color up to 1.5e+22 W m^-3 sr^-1");
    refused_by_volume(", \"temperature\": {\"grid\": \"temperature_big\"}", "medium.sources[0].temperature.grid",
                      "temperature_big",
                      "1 voxel is too hot: temperature.scale x value + offset up to 3e+38 K, over the bound of 1e+05 K "
                      "(scene/limits.h)");
    refused_by_volume(", \"temperature\": {\"grid\": \"temperature\", \"scale\": 100}",
                      "medium.sources[0].temperature.grid", "temperature",
                      "512 voxels are too hot: temperature.scale x value + offset up to 1.5e+05 K");
    /* a negative scale: the coldest value is the hottest */
    refused_by_volume(", \"temperature\": {\"grid\": \"heat_negative\", \"scale\": -1e5, \"offset\": 1}",
                      "medium.sources[0].temperature.grid", "heat_negative", "512 voxels are too hot");

    /* the bounds themselves are accepted: density 1 x 1e10, emission 1 x 1e21, 1500 K x 66.6 = 99 900 K */
    veil_scene s = scene_of(", \"density_scale\": 1e10, \"emission\": {\"grid\": \"heat\", \"scale\": 1e21},"
                            " \"temperature\": {\"grid\": \"temperature\", \"scale\": 66.6}", "");
    veil_scene_volume v;
    if (opened(&s, &v)) veil_scene_volume_close(&v);
    veil_scene_free(&s);

    /* negative density: read as 0, copied (native), resampled (max_resolution) and sparse */
    for (int mode = 0; mode < 3; ++mode) {
        s = scene_of(", \"grid\": \"density_negative\"", mode == 1   ? ", \"max_resolution\": 5"
                                                          : mode == 2 ? ", \"representation\": \"sparse\""
                                                                      : "");
        if (!opened(&s, &v)) continue;
        CHECK(strstr(v.resolution, "grid 'density_negative': 64 voxels below 0 read as 0") != NULL,
              "mode %d: --stats says how many voxels read 0: %s", mode, v.resolution);
        veil_error err = {0};
        double lo, sum;
        if (mode < 2) {
            float* d = NULL;
            CHECK(veil_scene_volume_density(&v, &d, &err) == VEIL_OK, "%s", err.msg);
            /* the same grid with every voxel 1 (density): resampling weighs values with weights >= 0, so
             * the clamped grid (0 where it was -0.5, else 1) resamples to between 0 and it, voxel by voxel */
            veil_scene s1 = scene_of("", mode == 1 ? ", \"max_resolution\": 5" : "");
            veil_scene_volume v1;
            float* d1 = NULL;
            if (opened(&s1, &v1)) {
                CHECK(veil_scene_volume_density(&v1, &d1, &err) == VEIL_OK, "%s", err.msg);
                CHECK(memcmp(&v1.grid, &v.grid, sizeof v.grid) == 0, "the two grids' volumes differ");
                veil_scene_volume_close(&v1);
            }
            veil_scene_free(&s1);
            if (d && d1) {
                min_sum(d, veil_grid_voxels(&v.grid), 1, 0, &lo, &sum);
                size_t above = 0;
                for (size_t i = 0; i < veil_grid_voxels(&v.grid); ++i) above += d[i] > d1[i];
                CHECK(lo >= 0.0, "mode %d: a voxel of %g (negative density read as such)", mode, lo);
                CHECK(above == 0, "mode %d: %zu voxels above the all-ones grid's", mode, above);
                /* copied: the 448 voxels of 1, exactly */
                CHECK(mode == 1 || sum == 448.0, "copied: the voxels sum to %g, expected 448 (the 64 of -0.5 read 0)",
                      sum);
                printf("negative density, %s: min %g, sum %g\n", mode ? "resampled" : "copied", lo, sum);
            }
            free(d);
            free(d1);
        } else {
            veil_sparse sp;
            CHECK(veil_sparse_build(&v, 2048, &sp, &err) == VEIL_OK, "%s", err.msg);
            int t[3];
            veil_sparse_atlas_texels(&sp, t);
            min_sum(sp.texels, (size_t)t[0] * (size_t)t[1] * (size_t)t[2], 1, 0, &lo, &sum);
            CHECK(lo >= 0.0 && sp.voxels == 448, "sparse: min texel %g, %zu voxels taken (expected >= 0 and 448)", lo,
                  sp.voxels);
            veil_sparse_free(&sp);
        }
        veil_scene_volume_close(&v);
        veil_scene_free(&s);
    }

    /* negative heat: emits nothing (it emitted -1 x scale: negative radiance); a temperature grid keeps
     * its negative values: -1 x -1000 K = 1000 K glows where there is density (dense and sparse) */
    static const char* const heat[] = {", \"emission\": {\"grid\": \"heat_negative\"}",
                                       ", \"temperature\": {\"grid\": \"heat_negative\", \"scale\": -1000}"};
    for (int k = 0; k < 2; ++k)
        for (int sparse = 0; sparse < 2; ++sparse) {
            s = scene_of(heat[k], sparse ? ", \"representation\": \"sparse\"" : "");
            if (!opened(&s, &v)) continue;
            veil_error err = {0};
            double lo, sum;
            if (!sparse) {
                float* rgba = NULL;
                CHECK(veil_scene_volume_emission(&v, &rgba, &err) == VEIL_OK && rgba, "%s", err.msg);
                if (rgba) min_sum(rgba, 4 * veil_grid_voxels(&v.grid), 4, 0, &lo, &sum);
                free(rgba);
            } else {
                veil_sparse sp;
                CHECK(veil_sparse_build(&v, 2048, &sp, &err) == VEIL_OK, "%s", err.msg);
                int t[3];
                veil_sparse_atlas_texels(&sp, t);
                lo = 0.0, sum = 0.0;
                if (sp.emission_texels) min_sum(sp.emission_texels, 4 * (size_t)t[0] * t[1] * t[2], 4, 0, &lo, &sum);
                veil_sparse_free(&sp);
            }
            if (k == 0)
                CHECK(lo == 0.0 && sum == 0.0, "%s negative heat: emission from %g, sum %g; expected none",
                      sparse ? "sparse" : "dense", lo, sum);
            else
                CHECK(lo >= 0.0 && sum > 0.0, "%s temperature of -1 x -1000: emission from %g, sum %g; expected a glow",
                      sparse ? "sparse" : "dense", lo, sum);
            veil_scene_volume_close(&v);
            veil_scene_free(&s);
        }
}

/* ---- render --------------------------------------------------------------- */

static void all_finite(const char* what, const veil_image_set* im)
{
    const float* planes[] = {im->rgba, im->aov_t, im->aov_s, im->aov_v, im->aov_m, im->aov_q};
    static const char* const names[] = {"rgba", "T", "single", "volume", "screen", "q"};
    size_t n = (size_t)im->width * (size_t)im->height * 4, bad = 0, negative = 0, seen = 0;
    for (int p = 0; p < 6; ++p) {
        if (!planes[p]) continue;
        ++seen;
        for (size_t i = 0; i < n; ++i) {
            bad += !isfinite(planes[p][i]);
            negative += planes[p][i] < 0.0f;
        }
        CHECK(bad == 0 && negative == 0, "%s: %s has %zu values not finite and %zu below 0", what, names[p], bad, negative);
    }
    CHECK(seen >= 4, "%s: only %zu planes", what, seen);
}

static void test_render(void)
{
    const char* vdb = values_file("values.vdb");
    char json[6][4096];
    /* every bound at once, dense then sparse: the octaves and the emission's lights (1e21 x 1e-3 m^3 x 512
     * voxels = 5e20 W/sr, held at 1e20) */
    static const char extreme[] =
        "{\"camera\": {\"position\": [0.35, 0.35, 3], \"look_at\": [0.35, 0.35, 0.35], \"width\": 16, \"height\": 16},"
        " \"medium\": {\"sigma_a\": [1e10, 0, 1e10], \"sigma_s\": [1e10, 1e10, 0], \"phase\": {\"type\": \"hg\", \"g\": 0.99}%s,"
        "  \"sources\": [{\"type\": \"vdb\", \"file\": \"%s\", \"density_scale\": 1e10,"
        "   \"emission\": {\"grid\": \"heat\", \"scale\": 1e21}}]},"
        " \"lights\": [{\"type\": \"point\", \"position\": [0.35, 2, 0.35], \"intensity\": [1e20, 1e20, 1e20]},"
        "  {\"type\": \"directional\", \"direction\": [0, -1, 0], \"irradiance\": [1e20, 1e20, 1e20]}],"
        " \"background\": {\"color\": [1e20, 1e20, 1e20]}%s}";
    snprintf(json[0], sizeof json[0], extreme, "", vdb, "");
    snprintf(json[1], sizeof json[1], extreme, ", \"representation\": \"sparse\"", vdb, "");
    snprintf(json[2], sizeof json[2], extreme, "", vdb, ", \"multiple_scattering\": {\"volumetric_method\": \"diffusion\"}");
    /* a temperature of 99 900 K, k = 1e10 at density 1e10: k rho B = 2e29, held at max(1e21, sigma_a rho B) */
    snprintf(json[3], sizeof json[3],
             "{\"camera\": {\"position\": [0.35, 0.35, 3], \"look_at\": [0.35, 0.35, 0.35], \"width\": 16, \"height\": 16},"
             " \"medium\": {\"sigma_a\": [1, 1e10, 0], \"sigma_s\": [1e10, 1e10, 1e10], \"sources\": [{\"type\": \"vdb\","
             "  \"file\": \"%s\", \"density_scale\": 1e10, \"temperature\": {\"grid\": \"temperature\", \"scale\": 66.6,"
             "  \"intensity\": 1e10}}]},"
             " \"lights\": [{\"type\": \"point\", \"position\": [0.35, 2, 0.35], \"intensity\": [1e20, 1e20, 1e20]}]}",
             vdb);
    /* a fog of density 1e10 and falloff 1e20 around the grid, with the octaves' legs gate */
    snprintf(json[4], sizeof json[4],
             "{\"camera\": {\"position\": [0.35, 0.35, 3], \"look_at\": [0.35, 0.35, 0.35], \"width\": 16, \"height\": 16},"
             " \"medium\": {\"sigma_a\": [1e10, 1e10, 1e10], \"sigma_s\": [1e10, 1e10, 1e10], \"sources\": ["
             "  {\"type\": \"exponential\", \"density\": 1e10, \"falloff\": 1e20, \"direction\": [0, 1, 0], \"origin\": [0, 0.3, 0]},"
             "  {\"type\": \"vdb\", \"file\": \"%s\", \"density_scale\": 1e10}]},"
             " \"lights\": [{\"type\": \"point\", \"position\": [0.35, 2, 0.35], \"intensity\": [1e20, 1e20, 1e20]}],"
             " \"background\": {\"color\": [1e20, 1e20, 1e20]}, \"multiple_scattering\": {\"octave_gate\": \"legs\"}}",
             vdb);
    /* negative heat */
    snprintf(json[5], sizeof json[5],
             "{\"camera\": {\"position\": [0.35, 0.35, 3], \"look_at\": [0.35, 0.35, 0.35], \"width\": 16, \"height\": 16},"
             " \"medium\": {\"sigma_a\": [0.5, 0.5, 0.5], \"sigma_s\": [1, 1, 1], \"sources\": [{\"type\": \"vdb\","
             "  \"file\": \"%s\", \"emission\": {\"grid\": \"heat_negative\"}}]},"
             " \"lights\": [{\"type\": \"point\", \"position\": [0.35, 2, 0.35], \"intensity\": [1, 1, 1]}]}",
             vdb);
    static const char* const what[] = {"every bound, dense", "every bound, sparse", "every bound, diffusion",
                                       "99 900 K", "fog at its bounds", "negative heat"};
    veil_gl* gl = check_gpu_or_skip();
    veil_renderer* r = NULL;
    veil_error err = {0};
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    for (int i = 0; r && i < 6; ++i) {
        veil_scene s;
        veil_result pr = veil_scene_parse("bounds.json", json[i], strlen(json[i]), &s, &err);
        CHECK(pr == VEIL_OK, "%s: %s", what[i], err.msg);
        if (pr != VEIL_OK) continue;
        veil_image_set im = {0};
        CHECK(veil_render_scene_images(r, &s, &(veil_render_opts){.seed = 1}, &im, NULL, &err) == VEIL_OK, "%s: %s",
              what[i], err.msg);
        if (im.rgba) all_finite(what[i], &im);
        veil_image_set_free(&im);
        veil_scene_free(&s);
    }
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
}

int main(int argc, char** argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: test_grid_values VDB_DATA open|volume|render\n");
        return 2;
    }
    g_data = argv[1];
    if (strcmp(argv[2], "open") == 0) test_open();
    else if (strcmp(argv[2], "volume") == 0) test_volume();
    else if (strcmp(argv[2], "render") == 0) test_render();
    else return 2;
    return check_finish();
}
