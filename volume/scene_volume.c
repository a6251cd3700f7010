#define _POSIX_C_SOURCE 200809L /* stat: st_mtim */
#include "scene_volume.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "../core/hash.h"
#include "../core/progress.h"
#include "../scene/limits.h"
#include "blackbody.h"
#include "motion_blur.h"
#include "sparse.h"
#include "vdb_volume.h"

void veil_scene_volume_close(veil_scene_volume* v)
{
    if (!v) return;
    for (int i = 0; i < v->vdb_count; ++i) veil_vdb_close(v->vdbs[i]);
    for (int i = 0; i < v->emission_count; ++i) veil_vdb_close(v->emission[i].grid);
    free(v->particles);
    memset(v, 0, sizeof *v);
}

/* Grows [lo, hi] (valid when *any) by the box [a, b]. */
static void grow(float lo[3], float hi[3], int* any, const float a[3], const float b[3])
{
    for (int k = 0; k < 3; ++k) {
        lo[k] = *any ? fminf(lo[k], a[k]) : a[k];
        hi[k] = *any ? fmaxf(hi[k], b[k]) : b[k];
    }
    *any = 1;
}

/* Opens grid `name` of source i: a vdb source's from its file, an array
 * source's from the scene's grids (veil_scene_set_grid); then places it
 * by the source's transform. Errors name the source and the field. */
static veil_result open_grid(const veil_scene* s, const veil_source* src, size_t i, const char* field,
                             const char* name, int level_set_to_fog, veil_vdb** out, char* chosen, size_t chosen_len,
                             veil_error* err)
{
    veil_error inner = {{0}};
    veil_result r;
    *out = NULL;
    if (src->type == VEIL_SOURCE_ARRAY) {
        const veil_scene_grid* g = veil_scene_grid_find(s, name);
        if (!g)
            return veil_fail(err, VEIL_ERR_INVALID, "medium.sources[%zu]%s: no grid '%.200s' was given (an \"array\" "
                             "source reads a grid from memory: veil_scene_set_grid, or grids={'%.200s': array} in "
                             "Python)", i, field, name, name);
        char label[288];
        snprintf(label, sizeof label, "<array '%.200s'>", name);
        r = veil_vdb_from_dense(label, name, g->data, g->dims, g->z_fastest, g->index_to_world, out, &inner);
        if (r == VEIL_OK && chosen) snprintf(chosen, chosen_len, "%s", name);
    } else {
        r = veil_vdb_open(src->vdb.file, name, level_set_to_fog, out, chosen, chosen_len, &inner);
    }
    if (r == VEIL_OK && src->vdb.has_transform) r = veil_vdb_place(*out, src->vdb.transform, &inner);
    if (r != VEIL_OK) {
        veil_vdb_close(*out);
        *out = NULL;
        return veil_fail(err, r, "medium.sources[%zu]%s: %.1900s", i, field, inner.msg);
    }
    return VEIL_OK;
}

/* Opens source i's emission (temperature: 1) grid, of the same file, and
 * grows [lo, hi] by its support. The source's density grid is the last
 * opened (vdbs[vdb_count - 1]). */
static veil_result open_emission(const veil_scene* s, veil_scene_volume* v, const veil_source* src, size_t i,
                                 int temperature, const veil_motion_blur* mb, float lo[3], float hi[3], int* any,
                                 veil_error* err)
{
    veil_vdb* e = NULL;
    veil_error inner = {{0}};
    const char* name = temperature ? src->vdb.temperature_grid : src->vdb.emission_grid;
    veil_result r = open_grid(s, src, i, temperature ? ".temperature.grid" : ".emission.grid", name, 0, &e, NULL, 0,
                              err);
    if (r != VEIL_OK) return r;
    veil_emission_source* es = &v->emission[v->emission_count++];
    memset(es, 0, sizeof *es);
    es->grid = e;
    /* blurred with the density's velocity and times (a temperature below 0 is kept, as it is read) */
    r = veil_motion_blur_apply(mb, e, !temperature, &v->blur_seconds, NULL, &inner);
    if (r != VEIL_OK)
        return veil_fail(err, r, "medium.sources[%zu].%s.grid: motion blur: %.1900s", i,
                         temperature ? "temperature" : "emission", inner.msg);
    es->temperature = temperature;
    es->density = v->vdb_count - 1;
    es->t_scale = src->vdb.temperature_scale, es->t_offset = src->vdb.temperature_offset;
    double most = 0.0; /* the largest emission factor, for the values' bound */
    for (int c = 0; c < 3; ++c) {
        es->factor[c] = temperature ? src->vdb.temperature_intensity : src->vdb.emission_scale * src->vdb.emission_color[c];
        most = fmax(most, (double)es->factor[c]);
    }
    r = temperature ? veil_vdb_check_values(e, VEIL_VALUES_TEMPERATURE, es->t_scale, es->t_offset, &inner)
                    : veil_vdb_check_values(e, VEIL_VALUES_EMISSION, most, 0.0, &inner);
    if (r != VEIL_OK)
        return veil_fail(err, r, "medium.sources[%zu].%s.grid: %.1900s", i, temperature ? "temperature" : "emission",
                         inner.msg);
    int ilo[3], ihi[3];
    size_t active = 0;
    r = veil_vdb_index_bbox(e, ilo, ihi, &active);
    if (r == VEIL_OK && active > 0 && !temperature) { /* a temperature grid emits only where there is density */
        float a[3], b[3];
        r = veil_vdb_world_support(e, a, b, err);
        if (r == VEIL_OK) grow(lo, hi, any, a, b);
    }
    return r;
}

/* Notes in v->motion what source i's motion blur did, for --stats and
 * --explain (appended to v->resolution once the grid is chosen). */
static void note_blur(veil_scene_volume* v, size_t i, const veil_motion_blur* mb, const veil_vdb_advect_report* rep)
{
    char note[256]; /* (what fits in v->motion is kept) */
    snprintf(note, sizeof note, "; source %zu blurred by '%.64s': %d samples, %.3g voxels over the shutter%s, "
             "%.3g reads (~%.2g s of CPU)", i, mb->velocity_name, mb->samples, mb->displacement,
             mb->displacement > VEIL_BLUR_MAX_SAMPLES ? " (capped)" : rep->reach ? "" : " (no motion)", rep->reads,
             rep->reads * VEIL_BLUR_READ_SECONDS);
    size_t len = strlen(v->motion), n = strlen(note);
    if (len + n < sizeof v->motion) memcpy(v->motion + len, note, n + 1);
}

/* Opens source i's grid and grows [lo, hi] by its support. */
static veil_result open_vdb(const veil_scene* s, veil_scene_volume* v, const veil_source* src, size_t i, float lo[3],
                            float hi[3], int* any, veil_error* err)
{
    if (v->vdb_count == VEIL_MAX_VDB_SOURCES)
        return veil_fail(err, VEIL_ERR_LIMIT, "medium.sources[%zu]: at most %d vdb sources", i, VEIL_MAX_VDB_SOURCES);
    char chosen[256];
    veil_vdb* vdb = NULL;
    veil_error inner = {{0}};
    if (veil_progress_wanted() && src->vdb.file) {
        const char* base = strrchr(src->vdb.file, '/');
        char what[160];
        snprintf(what, sizeof what, "reading %.140s", base ? base + 1 : src->vdb.file);
        veil_progress(what, 0, 1);
    }
    veil_result r = open_grid(s, src, i, src->type == VEIL_SOURCE_ARRAY ? ".grid" : "", src->vdb.grid,
                              src->vdb.level_set_to_fog, &vdb, chosen, sizeof chosen, err);
    if (r != VEIL_OK) return r;
    v->vdbs[v->vdb_count] = vdb;
    v->vdb_scale[v->vdb_count++] = src->vdb.density_scale;
    /* motion blur: the grids replaced by their means over the shutter before anything reads them */
    veil_motion_blur mb;
    veil_vdb_advect_report blur = {0};
    r = veil_motion_blur_open(s, src, i, vdb, &mb, err);
    if (r != VEIL_OK) return r;
    r = veil_motion_blur_apply(&mb, vdb, 1, &v->blur_seconds, &blur, &inner);
    if (r != VEIL_OK) {
        veil_motion_blur_close(&mb);
        return veil_fail(err, r, "medium.sources[%zu]: motion blur: %.1900s", i, inner.msg);
    }
    if (mb.velocity) {
        note_blur(v, i, &mb, &blur);
        snprintf(v->velocity_read[v->vdb_count - 1], sizeof v->velocity_read[0], "%s", mb.velocity_name);
    }
    r = veil_vdb_check_values(vdb, VEIL_VALUES_DENSITY, src->vdb.density_scale, 0.0, &inner);
    if (r != VEIL_OK) {
        veil_motion_blur_close(&mb);
        return veil_fail(err, r, "medium.sources[%zu]: %.1900s", i, inner.msg);
    }
    int ilo[3], ihi[3];
    size_t active = 0;
    r = veil_vdb_index_bbox(vdb, ilo, ihi, &active);
    if (r == VEIL_OK && active > 0 && src->vdb.density_scale > 0.0f) {
        float a[3], b[3];
        r = veil_vdb_world_support(vdb, a, b, err);
        if (r == VEIL_OK) grow(lo, hi, any, a, b);
    }
    v->vdb_voxels += active;
    if (r == VEIL_OK && src->vdb.emission_grid) r = open_emission(s, v, src, i, 0, &mb, lo, hi, any, err);
    if (r == VEIL_OK && src->vdb.temperature_grid) r = open_emission(s, v, src, i, 1, &mb, lo, hi, any, err);
    veil_motion_blur_close(&mb);
    return r;
}

double* veil_emission_table(void) { return veil_blackbody_table(); }

void veil_emission_eps(const veil_scene_volume* v, const veil_emission_source* es, const double* table, float value,
                       float rho, float eps[3])
{
    if (!es->temperature) {
        for (int c = 0; c < 3; ++c) eps[c] = es->factor[c] * value;
        return;
    }
    eps[0] = eps[1] = eps[2] = 0.0f;
    if (!(rho > 0.0f)) return;
    double bb[3];
    veil_blackbody_lookup(table, (double)es->t_scale * value + es->t_offset, bb);
    for (int c = 0; c < 3; ++c) {
        double kc = es->factor[c] >= 0.0f ? es->factor[c] : v->sigma_a[c];
        /* k rho B within max(VEIL_MAX_EMISSION, sigma_a rho B) (scene/limits.h): Kirchhoff's emission
         * (k <= sigma_a) as it is, its radiance under B; a larger k (<= 1e10) at rho <= 1e10 and
         * B(1e5 K) = 2e9 could make 2e29, more than a ray can sum under FLT_MAX */
        double e = kc * rho * bb[c], cap = fmax(VEIL_MAX_EMISSION, (double)v->sigma_a[c] * rho * bb[c]);
        eps[c] = (float)fmin(e, cap);
    }
}

veil_result veil_scene_volume_emission(const veil_scene_volume* v, float** rgba, veil_error* err)
{
    *rgba = NULL;
    if (!v->has_volume || v->emission_count == 0) return VEIL_OK;
    size_t n = veil_grid_voxels(&v->grid);
    float* out = calloc(n * 4, sizeof *out);
    float* one = malloc(n * sizeof *one);
    float* rho = malloc(n * sizeof *rho);
    double* table = veil_emission_table();
    veil_result r = out && one && rho && table ? VEIL_OK
                                               : veil_fail(err, VEIL_ERR_OOM, "out of memory for a %zu-voxel emission", n);
    for (int i = 0; i < v->emission_count && r == VEIL_OK; ++i) {
        const veil_emission_source* es = &v->emission[i];
        memset(one, 0, n * sizeof *one);
        r = es->temperature ? veil_vdb_to_grid_signed(es->grid, 1.0f, &v->grid, one, err)
                            : veil_vdb_to_grid(es->grid, 1.0f, &v->grid, one, err);
        if (r == VEIL_OK && es->temperature) {
            memset(rho, 0, n * sizeof *rho);
            r = veil_vdb_to_grid(v->vdbs[es->density], v->vdb_scale[es->density], &v->grid, rho, err);
        }
        for (size_t k = 0; k < n && r == VEIL_OK; ++k) {
            float eps[3];
            veil_emission_eps(v, es, table, one[k], es->temperature ? rho[k] : 0.0f, eps);
            for (int c = 0; c < 3; ++c) out[4 * k + (size_t)c] += eps[c];
        }
    }
    free(one);
    free(rho);
    free(table);
    if (r != VEIL_OK) {
        free(out);
        return r;
    }
    *rgba = out;
    return VEIL_OK;
}

/* A file's identity: its path, size, modification time and inode, not
 * its bytes (a file rewritten in place changes its mtime). A file that
 * cannot be stat'ed keys as such; opening it reports the error. */
static uint64_t hash_file_identity(uint64_t k, const char* path)
{
    struct stat sb;
    memset(&sb, 0, sizeof sb);
    int ok = stat(path, &sb) == 0;
    k = veil_hash_bytes(k, path, strlen(path) + 1);
    k = veil_hash_bytes(k, &ok, sizeof ok);
    if (!ok) return k;
    int64_t id[5] = {(int64_t)sb.st_size, (int64_t)sb.st_mtim.tv_sec, (int64_t)sb.st_mtim.tv_nsec,
                     (int64_t)sb.st_ino, (int64_t)sb.st_dev};
    return veil_hash_bytes(k, id, sizeof id);
}

uint64_t veil_scene_volume_key(const veil_scene* s)
{
    uint64_t k = veil_hash_bytes(VEIL_FNV_OFFSET, &s->medium.max_resolution, sizeof s->medium.max_resolution);
    k = veil_hash_bytes(k, &s->medium.max_resolution_set, sizeof s->medium.max_resolution_set);
    k = veil_hash_bytes(k, &s->medium.representation, sizeof s->medium.representation);
    for (size_t i = 0; i < s->medium.source_count; ++i) {
        const veil_source* src = &s->medium.sources[i];
        if (src->type == VEIL_SOURCE_EXPONENTIAL) continue; /* never voxelised */
        int type = (int)src->type;
        k = veil_hash_bytes(k, &type, sizeof type);
        if (src->type == VEIL_SOURCE_RBF) {
            k = veil_hash_bytes(k, &src->particle_count, sizeof src->particle_count);
            k = veil_hash_bytes(k, src->particles, src->particle_count * sizeof *src->particles);
        } else if (src->type == VEIL_SOURCE_RBF_RANDOM) {
            const veil_rbf_random_desc* d = &src->random;
            k = veil_hash_bytes(k, &d->count, sizeof d->count);
            k = veil_hash_bytes(k, &d->seed, sizeof d->seed);
            k = veil_hash_bytes(k, d->bounds, sizeof d->bounds);
            k = veil_hash_bytes(k, d->radius, sizeof d->radius);
            k = veil_hash_bytes(k, d->amplitude, sizeof d->amplitude);
        } else if (src->type == VEIL_SOURCE_VDB || src->type == VEIL_SOURCE_ARRAY) {
            const char* grid = src->vdb.grid ? src->vdb.grid : "";
            if (src->type == VEIL_SOURCE_VDB) {
                k = hash_file_identity(k, src->vdb.file);
            } else { /* the grids' contents, by name (a grid not given keys as such; opening it reports it) */
                const char* names[3] = {src->vdb.grid, src->vdb.emission_grid, src->vdb.temperature_grid};
                for (int g = 0; g < 3; ++g) {
                    const veil_scene_grid* sg = veil_scene_grid_find(s, names[g]);
                    uint64_t h = sg ? sg->hash : 0;
                    k = veil_hash_bytes(k, &h, sizeof h);
                }
            }
            k = veil_hash_bytes(k, &src->vdb.has_transform, sizeof src->vdb.has_transform);
            k = veil_hash_bytes(k, src->vdb.transform, sizeof src->vdb.transform);
            k = veil_hash_bytes(k, grid, strlen(grid) + 1);
            k = veil_hash_bytes(k, &src->vdb.density_scale, sizeof src->vdb.density_scale);
            k = veil_hash_bytes(k, &src->vdb.level_set_to_fog, sizeof src->vdb.level_set_to_fog);
            const char* eg = src->vdb.emission_grid ? src->vdb.emission_grid : "";
            k = veil_hash_bytes(k, eg, strlen(eg) + 1);
            k = veil_hash_bytes(k, &src->vdb.emission_scale, sizeof src->vdb.emission_scale);
            k = veil_hash_bytes(k, src->vdb.emission_color, sizeof src->vdb.emission_color);
            const char* tg = src->vdb.temperature_grid ? src->vdb.temperature_grid : "";
            k = veil_hash_bytes(k, tg, strlen(tg) + 1);
            k = veil_hash_bytes(k, &src->vdb.temperature_scale, sizeof src->vdb.temperature_scale);
            k = veil_hash_bytes(k, &src->vdb.temperature_offset, sizeof src->vdb.temperature_offset);
            k = veil_hash_bytes(k, &src->vdb.temperature_intensity, sizeof src->vdb.temperature_intensity);
            /* motion blur: the velocity, the shutter and the frame rate make the grids (only when asked for,
             * so that a scene without blur keys as before) */
            if (src->vdb.has_velocity && s->camera.has_shutter) {
                const char* vg = src->vdb.velocity_grid ? src->vdb.velocity_grid : "";
                const double fps = s->fps > 0.0 ? s->fps : VEIL_SCENE_DEFAULT_FPS;
                k = veil_hash_bytes(k, vg, strlen(vg) + 1);
                k = veil_hash_bytes(k, &src->vdb.velocity_unit, sizeof src->vdb.velocity_unit);
                k = veil_hash_bytes(k, &src->vdb.velocity_scale, sizeof src->vdb.velocity_scale);
                k = veil_hash_bytes(k, s->camera.shutter, sizeof s->camera.shutter);
                k = veil_hash_bytes(k, &fps, sizeof fps);
            }
            k = veil_hash_bytes(k, s->medium.sigma_a, sizeof s->medium.sigma_a); /* Kirchhoff's k */
            k = veil_hash_bytes(k, &s->multiple.emission_lights, sizeof s->multiple.emission_lights);
        }
    }
    return k;
}

int veil_scene_volume_needed(const veil_scene* s)
{
    for (size_t i = 0; i < s->medium.source_count; ++i)
        if (s->medium.sources[i].type != VEIL_SOURCE_EXPONENTIAL) return 1;
    return 0;
}

/* The native grid over [lo, hi] (module comment in scene_volume.h): 1 when
 * it applies (and *g, note are set), 0 to fit to max_resolution instead. */
static int native_grid(const veil_scene_volume* v, const float lo[3], const float hi[3], veil_grid* g, char* note,
                       size_t note_len, int big)
{
    double edge = HUGE_VAL, origin[3] = {0, 0, 0};
    int aligned = 0, which = -1;
    for (int i = 0; i < v->vdb_count; ++i) {
        double e, o[3];
        int al;
        if (!veil_vdb_lattice(v->vdbs[i], &e, o, &al)) continue;
        /* the finest edge; among equal ones, one whose cubes are axis-aligned */
        if (e < edge * (1.0 - VEIL_VDB_ALIGN_TOL) || (fabs(e - edge) <= VEIL_VDB_ALIGN_TOL * edge && al && !aligned)) {
            edge = e, aligned = al, which = i;
            memcpy(origin, o, sizeof o);
        }
    }
    if (which < 0) return 0;
    double n = 1.0;
    int dims[3];
    double org[3];
    for (int a = 0; a < 3; ++a) {
        /* index points covering [lo, hi]; the voxel centres sit on them when aligned */
        double base = aligned ? origin[a] : (double)lo[a];
        /* (lo, hi are floats: allow their rounding, VEIL_VDB_ALIGN_TOL of a voxel) */
        double i0 = floor(((double)lo[a] - base) / edge + VEIL_VDB_ALIGN_TOL);
        double i1 = ceil(((double)hi[a] - base) / edge - VEIL_VDB_ALIGN_TOL);
        double d = fmax(i1 - i0 + 1.0, 2.0);
        if (d > (big ? VEIL_SPARSE_MAX_SIDE : VEIL_SCENE_MAX_RESOLUTION)) {
            snprintf(note, note_len, "resampled: the VDB's %.4g m voxels make %.0f along an axis (at most %d%s)", edge, d,
                     big ? VEIL_SPARSE_MAX_SIDE : VEIL_SCENE_MAX_RESOLUTION, big ? ", sparse" : "");
            return 0;
        }
        dims[a] = (int)d;
        org[a] = base + (i0 - 0.5) * edge;
        n *= d;
    }
    if (n > (double)VEIL_NATIVE_MAX_VOXELS && !big) {
        snprintf(note, note_len, "resampled: the VDB's %.4g m voxels make a %dx%dx%d grid, over the dense cap of "
                 "%zu voxels", edge, dims[0], dims[1], dims[2], (size_t)VEIL_NATIVE_MAX_VOXELS);
        return 0;
    }
    for (int a = 0; a < 3; ++a) g->dims[a] = dims[a], g->origin[a] = (float)org[a];
    g->voxel = (float)edge;
    if (aligned)
        snprintf(note, note_len, "native: the VDB's %.4g m voxels, %dx%dx%d, values copied%s", edge, dims[0], dims[1],
                 dims[2], v->vdb_count > 1 ? " (the finest grid; the others resampled onto it)" : "");
    else
        snprintf(note, note_len, "native voxel size %.4g m, resampled (the field at each voxel centre): the VDB's "
                 "voxels are rotated or not cubes", edge);
    return 1;
}

/* Why v cannot be sparse ("" when it can): volume/sparse.h. */
static void sparse_obstacle(const veil_scene* s, const veil_scene_volume* v, char* why, size_t len)
{
    why[0] = 0;
    if (s->medium.max_resolution_set)
        snprintf(why, len, "medium.max_resolution asks for a resampled grid");
    else if (v->particle_count > 0)
        snprintf(why, len, "the medium has RBF particles (splatted into a dense grid)");
    else if (v->vdb_count == 0)
        snprintf(why, len, "the medium has no vdb source");
    if (why[0]) return;
    int temperature = 0;
    for (int i = 0; i < v->emission_count; ++i) temperature |= v->emission[i].temperature;
    if (temperature && v->vdb_count > 1) {
        snprintf(why, len, "a temperature grid with several vdb sources (dense only)");
        return;
    }
    double edge0 = 0, origin0[3] = {0, 0, 0};
    for (int i = 0; i < v->vdb_count + v->emission_count; ++i) {
        const veil_vdb* grid = i < v->vdb_count ? v->vdbs[i] : v->emission[i - v->vdb_count].grid;
        double e, o[3];
        int al;
        if (!veil_vdb_lattice(grid, &e, o, &al)) continue; /* no active voxel: adds nothing */
        if (!al) {
            snprintf(why, len, "%s: its voxels are rotated or not cubes", veil_vdb_path(grid));
            return;
        }
        if (edge0 == 0) {
            edge0 = e;
            memcpy(origin0, o, sizeof o);
            continue;
        }
        int on = fabs(e - edge0) <= VEIL_VDB_ALIGN_TOL * edge0;
        for (int a = 0; a < 3 && on; ++a) {
            double k = (o[a] - origin0[a]) / edge0;
            on = fabs(k - floor(k + 0.5)) <= VEIL_VDB_ALIGN_TOL;
        }
        if (!on) {
            snprintf(why, len, "%s%s%s: its voxels are not on the lattice of %s", veil_vdb_path(grid),
                     i < v->vdb_count ? "" : ", grid ", i < v->vdb_count ? "" : veil_vdb_grid_name(grid),
                     veil_vdb_path(v->vdbs[0]));
            return;
        }
    }
}

/* The grid over [lo, hi]: native for VDBs without an explicit max_resolution
 * (sparse when the native grid is over the dense cap, or asked for), else fitted. */
static veil_result choose_grid(const veil_scene* s, veil_scene_volume* v, const float lo[3], const float hi[3],
                               veil_error* err)
{
    v->resolution[0] = 0;
    veil_representation rep = s->medium.representation;
    char obstacle[320];
    sparse_obstacle(s, v, obstacle, sizeof obstacle);
    if (rep == VEIL_REPRESENTATION_SPARSE && obstacle[0])
        return veil_fail(err, VEIL_ERR_INVALID, "medium.representation: \"sparse\" is not possible here: %s", obstacle);
    if (rep != VEIL_REPRESENTATION_SPARSE && !s->medium.max_resolution_set && v->vdb_count > 0 &&
        native_grid(v, lo, hi, &v->grid, v->resolution, sizeof v->resolution, 0))
        return VEIL_OK;
    if (rep != VEIL_REPRESENTATION_DENSE && !obstacle[0]) {
        char dense_note[320];
        snprintf(dense_note, sizeof dense_note, "%s", v->resolution);
        if (native_grid(v, lo, hi, &v->grid, v->resolution, sizeof v->resolution, 1)) {
            const int* d = v->grid.dims;
            v->sparse = 1;
            snprintf(v->resolution, sizeof v->resolution, "sparse: the VDB's %.4g m voxels, a %dx%dx%d box (%s)",
                     v->grid.voxel, d[0], d[1], d[2],
                     rep == VEIL_REPRESENTATION_SPARSE ? "medium.representation" : "over the dense cap of 2^27 voxels");
            return VEIL_OK;
        }
        /* asked for, a grid the sparse tables cannot hold is an error (auto resamples it, and says why) */
        if (rep == VEIL_REPRESENTATION_SPARSE) {
            const char* why = strncmp(v->resolution, "resampled: ", 11) ? v->resolution : v->resolution + 11;
            return veil_fail(err, VEIL_ERR_INVALID, "medium.representation: \"sparse\" is not possible here: %s; "
                             "\"auto\" resamples it, or set medium.max_resolution", why[0] ? why : "no native grid");
        }
        if (!v->resolution[0]) snprintf(v->resolution, sizeof v->resolution, "%s", dense_note);
    }
    int res = s->medium.max_resolution;
    if (!s->medium.max_resolution_set && v->resolution[0]) {
        /* the native grid is too large: the finest that fits the cap, as a cube root of it */
        res = (int)cbrt((double)VEIL_NATIVE_MAX_VOXELS);
        if (res > VEIL_SCENE_MAX_RESOLUTION) res = VEIL_SCENE_MAX_RESOLUTION;
        if (obstacle[0] && v->vdb_count > 0) {
            size_t len = strlen(v->resolution);
            snprintf(v->resolution + len, sizeof v->resolution - len, "; not sparse: %s", obstacle);
        }
    }
    veil_result r = veil_grid_fit(lo, hi, res, &v->grid, err);
    if (r == VEIL_OK && !v->resolution[0])
        snprintf(v->resolution, sizeof v->resolution, "%s: %d voxels along the longest side%s",
                 v->vdb_count ? "resampled" : "fitted", res,
                 s->medium.max_resolution_set ? " (medium.max_resolution)" : " (the default for particles)");
    else if (r == VEIL_OK) {
        size_t len = strlen(v->resolution);
        snprintf(v->resolution + len, sizeof v->resolution - len, "; %d voxels along the longest side", res);
    }
    return r;
}

/* Appends to v->resolution the grids of vdb i's file that nothing read:
 * neither the density nor an emission or temperature grid of it. */
static void note_unread(veil_scene_volume* v, int i)
{
    char unread[256] = "";
    const char* p = veil_vdb_other_grids(v->vdbs[i]);
    while (*p) {
        const char* end = strstr(p, ", ");
        size_t n = end ? (size_t)(end - p) : strlen(p);
        int used = 0;
        for (int e = 0; e < v->emission_count; ++e) {
            const char* name = veil_vdb_grid_name(v->emission[e].grid);
            size_t k = strlen(name);
            used |= v->emission[e].density == i && n > k + 1 && strncmp(p, name, k) == 0 && p[k] == ' ';
        }
        /* the velocity of a blurred source: "vel", or each of "vel.x/.y/.z" */
        const char* vel = v->velocity_read[i];
        const char* dot = strstr(vel, ".x/.y/.z");
        size_t vk = dot ? (size_t)(dot - vel) : strlen(vel);
        used |= vk > 0 && n > vk + 1 && strncmp(p, vel, vk) == 0 &&
                (dot ? p[vk] == '.' && strchr("xyz", p[vk + 1]) && p[vk + 2] == ' ' : p[vk] == ' ');
        size_t len = strlen(unread);
        if (!used && len + n + 3 < sizeof unread) snprintf(unread + len, sizeof unread - len, "%s%.*s", len ? ", " : "", (int)n, p);
        p += n;
        if (end) p += 2;
    }
    size_t len = strlen(v->resolution);
    if (*unread && len + 16 < sizeof v->resolution)
        snprintf(v->resolution + len, sizeof v->resolution - len, "; not read: %s", unread);
}

/* Appends to v->resolution how many voxels of `grid` below 0 read as 0 (a
 * density or emission: scene/limits.h); short, as --stats gives the stage
 * 255 characters. */
static void note_negative(veil_scene_volume* v, const veil_vdb* grid)
{
    veil_vdb_values x;
    veil_vdb_value_range(grid, &x);
    size_t len = strlen(v->resolution);
    if (x.negative > 0 && len + 32 < sizeof v->resolution)
        snprintf(v->resolution + len, sizeof v->resolution - len, "; grid '%s': %llu voxel%s below 0 read as 0",
                 veil_vdb_grid_name(grid), (unsigned long long)x.negative, x.negative == 1 ? "" : "s");
}

veil_result veil_scene_volume_open(const veil_scene* s, veil_scene_volume* out, veil_error* err)
{
    veil_scene_volume v;
    memset(&v, 0, sizeof v);
    memset(out, 0, sizeof *out);
    v.key = veil_scene_volume_key(s);
    memcpy(v.sigma_a, s->medium.sigma_a, sizeof v.sigma_a);
    v.emission_lights = s->multiple.emission_lights;
    veil_result r = veil_scene_particles(s, &v.particles, &v.particle_count, err);
    float lo[3], hi[3], a[3], b[3];
    int any = 0;
    for (size_t i = 0; i < s->medium.source_count && r == VEIL_OK; ++i)
        if (s->medium.sources[i].type == VEIL_SOURCE_VDB || s->medium.sources[i].type == VEIL_SOURCE_ARRAY)
            r = open_vdb(s, &v, &s->medium.sources[i], i, lo, hi, &any, err);
    if (r == VEIL_OK) {
        if (veil_rbf_bounds(v.particles, v.particle_count, a, b)) grow(lo, hi, &any, a, b);
        if (any) r = choose_grid(s, &v, lo, hi, err);
        v.has_volume = any;
    }
    /* a dense grid's resampling checked now, before the GPU's volume or a CPU copy is made (a tile over a
     * 4096^3 box was refused there only after 2 s and 600 MB); veil_vdb_to_grid checks the same again */
    for (int i = 0; r == VEIL_OK && v.has_volume && !v.sparse && i < v.vdb_count + v.emission_count; ++i) {
        veil_vdb_resample_plan plan;
        if (i < v.vdb_count && !(v.vdb_scale[i] > 0.0f)) continue;
        r = veil_vdb_plan_resample(i < v.vdb_count ? v.vdbs[i] : v.emission[i - v.vdb_count].grid, &v.grid, &plan, err);
    }
    /* what the motion blur did, first: the notes below may fill the line */
    if (r == VEIL_OK && v.motion[0]) {
        size_t len = strlen(v.resolution);
        snprintf(v.resolution + len, sizeof v.resolution - len, "%s", v.motion);
    }
    /* say which grids of the files were not read (velocity and the like) */
    for (int i = 0; i < v.vdb_count && r == VEIL_OK; ++i) note_negative(&v, v.vdbs[i]);
    for (int i = 0; i < v.emission_count && r == VEIL_OK; ++i)
        if (!v.emission[i].temperature) note_negative(&v, v.emission[i].grid);
    for (int i = 0; i < v.vdb_count && r == VEIL_OK; ++i) note_unread(&v, i);

    if (r != VEIL_OK) {
        veil_scene_volume_close(&v);
        return r;
    }
    *out = v;
    return VEIL_OK;
}

veil_result veil_scene_volume_add_vdbs(const veil_scene_volume* v, float* density, veil_error* err)
{
    veil_result r = VEIL_OK;
    for (int i = 0; i < v->vdb_count && r == VEIL_OK; ++i) r = veil_vdb_to_grid(v->vdbs[i], v->vdb_scale[i], &v->grid, density, err);
    return r;
}

veil_result veil_scene_volume_density(const veil_scene_volume* v, float** density, veil_error* err)
{
    *density = NULL;
    if (!v->has_volume) return veil_fail(err, VEIL_ERR_INVALID, "the scene has no voxelised source");
    if (v->sparse)
        return veil_fail(err, VEIL_ERR_LIMIT, "a %dx%dx%d grid (sparse) has no dense copy on the CPU: set "
                         "medium.max_resolution (the dense cap is 2^27 voxels)", v->grid.dims[0], v->grid.dims[1],
                         v->grid.dims[2]);
    size_t n = veil_grid_voxels(&v->grid);
    float* d = calloc(n, sizeof(float));
    if (!d) return veil_fail(err, VEIL_ERR_OOM, "out of memory for a %zu-voxel volume", n);
    veil_result r = veil_scene_volume_add_vdbs(v, d, err);
    if (r == VEIL_OK && v->particle_count > 0) {
        veil_rbf_bins bins = {0};
        r = veil_rbf_bin(&v->grid, v->particles, v->particle_count, &bins, err);
        if (r == VEIL_OK) veil_inject_rbf_cpu(&v->grid, &bins, d);
        veil_rbf_bins_free(&bins);
    }
    if (r != VEIL_OK) {
        free(d);
        return r;
    }
    *density = d;
    return VEIL_OK;
}
