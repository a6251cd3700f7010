#include "volumetric.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "../core/hash.h"
#include "../gpu/gl_util.h"
#include "../gpu/programs.h"

struct veil_volumetric {
    GLuint source_program, sor_program, escape_program, ubo, medium_ubo;
    GLuint escape_sparse_program; /* escape.comp over a sparse volume, made when first needed */
    float cell;                   /* the kept field's cell (m), for the report */
    int sparse;                   /* ... and whether it is over a sparse volume */
    GLuint src, phi;    /* 3D textures of the kept field (0: none) */
    veil_cache_programs cache;
    veil_cache_report cache_rep; /* the kept cache's */
    int dims[3];
    veil_volumetric_field field;
    uint64_t key;
    int keyed;          /* a field (or "none") is kept under key */
};

veil_result veil_volumetric_create(veil_volumetric** out, veil_error* err)
{
    *out = NULL;
    veil_volumetric* d = calloc(1, sizeof *d);
    if (!d) return veil_fail(err, VEIL_ERR_OOM, "out of memory creating the volumetric stage");
    veil_result r = veil_gpu_program("volumetric/shaders/diffusion_source.comp", &d->source_program, err);
    if (r == VEIL_OK) r = veil_gpu_program("volumetric/shaders/diffusion_sor.comp", &d->sor_program, err);
    if (r == VEIL_OK) r = veil_gpu_program("volumetric/shaders/escape.comp", &d->escape_program, err);
    if (r == VEIL_OK)
        r = veil_gl_buffer(NULL, sizeof(veil_diffusion_block), GL_DYNAMIC_STORAGE_BIT, "veil diffusion block", &d->ubo,
                           err);
    if (r == VEIL_OK)
        r = veil_gl_buffer(NULL, sizeof(veil_medium_block), GL_DYNAMIC_STORAGE_BIT, "veil volumetric medium block",
                           &d->medium_ubo, err);
    if (r != VEIL_OK) {
        veil_volumetric_destroy(d);
        return r;
    }
    *out = d;
    return VEIL_OK;
}

void veil_volumetric_clear(veil_volumetric* d)
{
    if (!d) return;
    glDeleteTextures(1, &d->src);
    glDeleteTextures(1, &d->phi);
    d->src = d->phi = 0;
    memset(&d->cache_rep, 0, sizeof d->cache_rep);
    memset(&d->field, 0, sizeof d->field);
    memset(d->dims, 0, sizeof d->dims);
    d->keyed = 0;
}

void veil_volumetric_destroy(veil_volumetric* d)
{
    if (!d) return;
    veil_volumetric_clear(d);
    glDeleteProgram(d->source_program);
    glDeleteProgram(d->sor_program);
    glDeleteProgram(d->escape_program);
    glDeleteProgram(d->escape_sparse_program);
    veil__cache_programs_free(&d->cache);
    glDeleteBuffers(1, &d->ubo);
    glDeleteBuffers(1, &d->medium_ubo);
    free(d);
}

/* The grid: over the EV's medium box, cells of two voxels (at most `cells`
 * along the longest side); without an EV over the first fog's box. 0 when
 * there is none. */
static int grid_of(const veil_lit_medium* md, int cells, float lo[3], float* h, int dims[3])
{
    float hi[3];
    if (md->grid) {
        veil_grid_medium_box(md->grid, lo, hi);
        *h = 2.0f * md->grid->voxel;
    } else {
        const veil_medium* m = &md->scene->medium;
        size_t i = 0;
        while (i < m->source_count && m->sources[i].type != VEIL_SOURCE_EXPONENTIAL) ++i;
        if (i == m->source_count) return 0;
        for (int a = 0; a < 3; ++a) lo[a] = m->sources[i].fog.bounds[0][a], hi[a] = m->sources[i].fog.bounds[1][a];
        *h = 0.0f;
    }
    float longest = 0.0f;
    for (int a = 0; a < 3; ++a) longest = fmaxf(longest, hi[a] - lo[a]);
    if (!(longest > 0.0f) || !(longest <= VEIL_DIFFUSION_MAX_EXTENT)) return 0;
    if (!(*h > 0.0f) || longest / *h + 1.0f > (float)cells) *h = longest / (float)(cells - 1);
    for (int a = 0; a < 3; ++a) {
        dims[a] = (int)ceilf((hi[a] - lo[a]) / *h) + 1;
        if (dims[a] < 2) dims[a] = 2;
        if (dims[a] > cells) dims[a] = cells;
    }
    return 1;
}

int veil_volumetric_grid(const veil_volumetric_desc* d, float lo[3], float* h, int dims[3])
{
    if (d->kind == VEIL_FIELD_CACHE) return veil__cache_grid(&d->medium, d->cache.cells, lo, h, dims);
    return grid_of(&d->medium, d->kind == VEIL_FIELD_ESCAPE ? VEIL_ESCAPE_CELLS : d->diffusion_cells, lo, h, dims);
}

int veil_volumetric_sweeps(const veil_volumetric_desc* d, const int dims[3])
{
    if (d->kind != VEIL_FIELD_FLUENCE) return 0;
    int longest = dims[0] > dims[1] ? (dims[0] > dims[2] ? dims[0] : dims[2]) : (dims[1] > dims[2] ? dims[1] : dims[2]);
    return d->diffusion_iterations > 0 ? d->diffusion_iterations : 3 * longest;
}

const veil_volumetric_field* veil_volumetric_field_of(const veil_volumetric* v)
{
    return &v->field;
}

/* An rgba32f field: zero everywhere and beyond its border (phi = 0 there). */
static veil_result texture3d(const int dims[3], const char* label, GLuint* tex, veil_error* err)
{
    veil_result r = veil_gl_texture3d(GL_RGBA32F, dims, label, tex, err);
    if (r != VEIL_OK) return r;
    glTextureParameteri(*tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTextureParameteri(*tex, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    glTextureParameteri(*tex, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_BORDER);
    static const float zero[4] = {0, 0, 0, 0};
    glTextureParameterfv(*tex, GL_TEXTURE_BORDER_COLOR, zero);
    glClearTexImage(*tex, 0, GL_RGBA, GL_FLOAT, zero);
    return veil_gl_check(label, err);
}

double veil_volumetric_sparse_escape_rays(double bricks)
{
    return bricks * (VEIL_SPARSE_ESCAPE * VEIL_SPARSE_ESCAPE * VEIL_SPARSE_ESCAPE) * VEIL_ESCAPE_DIRECTIONS;
}

/* The escape field of a sparse volume: VEIL_SPARSE_ESCAPE^3 points a kept
 * brick, in an atlas laid out like the density's (volumetric/shaders/escape.comp
 * with VEIL_SPARSE). */
static veil_result escape_sparse(veil_volumetric* d, const veil_lit_medium* md, int dims[3], veil_error* err)
{
    const veil_ev_sparse* sp = md->sparse;
    veil_result r = VEIL_OK;
    if (!d->escape_sparse_program)
        r = veil_gpu_program_variant("volumetric/shaders/escape.comp", "#define VEIL_SPARSE 1\n", "sparse",
                                     &d->escape_sparse_program, err);
    veil_medium_block mu;
    veil_lit_medium_fill(md, &mu);
    for (int a = 0; a < 3; ++a) dims[a] = VEIL_SPARSE_ESCAPE * sp->block.atlas[a];
    if (r == VEIL_OK) r = texture3d(dims, "veil escape field (sparse atlas)", &d->phi, err);
    if (r != VEIL_OK) return r;
    veil_diffusion_block u;
    memset(&u, 0, sizeof u);
    for (int a = 0; a < 3; ++a) u.dims[a] = dims[a];
    glNamedBufferSubData(d->medium_ubo, 0, sizeof mu, &mu);
    glNamedBufferSubData(d->ubo, 0, sizeof u, &u);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_MEDIUM, d->medium_ubo);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_DIFFUSION, d->ubo);
    glUseProgram(d->escape_sparse_program);
    veil_ev_sparse_bind(sp);
    glBindTextureUnit(VEIL_TEX_EV, sp->atlas);
    glBindImageTexture(VEIL_IMAGE_DIFF_PHI, d->phi, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDispatchCompute(veil_groups(dims[0], VEIL_DIFFUSION_GROUP), veil_groups(dims[1], VEIL_DIFFUSION_GROUP),
                      veil_groups(dims[2], VEIL_DIFFUSION_GROUP));
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glBindImageTexture(VEIL_IMAGE_DIFF_PHI, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glBindTextureUnit(VEIL_TEX_EV, 0);
    veil_ev_sparse_bind(NULL);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_MEDIUM, 0);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_DIFFUSION, 0);
    glUseProgram(0);
    return veil_gl_check("escape field over a sparse volume (volumetric/shaders/escape.comp)", err);
}

/* "No field" kept under key: a later frame with the same key skips as well. */
static veil_result keep_none(veil_volumetric* d, uint64_t key, veil_volumetric_report* rep)
{
    d->keyed = 1, d->key = key;
    rep->skipped = 1;
    return VEIL_OK;
}

/* The light cache (volumetric/cache.h) on its grid over the medium, dense or sparse alike. */
static veil_result update_cache(veil_volumetric* d, const veil_volumetric_desc* vd, uint64_t key,
                                veil_volumetric_field* field, veil_volumetric_report* rep, veil_error* err)
{
    const veil_lit_medium* md = &vd->medium;
    float lo[3], h;
    int dims[3];
    rep->sparse = d->sparse = md->grid && md->sparse;
    if (!veil_volumetric_grid(vd, lo, &h, dims)) return keep_none(d, key, rep);
    veil_medium_block mu;
    veil_lit_medium_fill(md, &mu);
    veil_result r = veil__cache_build(&d->cache, md, &mu, lo, h, dims, &vd->cache, &d->phi, &d->cache_rep, err);
    if (r != VEIL_OK) {
        veil_volumetric_clear(d);
        return r;
    }
    rep->cache = d->cache_rep;
    if (!d->phi) return keep_none(d, key, rep); /* too thick for photons */
    memcpy(d->dims, dims, sizeof dims);
    for (int a = 0; a < 3; ++a) {
        d->field.tex_min[a] = lo[a]; /* cell k spans lo + [k, k + 1] h: its centre is texel k's */
        d->field.tex_inv[a] = 1.0f / ((float)dims[a] * h);
    }
    d->field.texture = d->phi;
    d->field.depth = dims[2];
    d->field.kind = VEIL_FIELD_CACHE;
    d->field.first_only = d->cache_rep.too_thick;
    d->keyed = 1, d->key = key;
    *field = d->field;
    memcpy(rep->dims, dims, sizeof rep->dims);
    rep->cell = d->cell = h;
    return VEIL_OK;
}

veil_result veil_volumetric_update(veil_volumetric* d, const veil_volumetric_desc* vd, uint64_t key,
                                   veil_volumetric_field* field, veil_volumetric_report* rep, veil_error* err)
{
    const veil_lit_medium* md = &vd->medium;
    const veil_field_kind kind = vd->kind;
    memset(rep, 0, sizeof *rep);
    rep->key = key;
    if (d->keyed && d->key == key) {
        *field = d->field;
        rep->cached = 1;
        rep->skipped = d->phi == 0;
        memcpy(rep->dims, d->dims, sizeof rep->dims);
        rep->cell = d->cell;
        rep->sparse = d->sparse;
        rep->cache = d->cache_rep;
        return VEIL_OK;
    }
    veil_volumetric_clear(d);
    memset(field, 0, sizeof *field);
    float lo[3], h;
    int dims[3];
    if (kind == VEIL_FIELD_CACHE) return update_cache(d, vd, key, field, rep, err);
    int escape = kind == VEIL_FIELD_ESCAPE;
    if (md->grid && md->sparse) {
        rep->sparse = 1;
        d->sparse = 1, d->cell = 0.0f;
        if (!escape) return keep_none(d, key, rep); /* the diffusion solve needs a dense grid: no field */
        veil_result r = escape_sparse(d, md, dims, err);
        if (r != VEIL_OK) {
            veil_volumetric_clear(d);
            return r;
        }
        memcpy(d->dims, dims, sizeof dims);
        d->field.texture = d->phi;
        d->field.kind = kind;
        d->keyed = 1, d->key = key;
        *field = d->field;
        memcpy(rep->dims, dims, sizeof rep->dims);
        rep->cell = d->cell = (float)VEIL_BRICK / (VEIL_SPARSE_ESCAPE - 1) * md->grid->voxel;
        d->sparse = 1;
        return VEIL_OK;
    }
    if (!veil_volumetric_grid(vd, lo, &h, dims)) return keep_none(d, key, rep);
    veil_medium_block mu;
    veil_lit_medium_fill(md, &mu);
    const veil_medium* m = &md->scene->medium;
    float g = m->phase.type == VEIL_PHASE_HG ? m->phase.g : 0.0f, extent = 0.0f;
    veil_diffusion_block u;
    memset(&u, 0, sizeof u);
    for (int a = 0; a < 3; ++a) {
        u.origin[a] = lo[a];
        u.dims[a] = dims[a];
        u.sigma_a[a] = m->sigma_a[a];
        u.sigma_tr[a] = m->sigma_a[a] + m->sigma_s[a] * (1.0f - g);
        extent = fmaxf(extent, (float)dims[a] * h);
    }
    u.origin[3] = h;
    u.sigma_tr[3] = VEIL_DIFFUSION_VACUUM;
    (void)extent;
    u.relax[0] = VEIL_DIFFUSION_OMEGA;
    veil_result r = texture3d(dims, "veil diffusion source", &d->src, err);
    if (r == VEIL_OK) r = texture3d(dims, "veil diffusion fluence", &d->phi, err);
    if (r != VEIL_OK) {
        veil_volumetric_clear(d);
        return r;
    }
    int sweeps = veil_volumetric_sweeps(vd, dims);
    glNamedBufferSubData(d->medium_ubo, 0, sizeof mu, &mu);
    glNamedBufferSubData(d->ubo, 0, sizeof u, &u);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_MEDIUM, d->medium_ubo);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_DIFFUSION, d->ubo);
    glBindTextureUnit(VEIL_TEX_EV, md->grid ? md->ev : 0);
    veil_lit_medium_bind_depths(md);
    if (escape) {
        glUseProgram(d->escape_program);
        glBindImageTexture(VEIL_IMAGE_DIFF_PHI, d->phi, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glDispatchCompute(veil_groups(dims[0], VEIL_DIFFUSION_GROUP), veil_groups(dims[1], VEIL_DIFFUSION_GROUP),
                          veil_groups(dims[2], VEIL_DIFFUSION_GROUP));
    }
    glUseProgram(escape ? 0 : d->source_program);
    glBindImageTexture(VEIL_IMAGE_DIFF_SRC, d->src, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    if (!escape)
        glDispatchCompute(veil_groups(dims[0], VEIL_DIFFUSION_GROUP), veil_groups(dims[1], VEIL_DIFFUSION_GROUP),
                          veil_groups(dims[2], VEIL_DIFFUSION_GROUP));
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    glUseProgram(d->sor_program);
    glBindImageTexture(VEIL_IMAGE_DIFF_SRC, d->src, 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
    glBindImageTexture(VEIL_IMAGE_DIFF_PHI, d->phi, 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
    for (int it = 0; it < sweeps; ++it)
        for (int parity = 0; parity < 2; ++parity) {
            u.dims[3] = parity;
            glNamedBufferSubData(d->ubo, offsetof(veil_diffusion_block, dims), sizeof u.dims, u.dims);
            glDispatchCompute(veil_groups((dims[0] + 1) / 2, VEIL_DIFFUSION_GROUP),
                              veil_groups(dims[1], VEIL_DIFFUSION_GROUP), veil_groups(dims[2], VEIL_DIFFUSION_GROUP));
            glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        }
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glBindImageTexture(VEIL_IMAGE_DIFF_SRC, 0, 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
    glBindImageTexture(VEIL_IMAGE_DIFF_PHI, 0, 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
    for (int t = 0; t <= VEIL_TEX_OPV0 + VEIL_MAX_OPV_TEXTURES; ++t) glBindTextureUnit((GLuint)t, 0);
    if (!md->sparse) veil_lit_medium_bind_depths(NULL);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_MEDIUM, 0);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_DIFFUSION, 0);
    glUseProgram(0);
    r = veil_gl_check("diffusion (volumetric/shaders/diffusion_*.comp)", err);
    if (r != VEIL_OK) {
        veil_volumetric_clear(d);
        return r;
    }
    memcpy(d->dims, dims, sizeof dims);
    for (int a = 0; a < 3; ++a) {
        d->field.tex_min[a] = lo[a] - 0.5f * h; /* cell centres at texel centres */
        d->field.tex_inv[a] = 1.0f / ((float)dims[a] * h);
    }
    d->field.texture = d->phi;
    d->field.kind = kind;
    d->keyed = 1, d->key = key;
    *field = d->field;
    memcpy(rep->dims, dims, sizeof rep->dims);
    rep->cell = d->cell = h;
    d->sparse = 0;
    rep->iterations = sweeps;
    return VEIL_OK;
}

/* The kept field's texture read back: its first grid (layer 0) or, for the light cache's stacked
 * texture, another of its VEIL_CACHE_SLABS (core/shared.glsl.h). */
static float* readback(const veil_volumetric* d, int layer, int dims[3])
{
    if (!d->phi) return NULL;
    const int stacked = d->field.kind == VEIL_FIELD_CACHE;
    if (layer && !stacked) return NULL;
    size_t n = (size_t)d->dims[0] * (size_t)d->dims[1] * (size_t)d->dims[2] * 4;
    float* out = malloc((stacked ? VEIL_CACHE_SLABS : 1) * n * sizeof *out);
    if (!out) return NULL;
    glGetTextureImage(d->phi, 0, GL_RGBA, GL_FLOAT, (GLsizei)((stacked ? VEIL_CACHE_SLABS : 1) * n * sizeof *out), out);
    if (layer) memmove(out, out + (size_t)layer * n, n * sizeof *out);
    memcpy(dims, d->dims, 3 * sizeof *dims);
    return out; /* (a stacked texture's other layers stay allocated until it is freed) */
}

float* veil_volumetric_readback(const veil_volumetric* d, int dims[3])
{
    return readback(d, 0, dims);
}

float* veil_volumetric_readback_flux(const veil_volumetric* d, int dims[3])
{
    return readback(d, 1, dims);
}

float* veil_volumetric_readback_later(const veil_volumetric* d, int dims[3])
{
    return readback(d, 2, dims);
}

uint64_t veil_volumetric_key(uint64_t ev_key, const veil_volumetric_desc* d)
{
    const veil_scene* s = d->medium.scene;
    int escape = d->kind == VEIL_FIELD_ESCAPE;
    uint64_t key = veil_hash_bytes(ev_key, &s->medium.sigma_a, sizeof s->medium.sigma_a);
    key = veil_hash_bytes(key, &s->medium.sigma_s, sizeof s->medium.sigma_s);
    key = veil_hash_bytes(key, &s->medium.phase, sizeof s->medium.phase);
    if (!escape) /* the source is lit: the lights' geometry and colour */
        key = veil_hash_bytes(key, d->medium.lights, (size_t)d->medium.light_count * sizeof *d->medium.lights);
    key = veil_hash_bytes(key, &escape, sizeof escape);
    key = veil_hash_bytes(key, &d->diffusion_cells, sizeof d->diffusion_cells);
    key = veil_hash_bytes(key, &d->diffusion_iterations, sizeof d->diffusion_iterations);
    if (d->kind == VEIL_FIELD_CACHE) {
        key = veil_hash_bytes(key, &d->kind, sizeof d->kind);
        key = veil_hash_bytes(key, &d->cache.photons, sizeof d->cache.photons);
        key = veil_hash_bytes(key, &d->cache.cells, sizeof d->cache.cells);
        key = veil_hash_bytes(key, &d->cache.seed, sizeof d->cache.seed);
        key = veil_hash_bytes(key, &d->cache.emission, sizeof d->cache.emission);
        key = veil_hash_bytes(key, &d->cache.environment, sizeof d->cache.environment);
        if (d->cache.environment) {
            key = veil_hash_bytes(key, &s->environment.key, sizeof s->environment.key);
            key = veil_hash_bytes(key, &d->cache.env_texels, sizeof d->cache.env_texels);
        }
    }
    for (size_t i = 0; i < s->medium.source_count; ++i)
        if (s->medium.sources[i].type == VEIL_SOURCE_EXPONENTIAL)
            key = veil_hash_bytes(key, &s->medium.sources[i].fog, sizeof s->medium.sources[i].fog);
    return key;
}
