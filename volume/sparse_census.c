/* veil — a sparse volume's bricks counted before they are gathered, and
 * the frame's work estimated on them by walking the shaders' own rays
 * (sparse.h: the census, the estimate and their budgets). */
#include "sparse.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/rng.h"
#include "scene_volume.h"
#include "vdb_volume.h"

#define B VEIL_BRICK
#define N VEIL_SPARSE_NODE

/* ---- the census (sparse.h) ---------------------------------------------- */

/* 1: brick b was added, 0: it was there, -1: out of memory. */
static int census_add(veil_sparse_census* c, const int b[3])
{
    if (2 * (c->count + 1) > c->key_cap) {
        size_t cap = c->key_cap ? 2 * c->key_cap : 1024;
        uint64_t* keys = calloc(cap, sizeof *keys);
        if (!keys) return -1;
        for (size_t i = 0; i < c->key_cap; ++i) {
            if (!c->keys[i]) continue;
            size_t j = (size_t)veil_mix64(c->keys[i]) & (cap - 1);
            while (keys[j]) j = (j + 1) & (cap - 1);
            keys[j] = c->keys[i];
        }
        free(c->keys);
        c->keys = keys, c->key_cap = cap;
    }
    uint64_t key = veil__sparse_pack(b);
    size_t i = (size_t)veil_mix64(key) & (c->key_cap - 1);
    while (c->keys[i] && c->keys[i] != key) i = (i + 1) & (c->key_cap - 1);
    if (c->keys[i]) return 0;
    c->keys[i] = key;
    ++c->count;
    return 1;
}

static int census_has(const veil_sparse_census* c, const int b[3])
{
    for (int a = 0; a < 3; ++a)
        if (b[a] < 0 || b[a] >= c->brick_dims[a]) return 0;
    size_t n = (size_t)(b[0] / N) + (size_t)c->top[0] * ((size_t)(b[1] / N) + (size_t)c->top[1] * (size_t)(b[2] / N));
    if (!(c->node_bits[n / 8] >> (n % 8) & 1)) return 0;
    uint64_t key = veil__sparse_pack(b);
    for (size_t i = (size_t)veil_mix64(key) & (c->key_cap - 1);; i = (i + 1) & (c->key_cap - 1)) {
        if (c->keys[i] == key) return 1;
        if (!c->keys[i]) return 0;
    }
}

typedef struct census_walk {
    veil_sparse_census* c;
    int off[3];
    int bricks;   /* 1: the grid makes bricks (density, emission); 0: a temperature grid */
    int oom;
} census_walk;

/* The bricks of the grid box [lo, hi] (VDB index) on the sparse grid: lo[a]..hi[a] of each axis, clipped; 0 when none. */
static double box_bricks(const census_walk* w, const int lo[3], const int hi[3], int blo[3], int bhi[3])
{
    double n = 1.0;
    for (int a = 0; a < 3; ++a) {
        long long l = (long long)lo[a] + w->off[a], h = (long long)hi[a] + w->off[a];
        if (l < 0) l = 0;
        if (h > w->c->dims[a] - 1) h = w->c->dims[a] - 1;
        if (h < l) return 0.0;
        blo[a] = (int)(l / B), bhi[a] = (int)(h / B);
        n *= (double)(bhi[a] - blo[a] + 1);
    }
    return n;
}

/* Leaves: their bricks into the set. Tiles: counted (added when the total stays under the cap). */
static int census_box(void* user, const int lo[3], const int hi[3], uint64_t voxels, int tile)
{
    census_walk* w = user;
    veil_sparse_census* c = w->c;
    if (tile) ++c->tiles, c->tile_voxels += (double)voxels;
    else ++c->leaves, c->leaf_voxels += voxels;
    if ((double)c->leaf_voxels + c->tile_voxels > (double)VEIL_SPARSE_MAX_BRICKS * (B * B * B)) {
        /* more voxels to visit one by one than the cap's bricks hold (a temperature grid's tiles make no brick) */
        c->bricks = fmax(c->bricks, ((double)c->leaf_voxels + c->tile_voxels) / (B * B * B));
        c->over = 1;
        return 0;
    }
    if (!w->bricks) return 1;
    int blo[3], bhi[3];
    double n = box_bricks(w, lo, hi, blo, bhi);
    if (n == 0.0) return 1;
    if ((double)c->count + n > (double)VEIL_SPARSE_MAX_BRICKS) { /* past the cap: counted, not enumerated */
        c->bricks = (double)c->count + n;
        c->over = 1;
        return 0;
    }
    for (int z = blo[2]; z <= bhi[2]; ++z)
        for (int y = blo[1]; y <= bhi[1]; ++y)
            for (int x = blo[0]; x <= bhi[0]; ++x) {
                const int b[3] = {x, y, z};
                if (census_add(c, b) < 0) {
                    w->oom = 1;
                    return 0;
                }
            }
    c->bricks = (double)c->count;
    return 1;
}

void veil_sparse_census_free(veil_sparse_census* c)
{
    if (!c) return;
    free(c->coords);
    free(c->keys);
    free(c->node_bits);
    memset(c, 0, sizeof *c);
}

veil_result veil_sparse_census_of(const veil_scene_volume* v, veil_sparse_census* out, veil_error* err)
{
    memset(out, 0, sizeof *out);
    const veil_grid* g = &v->grid;
    for (int a = 0; a < 3; ++a) {
        if (g->dims[a] > VEIL_SPARSE_MAX_SIDE)
            return veil_fail(err, VEIL_ERR_LIMIT, "a sparse volume of %dx%dx%d voxels: at most %d a side", g->dims[0],
                             g->dims[1], g->dims[2], VEIL_SPARSE_MAX_SIDE);
        out->dims[a] = g->dims[a];
        out->brick_dims[a] = (g->dims[a] + B - 1) / B;
        out->top[a] = (out->brick_dims[a] + N - 1) / N;
    }
    veil_result r = VEIL_OK;
    census_walk w = {.c = out};
    /* the grids the gather reads, in its order: the densities, then the emission and temperature grids */
    for (int i = 0; i < v->vdb_count + v->emission_count && r == VEIL_OK && !out->over; ++i) {
        const veil_vdb* grid = i < v->vdb_count ? v->vdbs[i] : v->emission[i - v->vdb_count].grid;
        if (i < v->vdb_count && !(v->vdb_scale[i] > 0.0f)) continue;
        w.bricks = i < v->vdb_count || !v->emission[i - v->vdb_count].temperature;
        r = veil__sparse_offset_of(v, grid, w.off, err);
        if (r == VEIL_OK) r = veil_vdb_each_box(grid, census_box, &w, err);
        if (r == VEIL_OK && w.oom) r = veil_fail(err, VEIL_ERR_OOM, "out of memory counting the sparse volume's bricks");
        if (out->over) out->worst = veil_vdb_path(grid);
    }
    if (r == VEIL_OK && !out->over) { /* the lookups the estimate walks */
        size_t nodes = (size_t)out->top[0] * (size_t)out->top[1] * (size_t)out->top[2];
        out->node_bits = calloc(nodes / 8 + 1, 1);
        out->coords = malloc((out->count ? out->count : 1) * 4 * sizeof *out->coords);
        if (!out->node_bits || !out->coords) r = veil_fail(err, VEIL_ERR_OOM, "out of memory for the sparse census");
        size_t k = 0;
        for (size_t i = 0; r == VEIL_OK && i < out->key_cap; ++i) {
            if (!out->keys[i]) continue;
            uint64_t key = out->keys[i] - 1;
            int32_t* b = out->coords + 4 * k++;
            b[0] = (int32_t)(key & 0x1fffff), b[1] = (int32_t)(key >> 21 & 0x1fffff), b[2] = (int32_t)(key >> 42 & 0x1fffff);
            b[3] = 0;
            size_t n = (size_t)(b[0] / N) + (size_t)out->top[0] * ((size_t)(b[1] / N) + (size_t)out->top[1] * (size_t)(b[2] / N));
            out->node_bits[n / 8] |= (uint8_t)(1u << (n % 8));
        }
    }
    if (r == VEIL_OK && out->over) { /* nothing to walk */
        free(out->keys);
        out->keys = NULL, out->key_cap = 0, out->count = 0;
    }
    if (r != VEIL_OK) veil_sparse_census_free(out);
    return r;
}

/* ---- the shaders' rays on the census (the work estimate, sparse.h) ------ */

static int node_holds(const veil_sparse_census* c, const int b[3])
{
    size_t n = (size_t)(b[0] / N) + (size_t)c->top[0] * ((size_t)(b[1] / N) + (size_t)c->top[1] * (size_t)(b[2] / N));
    return c->node_bits[n / 8] >> (n % 8) & 1;
}

/* Distance along d from p to where it leaves the cube of `region` bricks
 * that holds brick b (sparse_common.glsl's sp_region_exit; ahead: its
 * sp_region_exit_ahead, where a face p sits on does not end it). */
static double region_exit(const double p[3], const double d[3], const int b[3], int region, int ahead)
{
    double t = HUGE_VAL;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0) continue;
        double lo = (double)(b[a] / region * region * B) + 0.5, hi = lo + (double)(region * B);
        double ta = ((d[a] > 0.0 ? hi : lo) - p[a]) / d[a];
        if (ahead && !(ta > 0.0)) continue;
        t = fmin(t, fmax(ta, 0.0));
    }
    return t;
}

/* The loop of sp_integral (volume/shaders/sparse_common.glsl) along q + t d,
 * t in [t0, t1] within the box of voxel centres, on the census's bricks:
 * its steps (a region each: a node without bricks, else a brick) plus its
 * samples (every h voxels in a kept brick). stop: end on entering a kept
 * brick (propagate_sparse.comp's walk past its own brick). */
static double ray_units(const veil_sparse_census* c, const double q[3], const double d[3], double t0, double t1,
                        double h, int stop)
{
    double s0 = t0, s1 = t1;
    for (int a = 0; a < 3; ++a) { /* box_hit with [0.5, dims - 0.5] */
        double lo = 0.5, hi = (double)c->dims[a] - 0.5;
        if (d[a] == 0.0) {
            if (q[a] < lo || q[a] > hi) return 0.0;
            continue;
        }
        double ta = (lo - q[a]) / d[a], tb = (hi - q[a]) / d[a];
        s0 = fmax(s0, fmin(ta, tb));
        s1 = fmin(s1, fmax(ta, tb));
    }
    double units = 0.0, t = s0;
    /* a ray crosses at most every brick of each axis once (and the guard keeps a rounding loop finite) */
    long long guard = 4LL * ((long long)c->brick_dims[0] + c->brick_dims[1] + c->brick_dims[2]) + 16;
    while (t < s1 && guard-- > 0) {
        double ahead = fmax(1e-3, 4.8e-7 * t), p[3];
        int b[3];
        for (int a = 0; a < 3; ++a) {
            p[a] = q[a] + d[a] * t;
            b[a] = (int)floor((q[a] + d[a] * (t + ahead) - 0.5) / B);
        }
        int inside = b[0] >= 0 && b[1] >= 0 && b[2] >= 0 && b[0] < c->brick_dims[0] && b[1] < c->brick_dims[1] &&
                     b[2] < c->brick_dims[2];
        int kept = inside && census_has(c, b);
        int region = inside && !node_holds(c, b) ? N : 1;
        double te = fmin(t + fmax(region_exit(p, d, b, region, 1), ahead), s1);
        units += 1.0;
        if (kept) {
            if (stop) return units;
            units += ceil((te - t) / h);
        }
        t = te;
    }
    return units;
}

/* Up to VEIL_SPARSE_ESTIMATE_BRICKS of the census's bricks, spread over its list (a hash's order). */
static size_t sampled(const veil_sparse_census* c, size_t k)
{
    size_t n = c->count < VEIL_SPARSE_ESTIMATE_BRICKS ? c->count : VEIL_SPARSE_ESTIMATE_BRICKS;
    return n ? k * c->count / n : 0;
}

static size_t sample_count(const veil_sparse_census* c)
{
    return c->count < VEIL_SPARSE_ESTIMATE_BRICKS ? c->count : VEIL_SPARSE_ESTIMATE_BRICKS;
}

double veil_sparse_od_units(const veil_sparse_census* c, const veil_index_light* l)
{
    size_t n = sample_count(c);
    if (!n || c->over) return 0.0;
    double sum = 0.0;
    for (size_t k = 0; k < n; ++k) {
        const int32_t* b = c->coords + 4 * sampled(c, k);
        /* the brick's middle texel (voxel 8b + 4, at 8b + 4.5), as propagate_sparse.comp */
        double q[3], d[3], len = HUGE_VAL, norm = 0.0;
        for (int a = 0; a < 3; ++a) {
            q[a] = (double)b[a] * B + 4.5;
            d[a] = l->type == VEIL_LIGHT_DIRECTIONAL ? (double)l->v[a] : (double)l->v[a] + 0.5 - q[a];
            norm += d[a] * d[a];
        }
        norm = sqrt(norm);
        if (!(norm > 0.0)) continue;
        for (int a = 0; a < 3; ++a) d[a] /= norm;
        if (l->type != VEIL_LIGHT_DIRECTIONAL) len = norm;
        /* its own brick at VEIL_SPARSE_OD_STEP, then the walk to the first kept brick */
        const int own[3] = {b[0], b[1], b[2]};
        double t = fmin(region_exit(q, d, own, 1, 0), len);
        sum += ceil(t / VEIL_SPARSE_OD_STEP) + 1.0 + ray_units(c, q, d, t, len, 1.0, 1);
    }
    return sum / (double)n;
}

double veil_sparse_escape_units(const veil_sparse_census* c)
{
    size_t n = sample_count(c);
    if (!n || c->over) return 0.0;
    double sum = 0.0;
    for (size_t k = 0; k < n; ++k) {
        const int32_t* b = c->coords + 4 * sampled(c, k);
        double q[3];
        for (int a = 0; a < 3; ++a) q[a] = (double)b[a] * B + 4.5;
        /* escape.comp's 14 directions: the 6 axes and the 8 diagonals, to the box's edge at a step a voxel */
        for (int dir = 0; dir < 14; ++dir) {
            double d[3] = {0, 0, 0};
            if (dir < 6) d[dir / 2] = dir & 1 ? -1.0 : 1.0;
            else
                for (int a = 0; a < 3; ++a) d[a] = ((dir - 6) >> a & 1 ? -1.0 : 1.0) / sqrt(3.0);
            sum += ray_units(c, q, d, 0.0, HUGE_VAL, 1.0, 0);
        }
    }
    return sum / ((double)n * 14.0);
}

veil_result veil_sparse_work_check(veil_sparse_work* w, veil_error* err)
{
    w->seconds = VEIL_SPARSE_PASS_SECONDS * w->passes +
                 VEIL_SPARSE_UNIT_SECONDS * (w->od_rays * w->od_units + w->escape_rays * w->escape_units);
    if (!(w->seconds > VEIL_SPARSE_MAX_SECONDS)) return VEIL_OK;
    return veil_fail(err, VEIL_ERR_LIMIT,
                     "a sparse volume of %.0f bricks over a %dx%dx%d box asks for about %.0f s of a CPU driver's time "
                     "(%.0f optical-depth passes and %.3g texel rays of %.0f steps for %d light%s, %.3g escape-field "
                     "rays of %.0f steps), over the budget of %.0f s (VEIL_SPARSE_MAX_SECONDS); crop the grid, set "
                     "medium.max_resolution to resample it, or turn multiple_scattering.volumetric off",
                     w->bricks, w->dims[0], w->dims[1], w->dims[2], w->seconds, w->passes, w->od_rays, w->od_units,
                     w->lights, w->lights == 1 ? "" : "s", w->escape_rays, w->escape_units,
                     (double)VEIL_SPARSE_MAX_SECONDS);
}

veil_result veil_sparse_census_check(const veil_sparse_census* c, veil_error* err)
{
    if (!c->over) return VEIL_OK;
    return veil_fail(err, VEIL_ERR_LIMIT,
                     "%s: a sparse volume of at least %.0f bricks (8^3 voxels each) counted over %llu active tiles of %.4g "
                     "voxels and %llu leaves of %llu voxels: at most %zu bricks (VEIL_SPARSE_MAX_BRICKS); crop the grid, "
                     "or set medium.max_resolution to resample it", c->worst ? c->worst : "the grids", c->bricks,
                     (unsigned long long)c->tiles, c->tile_voxels, (unsigned long long)c->leaves,
                     (unsigned long long)c->leaf_voxels, (size_t)VEIL_SPARSE_MAX_BRICKS);
}

