/* veil — scene files (JSON) → veil_scene. See io/scene.h, docs/scene-format.md.
 *
 * Every value is read through a small set of helpers that know the JSON path
 * of what they read (a linked list of path components on the stack, printed
 * only when something is wrong), so each message names the file, the field
 * and what was expected.
 */
#include "scene.h"

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

#define TRY(expr)                                                              \
    do {                                                                       \
        veil_result try_r_ = (expr);                                           \
        if (try_r_ != VEIL_OK) return try_r_;                                  \
    } while (0)

/* One component of a JSON path: `.key` when key is set, else `[index]`. */
typedef struct jpath {
    const struct jpath* up;
    const char* key;
    size_t index;
} jpath;

typedef struct ctx {
    const char* name; /* file name, first thing in every message */
    veil_error* err;
} ctx;

/* Accepted numbers: [lo, hi] (or open ends), optionally integral. */
typedef struct range {
    double lo, hi;
    bool lo_open, hi_open, integer;
    const char* what; /* the expectation, as printed */
} range;

static const range R_ANY = {-DBL_MAX, DBL_MAX, false, false, false, "a number"};
static const range R_NONNEG = {0, DBL_MAX, false, false, false, "a number >= 0"};
static const range R_POS = {0, DBL_MAX, true, false, false, "a number > 0"};
static const range R_FOV = {0, 180, true, true, false, "a number of degrees in (0, 180)"};
static const range R_OUTER = {0, 180, true, false, false, "a number of degrees in (0, 180]"};
static const range R_G = {-1, 1, true, true, false, "a number in (-1, 1)"};
static const range R_SIZE = {1, VEIL_SCENE_MAX_IMAGE, false, false, true, "an integer in [1, 16384]"};
static const range R_RES = {2, VEIL_SCENE_MAX_RESOLUTION, false, false, true, "an integer in [2, 2048]"};
static const range R_COUNT = {0, 1e7, false, false, true, "an integer in [0, 10000000]"};
static const range R_SEED = {0, 9007199254740992.0, false, true, true, "an integer in [0, 2^53)"};

static const char* const ROOT_KEYS[] = {"camera", "medium", "lights", "background", NULL};
static const char* const CAMERA_KEYS[] = {"position", "look_at", "up", "fov_y_deg", "width", "height", NULL};
static const char* const MEDIUM_KEYS[] = {"sigma_a", "sigma_s", "phase", "max_resolution", "sources", NULL};
static const char* const PHASE_TYPES[] = {"isotropic", "hg", NULL}; /* = veil_phase_type */
static const char* const ISO_KEYS[] = {"type", NULL};
static const char* const HG_KEYS[] = {"type", "g", NULL};
static const char* const SOURCE_TYPES[] = {"rbf", "rbf_random", NULL}; /* = veil_source_type */
static const char* const RBF_KEYS[] = {"type", "particles", NULL};
static const char* const RANDOM_KEYS[] = {"type", "count", "seed", "bounds", "radius", "amplitude", NULL};
static const char* const PARTICLE_KEYS[] = {"center", "amplitude", "sharpness", NULL};
static const char* const LIGHT_TYPES[] = {"point", "directional", "spot", NULL}; /* = veil_light_type */
static const char* const POINT_KEYS[] = {"type", "position", "intensity", NULL};
static const char* const DIR_KEYS[] = {"type", "direction", "irradiance", NULL};
static const char* const SPOT_KEYS[] = {"type", "position", "direction", "intensity", "inner_angle_deg",
                                        "outer_angle_deg", NULL};
static const char* const* const LIGHT_KEYS[] = {POINT_KEYS, DIR_KEYS, SPOT_KEYS}; /* by veil_light_type */
static const char* const BACKGROUND_KEYS[] = {"color", NULL};

/* ---- messages ---------------------------------------------------------- */

static size_t path_format(const jpath* p, char* buf, size_t n)
{
    size_t len = p->up ? path_format(p->up, buf, n) : 0;
    if (len >= n) return len;
    int w = p->key ? snprintf(buf + len, n - len, "%s%s", len ? "." : "", p->key)
                   : snprintf(buf + len, n - len, "[%zu]", p->index);
    return w < 0 ? len : len + (size_t)w;
}

/* Copies at most max bytes of src (stopping at a newline or NUL, never
 * splitting a UTF-8 sequence), control characters replaced by '?'. */
static void excerpt(char* dst, const char* src, size_t len, size_t max)
{
    size_t n = 0;
    while (n < len && n < max && src[n] != '\n' && src[n] != '\r' && src[n] != '\0') ++n;
    if (n < len && n == max)
        while (n > 0 && ((unsigned char)src[n] & 0xC0) == 0x80) --n;
    for (size_t i = 0; i < n; ++i) dst[i] = (unsigned char)src[i] < 0x20 ? '?' : src[i];
    dst[n] = '\0';
}

/* "a string (\"abc\")", "an array of 2 elements", "-3", ... */
static const char* describe(const cJSON* v, char* buf, size_t n)
{
    if (cJSON_IsNull(v)) return "null";
    if (cJSON_IsBool(v)) return cJSON_IsTrue(v) ? "true" : "false";
    if (cJSON_IsObject(v)) return "an object";
    if (cJSON_IsNumber(v)) {
        snprintf(buf, n, "%.9g", v->valuedouble);
    } else if (cJSON_IsString(v)) {
        char text[48];
        size_t len = strlen(v->valuestring);
        excerpt(text, v->valuestring, len, 40);
        snprintf(buf, n, "a string (\"%s%s\")", text, strlen(text) < len ? "..." : "");
    } else if (cJSON_IsArray(v)) {
        int k = cJSON_GetArraySize(v);
        snprintf(buf, n, "an array of %d element%s", k, k == 1 ? "" : "s");
    } else {
        return "an unknown value";
    }
    return buf;
}

#if defined(__GNUC__)
#define SCENE_PRINTF __attribute__((format(printf, 3, 4)))
#else
#define SCENE_PRINTF
#endif

/* "<file>: <path>: <message>", VEIL_ERR_INVALID. */
static SCENE_PRINTF veil_result fail_at(const ctx* c, const jpath* p, const char* fmt, ...)
{
    char where[512] = "", what[1024];
    if (p) path_format(p, where, sizeof where);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (!p) return veil_fail(c->err, VEIL_ERR_INVALID, "%s: %s", c->name, what);
    return veil_fail(c->err, VEIL_ERR_INVALID, "%s: %s: %s", c->name, where, what);
}

static veil_result expected(const ctx* c, const jpath* p, const char* what, const cJSON* got)
{
    char buf[128];
    return fail_at(c, p, "expected %s, got %s", what, describe(got, buf, sizeof buf));
}

static void join(const char* const* names, bool quote, char* buf, size_t n)
{
    size_t len = 0;
    buf[0] = '\0';
    for (size_t i = 0; names[i] && len < n; ++i) {
        int w = snprintf(buf + len, n - len, "%s%s%s%s", i ? ", " : "", quote ? "\"" : "",
                         names[i], quote ? "\"" : "");
        if (w < 0) return;
        len += (size_t)w;
    }
}

/* ---- generic readers --------------------------------------------------- */

/* Every key of obj must be in allowed, once. */
static veil_result check_keys(const ctx* c, const cJSON* obj, const jpath* p, const char* const* allowed)
{
    const cJSON* kv;
    cJSON_ArrayForEach(kv, obj) {
        const jpath kp = {p, kv->string, 0};
        bool known = false;
        for (size_t i = 0; allowed[i] && !known; ++i) known = strcmp(kv->string, allowed[i]) == 0;
        if (!known) {
            char list[256];
            join(allowed, false, list, sizeof list);
            return fail_at(c, &kp, "unknown key (expected one of: %s)", list);
        }
        for (const cJSON* o = kv->next; o; o = o->next)
            if (strcmp(o->string, kv->string) == 0) return fail_at(c, &kp, "duplicate key");
    }
    return VEIL_OK;
}

/* *v = obj[p->key], NULL when absent; absent and required is an error. */
static veil_result lookup(const ctx* c, const cJSON* obj, const jpath* p, bool required,
                          const char* what, const cJSON** v)
{
    *v = cJSON_GetObjectItemCaseSensitive(obj, p->key);
    if (!*v && required) return fail_at(c, p, "missing required field (%s)", what);
    return VEIL_OK;
}

/* An object or array field; *v stays NULL when optional and absent. */
static veil_result get_container(const ctx* c, const cJSON* obj, const jpath* p, bool required,
                                 bool array, const cJSON** v)
{
    const char* what = array ? "an array" : "an object";
    TRY(lookup(c, obj, p, required, what, v));
    if (*v && !(array ? cJSON_IsArray(*v) : cJSON_IsObject(*v))) return expected(c, p, what, *v);
    return VEIL_OK;
}

static veil_result parse_number(const ctx* c, const cJSON* v, const jpath* p, const range* r, double* out)
{
    char buf[64];
    if (!cJSON_IsNumber(v)) return expected(c, p, r->what, v);
    double x = v->valuedouble;
    if (!isfinite(x) || (!r->integer && fabs(x) > FLT_MAX))
        return fail_at(c, p, "expected %s, got %s (numbers must be finite and fit in single precision)",
                       r->what, describe(v, buf, sizeof buf));
    if (!r->integer) x = (double)(float)x; /* what will be stored */
    bool ok = (r->lo_open ? x > r->lo : x >= r->lo) && (r->hi_open ? x < r->hi : x <= r->hi);
    if (ok && (!r->integer || x == floor(x))) {
        *out = x;
        return VEIL_OK;
    }
    bool positive = r->lo > 0 || (r->lo == 0 && r->lo_open);
    return fail_at(c, p, "expected %s, got %s%s", r->what, describe(v, buf, sizeof buf),
                   positive && x <= 0 ? " (negative and zero values are not allowed)" : "");
}

/* obj[key] as a number; *out keeps its default when optional and absent. */
static veil_result get_number(const ctx* c, const cJSON* obj, const jpath* pp, const char* key,
                              bool required, const range* r, double* out)
{
    const jpath p = {pp, key, 0};
    const cJSON* v;
    TRY(lookup(c, obj, &p, required, r->what, &v));
    return v ? parse_number(c, v, &p, r, out) : VEIL_OK;
}

static veil_result get_int(const ctx* c, const cJSON* obj, const jpath* pp, const char* key,
                           const range* r, int* out)
{
    double x = *out;
    TRY(get_number(c, obj, pp, key, false, r, &x));
    *out = (int)x;
    return VEIL_OK;
}

/* An array of exactly n numbers (>= 0 when nonneg). */
static veil_result parse_floats(const ctx* c, const cJSON* v, const jpath* p, int n, bool nonneg, float* out)
{
    char what[64];
    snprintf(what, sizeof what, "an array of %d numbers%s", n, nonneg ? " >= 0" : "");
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != n) return expected(c, p, what, v);
    size_t i = 0;
    const cJSON* e;
    cJSON_ArrayForEach(e, v) {
        const jpath ep = {p, NULL, i};
        double x;
        TRY(parse_number(c, e, &ep, nonneg ? &R_NONNEG : &R_ANY, &x));
        out[i++] = (float)x;
    }
    return VEIL_OK;
}

static veil_result get_floats(const ctx* c, const cJSON* obj, const jpath* pp, const char* key,
                              bool required, int n, bool nonneg, float* out)
{
    char what[64];
    snprintf(what, sizeof what, "an array of %d numbers%s", n, nonneg ? " >= 0" : "");
    const jpath p = {pp, key, 0};
    const cJSON* v;
    TRY(lookup(c, obj, &p, required, what, &v));
    return v ? parse_floats(c, v, &p, n, nonneg, out) : VEIL_OK;
}

/* obj.type, one of names; *kind is its index. */
static veil_result get_kind(const ctx* c, const cJSON* obj, const jpath* pp, const char* const* names, int* kind)
{
    char what[160] = "one of ";
    join(names, true, what + 7, sizeof what - 7);
    const jpath p = {pp, "type", 0};
    const cJSON* v;
    TRY(lookup(c, obj, &p, true, what, &v));
    for (int i = 0; cJSON_IsString(v) && names[i]; ++i) {
        if (strcmp(v->valuestring, names[i]) == 0) {
            *kind = i;
            return VEIL_OK;
        }
    }
    return expected(c, &p, what, v);
}

/* An array field's elements: calloc'd, count stored before filling, so a
 * partial result is freed by veil_scene_free(). */
static veil_result alloc_items(const ctx* c, const jpath* p, const cJSON* arr, size_t size,
                               size_t limit, void** items, size_t* count)
{
    size_t n = arr ? (size_t)cJSON_GetArraySize(arr) : 0;
    if (n > limit) return fail_at(c, p, "too many elements (%zu, at most %zu)", n, limit);
    if (n == 0) return VEIL_OK;
    *items = calloc(n, size);
    if (!*items) return veil_fail(c->err, VEIL_ERR_OOM, "%s: out of memory reading %zu elements", c->name, n);
    *count = n;
    return VEIL_OK;
}

/* ---- the scene --------------------------------------------------------- */

static veil_result check_camera(const ctx* c, const jpath* p, const veil_camera* cam)
{
    const jpath lp = {p, "look_at", 0}, up = {p, "up", 0};
    double d[3], u[3], x[3];
    for (int i = 0; i < 3; ++i) d[i] = (double)cam->look_at[i] - cam->position[i], u[i] = cam->up[i];
    if (d[0] == 0 && d[1] == 0 && d[2] == 0)
        return fail_at(c, &lp, "must differ from camera.position (both are [%g, %g, %g])",
                       d[0] + cam->position[0], d[1] + cam->position[1], d[2] + cam->position[2]);
    x[0] = d[1] * u[2] - d[2] * u[1], x[1] = d[2] * u[0] - d[0] * u[2], x[2] = d[0] * u[1] - d[1] * u[0];
    double nd = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    double nu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) <= 1e-6 * nd * nu)
        return fail_at(c, &up, "expected a non-zero vector not parallel to the view direction "
                       "(look_at - position = [%g, %g, %g]), got [%g, %g, %g]",
                       d[0], d[1], d[2], u[0], u[1], u[2]);
    return VEIL_OK;
}

static veil_result parse_camera(const ctx* c, const cJSON* root, veil_camera* cam)
{
    const jpath p = {NULL, "camera", 0};
    const cJSON* o;
    double fov = cam->fov_y_deg;
    TRY(get_container(c, root, &p, true, false, &o));
    TRY(check_keys(c, o, &p, CAMERA_KEYS));
    TRY(get_floats(c, o, &p, "position", true, 3, false, cam->position));
    TRY(get_floats(c, o, &p, "look_at", true, 3, false, cam->look_at));
    TRY(get_floats(c, o, &p, "up", false, 3, false, cam->up));
    TRY(get_number(c, o, &p, "fov_y_deg", false, &R_FOV, &fov));
    cam->fov_y_deg = (float)fov;
    TRY(get_int(c, o, &p, "width", &R_SIZE, &cam->width));
    TRY(get_int(c, o, &p, "height", &R_SIZE, &cam->height));
    return check_camera(c, &p, cam);
}

static veil_result parse_phase(const ctx* c, const cJSON* medium, const jpath* mp, veil_phase* ph)
{
    const jpath p = {mp, "phase", 0};
    const cJSON* o;
    int kind;
    TRY(get_container(c, medium, &p, false, false, &o));
    if (!o) return VEIL_OK; /* isotropic */
    TRY(get_kind(c, o, &p, PHASE_TYPES, &kind));
    TRY(check_keys(c, o, &p, kind == VEIL_PHASE_HG ? HG_KEYS : ISO_KEYS));
    ph->type = (veil_phase_type)kind;
    double g = 0;
    if (kind == VEIL_PHASE_HG) TRY(get_number(c, o, &p, "g", true, &R_G, &g));
    ph->g = (float)g;
    return VEIL_OK;
}

static veil_result parse_particles(const ctx* c, const cJSON* so, const jpath* sp, veil_source* src)
{
    const jpath p = {sp, "particles", 0};
    const cJSON* arr, *e;
    size_t i = 0;
    TRY(get_container(c, so, &p, true, true, &arr));
    void* items = NULL;
    TRY(alloc_items(c, &p, arr, sizeof *src->particles, VEIL_SCENE_MAX_PARTICLES, &items, &src->particle_count));
    src->particles = items;
    cJSON_ArrayForEach(e, arr) {
        const jpath ep = {&p, NULL, i};
        veil_particle* q = &src->particles[i++];
        double amp, sharp;
        if (!cJSON_IsObject(e)) return expected(c, &ep, "an object", e);
        TRY(check_keys(c, e, &ep, PARTICLE_KEYS));
        TRY(get_floats(c, e, &ep, "center", true, 3, false, q->center));
        TRY(get_number(c, e, &ep, "amplitude", true, &R_NONNEG, &amp));
        TRY(get_number(c, e, &ep, "sharpness", true, &R_POS, &sharp));
        q->amplitude = (float)amp, q->sharpness = (float)sharp;
    }
    return VEIL_OK;
}

static veil_result parse_bounds(const ctx* c, const cJSON* so, const jpath* sp, float b[2][3])
{
    static const char what[] = "an array of 2 arrays of 3 numbers (min and max corner)";
    const jpath p = {sp, "bounds", 0};
    const jpath ep[2] = {{&p, NULL, 0}, {&p, NULL, 1}};
    const cJSON* v;
    TRY(lookup(c, so, &p, true, what, &v));
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 2) return expected(c, &p, what, v);
    TRY(parse_floats(c, cJSON_GetArrayItem(v, 0), &ep[0], 3, false, b[0]));
    TRY(parse_floats(c, cJSON_GetArrayItem(v, 1), &ep[1], 3, false, b[1]));
    for (int i = 0; i < 3; ++i)
        if (b[0][i] > b[1][i])
            return fail_at(c, &p, "expected min <= max on every axis, got %c: %g > %g",
                           "xyz"[i], b[0][i], b[1][i]);
    return VEIL_OK;
}

static veil_result parse_random(const ctx* c, const cJSON* so, const jpath* sp, veil_rbf_random_desc* d)
{
    const jpath rp = {sp, "radius", 0}, ap = {sp, "amplitude", 0};
    double count, seed;
    TRY(get_number(c, so, sp, "count", true, &R_COUNT, &count));
    TRY(get_number(c, so, sp, "seed", true, &R_SEED, &seed));
    d->count = (uint32_t)count, d->seed = (uint64_t)seed;
    TRY(parse_bounds(c, so, sp, d->bounds));
    TRY(get_floats(c, so, sp, "radius", true, 2, true, d->radius));
    if (!(d->radius[0] > 0 && d->radius[0] <= d->radius[1] && isfinite(1.0f / d->radius[0])))
        return fail_at(c, &rp, "expected [r0, r1] with 0 < r0 <= r1 (metres), got [%g, %g]",
                       d->radius[0], d->radius[1]);
    TRY(get_floats(c, so, sp, "amplitude", true, 2, true, d->amplitude));
    if (d->amplitude[0] > d->amplitude[1])
        return fail_at(c, &ap, "expected [c0, c1] with 0 <= c0 <= c1, got [%g, %g]",
                       d->amplitude[0], d->amplitude[1]);
    return VEIL_OK;
}

static veil_result parse_sources(const ctx* c, const cJSON* medium, const jpath* mp, veil_medium* m)
{
    const jpath p = {mp, "sources", 0};
    const cJSON* arr, *e;
    size_t i = 0;
    TRY(get_container(c, medium, &p, true, true, &arr));
    void* items = NULL;
    TRY(alloc_items(c, &p, arr, sizeof *m->sources, SIZE_MAX, &items, &m->source_count));
    m->sources = items;
    cJSON_ArrayForEach(e, arr) {
        const jpath ep = {&p, NULL, i};
        veil_source* src = &m->sources[i++];
        int kind;
        if (!cJSON_IsObject(e)) return expected(c, &ep, "an object", e);
        TRY(get_kind(c, e, &ep, SOURCE_TYPES, &kind));
        src->type = (veil_source_type)kind;
        TRY(check_keys(c, e, &ep, kind == VEIL_SOURCE_RBF ? RBF_KEYS : RANDOM_KEYS));
        TRY(kind == VEIL_SOURCE_RBF ? parse_particles(c, e, &ep, src)
                                    : parse_random(c, e, &ep, &src->random));
    }
    return VEIL_OK;
}

static veil_result parse_medium(const ctx* c, const cJSON* root, veil_medium* m)
{
    const jpath p = {NULL, "medium", 0};
    const cJSON* o;
    TRY(get_container(c, root, &p, true, false, &o));
    TRY(check_keys(c, o, &p, MEDIUM_KEYS));
    TRY(get_floats(c, o, &p, "sigma_a", false, 3, true, m->sigma_a));
    TRY(get_floats(c, o, &p, "sigma_s", true, 3, true, m->sigma_s));
    TRY(parse_phase(c, o, &p, &m->phase));
    TRY(get_int(c, o, &p, "max_resolution", &R_RES, &m->max_resolution));
    return parse_sources(c, o, &p, m);
}

static veil_result parse_direction(const ctx* c, const cJSON* lo, const jpath* lp, float dir[3])
{
    const jpath p = {lp, "direction", 0};
    TRY(get_floats(c, lo, lp, "direction", true, 3, false, dir));
    double len = sqrt((double)dir[0] * dir[0] + (double)dir[1] * dir[1] + (double)dir[2] * dir[2]);
    if (!(len > 0))
        return fail_at(c, &p, "expected a non-zero vector (the direction light travels), got [%g, %g, %g]",
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
    TRY(get_number(c, lo, lp, "outer_angle_deg", true, &R_OUTER, &outer));
    snprintf(what, sizeof what, "a number of degrees in [0, outer_angle_deg) = [0, %g)", outer);
    const range r = {0, outer, false, true, false, what};
    TRY(get_number(c, lo, lp, "inner_angle_deg", false, &r, &inner));
    l->inner_angle_deg = (float)inner, l->outer_angle_deg = (float)outer;
    return VEIL_OK;
}

static veil_result parse_lights(const ctx* c, const cJSON* root, veil_scene* s)
{
    const jpath p = {NULL, "lights", 0};
    const cJSON* arr, *e;
    size_t i = 0;
    TRY(get_container(c, root, &p, false, true, &arr));
    void* items = NULL;
    TRY(alloc_items(c, &p, arr, sizeof *s->lights, VEIL_MAX_LIGHTS, &items, &s->light_count));
    s->lights = items;
    cJSON_ArrayForEach(e, arr) {
        const jpath ep = {&p, NULL, i};
        veil_light* l = &s->lights[i++];
        int kind;
        if (!cJSON_IsObject(e)) return expected(c, &ep, "an object", e);
        TRY(get_kind(c, e, &ep, LIGHT_TYPES, &kind));
        l->type = (veil_light_type)kind;
        TRY(check_keys(c, e, &ep, LIGHT_KEYS[kind]));
        if (kind != VEIL_LIGHT_DIRECTIONAL) TRY(get_floats(c, e, &ep, "position", true, 3, false, l->position));
        if (kind != VEIL_LIGHT_POINT) TRY(parse_direction(c, e, &ep, l->direction));
        const char* power = kind == VEIL_LIGHT_DIRECTIONAL ? "irradiance" : "intensity";
        TRY(get_floats(c, e, &ep, power, true, 3, true, l->color));
        if (kind == VEIL_LIGHT_SPOT) TRY(parse_cone(c, e, &ep, l));
    }
    return VEIL_OK;
}

static veil_result parse_background(const ctx* c, const cJSON* root, float color[3])
{
    const jpath p = {NULL, "background", 0};
    const cJSON* o;
    TRY(get_container(c, root, &p, false, false, &o));
    if (!o) return VEIL_OK;
    TRY(check_keys(c, o, &p, BACKGROUND_KEYS));
    return get_floats(c, o, &p, "color", false, 3, true, color);
}

static veil_result parse_root(const ctx* c, const cJSON* root, veil_scene* s)
{
    if (!cJSON_IsObject(root)) {
        char buf[128];
        return fail_at(c, NULL, "expected a JSON object at the top level, got %s",
                       describe(root, buf, sizeof buf));
    }
    TRY(check_keys(c, root, NULL, ROOT_KEYS));
    TRY(parse_camera(c, root, &s->camera));
    TRY(parse_medium(c, root, &s->medium));
    TRY(parse_lights(c, root, s));
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
    excerpt(near, json + start, len - start, 24);
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
    if (!slash) s->base_dir = dup_range(".", 1);
    else s->base_dir = dup_range(c->name, slash == c->name ? 1 : (size_t)(slash - c->name));
    if (!s->path || !s->base_dir) return veil_fail(c->err, VEIL_ERR_OOM, "%s: out of memory", c->name);
    return VEIL_OK;
}

veil_result veil_scene_parse(const char* name, const char* json, size_t len,
                             veil_scene* out, veil_error* err)
{
    if (!out || (!json && len)) return veil_fail(err, VEIL_ERR_INVALID, "veil_scene_parse: NULL argument");
    memset(out, 0, sizeof *out);
    const ctx c = {name ? name : "<scene>", err};
    if (!json) json = "";
    cJSON* root;
    TRY(parse_json(&c, json, len, &root));
    veil_scene s = {0};
    s.camera = (veil_camera){.up = {0, 1, 0}, .fov_y_deg = VEIL_SCENE_DEFAULT_FOV_Y,
                             .width = VEIL_SCENE_DEFAULT_WIDTH, .height = VEIL_SCENE_DEFAULT_HEIGHT};
    s.medium.max_resolution = VEIL_SCENE_DEFAULT_MAX_RES;
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

/* Reads all of f into a NUL-terminated buffer, at most SCENE_MAX_FILE_BYTES. */
static veil_result read_all(const char* path, FILE* f, char** buf, size_t* len, veil_error* err)
{
    size_t cap = (size_t)1 << 16, n = 0;
    char* b = NULL;
    veil_result r = VEIL_OK;
    for (;;) {
        char* nb = realloc(b, cap + 1);
        if (!nb) {
            r = veil_fail(err, VEIL_ERR_OOM, "%s: out of memory reading %zu bytes", path, cap);
            break;
        }
        b = nb;
        n += fread(b + n, 1, cap - n, f);
        if (n < cap) break; /* end of file or error */
        if (n > SCENE_MAX_FILE_BYTES) {
            r = veil_fail(err, VEIL_ERR_LIMIT, "%s: file is larger than %zu MiB, the limit for scene files",
                          path, SCENE_MAX_FILE_BYTES >> 20);
            break;
        }
        cap = cap > SCENE_MAX_FILE_BYTES / 2 ? SCENE_MAX_FILE_BYTES + 1 : 2 * cap;
    }
    if (r == VEIL_OK && ferror(f)) r = veil_fail(err, VEIL_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    if (r != VEIL_OK) {
        free(b);
        return r;
    }
    b[n] = '\0';
    *buf = b, *len = n;
    return VEIL_OK;
}

veil_result veil_scene_load(const char* path, veil_scene* out, veil_error* err)
{
    if (!out || !path) return veil_fail(err, VEIL_ERR_INVALID, "veil_scene_load: NULL argument");
    memset(out, 0, sizeof *out);
    errno = 0;
    FILE* f = fopen(path, "rb");
    if (!f) return veil_fail(err, VEIL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    char* buf = NULL;
    size_t len = 0;
    veil_result r = read_all(path, f, &buf, &len, err);
    fclose(f);
    if (r != VEIL_OK) return r;
    r = veil_scene_parse(path, buf, len, out, err);
    free(buf);
    return r;
}

void veil_scene_free(veil_scene* s)
{
    if (!s) return;
    for (size_t i = 0; i < s->medium.source_count; ++i) free(s->medium.sources[i].particles);
    free(s->medium.sources);
    free(s->lights);
    free(s->path);
    free(s->base_dir);
    memset(s, 0, sizeof *s);
}

static size_t source_particles(const veil_source* src)
{
    return src->type == VEIL_SOURCE_RBF ? src->particle_count : src->random.count;
}

veil_result veil_scene_particles(const veil_scene* s, veil_particle** out,
                                 size_t* count, veil_error* err)
{
    if (!s || !out || !count) return veil_fail(err, VEIL_ERR_INVALID, "veil_scene_particles: NULL argument");
    *out = NULL, *count = 0;
    const char* name = s->path ? s->path : "<scene>";
    size_t total = 0, bytes, k = 0;
    for (size_t i = 0; i < s->medium.source_count; ++i) {
        size_t n = source_particles(&s->medium.sources[i]);
        if (n > VEIL_SCENE_MAX_PARTICLES - total)
            return veil_fail(err, VEIL_ERR_LIMIT, "%s: medium.sources[%zu]: the sources hold more than %u "
                             "particles in total", name, i, VEIL_SCENE_MAX_PARTICLES);
        total += n;
    }
    /* at least one element, so that *out is never NULL on success */
    if (!veil_mul_sizes(total ? total : 1, sizeof(veil_particle), 1, 1, &bytes))
        return veil_fail(err, VEIL_ERR_LIMIT, "%s: %zu particles do not fit in memory", name, total);
    veil_particle* p = malloc(bytes);
    if (!p)
        return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory allocating %zu particles (%zu bytes)",
                         name, total, bytes);
    for (size_t i = 0; i < s->medium.source_count; ++i) {
        const veil_source* src = &s->medium.sources[i];
        size_t n = source_particles(src);
        if (n && src->type == VEIL_SOURCE_RBF) memcpy(p + k, src->particles, n * sizeof *p);
        else if (n) veil_rbf_random_generate(&src->random, p + k);
        k += n;
    }
    *out = p, *count = total;
    return VEIL_OK;
}
