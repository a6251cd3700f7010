#include "sparse.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/rng.h"
#include "scene_volume.h"
#include "vdb_volume.h"

#define B VEIL_BRICK
#define A VEIL_SPARSE_APRON
#define N VEIL_SPARSE_NODE

/* ---- the bricks while they are gathered: a hash of brick -> slot ------- */

typedef struct gather {
    uint64_t* keys;  /* packed brick + 1, 0: empty */
    uint32_t* slots;
    size_t cap;      /* a power of two */
    float* data;     /* 512 floats a slot, x fastest */
    float* edata;    /* with emission: 3 x 512 floats a slot, eps per channel, channel-major per slot */
    float* one;      /* with emission: 512 floats a slot, one emission grid's values while it is read */
    int emission;    /* 1: edata and one are kept */
    int create;      /* 1: a voxel of a brick not kept makes it (0: only kept bricks take values) */
    float* into;     /* what add_voxel adds to: data or one */
    int32_t* coords; /* 4 ints a slot */
    size_t count, data_cap;
    int bricks[3], dims[3];
    int off[3];      /* this source: grid voxel = VDB index + off */
    float scale;
    int keep_negative; /* 1: a temperature grid's values (else below 0 reads 0: scene/limits.h) */
    uint64_t last_key; /* the last brick found, and its slot (voxels come leaf by leaf) */
    uint32_t last_slot;
    size_t voxels;
    int oom;
} gather;

static uint64_t pack(const int b[3])
{
    return ((uint64_t)(uint32_t)b[0] | (uint64_t)(uint32_t)b[1] << 21 | (uint64_t)(uint32_t)b[2] << 42) + 1;
}

static size_t bucket(const gather* g, uint64_t key)
{
    return (size_t)veil_mix64(key) & (g->cap - 1);
}

/* Slot + 1 of brick b, 0 when absent. */
static uint32_t find(const gather* g, const int b[3])
{
    for (int a = 0; a < 3; ++a)
        if (b[a] < 0 || b[a] >= g->bricks[a]) return 0;
    uint64_t key = pack(b);
    for (size_t i = bucket(g, key);; i = (i + 1) & (g->cap - 1)) {
        if (g->keys[i] == key) return g->slots[i] + 1;
        if (!g->keys[i]) return 0;
    }
}

static int rehash(gather* g, size_t cap)
{
    uint64_t* keys = calloc(cap, sizeof *keys);
    uint32_t* slots = malloc(cap * sizeof *slots);
    if (!keys || !slots) {
        free(keys);
        free(slots);
        return 0;
    }
    gather n = *g;
    n.keys = keys, n.slots = slots, n.cap = cap;
    for (size_t i = 0; i < g->cap; ++i) {
        if (!g->keys[i]) continue;
        size_t j = bucket(&n, g->keys[i]);
        while (keys[j]) j = (j + 1) & (cap - 1);
        keys[j] = g->keys[i], slots[j] = g->slots[i];
    }
    free(g->keys);
    free(g->slots);
    g->keys = keys, g->slots = slots, g->cap = cap;
    return 1;
}

/* Slot of brick b (in the grid), made (zeroed) when absent; -1 out of memory. */
static long long get(gather* g, const int b[3])
{
    uint64_t key = pack(b);
    if (key == g->last_key) return g->last_slot;
    if (2 * (g->count + 1) > g->cap && !rehash(g, 2 * g->cap)) return -1;
    size_t i = bucket(g, key);
    while (g->keys[i] && g->keys[i] != key) i = (i + 1) & (g->cap - 1);
    if (!g->keys[i]) {
        if (g->count == g->data_cap) {
            size_t cap = g->data_cap ? 2 * g->data_cap : 1024;
            float* d = realloc(g->data, cap * B * B * B * sizeof *d);
            if (!d) return -1;
            g->data = d;
            if (g->emission) {
                float* e = realloc(g->edata, cap * 3 * B * B * B * sizeof *e);
                if (!e) return -1;
                g->edata = e;
                float* o = realloc(g->one, cap * B * B * B * sizeof *o);
                if (!o) return -1;
                g->one = o;
            }
            int32_t* c = realloc(g->coords, cap * 4 * sizeof *c);
            if (!c) return -1;
            g->coords = c;
            g->data_cap = cap;
        }
        memset(g->data + g->count * B * B * B, 0, B * B * B * sizeof *g->data);
        if (g->emission) {
            memset(g->edata + g->count * 3 * B * B * B, 0, 3 * B * B * B * sizeof *g->edata);
            memset(g->one + g->count * B * B * B, 0, B * B * B * sizeof *g->one);
        }
        for (int a = 0; a < 3; ++a) g->coords[4 * g->count + a] = b[a];
        g->coords[4 * g->count + 3] = 0;
        g->keys[i] = key, g->slots[i] = (uint32_t)g->count++;
    }
    g->last_key = key, g->last_slot = g->slots[i];
    return g->slots[i];
}

static void add_voxel(void* user, const int ijk[3], float value)
{
    gather* g = user;
    if (value < 0.0f && !g->keep_negative) return; /* reads 0: adds nothing, makes no brick */
    int t[3], b[3];
    for (int a = 0; a < 3; ++a) {
        t[a] = ijk[a] + g->off[a];
        if (t[a] < 0 || t[a] >= g->dims[a]) return; /* the grid covers every support: not reached */
        b[a] = t[a] / B;
    }
    long long s;
    if (g->create) {
        s = get(g, b);
        if (s < 0) {
            g->oom = 1;
            return;
        }
    } else {
        uint32_t k = find(g, b);
        if (!k) return;
        s = (long long)k - 1;
    }
    float* into = g->into ? g->into : g->data;
    into[(size_t)s * B * B * B + (size_t)(t[0] % B) + B * ((size_t)(t[1] % B) + B * (size_t)(t[2] % B))] +=
        g->scale * value;
    g->voxels += into == g->data;
}

/* The voxel at grid index t: 0 outside the grid or in a brick not kept. */
static float voxel_at(const gather* g, const int t[3])
{
    int b[3];
    for (int a = 0; a < 3; ++a) {
        if (t[a] < 0 || t[a] >= g->dims[a]) return 0.0f;
        b[a] = t[a] / B;
    }
    uint32_t s = find(g, b);
    if (!s) return 0.0f;
    return g->data[(size_t)(s - 1) * B * B * B + (size_t)(t[0] % B) + B * ((size_t)(t[1] % B) + B * (size_t)(t[2] % B))];
}

/* The emission at grid index t into eps (0 where voxel_at is 0 too). */
static void emission_at(const gather* g, const int t[3], float eps[3])
{
    eps[0] = eps[1] = eps[2] = 0.0f;
    int b[3];
    for (int a = 0; a < 3; ++a) {
        if (t[a] < 0 || t[a] >= g->dims[a]) return;
        b[a] = t[a] / B;
    }
    uint32_t s = find(g, b);
    if (!s) return;
    size_t k = (size_t)(t[0] % B) + B * ((size_t)(t[1] % B) + B * (size_t)(t[2] % B));
    for (int c = 0; c < 3; ++c) eps[c] = g->edata[(size_t)(s - 1) * 3 * B * B * B + (size_t)c * B * B * B + k];
}

static veil_result offset_of(const veil_scene_volume* v, const veil_vdb* vdb, int off[3], veil_error* err);

/* Adds the scene's emission sources to the bricks: each grid's values read
 * into `one` (an emission grid makes the bricks it reaches; a temperature
 * grid emits only where there is density, so only kept bricks take it),
 * then eps per voxel as the dense path forms it (veil_emission_eps). */
static veil_result gather_emission(const veil_scene_volume* v, gather* g, veil_error* err)
{
    double* table = veil_emission_table();
    if (!table) return veil_fail(err, VEIL_ERR_OOM, "out of memory for the blackbody table");
    veil_result r = VEIL_OK;
    for (int i = 0; i < v->emission_count && r == VEIL_OK; ++i) {
        const veil_emission_source* es = &v->emission[i];
        memset(g->one, 0, g->count * B * B * B * sizeof *g->one);
        g->into = g->one, g->scale = 1.0f, g->create = !es->temperature, g->last_key = 0;
        g->keep_negative = es->temperature;
        r = offset_of(v, es->grid, g->off, err);
        if (r == VEIL_OK) r = veil_vdb_each_voxel(es->grid, add_voxel, g, err);
        if (r == VEIL_OK && g->oom) r = veil_fail(err, VEIL_ERR_OOM, "out of memory for the sparse volume's bricks");
        for (size_t s = 0; s < g->count && r == VEIL_OK; ++s)
            for (size_t k = 0; k < B * B * B; ++k) {
                float eps[3];
                veil_emission_eps(v, es, table, g->one[s * B * B * B + k], g->data[s * B * B * B + k], eps);
                for (int c = 0; c < 3; ++c) g->edata[s * 3 * B * B * B + (size_t)c * B * B * B + k] += eps[c];
            }
    }
    g->into = NULL, g->create = 1, g->last_key = 0, g->keep_negative = 0;
    free(table);
    return r;
}

/* The whole-voxel offset of VDB i on the grid (VEIL_ERR_INVALID when its
 * voxels do not lie on the grid's: volume/scene_volume.c checks first). */
static veil_result offset_of(const veil_scene_volume* v, const veil_vdb* vdb, int off[3], veil_error* err)
{
    double edge, origin[3];
    int aligned;
    const veil_grid* g = &v->grid;
    if (!veil_vdb_lattice(vdb, &edge, origin, &aligned) || !aligned ||
        fabs(edge - g->voxel) > VEIL_VDB_ALIGN_TOL * g->voxel)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: its voxels are not the sparse grid's", veil_vdb_path(vdb));
    for (int a = 0; a < 3; ++a) {
        /* VDB index k sits at origin + k edge; grid voxel j's centre at g->origin + (j + 0.5) voxel */
        double o = (origin[a] - g->origin[a]) / g->voxel - 0.5;
        double r = floor(o + 0.5);
        if (fabs(o - r) > 4 * VEIL_VDB_ALIGN_TOL)
            return veil_fail(err, VEIL_ERR_INVALID, "%s: its voxels are off the sparse grid's by %.3g voxel",
                             veil_vdb_path(vdb), fabs(o - r));
        off[a] = (int)r;
    }
    return VEIL_OK;
}

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
    uint64_t key = pack(b);
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
    uint64_t key = pack(b);
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
        r = offset_of(v, grid, w.off, err);
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

void veil_sparse_free(veil_sparse* s)
{
    if (!s) return;
    free(s->top_table);
    free(s->nodes);
    free(s->coords);
    free(s->texels);
    free(s->emission_texels);
    free(s->emitters);
    memset(s, 0, sizeof *s);
}

void veil_sparse_atlas_texels(const veil_sparse* s, int out[3])
{
    for (int a = 0; a < 3; ++a) out[a] = A * s->atlas[a];
}

size_t veil_sparse_bytes(const veil_sparse* s)
{
    int t[3];
    veil_sparse_atlas_texels(s, t);
    size_t top = (size_t)s->top[0] * (size_t)s->top[1] * (size_t)s->top[2];
    return (size_t)t[0] * (size_t)t[1] * (size_t)t[2] * (s->emission_texels ? 5 : 1) * sizeof(float) + top * 4 +
           s->node_count * VEIL_SPARSE_NODE_BRICKS * 4 + s->count * 16;
}

uint32_t veil_sparse_slot(const veil_sparse* s, const int b[3])
{
    for (int a = 0; a < 3; ++a)
        if (b[a] < 0 || b[a] >= s->bricks[a]) return 0;
    size_t t = (size_t)(b[0] / N) + (size_t)s->top[0] * ((size_t)(b[1] / N) + (size_t)s->top[1] * (size_t)(b[2] / N));
    uint32_t node = s->top_table[t];
    if (!node) return 0;
    return s->nodes[(size_t)(node - 1) * VEIL_SPARSE_NODE_BRICKS + (size_t)(b[0] % N) +
                    N * ((size_t)(b[1] % N) + N * (size_t)(b[2] % N))];
}

float veil_sparse_sample(const veil_sparse* s, const float q[3])
{
    float p[3], f[3];
    int b[3], i0[3], t[3];
    for (int a = 0; a < 3; ++a) {
        p[a] = q[a] - 0.5f;
        b[a] = (int)floorf(p[a] / (float)B);
    }
    uint32_t slot = veil_sparse_slot(s, b);
    if (!slot) return 0.0f;
    size_t k = slot - 1;
    int corner[3] = {(int)(k % (size_t)s->atlas[0]) * A, (int)(k / (size_t)s->atlas[0] % (size_t)s->atlas[1]) * A,
                     (int)(k / ((size_t)s->atlas[0] * (size_t)s->atlas[1])) * A};
    veil_sparse_atlas_texels(s, t);
    for (int a = 0; a < 3; ++a) {
        float local = p[a] - (float)(B * b[a]); /* [0, 8) */
        i0[a] = (int)floorf(local);
        if (i0[a] > B - 1) i0[a] = B - 1; /* rounding at the brick's top */
        f[a] = local - (float)i0[a];
    }
    float sum = 0.0f;
    for (int c = 0; c < 8; ++c) {
        float w = 1.0f;
        size_t idx = 0, stride = 1;
        for (int a = 0; a < 3; ++a) {
            int up = (c >> a) & 1;
            w *= up ? f[a] : 1.0f - f[a];
            idx += stride * (size_t)(corner[a] + i0[a] + up);
            stride *= (size_t)t[a];
        }
        sum += w * s->texels[idx];
    }
    return sum;
}

void veil_sparse_block_fill(const veil_sparse* s, veil_sparse_block* out)
{
    memset(out, 0, sizeof *out);
    int t[3];
    veil_sparse_atlas_texels(s, t);
    for (int a = 0; a < 3; ++a) {
        out->bricks[a] = s->bricks[a];
        out->top[a] = s->top[a];
        out->atlas[a] = s->atlas[a];
        out->origin[a] = s->grid.origin[a];
        out->inv_atlas[a] = 1.0f / (float)t[a];
        out->dims[a] = (float)s->grid.dims[a];
    }
    out->bricks[3] = (int32_t)s->count;
    out->origin[3] = s->grid.voxel;
}

/* Keeps the bricks below each kept brick whose interpolation cells reach
 * its non-zero voxels on its low faces (module comment). */
static veil_result dilate(gather* g, veil_error* err)
{
    size_t own = g->count;
    for (size_t s = 0; s < own; ++s) {
        unsigned need = 0; /* bit d: the brick at -(d & 1, d >> 1 & 1, d >> 2 & 1) */
        const float* d = g->data + s * B * B * B;
        for (int z = 0; z < B; ++z)
            for (int y = 0; y < B; ++y)
                for (int x = 0; x < B; ++x) {
                    if (x && y && z) continue;
                    size_t k = (size_t)(x + B * (y + B * z));
                    const float* e = g->emission ? g->edata + s * 3 * B * B * B + k : NULL;
                    if (d[k] == 0.0f && (!e || (e[0] == 0.0f && e[B * B * B] == 0.0f && e[2 * B * B * B] == 0.0f)))
                        continue;
                    unsigned m = (x == 0) | (y == 0) << 1 | (z == 0) << 2;
                    for (unsigned bits = 1; bits < 8; ++bits)
                        if ((bits & m) == bits) need |= 1u << bits;
                }
        for (unsigned bits = 1; bits < 8; ++bits) {
            if (!(need >> bits & 1)) continue;
            int b[3];
            for (int a = 0; a < 3; ++a) b[a] = g->coords[4 * s + (size_t)a] - (int)(bits >> a & 1);
            if (b[0] < 0 || b[1] < 0 || b[2] < 0 || find(g, b)) continue;
            g->last_key = 0;
            if (get(g, b) < 0) return veil_fail(err, VEIL_ERR_OOM, "out of memory for the sparse volume's bricks");
        }
    }
    return VEIL_OK;
}

static veil_result tables(veil_sparse* out, veil_error* err)
{
    size_t top = (size_t)out->top[0] * (size_t)out->top[1] * (size_t)out->top[2];
    out->top_table = calloc(top, sizeof *out->top_table);
    if (!out->top_table) return veil_fail(err, VEIL_ERR_OOM, "out of memory for a %zu-node table", top);
    size_t cap = 0;
    for (size_t s = 0; s < out->count; ++s) {
        const int32_t* b = out->coords + 4 * s;
        size_t t = (size_t)(b[0] / N) + (size_t)out->top[0] * ((size_t)(b[1] / N) + (size_t)out->top[1] * (size_t)(b[2] / N));
        if (!out->top_table[t]) {
            if (out->node_count == cap) {
                cap = cap ? 2 * cap : 16;
                uint32_t* n = realloc(out->nodes, cap * VEIL_SPARSE_NODE_BRICKS * sizeof *n);
                if (!n) return veil_fail(err, VEIL_ERR_OOM, "out of memory for the sparse volume's nodes");
                out->nodes = n;
            }
            memset(out->nodes + out->node_count * VEIL_SPARSE_NODE_BRICKS, 0,
                   VEIL_SPARSE_NODE_BRICKS * sizeof *out->nodes);
            out->top_table[t] = (uint32_t)++out->node_count;
        }
        out->nodes[(size_t)(out->top_table[t] - 1) * VEIL_SPARSE_NODE_BRICKS + (size_t)(b[0] % N) +
                   N * ((size_t)(b[1] % N) + N * (size_t)(b[2] % N))] = (uint32_t)(s + 1);
    }
    return VEIL_OK;
}

veil_result veil_sparse_build(const veil_scene_volume* v, int max_side, veil_sparse* out, veil_error* err)
{
    memset(out, 0, sizeof *out);
    const veil_grid* grid = &v->grid;
    out->grid = *grid;
    for (int a = 0; a < 3; ++a) {
        if (grid->dims[a] > VEIL_SPARSE_MAX_SIDE)
            return veil_fail(err, VEIL_ERR_LIMIT, "a sparse volume of %dx%dx%d voxels: at most %d a side",
                             grid->dims[0], grid->dims[1], grid->dims[2], VEIL_SPARSE_MAX_SIDE);
        out->bricks[a] = (grid->dims[a] + B - 1) / B;
        out->top[a] = (out->bricks[a] + N - 1) / N;
    }
    /* the bricks counted first, a tile by its box: refused here before one is expanded */
    veil_sparse_census census;
    veil_result cr = veil_sparse_census_of(v, &census, err);
    if (cr == VEIL_OK) cr = veil_sparse_census_check(&census, err);
    veil_sparse_census_free(&census);
    if (cr != VEIL_OK) return cr;
    gather g = {.cap = 1 << 12, .create = 1, .emission = v->emission_count > 0};
    memcpy(g.bricks, out->bricks, sizeof g.bricks);
    memcpy(g.dims, grid->dims, sizeof g.dims);
    g.keys = calloc(g.cap, sizeof *g.keys);
    g.slots = malloc(g.cap * sizeof *g.slots);
    veil_result r = g.keys && g.slots ? VEIL_OK : veil_fail(err, VEIL_ERR_OOM, "out of memory for the sparse volume");
    for (int i = 0; i < v->vdb_count && r == VEIL_OK; ++i) {
        if (!(v->vdb_scale[i] > 0.0f)) continue;
        r = offset_of(v, v->vdbs[i], g.off, err);
        g.scale = v->vdb_scale[i];
        g.last_key = 0;
        if (r == VEIL_OK) r = veil_vdb_each_voxel(v->vdbs[i], add_voxel, &g, err);
        if (r == VEIL_OK && g.oom) r = veil_fail(err, VEIL_ERR_OOM, "out of memory for the sparse volume's bricks");
    }
    if (r == VEIL_OK && g.emission) r = gather_emission(v, &g, err);
    if (r == VEIL_OK) r = dilate(&g, err);
    /* the atlas: a near-square slab of bricks */
    int per = max_side / A;
    if (r == VEIL_OK) {
        size_t side = (size_t)ceil(sqrt((double)(g.count ? g.count : 1)));
        if (side > (size_t)per) side = (size_t)per;
        out->atlas[0] = out->atlas[1] = (int)side;
        size_t layers = (g.count + side * side - 1) / (side * side);
        if (layers < 1) layers = 1;
        if (layers > (size_t)per)
            r = veil_fail(err, VEIL_ERR_LIMIT, "a sparse volume of %zu bricks: the atlas holds at most %d^3 (%d texels a "
                          "side on this device)", g.count, per, max_side);
        out->atlas[2] = (int)layers;
    }
    if (r == VEIL_OK) {
        int t[3];
        veil_sparse_atlas_texels(out, t);
        size_t n = (size_t)t[0] * (size_t)t[1] * (size_t)t[2];
        out->texels = calloc(n, sizeof *out->texels);
        if (!out->texels) r = veil_fail(err, VEIL_ERR_OOM, "out of memory for a %zu-texel atlas", n);
        if (r == VEIL_OK && g.emission) {
            out->emission_texels = calloc(n * 4, sizeof *out->emission_texels);
            if (!out->emission_texels) r = veil_fail(err, VEIL_ERR_OOM, "out of memory for a %zu-texel emission atlas", n);
        }
        for (size_t s = 0; s < g.count && r == VEIL_OK; ++s) {
            int corner[3] = {(int)(s % (size_t)out->atlas[0]) * A, (int)(s / (size_t)out->atlas[0] % (size_t)out->atlas[1]) * A,
                             (int)(s / ((size_t)out->atlas[0] * (size_t)out->atlas[1])) * A};
            const int32_t* b = g.coords + 4 * s;
            for (int z = 0; z < A; ++z)
                for (int y = 0; y < A; ++y)
                    for (int x = 0; x < A; ++x) {
                        int vox[3] = {B * b[0] + x, B * b[1] + y, B * b[2] + z};
                        float value = x < B && y < B && z < B ? g.data[s * B * B * B + (size_t)(x + B * (y + B * z))]
                                                              : voxel_at(&g, vox);
                        size_t at = (size_t)(corner[0] + x) +
                                    (size_t)t[0] * ((size_t)(corner[1] + y) + (size_t)t[1] * (size_t)(corner[2] + z));
                        out->texels[at] = value;
                        if (out->emission_texels) emission_at(&g, vox, out->emission_texels + 4 * at);
                    }
        }
    }
    /* the emitting voxels, for the emission's lights (volume/emission_lights.h) */
    size_t emitting = 0;
    for (size_t k = 0; r == VEIL_OK && g.emission && k < g.count * B * B * B; ++k) {
        const float* e = g.edata + (k / (B * B * B)) * 3 * B * B * B + k % (B * B * B);
        emitting += VEIL_LUM_R * e[0] + VEIL_LUM_G * e[B * B * B] + VEIL_LUM_B * e[2 * B * B * B] > 0.0;
    }
    if (emitting) {
        out->emitters = malloc(emitting * 6 * sizeof *out->emitters);
        if (!out->emitters) r = veil_fail(err, VEIL_ERR_OOM, "out of memory for %zu emitting voxels", emitting);
        double dv = (double)grid->voxel * grid->voxel * grid->voxel;
        for (size_t k = 0; r == VEIL_OK && k < g.count * B * B * B; ++k) {
            size_t s = k / (B * B * B), j = k % (B * B * B);
            const float* e = g.edata + s * 3 * B * B * B + j;
            if (!(VEIL_LUM_R * e[0] + VEIL_LUM_G * e[B * B * B] + VEIL_LUM_B * e[2 * B * B * B] > 0.0)) continue;
            int local[3] = {(int)(j % B), (int)(j / B % B), (int)(j / (B * B))};
            float* p = out->emitters + 6 * out->emitter_count++;
            veil_grid_center(grid, B * g.coords[4 * s] + local[0], B * g.coords[4 * s + 1] + local[1],
                             B * g.coords[4 * s + 2] + local[2], p);
            for (int c = 0; c < 3; ++c) p[3 + c] = (float)(e[(size_t)c * B * B * B] * dv);
        }
    }
    out->count = g.count;
    out->coords = g.coords;
    out->voxels = g.voxels;
    g.coords = NULL;
    if (r == VEIL_OK) r = tables(out, err);
    free(g.keys);
    free(g.slots);
    free(g.data);
    free(g.edata);
    free(g.one);
    free(g.coords);
    if (r != VEIL_OK) veil_sparse_free(out);
    return r;
}
