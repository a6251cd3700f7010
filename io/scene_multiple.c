/* veil — the "multiple_scattering" object of a scene file (scene/scene.h's
 * veil_multiple; docs/scene-format.md lists every field with its unit).
 * Absent fields keep veil_multiple_defaults(). */
#include "scene_multiple.h"
#include "../scene/limits.h"

#include <stdio.h>
#include <string.h>

static const char* const MS_KEYS[] = {
    "screen_space", "volumetric", "c", "mask_epsilon", "mask", "luminance_weighting", "density_blur", "levels",
    "filter", "weights", "interpolation", "separation", "separation_luminance", "separation_luminance_width",
    "separation_density", "separation_density_width", "k_ssc", "thin_threshold", "octaves", "emission_lights", "octave_extinction",
    "octave_contribution", "octave_eccentricity", "volumetric_method", "diffusion_cells", "diffusion_iterations",
    "octave_gate", "cache_photons", "cache_cells", "cache_seed", "cache_gather_rays", NULL};
static const char* const GATES[] = {"legs", "escape", NULL}; /* = veil_octave_gate */
static const char* const VOL_METHODS[] = {"octave", "diffusion", "cache", NULL}; /* = veil_volumetric_method */
static const char* const FILTERS[] = {"2x2", "4x4", "6x6", NULL};                                 /* = veil_spread_filter */
static const char* const INTERPS[] = {"linear-bilinear", "linear-bicubic", "cubic-bicubic", NULL}; /* = veil_spread_interp */

/* the spread's numbers: within VEIL_MAX_SPREAD (scene/limits.h) */
static const range R_POS = {0, VEIL_MAX_SPREAD, true, false, false, "a number in (0, 1e30] (scene/limits.h)"};
static const range R_NONNEG = {0, VEIL_MAX_SPREAD, false, false, false, "a number in [0, 1e30] (scene/limits.h)"};
static const range R_LEVELS = {0, VEIL_SPREAD_MAX_LEVEL, false, false, true, "an integer in [0, 12] (0: from the image size)"};
static const range R_UNIT_CLOSED = {0, 1, false, false, false, "a number in [0, 1]"};
static const range R_UNIT_OPEN_LO = {0, 1, true, false, false, "a number in (0, 1]"};
static const range R_UNIT_OPEN_HI = {0, 1, false, true, false, "a number in [0, 1)"};
static const range R_OCTAVES = {1, 16, false, false, true, "an integer in [1, 16]"};
static const range R_EMISSION_LIGHTS = {0, 16, false, false, true, "an integer in [0, 16]"};
static const range R_CELLS = {8, 256, false, false, true, "an integer in [8, 256]"};
static const range R_PHOTONS = {0, 1 << 30, false, false, true, "an integer in [0, 1073741824] (0: the quality's)"};
static const range R_CACHE_CELLS = {0, 512, false, false, true, "an integer in [0, 512] (0: the quality's; else at least 4)"};
static const range R_SEED = {0, 2147483647.0, false, false, true, "an integer in [0, 2147483647]"};
static const range R_GATHER = {-1, 4096, false, false, true, "an integer in [-1, 4096] (0: the quality's; -1: off)"};
static const range R_ITER = {0, 100000, false, false, true, "an integer in [0, 100000] (0: 3 x the cells)"};

static veil_result get_bool(const ctx* c, const cJSON* o, const jpath* pp, const char* key, int* out)
{
    const jpath p = {pp, key, 0};
    const cJSON* v;
    TRY(veil__jr_lookup(c, o, &p, false, "true or false", &v));
    if (!v) return VEIL_OK;
    if (!cJSON_IsBool(v)) return veil__jr_expected(c, &p, "true or false", v);
    *out = cJSON_IsTrue(v) ? 1 : 0;
    return VEIL_OK;
}

static veil_result get_float(const ctx* c, const cJSON* o, const jpath* pp, const char* key, const range* r,
                             float* out)
{
    double x = *out;
    TRY(veil__jr_get_number(c, o, pp, key, false, r, &x));
    *out = (float)x;
    return VEIL_OK;
}

/* "weights": the filter's taps, as many as it has, >= 0, symmetric is not
 * required; normalised to sum 1 (a blur that keeps energy). */
static veil_result get_weights(const ctx* c, const cJSON* o, const jpath* pp, veil_multiple* m)
{
    const jpath p = {pp, "weights", 0};
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(o, "weights");
    int n = veil_spread_taps(m->filter);
    if (!v) return VEIL_OK;
    float w[6] = {0};
    TRY(veil__jr_parse_floats(c, v, &p, n, true, w));
    double sum = 0;
    for (int i = 0; i < n; ++i) sum += w[i];
    if (!(sum > 0) || !(sum <= VEIL_MAX_SPREAD))
        return veil__jr_fail_at(c, &p, "expected %d weights with a sum in (0, 1e30] (they are normalised: scene/limits.h)", n);
    for (int i = 0; i < 6; ++i) m->weights[i] = i < n ? (float)(w[i] / sum) : 0.0f;
    return VEIL_OK;
}

veil_result veil__parse_multiple(const ctx* c, const cJSON* root, veil_multiple* m)
{
    veil_multiple_defaults(m);
    const jpath p = {NULL, "multiple_scattering", 0};
    const cJSON* o;
    TRY(veil__jr_get_container(c, root, &p, false, false, &o));
    if (!o) return VEIL_OK;
    TRY(veil__jr_check_keys(c, o, &p, MS_KEYS));
    int filter = (int)m->filter, interp = (int)m->interp;
    TRY(get_bool(c, o, &p, "screen_space", &m->screen_space));
    TRY(get_bool(c, o, &p, "volumetric", &m->volumetric));
    int vm = (int)m->volumetric_method;
    TRY(veil__jr_get_name(c, o, &p, "volumetric_method", VOL_METHODS, &vm));
    m->volumetric_method = (veil_volumetric_method)vm;
    TRY(veil__jr_get_int(c, o, &p, "diffusion_cells", &R_CELLS, &m->diffusion_cells));
    TRY(veil__jr_get_int(c, o, &p, "diffusion_iterations", &R_ITER, &m->diffusion_iterations));
    int photons = (int)m->cache_photons, seed = (int)m->cache_seed;
    TRY(veil__jr_get_int(c, o, &p, "cache_photons", &R_PHOTONS, &photons));
    TRY(veil__jr_get_int(c, o, &p, "cache_cells", &R_CACHE_CELLS, &m->cache_cells));
    if (m->cache_cells > 0 && m->cache_cells < 4) {
        const jpath cp = {&p, "cache_cells", 0};
        return veil__jr_fail_at(c, &cp, "expected 0 (the quality's) or an integer in [4, 512], got %d", m->cache_cells);
    }
    TRY(veil__jr_get_int(c, o, &p, "cache_seed", &R_SEED, &seed));
    TRY(veil__jr_get_int(c, o, &p, "cache_gather_rays", &R_GATHER, &m->cache_gather_rays));
    m->cache_photons = photons, m->cache_seed = (unsigned)seed;
    TRY(get_float(c, o, &p, "c", &R_POS, &m->c));
    TRY(get_float(c, o, &p, "mask_epsilon", &R_NONNEG, &m->mask_epsilon));
    TRY(get_bool(c, o, &p, "mask", &m->mask));
    TRY(get_bool(c, o, &p, "luminance_weighting", &m->luminance_weighting));
    TRY(get_bool(c, o, &p, "density_blur", &m->density_blur));
    TRY(veil__jr_get_int(c, o, &p, "levels", &R_LEVELS, &m->levels));
    TRY(veil__jr_get_name(c, o, &p, "filter", FILTERS, &filter));
    m->filter = (veil_spread_filter)filter;
    veil_spread_default_weights(m->filter, m->weights);
    TRY(get_weights(c, o, &p, m));
    TRY(veil__jr_get_name(c, o, &p, "interpolation", INTERPS, &interp));
    m->interp = (veil_spread_interp)interp;
    TRY(get_bool(c, o, &p, "separation", &m->separation));
    TRY(get_float(c, o, &p, "separation_luminance", &R_NONNEG, &m->sep_luminance));
    TRY(get_float(c, o, &p, "separation_luminance_width", &R_POS, &m->sep_luminance_width));
    TRY(get_float(c, o, &p, "separation_density", &R_POS, &m->sep_density));
    TRY(get_float(c, o, &p, "separation_density_width", &R_POS, &m->sep_density_width));
    if (m->sep_density_width > m->sep_density) {
        const jpath wp = {&p, "separation_density_width", 0};
        return veil__jr_fail_at(c, &wp, "expected at most separation_density (%g): the ramp is [T - eps, T] "
                                "of a density >= 0, got %g", m->sep_density, m->sep_density_width);
    }
    TRY(get_float(c, o, &p, "k_ssc", &R_UNIT_CLOSED, &m->k_ssc));
    TRY(get_float(c, o, &p, "thin_threshold", &R_NONNEG, &m->thin_threshold));
    TRY(veil__jr_get_int(c, o, &p, "octaves", &R_OCTAVES, &m->octaves));
    TRY(veil__jr_get_int(c, o, &p, "emission_lights", &R_EMISSION_LIGHTS, &m->emission_lights));
    TRY(veil__jr_get_name(c, o, &p, "octave_gate", GATES, &m->octave_gate));
    TRY(get_float(c, o, &p, "octave_extinction", &R_UNIT_OPEN_LO, &m->octave_a));
    TRY(get_float(c, o, &p, "octave_contribution", &R_UNIT_OPEN_HI, &m->octave_b));
    return get_float(c, o, &p, "octave_eccentricity", &R_UNIT_CLOSED, &m->octave_c);
}
