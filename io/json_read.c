#include "json_read.h"

#include <errno.h>

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene.h"
#include "../scene/limits.h"

const range VEIL__R_ANY = {-DBL_MAX, DBL_MAX, false, false, false, "a number"};
const range VEIL__R_COORD = {-VEIL_MAX_COORD, VEIL_MAX_COORD, false, false, false,
                             "a number in [-1e15, 1e15] (m: scene/limits.h)"};
const range VEIL__R_LIGHT = {0, VEIL_MAX_LIGHT, false, false, false, "a number in [0, 1e20] (scene/limits.h)"};
const range VEIL__R_SHARPNESS = {VEIL_MIN_SHARPNESS, DBL_MAX, false, false, false,
                                 "a number >= 1e-29 (its cut-off radius within 1e15 m: scene/limits.h)"};
const range VEIL__R_SIGMA = {0, VEIL_MAX_SIGMA, false, false, false, "a number in [0, 1e10] (m^-1: scene/limits.h)"};
const range VEIL__R_DENSITY = {0, VEIL_MAX_DENSITY, false, false, false, "a number in [0, 1e10] (scene/limits.h)"};
const range VEIL__R_FALLOFF = {0, VEIL_MAX_FALLOFF, false, false, false, "a number in [0, 1e20] (m^-1: scene/limits.h)"};
const range VEIL__R_EMISSION = {0, VEIL_MAX_EMISSION, false, false, false, "a number in [0, 1e21] (scene/limits.h)"};
const range VEIL__R_KELVIN = {-VEIL_MAX_KELVIN, VEIL_MAX_KELVIN, false, false, false,
                              "a number in [-1e5, 1e5] (K: scene/limits.h)"};
const range VEIL__R_BACKGROUND = {0, VEIL_MAX_BACKGROUND, false, false, false, "a number in [0, 1e20] (scene/limits.h)"};
const range VEIL__R_NONNEG = {0, DBL_MAX, false, false, false, "a number >= 0"};
const range VEIL__R_POS = {0, DBL_MAX, true, false, false, "a number > 0"};
const range VEIL__R_FOV = {0, 180, true, true, false, "a number of degrees in (0, 180)"};
const range VEIL__R_OUTER = {0, 180, true, false, false, "a number of degrees in (0, 180]"};
const range VEIL__R_G = {-1, 1, true, true, false, "a number in (-1, 1)"};
const range VEIL__R_SIZE = {1, VEIL_SCENE_MAX_IMAGE, false, false, true, "an integer in [1, 16384]"};
const range VEIL__R_RES = {2, VEIL_SCENE_MAX_RESOLUTION, false, false, true, "an integer in [2, 2048]"};
const range VEIL__R_COUNT = {0, 1e7, false, false, true, "an integer in [0, 10000000]"};
const range VEIL__R_SEED = {0, 9007199254740992.0, false, true, true, "an integer in [0, 2^53)"};

/* ---- messages ---------------------------------------------------------- */

size_t veil__jr_path_format(const jpath* p, char* buf, size_t n)
{
    size_t len = p->up ? veil__jr_path_format(p->up, buf, n) : 0;
    if (len >= n) return len;
    int w = p->key ? snprintf(buf + len, n - len, "%s%s", len ? "." : "", p->key)
                   : snprintf(buf + len, n - len, "[%zu]", p->index);
    return w < 0 ? len : len + (size_t)w;
}

/* Copies at most max bytes of src (stopping at a newline or NUL, never
 * splitting a UTF-8 sequence), control characters replaced by '?'. */
void veil__jr_excerpt(char* dst, const char* src, size_t len, size_t max)
{
    size_t n = 0;
    while (n < len && n < max && src[n] != '\n' && src[n] != '\r' && src[n] != '\0') ++n;
    if (n < len && n == max)
        while (n > 0 && ((unsigned char)src[n] & 0xC0) == 0x80) --n;
    for (size_t i = 0; i < n; ++i) dst[i] = (unsigned char)src[i] < 0x20 ? '?' : src[i];
    dst[n] = '\0';
}

/* "a string (\"abc\")", "an array of 2 elements", "-3", ... */
const char* veil__jr_describe(const cJSON* v, char* buf, size_t n)
{
    if (cJSON_IsNull(v)) return "null";
    if (cJSON_IsBool(v)) return cJSON_IsTrue(v) ? "true" : "false";
    if (cJSON_IsObject(v)) return "an object";
    if (cJSON_IsNumber(v)) {
        snprintf(buf, n, "%.9g", v->valuedouble);
    } else if (cJSON_IsString(v)) {
        char text[48];
        size_t len = strlen(v->valuestring);
        veil__jr_excerpt(text, v->valuestring, len, 40);
        snprintf(buf, n, "a string (\"%s%s\")", text, strlen(text) < len ? "..." : "");
    } else if (cJSON_IsArray(v)) {
        int k = cJSON_GetArraySize(v);
        snprintf(buf, n, "an array of %d element%s", k, k == 1 ? "" : "s");
    } else {
        return "an unknown value";
    }
    return buf;
}

/* "<file>: <path>: <message>", VEIL_ERR_INVALID. */
veil_result veil__jr_fail_at(const ctx* c, const jpath* p, const char* fmt, ...)
{
    char where[512] = "", what[1024];
    if (p) veil__jr_path_format(p, where, sizeof where);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (!p) return veil_fail(c->err, VEIL_ERR_INVALID, "%s: %s", c->name, what);
    return veil_fail(c->err, VEIL_ERR_INVALID, "%s: %s: %s", c->name, where, what);
}

veil_result veil__jr_expected(const ctx* c, const jpath* p, const char* what, const cJSON* got)
{
    char buf[128];
    return veil__jr_fail_at(c, p, "expected %s, got %s", what, veil__jr_describe(got, buf, sizeof buf));
}

void veil__jr_join(const char* const* names, bool quote, char* buf, size_t n)
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
veil_result veil__jr_check_keys(const ctx* c, const cJSON* obj, const jpath* p, const char* const* allowed)
{
    const cJSON* kv;
    cJSON_ArrayForEach(kv, obj) {
        const jpath kp = {p, kv->string, 0};
        bool known = false;
        for (size_t i = 0; allowed[i] && !known; ++i) known = strcmp(kv->string, allowed[i]) == 0;
        if (!known) {
            char list[256];
            veil__jr_join(allowed, false, list, sizeof list);
            return veil__jr_fail_at(c, &kp, "unknown key (expected one of: %s)", list);
        }
        for (const cJSON* o = kv->next; o; o = o->next)
            if (strcmp(o->string, kv->string) == 0) return veil__jr_fail_at(c, &kp, "duplicate key");
    }
    return VEIL_OK;
}

/* *v = obj[p->key], NULL when absent; absent and required is an error. */
veil_result veil__jr_lookup(const ctx* c, const cJSON* obj, const jpath* p, bool required,
                          const char* what, const cJSON** v)
{
    *v = cJSON_GetObjectItemCaseSensitive(obj, p->key);
    if (!*v && required) return veil__jr_fail_at(c, p, "missing required field (%s)", what);
    return VEIL_OK;
}

/* An object or array field; *v stays NULL when optional and absent. */
veil_result veil__jr_get_container(const ctx* c, const cJSON* obj, const jpath* p, bool required,
                                 bool array, const cJSON** v)
{
    const char* what = array ? "an array" : "an object";
    TRY(veil__jr_lookup(c, obj, p, required, what, v));
    if (*v && !(array ? cJSON_IsArray(*v) : cJSON_IsObject(*v))) return veil__jr_expected(c, p, what, *v);
    return VEIL_OK;
}

veil_result veil__jr_parse_number(const ctx* c, const cJSON* v, const jpath* p, const range* r, double* out)
{
    char buf[64];
    if (!cJSON_IsNumber(v)) return veil__jr_expected(c, p, r->what, v);
    double x = v->valuedouble;
    if (!isfinite(x) || (!r->integer && fabs(x) > FLT_MAX))
        return veil__jr_fail_at(c, p, "expected %s, got %s (numbers must be finite and fit in single precision)",
                       r->what, veil__jr_describe(v, buf, sizeof buf));
    /* what will be stored, against the bounds as floats hold them (1e21 is 1.00000002e21 in a float:
     * the bound itself is accepted) */
    double lo = r->lo, hi = r->hi;
    if (!r->integer) x = (double)(float)x, lo = (double)(float)fmax(lo, -FLT_MAX), hi = (double)(float)fmin(hi, FLT_MAX);
    bool ok = (r->lo_open ? x > lo : x >= lo) && (r->hi_open ? x < hi : x <= hi);
    if (ok && (!r->integer || x == floor(x))) {
        *out = x;
        return VEIL_OK;
    }
    bool positive = r->lo > 0 || (r->lo == 0 && r->lo_open);
    /* above the range: say so and give the bound (a number > 0 of 3e38 is not "negative or zero") */
    bool above = r->hi_open ? x >= hi : x > hi;
    if (above && r->hi < DBL_MAX) {
        char bound[32];
        snprintf(bound, sizeof bound, "%.3g", r->hi);
        return veil__jr_fail_at(c, p, "expected %s, got %s (too large: %s %s)", r->what,
                                veil__jr_describe(v, buf, sizeof buf), r->hi_open ? "below" : "at most", bound);
    }
    return veil__jr_fail_at(c, p, "expected %s, got %s%s", r->what, veil__jr_describe(v, buf, sizeof buf),
                   positive && x <= 0 ? " (negative and zero values are not allowed)" : "");
}

/* obj[key] as a number; *out keeps its default when optional and absent. */
veil_result veil__jr_get_number(const ctx* c, const cJSON* obj, const jpath* pp, const char* key,
                              bool required, const range* r, double* out)
{
    const jpath p = {pp, key, 0};
    const cJSON* v;
    TRY(veil__jr_lookup(c, obj, &p, required, r->what, &v));
    return v ? veil__jr_parse_number(c, v, &p, r, out) : VEIL_OK;
}

veil_result veil__jr_get_int(const ctx* c, const cJSON* obj, const jpath* pp, const char* key,
                           const range* r, int* out)
{
    double x = *out;
    TRY(veil__jr_get_number(c, obj, pp, key, false, r, &x));
    *out = (int)x;
    return VEIL_OK;
}

/* An array of exactly n numbers (>= 0 when nonneg). */
veil_result veil__jr_parse_floats(const ctx* c, const cJSON* v, const jpath* p, int n, bool nonneg, float* out)
{
    return veil__jr_parse_floats_in(c, v, p, n, nonneg ? &VEIL__R_NONNEG : &VEIL__R_ANY, out);
}

/* "an array of 3 numbers >= 0", "... numbers, each in [0, 1e20] (...)". */
static void float_array_what(int n, const range* r, char* what, size_t len)
{
    if (r == &VEIL__R_ANY || r == &VEIL__R_NONNEG)
        snprintf(what, len, "an array of %d numbers%s", n, r == &VEIL__R_NONNEG ? " >= 0" : "");
    else
        snprintf(what, len, "an array of %d numbers, each %s", n, r->what + (strncmp(r->what, "a number ", 9) ? 0 : 9));
}

veil_result veil__jr_parse_floats_in(const ctx* c, const cJSON* v, const jpath* p, int n, const range* r, float* out)
{
    char what[160];
    float_array_what(n, r, what, sizeof what);
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != n) return veil__jr_expected(c, p, what, v);
    size_t i = 0;
    const cJSON* e;
    cJSON_ArrayForEach(e, v) {
        const jpath ep = {p, NULL, i};
        double x;
        TRY(veil__jr_parse_number(c, e, &ep, r, &x));
        out[i++] = (float)x;
    }
    return VEIL_OK;
}

veil_result veil__jr_get_floats_in(const ctx* c, const cJSON* obj, const jpath* pp, const char* key, bool required,
                                   int n, const range* r, float* out)
{
    const jpath p = {pp, key, 0};
    const cJSON* v;
    char what[160];
    float_array_what(n, r, what, sizeof what);
    TRY(veil__jr_lookup(c, obj, &p, required, what, &v));
    return v ? veil__jr_parse_floats_in(c, v, &p, n, r, out) : VEIL_OK;
}

veil_result veil__jr_get_floats(const ctx* c, const cJSON* obj, const jpath* pp, const char* key,
                              bool required, int n, bool nonneg, float* out)
{
    char what[64];
    snprintf(what, sizeof what, "an array of %d numbers%s", n, nonneg ? " >= 0" : "");
    const jpath p = {pp, key, 0};
    const cJSON* v;
    TRY(veil__jr_lookup(c, obj, &p, required, what, &v));
    return v ? veil__jr_parse_floats(c, v, &p, n, nonneg, out) : VEIL_OK;
}

/* obj.type, one of names; *kind is its index. */
veil_result veil__jr_get_kind(const ctx* c, const cJSON* obj, const jpath* pp, const char* const* names, int* kind)
{
    char what[160] = "one of ";
    veil__jr_join(names, true, what + 7, sizeof what - 7);
    const jpath p = {pp, "type", 0};
    const cJSON* v;
    TRY(veil__jr_lookup(c, obj, &p, true, what, &v));
    for (int i = 0; cJSON_IsString(v) && names[i]; ++i) {
        if (strcmp(v->valuestring, names[i]) == 0) {
            *kind = i;
            return VEIL_OK;
        }
    }
    return veil__jr_expected(c, &p, what, v);
}

/* An array field's elements: calloc'd, count stored before filling, so a
 * partial result is freed by veil_scene_free(). */
veil_result veil__jr_alloc_items(const ctx* c, const jpath* p, const cJSON* arr, size_t size,
                               size_t limit, void** items, size_t* count)
{
    size_t n = arr ? (size_t)cJSON_GetArraySize(arr) : 0;
    if (n > limit) return veil__jr_fail_at(c, p, "too many elements (%zu, at most %zu)", n, limit);
    if (n == 0) return VEIL_OK;
    *items = calloc(n, size);
    if (!*items) return veil_fail(c->err, VEIL_ERR_OOM, "%s: out of memory reading %zu elements", c->name, n);
    *count = n;
    return VEIL_OK;
}

/* ---- the scene --------------------------------------------------------- */


veil_result veil__read_file(const char* path, size_t limit, const char* kind, char** buf, size_t* len,
                            veil_error* err)
{
    errno = 0;
    FILE* f = fopen(path, "rb");
    if (!f) return veil_fail(err, VEIL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
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
        if (n > limit) {
            r = veil_fail(err, VEIL_ERR_LIMIT, "%s: file is larger than %zu MiB, the limit for %s files", path,
                          limit >> 20, kind);
            break;
        }
        cap = cap > limit / 2 ? limit + 1 : 2 * cap;
    }
    if (r == VEIL_OK && ferror(f)) r = veil_fail(err, VEIL_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    fclose(f);
    if (r != VEIL_OK) {
        free(b);
        return r;
    }
    b[n] = '\0';
    *buf = b, *len = n;
    return VEIL_OK;
}

veil_result veil__jr_get_name(const ctx* c, const cJSON* o, const jpath* pp, const char* key,
                               const char* const* names, int* out)
{
    const jpath p = {pp, key, 0};
    char what[160] = "one of ";
    veil__jr_join(names, true, what + 7, sizeof what - 7);
    const cJSON* v;
    TRY(veil__jr_lookup(c, o, &p, false, what, &v));
    if (!v) return VEIL_OK;
    for (int i = 0; cJSON_IsString(v) && names[i]; ++i) {
        if (strcmp(v->valuestring, names[i]) == 0) {
            *out = i;
            return VEIL_OK;
        }
    }
    return veil__jr_expected(c, &p, what, v);
}
