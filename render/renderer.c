#include "renderer.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/hash.h"
#include "../propagate/opv_gpu.h"
#include "../io/vdb.h"
#include "../volume/inject_gpu.h"
#include "../volume/scene_volume.h"
#include "camera.h"
#include "gl_util.h"

struct veil_renderer {
    GLuint inject, march, occupancy;
    veil_opv_programs opv_programs;
    unsigned long long memory_budget; /* bytes, see veil_gl_info */
    /* the cached extinction volume and what it was made from */
    uint64_t ev_key;
    GLuint ev, occ; /* the volume, and its occupancy bricks */
    int has_volume;
    veil_grid grid;
    size_t particles;
    /* the cached optical-depth textures and what each was made from */
    uint64_t opv_key[VEIL_MAX_OPV_TEXTURES];
    GLuint opv[VEIL_MAX_OPV_TEXTURES];
};

/* ---- lifetime ---------------------------------------------------------- */

veil_result veil_renderer_create(const veil_gl* gl, veil_renderer** out, veil_error* err)
{
    *out = NULL;
    veil_renderer* r = calloc(1, sizeof *r);
    if (!r) return veil_fail(err, VEIL_ERR_OOM, "out of memory creating the renderer");
    r->memory_budget = veil_gl_get_info(gl)->memory_budget;
    veil_result res = veil_gl_compute_program("volume/shaders/inject_rbf.comp", veil_shader_inject_rbf_comp,
                                              &r->inject, err);
    if (res == VEIL_OK) res = veil_opv_programs_create(&r->opv_programs, err);
    if (res == VEIL_OK)
        res = veil_gl_compute_program("render/shaders/march.comp", veil_shader_march_comp, &r->march, err);
    if (res == VEIL_OK)
        res = veil_gl_compute_program("render/shaders/occupancy.comp", veil_shader_occupancy_comp, &r->occupancy,
                                      err);
    if (res != VEIL_OK) {
        veil_renderer_destroy(r);
        return res;
    }
    *out = r;
    return VEIL_OK;
}

static void drop_opvs(veil_renderer* r)
{
    glDeleteTextures(VEIL_MAX_OPV_TEXTURES, r->opv);
    memset(r->opv, 0, sizeof r->opv);
    memset(r->opv_key, 0, sizeof r->opv_key);
}

static void drop_volume(veil_renderer* r)
{
    glDeleteTextures(1, &r->ev);
    glDeleteTextures(1, &r->occ);
    r->ev = r->occ = 0;
    r->ev_key = 0;
    r->has_volume = 0;
    drop_opvs(r);
}

void veil_renderer_destroy(veil_renderer* r)
{
    if (!r) return;
    drop_volume(r);
    glDeleteProgram(r->inject);
    glDeleteProgram(r->march);
    glDeleteProgram(r->occupancy);
    veil_opv_programs_destroy(&r->opv_programs);
    free(r);
}

/* ---- helpers ----------------------------------------------------------- */

/* GPU bytes of the EV and the OPVs (plus the scratch ping-pong texture),
 * checked for overflow and against the budget before anything is made. */
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

static veil_result read_texture(GLuint tex, GLenum format, size_t floats, float* out, const char* what,
                                veil_error* err)
{
    size_t bytes = floats * sizeof(float);
    if (bytes > (size_t)INT32_MAX)
        return veil_fail(err, VEIL_ERR_LIMIT, "%s: %zu bytes is too large to read back", what, bytes);
    glGetTextureImage(tex, 0, format, GL_FLOAT, (GLsizei)bytes, out);
    return veil_gl_check(what, err);
}

static float max_sigma_t(const veil_medium* m)
{
    float mx = 0.0f;
    for (int c = 0; c < 3; ++c) mx = fmaxf(mx, m->sigma_a[c] + m->sigma_s[c]);
    return mx;
}

static int count_fogs(const veil_scene* s)
{
    int n = 0;
    for (size_t i = 0; i < s->medium.source_count; ++i) n += s->medium.sources[i].type == VEIL_SOURCE_EXPONENTIAL;
    return n;
}

/* Does light l add anything inside the box of g (NULL: the medium is fog
 * only, unbounded as far as this test goes)? Zero colour never does; a spot
 * whose outer cone misses the box's bounding sphere does not. */
static int light_reaches(const veil_light* l, const veil_grid* g)
{
    if (!(l->color[0] > 0.0f || l->color[1] > 0.0f || l->color[2] > 0.0f)) return 0;
    if (!g || l->type != VEIL_LIGHT_SPOT || l->outer_angle_deg >= 90.0f) return 1;
    double c[3], d2 = 0.0, r2 = 0.0;
    for (int a = 0; a < 3; ++a) {
        double half = 0.5 * g->dims[a] * (double)g->voxel;
        c[a] = g->origin[a] + half - l->position[a];
        d2 += c[a] * c[a];
        r2 += half * half;
    }
    if (d2 <= r2) return 1; /* the light is within the sphere */
    double cos_axis = (c[0] * l->direction[0] + c[1] * l->direction[1] + c[2] * l->direction[2]) / sqrt(d2);
    double angle = acos(fmax(-1.0, fmin(1.0, cos_axis)));
    double spread = l->outer_angle_deg * (VEIL_PI / 180.0) + asin(sqrt(r2 / d2));
    return angle <= spread;
}

/* ---- stage 1: the extinction volume ------------------------------------ */

static veil_result make_ev(veil_renderer* r, const veil_grid* g, uint64_t key, int n_lights, veil_error* err)
{
    static const GLfloat zero = 0.0f;
    drop_volume(r);
    veil_result res = check_volume_size(r, g, n_lights, err);
    if (res == VEIL_OK) res = veil_gl_texture3d(GL_R32F, g->dims, "veil extinction volume", &r->ev, err);
    if (res != VEIL_OK) return res;
    glClearTexImage(r->ev, 0, GL_RED, GL_FLOAT, &zero); /* sources add to it */
    r->grid = *g;
    r->has_volume = 1;
    r->ev_key = key;
    return VEIL_OK;
}

/* The EV's occupancy bricks (render/shaders/occupancy.comp), made once
 * the EV holds its density. */
static veil_result build_occupancy(veil_renderer* r, veil_error* err)
{
    int b[3];
    for (int a = 0; a < 3; ++a) b[a] = (r->grid.dims[a] + VEIL_BRICK - 1) / VEIL_BRICK;
    veil_result res = veil_gl_texture3d(GL_R32F, b, "veil occupancy bricks", &r->occ, err);
    if (res != VEIL_OK) return res;
    GLuint p = r->occupancy;
    glUseProgram(p);
    glProgramUniform3i(p, glGetUniformLocation(p, "u_dims"), r->grid.dims[0], r->grid.dims[1], r->grid.dims[2]);
    glProgramUniform3i(p, glGetUniformLocation(p, "u_bricks"), b[0], b[1], b[2]);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    glBindImageTexture(VEIL_IMAGE_EV, r->ev, 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32F);
    glBindImageTexture(VEIL_IMAGE_OUT, r->occ, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    glDispatchCompute(veil_groups(b[0], 4), veil_groups(b[1], 4), veil_groups(b[2], 4));
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glBindImageTexture(VEIL_IMAGE_EV, 0, 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32F);
    glBindImageTexture(VEIL_IMAGE_OUT, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    glUseProgram(0);
    return veil_gl_check("occupancy bricks (render/shaders/occupancy.comp)", err);
}

/* The EV from every voxelised source: OpenVDB grids resampled on the CPU
 * into the volume, then the RBF particles added on the GPU. */
static veil_result inject_scene(veil_renderer* r, const veil_scene* s, veil_render_stats* st, veil_error* err)
{
    veil_scene_volume v;
    veil_result res = veil_scene_volume_open(s, &v, err);
    if (res != VEIL_OK) return res;
    st->vdb_voxels = v.vdb_voxels;
    if (r->ev_key == v.key) {
        st->inject_cached = 1;
        st->vdb_voxels = 0;
    } else if (!v.has_volume) {
        drop_volume(r);
        r->ev_key = v.key; /* an empty medium, remembered as such */
    } else {
        const veil_grid* g = &v.grid;
        veil_rbf_bins bins = {0};
        float* density = NULL;
        res = make_ev(r, g, v.key, (int)s->light_count, err);
        if (res == VEIL_OK && v.vdb_count > 0) {
            density = calloc(veil_grid_voxels(g), sizeof(float));
            if (!density) res = veil_fail(err, VEIL_ERR_OOM, "out of memory for a %zu-voxel volume", veil_grid_voxels(g));
            if (res == VEIL_OK) res = veil_scene_volume_add_vdbs(&v, density, err);
            if (res == VEIL_OK) {
                glTextureSubImage3D(r->ev, 0, 0, 0, 0, g->dims[0], g->dims[1], g->dims[2], GL_RED, GL_FLOAT, density);
                res = veil_gl_check("uploading the resampled grids", err);
            }
        }
        size_t n = v.particle_count;
        if (res == VEIL_OK && n > 0) res = veil_rbf_bin(g, v.particles, n, &bins, err);
        if (res == VEIL_OK && n > 0) res = veil_inject_rbf_gpu(r->inject, g, &bins, r->ev, err);
        if (res == VEIL_OK) res = build_occupancy(r, err);
        if (res != VEIL_OK) drop_volume(r);
        free(density);
        veil_rbf_bins_free(&bins);
        r->particles = n;
    }
    veil_scene_volume_close(&v);
    return res;
}

/* ---- stage 2: optical depth -------------------------------------------- */

static veil_result propagate(veil_renderer* r, const veil_scene* s, const veil_light* lights, int n,
                             veil_opv_method method, veil_render_stats* st, veil_error* err)
{
    float st_max = max_sigma_t(&s->medium);
    /* D changes of tol move tau by at most st_max * tol */
    veil_opv_params params = {.method = method,
                              .tolerance = st_max > 0.0f ? VEIL_OPV_TAU_TOLERANCE / st_max : INFINITY};
    veil_result res = VEIL_OK;
    for (int t = 0; 4 * t < n && res == VEIL_OK; ++t) {
        int count = n - 4 * t < 4 ? n - 4 * t : 4;
        veil_opv_light ol[4];
        uint64_t key = veil_hash_bytes(r->ev_key, &params, sizeof params);
        for (int c = 0; c < count; ++c) {
            veil_opv_light_from_world(&r->grid, &lights[4 * t + c], &ol[c]);
            key = veil_hash_bytes(key, &ol[c], sizeof ol[c]);
        }
        if (r->opv[t] && r->opv_key[t] == key) {
            ++st->opv_cached;
            continue;
        }
        if (!r->opv[t]) res = veil_gl_texture3d(GL_RGBA32F, r->grid.dims, "veil optical-depth volume", &r->opv[t], err);
        int it = 0;
        r->opv_key[t] = 0;
        if (res == VEIL_OK) res = veil_opv_gpu(&r->opv_programs, &r->grid, r->ev, ol, count, &params, &r->opv[t], &it, err);
        if (res == VEIL_OK) r->opv_key[t] = key;
        st->propagate_iterations = it > st->propagate_iterations ? it : st->propagate_iterations;
        ++st->opv_computed;
    }
    return res;
}

/* ---- stage 3: the march ------------------------------------------------- */

static void set_march_uniforms(GLuint p, const veil_scene* s, const veil_light* lights, int n,
                               const veil_camera_basis* cam, int w, int h, const veil_grid* g, float step_voxels,
                               uint32_t seed, int skip_empty, float max_distance)
{
    glProgramUniform1f(p, glGetUniformLocation(p, "u_stop_t"), max_distance > 0.0f ? max_distance : 3.0e38f);
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
        float lo[3], hi[3], inv[3];
        veil_grid_medium_box(g, lo, hi);
        for (int a = 0; a < 3; ++a) inv[a] = 1.0f / ((float)g->dims[a] * g->voxel);
        glProgramUniform3fv(p, glGetUniformLocation(p, "u_box_min"), 1, lo);
        glProgramUniform3fv(p, glGetUniformLocation(p, "u_box_max"), 1, hi);
        glProgramUniform3fv(p, glGetUniformLocation(p, "u_tex_min"), 1, g->origin);
        glProgramUniform3fv(p, glGetUniformLocation(p, "u_tex_inv_size"), 1, inv);
        glProgramUniform1f(p, glGetUniformLocation(p, "u_step"), step_voxels * g->voxel);
        float md = VEIL_MIN_LIGHT_DISTANCE_VOXELS * g->voxel;
        glProgramUniform1f(p, glGetUniformLocation(p, "u_min_dist2"), md * md);
    }
    GLint types[VEIL_MAX_LIGHTS] = {0};
    GLfloat pos[3 * VEIL_MAX_LIGHTS] = {0}, dir[3 * VEIL_MAX_LIGHTS] = {0}, col[3 * VEIL_MAX_LIGHTS] = {0};
    GLfloat cone[2 * VEIL_MAX_LIGHTS] = {0};
    for (int l = 0; l < n; ++l) {
        types[l] = lights[l].type;
        memcpy(pos + 3 * l, lights[l].position, sizeof(float[3]));
        memcpy(dir + 3 * l, lights[l].direction, sizeof(float[3]));
        memcpy(col + 3 * l, lights[l].color, sizeof(float[3]));
        cone[2 * l] = cosf(lights[l].inner_angle_deg * (float)(VEIL_PI / 180.0));
        cone[2 * l + 1] = cosf(lights[l].outer_angle_deg * (float)(VEIL_PI / 180.0));
    }
    glProgramUniform1i(p, glGetUniformLocation(p, "u_light_count"), n);
    glProgramUniform1iv(p, glGetUniformLocation(p, "u_light_type"), VEIL_MAX_LIGHTS, types);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_light_pos"), VEIL_MAX_LIGHTS, pos);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_light_dir"), VEIL_MAX_LIGHTS, dir);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_light_color"), VEIL_MAX_LIGHTS, col);
    glProgramUniform2fv(p, glGetUniformLocation(p, "u_light_cone"), VEIL_MAX_LIGHTS, cone);
    GLint fogs = 0;
    GLfloat fd[VEIL_MAX_FOGS] = {0}, ff[VEIL_MAX_FOGS] = {0}, fn[3 * VEIL_MAX_FOGS] = {0},
            fo[3 * VEIL_MAX_FOGS] = {0}, flo[3 * VEIL_MAX_FOGS] = {0}, fhi[3 * VEIL_MAX_FOGS] = {0};
    for (size_t i = 0; i < s->medium.source_count && fogs < VEIL_MAX_FOGS; ++i) {
        const veil_source* src = &s->medium.sources[i];
        if (src->type != VEIL_SOURCE_EXPONENTIAL) continue;
        fd[fogs] = src->fog.density;
        ff[fogs] = src->fog.falloff;
        memcpy(fn + 3 * fogs, src->fog.direction, sizeof(float[3]));
        memcpy(fo + 3 * fogs, src->fog.origin, sizeof(float[3]));
        memcpy(flo + 3 * fogs, src->fog.bounds[0], sizeof(float[3]));
        memcpy(fhi + 3 * fogs, src->fog.bounds[1], sizeof(float[3]));
        ++fogs;
    }
    glProgramUniform1i(p, glGetUniformLocation(p, "u_fog_count"), fogs);
    glProgramUniform1fv(p, glGetUniformLocation(p, "u_fog_density"), VEIL_MAX_FOGS, fd);
    glProgramUniform1fv(p, glGetUniformLocation(p, "u_fog_falloff"), VEIL_MAX_FOGS, ff);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_fog_dir"), VEIL_MAX_FOGS, fn);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_fog_origin"), VEIL_MAX_FOGS, fo);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_fog_min"), VEIL_MAX_FOGS, flo);
    glProgramUniform3fv(p, glGetUniformLocation(p, "u_fog_max"), VEIL_MAX_FOGS, fhi);
    glProgramUniform1i(p, glGetUniformLocation(p, "u_skip"), g != NULL && fogs == 0 && skip_empty);
    if (g) glProgramUniform1f(p, glGetUniformLocation(p, "u_voxel"), g->voxel);
    if (!g) {
        float md = VEIL_MIN_LIGHT_DISTANCE_VOXELS * VEIL_FOG_MIN_STEP;
        glProgramUniform1f(p, glGetUniformLocation(p, "u_step"), VEIL_FOG_MIN_STEP);
        glProgramUniform1f(p, glGetUniformLocation(p, "u_min_dist2"), md * md);
    }
    GLint units[VEIL_MAX_OPV_TEXTURES];
    for (int t = 0; t < VEIL_MAX_OPV_TEXTURES; ++t) units[t] = VEIL_TEX_OPV0 + t;
    glProgramUniform1iv(p, glGetUniformLocation(p, "u_opv"), VEIL_MAX_OPV_TEXTURES, units);
}

static veil_result march(veil_renderer* r, const veil_scene* s, const veil_light* lights, int n,
                         const veil_render_opts* o, int w, int h, float** rgba, veil_error* err)
{
    veil_camera_basis cam;
    veil_result res = veil_camera_make_basis(o->camera ? o->camera : &s->camera, w, h, &cam, err);
    if (res != VEIL_OK) return res;
    size_t floats;
    if (!veil_mul_sizes((size_t)w, (size_t)h, 4, 1, &floats)) return veil_fail(err, VEIL_ERR_LIMIT, "image too large");
    float step = o->step_voxels > 0.0f ? o->step_voxels : VEIL_DEFAULT_STEP_VOXELS;
    GLuint out_tex = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &out_tex);
    glTextureStorage2D(out_tex, 1, GL_RGBA32F, w, h);
    glObjectLabel(GL_TEXTURE, out_tex, -1, "veil image");
    res = veil_gl_check("allocating the output image", err);
    if (res == VEIL_OK) {
        *rgba = malloc(floats * sizeof(float));
        if (!*rgba) res = veil_fail(err, VEIL_ERR_OOM, "out of memory for a %dx%d image", w, h);
    }
    if (res == VEIL_OK) {
        GLuint p = r->march;
        glUseProgram(p);
        set_march_uniforms(p, s, lights, n, &cam, w, h, r->has_volume ? &r->grid : NULL, step, o->seed,
                           !o->no_skip, o->max_distance);
        glBindTextureUnit(VEIL_TEX_EV, r->ev);
        glBindTextureUnit(VEIL_TEX_OCC, r->occ);
        for (int t = 0; t < VEIL_MAX_OPV_TEXTURES; ++t) glBindTextureUnit(VEIL_TEX_OPV0 + t, r->opv[t]);
        glBindImageTexture(VEIL_IMAGE_OUT, out_tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glDispatchCompute(veil_groups(w, VEIL_MARCH_GROUP), veil_groups(h, VEIL_MARCH_GROUP), 1);
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
        glBindImageTexture(VEIL_IMAGE_OUT, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        for (int t = 0; t <= VEIL_TEX_OCC; ++t) glBindTextureUnit((GLuint)t, 0);
        glUseProgram(0);
        res = veil_gl_check("ray march (render/shaders/march.comp)", err);
        if (res == VEIL_OK) res = read_texture(out_tex, GL_RGBA, floats, *rgba, "reading back the image", err);
        if (res != VEIL_OK) {
            free(*rgba);
            *rgba = NULL;
        }
    }
    glDeleteTextures(1, &out_tex);
    return res;
}

/* Propagates and marches once the EV is in place (or known empty). */
static veil_result light_and_march(veil_renderer* r, const veil_scene* s, const veil_render_opts* o, float** rgba,
                                   veil_render_stats* st, veil_error* err)
{
    const veil_camera* camera = o->camera ? o->camera : &s->camera;
    int w = o->width > 0 ? o->width : camera->width;
    int h = o->height > 0 ? o->height : camera->height;
    if (w < 1 || h < 1 || w > VEIL_SCENE_MAX_IMAGE || h > VEIL_SCENE_MAX_IMAGE)
        return veil_fail(err, VEIL_ERR_INVALID, "image size %dx%d is outside 1..%d", w, h, VEIL_SCENE_MAX_IMAGE);
    if (s->light_count > VEIL_MAX_LIGHTS)
        return veil_fail(err, VEIL_ERR_LIMIT, "%zu lights; at most %d are supported", s->light_count, VEIL_MAX_LIGHTS);
    veil_light lights[VEIL_MAX_LIGHTS];
    int n = 0, fogs = count_fogs(s);
    for (size_t l = 0; l < s->light_count && (r->has_volume || fogs); ++l)
        if (light_reaches(&s->lights[l], r->has_volume ? &r->grid : NULL)) lights[n++] = s->lights[l];
    st->fogs = fogs;
    st->lights_used = n;
    st->method = veil_opv_method_resolve(o->method);
    st->has_volume = r->has_volume;
    st->grid = r->grid;
    st->particles = r->particles;
    veil_result res = VEIL_OK;
    double t0 = veil_now_ms();
    if (n > 0 && r->has_volume) {
        res = propagate(r, s, lights, n, st->method, st, err);
        glFinish();
    }
    double t1 = veil_now_ms();
    if (res == VEIL_OK) res = march(r, s, lights, n, o, w, h, rgba, err);
    st->propagate_ms = t1 - t0;
    st->render_ms = veil_now_ms() - t1;
    return res;
}

/* ---- public entry points ------------------------------------------------ */

veil_result veil_render_density(veil_renderer* r, const veil_scene* s, const veil_grid* g, const float* density,
                                const veil_render_opts* opts, float** rgba, veil_render_stats* stats,
                                veil_error* err)
{
    veil_render_opts o = opts ? *opts : (veil_render_opts){0};
    veil_render_stats st = {0};
    *rgba = NULL;
    double t0 = veil_now_ms();
    uint64_t key = veil_hash_bytes(VEIL_FNV_OFFSET, g, sizeof *g);
    key = veil_hash_bytes(key, density, veil_grid_voxels(g) * sizeof(float));
    veil_result res = VEIL_OK;
    if (r->has_volume && r->ev_key == key) {
        st.inject_cached = 1;
    } else {
        res = make_ev(r, g, key, (int)s->light_count, err);
        if (res == VEIL_OK) {
            glTextureSubImage3D(r->ev, 0, 0, 0, 0, g->dims[0], g->dims[1], g->dims[2], GL_RED, GL_FLOAT, density);
            res = veil_gl_check("uploading the extinction volume", err);
        }
        if (res == VEIL_OK) res = build_occupancy(r, err);
        if (res != VEIL_OK) drop_volume(r);
        r->particles = 0;
    }
    glFinish();
    st.inject_ms = veil_now_ms() - t0;
    if (res == VEIL_OK) res = light_and_march(r, s, &o, rgba, &st, err);
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
    veil_result res = inject_scene(r, s, &st, err);
    glFinish();
    st.inject_ms = veil_now_ms() - t0;
    if (res == VEIL_OK) res = light_and_march(r, s, &o, rgba, &st, err);
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
    if (res == VEIL_OK) {
        static const GLfloat zero = 0.0f;
        glClearTexImage(ev, 0, GL_RED, GL_FLOAT, &zero);
        res = veil_inject_rbf_gpu(r->inject, g, &bins, ev, err);
    }
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
    veil_result res = tmp ? veil_gl_texture3d(GL_R32F, g->dims, "veil extinction volume", &ev, err)
                          : veil_fail(err, VEIL_ERR_OOM, "out of memory");
    if (res == VEIL_OK) {
        glTextureSubImage3D(ev, 0, 0, 0, 0, g->dims[0], g->dims[1], g->dims[2], GL_RED, GL_FLOAT, density);
        res = veil_gl_check("uploading the extinction volume", err);
    }
    for (int t = 0; t < n_tex && res == VEIL_OK; ++t)
        res = veil_gl_texture3d(GL_RGBA32F, g->dims, "veil optical-depth volume", &opv[t], err);
    if (res == VEIL_OK) res = veil_opv_gpu(&r->opv_programs, g, ev, lights, n_lights, params, opv, iterations, err);
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
