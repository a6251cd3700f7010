#include "opv_set.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/hash.h"
#include "../core/progress.h"
#include "../gpu/gl_util.h"
#include "../gpu/programs.h"
#include "opv_gpu.h"

struct veil_opv_set {
    veil_opv_programs programs;
    GLuint sparse_program; /* propagate/shaders/propagate_sparse.comp, made when first needed */
    GLuint tex[VEIL_MAX_OPV_TEXTURES];
    int dims[VEIL_MAX_OPV_TEXTURES][3];
    uint64_t key[VEIL_MAX_OPV_TEXTURES]; /* 0: none (or being remade) */
};

veil_result veil_opv_set_create(veil_opv_set** out, veil_error* err)
{
    *out = NULL;
    veil_opv_set* s = calloc(1, sizeof *s);
    if (!s) return veil_fail(err, VEIL_ERR_OOM, "out of memory creating the optical-depth volumes");
    veil_result r = veil_opv_programs_create(&s->programs, err);
    if (r != VEIL_OK) {
        free(s);
        return r;
    }
    *out = s;
    return VEIL_OK;
}

void veil_opv_set_clear(veil_opv_set* s)
{
    glDeleteTextures(VEIL_MAX_OPV_TEXTURES, s->tex);
    memset(s->tex, 0, sizeof s->tex);
    memset(s->dims, 0, sizeof s->dims);
    memset(s->key, 0, sizeof s->key);
}

void veil_opv_set_destroy(veil_opv_set* s)
{
    if (!s) return;
    veil_opv_set_clear(s);
    glDeleteProgram(s->sparse_program);
    veil_opv_programs_destroy(&s->programs);
    free(s);
}

GLuint veil_opv_set_texture(const veil_opv_set* s, int t) { return s->tex[t]; }

uint64_t veil_opv_texture_key(uint64_t ev_key, const veil_opv_params* params, const veil_opv_light* lights, int count)
{
    uint64_t key = veil_hash_bytes(ev_key, params, sizeof *params);
    for (int c = 0; c < count; ++c) key = veil_hash_bytes(key, &lights[c], sizeof lights[c]);
    return key;
}

int veil_opv_set_has(const veil_opv_set* s, int t, uint64_t key) { return s->tex[t] && s->key[t] == key; }

/* Texture t of dims (kept when it has them already). */
static veil_result texture_of(veil_opv_set* s, int t, const int dims[3], const char* label, veil_error* err)
{
    if (s->tex[t] && !memcmp(s->dims[t], dims, sizeof s->dims[t])) return VEIL_OK;
    glDeleteTextures(1, &s->tex[t]);
    s->tex[t] = 0;
    memset(s->dims[t], 0, sizeof s->dims[t]);
    veil_result r = veil_gl_texture3d(GL_RGBA32F, dims, label, &s->tex[t], err);
    if (r == VEIL_OK) memcpy(s->dims[t], dims, sizeof s->dims[t]);
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
static long long level_of(const veil_opv_light* l, const int32_t* b, int sun_sign[3], const int c[3])
{
    long long v = 0;
    for (int a = 0; a < 3; ++a)
        v += l->type == VEIL_LIGHT_DIRECTIONAL ? -(long long)sun_sign[a] * b[a] : llabs((long long)b[a] - c[a]);
    return v;
}

/* Texture t over a sparse volume: for each light, passes of
 * propagate/shaders/propagate_sparse.comp over the kept bricks, level by
 * level (each pass reads only bricks of earlier passes). *passes: the most
 * passes of any light. */
static veil_result sparse_depths(veil_opv_set* s, const veil_ev_sparse* sp, const veil_opv_light* ol, int count,
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
        float light[4];
        int sign[3], cb[3];
        for (int a = 0; a < 3; ++a) {
            light[a] = ol[c].v[a] + (ol[c].type == VEIL_LIGHT_DIRECTIONAL ? 0.0f : 0.5f);
            sign[a] = ol[c].v[a] > 0.0f ? 1 : ol[c].v[a] < 0.0f ? -1 : 0;
            double cell = floor(((double)light[a] - 0.5) / VEIL_BRICK);
            cb[a] = cell < -1e9 ? -1000000000 : cell > 1e9 ? 1000000000 : (int)cell;
        }
        light[3] = (float)ol[c].type;
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
        if (r != VEIL_OK) break;
        glCreateTextures(GL_TEXTURE_BUFFER, 1, &list_tex);
        glTextureBuffer(list_tex, GL_R32I, buf);
        glUseProgram(p);
        glProgramUniform4fv(p, glGetUniformLocation(p, "u_light"), 1, light);
        glProgramUniform1i(p, glGetUniformLocation(p, "u_channel"), c);
        veil_ev_sparse_bind(sp);
        glBindTextureUnit(VEIL_TEX_EV, sp->atlas);
        glBindTextureUnit(VEIL_TEX_SPARSE_LIST, list_tex);
        glBindTextureUnit(VEIL_TEX_OPV0, tex);
        glBindImageTexture(VEIL_IMAGE_SPARSE_OUT, tex, 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
        int done = 0;
        for (size_t k = 0; k < levels; ++k) { /* rank 0, the bricks nearest the light, first */
            size_t m = first[k + 1] - first[k];
            if (!m) continue;
            glProgramUniform1i(p, glGetUniformLocation(p, "u_first"), (GLint)first[k]);
            for (size_t g = 0; g < m; g += 65535) { /* GL's guaranteed work groups per dispatch */
                if (g) glProgramUniform1i(p, glGetUniformLocation(p, "u_first"), (GLint)(first[k] + g));
                glDispatchCompute((GLuint)(m - g < 65535 ? m - g : 65535), 1, 1);
            }
            glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
            ++done;
        }
        *passes = done > *passes ? done : *passes;
        glBindImageTexture(VEIL_IMAGE_SPARSE_OUT, 0, 0, GL_TRUE, 0, GL_READ_WRITE, GL_RGBA32F);
        glBindTextureUnit(VEIL_TEX_OPV0, 0);
        glBindTextureUnit(VEIL_TEX_SPARSE_LIST, 0);
        glBindTextureUnit(VEIL_TEX_EV, 0);
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

veil_result veil_opv_set_update(veil_opv_set* s, const veil_grid* g, GLuint ev, const veil_ev_sparse* sp,
                                uint64_t ev_key, const veil_light* lights, int n, const veil_opv_params* params,
                                veil_opv_report* rep, veil_error* err)
{
    memset(rep, 0, sizeof *rep);
    veil_result r = VEIL_OK;
    const int report = veil_progress_wanted();
    for (int t = 0; 4 * t < n && r == VEIL_OK; ++t) {
        if (report) { /* lights done of all; the textures before this one finished first */
            glFinish();
            veil_progress("optical depth, lights", 4.0 * t, n);
        }
        int count = n - 4 * t < 4 ? n - 4 * t : 4;
        veil_opv_light ol[4];
        for (int c = 0; c < count; ++c) veil_opv_light_from_world(g, &lights[4 * t + c], &ol[c]);
        uint64_t key = veil_opv_texture_key(ev_key, params, ol, count);
        if (veil_opv_set_has(s, t, key)) {
            ++rep->cached;
            continue;
        }
        r = texture_of(s, t, sp ? sp->atlas_texels : g->dims, sp ? "veil optical depth (sparse atlas)" : "veil optical-depth volume", err);
        int it = 0;
        s->key[t] = 0;
        if (r == VEIL_OK && sp) r = sparse_depths(s, sp, ol, count, s->tex[t], &it, err);
        else if (r == VEIL_OK) r = veil_opv_gpu(&s->programs, g, ev, ol, count, params, &s->tex[t], &it, err);
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
                                            const veil_opv_light* lights, int n_lights,
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
    for (int t = 0; t < n_tex && r == VEIL_OK; ++t)
        r = veil_gl_texture3d(GL_RGBA32F, g->dims, "veil optical-depth volume", &opv[t], err);
    if (r == VEIL_OK) r = veil_opv_gpu(&s->programs, g, ev, lights, n_lights, params, opv, iterations, err);
    for (int t = 0; t < n_tex && r == VEIL_OK; ++t) {
        r = veil_gl_read_texture(opv[t], GL_RGBA, nv * 4, tmp, "reading back an OPV", err);
        for (int c = 0; c < 4 && 4 * t + c < n_lights && r == VEIL_OK; ++c)
            for (size_t v = 0; v < nv; ++v) out[(size_t)(4 * t + c) * nv + v] = tmp[4 * v + c];
    }
    glDeleteTextures(1, &ev);
    glDeleteTextures(VEIL_MAX_OPV_TEXTURES, opv);
    free(tmp);
    return r;
}
