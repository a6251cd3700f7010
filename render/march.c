#include "march.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/progress.h"
#include "../gpu/gl_util.h"
#include "../gpu/programs.h"
#include "../scene/camera.h"
#include "../scene/light.h"

struct veil_march {
    GLuint program, program_emission, ubo; /* the march, and its variant with emission */
    GLuint program_sparse[2];              /* over a sparse volume (and with emission), made when first needed */
};

veil_result veil_march_create(veil_march** out, veil_error* err)
{
    *out = NULL;
    veil_march* m = calloc(1, sizeof *m);
    if (!m) return veil_fail(err, VEIL_ERR_OOM, "out of memory creating the ray marcher");
    veil_result r = veil_gpu_program("render/shaders/march.comp", &m->program, err);
    if (r == VEIL_OK) /* the emission variant: the same file with VEIL_MARCH_EMISSION defined */
        r = veil_gpu_program_variant("render/shaders/march.comp", "#define VEIL_MARCH_EMISSION 1\n", "emission",
                                     &m->program_emission, err);
    if (r == VEIL_OK)
        r = veil_gl_buffer(NULL, sizeof(veil_march_block), GL_DYNAMIC_STORAGE_BIT, "veil march block", &m->ubo, err);
    if (r != VEIL_OK) {
        veil_march_destroy(m);
        return r;
    }
    *out = m;
    return VEIL_OK;
}

void veil_march_destroy(veil_march* m)
{
    if (!m) return;
    glDeleteProgram(m->program);
    glDeleteProgram(m->program_emission);
    glDeleteProgram(m->program_sparse[0]);
    glDeleteProgram(m->program_sparse[1]);
    glDeleteBuffers(1, &m->ubo);
    free(m);
}

static void set3(float dst[4], const float src[3], float w)
{
    dst[0] = src[0], dst[1] = src[1], dst[2] = src[2], dst[3] = w;
}

veil_result veil_march_block_fill(const veil_march_desc* d, veil_march_block* u, veil_error* err)
{
    veil_camera_basis cam;
    veil_result r = veil_camera_make_basis(d->camera, d->width, d->height, &cam, err);
    if (r != VEIL_OK) return r;
    memset(u, 0, sizeof *u);
    const veil_medium* m = &d->scene->medium;
    set3(u->cam_pos, cam.pos, 0.0f);
    set3(u->cam_fwd, cam.fwd, 0.0f);
    set3(u->cam_right, cam.right, 0.0f);
    set3(u->cam_up, cam.up, 0.0f);
    for (int c = 0; c < 3; ++c) u->sigma_t[c] = m->sigma_a[c] + m->sigma_s[c];
    set3(u->sigma_s, m->sigma_s, 0.0f);
    if (!d->no_background) set3(u->background, d->scene->background, 0.0f);
    float g = m->phase.type == VEIL_PHASE_HG ? m->phase.g : 0.0f;
    if (d->grid) {
        float lo[3], hi[3], inv[3];
        veil_grid_medium_box(d->grid, lo, hi);
        for (int a = 0; a < 3; ++a) inv[a] = 1.0f / ((float)d->grid->dims[a] * d->grid->voxel);
        set3(u->box_min, lo, 0.0f);
        set3(u->box_max, hi, 0.0f);
        set3(u->tex_min, d->grid->origin, 0.0f);
        set3(u->tex_inv_size, inv, 0.0f);
        float md = VEIL_MIN_LIGHT_DISTANCE_VOXELS * d->grid->voxel;
        u->march[0] = d->step_voxels * d->grid->voxel;
        u->march[1] = md * md;
        u->march[2] = d->grid->voxel;
    } else {
        float md = VEIL_MIN_LIGHT_DISTANCE_VOXELS * VEIL_FOG_MIN_STEP;
        u->march[0] = VEIL_FOG_MIN_STEP;
        u->march[1] = md * md;
    }
    u->march[3] = g;
    u->limits[0] = d->max_distance > 0.0f ? d->max_distance : 3.0e38f;
    int fogs = 0;
    for (size_t i = 0; i < m->source_count && fogs < VEIL_MAX_FOGS; ++i) {
        const veil_source* src = &m->sources[i];
        if (src->type != VEIL_SOURCE_EXPONENTIAL) continue;
        veil_gpu_fog* f = &u->fogs[fogs++];
        set3(f->direction, src->fog.direction, src->fog.density);
        set3(f->origin, src->fog.origin, src->fog.falloff);
        set3(f->box_min, src->fog.bounds[0], 0.0f);
        set3(f->box_max, src->fog.bounds[1], 0.0f);
    }
    int n = d->light_count < VEIL_MAX_LIGHTS ? d->light_count : VEIL_MAX_LIGHTS;
    for (int l = 0; l < n; ++l) veil_light_to_gpu(&d->lights[l], &u->lights[l]);
    u->size[0] = d->width, u->size[1] = d->height, u->size[2] = n, u->size[3] = fogs;
    u->flags[0] = d->grid != NULL;
    /* empty bricks hold no density but may glow: no skipping with emission (a sparse volume's bricks
     * not kept hold neither) */
    u->flags[1] = d->grid != NULL && fogs == 0 && d->skip_empty && (!d->emission || d->sparse);
    u->limits[1] = d->grid != NULL && d->emission ? 1.0f : 0.0f;
    u->flags[2] = d->seed;
    u->flags[3] = d->end_distance != NULL;
    for (int k = 0; d->grid && !d->sparse && k < d->sun_count && k < VEIL_MAX_SUNS; ++k) {
        int l = d->suns[k].light;
        if (l < 0 || l >= n) continue;
        u->sun_of[l / 4][l % 4] = k + 1;
        for (int row = 0; row < 3; ++row) memcpy(u->sun_map[3 * k + row], d->suns[k].to_tex[row], sizeof u->sun_map[0]);
        const float* c = d->suns[k].space.axis[2];
        float along = sqrtf(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        u->sun_step[k][0] = along * d->grid->voxel;
        u->sun_step[k][1] = (float)d->suns[k].space.nodes[2];
        u->sun_step[k][2] = ceilf(along); /* pieces of at most a voxel, as the prefix sum's panels */
    }
    const veil_multiple* ms = &d->scene->multiple;
    if (d->diffusion && d->diffusion->texture) {
        set3(u->diffusion, d->diffusion->tex_min, d->diffusion->kind);
        set3(u->diffusion_inv, d->diffusion->tex_inv, 0.0f);
    }
    if (ms->volumetric && ms->volumetric_method == VEIL_VOLUMETRIC_OCTAVE && ms->octaves > 1) {
        u->octave[0] = ms->octave_a, u->octave[1] = ms->octave_b, u->octave[2] = ms->octave_c;
        u->octave[3] = (float)ms->octaves;
    }
    return VEIL_OK;
}

void veil_march_bind_depths(const veil_march_desc* d)
{
    for (int t = 0; t < VEIL_MAX_OPV_TEXTURES; ++t) glBindTextureUnit(VEIL_TEX_OPV0 + t, d && d->opv ? d->opv[t] : 0);
    if (d && d->sparse) return; /* the sparse tables hold these units */
    for (int k = 0; k < VEIL_MAX_SUNS; ++k)
        glBindTextureUnit(VEIL_TEX_SUN0 + k, d && d->grid && k < d->sun_count ? d->suns[k].texture : 0);
}

static veil_result image(int w, int h, const char* label, GLuint* tex, veil_error* err)
{
    glCreateTextures(GL_TEXTURE_2D, 1, tex);
    glTextureStorage2D(*tex, 1, GL_RGBA32F, w, h);
    glObjectLabel(GL_TEXTURE, *tex, -1, label);
    return veil_gl_check(label, err);
}

static uint64_t g_band_work = VEIL_MARCH_DISPATCH_WORK;

void veil_march_set_dispatch_work(uint64_t work) { g_band_work = work ? work : VEIL_MARCH_DISPATCH_WORK; }

int veil_march_band_rows(const veil_march_desc* d, int w, int h)
{
    double steps = 1.0;
    if (d->grid) {
        float lo[3], hi[3];
        veil_grid_medium_box(d->grid, lo, hi);
        const double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
        steps += sqrt(dx * dx + dy * dy + dz * dz) / ((double)d->step_voxels * d->grid->voxel);
    }
    for (size_t i = 0; i < d->scene->medium.source_count; ++i)
        if (d->scene->medium.sources[i].type == VEIL_SOURCE_EXPONENTIAL) steps += 64.0;
    const double per_row = (double)w * steps * (1.0 + d->light_count);
    double rows = floor((double)g_band_work / per_row / VEIL_MARCH_GROUP) * VEIL_MARCH_GROUP;
    if (rows < VEIL_MARCH_GROUP) rows = VEIL_MARCH_GROUP;
    return rows >= h ? h : (int)rows;
}

veil_result veil_march_run(veil_march* m, const veil_march_desc* d, veil_image_set* out, veil_error* err)
{
    veil_image_set_free(out);
    veil_march_block u;
    veil_result r = veil_march_block_fill(d, &u, err);
    if (r != VEIL_OK) return r;
    int w = d->width, h = d->height;
    size_t floats;
    if (!veil_mul_sizes((size_t)w, (size_t)h, 4, 1, &floats)) return veil_fail(err, VEIL_ERR_LIMIT, "image too large");
    enum { N = 5 };
    GLuint tex[N] = {0};
    static const char* const labels[N] = {"veil image", "veil image T, P", "veil image single, depth",
                                          "veil image volumetric", "veil image out-scattered single"};
    static const GLuint units[N] = {VEIL_IMAGE_OUT, VEIL_IMAGE_AOV_T, VEIL_IMAGE_AOV_S, VEIL_IMAGE_AOV_V,
                                    VEIL_IMAGE_AOV_Q};
    for (int i = 0; i < N && r == VEIL_OK; ++i) r = image(w, h, labels[i], &tex[i], err);
    GLuint limit = 0;
    if (r == VEIL_OK && d->end_distance) {
        glCreateTextures(GL_TEXTURE_2D, 1, &limit);
        glTextureStorage2D(limit, 1, GL_R32F, w, h);
        glTextureSubImage2D(limit, 0, 0, 0, w, h, GL_RED, GL_FLOAT, d->end_distance);
        glObjectLabel(GL_TEXTURE, limit, -1, "veil ray ends");
        r = veil_gl_check("veil ray ends", err);
    }
    float** dst[N] = {&out->rgba, &out->aov_t, &out->aov_s, &out->aov_v, &out->aov_q};
    for (int i = 0; i < N && r == VEIL_OK; ++i) {
        *dst[i] = malloc(floats * sizeof(float));
        if (!*dst[i]) r = veil_fail(err, VEIL_ERR_OOM, "out of memory for a %dx%d image", w, h);
    }
    if (r == VEIL_OK) {
        out->width = w, out->height = h;
        glNamedBufferSubData(m->ubo, 0, sizeof u, &u);
        int e = d->emission != 0;
        if (d->grid && d->sparse && !m->program_sparse[e])
            r = veil_gpu_program_variant("render/shaders/march.comp",
                                         e ? "#define VEIL_SPARSE 1\n#define VEIL_MARCH_EMISSION 1\n" : "#define VEIL_SPARSE 1\n",
                                         e ? "sparse, emission" : "sparse", &m->program_sparse[e], err);
    }
    if (r == VEIL_OK) {
        glUseProgram(d->grid && d->sparse ? m->program_sparse[d->emission != 0]
                     : d->grid && d->emission ? m->program_emission : m->program);
        veil_ev_sparse_bind(d->grid ? d->sparse : NULL);
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_MARCH, m->ubo);
        glBindTextureUnit(VEIL_TEX_EV, d->grid ? d->ev : 0);
        glBindTextureUnit(VEIL_TEX_OCC, d->grid ? d->occupancy : 0);
        veil_march_bind_depths(d);
        glBindTextureUnit(VEIL_TEX_LIMIT, limit);
        glBindTextureUnit(VEIL_TEX_DIFFUSION, d->diffusion ? d->diffusion->texture : 0);
        glBindTextureUnit(VEIL_TEX_EMISSION, d->grid ? d->emission : 0);
        for (int i = 0; i < N; ++i) glBindImageTexture(units[i], tex[i], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        const GLuint program = d->grid && d->sparse ? m->program_sparse[d->emission != 0]
                               : d->grid && d->emission ? m->program_emission : m->program;
        const GLint first_row = glGetUniformLocation(program, "u_first_row");
        const int band = veil_march_band_rows(d, w, h);
        const int report = veil_progress_wanted();
        if (report) veil_progress("march, rows", 0, h);
        for (int y = 0; y < h; y += band) {
            glProgramUniform1i(program, first_row, y);
            glDispatchCompute(veil_groups(w, VEIL_MARCH_GROUP), veil_groups(h - y < band ? h - y : band, VEIL_MARCH_GROUP), 1);
            if (report) { /* what is reported is done */
                glFinish();
                veil_progress("march, rows", y + band < h ? y + band : h, h);
            } else {
                glFlush();
            }
        }
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
        for (int i = 0; i < N; ++i) glBindImageTexture(units[i], 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        for (int t = 0; t <= VEIL_TEX_EMISSION; ++t) glBindTextureUnit((GLuint)t, 0);
        if (!(d->grid && d->sparse)) veil_march_bind_depths(NULL);
        veil_ev_sparse_bind(NULL);
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_MARCH, 0);
        glUseProgram(0);
        r = veil_gl_check("ray march (render/shaders/march.comp)", err);
        for (int i = 0; i < N && r == VEIL_OK; ++i)
            r = veil_gl_read_texture(tex[i], GL_RGBA, floats, *dst[i], "reading back the image", err);
    }
    glDeleteTextures(N, tex);
    glDeleteTextures(1, &limit);
    if (r != VEIL_OK) veil_image_set_free(out);
    return r;
}
