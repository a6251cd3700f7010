/* veil — the medium's density sources in a scene file (see
 * docs/scene-format.md): explicit RBF particles, seeded random particle
 * clouds, OpenVDB grids and analytic exponential fog. Private to io/. */
#include "scene_sources.h"
#include "../scene/frame_pattern.h"
#include "particles.h"
#include "../scene/limits.h"
#include "particles_json.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char* const SOURCE_TYPES[] = {"rbf", "rbf_random", "vdb", "exponential", "array", NULL}; /* = veil_source_type */
static const char* const VDB_KEYS[] = {"type", "file", "grid", "density_scale", "level_set", "emission", "temperature",
                                       "frame_offset", "transform", "velocity", NULL};
static const char* const ARRAY_KEYS[] = {"type", "grid", "density_scale", "emission", "temperature", "transform", NULL};
static const char* const TEMPERATURE_KEYS[] = {"grid", "scale", "offset", "intensity", NULL};
static const char* const EMISSION_KEYS[] = {"grid", "scale", "color", NULL};
static const char* const VELOCITY_KEYS[] = {"grid", "unit", "scale", NULL};
static const char* const VELOCITY_UNITS[] = {"second", "frame", NULL}; /* = veil_velocity_unit */
static const char* const FOG_KEYS[] = {"type", "density", "falloff", "direction", "origin", "bounds", NULL};
static const char* const RBF_KEYS[] = {"type", "particles", "file", NULL};
static const char* const RANDOM_KEYS[] = {"type", "count", "seed", "bounds", "radius", "amplitude", NULL};

static veil_result parse_particles(const ctx* c, const cJSON* so, const jpath* sp, veil_source* src)
{
    const jpath p = {sp, "particles", 0};
    return veil__parse_particle_array(c, so, &p, &src->particles, &src->particle_count);
}

static veil_result parse_bounds(const ctx* c, const cJSON* so, const jpath* sp, float b[2][3])
{
    static const char what[] = "an array of 2 arrays of 3 numbers (min and max corner)";
    const jpath p = {sp, "bounds", 0};
    const jpath ep[2] = {{&p, NULL, 0}, {&p, NULL, 1}};
    const cJSON* v;
    TRY(veil__jr_lookup(c, so, &p, true, what, &v));
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 2) return veil__jr_expected(c, &p, what, v);
    TRY(veil__jr_parse_floats_in(c, cJSON_GetArrayItem(v, 0), &ep[0], 3, &VEIL__R_COORD, b[0]));
    TRY(veil__jr_parse_floats_in(c, cJSON_GetArrayItem(v, 1), &ep[1], 3, &VEIL__R_COORD, b[1]));
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
    static const range radius = {0, VEIL_MAX_COORD, false, false, false, "a number in [0, 1e15] (m: scene/limits.h)"};
    TRY(veil__jr_get_floats_in(c, so, sp, "radius", true, 2, &radius, d->radius));
    if (!(d->radius[0] > 0 && d->radius[0] <= d->radius[1] && isfinite(1.0f / d->radius[0])))
        return veil__jr_fail_at(c, &rp, "expected [r0, r1] with 0 < r0 <= r1 (metres), got [%g, %g]",
                       d->radius[0], d->radius[1]);
    TRY(veil__jr_get_floats_in(c, so, sp, "amplitude", true, 2, &VEIL__R_DENSITY, d->amplitude));
    if (d->amplitude[0] > d->amplitude[1])
        return veil__jr_fail_at(c, &ap, "expected [c0, c1] with 0 <= c0 <= c1, got [%g, %g]",
                       d->amplitude[0], d->amplitude[1]);
    return VEIL_OK;
}

/* A string field; *out is a newly allocated copy (NULL when absent and optional). */
veil_result veil__get_string(const ctx* c, const cJSON* o, const jpath* pp, const char* key, bool required,
                             char** out)
{
    const jpath p = {pp, key, 0};
    const cJSON* v;
    *out = NULL;
    TRY(veil__jr_lookup(c, o, &p, required, "a string", &v));
    if (!v) return VEIL_OK;
    if (!cJSON_IsString(v) || !v->valuestring[0]) return veil__jr_expected(c, &p, "a non-empty string", v);
    *out = malloc(strlen(v->valuestring) + 1);
    if (!*out) return veil_fail(c->err, VEIL_ERR_OOM, "%s: out of memory", c->name);
    strcpy(*out, v->valuestring);
    return VEIL_OK;
}

/* `file` resolved against the scene's folder (c->base, else the scene
 * file's), and checked readable (unless `unchecked`: a sequence's pattern,
 * whose frames are checked as they are needed). */
veil_result veil__resolve_path(const ctx* c, const jpath* fp, char** file, int unchecked)
{
    const char* slash = strrchr(c->name, '/');
    const char* base = c->base ? c->base : c->name;
    size_t dir = c->base ? strlen(c->base) : slash ? (size_t)(slash - c->name) + 1 : 0;
    if ((*file)[0] != '/' && dir > 0) {
        const int sep = base[dir - 1] != '/'; /* a base folder given without its trailing slash */
        size_t n = strlen(*file);
        char* joined = malloc(dir + (size_t)sep + n + 1);
        if (!joined) return veil_fail(c->err, VEIL_ERR_OOM, "%s: out of memory", c->name);
        memcpy(joined, base, dir);
        if (sep) joined[dir] = '/';
        memcpy(joined + dir + sep, *file, n + 1);
        free(*file);
        *file = joined;
    }
    if (unchecked) return VEIL_OK;
    FILE* f = fopen(*file, "rb");
    if (!f) return veil__jr_fail_at(c, fp, "cannot open '%s': %s", *file, strerror(errno));
    fclose(f);
    return VEIL_OK;
}

static veil_result resolve_file(const ctx* c, const jpath* fp, char** file) { return veil__resolve_path(c, fp, file, 0); }

/* "rbf": inline "particles", or a particle "file" (docs/particles.md) read now. */
static veil_result parse_rbf(const ctx* c, const cJSON* so, const jpath* sp, veil_source* src)
{
    const jpath fp = {sp, "file", 0};
    const bool inl = cJSON_GetObjectItemCaseSensitive(so, "particles") != NULL;
    const bool file = cJSON_GetObjectItemCaseSensitive(so, "file") != NULL;
    if (inl && file)
        return veil__jr_fail_at(c, sp, "give either \"particles\" or \"file\", not both");
    if (!file) {
        if (!inl)
            return veil__jr_fail_at(c, sp, "missing required field: \"particles\" (an array of particles) or "
                                           "\"file\" (a particle file, docs/particles.md)");
        return parse_particles(c, so, sp, src);
    }
    char* path = NULL;
    veil_result r = veil__get_string(c, so, sp, "file", true, &path);
    if (r == VEIL_OK) r = resolve_file(c, &fp, &path);
    if (r == VEIL_OK) {
        veil_error inner = {0};
        r = veil_particles_read(path, &src->particles, &src->particle_count, &inner);
        if (r != VEIL_OK) {
            veil_result code = r;
            r = veil__jr_fail_at(c, &fp, "%s", inner.msg);
            if (code == VEIL_ERR_OOM || code == VEIL_ERR_LIMIT || code == VEIL_ERR_IO) r = code; /* same message */
        }
    }
    if (r == VEIL_OK) src->particle_file = path; /* an input of the run (veil_scene_files) */
    else free(path);
    return r;
}

/* "transform": 4 rows of 4 numbers, an affine map (last row 0 0 0 1) with an invertible 3x3 part. */
static veil_result parse_transform(const ctx* c, const cJSON* so, const jpath* sp, veil_vdb_source* v)
{
    static const char what[] = "an array of 4 rows of 4 numbers (a 4x4 matrix acting on column vectors, last row "
                               "0 0 0 1)";
    const jpath p = {sp, "transform", 0};
    const cJSON* t;
    TRY(veil__jr_lookup(c, so, &p, false, what, &t));
    if (!t) return VEIL_OK;
    if (!cJSON_IsArray(t) || cJSON_GetArraySize(t) != 4) return veil__jr_expected(c, &p, what, t);
    double(*m)[4] = v->transform;
    for (int r = 0; r < 4; ++r) {
        const jpath rp = {&p, NULL, (size_t)r};
        float row[4];
        TRY(veil__jr_parse_floats_in(c, cJSON_GetArrayItem(t, r), &rp, 4, &VEIL__R_COORD, row));
        /* the numbers as written (parse_floats_in checks them; the values are read again as doubles) */
        const cJSON* e;
        int k = 0;
        cJSON_ArrayForEach(e, cJSON_GetArrayItem(t, r)) m[r][k++] = e->valuedouble;
    }
    double det;
    int affine = veil_affine_check((const double(*)[4])m, &det);
    if (affine < 0)
        return veil__jr_fail_at(c, &(jpath){&p, NULL, 3}, "expected [0, 0, 0, 1] (veil takes affine maps), got "
                                "[%g, %g, %g, %g]", m[3][0], m[3][1], m[3][2], m[3][3]);
    if (affine == 0)
        return veil__jr_fail_at(c, &p, "the matrix is singular (determinant %g): a voxel would have no volume", det);
    v->has_transform = 1;
    return VEIL_OK;
}

static veil_result parse_grids(const ctx* c, const cJSON* so, const jpath* sp, veil_vdb_source* v, int array);

/* "velocity": {"grid": name (default: found by name, io/vdb.h), "unit": "second" | "frame" ("second"),
 * "scale": a number in [0, 1e6] (1)}: what the density moves with, for motion blur */
static veil_result parse_velocity(const ctx* c, const cJSON* so, const jpath* sp, veil_vdb_source* v)
{
    const jpath p = {sp, "velocity", 0};
    const cJSON* o;
    TRY(veil__jr_get_container(c, so, &p, false, false, &o));
    if (!o) return VEIL_OK;
    TRY(veil__jr_check_keys(c, o, &p, VELOCITY_KEYS));
    TRY(veil__get_string(c, o, &p, "grid", false, &v->velocity_grid));
    int unit = VEIL_VELOCITY_PER_SECOND;
    TRY(veil__jr_get_name(c, o, &p, "unit", VELOCITY_UNITS, &unit));
    /* a scale beyond 1e6 turns any stored velocity into an absurd displacement; a negative one
     * would run the flow backwards (write the shutter the other way round instead) */
    static const range scale = {0, 1e6, false, false, false, "a number in [0, 1e6]"};
    double s = 1.0;
    TRY(veil__jr_get_number(c, o, &p, "scale", false, &scale, &s));
    v->has_velocity = 1, v->velocity_unit = unit, v->velocity_scale = (float)s;
    return VEIL_OK;
}

static veil_result parse_vdb(const ctx* c, const cJSON* so, const jpath* sp, veil_vdb_source* v)
{
    const jpath fp = {sp, "file", 0};
    TRY(veil__get_string(c, so, sp, "file", true, &v->file));
    int kind = veil_frame_pattern_kind(v->file);
    if (kind < 0)
        return veil__jr_fail_at(c, &fp, "'%s': a sequence's file holds the frame number once, as #### or %%04d "
                                "(a literal '%%' is written %%%%)", v->file);
    if (kind == 1) { /* a sequence: frame 1's file until veil_scene_set_frame() says otherwise */
        TRY(veil__resolve_path(c, &fp, &v->file, 1));
        v->sequence = v->file;
        v->file = NULL;
        double off = 0.0;
        TRY(veil__jr_get_number(c, so, sp, "frame_offset", false, &VEIL__R_ANY, &off));
        if (off != floor(off) || fabs(off) > 1e9)
            return veil__jr_fail_at(c, &(jpath){sp, "frame_offset", 0}, "expected a whole number of frames within 1e9, "
                                    "got %g", off);
        v->frame_offset = (long)off;
        char first[4096];
        veil_result r = veil_frame_pattern_path(v->sequence, 1 + v->frame_offset, first, sizeof first, c->err);
        if (r != VEIL_OK) return r;
        size_t len = strlen(first) + 1;
        v->file = malloc(len);
        if (v->file) memcpy(v->file, first, len);
        if (!v->file) return veil_fail(c->err, VEIL_ERR_OOM, "%s: out of memory", c->name);
    } else {
        if (cJSON_GetObjectItemCaseSensitive(so, "frame_offset"))
            return veil__jr_fail_at(c, &(jpath){sp, "frame_offset", 0}, "only for a sequence (a file with #### or %%04d)");
        TRY(resolve_file(c, &fp, &v->file));
    }
    TRY(parse_velocity(c, so, sp, v));
    return parse_grids(c, so, sp, v, 0);
}

/* An "array" source: a vdb source's grids without a file, from veil_scene_set_grid. */
static veil_result parse_array(const ctx* c, const cJSON* so, const jpath* sp, veil_vdb_source* v)
{
    return parse_grids(c, so, sp, v, 1);
}

/* What a vdb and an array source share: the grids, their scales and the transform. */
static veil_result parse_grids(const ctx* c, const cJSON* so, const jpath* sp, veil_vdb_source* v, int array)
{
    const jpath lp = {sp, "level_set", 0};
    TRY(veil__get_string(c, so, sp, "grid", array != 0, &v->grid));
    TRY(parse_transform(c, so, sp, v));
    double scale = 1.0;
    TRY(veil__jr_get_number(c, so, sp, "density_scale", false, &VEIL__R_DENSITY, &scale));
    v->density_scale = (float)scale;
    char* ls = NULL;
    TRY(veil__get_string(c, so, sp, "level_set", false, &ls));
    if (ls && strcmp(ls, "to_fog") != 0) {
        veil_result r = veil__jr_fail_at(c, &lp, "expected \"to_fog\" (convert a level set into a fog volume), got \"%s\"", ls);
        free(ls);
        return r;
    }
    v->level_set_to_fog = ls != NULL;
    free(ls);
    /* "temperature": {"grid": name (required), "scale" (1), "offset" (0, kelvin), "intensity" (>= 0)} */
    const jpath tp = {sp, "temperature", 0};
    const cJSON* to;
    TRY(veil__jr_get_container(c, so, &tp, false, false, &to));
    if (to) {
        TRY(veil__jr_check_keys(c, to, &tp, TEMPERATURE_KEYS));
        TRY(veil__get_string(c, to, &tp, "grid", true, &v->temperature_grid));
        double ts = 1.0, toff = 0.0, ti = -1.0;
        TRY(veil__jr_get_number(c, to, &tp, "scale", false, &VEIL__R_KELVIN, &ts));
        TRY(veil__jr_get_number(c, to, &tp, "offset", false, &VEIL__R_KELVIN, &toff));
        TRY(veil__jr_get_number(c, to, &tp, "intensity", false, &VEIL__R_SIGMA, &ti));
        v->temperature_scale = (float)ts, v->temperature_offset = (float)toff, v->temperature_intensity = (float)ti;
    }
    /* "emission": {"grid": name (required), "scale": >= 0 (1), "color": [3] >= 0 ([1, 1, 1])} */
    const jpath ep = {sp, "emission", 0};
    const cJSON* eo;
    TRY(veil__jr_get_container(c, so, &ep, false, false, &eo));
    if (!eo) return VEIL_OK;
    TRY(veil__jr_check_keys(c, eo, &ep, EMISSION_KEYS));
    TRY(veil__get_string(c, eo, &ep, "grid", true, &v->emission_grid));
    double es = 1.0;
    TRY(veil__jr_get_number(c, eo, &ep, "scale", false, &VEIL__R_EMISSION, &es));
    v->emission_scale = (float)es;
    v->emission_color[0] = v->emission_color[1] = v->emission_color[2] = 1.0f;
    TRY(veil__jr_get_floats_in(c, eo, &ep, "color", false, 3, &VEIL__R_EMISSION, v->emission_color));
    /* eps = scale x value x color: a value of 1 must stay within the bound (scene/limits.h) */
    for (int k = 0; k < 3; ++k)
        if ((double)v->emission_scale * v->emission_color[k] > (double)(float)VEIL_MAX_EMISSION) /* the bound as stored */
            return veil__jr_fail_at(c, &(jpath){&ep, "scale", 0}, "scale x color[%d] = %g x %g = %g W m^-3 sr^-1 "
                                    "for a value of 1, over the bound of 1e21 (scene/limits.h)", k,
                                    (double)v->emission_scale, (double)v->emission_color[k],
                                    (double)v->emission_scale * v->emission_color[k]);
    return VEIL_OK;
}

static veil_result parse_fog(const ctx* c, const cJSON* so, const jpath* sp, veil_exp_fog* f)
{
    const jpath dp = {sp, "direction", 0};
    double density, falloff;
    TRY(veil__jr_get_number(c, so, sp, "density", true, &VEIL__R_DENSITY, &density));
    TRY(veil__jr_get_number(c, so, sp, "falloff", true, &VEIL__R_FALLOFF, &falloff));
    f->density = (float)density, f->falloff = (float)falloff;
    TRY(veil__jr_get_floats(c, so, sp, "direction", true, 3, false, f->direction));
    double len = sqrt((double)f->direction[0] * f->direction[0] + (double)f->direction[1] * f->direction[1] +
                      (double)f->direction[2] * f->direction[2]);
    if (!(len > 0))
        return veil__jr_fail_at(c, &dp, "expected a non-zero vector (the direction the density falls off along)");
    for (int a = 0; a < 3; ++a) f->direction[a] = (float)(f->direction[a] / len);
    TRY(veil__jr_get_floats_in(c, so, sp, "origin", true, 3, &VEIL__R_COORD, f->origin));
    if (cJSON_GetObjectItemCaseSensitive(so, "bounds")) {
        TRY(parse_bounds(c, so, sp, f->bounds));
    } else {
        for (int a = 0; a < 3; ++a) {
            f->bounds[0][a] = f->origin[a] - VEIL_FOG_DEFAULT_HALF_EXTENT;
            f->bounds[1][a] = f->origin[a] + VEIL_FOG_DEFAULT_HALF_EXTENT;
        }
    }
    return VEIL_OK;
}

veil_result veil__parse_sources(const ctx* c, const cJSON* medium, const jpath* mp, veil_medium* m)
{
    static const char* const* const keys[] = {RBF_KEYS, RANDOM_KEYS, VDB_KEYS, FOG_KEYS, ARRAY_KEYS}; /* by type */
    const jpath p = {mp, "sources", 0};
    const cJSON* arr, *e;
    size_t i = 0, fogs = 0;
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
        TRY(veil__jr_check_keys(c, e, &ep, keys[kind]));
        switch (src->type) {
        case VEIL_SOURCE_RBF: TRY(parse_rbf(c, e, &ep, src)); break;
        case VEIL_SOURCE_RBF_RANDOM: TRY(parse_random(c, e, &ep, &src->random)); break;
        case VEIL_SOURCE_VDB: TRY(parse_vdb(c, e, &ep, &src->vdb)); break;
        case VEIL_SOURCE_ARRAY: TRY(parse_array(c, e, &ep, &src->vdb)); break;
        case VEIL_SOURCE_EXPONENTIAL:
            if (++fogs > VEIL_MAX_FOGS)
                return veil__jr_fail_at(c, &ep, "at most %d exponential fogs are supported", VEIL_MAX_FOGS);
            TRY(parse_fog(c, e, &ep, &src->fog));
            break;
        }
    }
    return VEIL_OK;
}
