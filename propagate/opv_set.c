#include "opv_set.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/hash.h"
#include "../core/progress.h"
#include "../gpu/gl_util.h"
#include "../gpu/programs.h"
#include "opv_blocks.glsl.h"
#include "opv_gpu.h"

struct veil_opv_set {
    veil_opv_programs programs;
    GLuint sparse_program; /* propagate/shaders/propagate_sparse.comp, made when first needed */
    GLuint sun_program;    /* propagate/shaders/sun_prefix.comp, made when first needed */
    veil_pass_run sparse_run; /* the sparse passes of one light (a veil_sparse_od_block each) */
    GLuint sun_block;         /* the prefix sums' uniform buffer (veil_sun_block), made with the program */
    GLuint tex[VEIL_MAX_OPV_TEXTURES];
    int dims[VEIL_MAX_OPV_TEXTURES][3];
    GLenum format[VEIL_MAX_OPV_TEXTURES]; /* rgba32f, or r32f for one light on the grid (ordered methods) */
    uint64_t key[VEIL_MAX_OPV_TEXTURES]; /* 0: none (or being remade) */
    veil_opv_sun sun[VEIL_MAX_SUNS];     /* the first `suns` in use */
    uint64_t sun_key[VEIL_MAX_SUNS];     /* 0: none (or being remade) */
    int suns;
};

veil_result veil_opv_set_create(veil_opv_set** out, veil_error* err)
{
    *out = NULL;
    veil_opv_set* s = calloc(1, sizeof *s);
    if (!s) return veil_fail(err, VEIL_ERR_OOM, "out of memory creating the optical-depth volumes");
    veil_pass_run_init(&s->sparse_run, sizeof(veil_sparse_od_block), "veil sparse optical depth blocks");
    veil_result r = veil_opv_programs_create(&s->programs, err);
    if (r != VEIL_OK) {
        free(s);
        return r;
    }
    *out = s;
    return VEIL_OK;
}

static void drop_sun(veil_opv_set* s, int k)
{
    glDeleteTextures(1, &s->sun[k].texture);
    memset(&s->sun[k], 0, sizeof s->sun[k]);
    s->sun_key[k] = 0;
}

void veil_opv_set_clear(veil_opv_set* s)
{
    glDeleteTextures(VEIL_MAX_OPV_TEXTURES, s->tex);
    memset(s->tex, 0, sizeof s->tex);
    memset(s->dims, 0, sizeof s->dims);
    memset(s->key, 0, sizeof s->key);
    for (int k = 0; k < VEIL_MAX_SUNS; ++k) drop_sun(s, k);
    s->suns = 0;
}

void veil_opv_set_destroy(veil_opv_set* s)
{
    if (!s) return;
    veil_opv_set_clear(s);
    glDeleteProgram(s->sparse_program);
    glDeleteProgram(s->sun_program);
    veil_pass_run_free(&s->sparse_run);
    glDeleteBuffers(1, &s->sun_block);
    veil_opv_programs_destroy(&s->programs);
    free(s);
}

GLuint veil_opv_set_texture(const veil_opv_set* s, int t) { return s->tex[t]; }

const veil_opv_sun* veil_opv_set_suns(const veil_opv_set* s, int* count)
{
    *count = s->suns;
    return s->sun;
}

/* The parameters a key holds: all but the suns' memory allowance, which
 * shows in a grid's key through the grid it makes (its spacing). */
static uint64_t params_key(uint64_t key, const veil_opv_params* params)
{
    veil_opv_params p = *params;
    p.sun_bytes = 0.0;
    return veil_hash_bytes(key, &p, sizeof p);
}

uint64_t veil_opv_texture_key(uint64_t ev_key, const veil_opv_params* params, const veil_index_light* lights, int count)
{
    uint64_t key = params_key(ev_key, params);
    for (int c = 0; c < count; ++c) key = veil_hash_bytes(key, &lights[c], sizeof lights[c]);
    return key;
}

int veil_opv_set_has(const veil_opv_set* s, int t, uint64_t key) { return s->tex[t] && s->key[t] == key; }

/* Texture t of dims and format (kept when it has them already). */
static veil_result texture_of(veil_opv_set* s, int t, const int dims[3], GLenum format, const char* label,
                              veil_error* err)
{
    if (s->tex[t] && !memcmp(s->dims[t], dims, sizeof s->dims[t]) && s->format[t] == format) return VEIL_OK;
    glDeleteTextures(1, &s->tex[t]);
    s->tex[t] = 0;
    memset(s->dims[t], 0, sizeof s->dims[t]);
    veil_result r = veil_gl_texture3d(format, dims, label, &s->tex[t], err);
    if (r == VEIL_OK) memcpy(s->dims[t], dims, sizeof s->dims[t]);
    s->format[t] = format;
    return r;
}

/* The order of light l's passes over a sparse volume: each slot's level,
 * so that a brick's path to the light leaves it towards bricks of lower
 * levels only. A sun: sum over axes of s_a b_a, s_a the sign of the
 * direction towards it (crossing a face towards the light adds 1), the
 * highest first: returned negated. A point light in brick c: the Manhattan
 * distance sum |b_a - c_a| (crossing a face towards it takes 1 off; where
 * b_a = c_a the path stays in that slab), from 0 up. So the lowest value
 * goes first either way. */
static long long level_of(const veil_index_light* l, const int32_t* b, int sun_sign[3], const int c[3])
{
    long long v = 0;
    for (int a = 0; a < 3; ++a)
        v += l->type == VEIL_LIGHT_DIRECTIONAL ? -(long long)sun_sign[a] * b[a] : llabs((long long)b[a] - c[a]);
    return v;
}

/* What level_of needs of light l: the signs of a sun's direction, a point light's brick. */
static void level_setup(const veil_index_light* l, int sign[3], int cb[3])
{
    for (int a = 0; a < 3; ++a) {
        /* the light in the sparse index space (opv.h's has voxel i's centre at i, this one at i + 0.5) */
        float light = l->v[a] + (l->type == VEIL_LIGHT_DIRECTIONAL ? 0.0f : 0.5f);
        sign[a] = l->v[a] > 0.0f ? 1 : l->v[a] < 0.0f ? -1 : 0;
        double cell = floor(((double)light - 0.5) / VEIL_BRICK);
        cb[a] = cell < -1e9 ? -1000000000 : cell > 1e9 ? 1000000000 : (int)cell;
    }
}

size_t veil_opv_sparse_passes(const int32_t* bricks, size_t n, const veil_index_light* l)
{
    if (!n) return 0;
    int sign[3], cb[3];
    level_setup(l, sign, cb);
    long long lo = 0, hi = 0;
    for (size_t i = 0; i < n; ++i) {
        long long v = level_of(l, bricks + 4 * i, sign, cb);
        if (i == 0 || v < lo) lo = v;
        if (i == 0 || v > hi) hi = v;
    }
    /* the levels span at most the bricks' extent on the three axes (a few thousand): a byte each */
    size_t range = (size_t)(hi - lo) + 1, passes = 0;
    unsigned char* seen = calloc(range, 1);
    if (!seen) return range < n ? range : n; /* at most either */
    for (size_t i = 0; i < n; ++i) {
        size_t k = (size_t)(level_of(l, bricks + 4 * i, sign, cb) - lo);
        passes += !seen[k];
        seen[k] = 1;
    }
    free(seen);
    return passes;
}

/* Texture t over a sparse volume: for each light, passes of
 * propagate/shaders/propagate_sparse.comp over the kept bricks, level by
 * level (each pass reads only bricks of earlier passes). *passes: the most
 * passes of any light. */
static veil_result sparse_depths(veil_opv_set* s, const veil_ev_sparse* sp, const veil_index_light* ol, int count,
                                 GLuint tex, int* passes, veil_error* err)
{
    veil_result r = VEIL_OK;
    if (!s->sparse_program) r = veil_gpu_program("propagate/shaders/propagate_sparse.comp", &s->sparse_program, err);
    if (r != VEIL_OK) return r;
    size_t n = sp->slots;
    long long* level = malloc((n ? n : 1) * sizeof *level);
    int32_t* list = malloc((n ? n : 1) * sizeof *list);
    size_t* first = NULL;
    GLuint buf = 0, list_tex = 0;
    if (!level || !list) r = veil_fail(err, VEIL_ERR_OOM, "out of memory ordering %zu bricks", n);
    GLuint p = s->sparse_program;
    static const float zero[4] = {0, 0, 0, 0};
    glClearTexImage(tex, 0, GL_RGBA, GL_FLOAT, zero);
    *passes = 0;
    for (int c = 0; c < count && r == VEIL_OK && n > 0; ++c) {
        /* the light in the sparse index space (opv.h's has voxel i's centre at i, this one at i + 0.5) */
        veil_sparse_od_block blk;
        memset(&blk, 0, sizeof blk);
        float* light = blk.light;
        int sign[3], cb[3];
        for (int a = 0; a < 3; ++a) light[a] = ol[c].v[a] + (ol[c].type == VEIL_LIGHT_DIRECTIONAL ? 0.0f : 0.5f);
        level_setup(&ol[c], sign, cb);
        light[3] = (float)ol[c].type;
        blk.pass[0] = c;
        /* counting sort of the slots by level */
        long long lo = 0, hi = 0;
        for (size_t i = 0; i < n; ++i) {
            level[i] = level_of(&ol[c], sp->bricks + 4 * i, sign, cb);
            if (i == 0 || level[i] < lo) lo = level[i];
            if (i == 0 || level[i] > hi) hi = level[i];
        }
        size_t levels = (size_t)(hi - lo) + 1;
        free(first);
        first = calloc(levels + 1, sizeof *first);
        if (!first) {
            r = veil_fail(err, VEIL_ERR_OOM, "out of memory for %zu passes", levels);
            break;
        }
        for (size_t i = 0; i < n; ++i) ++first[level[i] - lo + 1];
        for (size_t k = 0; k < levels; ++k) first[k + 1] += first[k];
        size_t* at = calloc(levels, sizeof *at);
        if (!at) {
            r = veil_fail(err, VEIL_ERR_OOM, "out of memory for %zu passes", levels);
            break;
        }
        for (size_t i = 0; i < n; ++i) {
            size_t k = (size_t)(level[i] - lo);
            list[first[k] + at[k]++] = (int32_t)i;
        }
        free(at);
        glDeleteTextures(1, &list_tex);
        glDeleteBuffers(1, &buf);
        list_tex = buf = 0;
        r = veil_gl_buffer(list, n * sizeof *list, 0, "veil sparse pass order", &buf, err);
        /* the light's passes, level by level, each level in dispatches of at most 65535 bricks (GL's
         * guaranteed work groups per dispatch) */
        veil_pass_run_clear(&s->sparse_run);
        for (size_t k = 0; k < levels && r == VEIL_OK; ++k)
            for (size_t g = 0; g < first[k + 1] - first[k] && r == VEIL_OK; g += 65535) {
                size_t m = first[k + 1] - first[k] - g;
                void* mem = NULL;
                r = veil_pass_run_add(&s->sparse_run, (GLuint)(m < 65535 ? m : 65535), 1, 1, &mem, err);
                if (r != VEIL_OK) break;
                veil_sparse_od_block* b = mem;
                *b = blk;
                b->pass[1] = (int32_t)(first[k] + g); /* the dispatch's first entry of the list */
            }
        if (r == VEIL_OK) r = veil_pass_run_upload(&s->sparse_run, err);
        if (r != VEIL_OK) break;
        glCreateTextures(GL_TEXTURE_BUFFER, 1, &list_tex);
        glTextureBuffer(list_tex, GL_R32I, buf);
        glUseProgram(p);
        veil_ev_sparse_bind(sp);
        glBindTextureUnit(VEIL_TEX_EV, sp->atlas);
        glBindTextureUnit(VEIL_TEX_SPARSE_LIST, list_tex);
        glBindTextureUnit(VEIL_TEX_OPV0, tex);
        glBindImageTexture(VEIL_IMAGE_SPARSE_OUT, tex, 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
        int done = 0;
        size_t next = 0; /* the run's next dispatch */
        for (size_t k = 0; k < levels; ++k) { /* rank 0, the bricks nearest the light, first */
            size_t m = first[k + 1] - first[k];
            if (!m) continue;
            for (size_t g = 0; g < m; g += 65535) veil_pass_run_dispatch(&s->sparse_run, VEIL_UBO_PROPAGATE, next++);
            glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
            ++done;
        }
        *passes = done > *passes ? done : *passes;
        glBindImageTexture(VEIL_IMAGE_SPARSE_OUT, 0, 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
        glBindTextureUnit(VEIL_TEX_OPV0, 0);
        glBindTextureUnit(VEIL_TEX_SPARSE_LIST, 0);
        glBindTextureUnit(VEIL_TEX_EV, 0);
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_PROPAGATE, 0);
        veil_ev_sparse_bind(NULL);
        glUseProgram(0);
        r = veil_gl_check("optical depth over a sparse volume (propagate/shaders/propagate_sparse.comp)", err);
    }
    glDeleteTextures(1, &list_tex);
    glDeleteBuffers(1, &buf);
    free(first);
    free(level);
    free(list);
    return r;
}

/* Fills texture tex (r32f, the nodes of sp) with one light's light-space
 * optical depth over the EV texture ev (occ: its occupancy bricks, 0: no
 * skipping): a sun's grid in one dispatch, a point light's a face at a time. */
static veil_result sun_depths(veil_opv_set* s, const veil_grid* g, GLuint ev, GLuint occ, const veil_sun_space* sp,
                              GLuint tex, veil_error* err)
{
    veil_result r = VEIL_OK;
    if (!s->sun_block)
        r = veil_gl_buffer(NULL, sizeof(veil_sun_block), GL_DYNAMIC_STORAGE_BIT, "veil light-space block",
                           &s->sun_block, err);
    if (r == VEIL_OK && !s->sun_program) r = veil_gpu_program("propagate/shaders/sun_prefix.comp", &s->sun_program, err);
    if (r != VEIL_OK) return r;
    glUseProgram(s->sun_program);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_PROPAGATE, s->sun_block);
    glBindTextureUnit(VEIL_TEX_EV, ev);
    glBindTextureUnit(VEIL_TEX_OCC, occ);
    glBindImageTexture(VEIL_IMAGE_OPV_DST, tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    for (int f = 0; f < (sp->perspective ? 6 : 1); ++f) {
        if (sp->perspective && sp->face[f].nz == 0) continue;
        float fr[6][3];
        veil_sun_space_columns(sp, f, fr);
        veil_sun_block blk;
        memset(&blk, 0, sizeof blk);
        for (int a = 0; a < 3; ++a) {
            blk.dims[a] = g->dims[a];
            blk.origin[a] = fr[0][a];
            for (int k = 0; k < 3; ++k) blk.axis[k][a] = fr[1 + k][a];
            blk.spread[0][a] = fr[4][a];
            blk.spread[1][a] = fr[5][a];
        }
        blk.dims[3] = sp->panels;
        blk.nodes[3] = (occ != 0) | (sp->perspective ? 2 : 0);
        const float* c = sp->axis[2];
        blk.origin[3] = sqrtf(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) * g->voxel; /* m a step along c (a sun's) */
        blk.spread[0][3] = g->voxel;
        if (sp->perspective) {
            blk.nodes[0] = sp->face[f].nu, blk.nodes[1] = sp->face[f].nv, blk.nodes[2] = sp->face[f].nz;
            blk.place[0] = sp->face[f].first;
        } else {
            for (int a = 0; a < 3; ++a) blk.nodes[a] = sp->nodes[a];
        }
        blk.place[1] = sp->nodes[0], blk.place[2] = sp->nodes[1];
        glNamedBufferSubData(s->sun_block, 0, sizeof blk, &blk);
        glDispatchCompute(veil_groups(sp->nodes[0], 8), veil_groups(sp->nodes[1], 8), 1);
    }
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    glBindImageTexture(VEIL_IMAGE_OPV_DST, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    glBindTextureUnit(VEIL_TEX_EV, 0);
    glBindTextureUnit(VEIL_TEX_OCC, 0);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_PROPAGATE, 0);
    glUseProgram(0);
    return veil_gl_check("a light's light-space optical depth (propagate/shaders/sun_prefix.comp)", err);
}

int veil_opv_plan_suns(const veil_grid* g, uint64_t ev_key, const veil_light* lights, int n,
                       const veil_opv_params* params, int max_axis, veil_index_light* ol, veil_opv_sun* want,
                       uint64_t* want_key)
{
    int count = 0;
    for (int l = 0; l < n; ++l) veil_light_to_index(&lights[l], g->dims, g->origin, g->voxel, &ol[l]);
    if (params->method != VEIL_OPV_LIGHT_SPACE) return 0;
    int suns = 0; /* the memory allowed is shared by the lights that may get a grid */
    for (int l = 0; l < n && suns < VEIL_MAX_SUNS; ++l) suns += ol[l].type == VEIL_LIGHT_DIRECTIONAL || ol[l].type == VEIL_LIGHT_POINT;
    for (int l = 0; l < n && count < VEIL_MAX_SUNS; ++l) {
        const int sun = ol[l].type == VEIL_LIGHT_DIRECTIONAL;
        veil_opv_sun* w = &want[count];
        memset(w, 0, sizeof *w);
        veil_error ignored;
        size_t voxels = veil_grid_voxels(g), most = VEIL_SUN_MAX_NODES;
        if (voxels < most / VEIL_SUN_NODES_PER_VOXEL) most = voxels * VEIL_SUN_NODES_PER_VOXEL;
        if (params->sun_bytes > 0.0 && params->sun_bytes / (4.0 * suns) < (double)most)
            most = (size_t)(params->sun_bytes / (4.0 * suns)); /* r32f nodes */
        /* the spacing asked for, widened across the light by 5/4 at a time until the grid fits
         * (up to VEIL_SUN_WIDEST voxels, or what was asked if wider) */
        float across = sun ? veil_opv_sun_across(params) : veil_opv_point_across(params);
        float widest = across > VEIL_SUN_WIDEST ? across : VEIL_SUN_WIDEST;
        veil_result made = VEIL_ERR_LIMIT;
        /* a point light's grid also widens until its prefix sums cost no more than the semi-Lagrangian
         * pass would (veil_opv_point_work) */
        const double work = sun ? 0.0 : veil_opv_point_work(params) * (double)voxels;
        for (; made != VEIL_OK && across <= widest; across *= 1.25f) {
            made = sun ? veil_sun_space_make(g, lights[l].direction, across, veil_opv_sun_along(params),
                                             veil_opv_sun_panels(params), max_axis, most, &w->space, &ignored)
                       : veil_point_space_make(g, ol[l].v, across, veil_opv_point_along(params),
                                               veil_opv_sun_panels(params), max_axis, most, &w->space, &ignored);
            if (made == VEIL_OK && !sun && across * 1.25f <= widest && veil_point_space_work(g, &w->space) > work)
                made = VEIL_ERR_LIMIT;
        }
        if (made != VEIL_OK) continue; /* too large a grid even so: this light stays on the EV's grid */
        w->light = l;
        if (sun) veil_sun_space_to_texture(g, &w->space, w->to_tex);
        want_key[count] = veil_hash_bytes(params_key(ev_key, params), &w->space, sizeof w->space);
        ol[l].elsewhere = 1;
        ++count;
    }
    return count;
}

/* The light-space grids for the suns among lights[0..n) (veil_opv_plan_suns):
 * brings their textures up to date. */
static veil_result update_suns(veil_opv_set* s, const veil_grid* g, GLuint ev, GLuint occ, int count,
                               const veil_opv_sun* want, const uint64_t* want_key, veil_opv_report* rep,
                               veil_error* err)
{
    /* keep each grid whose key is wanted (in the wanted slot), drop the rest */
    veil_opv_sun keep[VEIL_MAX_SUNS];
    uint64_t keep_key[VEIL_MAX_SUNS];
    memset(keep, 0, sizeof keep);
    memset(keep_key, 0, sizeof keep_key);
    for (int k = 0; k < count; ++k)
        for (int o = 0; o < s->suns; ++o)
            if (s->sun_key[o] && s->sun_key[o] == want_key[k] && s->sun[o].texture) {
                keep[k] = s->sun[o];
                keep_key[k] = want_key[k];
                s->sun[o].texture = 0;
                s->sun_key[o] = 0;
                break;
            }
    for (int o = 0; o < VEIL_MAX_SUNS; ++o) drop_sun(s, o);
    s->suns = count;
    veil_result r = VEIL_OK;
    for (int k = 0; k < count; ++k) {
        if (keep_key[k]) {
            s->sun[k] = keep[k];
            s->sun[k].light = want[k].light; /* the same grid may serve a light at another index */
            s->sun_key[k] = keep_key[k];
            continue;
        }
        s->sun[k] = want[k];
        if (r == VEIL_OK) r = veil_gl_texture2d_array(GL_R32F, want[k].space.nodes, "veil light-space optical depth",
                                                &s->sun[k].texture, err);
        if (r == VEIL_OK) r = sun_depths(s, g, ev, occ, &want[k].space, s->sun[k].texture, err);
        if (r == VEIL_OK) s->sun_key[k] = want_key[k];
        ++rep->suns_computed;
    }
    rep->suns = count;
    for (int k = 0; k < count; ++k) {
        float across = s->sun[k].space.across;
        rep->sun_across = across > rep->sun_across ? across : rep->sun_across;
    }
    for (int k = 0; k < count; ++k) rep->mib += (double)veil_sun_space_nodes(&s->sun[k].space) * 4.0 / 1048576.0;
    return r;
}

veil_result veil_opv_set_update(veil_opv_set* s, const veil_grid* g, GLuint ev, GLuint occ,
                                const veil_ev_sparse* sp, uint64_t ev_key, const veil_light* lights, int n,
                                const veil_opv_params* params, veil_opv_report* rep, veil_error* err)
{
    memset(rep, 0, sizeof *rep);
    if (params->method <= VEIL_OPV_DEFAULT || params->method >= VEIL_OPV_METHOD_COUNT)
        return veil_fail(err, VEIL_ERR_INVALID, "propagate: method %d is not a resolved method (veil_opv_method_resolve)",
                         (int)params->method);
    veil_result r = VEIL_OK;
    const int report = veil_progress_wanted();
    veil_index_light ol[VEIL_MAX_LIGHTS];
    n = n < VEIL_MAX_LIGHTS ? n : VEIL_MAX_LIGHTS;
    veil_opv_sun want[VEIL_MAX_SUNS];
    uint64_t want_key[VEIL_MAX_SUNS];
    GLint max_axis = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max_axis);
    int suns = veil_opv_plan_suns(g, ev_key, lights, n, params, sp ? 0 : max_axis, ol, want, want_key);
    if (suns > 0) {
        if (report) veil_progress("optical depth, suns", 0, 1);
        r = update_suns(s, g, ev, occ, suns, want, want_key, rep, err);
    } else {
        for (int k = 0; k < VEIL_MAX_SUNS; ++k) drop_sun(s, k);
        s->suns = 0;
    }
    for (int t = 0; 4 * t < n && r == VEIL_OK; ++t) {
        if (report) { /* lights done of all; the textures before this one finished first */
            glFinish();
            veil_progress("optical depth, lights", 4.0 * t, n);
            if (veil_progress_cancelled()) { /* the textures made so far keep their keys */
                r = veil_fail(err, VEIL_ERR_CANCELLED, "cancelled by the progress callback during the optical "
                              "depth (%d of %d lights done)", 4 * t, n);
                break;
            }
        }
        int count = n - 4 * t < 4 ? n - 4 * t : 4, on_grid = 0;
        for (int c = 0; c < count; ++c) on_grid += !ol[4 * t + c].elsewhere;
        if (!on_grid) { /* every light of this texture has its own grid */
            glDeleteTextures(1, &s->tex[t]);
            s->tex[t] = 0;
            s->key[t] = 0;
            memset(s->dims[t], 0, sizeof s->dims[t]);
            continue;
        }
        const int* td = sp ? sp->atlas_texels : g->dims;
        /* one light on the grid by an ordered method: r32f (the march reads channel 0 either way) */
        veil_opv_method m = params->method;
        int one = !sp && on_grid == 1 && count == 1 && m != VEIL_OPV_JACOBI && m != VEIL_OPV_JACOBI_CORRECTED;
        rep->mib += (double)td[0] * td[1] * td[2] * (one ? 4.0 : 16.0) / 1048576.0;
        uint64_t key = veil_opv_texture_key(ev_key, params, ol + 4 * t, count);
        if (veil_opv_set_has(s, t, key)) {
            ++rep->cached;
            continue;
        }
        r = texture_of(s, t, td, one ? GL_R32F : GL_RGBA32F,
                       sp ? "veil optical depth (sparse atlas)" : "veil optical-depth volume", err);
        int it = 0;
        s->key[t] = 0;
        if (r == VEIL_OK && sp) r = sparse_depths(s, sp, ol + 4 * t, count, s->tex[t], &it, err);
        else if (r == VEIL_OK) r = veil_opv_gpu(&s->programs, g, ev, ol + 4 * t, count, params, &s->tex[t], &it, err);
        if (r == VEIL_OK) s->key[t] = key;
        rep->iterations = it > rep->iterations ? it : rep->iterations;
        ++rep->computed;
    }
    if (report && r == VEIL_OK) {
        glFinish();
        veil_progress("optical depth, lights", n, n);
    }
    return r;
}

veil_result veil_opv_set_propagate_readback(veil_opv_set* s, const veil_grid* g, const float* density,
                                            const veil_index_light* lights, int n_lights,
                                            const veil_opv_params* params, float* out, int* iterations,
                                            veil_error* err)
{
    if (n_lights < 1 || n_lights > VEIL_MAX_LIGHTS)
        return veil_fail(err, VEIL_ERR_INVALID, "propagate: %d lights (1..%d)", n_lights, VEIL_MAX_LIGHTS);
    GLuint ev = 0, opv[VEIL_MAX_OPV_TEXTURES] = {0};
    int n_tex = (n_lights + 3) / 4;
    size_t nv = veil_grid_voxels(g);
    float* tmp = malloc(nv * 4 * sizeof(float));
    veil_result r = tmp ? veil_gl_texture3d(GL_R32F, g->dims, "veil extinction volume", &ev, err)
                        : veil_fail(err, VEIL_ERR_OOM, "out of memory");
    if (r == VEIL_OK) {
        glTextureSubImage3D(ev, 0, 0, 0, 0, g->dims[0], g->dims[1], g->dims[2], GL_RED, GL_FLOAT, density);
        r = veil_gl_check("uploading the extinction volume", err);
    }
    /* a door for tests and benchmarks: the method is resolved here, as the frame's plan does */
    veil_opv_params resolved = *params;
    resolved.method = veil_opv_method_resolve(params->method);
    params = &resolved;
    /* as veil_opv_set_update makes them: a texture of one light is r32f for the ordered methods */
    veil_opv_method m = params->method;
    int ordered = m != VEIL_OPV_JACOBI && m != VEIL_OPV_JACOBI_CORRECTED;
    for (int t = 0; t < n_tex && r == VEIL_OK; ++t) {
        int one = ordered && n_lights - 4 * t == 1;
        r = veil_gl_texture3d(one ? GL_R32F : GL_RGBA32F, g->dims, "veil optical-depth volume", &opv[t], err);
    }
    if (r == VEIL_OK) r = veil_opv_gpu(&s->programs, g, ev, lights, n_lights, params, opv, iterations, err);
    for (int t = 0; t < n_tex && r == VEIL_OK; ++t) {
        int one = ordered && n_lights - 4 * t == 1;
        r = veil_gl_read_texture(opv[t], one ? GL_RED : GL_RGBA, nv * (one ? 1 : 4), tmp, "reading back an OPV", err);
        for (int c = 0; c < 4 && 4 * t + c < n_lights && r == VEIL_OK; ++c)
            for (size_t v = 0; v < nv; ++v) out[(size_t)(4 * t + c) * nv + v] = tmp[(one ? 1 : 4) * v + c];
    }
    glDeleteTextures(1, &ev);
    glDeleteTextures(VEIL_MAX_OPV_TEXTURES, opv);
    free(tmp);
    return r;
}

veil_result veil_opv_set_sun_readback(veil_opv_set* s, const veil_grid* g, const float* density,
                                      const veil_sun_space* space, int occupancy, float* out, veil_error* err)
{
    GLuint ev = 0, occ = 0, tex = 0;
    int bricks[3];
    for (int a = 0; a < 3; ++a) bricks[a] = (g->dims[a] + VEIL_BRICK - 1) / VEIL_BRICK;
    size_t nb = (size_t)bricks[0] * bricks[1] * bricks[2];
    float* bmax = occupancy ? calloc(nb, sizeof *bmax) : NULL;
    veil_result r = occupancy && !bmax ? veil_fail(err, VEIL_ERR_OOM, "out of memory") : VEIL_OK;
    if (r == VEIL_OK) r = veil_gl_texture3d(GL_R32F, g->dims, "veil extinction volume", &ev, err);
    if (r == VEIL_OK) {
        glTextureSubImage3D(ev, 0, 0, 0, 0, g->dims[0], g->dims[1], g->dims[2], GL_RED, GL_FLOAT, density);
        r = veil_gl_check("uploading the extinction volume", err);
    }
    if (r == VEIL_OK && occupancy) { /* each brick's largest density with the ring around it (occupancy.comp) */
        for (int k = 0; k < g->dims[2]; ++k)
            for (int j = 0; j < g->dims[1]; ++j)
                for (int i = 0; i < g->dims[0]; ++i) {
                    float v = density[((size_t)k * g->dims[1] + j) * g->dims[0] + i];
                    const int x[3] = {i, j, k};
                    int lo[3], hi[3];
                    for (int a = 0; a < 3; ++a) { /* bricks b with 8b - 1 <= x <= 8b + 8 */
                        lo[a] = (x[a] + VEIL_BRICK - 1) / VEIL_BRICK - 1;
                        lo[a] = lo[a] < 0 ? 0 : lo[a];
                        hi[a] = (x[a] + 1) / VEIL_BRICK;
                        hi[a] = hi[a] > bricks[a] - 1 ? bricks[a] - 1 : hi[a];
                    }
                    for (int c = lo[2]; c <= hi[2]; ++c)
                        for (int b = lo[1]; b <= hi[1]; ++b)
                            for (int a = lo[0]; a <= hi[0]; ++a) {
                                float* m = &bmax[((size_t)c * bricks[1] + b) * bricks[0] + a];
                                *m = v > *m ? v : *m;
                            }
                }
        r = veil_gl_texture3d(GL_R32F, bricks, "veil occupancy", &occ, err);
        if (r == VEIL_OK) {
            glTextureSubImage3D(occ, 0, 0, 0, 0, bricks[0], bricks[1], bricks[2], GL_RED, GL_FLOAT, bmax);
            r = veil_gl_check("uploading the occupancy", err);
        }
    }
    if (r == VEIL_OK) r = veil_gl_texture2d_array(GL_R32F, space->nodes, "veil light-space optical depth", &tex, err);
    if (r == VEIL_OK) r = sun_depths(s, g, ev, occ, space, tex, err);
    if (r == VEIL_OK)
        r = veil_gl_read_texture(tex, GL_RED, veil_sun_space_nodes(space), out, "reading back a light-space grid", err);
    glDeleteTextures(1, &ev);
    glDeleteTextures(1, &occ);
    glDeleteTextures(1, &tex);
    free(bmax);
    return r;
}
