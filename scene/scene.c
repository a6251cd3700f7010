/* veil — releasing a scene, and the particles its sources describe. */
#include "scene.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/hash.h"
#include "frame_pattern.h"
#include "limits.h"

/* At most this many values in a grid from memory (as VEIL_VDB_MAX_DENSE_VOXELS: 2^30 floats, 4 GiB). */
#define VEIL_SCENE_GRID_MAX_VALUES ((size_t)1 << 30)
/* A grid is held as OpenVDB's tree of 8^3 leaves (io/vdb.h): a thin one pads every value to a leaf (a 1 x 1
 * x 2^28 line takes 2^25 leaves of 512 values: 64 GiB and 74 s where a cube of as many values takes 1 GiB and
 * 1.8 s). The leaves' voxels, at most twice the values' cap (8 GiB), refused from the dimensions alone. */
#define VEIL_SCENE_GRID_MAX_TREE_VOXELS ((double)((size_t)1 << 31))

int veil_affine_check(const double m[4][4], double* det)
{
    *det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (m[3][0] != 0.0 || m[3][1] != 0.0 || m[3][2] != 0.0 || m[3][3] != 1.0) return -1;
    double scale = 0.0; /* the longest column: a determinant under 1e-12 of its cube is singular in double */
    for (int c = 0; c < 3; ++c) scale = fmax(scale, sqrt(m[0][c] * m[0][c] + m[1][c] * m[1][c] + m[2][c] * m[2][c]));
    return fabs(*det) > 1e-12 * scale * scale * scale ? 1 : 0;
}

const veil_scene_grid* veil_scene_grid_find(const veil_scene* s, const char* name)
{
    for (size_t i = 0; s && name && i < s->grid_count; ++i)
        if (!strcmp(s->grids[i].name, name)) return &s->grids[i];
    return NULL;
}

veil_result veil_scene_grid_set(veil_scene* s, const char* name, const float* data, const int dims[3], int z_fastest,
                                const double index_to_world[4][4], veil_error* err)
{
    if (!name[0]) return veil_fail(err, VEIL_ERR_INVALID, "grid: the name is empty");
    size_t n = 1;
    for (int a = 0; a < 3; ++a) {
        if (dims[a] < 1 || (size_t)dims[a] > VEIL_SCENE_GRID_MAX_VALUES)
            return veil_fail(err, VEIL_ERR_INVALID, "grid '%.200s': dimension %d is %d (expected 1..2^30)", name, a,
                             dims[a]);
        n *= (size_t)dims[a];
        if (n > VEIL_SCENE_GRID_MAX_VALUES)
            return veil_fail(err, VEIL_ERR_LIMIT, "grid '%.200s': %dx%dx%d values, over the limit of 2^30", name,
                             dims[0], dims[1], dims[2]);
    }
    double leaves = 1.0;
    for (int a = 0; a < 3; ++a) leaves *= (double)((dims[a] + 7) / 8);
    if (leaves * 512.0 > VEIL_SCENE_GRID_MAX_TREE_VOXELS)
        return veil_fail(err, VEIL_ERR_LIMIT, "grid '%.200s': %dx%dx%d values fill %.0f of OpenVDB's 8^3 leaves, "
                         "%.3g voxels (%.3g GB) as veil holds a grid, over the limit of 2^31 (8.6 GB): a grid this "
                         "thin pads each value to a leaf; give it at least 8 voxels thick, or fewer values", name,
                         dims[0], dims[1], dims[2], leaves, leaves * 512.0, leaves * 512.0 * 4.0 / 1e9);
    const double(*m)[4] = index_to_world;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
            if (!isfinite(m[r][c]))
                return veil_fail(err, VEIL_ERR_INVALID, "grid '%.200s': index_to_world[%d][%d] is not finite", name,
                                 r, c);
    double det;
    int affine = veil_affine_check(m, &det);
    if (affine < 0)
        return veil_fail(err, VEIL_ERR_INVALID, "grid '%.200s': index_to_world's last row is %g %g %g %g, not 0 0 0 1 "
                         "(an affine map)", name, m[3][0], m[3][1], m[3][2], m[3][3]);
    if (affine == 0)
        return veil_fail(err, VEIL_ERR_INVALID, "grid '%.200s': index_to_world is singular (determinant %g)", name, det);
    if (!(fabs(det) >= VEIL_MIN_VOXEL_VOLUME))
        return veil_fail(err, VEIL_ERR_INVALID, "grid '%.200s': index_to_world makes a voxel of %g m^3, under the "
                         "%g m^3 (a cube of 14.4 um) OpenVDB's maps hold (scene/limits.h)", name, fabs(det),
                         VEIL_MIN_VOXEL_VOLUME);
    double far = 0.0, edge = INFINITY; /* the largest |coordinate| of the box; the smallest voxel edge */
    for (int c = 0; c < 3; ++c) edge = fmin(edge, sqrt(m[0][c] * m[0][c] + m[1][c] * m[1][c] + m[2][c] * m[2][c]));
    for (int corner = 0; corner < 8; ++corner) { /* the grid's box within the scene's coordinates */
        const double idx[3] = {corner & 1 ? dims[0] - 1 : 0, corner & 2 ? dims[1] - 1 : 0, corner & 4 ? dims[2] - 1 : 0};
        for (int r = 0; r < 3; ++r) {
            const double x = m[r][0] * idx[0] + m[r][1] * idx[1] + m[r][2] * idx[2] + m[r][3];
            if (!(fabs(x) <= VEIL_MAX_COORD))
                return veil_fail(err, VEIL_ERR_INVALID, "grid '%.200s': index_to_world puts index [%.0f, %.0f, %.0f] "
                                 "at %c = %g m, beyond the scene's +-%g m (scene/limits.h)", name, idx[0], idx[1],
                                 idx[2], "xyz"[r], x, VEIL_MAX_COORD);
            far = fmax(far, fabs(x));
        }
    }
    if (!(edge >= VEIL_MIN_VOXEL_RELATIVE * far))
        return veil_fail(err, VEIL_ERR_INVALID, "grid '%.200s': voxels of %g m at %g m from the origin, under 2^-20 of "
                         "that distance (%g m): finer than single-precision positions resolve there (scene/limits.h)",
                         name, edge, far, VEIL_MIN_VOXEL_RELATIVE * far);
    /* a value that is not finite, refused here: OpenVDB's copyFromDense would take a NaN for the
     * background (its comparison with 0 is false) and the grid would read 0 there, silently */
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(data[i]) && bad++ == 0) first = i;
    if (bad) { /* the first one's index (i, j, k), from its offset in the caller's order */
        size_t i, j, k, nx = (size_t)dims[0], ny = (size_t)dims[1], nz = (size_t)dims[2];
        if (z_fastest) k = first % nz, j = first / nz % ny, i = first / nz / ny;
        else i = first % nx, j = first / nx % ny, k = first / nx / ny;
        return veil_fail(err, VEIL_ERR_INVALID, "grid '%.200s': %zu value%s not finite (NaN or infinite), the first "
                         "at index [%zu, %zu, %zu] (offset %zu of %zu)", name, bad, bad == 1 ? " is" : "s are", i, j,
                         k, first, n);
    }
    float* copy = malloc(n * sizeof *copy);
    char* nm = malloc(strlen(name) + 1);
    veil_scene_grid* slot = (veil_scene_grid*)veil_scene_grid_find(s, name);
    if (!slot && copy && nm) {
        veil_scene_grid* g = realloc(s->grids, (s->grid_count + 1) * sizeof *g);
        if (g) {
            s->grids = g;
            slot = &g[s->grid_count++];
            memset(slot, 0, sizeof *slot);
        }
    }
    if (!copy || !nm || !slot) {
        free(copy);
        free(nm);
        return veil_fail(err, VEIL_ERR_OOM, "grid '%.200s': out of memory for %zu values", name, n);
    }
    memcpy(copy, data, n * sizeof *copy);
    strcpy(nm, name);
    free(slot->name);
    free(slot->data);
    slot->name = nm;
    slot->data = copy;
    memcpy(slot->dims, dims, sizeof slot->dims);
    slot->z_fastest = z_fastest != 0;
    memcpy(slot->index_to_world, index_to_world, sizeof slot->index_to_world);
    uint64_t h = veil_hash_words(VEIL_FNV_OFFSET, copy, n * sizeof *copy);
    h = veil_hash_bytes(h, slot->dims, sizeof slot->dims);
    h = veil_hash_bytes(h, &slot->z_fastest, sizeof slot->z_fastest);
    slot->hash = veil_hash_bytes(h, slot->index_to_world, sizeof slot->index_to_world);
    return VEIL_OK;
}

void veil_scene_free(veil_scene* s)
{
    if (!s) return;
    for (size_t i = 0; i < s->medium.source_count; ++i) {
        free(s->medium.sources[i].particles);
        free(s->medium.sources[i].particle_file);
        free(s->medium.sources[i].vdb.file);
        free(s->medium.sources[i].vdb.sequence);
        free(s->medium.sources[i].vdb.grid);
        free(s->medium.sources[i].vdb.emission_grid);
        free(s->medium.sources[i].vdb.temperature_grid);
        free(s->medium.sources[i].vdb.velocity_grid);
    }
    free(s->medium.sources);
    for (size_t i = 0; i < s->grid_count; ++i) {
        free(s->grids[i].name);
        free(s->grids[i].data);
    }
    free(s->grids);
    free(s->lights);
    veil_env_free(&s->environment);
    free(s->path);
    free(s->base_dir);
    memset(s, 0, sizeof *s);
}

static size_t source_particles(const veil_source* src)
{
    if (src->type == VEIL_SOURCE_RBF) return src->particle_count;
    return src->type == VEIL_SOURCE_RBF_RANDOM ? src->random.count : 0;
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
        else if (n && src->type == VEIL_SOURCE_RBF_RANDOM) veil_rbf_random_generate(&src->random, p + k);
        k += n;
    }
    *out = p, *count = total;
    return VEIL_OK;
}

/* ---- multiple scattering settings -------------------------------------- */

int veil_spread_taps(veil_spread_filter f) { return f == VEIL_SPREAD_2X2 ? 2 : (f == VEIL_SPREAD_6X6 ? 6 : 4); }

void veil_spread_default_weights(veil_spread_filter f, float w[6])
{
    memset(w, 0, 6 * sizeof *w);
    if (f == VEIL_SPREAD_2X2) {
        w[0] = w[1] = 0.5f; /* a box: the plain MIP average */
    } else if (f == VEIL_SPREAD_4X4) {
        /* the paper's taps (Elek et al. 2013) */
        w[0] = w[3] = 0.13f;
        w[1] = w[2] = 0.37f;
    } else {
        /* a unit-variance Gaussian sampled at +-0.5, +-1.5, +-2.5 pixels,
         * normalised: exp(-x^2/2) = 0.8825, 0.3247, 0.0439 over 2.5022 */
        w[0] = w[5] = 0.0175f;
        w[1] = w[4] = 0.1298f;
        w[2] = w[3] = 0.3527f;
    }
}

void veil_multiple_defaults(veil_multiple* m)
{
    memset(m, 0, sizeof *m);
    m->screen_space = 1;
    m->volumetric = 1;
    m->volumetric_method = VEIL_VOLUMETRIC_CACHE;
    m->diffusion_cells = 64;
    m->diffusion_iterations = 0;
    m->cache_photons = 0;
    m->cache_cells = 0;
    m->cache_gather_rays = 0;
    m->cache_seed = 1;
    m->c = 0.86f;
    m->mask_epsilon = 2.0f;
    m->mask = 1;
    m->luminance_weighting = 1;
    m->density_blur = 1;
    m->levels = 0;
    m->filter = VEIL_SPREAD_4X4;
    veil_spread_default_weights(m->filter, m->weights);
    m->interp = VEIL_INTERP_LINEAR_BICUBIC;
    m->separation = 0;
    /* the paper states no values for these: a pixel counts as bright from
     * 10x the luminance of a white surface lit at 1 W/m^2 (1/pi), and as
     * clear when its integrated density is below 1 density-metre */
    m->sep_luminance = 3.0f;
    m->sep_luminance_width = 3.0f;
    m->sep_density = 1.0f;
    m->sep_density_width = 0.5f;
    m->k_ssc = 0.7f;
    m->thin_threshold = 1e-3f;
    /* fitted on data/scenes fog_lights, demo, cloud, vdb_smoke, each at 1x and 3x density
     * (bench/multiple_scattering_fit.py;
     * docs/multiple-scattering.md has the grid, the fit and the check on scenes it never saw) */
    m->octaves = 10;
    m->emission_lights = 8;
    m->octave_a = 0.3f;
    m->octave_b = 0.9f;
    m->octave_c = 0.7f;
    m->octave_gate = VEIL_GATE_ESCAPE;
}

static const char* const quality_names[VEIL_QUALITY_COUNT] = {NULL, "draft", "default", "high", "max"};

const char* veil_quality_name(veil_quality q)
{
    return (unsigned)q < VEIL_QUALITY_COUNT ? quality_names[q] : NULL;
}

int veil_quality_parse(const char* name, veil_quality* out)
{
    for (int q = 1; q < VEIL_QUALITY_COUNT; ++q)
        if (!strcmp(name, quality_names[q])) {
            *out = (veil_quality)q;
            return 1;
        }
    return 0;
}

int veil_scene_is_sequence(const veil_scene* s)
{
    for (size_t i = 0; i < s->medium.source_count; ++i)
        if (s->medium.sources[i].type == VEIL_SOURCE_VDB && s->medium.sources[i].vdb.sequence) return 1;
    return 0;
}

veil_result veil_scene_set_frame(veil_scene* s, long frame, veil_error* err)
{
    for (size_t i = 0; i < s->medium.source_count; ++i) {
        veil_vdb_source* v = &s->medium.sources[i].vdb;
        if (s->medium.sources[i].type != VEIL_SOURCE_VDB || !v->sequence) continue;
        char path[4096];
        long f = frame + v->frame_offset;
        veil_result r = veil_frame_pattern_path(v->sequence, f, path, sizeof path, err);
        if (r != VEIL_OK) return r;
        FILE* fp = fopen(path, "rb");
        if (!fp)
            return veil_fail(err, VEIL_ERR_IO, "medium.sources[%zu].file: frame %ld: cannot open '%s': %s", i, frame,
                             path, strerror(errno));
        fclose(fp);
        size_t len = strlen(path) + 1;
        char* copy = malloc(len);
        if (copy) memcpy(copy, path, len);
        if (!copy) return veil_fail(err, VEIL_ERR_OOM, "out of memory");
        free(v->file);
        v->file = copy;
    }
    return VEIL_OK;
}

size_t veil_scene_files(const veil_scene* s, veil_scene_file* out, size_t n)
{
    size_t k = 0;
    for (size_t i = 0; i < s->medium.source_count; ++i) {
        const veil_source* src = &s->medium.sources[i];
        veil_scene_file f = {.path = NULL};
        if (src->type == VEIL_SOURCE_VDB && src->vdb.sequence)
            f.path = src->vdb.sequence, f.sequence = 1, f.frame_offset = src->vdb.frame_offset;
        else if (src->type == VEIL_SOURCE_VDB)
            f.path = src->vdb.file;
        else if (src->type == VEIL_SOURCE_RBF)
            f.path = src->particle_file;
        if (!f.path) continue;
        snprintf(f.field, sizeof f.field, "medium.sources[%zu].file", i);
        if (k < n) out[k] = f;
        ++k;
    }
    if (s->environment.present && s->environment.file) { /* issue 41: the map is an input as any other */
        veil_scene_file f = {.path = s->environment.file};
        snprintf(f.field, sizeof f.field, "lights[%zu].file", s->environment.light_index);
        if (k < n) out[k] = f;
        ++k;
    }
    return k;
}

veil_result veil_scene_file_at(const veil_scene_file* f, long frame, char* out, size_t n, veil_error* err)
{
    if (f->sequence) return veil_frame_pattern_path(f->path, frame + f->frame_offset, out, n, err);
    size_t len = strlen(f->path);
    if (len >= n) return veil_fail(err, VEIL_ERR_LIMIT, "'%s': the name is too long", f->path);
    memcpy(out, f->path, len + 1);
    return VEIL_OK;
}
