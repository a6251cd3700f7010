#include "spread.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "../core/clock.h"
#include "../core/progress.h"
#include "../gpu/gl_util.h"
#include "../gpu/programs.h"

enum { PREP, DOWN, FETCH, PROGRAMS };
static const char* const PROGRAM_FILES[PROGRAMS] = {"render/shaders/spread_prep.comp", "render/shaders/spread_down.comp",
                                                    "render/shaders/spread_fetch.comp"};

struct veil_spread {
    GLuint program[PROGRAMS], ubo;
};

veil_result veil_spread_create(veil_spread** out, veil_error* err)
{
    *out = NULL;
    veil_spread* s = calloc(1, sizeof *s);
    if (!s) return veil_fail(err, VEIL_ERR_OOM, "out of memory creating the spread pass");
    veil_result r = VEIL_OK;
    for (int i = 0; i < PROGRAMS && r == VEIL_OK; ++i) r = veil_gpu_program(PROGRAM_FILES[i], &s->program[i], err);
    if (r == VEIL_OK)
        r = veil_gl_buffer(NULL, sizeof(veil_spread_block), GL_DYNAMIC_STORAGE_BIT, "veil spread block", &s->ubo, err);
    if (r != VEIL_OK) {
        veil_spread_destroy(s);
        return r;
    }
    *out = s;
    return VEIL_OK;
}

void veil_spread_destroy(veil_spread* s)
{
    if (!s) return;
    for (int i = 0; i < PROGRAMS; ++i) glDeleteProgram(s->program[i]);
    glDeleteBuffers(1, &s->ubo);
    free(s);
}

int veil_spread_levels(const veil_multiple* m, int w, int h)
{
    if (m->levels > 0) {
        /* a level whose texel spans the whole image adds nothing (and would pad the
         * chains far beyond it): at most ceil(log2(the larger side)) */
        int side = w > h ? w : h, top = 0;
        while ((1 << top) < side) ++top;
        int k = m->levels < VEIL_SPREAD_MAX_LEVEL ? m->levels : VEIL_SPREAD_MAX_LEVEL;
        return k < top ? k : (top > 0 ? top : 1);
    }
    int side = w < h ? w : h, k = 0;
    while ((2 << k) <= side) ++k; /* k = floor(log2(side)) */
    k -= 1;
    return k < 0 ? 0 : (k > 7 ? 7 : k);
}

float veil_spread_max_scattering(const veil_scene* sc, const float* aov_t, const float* aov_q, int w, int h)
{
    const float* ss = sc->medium.sigma_s;
    float mean = (ss[0] + ss[1] + ss[2]) / 3.0f, pmax = 0.0f;
    size_t n = (size_t)w * (size_t)h;
    for (size_t i = 0; i < n; ++i) {
        pmax = fmaxf(pmax, aov_t[4 * i + 3]);
        if (aov_q) pmax = fmaxf(pmax, aov_q[4 * i + 3]);
    }
    return pmax * mean;
}

static veil_result texture2d(int w, int h, int levels, const void* data, const char* label, GLuint* tex,
                             veil_error* err)
{
    glCreateTextures(GL_TEXTURE_2D, 1, tex);
    glTextureStorage2D(*tex, levels, GL_RGBA32F, w, h);
    if (data) glTextureSubImage2D(*tex, 0, 0, 0, w, h, GL_RGBA, GL_FLOAT, data);
    glTextureParameteri(*tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_NEAREST);
    glTextureParameteri(*tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(*tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTextureParameteri(*tex, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    static const float zero[4] = {0, 0, 0, 0};
    glTextureParameterfv(*tex, GL_TEXTURE_BORDER_COLOR, zero);
    glObjectLabel(GL_TEXTURE, *tex, -1, label);
    return veil_gl_check(label, err);
}

/* Level 0 of a padded chain, cropped to w x h. */
static veil_result read_level0(GLuint tex, int w, int h, int pw, int ph, float* out, veil_error* err)
{
    size_t floats = (size_t)pw * (size_t)ph * 4;
    float* all = malloc(floats * sizeof *all);
    if (!all) return veil_fail(err, VEIL_ERR_OOM, "spread: out of memory");
    veil_result r = veil_gl_read_texture(tex, GL_RGBA, floats, all, "reading back the spread's level 0", err);
    for (int y = 0; y < h && r == VEIL_OK; ++y)
        memcpy(out + 4 * (size_t)y * (size_t)w, all + 4 * (size_t)y * (size_t)pw, 4 * (size_t)w * sizeof *out);
    free(all);
    return r;
}

static void fill_block(const veil_scene* sc, const veil_spread_input* in, int K, int pw, int ph,
                       veil_spread_block* u)
{
    const veil_multiple* m = &sc->multiple;
    const veil_medium* md = &sc->medium;
    memset(u, 0, sizeof *u);
    for (int c = 0; c < 3; ++c) {
        u->sigma_a[c] = md->sigma_a[c];
        u->sigma_s[c] = md->sigma_s[c];
    }
    u->sigma_a[3] = (md->sigma_a[0] + md->sigma_a[1] + md->sigma_a[2]) / 3.0f;
    u->sigma_s[3] = (md->sigma_s[0] + md->sigma_s[1] + md->sigma_s[2]) / 3.0f;
    u->params[0] = m->c;
    u->params[1] = m->mask_epsilon;
    u->params[2] = md->phase.type == VEIL_PHASE_HG ? md->phase.g : 0.0f;
    /* the angle one pixel subtends at the image centre */
    u->params[3] = (float)(2.0 * tan(0.5 * in->fov_y_deg * VEIL_PI / 180.0) / in->height);
    u->sep[0] = m->sep_luminance, u->sep[1] = m->sep_luminance_width;
    u->sep[2] = m->sep_density, u->sep[3] = m->sep_density_width;
    for (int i = 0; i < 4; ++i) u->weights_lo[i] = m->weights[i];
    u->weights_hi[0] = m->weights[4], u->weights_hi[1] = m->weights[5];
    u->weights_hi[2] = m->k_ssc * (float)K;
    u->size[0] = in->width, u->size[1] = in->height, u->size[2] = pw, u->size[3] = ph;
    u->mode[0] = veil_spread_taps(m->filter);
    u->mode[1] = m->interp;
    u->mode[2] = K;
    u->flags[0] = m->mask != 0, u->flags[1] = m->luminance_weighting != 0;
    u->flags[2] = m->density_blur != 0, u->flags[3] = m->separation != 0;
}

/* After a pass of `passes`: with a progress sink, the pass finished and reported ("spread", passes done of
 * all), and 1 when a cancel was asked for (issue 41: a pass of a 4K frame takes most of a second on a
 * software rasteriser). */
static int pass_done(int pass, int passes)
{
    if (!veil_progress_wanted()) return 0;
    glFinish();
    veil_progress("spread", pass, passes);
    return pass < passes && veil_progress_cancelled();
}

veil_result veil_spread_run(veil_spread* s, const veil_scene* sc, const veil_spread_input* in, float* out,
                            float* level0, veil_spread_report* rep, veil_error* err)
{
    double t0 = veil_now_ms();
    int w = in->width, h = in->height;
    if (w < 1 || h < 1 || w > VEIL_SCENE_MAX_IMAGE || h > VEIL_SCENE_MAX_IMAGE)
        return veil_fail(err, VEIL_ERR_INVALID, "spread: image size %dx%d is outside 1..%d", w, h, VEIL_SCENE_MAX_IMAGE);
    if (!(in->aov_t || in->tex_t) || !(in->aov_s || in->tex_s) || !(in->fov_y_deg > 0.0f && in->fov_y_deg < 180.0f))
        return veil_fail(err, VEIL_ERR_INVALID, "spread: missing march buffers or field of view %g", in->fov_y_deg);
    int K = veil_spread_levels(&sc->multiple, w, h);
    int step = 1 << K, pw = (w + step - 1) / step * step, ph = (h + step - 1) / step * step;
    size_t n = (size_t)w * (size_t)h, floats;
    if (!veil_mul_sizes(n, 4, 1, 1, &floats)) return veil_fail(err, VEIL_ERR_LIMIT, "spread: image too large");
    float* L = NULL;
    float* zeros = NULL;
    if (!in->L) {
        L = malloc(floats * sizeof *L);
        if (!L) return veil_fail(err, VEIL_ERR_OOM, "spread: out of memory");
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 4; ++c) L[4 * i + c] = c < 3 ? in->background[c] : 0.0f;
    }
    if (!in->aov_q && !in->tex_q) {
        zeros = calloc(floats, sizeof *zeros);
        if (!zeros) {
            free(L);
            return veil_fail(err, VEIL_ERR_OOM, "spread: out of memory");
        }
    }
    veil_spread_block u;
    fill_block(sc, in, K, pw, ph, &u);
    enum { IN_L, IN_T, IN_S, IN_Q, SC, P, SSC, OUT, TEX };
    GLuint tex[TEX] = {0};
    const void* data[4] = {in->L ? (const void*)in->L : L, in->aov_t, in->aov_s, in->aov_q ? (const void*)in->aov_q : zeros};
    veil_result r = VEIL_OK;
    /* T, S and Q where the march left them (its images, read in place: no round trip through the CPU) */
    const GLuint given[4] = {0, in->tex_t, in->tex_s, in->tex_q};
    for (int i = IN_L; i <= IN_Q && r == VEIL_OK; ++i)
        r = given[i] ? VEIL_OK : texture2d(w, h, 1, data[i], "veil spread input", &tex[i], err);
    /* the separated chain needs every level only with separation; else one texel level keeps the binding valid */
    int sep = sc->multiple.separation != 0;
    if (r == VEIL_OK) r = texture2d(pw, ph, K + 1, NULL, "veil spread L_sc chain", &tex[SC], err);
    if (r == VEIL_OK) r = texture2d(pw, ph, K + 1, NULL, "veil spread P chain", &tex[P], err);
    if (r == VEIL_OK) r = texture2d(pw, ph, sep ? K + 1 : 1, NULL, "veil spread L_ssc chain", &tex[SSC], err);
    if (r == VEIL_OK) r = texture2d(w, h, 1, NULL, "veil spread output", &tex[OUT], err);
    free(L);
    free(zeros);
    if (r == VEIL_OK) {
        if (given[IN_T] || given[IN_S] || given[IN_Q]) glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT); /* the march's stores */
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_SPREAD, s->ubo);
        glNamedBufferSubData(s->ubo, 0, sizeof u, &u);
        /* 1: level 0 */
        glUseProgram(s->program[PREP]);
        for (int i = IN_L; i <= IN_Q; ++i)
            glBindImageTexture(VEIL_SPREAD_IN_L + (GLuint)i, given[i] ? given[i] : tex[i], 0, GL_FALSE, 0, GL_READ_ONLY,
                               GL_RGBA32F);
        glBindImageTexture(VEIL_SPREAD_OUT_SC, tex[SC], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glBindImageTexture(VEIL_SPREAD_OUT_P, tex[P], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glBindImageTexture(VEIL_SPREAD_OUT_SSC, tex[SSC], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glDispatchCompute(veil_groups(pw, VEIL_SPREAD_GROUP), veil_groups(ph, VEIL_SPREAD_GROUP), 1);
        int cancelled = pass_done(1, K + 2);
        /* 2: levels 1..K, each from the one below */
        glUseProgram(s->program[DOWN]);
        glBindTextureUnit(VEIL_SPREAD_TEX_SC, tex[SC]);
        glBindTextureUnit(VEIL_SPREAD_TEX_P, tex[P]);
        glBindTextureUnit(VEIL_SPREAD_TEX_SSC, tex[SSC]);
        for (int k = 1; k <= K && !cancelled; ++k) {
            glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
            u.mode[3] = k;
            glNamedBufferSubData(s->ubo, offsetof(veil_spread_block, mode), sizeof u.mode, u.mode);
            glBindImageTexture(VEIL_SPREAD_OUT_SC, tex[SC], k, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
            glBindImageTexture(VEIL_SPREAD_OUT_P, tex[P], k, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
            glBindImageTexture(VEIL_SPREAD_OUT_SSC, tex[SSC], sep ? k : 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
            glDispatchCompute(veil_groups(pw >> k, VEIL_SPREAD_GROUP), veil_groups(ph >> k, VEIL_SPREAD_GROUP), 1);
            cancelled = pass_done(1 + k, K + 2);
        }
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        /* 3: each pixel's level, read */
        if (!cancelled) {
            glUseProgram(s->program[FETCH]);
            glBindImageTexture(VEIL_SPREAD_OUT, tex[OUT], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
            glDispatchCompute(veil_groups(w, VEIL_SPREAD_GROUP), veil_groups(h, VEIL_SPREAD_GROUP), 1);
            glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
            pass_done(K + 2, K + 2);
        }
        for (GLuint i = 0; i < 8; ++i) glBindImageTexture(i, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
        for (GLuint i = 0; i < 3; ++i) glBindTextureUnit(i, 0);
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_SPREAD, 0);
        glUseProgram(0);
        r = veil_gl_check("screen-space spread (render/shaders/spread_*.comp)", err);
        if (r == VEIL_OK && cancelled)
            r = veil_fail(err, VEIL_ERR_CANCELLED, "cancelled by the progress callback during the screen-space spread");
        if (r == VEIL_OK) r = veil_gl_read_texture(tex[OUT], GL_RGBA, floats, out, "reading back the spread", err);
        if (r == VEIL_OK && level0) r = read_level0(tex[SC], w, h, pw, ph, level0, err);
    }
    glDeleteTextures(TEX, tex);
    if (rep) {
        rep->levels = K;
        rep->padded_width = pw, rep->padded_height = ph;
        rep->ms = veil_now_ms() - t0;
    }
    return r;
}
