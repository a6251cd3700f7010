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

static size_t bucket(const gather* g, uint64_t key)
{
    return (size_t)veil_mix64(key) & (g->cap - 1);
}

/* Slot + 1 of brick b, 0 when absent. */
static uint32_t find(const gather* g, const int b[3])
{
    for (int a = 0; a < 3; ++a)
        if (b[a] < 0 || b[a] >= g->bricks[a]) return 0;
    uint64_t key = veil__sparse_pack(b);
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
    uint64_t key = veil__sparse_pack(b);
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
        r = veil__sparse_offset_of(v, es->grid, g->off, err);
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
veil_result veil__sparse_offset_of(const veil_scene_volume* v, const veil_vdb* vdb, int off[3], veil_error* err)
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
        r = veil__sparse_offset_of(v, v->vdbs[i], g.off, err);
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
