/* Scene parser: good scenes (values, defaults, normalisation, particles) and
 * bad ones (result code, file name and exact JSON path in the message). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "io/scene.h"
#include "scene/camera.h"

/* JSON is written with single quotes here; parse() turns them into double. */
static veil_result parse(const char* name, const char* text, veil_scene* s, veil_error* e)
{
    static char buf[8192];
    size_t n = strlen(text);
    if (n >= sizeof buf) return VEIL_ERR_LIMIT;
    for (size_t i = 0; i <= n; ++i) buf[i] = text[i] == '\'' ? '"' : text[i];
    return veil_scene_parse(name, buf, n, s, e);
}

static int is_zeroed(const veil_scene* s)
{
    static const veil_scene zero;
    return memcmp(s, &zero, sizeof zero) == 0;
}

static int vec_close(const float* v, double x, double y, double z)
{
    return check_close(v[0], x, 1e-6, 1e-6) && check_close(v[1], y, 1e-6, 1e-6) &&
           check_close(v[2], z, 1e-6, 1e-6);
}

#define CAM "'camera':{'position':[0,0,5],'look_at':[0,0,0]}"
#define MED "'medium':{'sigma_s':[1,1,1],'sources':[]}"
#define LIGHT_OK "{'type':'point','position':[0,0,0],'intensity':[1,1,1]}"
#define SRC_OK "{'type':'rbf','particles':[]}"
#define LIGHTS(l) "{" CAM "," MED ",'lights':[" l "]}"
#define SPOT(f) LIGHTS("{'type':'spot','position':[0,0,0]," f "}")
#define SPOT_DI "'direction':[0,0,1],'intensity':[1,1,1],"
#define RND(f) "{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[{'type':'rbf_random'," f "}]}}"
#define RND_OK_COUNT "'count':3,'seed':1,"
#define RND_OK_BOUNDS "'bounds':[[0,0,0],[1,1,1]],"
#define SRC(f) "{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[" f "]}}"
#define VDB(f) SRC("{'type':'vdb','file':'/dev/null'," f "}") /* any readable file: the grid is not opened */
#define FOG(f) SRC("{'type':'exponential','direction':[0,1,0],'origin':[0,0,0]," f "}")

static void test_full(void)
{
    const char* text =
        "{'camera':{'position':[1,2,3],'look_at':[1,2,0],'up':[0,0.5,0],'fov_y_deg':30,"
        "'width':320,'height':200},"
        "'medium':{'sigma_a':[0.1,0.2,0.3],'sigma_s':[4,5,6],'phase':{'type':'hg','g':-0.5},"
        "'max_resolution':64,'sources':["
        "{'type':'rbf','particles':[{'center':[1,2,3],'amplitude':2,'sharpness':4},"
        "{'center':[-1,0,1],'amplitude':0,'sharpness':0.5}]},"
        "{'type':'rbf_random','count':5,'seed':9007199254740991,'bounds':[[-1,-2,-3],[1,2,3]],"
        "'radius':[0.1,0.2],'amplitude':[0.5,1.5]},"
        "{'type':'rbf','particles':[{'center':[7,8,9],'amplitude':3,'sharpness':1}]}]},"
        "'lights':[{'type':'point','position':[0,1,0],'intensity':[10,20,30]},"
        "{'type':'directional','direction':[0,-3,4],'irradiance':[1,2,3]}],"
        "'background':{'color':[0.25,0.5,1]}}";
    veil_scene s;
    veil_error e = {0};
    veil_result r = parse("dir/sub/full.json", text, &s, &e);
    CHECK(r == VEIL_OK, "full scene: %s", e.msg);
    if (r != VEIL_OK) return;
    CHECK(strcmp(s.path, "dir/sub/full.json") == 0, "path %s", s.path);
    CHECK(strcmp(s.base_dir, "dir/sub") == 0, "base_dir %s", s.base_dir);
    CHECK(vec_close(s.camera.position, 1, 2, 3), "position");
    CHECK(vec_close(s.camera.look_at, 1, 2, 0), "look_at");
    CHECK(vec_close(s.camera.up, 0, 1, 0), "up normalised on load: %g %g %g", s.camera.up[0], s.camera.up[1], s.camera.up[2]);
    CHECK(s.camera.fov_y_deg == 30.0f && s.camera.width == 320 && s.camera.height == 200, "camera");
    CHECK(vec_close(s.medium.sigma_a, 0.1, 0.2, 0.3), "sigma_a");
    CHECK(vec_close(s.medium.sigma_s, 4, 5, 6), "sigma_s");
    CHECK(s.medium.phase.type == VEIL_PHASE_HG && s.medium.phase.g == -0.5f, "phase");
    CHECK(s.medium.max_resolution == 64, "max_resolution %d", s.medium.max_resolution);
    CHECK(s.medium.source_count == 3, "source_count %zu", s.medium.source_count);
    if (s.medium.source_count == 3) {
        const veil_source* src = s.medium.sources;
        CHECK(src[0].type == VEIL_SOURCE_RBF && src[0].particle_count == 2, "source 0");
        CHECK(vec_close(src[0].particles[1].center, -1, 0, 1) && src[0].particles[1].sharpness == 0.5f,
              "particle 1");
        const veil_rbf_random_desc* d = &src[1].random;
        CHECK(src[1].type == VEIL_SOURCE_RBF_RANDOM && d->count == 5, "source 1");
        CHECK(d->seed == 9007199254740991ull, "seed %llu", (unsigned long long)d->seed);
        CHECK(vec_close(d->bounds[0], -1, -2, -3) && vec_close(d->bounds[1], 1, 2, 3), "bounds");
        CHECK(d->radius[0] == 0.1f && d->radius[1] == 0.2f, "radius");
        CHECK(d->amplitude[0] == 0.5f && d->amplitude[1] == 1.5f, "amplitude");
    }
    CHECK(s.light_count == 2, "light_count %zu", s.light_count);
    if (s.light_count == 2) {
        CHECK(s.lights[0].type == VEIL_LIGHT_POINT && vec_close(s.lights[0].position, 0, 1, 0), "point");
        CHECK(vec_close(s.lights[0].color, 10, 20, 30), "intensity");
        CHECK(s.lights[1].type == VEIL_LIGHT_DIRECTIONAL, "directional");
        CHECK(vec_close(s.lights[1].direction, 0, -0.6, 0.8), "direction not normalised: %g %g %g",
              s.lights[1].direction[0], s.lights[1].direction[1], s.lights[1].direction[2]);
        CHECK(vec_close(s.lights[1].color, 1, 2, 3), "irradiance");
    }
    CHECK(vec_close(s.background, 0.25, 0.5, 1), "background");

    veil_particle* p = NULL;
    size_t n = 0;
    r = veil_scene_particles(&s, &p, &n, &e);
    CHECK(r == VEIL_OK && n == 8, "particles: %zu, %s", n, e.msg);
    if (r == VEIL_OK && n == 8) {
        CHECK(vec_close(p[0].center, 1, 2, 3) && p[0].amplitude == 2 && p[0].sharpness == 4, "p[0]");
        CHECK(vec_close(p[7].center, 7, 8, 9) && p[7].amplitude == 3, "p[7] (third source)");
        for (int i = 2; i < 7; ++i) {
            int inside = 1;
            for (int k = 0; k < 3; ++k)
                inside &= p[i].center[k] >= -(k + 1) - 1e-6f && p[i].center[k] <= k + 1 + 1e-6f;
            CHECK(inside && p[i].amplitude >= 0.5f && p[i].amplitude <= 1.5f, "generated p[%d]", i);
            CHECK(p[i].sharpness >= 1 / 0.2f - 1e-3f && p[i].sharpness <= 1 / 0.1f + 1e-3f,
                  "generated p[%d] sharpness %g", i, p[i].sharpness);
        }
    }
    free(p);
    veil_scene_free(&s);
    CHECK(is_zeroed(&s), "veil_scene_free zeroes the scene");
    veil_scene_free(&s); /* a zeroed scene */
    veil_scene_free(NULL);
}

static void test_defaults(void)
{
    veil_scene s;
    veil_error e = {0};
    veil_result r = parse("min.json", "{" CAM "," MED "}", &s, &e);
    CHECK(r == VEIL_OK, "minimal scene: %s", e.msg);
    if (r != VEIL_OK) return;
    CHECK(strcmp(s.base_dir, ".") == 0, "base_dir %s", s.base_dir);
    CHECK(vec_close(s.camera.up, 0, 1, 0), "default up");
    CHECK(s.camera.fov_y_deg == VEIL_SCENE_DEFAULT_FOV_Y, "default fov");
    CHECK(s.camera.width == 640 && s.camera.height == 480, "default size");
    CHECK(vec_close(s.medium.sigma_a, 0, 0, 0), "default sigma_a");
    CHECK(s.medium.phase.type == VEIL_PHASE_ISOTROPIC && s.medium.phase.g == 0, "default phase");
    CHECK(s.medium.max_resolution == 128, "default max_resolution");
    CHECK(s.medium.source_count == 0 && s.light_count == 0 && s.lights == NULL, "empty lists");
    CHECK(vec_close(s.background, 0, 0, 0), "default background");
    veil_particle* p = NULL;
    size_t n = 99;
    r = veil_scene_particles(&s, &p, &n, &e);
    CHECK(r == VEIL_OK && n == 0 && p != NULL, "no particles: %s", e.msg);
    free(p);
    veil_scene_free(&s);

    r = parse("/abs.json", "{" CAM "," MED ",'lights':[],'background':{},"
              "'medium_unused':1}", &s, &e);
    CHECK(r == VEIL_ERR_INVALID && strstr(e.msg, "/abs.json: medium_unused: unknown key"), "%s", e.msg);
    r = parse("/abs.json", "{" CAM "," MED ",'lights':[],'background':{}}", &s, &e);
    CHECK(r == VEIL_OK && strcmp(s.base_dir, "/") == 0, "root base_dir: %s", e.msg);
    veil_scene_free(&s);
    r = parse("iso.json", "{" CAM ",'medium':{'sigma_s':[1,1,1],'phase':{'type':'isotropic'},"
              "'sources':[" SRC_OK "]}}", &s, &e);
    CHECK(r == VEIL_OK && s.medium.source_count == 1 && s.medium.sources[0].particle_count == 0,
          "explicit isotropic, empty particles: %s", e.msg);
    veil_scene_free(&s);
}

/* "multiple_scattering": absent -> veil_multiple_defaults(); given fields
 * replace them; a filter's weights are normalised to sum 1. */
static void test_multiple(void)
{
    veil_scene s;
    veil_error e = {0};
    veil_multiple d;
    veil_multiple_defaults(&d);
    veil_result r = parse("ms.json", "{" CAM "," MED "}", &s, &e);
    CHECK(r == VEIL_OK && memcmp(&s.multiple, &d, sizeof d) == 0, "absent: the defaults (%s)", e.msg);
    CHECK(d.screen_space && d.volumetric && d.filter == VEIL_SPREAD_4X4 && d.weights[0] == 0.13f &&
          d.weights[1] == 0.37f && d.c == 0.86f && d.mask_epsilon == 2.0f && d.k_ssc == 0.7f,
          "the paper's constants are the defaults");
    veil_scene_free(&s);
    r = parse("ms.json", "{" CAM "," MED ",'multiple_scattering':{'screen_space':false,'volumetric':true,"
              "'filter':'6x6','weights':[1,2,3,3,2,1],"
              "'interpolation':'cubic-bicubic','c':1.5,'levels':5,'octaves':4,'octave_gate':'legs',"
              "'volumetric_method':'cache','cache_photons':4096,'cache_cells':12,'cache_seed':9,'cache_gather_rays':36,"
              "'separation':true,'separation_density':2,'separation_density_width':2}}", &s, &e);
    CHECK(r == VEIL_OK, "a full object: %s", e.msg);
    if (r == VEIL_OK) {
        const veil_multiple* m = &s.multiple;
        CHECK(!m->screen_space && m->volumetric &&
              m->filter == VEIL_SPREAD_6X6 && m->interp == VEIL_INTERP_CUBIC_BICUBIC && m->c == 1.5f &&
              m->levels == 5 && m->octaves == 4 && m->octave_gate == VEIL_GATE_LEGS && m->separation &&
              m->volumetric_method == VEIL_VOLUMETRIC_CACHE && m->cache_photons == 4096 && m->cache_cells == 12 &&
              m->cache_seed == 9 && m->cache_gather_rays == 36 &&
              m->sep_density == 2.0f && m->sep_density_width == 2.0f, "values read");
        double sum = 0.0;
        for (int i = 0; i < 6; ++i) sum += m->weights[i];
        CHECK(fabs(sum - 1.0) < 1e-6 && fabsf(m->weights[2] - 0.25f) < 1e-7f, "weights normalised: sum %g, w2 %g",
              sum, m->weights[2]);
        CHECK(m->mask == d.mask && m->octave_a == d.octave_a, "fields not given keep their defaults");
    }
    veil_scene_free(&s);
    r = parse("ms.json", "{" CAM "," MED ",'multiple_scattering':{'filter':'2x2','weights':[0,0]}}", &s, &e);
    CHECK(r == VEIL_ERR_INVALID && strstr(e.msg, "multiple_scattering.weights: expected 2 weights with a sum in (0, 1e30]"),
          "zero weights refused: %s", e.msg);
    r = parse("ms.json", "{" CAM "," MED ",'multiple_scattering':{'cache_cells':2}}", &s, &e);
    CHECK(r == VEIL_ERR_INVALID && strstr(e.msg, "multiple_scattering.cache_cells: expected 0 (the quality's) or an "
                                                 "integer in [4, 512], got 2"),
          "a cache of 2 cells refused: %s", e.msg);
    r = parse("ms.json", "{" CAM "," MED ",'multiple_scattering':{'cache_gather_rays':-2}}", &s, &e);
    CHECK(r == VEIL_ERR_INVALID && strstr(e.msg, "multiple_scattering.cache_gather_rays: expected an integer in [-1, 4096]"),
          "a gather of -2 rays refused: %s", e.msg);
    r = parse("ms.json", "{" CAM "," MED ",'multiple_scattering':{'cache_gather_rays':1.5}}", &s, &e);
    CHECK(r == VEIL_ERR_INVALID && strstr(e.msg, "multiple_scattering.cache_gather_rays"),
          "a gather of 1.5 rays refused: %s", e.msg);
    r = parse("ms.json", "{" CAM "," MED ",'multiple_scattering':{'cache_photons':-1}}", &s, &e);
    CHECK(r == VEIL_ERR_INVALID && strstr(e.msg, "multiple_scattering.cache_photons: expected an integer in [0, "),
          "negative photons refused: %s", e.msg);
    r = parse("ms.json", "{" CAM "," MED ",'multiple_scattering':{'volumetric_method':'photons'}}", &s, &e);
    CHECK(r == VEIL_ERR_INVALID && strstr(e.msg, "multiple_scattering.volumetric_method") && strstr(e.msg, "cache"),
          "an unknown method refused, naming the known ones: %s", e.msg);
    r = parse("ms.json", "{" CAM "," MED ",'multiple_scattering':{'c':0}}", &s, &e);
    CHECK(r == VEIL_ERR_INVALID && strstr(e.msg, "multiple_scattering.c: expected a number in (0, 1e30]") &&
              strstr(e.msg, "(negative and zero values are not allowed)"), "c = 0: %s", e.msg);
    /* issue 22: a number too large for a field says so and gives the bound (it said "expected a number
     * > 0" of 3e38); every number of the spread within VEIL_MAX_SPREAD (scene/limits.h) */
    static const char* const SPREAD[] = {"c", "mask_epsilon", "separation_luminance", "separation_luminance_width",
                                         "separation_density", "separation_density_width", "thin_threshold"};
    for (size_t i = 0; i < sizeof SPREAD / sizeof SPREAD[0]; ++i) {
        char json[256], want[160];
        snprintf(json, sizeof json, "{" CAM "," MED ",'multiple_scattering':{'%s':3e38}}", SPREAD[i]);
        snprintf(want, sizeof want, "ms.json: multiple_scattering.%s: expected a number in ", SPREAD[i]);
        r = parse("ms.json", json, &s, &e);
        CHECK(r == VEIL_ERR_INVALID && strstr(e.msg, want) == e.msg &&
                  strstr(e.msg, "1e30] (scene/limits.h), got 3e+38 (too large: at most 1e+30)"),
              "%s = 3e38: %s", SPREAD[i], e.msg);
    }
    r = parse("ms.json", "{" CAM "," MED ",'multiple_scattering':{'filter':'2x2','weights':[3e38,3e38]}}", &s, &e);
    CHECK(r == VEIL_ERR_INVALID && strstr(e.msg, "multiple_scattering.weights: expected 2 weights with a sum in (0, 1e30]"),
          "weights summing to 6e38: %s", e.msg);
    r = parse("ms.json", "{" CAM "," MED ",'multiple_scattering':{'octave_contribution':1}}", &s, &e);
    CHECK(r == VEIL_ERR_INVALID && strstr(e.msg, "octave_contribution: expected a number in [0, 1)"), "b = 1: %s",
          e.msg);
}

/* camera.up is normalised on load, in double: an up of 3e38 or 1e-38 overflowed or underflowed its
 * squared length in the float camera basis ("up is parallel to the view direction" at render time). */
static void test_camera_up(void)
{
    static const char* const ups[] = {"[3e38,1,0]", "[0,3e38,3e38]", "[1e-38,1e-38,0]"};
    static const double want[3][3] = {{1, 0, 0}, {0, 0.70710678, 0.70710678}, {0.70710678, 0.70710678, 0}};
    for (int i = 0; i < 3; ++i) {
        char json[256];
        snprintf(json, sizeof json, "{'camera':{'position':[0,0,5],'look_at':[0,0,0],'up':%s}," MED "}", ups[i]);
        veil_scene s;
        veil_error e = {0};
        veil_result r = parse("up.json", json, &s, &e);
        CHECK(r == VEIL_OK, "up %s: %s", ups[i], e.msg);
        if (r != VEIL_OK) continue;
        CHECK(vec_close(s.camera.up, want[i][0], want[i][1], want[i][2]), "up %s read as %g %g %g", ups[i],
              s.camera.up[0], s.camera.up[1], s.camera.up[2]);
        veil_camera_basis b;
        CHECK(veil_camera_make_basis(&s.camera, 8, 8, &b, &e) == VEIL_OK, "up %s: basis: %s", ups[i], e.msg);
        veil_scene_free(&s);
    }
}

/* Every bound of scene/limits.h is itself accepted (issue 22), and kept as given. */
static void test_bounds_accepted(void)
{
    veil_scene s;
    veil_error e = {0};
    veil_result r = parse("bounds.json",
                          "{" CAM ",'medium':{'sigma_a':[1e10,0,1e10],'sigma_s':[1e10,1e10,0],'sources':["
                          "{'type':'vdb','file':'/dev/null','density_scale':1e10,"
                          "'emission':{'grid':'heat','scale':1e21,'color':[1,0.5,0]},"
                          "'temperature':{'grid':'t','scale':-1e5,'offset':1e5,'intensity':1e10}},"
                          "{'type':'exponential','density':1e10,'falloff':1e20,'direction':[0,1,0],'origin':[0,0,0]},"
                          "{'type':'rbf','particles':[{'center':[0,0,0],'amplitude':1e10,'sharpness':1}]}]},"
                          "'background':{'color':[1e20,0,1e20]},'multiple_scattering':{'c':1e30,'thin_threshold':1e30}}",
                          &s, &e);
    CHECK(r == VEIL_OK, "the bounds themselves: %s", e.msg);
    if (r != VEIL_OK) return;
    const veil_vdb_source* v = &s.medium.sources[0].vdb;
    CHECK(s.medium.sigma_a[0] == 1e10f && s.medium.sigma_s[1] == 1e10f && v->density_scale == 1e10f &&
              v->emission_scale == 1e21f && v->temperature_scale == -1e5f && v->temperature_offset == 1e5f &&
              v->temperature_intensity == 1e10f && s.medium.sources[1].fog.falloff == 1e20f &&
              s.medium.sources[2].particles[0].amplitude == 1e10f && s.background[2] == 1e20f && s.multiple.c == 1e30f,
          "values at the bounds kept as given");
    veil_scene_free(&s);
}

typedef struct bad_case {
    const char* json;
    veil_result code;
    const char* path;   /* the message must start with "bad.json: <path>: " */
    const char* detail; /* and contain this */
} bad_case;

static const bad_case BAD[] = {
    /* scene/limits.h (issue 22): the medium's coefficients and every scale, refused at load by name
     * (sigma_s 3e38 and sigma_a 1e20 made NaN pixels; emission.scale and temperature.scale 3e38
     * Inf and NaN pixels, or a render past 60 s) */
    {"{" CAM ",'medium':{'sigma_a':[1e20,0,0],'sigma_s':[1,1,1],'sources':[]}}", VEIL_ERR_INVALID,
     "medium.sigma_a[0]", "expected a number in [0, 1e10] (m^-1: scene/limits.h), got 1e+20 (too large: at most 1e+10)"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,3e38],'sources':[]}}", VEIL_ERR_INVALID,
     "medium.sigma_s[2]", "expected a number in [0, 1e10] (m^-1: scene/limits.h), got 3e+38 (too large: at most 1e+10)"},
    {"{" CAM "," MED ",'background':{'color':[1e21,0,0]}}", VEIL_ERR_INVALID, "background.color[0]",
     "expected a number in [0, 1e20] (scene/limits.h), got 1e+21 (too large: at most 1e+20)"},
    {VDB("'density_scale':1e11"), VEIL_ERR_INVALID, "medium.sources[0].density_scale",
     "expected a number in [0, 1e10] (scene/limits.h), got 1e+11 (too large: at most 1e+10)"},
    {VDB("'emission':{'grid':'heat','scale':3e38}"), VEIL_ERR_INVALID, "medium.sources[0].emission.scale",
     "expected a number in [0, 1e21] (scene/limits.h), got 3e+38 (too large: at most 1e+21)"},
    {VDB("'emission':{'grid':'heat','color':[1,1e22,1]}"), VEIL_ERR_INVALID, "medium.sources[0].emission.color[1]",
     "expected a number in [0, 1e21] (scene/limits.h), got 1e+22 (too large: at most 1e+21)"},
    {VDB("'emission':{'grid':'heat','scale':1e20,'color':[1,100,1]}"), VEIL_ERR_INVALID,
     "medium.sources[0].emission.scale", "scale x color[1] = 1e+20 x 100 = 1e+22 W m^-3 sr^-1 for a value of 1, "
     "over the bound of 1e21 (scene/limits.h)"},
    {VDB("'temperature':{'grid':'temperature','scale':3e38}"), VEIL_ERR_INVALID, "medium.sources[0].temperature.scale",
     "expected a number in [-1e5, 1e5] (K: scene/limits.h), got 3e+38 (too large: at most 1e+05)"},
    {VDB("'temperature':{'grid':'temperature','offset':-2e5}"), VEIL_ERR_INVALID,
     "medium.sources[0].temperature.offset", "expected a number in [-1e5, 1e5] (K: scene/limits.h), got -200000"},
    {VDB("'temperature':{'grid':'temperature','intensity':1e11}"), VEIL_ERR_INVALID,
     "medium.sources[0].temperature.intensity",
     "expected a number in [0, 1e10] (m^-1: scene/limits.h), got 1e+11 (too large: at most 1e+10)"},
    {FOG("'density':1e11,'falloff':0"), VEIL_ERR_INVALID, "medium.sources[0].density",
     "expected a number in [0, 1e10] (scene/limits.h), got 1e+11 (too large: at most 1e+10)"},
    {FOG("'density':1,'falloff':3e38"), VEIL_ERR_INVALID, "medium.sources[0].falloff",
     "expected a number in [0, 1e20] (m^-1: scene/limits.h), got 3e+38 (too large: at most 1e+20)"},
    {SRC("{'type':'rbf','particles':[{'center':[0,0,0],'amplitude':3e38,'sharpness':1}]}"), VEIL_ERR_INVALID,
     "medium.sources[0].particles[0].amplitude",
     "expected a number in [0, 1e10] (scene/limits.h), got 3e+38 (too large: at most 1e+10)"},
    {RND(RND_OK_COUNT RND_OK_BOUNDS "'radius':[1,1],'amplitude':[0,1e11]"), VEIL_ERR_INVALID,
     "medium.sources[0].amplitude[1]", "expected a number in [0, 1e10] (scene/limits.h), got 1e+11 (too large: at most 1e+10)"},
    /* scene/limits.h (issue 12): what the float pipeline cannot carry is refused at load, by name */
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[{'type':'rbf','particles':["
     "{'center':[3.4e38,0,0],'amplitude':1,'sharpness':1}]}]}}",
     VEIL_ERR_INVALID, "medium.sources[0].particles[0].center[0]", "expected a number in [-1e15, 1e15] (m: scene/limits.h), got 3.4e+38"},
    {LIGHTS("{'type':'point','position':[0,0,0],'intensity':[3.4e38,1,1]}"), VEIL_ERR_INVALID,
     "lights[0].intensity[0]", "expected a number in [0, 1e20] (scene/limits.h), got 3.4e+38"},
    {"{'camera':{'position':[1e20,0,5],'look_at':[0,0,0],'up':[0,1,0]}," MED "}", VEIL_ERR_INVALID,
     "camera.position[0]", "[-1e15, 1e15]"},
    {RND("'count':3,'seed':1,'bounds':[[-1e16,0,0],[1,1,1]],'radius':[1,1],'amplitude':[1,1]"), VEIL_ERR_INVALID,
     "medium.sources[0].bounds[0][0]", "[-1e15, 1e15]"},
    {"[1,2]", VEIL_ERR_INVALID, NULL, "expected a JSON object at the top level, got an array of 2"},
    {"{" MED "}", VEIL_ERR_INVALID, "camera", "missing required field (an object)"},
    {"{'camera':{'look_at':[0,0,0]}," MED "}", VEIL_ERR_INVALID, "camera.position",
     "missing required field (an array of 3 numbers, each in [-1e15, 1e15] (m: scene/limits.h))"},
    {"{'camera':{'position':'here','look_at':[0,0,0]}," MED "}", VEIL_ERR_INVALID, "camera.position",
     "expected an array of 3 numbers, each in [-1e15, 1e15] (m: scene/limits.h), got a string (\"here\")"},
    {"{'camera':{'position':[0,0,1],'look_at':[0,0,0],'fov':40}," MED "}", VEIL_ERR_INVALID, "camera.fov",
     "unknown key (expected one of: position, look_at, up, fov_y_deg, fov_deg, sensor_fit, shift, clip, shutter, "
     "width, height)"},
    /* the sensor fit, the shift and the clip planes (issue 25) */
    {"{'camera':{'position':[0,0,1],'look_at':[0,0,0],'sensor_fit':'diagonal'}," MED "}", VEIL_ERR_INVALID,
     "camera.sensor_fit", "expected one of \"vertical\", \"horizontal\", \"auto\", got a string (\"diagonal\")"},
    {"{'camera':{'position':[0,0,1],'look_at':[0,0,0],'fov_y_deg':30,'fov_deg':30}," MED "}", VEIL_ERR_INVALID,
     "camera.fov_deg", "give either \"fov_y_deg\" (vertical) or \"fov_deg\" (along sensor_fit), not both"},
    {"{'camera':{'position':[0,0,1],'look_at':[0,0,0],'fov_y_deg':30,'sensor_fit':'auto'}," MED "}", VEIL_ERR_INVALID,
     "camera.fov_y_deg", "with sensor_fit \"auto\" give \"fov_deg\" instead"},
    {"{'camera':{'position':[0,0,1],'look_at':[0,0,0],'fov_deg':180}," MED "}", VEIL_ERR_INVALID,
     "camera.fov_deg", "expected a number of degrees in (0, 180)"},
    {"{'camera':{'position':[0,0,1],'look_at':[0,0,0],'shift':[0.1,101]}," MED "}", VEIL_ERR_INVALID,
     "camera.shift[1]", "expected a number in [-100, 100]"},
    {"{'camera':{'position':[0,0,1],'look_at':[0,0,0],'clip':[2,1]}," MED "}", VEIL_ERR_INVALID,
     "camera.clip", "expected [near, far] with 0 <= near < far (m along the view axis), got [2, 1]"},
    {"{'camera':{'position':[0,0,1],'look_at':[0,0,0],'clip':[-1,1]}," MED "}", VEIL_ERR_INVALID,
     "camera.clip", "got [-1, 1]"},
    /* a source's transform and the array source (issue 25) */
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[{'type':'array','grid':'d','transform':[[1,0,0,0],[0,1,0,0],[0,0,1,0]]}]}}",
     VEIL_ERR_INVALID, "medium.sources[0].transform", "expected an array of 4 rows of 4 numbers"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[{'type':'array','grid':'d','transform':[[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,1,1]]}]}}",
     VEIL_ERR_INVALID, "medium.sources[0].transform[3]", "expected [0, 0, 0, 1] (veil takes affine maps), got [0, 0, 1, 1]"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[{'type':'array','grid':'d','transform':[[1,0,0,0],[0,1,0,0],[2,0,0,0],[0,0,0,1]]}]}}",
     VEIL_ERR_INVALID, "medium.sources[0].transform", "the matrix is singular (determinant 0)"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[{'type':'array','grid':'d','transform':[[1,0,0,0],[0,1,0,0],[0,0,1,'x'],[0,0,0,1]]}]}}",
     VEIL_ERR_INVALID, "medium.sources[0].transform[2][3]", "got a string"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[{'type':'array'}]}}", VEIL_ERR_INVALID, "medium.sources[0].grid",
     "missing required field (a string)"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[{'type':'array','grid':'d','file':'x.vdb'}]}}", VEIL_ERR_INVALID,
     "medium.sources[0].file",
     "unknown key (expected one of: type, grid, density_scale, emission, temperature, transform)"},
    {"{'camera':{'position':[0,0,1],'position':[0,0,2],'look_at':[0,0,0]}," MED "}", VEIL_ERR_INVALID,
     "camera.position", "duplicate key"},
    {"{'camera':{'position':[0,0,1e999],'look_at':[0,0,0]}," MED "}", VEIL_ERR_INVALID,
     "camera.position[2]", "finite"},
    {"{'camera':{'position':[0,1e39,1],'look_at':[0,0,0]}," MED "}", VEIL_ERR_INVALID,
     "camera.position[1]", "single precision"},
    {"{'camera':{'position':[0,0,1],'look_at':[0,0,0],'fov_y_deg':180}," MED "}", VEIL_ERR_INVALID,
     "camera.fov_y_deg", "expected a number of degrees in (0, 180), got 180"},
    {"{'camera':{'position':[0,0,1],'look_at':[0,0,0],'width':0}," MED "}", VEIL_ERR_INVALID,
     "camera.width", "not allowed"},
    {"{'camera':{'position':[0,0,1],'look_at':[0,0,0],'height':1.5}," MED "}", VEIL_ERR_INVALID,
     "camera.height", "expected an integer in [1, 16384], got 1.5"},
    {"{'camera':{'position':[1,1,1],'look_at':[1,1,1]}," MED "}", VEIL_ERR_INVALID, "camera.look_at",
     "must differ from camera.position"},
    {"{'camera':{'position':[0,0,1],'look_at':[0,0,0],'up':[0,0,-2]}," MED "}", VEIL_ERR_INVALID,
     "camera.up", "not parallel"},
    {"{" CAM ",'medium':{'sources':[]}}", VEIL_ERR_INVALID, "medium.sigma_s", "missing required field"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'sigma_a':[0,-1,0],'sources':[]}}", VEIL_ERR_INVALID,
     "medium.sigma_a[1]", "expected a number in [0, 1e10] (m^-1: scene/limits.h), got -1"},
    {"{" CAM ",'medium':{'sigma_s':[1,1],'sources':[]}}", VEIL_ERR_INVALID, "medium.sigma_s",
     "expected an array of 3 numbers, each in [0, 1e10] (m^-1: scene/limits.h), got an array of 2 elements"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'max_resolution':-3,'sources':[]}}", VEIL_ERR_INVALID,
     "medium.max_resolution", "expected an integer in [2, 2048], got -3 (negative and zero values"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'max_resolution':4096,'sources':[]}}", VEIL_ERR_INVALID,
     "medium.max_resolution", "got 4096"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'representation':'octree','sources':[]}}", VEIL_ERR_INVALID,
     "medium.representation", "expected one of \"auto\", \"dense\", \"sparse\""},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'phase':{'type':'rayleigh'},'sources':[]}}", VEIL_ERR_INVALID,
     "medium.phase.type", "expected one of \"isotropic\", \"hg\", got a string (\"rayleigh\")"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'phase':{'type':'hg','g':1},'sources':[]}}", VEIL_ERR_INVALID,
     "medium.phase.g", "expected a number in (-1, 1), got 1"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'phase':{'type':'hg'},'sources':[]}}", VEIL_ERR_INVALID,
     "medium.phase.g", "missing required field"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'phase':{'type':'isotropic','g':0.5},'sources':[]}}",
     VEIL_ERR_INVALID, "medium.phase.g", "unknown key (expected one of: type)"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1]}}", VEIL_ERR_INVALID, "medium.sources",
     "missing required field (an array)"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[" SRC_OK ",{'particles':[]}]}}", VEIL_ERR_INVALID,
     "medium.sources[1].type", "missing required field (one of \"rbf\", \"rbf_random\", \"vdb\", \"exponential\", \"array\")"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[" SRC_OK ",7]}}", VEIL_ERR_INVALID,
     "medium.sources[1]", "expected an object, got 7"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[{'type':'rbf','particles':["
     "{'center':[0,0,0],'amplitude':1,'sharpness':1},{'center':[0,0,0],'amplitude':1,'sharpness':0}]}]}}",
     VEIL_ERR_INVALID, "medium.sources[0].particles[1].sharpness", "expected a number >= 1e-29 (its cut-off radius within 1e15 m: scene/limits.h), got 0"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[{'type':'rbf','particles':["
     "{'center':[0,0],'amplitude':1,'sharpness':1}]}]}}",
     VEIL_ERR_INVALID, "medium.sources[0].particles[0].center", "expected an array of 3 numbers"},
    {"{" CAM ",'medium':{'sigma_s':[1,1,1],'sources':[{'type':'rbf','particles':["
     "{'center':[0,0,0],'amplitude':-1,'sharpness':1}]}]}}",
     VEIL_ERR_INVALID, "medium.sources[0].particles[0].amplitude", "expected a number in [0, 1e10] (scene/limits.h), got -1"},
    {RND("'count':1e8,'seed':1," RND_OK_BOUNDS "'radius':[1,1],'amplitude':[1,1]"), VEIL_ERR_INVALID,
     "medium.sources[0].count", "expected an integer in [0, 10000000]"},
    {RND("'count':3,'seed':-1," RND_OK_BOUNDS "'radius':[1,1],'amplitude':[1,1]"), VEIL_ERR_INVALID,
     "medium.sources[0].seed", "expected an integer in [0, 2^53), got -1"},
    {RND("'count':3,'seed':9007199254740992," RND_OK_BOUNDS "'radius':[1,1],'amplitude':[1,1]"),
     VEIL_ERR_INVALID, "medium.sources[0].seed", "expected an integer in [0, 2^53)"},
    {RND("'count':3,'seed':0.5," RND_OK_BOUNDS "'radius':[1,1],'amplitude':[1,1]"), VEIL_ERR_INVALID,
     "medium.sources[0].seed", "got 0.5"},
    {RND(RND_OK_COUNT "'bounds':[[0,0,0],[1,-1,1]],'radius':[1,1],'amplitude':[1,1]"), VEIL_ERR_INVALID,
     "medium.sources[0].bounds", "min <= max on every axis, got y: 0 > -1"},
    {RND(RND_OK_COUNT "'bounds':[[0,0,0],[1,1]],'radius':[1,1],'amplitude':[1,1]"), VEIL_ERR_INVALID,
     "medium.sources[0].bounds[1]", "expected an array of 3 numbers"},
    {RND(RND_OK_COUNT RND_OK_BOUNDS "'radius':[0,1],'amplitude':[1,1]"), VEIL_ERR_INVALID,
     "medium.sources[0].radius", "0 < r0 <= r1"},
    {RND(RND_OK_COUNT RND_OK_BOUNDS "'radius':[2,1],'amplitude':[1,1]"), VEIL_ERR_INVALID,
     "medium.sources[0].radius", "got [2, 1]"},
    {RND(RND_OK_COUNT RND_OK_BOUNDS "'radius':[1,1],'amplitude':[2,1]"), VEIL_ERR_INVALID,
     "medium.sources[0].amplitude", "0 <= c0 <= c1"},
    {RND(RND_OK_COUNT RND_OK_BOUNDS "'radius':[1,1]"), VEIL_ERR_INVALID,
     "medium.sources[0].amplitude", "missing required field (an array of 2 numbers, each in [0, 1e10] (scene/limits.h))"},
    {RND(RND_OK_COUNT RND_OK_BOUNDS "'radius':[1,1],'amplitude':[1,1],'particles':[]"), VEIL_ERR_INVALID,
     "medium.sources[0].particles", "unknown key"},
    {"{" CAM "," MED ",'lights':{}}", VEIL_ERR_INVALID, "lights", "expected an array, got an object"},
    {"{" CAM "," MED ",'lights':[" LIGHT_OK ",{'type':'point','position':[0,0,0],'intensity':'red'}]}",
     VEIL_ERR_INVALID, "lights[1].intensity", "expected an array of 3 numbers, each in [0, 1e20] (scene/limits.h), got a string (\"red\")"},
    {"{" CAM "," MED ",'lights':[{'type':'directional','direction':[0,0,0],'irradiance':[1,1,1]}]}",
     VEIL_ERR_INVALID, "lights[0].direction", "expected a non-zero vector"},
    {"{" CAM "," MED ",'lights':[{'type':'area','position':[0,0,0],'intensity':[1,1,1]}]}",
     VEIL_ERR_INVALID, "lights[0].type", "expected one of \"point\", \"directional\", \"spot\", \"environment\", got a string"},
    {"{" CAM "," MED ",'lights':[{'type':'point','direction':[0,0,1],'intensity':[1,1,1]}]}",
     VEIL_ERR_INVALID, "lights[0].direction", "unknown key (expected one of: type, position, intensity)"},
    {"{" CAM "," MED ",'lights':[{'type':'directional','direction':[0,0,1]}]}", VEIL_ERR_INVALID,
     "lights[0].irradiance", "missing required field"},
    /* spot lights */
    {SPOT(SPOT_DI "'inner_angle_deg':45,'outer_angle_deg':30"), VEIL_ERR_INVALID, "lights[0].inner_angle_deg",
     "expected a number of degrees in [0, outer_angle_deg) = [0, 30), got 45"},
    {SPOT(SPOT_DI "'inner_angle_deg':30,'outer_angle_deg':30"), VEIL_ERR_INVALID, "lights[0].inner_angle_deg",
     "expected a number of degrees in [0, outer_angle_deg) = [0, 30), got 30"},
    {SPOT(SPOT_DI "'inner_angle_deg':-5,'outer_angle_deg':30"), VEIL_ERR_INVALID, "lights[0].inner_angle_deg",
     "expected a number of degrees in [0, outer_angle_deg) = [0, 30), got -5"},
    {SPOT(SPOT_DI "'inner_angle_deg':'wide','outer_angle_deg':30"), VEIL_ERR_INVALID,
     "lights[0].inner_angle_deg", "got a string (\"wide\")"},
    {SPOT(SPOT_DI "'outer_angle_deg':190"), VEIL_ERR_INVALID, "lights[0].outer_angle_deg",
     "expected a number of degrees in (0, 180], got 190"},
    {SPOT(SPOT_DI "'outer_angle_deg':180.00001"), VEIL_ERR_INVALID, "lights[0].outer_angle_deg",
     "expected a number of degrees in (0, 180], got 180.00001"},
    {SPOT(SPOT_DI "'outer_angle_deg':0"), VEIL_ERR_INVALID, "lights[0].outer_angle_deg",
     "expected a number of degrees in (0, 180], got 0 (negative and zero values are not allowed)"},
    {SPOT(SPOT_DI "'inner_angle_deg':10"), VEIL_ERR_INVALID, "lights[0].outer_angle_deg",
     "missing required field (a number of degrees in (0, 180])"},
    {SPOT("'direction':[0,0,0],'intensity':[1,1,1],'outer_angle_deg':30"), VEIL_ERR_INVALID,
     "lights[0].direction", "expected a non-zero vector (the direction light travels), got [0, 0, 0]"},
    {SPOT("'intensity':[1,1,1],'outer_angle_deg':30"), VEIL_ERR_INVALID, "lights[0].direction",
     "missing required field (an array of 3 numbers)"},
    {SPOT(SPOT_DI "'outer_angle_deg':30,'irradiance':[1,1,1]"), VEIL_ERR_INVALID, "lights[0].irradiance",
     "unknown key (expected one of: type, position, direction, intensity, inner_angle_deg, outer_angle_deg)"},
    {LIGHTS("{'type':'spot','direction':[0,0,1],'intensity':[1,1,1],'outer_angle_deg':30}"), VEIL_ERR_INVALID,
     "lights[0].position", "missing required field (an array of 3 numbers, each in [-1e15, 1e15] (m: scene/limits.h))"},
    {SPOT("'direction':[0,0,1],'intensity':[1,-1,1],'outer_angle_deg':30"), VEIL_ERR_INVALID,
     "lights[0].intensity[1]", "expected a number in [0, 1e20] (scene/limits.h), got -1"},
    {LIGHTS(LIGHT_OK ",{'type':'point','position':[0,0,0],'intensity':[1,1,1],'inner_angle_deg':10}"),
     VEIL_ERR_INVALID, "lights[1].inner_angle_deg", "unknown key (expected one of: type, position, intensity)"},
    {LIGHTS("{'type':'point','position':[0,0,0],'intensity':[1,1,1],'outer_angle_deg':30}"), VEIL_ERR_INVALID,
     "lights[0].outer_angle_deg", "unknown key (expected one of: type, position, intensity)"},
    {LIGHTS("{'type':'directional','direction':[0,0,1],'irradiance':[1,1,1],'outer_angle_deg':30}"),
     VEIL_ERR_INVALID, "lights[0].outer_angle_deg", "unknown key (expected one of: type, direction, irradiance)"},
    {"{" CAM "," MED ",'background':{'colour':[1,1,1]}}", VEIL_ERR_INVALID, "background.colour",
     "unknown key (expected one of: color)"},
    {"{" CAM "," MED ",'background':{'color':[1,1,true]}}", VEIL_ERR_INVALID, "background.color[2]",
     "expected a number in [0, 1e20] (scene/limits.h), got true"},
    {"{" CAM "," MED ",'background':null}", VEIL_ERR_INVALID, "background", "expected an object, got null"},
};

static void test_bad(void)
{
    for (size_t i = 0; i < sizeof BAD / sizeof BAD[0]; ++i) {
        const bad_case* b = &BAD[i];
        veil_scene s;
        memset(&s, 0xAB, sizeof s);
        veil_error e = {0};
        veil_result r = parse("bad.json", b->json, &s, &e);
        char prefix[256];
        snprintf(prefix, sizeof prefix, "bad.json: %s%s", b->path ? b->path : "", b->path ? ": " : "");
        CHECK(r == b->code, "case %zu: result %s, expected %s (%s)", i, veil_result_name(r),
              veil_result_name(b->code), e.msg);
        CHECK(strncmp(e.msg, prefix, strlen(prefix)) == 0, "case %zu: message \"%s\" should start with \"%s\"",
              i, e.msg, prefix);
        CHECK(strstr(e.msg, b->detail) != NULL, "case %zu: message \"%s\" should contain \"%s\"", i, e.msg,
              b->detail);
        CHECK(is_zeroed(&s), "case %zu: scene not zeroed after failure", i);
        veil_scene_free(&s);
    }
}

static void test_spot(void)
{
    veil_scene s;
    veil_error e = {0};
    veil_result r = parse("spot.json", LIGHTS(LIGHT_OK ",{'type':'spot','position':[1,2,3],'direction':[0,-3,4],"
                          "'intensity':[10,20,30],'inner_angle_deg':12.5,'outer_angle_deg':30},"
                          "{'type':'spot','position':[0,0,0],'direction':[0,0,-0.001],'intensity':[0,0,0],"
                          "'outer_angle_deg':180},{'type':'spot','outer_angle_deg':1e-3,'inner_angle_deg':0,"
                          "'position':[0,0,0],'intensity':[1,1,1],'direction':[2,0,0]}"), &s, &e);
    CHECK(r == VEIL_OK, "spot lights: %s", e.msg);
    if (r != VEIL_OK) return;
    CHECK(s.light_count == 4, "light_count %zu", s.light_count);
    if (s.light_count == 4) {
        const veil_light* l = s.lights;
        CHECK(l[0].type == VEIL_LIGHT_POINT && l[0].inner_angle_deg == 0 && l[0].outer_angle_deg == 0,
              "point light has no cone");
        CHECK(l[1].type == VEIL_LIGHT_SPOT, "type %d", l[1].type);
        CHECK(vec_close(l[1].position, 1, 2, 3), "spot position");
        CHECK(vec_close(l[1].direction, 0, -0.6, 0.8), "spot direction not normalised: %g %g %g",
              l[1].direction[0], l[1].direction[1], l[1].direction[2]);
        CHECK(vec_close(l[1].color, 10, 20, 30), "spot intensity");
        CHECK(l[1].inner_angle_deg == 12.5f && l[1].outer_angle_deg == 30.0f, "spot angles %g %g",
              l[1].inner_angle_deg, l[1].outer_angle_deg);
        CHECK(l[2].type == VEIL_LIGHT_SPOT && vec_close(l[2].direction, 0, 0, -1), "tiny axis normalised");
        CHECK(l[2].inner_angle_deg == 0 && l[2].outer_angle_deg == 180.0f, "default inner 0, outer 180: %g %g",
              l[2].inner_angle_deg, l[2].outer_angle_deg);
        CHECK(vec_close(l[2].color, 0, 0, 0), "zero intensity is allowed");
        CHECK(l[3].type == VEIL_LIGHT_SPOT && vec_close(l[3].direction, 1, 0, 0) &&
              l[3].inner_angle_deg == 0 && l[3].outer_angle_deg == 1e-3f, "narrow spot, keys in any order");
    }
    veil_scene_free(&s);
}

static void test_exact_messages(void)
{
    veil_scene s;
    veil_error e = {0};
    parse("demo.json", LIGHTS(LIGHT_OK "," LIGHT_OK ",{'type':'spot','position':[0,0,0]," SPOT_DI
          "'inner_angle_deg':45,'outer_angle_deg':30}"), &s, &e);
    CHECK(strcmp(e.msg, "demo.json: lights[2].inner_angle_deg: expected a number of degrees in "
                        "[0, outer_angle_deg) = [0, 30), got 45 (too large: below 30)") == 0, "%s", e.msg);
    parse("demo.json", SPOT(SPOT_DI "'inner_angle_deg':5"), &s, &e);
    CHECK(strcmp(e.msg, "demo.json: lights[0].outer_angle_deg: missing required field "
                        "(a number of degrees in (0, 180])") == 0, "%s", e.msg);
    parse("scene.json", "{'camera':{'position':[0,0,1],'look_at':[0,0,0],'fov':40}," MED "}", &s, &e);
    CHECK(strcmp(e.msg, "scene.json: camera.fov: unknown key (expected one of: position, look_at, up, "
                        "fov_y_deg, fov_deg, sensor_fit, shift, clip, shutter, width, height)") == 0, "%s", e.msg);
    parse("demo.json", "{'camera':{'look_at':[0,0,0]}," MED "}", &s, &e);
    CHECK(strcmp(e.msg, "demo.json: camera.position: missing required field (an array of 3 numbers, each in [-1e15, 1e15] (m: scene/limits.h))") == 0,
          "%s", e.msg);
}

static void test_syntax(void)
{
    static const struct { const char* json; const char* prefix; } cases[] = {
        {"{\n  'camera': {\n    'position': [0,0,1],,\n", "syn.json:3:26: JSON syntax error near '\": [0,0,1],,' at the end"},
        {"{'camera':", "syn.json:1:10: JSON syntax error near '{\"camera\":' at the end of the input"},
        {"{'camera':{}} ]\n\n{", "syn.json:1:15: JSON syntax error near 'camera\":{}} ]': unexpected content"},
        {"{\n'camera':\n\n", "syn.json:3:1: JSON syntax error: unexpected end of input"},
        {"", "syn.json:1:1: JSON syntax error: unexpected end of input"},
        {"  \n ", "syn.json:2:1: JSON syntax error: unexpected end of input"},
        {"{} trailing", "syn.json:1:4: JSON syntax error near '{} trailing': unexpected content after"},
        {"{'a':\xc3\xa9x}", "syn.json:1:6: JSON syntax error near '{\"a\":\xc3\xa9x}'"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        veil_scene s;
        veil_error e = {0};
        veil_result r = parse("syn.json", cases[i].json, &s, &e);
        CHECK(r == VEIL_ERR_PARSE, "syntax case %zu: %s (%s)", i, veil_result_name(r), e.msg);
        CHECK(strncmp(e.msg, cases[i].prefix, strlen(cases[i].prefix)) == 0,
              "syntax case %zu: \"%s\" should start with \"%s\"", i, e.msg, cases[i].prefix);
        CHECK(is_zeroed(&s), "syntax case %zu: scene not zeroed", i);
    }
    /* a trailing NUL counted in len is accepted */
    veil_scene s;
    veil_error e = {0};
    const char text[] = "{\"camera\":{\"position\":[0,0,1],\"look_at\":[0,0,0]},"
                        "\"medium\":{\"sigma_s\":[1,1,1],\"sources\":[]}}\n";
    CHECK(veil_scene_parse("nul.json", text, sizeof text, &s, &e) == VEIL_OK, "trailing NUL: %s", e.msg);
    veil_scene_free(&s);
}

static void test_load(void)
{
    veil_scene s;
    veil_error e = {0};
    veil_result r = veil_scene_load("no_such_dir/missing.json", &s, &e);
    CHECK(r == VEIL_ERR_IO, "missing file: %s", veil_result_name(r));
    CHECK(strcmp(e.msg, "no_such_dir/missing.json: cannot open: No such file or directory") == 0, "%s", e.msg);
    CHECK(is_zeroed(&s), "missing file: scene not zeroed");

    const char* name = "test_scene_load.json";
    FILE* f = fopen(name, "wb");
    CHECK(f != NULL, "cannot create %s in the working directory", name);
    if (!f) return;
    fputs("{\"camera\":{\"position\":[0,0,1],\"look_at\":[0,0,0],\"width\":8,\"height\":4},\n"
          "\"medium\":{\"sigma_s\":[1,1,1],\"sources\":[]}}\n", f);
    fclose(f);
    r = veil_scene_load(name, &s, &e);
    CHECK(r == VEIL_OK && s.camera.width == 8 && strcmp(s.path, name) == 0 && strcmp(s.base_dir, ".") == 0,
          "load: %s", e.msg);
    veil_scene_free(&s);

    f = fopen(name, "wb");
    if (f) fputs("{\"camera\":{\"position\":[0,0,1],\n\"look_at\":[0,0,0]]}", f), fclose(f);
    r = veil_scene_load(name, &s, &e);
    CHECK(r == VEIL_ERR_PARSE && strncmp(e.msg, "test_scene_load.json:2:18: JSON syntax error", 44) == 0,
          "load syntax error: %s", e.msg);
    remove(name);
}

static void test_particle_limit(void)
{
    veil_source src[2] = {{.type = VEIL_SOURCE_RBF_RANDOM, .random = {.count = 6000000}},
                          {.type = VEIL_SOURCE_RBF_RANDOM, .random = {.count = 6000000}}};
    veil_scene s = {.path = "big.json", .medium = {.sources = src, .source_count = 2}};
    veil_particle* p = (veil_particle*)&s; /* must be reset to NULL */
    size_t n = 1;
    veil_error e = {0};
    veil_result r = veil_scene_particles(&s, &p, &n, &e);
    CHECK(r == VEIL_ERR_LIMIT && p == NULL && n == 0, "limit: %s", veil_result_name(r));
    CHECK(strstr(e.msg, "big.json: medium.sources[1]: ") == e.msg, "%s", e.msg);
    src[1] = (veil_source){.type = VEIL_SOURCE_RBF, .particle_count = (size_t)-1};
    r = veil_scene_particles(&s, &p, &n, &e);
    CHECK(r == VEIL_ERR_LIMIT && p == NULL, "overflowing count: %s", veil_result_name(r));
}

int main(void)
{
    test_full();
    test_defaults();
    test_multiple();
    test_bad();
    test_bounds_accepted();
    test_camera_up();
    test_spot();
    test_exact_messages();
    test_syntax();
    test_load();
    test_particle_limit();
    return check_finish();
}
