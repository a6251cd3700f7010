/* veil — RBF particle files: JSON and the compact little-endian binary
 * format (docs/particles.md). */
#define _POSIX_C_SOURCE 200809L
#include "particles.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "json_read.h"
#include "particles_json.h"
#include "../scene/limits.h"
#include "scene.h"
#include "tempfile.h"

/* Particle files larger than this are refused before reading (the binary
 * format needs 200 MB for the particle limit; JSON ~110 bytes a particle). */
#define PARTICLES_MAX_FILE_BYTES ((size_t)2 << 30)

static const char* const FILE_KEYS[] = {"format", "version", "particles", NULL};
static const char* const PARTICLE_KEYS[] = {"center", "amplitude", "sharpness", NULL};
static const char* const FIELD_NAMES[5] = {"center[0]", "center[1]", "center[2]", "amplitude", "sharpness"};

/* ---- checks shared by reader and writer -------------------------------- */

/* Index of the first bad field of q (0..4), or -1; *why says what was expected. */
/* The field a particle breaks (scene/limits.h), or -1. */
static int bad_field(const veil_particle* q, const char** why)
{
    for (int k = 0; k < 3; ++k)
        if (!(fabsf(q->center[k]) <= (float)VEIL_MAX_COORD)) return *why = "a number in [-1e15, 1e15] (m: scene/limits.h)", k;
    if (!(q->amplitude >= 0.0f && q->amplitude <= (float)VEIL_MAX_DENSITY))
        return *why = "a number in [0, 1e10] (scene/limits.h)", 3;
    if (!(isfinite(q->sharpness) && q->sharpness >= (float)VEIL_MIN_SHARPNESS))
        return *why = "a finite number >= 1e-29 (scene/limits.h)", 4;
    return -1;
}

static float field(const veil_particle* q, int k) { return k < 3 ? q->center[k] : k == 3 ? q->amplitude : q->sharpness; }

/* ---- little-endian bytes ----------------------------------------------- */

static uint32_t get_u32(const unsigned char* b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static void put_u32(unsigned char* b, uint32_t v)
{
    b[0] = (unsigned char)v, b[1] = (unsigned char)(v >> 8), b[2] = (unsigned char)(v >> 16),
    b[3] = (unsigned char)(v >> 24);
}

static float get_f32(const unsigned char* b)
{
    uint32_t u = get_u32(b);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

static void put_f32(unsigned char* b, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    put_u32(b, u);
}

/* ---- reading ----------------------------------------------------------- */

static veil_result read_binary(const char* path, const unsigned char* b, size_t len, veil_particle** out,
                               size_t* count, veil_error* err)
{
    if (len < VEIL_PARTICLES_HEADER_BYTES)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: truncated header: %zu bytes, a binary particle file has at least %u",
                         path, len, VEIL_PARTICLES_HEADER_BYTES);
    uint32_t n = get_u32(b + 8), reserved = get_u32(b + 12);
    if (reserved != 0)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: header: reserved field is %u, expected 0", path, reserved);
    if (n > VEIL_SCENE_MAX_PARTICLES)
        return veil_fail(err, VEIL_ERR_LIMIT, "%s: header: %u particles, at most %u are supported", path, n,
                         VEIL_SCENE_MAX_PARTICLES);
    size_t want = VEIL_PARTICLES_HEADER_BYTES + (size_t)n * VEIL_PARTICLES_RECORD_BYTES;
    if (len < want)
        return veil_fail(err, VEIL_ERR_INVALID,
                         "%s: truncated: the header announces %u particles (%zu bytes), the file has %zu bytes",
                         path, n, want, len);
    if (len > want)
        return veil_fail(err, VEIL_ERR_INVALID,
                         "%s: %zu bytes of trailing data after the %u particles the header announces "
                         "(expected exactly %zu bytes)", path, len - want, n, want);
    veil_particle* p = NULL;
    if (n) {
        p = malloc((size_t)n * sizeof *p);
        if (!p) return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory for %u particles", path, n);
    }
    for (uint32_t i = 0; i < n; ++i) {
        const unsigned char* r = b + VEIL_PARTICLES_HEADER_BYTES + (size_t)i * VEIL_PARTICLES_RECORD_BYTES;
        veil_particle* q = &p[i];
        for (int k = 0; k < 3; ++k) q->center[k] = get_f32(r + 4 * k);
        q->amplitude = get_f32(r + 12);
        q->sharpness = get_f32(r + 16);
        const char* why;
        int k = bad_field(q, &why);
        if (k >= 0) {
            char got[32];
            veil_result res = veil_fail(err, VEIL_ERR_INVALID, "%s: particle %u: %s: expected %s, got %s", path, i,
                                        FIELD_NAMES[k], why, veil_number_text(field(q, k), got, sizeof got));
            free(p);
            return res;
        }
    }
    *out = p, *count = n;
    return VEIL_OK;
}

veil_result veil__parse_particle_array(const ctx* c, const cJSON* obj, const jpath* p, veil_particle** out,
                                      size_t* count)
{
    const cJSON* arr, *e;
    size_t i = 0;
    TRY(veil__jr_get_container(c, obj, p, true, true, &arr));
    void* items = NULL;
    TRY(veil__jr_alloc_items(c, p, arr, sizeof **out, VEIL_SCENE_MAX_PARTICLES, &items, count));
    *out = items;
    cJSON_ArrayForEach(e, arr) {
        const jpath ep = {p, NULL, i};
        veil_particle* q = &(*out)[i++];
        double amp, sharp;
        if (!cJSON_IsObject(e)) return veil__jr_expected(c, &ep, "an object", e);
        TRY(veil__jr_check_keys(c, e, &ep, PARTICLE_KEYS));
        TRY(veil__jr_get_floats_in(c, e, &ep, "center", true, 3, &VEIL__R_COORD, q->center));
        TRY(veil__jr_get_number(c, e, &ep, "amplitude", true, &VEIL__R_DENSITY, &amp));
        TRY(veil__jr_get_number(c, e, &ep, "sharpness", true, &VEIL__R_SHARPNESS, &sharp));
        q->amplitude = (float)amp, q->sharpness = (float)sharp;
    }
    return VEIL_OK;
}

static veil_result json_syntax(const char* path, const char* s, size_t len, size_t pos, veil_error* err)
{
    size_t line = 1, col = 1;
    for (size_t i = 0; i < pos && i < len; ++i) {
        if (s[i] == '\n') line++, col = 1;
        else if (((unsigned char)s[i] & 0xC0) != 0x80) col++;
    }
    return veil_fail(err, VEIL_ERR_PARSE, "%s:%zu:%zu: JSON syntax error", path, line, col);
}

static veil_result parse_json_particles(const ctx* c, const cJSON* root, veil_particle** out, size_t* count)
{
    const jpath fp = {NULL, "format", 0}, vp = {NULL, "version", 0}, pp = {NULL, "particles", 0};
    const cJSON* v;
    if (!cJSON_IsObject(root)) return veil__jr_fail_at(c, NULL, "expected a JSON object at the top level");
    TRY(veil__jr_check_keys(c, root, NULL, FILE_KEYS));
    TRY(veil__jr_lookup(c, root, &fp, true, "the string \"veil-particles\"", &v));
    if (!cJSON_IsString(v) || strcmp(v->valuestring, "veil-particles") != 0)
        return veil__jr_expected(c, &fp, "the string \"veil-particles\"", v);
    TRY(veil__jr_lookup(c, root, &vp, true, "the number 1", &v));
    if (!cJSON_IsNumber(v) || v->valuedouble != 1.0) return veil__jr_expected(c, &vp, "the number 1", v);
    return veil__parse_particle_array(c, root, &pp, out, count);
}

static veil_result read_json(const char* path, const char* s, size_t len, veil_particle** out, size_t* count,
                             veil_error* err)
{
    const char* end = NULL;
    cJSON* root = cJSON_ParseWithLengthOpts(s, len, &end, 0);
    size_t pos = end && end >= s && end <= s + len ? (size_t)(end - s) : 0;
    if (!root) return json_syntax(path, s, len, pos, err);
    while (pos < len && strchr(" \t\r\n", s[pos]) && s[pos]) ++pos;
    if (pos < len) {
        cJSON_Delete(root);
        return json_syntax(path, s, len, pos, err);
    }
    const ctx c = {path, err, NULL};
    veil_particle* p = NULL;
    size_t n = 0;
    veil_result r = parse_json_particles(&c, root, &p, &n);
    cJSON_Delete(root);
    if (r != VEIL_OK) {
        free(p);
        return r;
    }
    if (n == 0) free(p), p = NULL;
    *out = p, *count = n;
    return VEIL_OK;
}

veil_result veil_particles_read(const char* path, veil_particle** out, size_t* count, veil_error* err)
{
    if (!path || !out || !count) return veil_fail(err, VEIL_ERR_INVALID, "veil_particles_read: NULL argument");
    *out = NULL, *count = 0;
    char* text = NULL;
    size_t len = 0;
    TRY(veil__read_file(path, PARTICLES_MAX_FILE_BYTES, "particle", &text, &len, err));
    const unsigned char* b = (const unsigned char*)text;
    veil_result r;
    size_t first = 0;
    while (first < len && strchr(" \t\r\n", b[first]) && b[first]) ++first;
    if (len >= 8 && memcmp(b, VEIL_PARTICLES_MAGIC, 8) == 0)
        r = read_binary(path, b, len, out, count, err);
    else if (first < len && b[first] == '{')
        r = read_json(path, (const char*)b, len, out, count, err);
    else if (len == 0)
        r = veil_fail(err, VEIL_ERR_INVALID, "%s: empty file, not a particle file", path);
    else
        r = veil_fail(err, VEIL_ERR_INVALID,
                      "%s: not a particle file (expected the magic \"" VEIL_PARTICLES_MAGIC
                      "\" or a JSON object, see docs/particles.md)", path);
    free(text);
    return r;
}

/* ---- writing ----------------------------------------------------------- */

static veil_result encode_binary(const veil_particle* p, size_t n, char** buf, size_t* len)
{
    size_t total = VEIL_PARTICLES_HEADER_BYTES + n * VEIL_PARTICLES_RECORD_BYTES;
    unsigned char* b = malloc(total);
    if (!b) return VEIL_ERR_OOM;
    memcpy(b, VEIL_PARTICLES_MAGIC, 8);
    put_u32(b + 8, (uint32_t)n);
    put_u32(b + 12, 0);
    for (size_t i = 0; i < n; ++i) {
        unsigned char* r = b + VEIL_PARTICLES_HEADER_BYTES + i * VEIL_PARTICLES_RECORD_BYTES;
        for (int k = 0; k < 5; ++k) put_f32(r + 4 * k, field(&p[i], k));
    }
    *buf = (char*)b, *len = total;
    return VEIL_OK;
}

/* 9 significant digits identify a float; where the shortest such decimal
 * lies beyond FLT_MAX (readers refuse it) or does not read back as f, all
 * 17 digits of the double are written: the round trip is bit-exact. */
static void fmt_float(char* out, size_t n, float f)
{
    snprintf(out, n, "%.9g", (double)f);
    double d = strtod(out, NULL);
    if (!(fabs(d) <= FLT_MAX) || (float)d != f) snprintf(out, n, "%.17g", (double)f);
}

/* Each particle's line is written whole into `line` (at most 16 + 5 x 24
 * digits of fmt_float + 36 of text: 172 bytes), then appended, the buffer
 * growing when it must: no line is ever cut, none written past the end. */
static veil_result encode_json(const veil_particle* p, size_t n, char** buf, size_t* len)
{
    static const char head[] = "{\"format\": \"veil-particles\", \"version\": 1, \"particles\": [";
    enum { PER = 176 };
    size_t cap = sizeof head + 8 + n * PER;
    char* b = malloc(cap);
    if (!b) return VEIL_ERR_OOM;
    size_t k = sizeof head - 1;
    memcpy(b, head, k);
    for (size_t i = 0; i <= n; ++i) {
        char v[5][32], line[256];
        int m;
        if (i < n) {
            for (int f = 0; f < 5; ++f) fmt_float(v[f], sizeof v[f], field(&p[i], f));
            m = snprintf(line, sizeof line, "%s\n  {\"center\": [%s, %s, %s], \"amplitude\": %s, \"sharpness\": %s}",
                         i ? "," : "", v[0], v[1], v[2], v[3], v[4]);
        } else {
            m = snprintf(line, sizeof line, "%s]}\n", n ? "\n" : "");
        }
        if (m < 0 || (size_t)m >= sizeof line) {
            free(b);
            return VEIL_ERR_INVALID;
        }
        if (k + (size_t)m + 1 > cap) {
            size_t grown = 2 * cap + (size_t)m + 1;
            char* nb = realloc(b, grown);
            if (!nb) {
                free(b);
                return VEIL_ERR_OOM;
            }
            b = nb, cap = grown;
        }
        memcpy(b + k, line, (size_t)m + 1);
        k += (size_t)m;
    }
    *buf = b, *len = k;
    return VEIL_OK;
}

veil_result veil_particles_write(const char* path, const veil_particle* p, size_t n, int binary, veil_error* err)
{
    if (!path || (!p && n)) return veil_fail(err, VEIL_ERR_INVALID, "veil_particles_write: NULL argument");
    if (n > VEIL_SCENE_MAX_PARTICLES)
        return veil_fail(err, VEIL_ERR_LIMIT, "%s: %zu particles, at most %u are supported", path, n,
                         VEIL_SCENE_MAX_PARTICLES);
    for (size_t i = 0; i < n; ++i) {
        const char* why;
        int k = bad_field(&p[i], &why);
        if (k >= 0)
        {
            char got[32];
            return veil_fail(err, VEIL_ERR_INVALID, "%s: particle %zu: %s: expected %s, got %s", path, i,
                             FIELD_NAMES[k], why, veil_number_text(field(&p[i], k), got, sizeof got));
        }
    }
    char* buf = NULL;
    size_t len = 0;
    if ((binary ? encode_binary(p, n, &buf, &len) : encode_json(p, n, &buf, &len)) != VEIL_OK)
        return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory encoding %zu particles", path, n);
    char* tmp = NULL;
    int fd = veil_open_temp_beside(path, &tmp);
    if (fd < 0) {
        veil_result r = errno ? veil_fail(err, VEIL_ERR_IO, "%s: cannot create: %s", path, strerror(errno))
                              : veil_fail(err, VEIL_ERR_IO, "%s: exists and is not a regular file", path);
        free(buf);
        return r;
    }
    size_t done = 0;
    int e = 0;
    while (done < len) {
        ssize_t w = write(fd, buf + done, len - done);
        if (w < 0) {
            if (errno == EINTR) continue;
            e = errno;
            break;
        }
        done += (size_t)w;
    }
    free(buf);
    if (close(fd) != 0 && !e) e = errno;
    if (!e && rename(tmp, path) != 0) e = errno;
    if (e) {
        unlink(tmp);
        veil_temp_forget(tmp);
        free(tmp);
        return veil_fail(err, VEIL_ERR_IO, "%s: cannot write: %s", path, strerror(e));
    }
    veil_temp_forget(tmp);
    free(tmp);
    return VEIL_OK;
}
