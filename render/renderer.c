#include "renderer.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../propagate/opv_gpu.h"
#include "../volume/inject_gpu.h"
#include "camera.h"
#include "gl_util.h"

struct veil_renderer {
    GLuint inject, propagate, march;
    unsigned long long memory_budget; /* bytes, see veil_gl_info */
};

veil_result veil_renderer_create(const veil_gl* gl, veil_renderer** out, veil_error* err)
{
    *out = NULL;
    veil_renderer* r = calloc(1, sizeof *r);
    if (!r) return veil_fail(err, VEIL_ERR_OOM, "out of memory creating the renderer");
    r->memory_budget = veil_gl_get_info(gl)->memory_budget;
    veil_result res = veil_gl_compute_program("volume/shaders/inject_rbf.comp", veil_shader_inject_rbf_comp,
                                              &r->inject, err);
    if (res == VEIL_OK)
        res = veil_gl_compute_program("propagate/shaders/propagate_jacobi.comp",
                                      veil_shader_propagate_jacobi_comp, &r->propagate, err);
    if (res == VEIL_OK)
        res = veil_gl_compute_program("render/shaders/march.comp", veil_shader_march_comp, &r->march, err);
    if (res != VEIL_OK) {
        veil_renderer_destroy(r);
        return res;
    }
    *out = r;
    return VEIL_OK;
}

void veil_renderer_destroy(veil_renderer* r)
{
    if (!r) return;
    glDeleteProgram(r->inject);
    glDeleteProgram(r->propagate);
    glDeleteProgram(r->march);
    free(r);
}

/* GPU bytes of the EV and the OPVs (plus the scratch ping-pong texture),
 * checked for overflow before anything is allocated. */
static veil_result check_volume_size(const veil_renderer* r, const veil_grid* g, int n_lights, veil_error* err)
{
    size_t n_tex = (size_t)(n_lights + 3) / 4, bytes_ev, bytes_opv;
    if (!veil_mul_sizes((size_t)g->dims[0], (size_t)g->dims[1], (size_t)g->dims[2], sizeof(float), &bytes_ev) ||
        !veil_mul_sizes(bytes_ev, 4, n_lights > 0 ? n_tex + 1 : 0, 1, &bytes_opv) || bytes_opv > SIZE_MAX - bytes_ev)
        return veil_fail(err, VEIL_ERR_LIMIT, "a %dx%dx%d volume with %d lights overflows the address space",
                         g->dims[0], g->dims[1], g->dims[2], n_lights);
    unsigned long long total = (unsigned long long)bytes_ev + bytes_opv;
    if (total > r->memory_budget)
        return veil_fail(err, VEIL_ERR_LIMIT,
                         "a %dx%dx%d extinction volume with %d lights needs %.0f MiB of textures, more than the "
                         "%.0f MiB allowed on this device; lower medium.max_resolution",
                         g->dims[0], g->dims[1], g->dims[2], n_lights, (double)total / 1048576.0,
                         (double)r->memory_budget / 1048576.0);
    return VEIL_OK;
}

static veil_result upload_density(const veil_grid* g, const float* density, GLuint* tex, veil_error* err)
{
    veil_result r = veil_gl_texture3d(GL_R32F, g->dims, "veil extinction volume", tex, err);
    if (r != VEIL_OK) return r;
    glTextureSubImage3D(*tex, 0, 0, 0, 0, g->dims[0], g->dims[1], g->dims[2], GL_RED, GL_FLOAT, density);
    return veil_gl_check("uploading the extinction volume", err);
}

static veil_result read_texture(GLuint tex, GLenum format, size_t floats, float* out, const char* what,
                                veil_error* err)
{
    size_t bytes = floats * sizeof(float);
    if (bytes > (size_t)INT32_MAX) return veil_fail(err, VEIL_ERR_LIMIT, "%s: %zu bytes is too large to read back", what, bytes);
    glGetTextureImage(tex, 0, format, GL_FLOAT, (GLsizei)bytes, out);
    return veil_gl_check(what, err);
}

static void lights_to_index_space(const veil_scene* s, const veil_grid* g, veil_opv_light* out)
{
    for (size_t l = 0; l < s->light_count; ++l) veil_opv_light_from_world(g, &s->lights[l], &out[l]);
}

static float max_sigma_t(const veil_medium* m)
{
    float mx = 0.0f;
    for (int c = 0; c < 3; ++c) mx = fmaxf(mx, m->sigma_a[c] + m->sigma_s[c]);
    return mx;
}

static void set_march_uniforms(GLuint p, const veil_scene* s, const veil_camera_basis* cam, int w, int h,
                               const veil_grid* g, float step_voxels, uint32_t seed)
{
    glProgramUniform2i(p, glGetUniformLocation(p, "u_size"), w, h);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_cam_pos"), 1, cam->pos);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_cam_fwd"), 1, cam->fwd);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_cam_right"), 1, cam->right);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_cam_up"), 1, cam->up);
    glProgramUniform1i(p, glGetUniformLocation(p, "u_has_volume"), g != NULL);
    float sigma_t[3];
    for (int c = 0; c < 3; ++c) sigma_t[c] = s->medium.sigma_a[c] + s->medium.sigma_s[c];
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_sigma_t"), 1, sigma_t);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_sigma_s"), 1, s->medium.sigma_s);
    glProgramUniform1f(p, glGetUniformLocation(p, "u_g"), s->medium.phase.type == VEIL_PHASE_HG ? s->medium.phase.g : 0.0f);
    glProgramUniform1ui(p, glGetUniformLocation(p, "u_seed"), seed);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_background"), 1, s->background);
    if (g) {
        float hi[3];
        for (int a = 0; a < 3; ++a) hi[a] = g->origin[a] + (float)g->dims[a] * g->voxel;
        glProgramUniform3fv(p, glGetUniformLocation(p, "u_box_min"), 1, g->origin);
        glProgramUniform3fv(p, glGetUniformLocation(p, "u_box_max"), 1, hi);
        glProgramUniform1f(p, glGetUniformLocation(p, "u_step"), step_voxels * g->voxel);
        float md = VEIL_MIN_LIGHT_DISTANCE_VOXELS * g->voxel;
        glProgramUniform1f(p, glGetUniformLocation(p, "u_min_dist2"), md * md);
    }
    int n = (int)s->light_count;
    GLint types[VEIL_MAX_LIGHTS] = {0};
    GLfloat pos[3 * VEIL_MAX_LIGHTS] = {0}, dir[3 * VEIL_MAX_LIGHTS] = {0}, col[3 * VEIL_MAX_LIGHTS] = {0};
    for (int l = 0; l < n; ++l) {
        types[l] = s->lights[l].type;
        memcpy(pos + 3 * l, s->lights[l].position, sizeof(float[3]));
        memcpy(dir + 3 * l, s->lights[l].direction, sizeof(float[3]));
        memcpy(col + 3 * l, s->lights[l].color, sizeof(float[3]));
    }
    glProgramUniform1i(p, glGetUniformLocation(p, "u_light_count"), n);
    glProgramUniform1iv(p, glGetUniformLocation(p, "u_light_type"), VEIL_MAX_LIGHTS, types);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_light_pos"), VEIL_MAX_LIGHTS, pos);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_light_dir"), VEIL_MAX_LIGHTS, dir);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_light_color"), VEIL_MAX_LIGHTS, col);
    GLint units[VEIL_MAX_OPV_TEXTURES];
    for (int t = 0; t < VEIL_MAX_OPV_TEXTURES; ++t) units[t] = VEIL_TEX_OPV0 + t;
    glProgramUniform1iv(p, glGetUniformLocation(p, "u_opv"), VEIL_MAX_OPV_TEXTURES, units);
}

/* Propagates (when there is a volume) and marches. ev may be 0 (no medium). */
static veil_result propagate_and_march(veil_renderer* r, const veil_scene* s, const veil_grid* g, GLuint ev,
                                       const veil_render_opts* o, float** rgba, veil_render_stats* st,
                                       veil_error* err)
{
    int w = o->width > 0 ? o->width : s->camera.width;
    int h = o->height > 0 ? o->height : s->camera.height;
    if (w < 1 || h < 1 || w > VEIL_SCENE_MAX_IMAGE || h > VEIL_SCENE_MAX_IMAGE)
        return veil_fail(err, VEIL_ERR_INVALID, "image size %dx%d is outside 1..%d", w, h, VEIL_SCENE_MAX_IMAGE);
    if (s->light_count > VEIL_MAX_LIGHTS)
        return veil_fail(err, VEIL_ERR_LIMIT, "%zu lights; at most %d are supported", s->light_count, VEIL_MAX_LIGHTS);
    veil_camera_basis cam;
    veil_result res = veil_camera_make_basis(&s->camera, w, h, &cam, err);
    if (res != VEIL_OK) return res;
    size_t floats;
    if (!veil_mul_sizes((size_t)w, (size_t)h, 4, 1, &floats)) return veil_fail(err, VEIL_ERR_LIMIT, "image too large");
    float step = o->step_voxels > 0.0f ? o->step_voxels : VEIL_DEFAULT_STEP_VOXELS;

    GLuint opv[VEIL_MAX_OPV_TEXTURES] = {0}, out_tex = 0;
    int n_tex = ((int)s->light_count + 3) / 4;
    double t0 = veil_now_ms();
    if (ev) {
        veil_opv_light lights[VEIL_MAX_LIGHTS];
        lights_to_index_space(s, g, lights);
        for (int t = 0; t < n_tex && res == VEIL_OK; ++t)
            res = veil_gl_texture3d(GL_RGBA32F, g->dims, "veil optical-depth volume", &opv[t], err);
        float st_max = max_sigma_t(&s->medium);
        /* D changes of tol move tau by at most st_max * tol */
        veil_opv_params params = {.tolerance = st_max > 0.0f ? VEIL_OPV_TAU_TOLERANCE / st_max : INFINITY};
        if (res == VEIL_OK && n_tex > 0)
            res = veil_opv_jacobi_gpu(r->propagate, g, ev, lights, (int)s->light_count, &params, opv,
                                      &st->propagate_iterations, err);
        glFinish();
    }
    double t1 = veil_now_ms();
    if (res == VEIL_OK) {
        glCreateTextures(GL_TEXTURE_2D, 1, &out_tex);
        glTextureStorage2D(out_tex, 1, GL_RGBA32F, w, h);
        glObjectLabel(GL_TEXTURE, out_tex, -1, "veil image");
        res = veil_gl_check("allocating the output image", err);
    }
    if (res == VEIL_OK) {
        *rgba = malloc(floats * sizeof(float));
        if (!*rgba) res = veil_fail(err, VEIL_ERR_OOM, "out of memory for a %dx%d image", w, h);
    }
    if (res == VEIL_OK) {
        GLuint p = r->march;
        glUseProgram(p);
        set_march_uniforms(p, s, &cam, w, h, ev ? g : NULL, step, o->seed);
        glBindTextureUnit(VEIL_TEX_EV, ev);
        for (int t = 0; t < VEIL_MAX_OPV_TEXTURES; ++t) glBindTextureUnit(VEIL_TEX_OPV0 + t, opv[t]);
        glBindImageTexture(VEIL_IMAGE_OUT, out_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glDispatchCompute(veil_groups(w, VEIL_MARCH_GROUP), veil_groups(h, VEIL_MARCH_GROUP), 1);
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
        glBindImageTexture(VEIL_IMAGE_OUT, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        for (int t = 0; t <= VEIL_MAX_OPV_TEXTURES; ++t) glBindTextureUnit((GLuint)t, 0);
        glUseProgram(0);
        res = veil_gl_check("ray march (render/shaders/march.comp)", err);
        if (res == VEIL_OK) res = read_texture(out_tex, GL_RGBA, floats, *rgba, "reading back the image", err);
        if (res != VEIL_OK) {
            free(*rgba);
            *rgba = NULL;
        }
    }
    double t2 = veil_now_ms();
    glDeleteTextures(1, &out_tex);
    glDeleteTextures(VEIL_MAX_OPV_TEXTURES, opv);
    st->propagate_ms = t1 - t0;
    st->render_ms = t2 - t1;
    return res;
}

veil_result veil_render_density(veil_renderer* r, const veil_scene* s, const veil_grid* g, const float* density,
                                const veil_render_opts* opts, float** rgba, veil_render_stats* stats,
                                veil_error* err)
{
    veil_render_opts o = opts ? *opts : (veil_render_opts){0};
    veil_render_stats st = {0};
    *rgba = NULL;
    GLuint ev = 0;
    veil_result res = check_volume_size(r, g, (int)s->light_count, err);
    double t0 = veil_now_ms();
    if (res == VEIL_OK) res = upload_density(g, density, &ev, err);
    glFinish();
    st.inject_ms = veil_now_ms() - t0;
    st.has_volume = 1;
    st.grid = *g;
    if (res == VEIL_OK) res = propagate_and_march(r, s, g, ev, &o, rgba, &st, err);
    glDeleteTextures(1, &ev);
    if (stats) *stats = st;
    return res;
}

veil_result veil_render_scene(veil_renderer* r, const veil_scene* s, const veil_render_opts* opts, float** rgba,
                              veil_render_stats* stats, veil_error* err)
{
    veil_render_opts o = opts ? *opts : (veil_render_opts){0};
    veil_render_stats st = {0};
    *rgba = NULL;
    double t0 = veil_now_ms();
    veil_particle* parts = NULL;
    size_t n = 0;
    veil_result res = veil_scene_particles(s, &parts, &n, err);
    float lo[3], hi[3];
    veil_grid g;
    veil_rbf_bins bins = {0};
    GLuint ev = 0;
    st.particles = n;
    st.has_volume = res == VEIL_OK && veil_rbf_bounds(parts, n, lo, hi);
    if (res == VEIL_OK && st.has_volume) {
        res = veil_grid_fit(lo, hi, s->medium.max_resolution, &g, err);
        if (res == VEIL_OK) res = check_volume_size(r, &g, (int)s->light_count, err);
        if (res == VEIL_OK) res = veil_rbf_bin(&g, parts, n, &bins, err);
        if (res == VEIL_OK) res = veil_gl_texture3d(GL_R32F, g.dims, "veil extinction volume", &ev, err);
        if (res == VEIL_OK) res = veil_inject_rbf_gpu(r->inject, &g, &bins, ev, err);
        glFinish();
        st.grid = g;
    }
    free(parts);
    veil_rbf_bins_free(&bins);
    st.inject_ms = veil_now_ms() - t0;
    if (res == VEIL_OK) res = propagate_and_march(r, s, st.has_volume ? &g : NULL, ev, &o, rgba, &st, err);
    glDeleteTextures(1, &ev);
    if (stats) *stats = st;
    return res;
}

veil_result veil_renderer_inject(veil_renderer* r, const veil_grid* g, const veil_particle* p, size_t n,
                                 float* density, veil_error* err)
{
    veil_rbf_bins bins = {0};
    GLuint ev = 0;
    veil_result res = veil_rbf_bin(g, p, n, &bins, err);
    if (res == VEIL_OK) res = veil_gl_texture3d(GL_R32F, g->dims, "veil extinction volume", &ev, err);
    if (res == VEIL_OK) res = veil_inject_rbf_gpu(r->inject, g, &bins, ev, err);
    if (res == VEIL_OK) res = read_texture(ev, GL_RED, veil_grid_voxels(g), density, "reading back the EV", err);
    glDeleteTextures(1, &ev);
    veil_rbf_bins_free(&bins);
    return res;
}

veil_result veil_renderer_propagate(veil_renderer* r, const veil_grid* g, const float* density,
                                    const veil_opv_light* lights, int n_lights, const veil_opv_params* params,
                                    float* out, int* iterations, veil_error* err)
{
    if (n_lights < 1 || n_lights > VEIL_MAX_LIGHTS)
        return veil_fail(err, VEIL_ERR_INVALID, "propagate: %d lights (1..%d)", n_lights, VEIL_MAX_LIGHTS);
    GLuint ev = 0, opv[VEIL_MAX_OPV_TEXTURES] = {0};
    int n_tex = (n_lights + 3) / 4;
    size_t nv = veil_grid_voxels(g);
    float* tmp = malloc(nv * 4 * sizeof(float));
    veil_result res = tmp ? upload_density(g, density, &ev, err) : veil_fail(err, VEIL_ERR_OOM, "out of memory");
    for (int t = 0; t < n_tex && res == VEIL_OK; ++t)
        res = veil_gl_texture3d(GL_RGBA32F, g->dims, "veil optical-depth volume", &opv[t], err);
    if (res == VEIL_OK) res = veil_opv_jacobi_gpu(r->propagate, g, ev, lights, n_lights, params, opv, iterations, err);
    for (int t = 0; t < n_tex && res == VEIL_OK; ++t) {
        res = read_texture(opv[t], GL_RGBA, nv * 4, tmp, "reading back an OPV", err);
        for (int c = 0; c < 4 && 4 * t + c < n_lights && res == VEIL_OK; ++c)
            for (size_t v = 0; v < nv; ++v) out[(size_t)(4 * t + c) * nv + v] = tmp[4 * v + c];
    }
    glDeleteTextures(1, &ev);
    glDeleteTextures(VEIL_MAX_OPV_TEXTURES, opv);
    free(tmp);
    return res;
}
