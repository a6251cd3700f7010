/* veil — the medium's density sources in a scene file (see
 * docs/scene-format.md): explicit RBF particles, seeded random particle
 * clouds. Private to io/. */
#include "scene_sources.h"

#include <math.h>
#include <stdlib.h>

static const char* const SOURCE_TYPES[] = {"rbf", "rbf_random", NULL}; /* = veil_source_type */
static const char* const RBF_KEYS[] = {"type", "particles", NULL};
static const char* const RANDOM_KEYS[] = {"type", "count", "seed", "bounds", "radius", "amplitude", NULL};
static const char* const PARTICLE_KEYS[] = {"center", "amplitude", "sharpness", NULL};

static veil_result parse_particles(const ctx* c, const cJSON* so, const jpath* sp, veil_source* src)
{
    const jpath p = {sp, "particles", 0};
    const cJSON* arr, *e;
    size_t i = 0;
    TRY(veil__jr_get_container(c, so, &p, true, true, &arr));
    void* items = NULL;
    TRY(veil__jr_alloc_items(c, &p, arr, sizeof *src->particles, VEIL_SCENE_MAX_PARTICLES, &items, &src->particle_count));
    src->particles = items;
    cJSON_ArrayForEach(e, arr) {
        const jpath ep = {&p, NULL, i};
        veil_particle* q = &src->particles[i++];
        double amp, sharp;
        if (!cJSON_IsObject(e)) return veil__jr_expected(c, &ep, "an object", e);
        TRY(veil__jr_check_keys(c, e, &ep, PARTICLE_KEYS));
        TRY(veil__jr_get_floats(c, e, &ep, "center", true, 3, false, q->center));
        TRY(veil__jr_get_number(c, e, &ep, "amplitude", true, &VEIL__R_NONNEG, &amp));
        TRY(veil__jr_get_number(c, e, &ep, "sharpness", true, &VEIL__R_POS, &sharp));
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
    TRY(veil__jr_lookup(c, so, &p, true, what, &v));
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 2) return veil__jr_expected(c, &p, what, v);
    TRY(veil__jr_parse_floats(c, cJSON_GetArrayItem(v, 0), &ep[0], 3, false, b[0]));
    TRY(veil__jr_parse_floats(c, cJSON_GetArrayItem(v, 1), &ep[1], 3, false, b[1]));
    for (int i = 0; i < 3; ++i)
        if (b[0][i] > b[1][i])
            return veil__jr_fail_at(c, &p, "expected min <= max on every axis, got %c: %g > %g",
                           "xyz"[i], b[0][i], b[1][i]);
    return VEIL_OK;
}

static veil_result parse_random(const ctx* c, const cJSON* so, const jpath* sp, veil_rbf_random_desc* d)
{
    const jpath rp = {sp, "radius", 0}, ap = {sp, "amplitude", 0};
    double count, seed;
    TRY(veil__jr_get_number(c, so, sp, "count", true, &VEIL__R_COUNT, &count));
    TRY(veil__jr_get_number(c, so, sp, "seed", true, &VEIL__R_SEED, &seed));
    d->count = (uint32_t)count, d->seed = (uint64_t)seed;
    TRY(parse_bounds(c, so, sp, d->bounds));
    TRY(veil__jr_get_floats(c, so, sp, "radius", true, 2, true, d->radius));
    if (!(d->radius[0] > 0 && d->radius[0] <= d->radius[1] && isfinite(1.0f / d->radius[0])))
        return veil__jr_fail_at(c, &rp, "expected [r0, r1] with 0 < r0 <= r1 (metres), got [%g, %g]",
                       d->radius[0], d->radius[1]);
    TRY(veil__jr_get_floats(c, so, sp, "amplitude", true, 2, true, d->amplitude));
    if (d->amplitude[0] > d->amplitude[1])
        return veil__jr_fail_at(c, &ap, "expected [c0, c1] with 0 <= c0 <= c1, got [%g, %g]",
                       d->amplitude[0], d->amplitude[1]);
    return VEIL_OK;
}

veil_result veil__parse_sources(const ctx* c, const cJSON* medium, const jpath* mp, veil_medium* m)
{
    const jpath p = {mp, "sources", 0};
    const cJSON* arr, *e;
    size_t i = 0;
    TRY(veil__jr_get_container(c, medium, &p, true, true, &arr));
    void* items = NULL;
    TRY(veil__jr_alloc_items(c, &p, arr, sizeof *m->sources, SIZE_MAX, &items, &m->source_count));
    m->sources = items;
    cJSON_ArrayForEach(e, arr) {
        const jpath ep = {&p, NULL, i};
        veil_source* src = &m->sources[i++];
        int kind;
        if (!cJSON_IsObject(e)) return veil__jr_expected(c, &ep, "an object", e);
        TRY(veil__jr_get_kind(c, e, &ep, SOURCE_TYPES, &kind));
        src->type = (veil_source_type)kind;
        TRY(veil__jr_check_keys(c, e, &ep, kind == VEIL_SOURCE_RBF ? RBF_KEYS : RANDOM_KEYS));
        TRY(kind == VEIL_SOURCE_RBF ? parse_particles(c, e, &ep, src)
                                    : parse_random(c, e, &ep, &src->random));
    }
    return VEIL_OK;
}

