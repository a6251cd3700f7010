/* veil — scene files (JSON) → veil_scene. See io/scene.h, docs/scene-format.md.
 * Values are read through io/json_read.h, so each message names the file,
 * the JSON path of the field and what was expected; the medium's sources
 * are read in io/scene_sources.c. */
#include "scene.h"
#include "json_read.h"
#include "scene_multiple.h"
#include "scene_sources.h"
#include "image.h"
#include "../scene/limits.h"

#include <cJSON.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SCENE_MAX_FILE_BYTES ((size_t)256 << 20) /* 256 MiB */

static const char* const ROOT_KEYS[] = {"camera", "medium", "lights", "background", "multiple_scattering", "quality",
                                        "deep", "fps", NULL};
static const char* const DEEP_KEYS[] = {"samples", NULL};
static const range R_DEEP_SAMPLES = {1, VEIL_DEEP_MAX_SAMPLES, false, false, true, "an integer in [1, 64]"};
_Static_assert(VEIL_DEEP_MAX_SAMPLES == 64, "R_DEEP_SAMPLES' text (and --deep-samples' in cli/) names the bound");
static const char* const QUALITIES[] = {"draft", "default", "high", "max", NULL}; /* = veil_quality - 1 */
static const char* const CAMERA_KEYS[] = {"position", "look_at", "up", "fov_y_deg", "fov_deg", "sensor_fit", "shift",
                                          "clip", "shutter", "width", "height", NULL};
static const char* const SENSOR_FITS[] = {"vertical", "horizontal", "auto", NULL}; /* = veil_sensor_fit */
static const char* const MEDIUM_KEYS[] = {"sigma_a", "sigma_s", "phase", "max_resolution", "representation",
                                           "sources", NULL};
static const char* const REPRESENTATIONS[] = {"auto", "dense", "sparse", NULL}; /* = veil_representation */
static const char* const PHASE_TYPES[] = {"isotropic", "hg", NULL}; /* = veil_phase_type */
static const char* const ISO_KEYS[] = {"type", NULL};
static const char* const HG_KEYS[] = {"type", "g", NULL};
/* = veil_light_type, and "environment" (scene/environment.h: not a veil_light) */
static const char* const LIGHT_TYPES[] = {"point", "directional", "spot", "environment", NULL};
#define ENVIRONMENT_KIND 3
static const char* const POINT_KEYS[] = {"type", "position", "intensity", NULL};
static const char* const DIR_KEYS[] = {"type", "direction", "irradiance", NULL};
static const char* const SPOT_KEYS[] = {"type", "position", "direction", "intensity", "inner_angle_deg",
                                        "outer_angle_deg", NULL};
static const char* const* const LIGHT_KEYS[] = {POINT_KEYS, DIR_KEYS, SPOT_KEYS}; /* by veil_light_type */
static const char* const BACKGROUND_KEYS[] = {"color", NULL};
static const char* const ENV_KEYS[] = {"type",  "color",  "file",      "intensity", "rotation_deg",
                                       "up",    "lights", "remainder", NULL};
static const char* const ENV_UP[] = {"y", "z", NULL};
static const char* const ENV_REMAINDER[] = {"cache", "lights", NULL}; /* = veil_environment.remainder_lights */

static veil_result check_camera(const ctx* c, const jpath* p, const veil_camera* cam)
{
    const jpath lp = {p, "look_at", 0}, up = {p, "up", 0};
    double d[3], u[3], x[3];
    for (int i = 0; i < 3; ++i) d[i] = (double)cam->look_at[i] - cam->position[i], u[i] = cam->up[i];
    if (d[0] == 0 && d[1] == 0 && d[2] == 0)
        return veil__jr_fail_at(c, &lp, "must differ from camera.position (both are [%g, %g, %g])",
                       d[0] + cam->position[0], d[1] + cam->position[1], d[2] + cam->position[2]);
    x[0] = d[1] * u[2] - d[2] * u[1], x[1] = d[2] * u[0] - d[0] * u[2], x[2] = d[0] * u[1] - d[1] * u[0];
    double nd = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    double nu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) <= 1e-6 * nd * nu)
        return veil__jr_fail_at(c, &up, "expected a non-zero vector not parallel to the view direction "
                       "(look_at - position = [%g, %g, %g]), got [%g, %g, %g]",
                       d[0], d[1], d[2], u[0], u[1], u[2]);
    return VEIL_OK;
}

static veil_result parse_camera(const ctx* c, const cJSON* root, veil_camera* cam)
{
    const jpath p = {NULL, "camera", 0};
    const cJSON* o;
    double fov = cam->fov_y_deg;
    TRY(veil__jr_get_container(c, root, &p, true, false, &o));
    TRY(veil__jr_check_keys(c, o, &p, CAMERA_KEYS));
    TRY(veil__jr_get_floats_in(c, o, &p, "position", true, 3, &VEIL__R_COORD, cam->position));
    TRY(veil__jr_get_floats_in(c, o, &p, "look_at", true, 3, &VEIL__R_COORD, cam->look_at));
    TRY(veil__jr_get_floats(c, o, &p, "up", false, 3, false, cam->up));
    /* the field of view: "fov_y_deg" (vertical), or "fov_deg" along "sensor_fit" */
    const jpath fp = {&p, "sensor_fit", 0};
    const cJSON* fit = cJSON_GetObjectItemCaseSensitive(o, "sensor_fit");
    if (fit) {
        int k = -1;
        for (int i = 0; fit && cJSON_IsString(fit) && SENSOR_FITS[i]; ++i)
            if (!strcmp(fit->valuestring, SENSOR_FITS[i])) k = i;
        if (k < 0) return veil__jr_expected(c, &fp, "one of \"vertical\", \"horizontal\", \"auto\"", fit);
        cam->sensor_fit = k;
    }
    const int y_given = cJSON_GetObjectItemCaseSensitive(o, "fov_y_deg") != NULL;
    if (y_given && cJSON_GetObjectItemCaseSensitive(o, "fov_deg"))
        return veil__jr_fail_at(c, &(jpath){&p, "fov_deg", 0}, "give either \"fov_y_deg\" (vertical) or "
                                "\"fov_deg\" (along sensor_fit), not both");
    if (y_given && cam->sensor_fit != VEIL_FIT_VERTICAL)
        return veil__jr_fail_at(c, &(jpath){&p, "fov_y_deg", 0}, "is the vertical field of view: with sensor_fit "
                                "\"%s\" give \"fov_deg\" instead", SENSOR_FITS[cam->sensor_fit]);
    TRY(veil__jr_get_number(c, o, &p, y_given ? "fov_y_deg" : "fov_deg", false, &VEIL__R_FOV, &fov));
    cam->fov_y_deg = (float)fov;
    /* Blender's shift: fractions of the fitted side's extent; within +-100 of it, the rays stay finite */
    static const range shift = {-100, 100, false, false, false, "a number in [-100, 100] (the image's fitted side)"};
    TRY(veil__jr_get_floats_in(c, o, &p, "shift", false, 2, &shift, cam->shift));
    const jpath cp = {&p, "clip", 0};
    if (cJSON_GetObjectItemCaseSensitive(o, "clip")) {
        TRY(veil__jr_get_floats_in(c, o, &p, "clip", false, 2, &VEIL__R_COORD, cam->clip));
        if (!(cam->clip[0] >= 0.0f && cam->clip[1] > cam->clip[0]))
            return veil__jr_fail_at(c, &cp, "expected [near, far] with 0 <= near < far (m along the view axis), "
                                    "got [%g, %g]", cam->clip[0], cam->clip[1]);
    }
    /* the shutter, in frames around the frame: motion blur of the sources that give a velocity */
    const jpath sp = {&p, "shutter", 0};
    if (cJSON_GetObjectItemCaseSensitive(o, "shutter")) {
        static const range frames = {-VEIL_MAX_SHUTTER_FRAMES, VEIL_MAX_SHUTTER_FRAMES, false, false, false,
                                     "a number of frames in [-4, 4] (relative to the frame: scene/scene.h)"};
        TRY(veil__jr_get_floats_in(c, o, &p, "shutter", false, 2, &frames, cam->shutter));
        if (!(cam->shutter[1] >= cam->shutter[0]))
            return veil__jr_fail_at(c, &sp, "expected [open, close] with open <= close (frames relative to the "
                                    "frame), got [%g, %g]", cam->shutter[0], cam->shutter[1]);
        cam->has_shutter = 1;
    }
    TRY(veil__jr_get_int(c, o, &p, "width", &VEIL__R_SIZE, &cam->width));
    TRY(veil__jr_get_int(c, o, &p, "height", &VEIL__R_SIZE, &cam->height));
    TRY(check_camera(c, &p, cam));
    /* up is a direction: normalised here, in double (the camera's basis is float, and an up of
     * [3e38, 1, 0] or [1e-38, 1e-38, 0] overflowed or underflowed its squared length there) */
    double u[3] = {cam->up[0], cam->up[1], cam->up[2]}, n = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int i = 0; i < 3; ++i) cam->up[i] = (float)(u[i] / n); /* n > 0: check_camera */
    return VEIL_OK;
}

static veil_result parse_phase(const ctx* c, const cJSON* medium, const jpath* mp, veil_phase* ph)
{
    const jpath p = {mp, "phase", 0};
    const cJSON* o;
    int kind;
    TRY(veil__jr_get_container(c, medium, &p, false, false, &o));
    if (!o) return VEIL_OK; /* isotropic */
    TRY(veil__jr_get_kind(c, o, &p, PHASE_TYPES, &kind));
    TRY(veil__jr_check_keys(c, o, &p, kind == VEIL_PHASE_HG ? HG_KEYS : ISO_KEYS));
    ph->type = (veil_phase_type)kind;
    double g = 0;
    if (kind == VEIL_PHASE_HG) TRY(veil__jr_get_number(c, o, &p, "g", true, &VEIL__R_G, &g));
    ph->g = (float)g;
    return VEIL_OK;
}

static veil_result parse_medium(const ctx* c, const cJSON* root, veil_medium* m)
{
    const jpath p = {NULL, "medium", 0};
    const cJSON* o;
    TRY(veil__jr_get_container(c, root, &p, true, false, &o));
    TRY(veil__jr_check_keys(c, o, &p, MEDIUM_KEYS));
    TRY(veil__jr_get_floats_in(c, o, &p, "sigma_a", false, 3, &VEIL__R_SIGMA, m->sigma_a));
    TRY(veil__jr_get_floats_in(c, o, &p, "sigma_s", true, 3, &VEIL__R_SIGMA, m->sigma_s));
    TRY(parse_phase(c, o, &p, &m->phase));
    TRY(veil__jr_get_int(c, o, &p, "max_resolution", &VEIL__R_RES, &m->max_resolution));
    m->max_resolution_set = cJSON_GetObjectItemCaseSensitive(o, "max_resolution") != NULL;
    int rep = (int)m->representation;
    TRY(veil__jr_get_name(c, o, &p, "representation", REPRESENTATIONS, &rep));
    m->representation = (veil_representation)rep;
    return veil__parse_sources(c, o, &p, m);
}

static veil_result parse_direction(const ctx* c, const cJSON* lo, const jpath* lp, float dir[3])
{
    const jpath p = {lp, "direction", 0};
    TRY(veil__jr_get_floats(c, lo, lp, "direction", true, 3, false, dir));
    double len = sqrt((double)dir[0] * dir[0] + (double)dir[1] * dir[1] + (double)dir[2] * dir[2]);
    if (!(len > 0))
        return veil__jr_fail_at(c, &p, "expected a non-zero vector (the direction light travels), got [%g, %g, %g]",
                       dir[0], dir[1], dir[2]);
    for (int i = 0; i < 3; ++i) dir[i] = (float)(dir[i] / len);
    return VEIL_OK;
}

/* A spot's cone: outer_angle_deg in (0, 180], then inner_angle_deg (default
 * 0) in [0, outer), both as stored (floats), so that 0 <= inner < outer. */
static veil_result parse_cone(const ctx* c, const cJSON* lo, const jpath* lp, veil_light* l)
{
    char what[96];
    double outer, inner = 0;
    TRY(veil__jr_get_number(c, lo, lp, "outer_angle_deg", true, &VEIL__R_OUTER, &outer));
    snprintf(what, sizeof what, "a number of degrees in [0, outer_angle_deg) = [0, %g)", outer);
    const range r = {0, outer, false, true, false, what};
    TRY(veil__jr_get_number(c, lo, lp, "inner_angle_deg", false, &r, &inner));
    l->inner_angle_deg = (float)inner, l->outer_angle_deg = (float)outer;
    return VEIL_OK;
}

/* The environment's map: an EXR's R, G, B (alpha ignored), times colour x intensity; NaN or infinite texels
 * refused (naming the texel), negative ones (a filtered map's ringing) read as 0. */
static veil_result load_environment_map(const ctx* c, const jpath* fp, veil_environment* env, const float tint[3])
{
    int w = 0, h = 0;
    float* rgba = NULL;
    veil_error inner = {0};
    const char* base = strrchr(env->file, '/');
    char what[160];
    snprintf(what, sizeof what, "reading %.140s", base ? base + 1 : env->file);
    /* over VEIL_ENV_MAX_TEXELS refused from the header, before any texel is read (issue 41: a 16384 x 8192
     * map took 2.1 GB and 20 s before its size was seen) */
    veil_result code = veil_read_exr_within(env->file, VEIL_ENV_MAX_TEXELS, what, &w, &h, &rgba, &inner);
    if (code != VEIL_OK) {
        veil_result r = veil__jr_fail_at(c, fp, "cannot read the environment map: %s%s", inner.msg,
                                         code == VEIL_ERR_LIMIT ? " (an environment map has at most 2^25 texels: "
                                                                  "8192 x 4096)" : "");
        return code == VEIL_ERR_OOM || code == VEIL_ERR_LIMIT || code == VEIL_ERR_IO || code == VEIL_ERR_CANCELLED ? code : r;
    }
    if ((size_t)w * (size_t)h > VEIL_ENV_MAX_TEXELS || w < 2 || h < 1) {
        free(rgba);
        return veil__jr_fail_at(c, fp, "'%s': an environment map of %dx%d texels (a lat-long map from 2x1 to %zu "
                                       "texels, twice as wide as high)", env->file, w, h, VEIL_ENV_MAX_TEXELS);
    }
    env->rgb = malloc((size_t)w * (size_t)h * 3 * sizeof *env->rgb);
    if (!env->rgb) {
        free(rgba);
        return veil_fail(c->err, VEIL_ERR_OOM, "%s: out of memory for the environment map (%dx%d)", c->name, w, h);
    }
    env->width = w, env->height = h;
    for (size_t t = 0; t < (size_t)w * (size_t)h; ++t)
        for (int k = 0; k < 3; ++k) {
            float v = rgba[4 * t + (size_t)k];
            if (!isfinite(v)) {
                free(rgba);
                return veil__jr_fail_at(c, fp, "'%s': texel (%zu, %zu) has %c %s: radiance must be finite",
                                        env->file, t % (size_t)w, t / (size_t)w, "RGB"[k], isnan(v) ? "NaN" : "inf");
            }
            double r = v > 0.0f ? (double)v * tint[k] : 0.0;
            if (r > VEIL_MAX_BACKGROUND) {
                free(rgba);
                return veil__jr_fail_at(c, fp, "'%s': texel (%zu, %zu) times color x intensity is %g: radiance at "
                                        "most %g (scene/limits.h)", env->file, t % (size_t)w, t / (size_t)w, r,
                                        VEIL_MAX_BACKGROUND);
            }
            env->rgb[3 * t + (size_t)k] = (float)r;
        }
    free(rgba);
    return VEIL_OK;
}

/* {"type": "environment", "color" | "file", "intensity", "rotation_deg", "up", "lights", "remainder"}
 * (scene/environment.h) */
static veil_result parse_environment(const ctx* c, const cJSON* e, const jpath* ep, veil_environment* env)
{
    static const range ROTATION = {-1e6, 1e6, false, false, false, "a number of degrees in [-1e6, 1e6]"};
    static const range LIGHTS = {1, VEIL_MAX_LIGHTS, false, false, true, "an integer in [1, 16]"};
    const jpath fp = {ep, "file", 0}, ip = {ep, "intensity", 0};
    TRY(veil__jr_check_keys(c, e, ep, ENV_KEYS));
    env->present = 1;
    env->lights = 0; /* the quality rung's */
    float color[3] = {1.0f, 1.0f, 1.0f};
    double intensity = 1.0, rotation = 0.0;
    const int has_color = cJSON_GetObjectItemCaseSensitive(e, "color") != NULL;
    TRY(veil__jr_get_floats_in(c, e, ep, "color", false, 3, &VEIL__R_BACKGROUND, color));
    TRY(veil__jr_get_number(c, e, ep, "intensity", false, &VEIL__R_BACKGROUND, &intensity));
    TRY(veil__jr_get_number(c, e, ep, "rotation_deg", false, &ROTATION, &rotation));
    TRY(veil__jr_get_int(c, e, ep, "lights", &LIGHTS, &env->lights));
    TRY(veil__jr_get_name(c, e, ep, "up", ENV_UP, &env->up_z));
    TRY(veil__jr_get_name(c, e, ep, "remainder", ENV_REMAINDER, &env->remainder_lights));
    TRY(veil__get_string(c, e, ep, "file", false, &env->file));
    env->rotation_deg = (float)rotation;
    float tint[3];
    for (int k = 0; k < 3; ++k) tint[k] = (float)(color[k] * intensity);
    if (env->file) {
        TRY(veil__resolve_path(c, &fp, &env->file, 0));
        TRY(load_environment_map(c, &fp, env, tint));
    } else {
        if (!has_color)
            return veil__jr_fail_at(c, ep, "missing required field: \"color\" (a constant sky's radiance, "
                                           "W m^-2 sr^-1) or \"file\" (a lat-long EXR map)");
        env->rgb = malloc(3 * sizeof *env->rgb);
        if (!env->rgb) return veil_fail(c->err, VEIL_ERR_OOM, "%s: out of memory", c->name);
        env->width = env->height = 1;
        for (int k = 0; k < 3; ++k) {
            if ((double)tint[k] > VEIL_MAX_BACKGROUND)
                return veil__jr_fail_at(c, &ip, "color x intensity is %g: radiance at most %g (scene/limits.h)",
                                        (double)tint[k], VEIL_MAX_BACKGROUND);
            env->rgb[k] = tint[k];
        }
    }
    double total[3];
    veil_env_integral(env, total);
    for (int k = 0; k < 3; ++k)
        if (total[k] > VEIL_MAX_LIGHT)
            return veil__jr_fail_at(c, env->file ? &fp : ep, "the environment's radiance integrates to %g W/m^2 over "
                                    "the sphere: at most %g, a light's limit (scene/limits.h)", total[k], VEIL_MAX_LIGHT);
    return VEIL_OK;
}

static veil_result parse_lights(const ctx* c, const cJSON* root, veil_scene* s)
{
    const jpath p = {NULL, "lights", 0};
    const cJSON* arr, *e;
    size_t i = 0;
    TRY(veil__jr_get_container(c, root, &p, false, true, &arr));
    void* items = NULL;
    size_t n = 0;
    TRY(veil__jr_alloc_items(c, &p, arr, sizeof *s->lights, VEIL_MAX_LIGHTS, &items, &s->light_count));
    s->lights = items;
    cJSON_ArrayForEach(e, arr) {
        const jpath ep = {&p, NULL, i++};
        int kind;
        if (!cJSON_IsObject(e)) return veil__jr_expected(c, &ep, "an object", e);
        TRY(veil__jr_get_kind(c, e, &ep, LIGHT_TYPES, &kind));
        if (kind == ENVIRONMENT_KIND) {
            if (s->environment.present)
                return veil__jr_fail_at(c, &ep, "a second environment light (lights[%zu] is one): at most one is "
                                                "supported", s->environment.light_index);
            TRY(parse_environment(c, e, &ep, &s->environment));
            s->environment.light_index = i - 1;
            continue;
        }
        veil_light* l = &s->lights[n++];
        l->type = (veil_light_type)kind;
        TRY(veil__jr_check_keys(c, e, &ep, LIGHT_KEYS[kind]));
        if (kind != VEIL_LIGHT_DIRECTIONAL)
            TRY(veil__jr_get_floats_in(c, e, &ep, "position", true, 3, &VEIL__R_COORD, l->position));
        if (kind != VEIL_LIGHT_POINT) TRY(parse_direction(c, e, &ep, l->direction));
        const char* power = kind == VEIL_LIGHT_DIRECTIONAL ? "irradiance" : "intensity";
        TRY(veil__jr_get_floats_in(c, e, &ep, power, true, 3, &VEIL__R_LIGHT, l->color));
        if (kind == VEIL_LIGHT_SPOT) TRY(parse_cone(c, e, &ep, l));
    }
    s->light_count = n; /* (the environment is one of the VEIL_MAX_LIGHTS entries: n < VEIL_MAX_LIGHTS with it) */
    if (s->environment.present) { /* (at most the room the other lights leave: docs/scene-format.md) */
        static const int rungs[VEIL_ENV_CUTS] = {VEIL_ENV_LIGHTS_DEFAULT, VEIL_ENV_LIGHTS_DRAFT, VEIL_ENV_LIGHTS_HIGH};
        if (veil_env_make_cuts(&s->environment, VEIL_MAX_LIGHTS - (int)n, rungs, VEIL_ENV_CUTS))
            return veil_fail(c->err, VEIL_ERR_CANCELLED, "%s: cancelled while the environment map was cut into "
                             "lights", c->name);
    }
    return VEIL_OK;
}

static veil_result parse_background(const ctx* c, const cJSON* root, float color[3])
{
    const jpath p = {NULL, "background", 0};
    const cJSON* o;
    TRY(veil__jr_get_container(c, root, &p, false, false, &o));
    if (!o) return VEIL_OK;
    TRY(veil__jr_check_keys(c, o, &p, BACKGROUND_KEYS));
    return veil__jr_get_floats_in(c, o, &p, "color", false, 3, &VEIL__R_BACKGROUND, color);
}

/* "deep": {"samples": N}: a deep image's cap (render/deep.h); 0 when absent */
static veil_result parse_deep(const ctx* c, const cJSON* root, int* samples)
{
    const jpath p = {NULL, "deep", 0};
    const cJSON* o;
    TRY(veil__jr_get_container(c, root, &p, false, false, &o));
    if (!o) return VEIL_OK;
    TRY(veil__jr_check_keys(c, o, &p, DEEP_KEYS));
    return veil__jr_get_int(c, o, &p, "samples", &R_DEEP_SAMPLES, samples);
}

static veil_result parse_root(const ctx* c, const cJSON* root, veil_scene* s)
{
    if (!cJSON_IsObject(root)) {
        char buf[128];
        return veil__jr_fail_at(c, NULL, "expected a JSON object at the top level, got %s",
                       veil__jr_describe(root, buf, sizeof buf));
    }
    TRY(veil__jr_check_keys(c, root, NULL, ROOT_KEYS));
    TRY(parse_camera(c, root, &s->camera));
    TRY(parse_medium(c, root, &s->medium));
    TRY(parse_lights(c, root, s));
    TRY(veil__parse_multiple(c, root, &s->multiple));
    int q = -1;
    TRY(veil__jr_get_name(c, root, NULL, "quality", QUALITIES, &q));
    s->quality = (veil_quality)(q + 1);
    s->background_set = cJSON_GetObjectItemCaseSensitive(root, "background") != NULL;
    TRY(parse_deep(c, root, &s->deep_samples));
    static const range fps = {0, VEIL_SCENE_MAX_FPS, true, false, false, "a number of frames per second in (0, 1000]"};
    TRY(veil__jr_get_number(c, root, NULL, "fps", false, &fps, &s->fps));
    return parse_background(c, root, s->background);
}

/* ---- text, files, names ------------------------------------------------ */

static bool is_space(char ch) { return ch == ' ' || ch == '\t' || ch == '\n' || ch == '\r'; }

static veil_result syntax_error(const ctx* c, const char* json, size_t len, size_t pos, const char* why)
{
    size_t line = 1, col = 1;
    for (size_t i = 0; i < pos; ++i) {
        if (json[i] == '\n') line++, col = 1;
        else if (((unsigned char)json[i] & 0xC0) != 0x80) col++; /* count UTF-8 characters */
    }
    size_t start = pos, rest = pos; /* show a little of the line before pos */
    while (start > 0 && pos - start < 12 && json[start - 1] != '\n') --start;
    while (start < pos && (is_space(json[start]) || ((unsigned char)json[start] & 0xC0) == 0x80)) ++start;
    while (rest < len && is_space(json[rest])) ++rest;
    char near[64];
    veil__jr_excerpt(near, json + start, len - start, 24);
    /* cJSON reports a premature end of input at the last byte */
    bool at_end = pos + 1 >= len || rest >= len || json[rest] == '\0';
    if (at_end && strspn(near, " \t") == strlen(near))
        return veil_fail(c->err, VEIL_ERR_PARSE, "%s:%zu:%zu: JSON syntax error: unexpected end of input",
                         c->name, line, col);
    return veil_fail(c->err, VEIL_ERR_PARSE, "%s:%zu:%zu: JSON syntax error near '%s'%s%s%s", c->name, line,
                     col, near, at_end ? " at the end of the input" : "", why ? ": " : "", why ? why : "");
}

static veil_result parse_json(const ctx* c, const char* json, size_t len, cJSON** out)
{
    const char* end = NULL;
    *out = len ? cJSON_ParseWithLengthOpts(json, len, &end, 0) : NULL;
    size_t pos = end && end >= json && end <= json + len ? (size_t)(end - json) : 0;
    if (!*out) return syntax_error(c, json, len, pos, NULL);
    while (pos < len && is_space(json[pos])) ++pos;
    if (pos == len || (pos + 1 == len && json[pos] == '\0')) return VEIL_OK;
    cJSON_Delete(*out);
    *out = NULL;
    return syntax_error(c, json, len, pos, "unexpected content after the JSON value");
}

static char* dup_range(const char* s, size_t n)
{
    char* d = malloc(n + 1);
    if (d) memcpy(d, s, n), d[n] = '\0';
    return d;
}

static veil_result set_names(const ctx* c, veil_scene* s)
{
    const char* slash = strrchr(c->name, '/');
    s->path = dup_range(c->name, strlen(c->name));
    if (c->base) s->base_dir = dup_range(c->base, strlen(c->base));
    else if (!slash) s->base_dir = dup_range(".", 1);
    else s->base_dir = dup_range(c->name, slash == c->name ? 1 : (size_t)(slash - c->name));
    if (!s->path || !s->base_dir) return veil_fail(c->err, VEIL_ERR_OOM, "%s: out of memory", c->name);
    return VEIL_OK;
}

veil_result veil_scene_parse(const char* name, const char* json, size_t len,
                             veil_scene* out, veil_error* err)
{
    return veil_scene_parse_in(name, json, len, NULL, out, err);
}

veil_result veil_scene_parse_in(const char* name, const char* json, size_t len, const char* base_dir,
                                veil_scene* out, veil_error* err)
{
    if (!out || (!json && len)) return veil_fail(err, VEIL_ERR_INVALID, "veil_scene_parse: NULL argument");
    memset(out, 0, sizeof *out);
    if (base_dir && !base_dir[0]) base_dir = NULL; /* "": the name's folder, as for a file */
    const ctx c = {name ? name : "<scene>", err, base_dir};
    if (!json) json = "";
    cJSON* root;
    TRY(parse_json(&c, json, len, &root));
    veil_scene s = {0};
    s.camera = (veil_camera){.up = {0, 1, 0}, .fov_y_deg = VEIL_SCENE_DEFAULT_FOV_Y,
                             .width = VEIL_SCENE_DEFAULT_WIDTH, .height = VEIL_SCENE_DEFAULT_HEIGHT};
    s.medium.max_resolution = VEIL_SCENE_DEFAULT_MAX_RES;
    s.fps = VEIL_SCENE_DEFAULT_FPS;
    veil_result r = parse_root(&c, root, &s);
    if (r == VEIL_OK) r = set_names(&c, &s);
    cJSON_Delete(root);
    if (r != VEIL_OK) {
        veil_scene_free(&s);
        return r;
    }
    *out = s;
    return VEIL_OK;
}

veil_result veil_scene_load(const char* path, veil_scene* out, veil_error* err)
{
    if (!out || !path) return veil_fail(err, VEIL_ERR_INVALID, "veil_scene_load: NULL argument");
    memset(out, 0, sizeof *out);
    char* buf = NULL;
    size_t len = 0;
    veil_result r = veil__read_file(path, SCENE_MAX_FILE_BYTES, "scene", &buf, &len, err);
    if (r != VEIL_OK) return r;
    r = veil_scene_parse(path, buf, len, out, err);
    free(buf);
    if (r == VEIL_OK) out->path_is_file = 1;
    return r;
}
