/* veil — reading JSON values with their path (private to io/).
 *
 * Every value is read through these helpers, which know the JSON path of
 * what they read (a linked list of path components on the stack, printed
 * only when something is wrong), so each message names the file, the field
 * (`lights[1].intensity`) and what was expected and found.
 */
#ifndef VEIL_JSON_READ_H
#define VEIL_JSON_READ_H

#include <cJSON.h>
#include <stdbool.h>
#include <stddef.h>

#include "../core/result.h"

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
    const char* base; /* the folder relative paths resolve against; NULL: the name's */
} ctx;

/* Accepted numbers: [lo, hi] (or open ends), optionally integral. */
typedef struct range {
    double lo, hi;
    bool lo_open, hi_open, integer;
    const char* what; /* the expectation, as printed */
} range;


/* The accepted ranges, shared by the scene readers. */
extern const range VEIL__R_ANY;
extern const range VEIL__R_COORD;     /* positions: scene/limits.h */
extern const range VEIL__R_LIGHT;     /* intensities, irradiances: scene/limits.h */
extern const range VEIL__R_SHARPNESS; /* particle sharpness: scene/limits.h */
extern const range VEIL__R_SIGMA;      /* sigma_a, sigma_s, temperature.intensity: scene/limits.h */
extern const range VEIL__R_DENSITY;    /* density_scale, amplitudes, fog density: scene/limits.h */
extern const range VEIL__R_FALLOFF;    /* fog falloff: scene/limits.h */
extern const range VEIL__R_EMISSION;   /* emission.scale and color: scene/limits.h */
extern const range VEIL__R_KELVIN;     /* temperature.scale and offset: scene/limits.h */
extern const range VEIL__R_BACKGROUND; /* background.color: scene/limits.h */
extern const range VEIL__R_NONNEG;
extern const range VEIL__R_POS;
extern const range VEIL__R_FOV;
extern const range VEIL__R_OUTER;
extern const range VEIL__R_G;
extern const range VEIL__R_SIZE;
extern const range VEIL__R_RES;
extern const range VEIL__R_COUNT;
extern const range VEIL__R_SEED;

#if defined(__GNUC__)
#define VEIL__JR_PRINTF __attribute__((format(printf, 3, 4)))
#else
#define VEIL__JR_PRINTF
#endif

size_t veil__jr_path_format(const jpath* p, char* buf, size_t n);
void veil__jr_excerpt(char* dst, const char* src, size_t len, size_t max);
const char* veil__jr_describe(const cJSON* v, char* buf, size_t n);
VEIL__JR_PRINTF veil_result veil__jr_fail_at(const ctx* c, const jpath* p, const char* fmt, ...);
veil_result veil__jr_expected(const ctx* c, const jpath* p, const char* what, const cJSON* got);
void veil__jr_join(const char* const* names, bool quote, char* buf, size_t n);
veil_result veil__jr_check_keys(const ctx* c, const cJSON* obj, const jpath* p, const char* const* allowed);
veil_result veil__jr_lookup(const ctx* c, const cJSON* obj, const jpath* p, bool required, const char* what, const cJSON** v);
/* Optional string key whose value is one of `names` (NULL-terminated): *out
 * = its index; left as it is when absent. */
veil_result veil__jr_get_name(const ctx* c, const cJSON* o, const jpath* pp, const char* key,
                              const char* const* names, int* out);
veil_result veil__jr_get_container(const ctx* c, const cJSON* obj, const jpath* p, bool required, bool array, const cJSON** v);
veil_result veil__jr_parse_number(const ctx* c, const cJSON* v, const jpath* p, const range* r, double* out);
veil_result veil__jr_get_number(const ctx* c, const cJSON* obj, const jpath* pp, const char* key, bool required, const range* r, double* out);
veil_result veil__jr_get_int(const ctx* c, const cJSON* obj, const jpath* pp, const char* key, const range* r, int* out);
veil_result veil__jr_parse_floats(const ctx* c, const cJSON* v, const jpath* p, int n, bool nonneg, float* out);
veil_result veil__jr_get_floats(const ctx* c, const cJSON* obj, const jpath* pp, const char* key, bool required, int n, bool nonneg, float* out);
/* The same with every element in range r (positions: &VEIL__R_COORD). */
veil_result veil__jr_get_floats_in(const ctx* c, const cJSON* obj, const jpath* pp, const char* key, bool required,
                                   int n, const range* r, float* out);
veil_result veil__jr_parse_floats_in(const ctx* c, const cJSON* v, const jpath* p, int n, const range* r, float* out);
veil_result veil__jr_get_kind(const ctx* c, const cJSON* obj, const jpath* pp, const char* const* names, int* kind);
veil_result veil__jr_alloc_items(const ctx* c, const jpath* p, const cJSON* arr, size_t size, size_t limit, void** items, size_t* count);

/* The whole file `path`, NUL-terminated, into a malloc'd *buf (*len bytes
 * before the NUL); at most `limit` bytes, refused above with a message
 * naming the limit for `kind` files ("scene", "particle"). */
veil_result veil__read_file(const char* path, size_t limit, const char* kind, char** buf, size_t* len,
                            veil_error* err);

#endif
