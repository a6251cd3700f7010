#include "ev.h"

#include <stdlib.h>
#include <string.h>

#include "../gpu/gl_util.h"
#include "../gpu/programs.h"
#include "emission_lights.h"
#include "inject_gpu.h"

struct veil_ev {
    GLuint inject, inject_octants, occupancy; /* programs (the splat's octants made when first needed) */
    GLuint tex, occ;          /* the volume and its occupancy bricks */
    GLuint emission;          /* rgba32f emission (0: none) */
    int present, is_sparse;
    veil_ev_sparse sparse;
    veil_light lights[VEIL_MAX_LIGHTS]; /* the emission as lights */
    int light_count;
    veil_grid grid;
    size_t splat_evals; /* the splat's dispatches' work (volume/volume.h; 0: VEIL_SPLAT_DISPATCH_EVALS) */
};

static size_t g_splat_evals; /* tests' override (0: none) */

void veil_ev_set_software(veil_ev* ev, int software)
{
    ev->splat_evals = software ? VEIL_SPLAT_SOFTWARE_EVALS : VEIL_SPLAT_DISPATCH_EVALS;
}

void veil_ev_set_splat_evals(size_t evals) { g_splat_evals = evals; }

static size_t splat_evals(const veil_ev* ev)
{
    return g_splat_evals ? g_splat_evals : ev->splat_evals ? ev->splat_evals : VEIL_SPLAT_DISPATCH_EVALS;
}

veil_result veil_ev_create(veil_ev** out, veil_error* err)
{
    *out = NULL;
    veil_ev* ev = calloc(1, sizeof *ev);
    if (!ev) return veil_fail(err, VEIL_ERR_OOM, "out of memory creating the extinction volume");
    veil_result r = veil_gpu_program("volume/shaders/inject_rbf.comp", &ev->inject, err);
    if (r == VEIL_OK) r = veil_gpu_program("volume/shaders/occupancy.comp", &ev->occupancy, err);
    if (r != VEIL_OK) {
        veil_ev_destroy(ev);
        return r;
    }
    *out = ev;
    return VEIL_OK;
}

void veil_ev_clear(veil_ev* ev)
{
    glDeleteTextures(1, &ev->tex);
    glDeleteTextures(1, &ev->occ);
    glDeleteTextures(1, &ev->emission);
    ev->tex = ev->occ = ev->emission = 0;
    ev->present = 0;
    ev->light_count = 0;
    if (ev->is_sparse) {
        veil_ev_sparse* sp = &ev->sparse;
        glDeleteTextures(1, &sp->top);
        glDeleteTextures(1, &sp->nodes);
        glDeleteTextures(1, &sp->coords);
        glDeleteBuffers(3, sp->buffers);
        glDeleteBuffers(1, &sp->ubo);
        free(sp->bricks);
        memset(sp, 0, sizeof *sp);
        ev->is_sparse = 0;
    }
}

const veil_light* veil_ev_emission_lights(const veil_ev* ev, int* n)
{
    *n = ev->present ? ev->light_count : 0;
    return ev->lights;
}

const veil_ev_sparse* veil_ev_sparse_of(const veil_ev* ev) { return ev->present && ev->is_sparse ? &ev->sparse : NULL; }

void veil_ev_sparse_bind(const veil_ev_sparse* sp)
{
    glBindTextureUnit(VEIL_TEX_SPARSE_TOP, sp ? sp->top : 0);
    glBindTextureUnit(VEIL_TEX_SPARSE_NODES, sp ? sp->nodes : 0);
    glBindTextureUnit(VEIL_TEX_SPARSE_COORDS, sp ? sp->coords : 0);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_SPARSE, sp ? sp->ubo : 0);
}

/* A buffer texture of n texels of `format` (bytes a texel) from data. */
static veil_result buffer_texture(GLenum format, size_t bytes, const void* data, const char* label, GLuint* buf,
                                  GLuint* tex, veil_error* err)
{
    GLint max_texels = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
    size_t texel = format == GL_RGBA32I ? 16 : 4;
    if (bytes / texel > (size_t)max_texels)
        return veil_fail(err, VEIL_ERR_LIMIT, "%s: %zu entries, over this device's %d for a buffer texture", label,
                         bytes / texel, max_texels);
    veil_result r = veil_gl_buffer(bytes ? data : NULL, bytes ? bytes : texel, 0, label, buf, err);
    if (r != VEIL_OK) return r;
    glCreateTextures(GL_TEXTURE_BUFFER, 1, tex);
    glTextureBuffer(*tex, format, *buf);
    glObjectLabel(GL_TEXTURE, *tex, -1, label);
    return veil_gl_check(label, err);
}

/* The sparse EV of v (v->sparse): built on the CPU (volume/sparse.c), uploaded. */
static veil_result build_sparse(veil_ev* ev, const veil_scene_volume* v, int n_lights, unsigned long long budget,
                                veil_error* err)
{
    GLint max3d = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
    veil_sparse s;
    veil_result r = veil_sparse_build(v, max3d, &s, err);
    if (r != VEIL_OK) return r;
    veil_ev_sparse* sp = &ev->sparse;
    ev->is_sparse = 1;
    veil_sparse_atlas_texels(&s, sp->atlas_texels);
    size_t texels = (size_t)sp->atlas_texels[0] * (size_t)sp->atlas_texels[1] * (size_t)sp->atlas_texels[2];
    /* the optical depths: an rgba32f atlas per 4 lights (veil_ev_check_budget's count for dense); the
     * emission's lights join the scene's */
    int lights = n_lights + (s.emitter_count ? v->emission_lights : 0);
    if (lights > VEIL_MAX_LIGHTS) lights = VEIL_MAX_LIGHTS;
    unsigned long long total = veil_sparse_bytes(&s) + (unsigned long long)texels * 16 * (unsigned long long)((lights + 3) / 4);
    if (total > budget)
        r = veil_fail(err, VEIL_ERR_LIMIT,
                      "a sparse volume of %zu bricks with %d lights needs %.0f MiB of textures, more than the %.0f MiB "
                      "allowed on this device; set medium.max_resolution", s.count, lights,
                      (double)total / 1048576.0, (double)budget / 1048576.0);
    if (r == VEIL_OK) r = veil_gl_texture3d(GL_R32F, sp->atlas_texels, "veil sparse atlas", &ev->tex, err);
    if (r == VEIL_OK) {
        glTextureSubImage3D(ev->tex, 0, 0, 0, 0, sp->atlas_texels[0], sp->atlas_texels[1], sp->atlas_texels[2], GL_RED,
                            GL_FLOAT, s.texels);
        r = veil_gl_check("uploading the sparse atlas", err);
    }
    if (r == VEIL_OK && s.emission_texels) {
        r = veil_gl_texture3d(GL_RGBA32F, sp->atlas_texels, "veil sparse emission atlas", &ev->emission, err);
        if (r == VEIL_OK) {
            glTextureSubImage3D(ev->emission, 0, 0, 0, 0, sp->atlas_texels[0], sp->atlas_texels[1], sp->atlas_texels[2],
                                GL_RGBA, GL_FLOAT, s.emission_texels);
            r = veil_gl_check("uploading the sparse emission atlas", err);
        }
    }
    if (r == VEIL_OK)
        r = veil_emission_lights_points(s.emitters, s.emitter_count, s.grid.voxel, v->emission_lights, ev->lights,
                                        &ev->light_count, err);
    size_t top = (size_t)s.top[0] * (size_t)s.top[1] * (size_t)s.top[2];
    if (r == VEIL_OK)
        r = buffer_texture(GL_R32UI, top * 4, s.top_table, "veil sparse top table", &sp->buffers[0], &sp->top, err);
    if (r == VEIL_OK)
        r = buffer_texture(GL_R32UI, s.node_count * VEIL_SPARSE_NODE_BRICKS * 4, s.nodes, "veil sparse nodes",
                           &sp->buffers[1], &sp->nodes, err);
    if (r == VEIL_OK)
        r = buffer_texture(GL_RGBA32I, s.count * 16, s.coords, "veil sparse bricks", &sp->buffers[2], &sp->coords, err);
    veil_sparse_block_fill(&s, &sp->block);
    if (r == VEIL_OK)
        r = veil_gl_buffer(&sp->block, sizeof sp->block, 0, "veil sparse block", &sp->ubo, err);
    sp->atlas = ev->tex;
    sp->slots = s.count;
    sp->bytes = veil_sparse_bytes(&s);
    sp->voxels = s.voxels;
    sp->bricks = s.coords; /* kept: veil_sparse_free below leaves it */
    s.coords = NULL;
    if (r == VEIL_OK) {
        ev->grid = v->grid;
        ev->present = 1;
    }
    veil_sparse_free(&s);
    return r;
}

void veil_ev_destroy(veil_ev* ev)
{
    if (!ev) return;
    veil_ev_clear(ev);
    glDeleteProgram(ev->inject);
    glDeleteProgram(ev->inject_octants);
    glDeleteProgram(ev->occupancy);
    free(ev);
}

const veil_grid* veil_ev_grid(const veil_ev* ev) { return ev->present ? &ev->grid : NULL; }
GLuint veil_ev_texture(const veil_ev* ev) { return ev->tex; }
GLuint veil_ev_emission(const veil_ev* ev) { return ev->present ? ev->emission : 0; }

GLuint veil_ev_occupancy(const veil_ev* ev) { return ev->occ; }

veil_result veil_ev_check_budget(const veil_grid* g, int n_lights, unsigned long long budget, veil_error* err)
{
    size_t n_tex = (size_t)(n_lights + 3) / 4, bytes_ev, bytes_opv;
    if (!veil_mul_sizes((size_t)g->dims[0], (size_t)g->dims[1], (size_t)g->dims[2], sizeof(float), &bytes_ev) ||
        !veil_mul_sizes(bytes_ev, 4, n_lights > 0 ? n_tex + 1 : 0, 1, &bytes_opv) || bytes_opv > SIZE_MAX - bytes_ev)
        return veil_fail(err, VEIL_ERR_LIMIT, "a %dx%dx%d volume with %d lights overflows the address space",
                         g->dims[0], g->dims[1], g->dims[2], n_lights);
    unsigned long long total = (unsigned long long)bytes_ev + bytes_opv;
    if (total > budget)
        return veil_fail(err, VEIL_ERR_LIMIT,
                         "a %dx%dx%d extinction volume with %d lights needs %.0f MiB of textures, more than the "
                         "%.0f MiB allowed on this device; lower medium.max_resolution",
                         g->dims[0], g->dims[1], g->dims[2], n_lights, (double)total / 1048576.0,
                         (double)budget / 1048576.0);
    return VEIL_OK;
}

/* A zeroed EV texture of grid g (sources add to it). */
static veil_result make(veil_ev* ev, const veil_grid* g, int n_lights, unsigned long long budget, veil_error* err)
{
    static const GLfloat zero = 0.0f;
    veil_ev_clear(ev);
    veil_result r = veil_ev_check_budget(g, n_lights, budget, err);
    if (r == VEIL_OK) r = veil_gl_texture3d(GL_R32F, g->dims, "veil extinction volume", &ev->tex, err);
    if (r != VEIL_OK) return r;
    glClearTexImage(ev->tex, 0, GL_RED, GL_FLOAT, &zero);
    ev->grid = *g;
    ev->present = 1;
    return VEIL_OK;
}

/* The occupancy bricks, made once the EV holds its density. */
static veil_result build_occupancy(veil_ev* ev, veil_error* err)
{
    int b[3];
    for (int a = 0; a < 3; ++a) b[a] = (ev->grid.dims[a] + VEIL_BRICK - 1) / VEIL_BRICK;
    veil_grid_block blk;
    memset(&blk, 0, sizeof blk);
    for (int a = 0; a < 3; ++a) {
        blk.dims[a] = ev->grid.dims[a];
        blk.bricks[a] = b[a];
        blk.origin[a] = ev->grid.origin[a];
    }
    blk.origin[3] = ev->grid.voxel;
    GLuint block = 0;
    veil_result r = veil_gl_texture3d(GL_R32F, b, "veil occupancy bricks", &ev->occ, err);
    if (r == VEIL_OK) r = veil_gl_buffer(&blk, sizeof blk, 0, "veil occupancy block", &block, err);
    if (r != VEIL_OK) return r;
    glUseProgram(ev->occupancy);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_GRID, block);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    glBindImageTexture(VEIL_IMAGE_EV, ev->tex, 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32F);
    glBindImageTexture(VEIL_IMAGE_OUT, ev->occ, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    glDispatchCompute(veil_groups(b[0], VEIL_OCCUPANCY_GROUP), veil_groups(b[1], VEIL_OCCUPANCY_GROUP),
                      veil_groups(b[2], VEIL_OCCUPANCY_GROUP));
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glBindImageTexture(VEIL_IMAGE_EV, 0, 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32F);
    glBindImageTexture(VEIL_IMAGE_OUT, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_GRID, 0);
    glUseProgram(0);
    glDeleteBuffers(1, &block);
    return veil_gl_check("occupancy bricks (volume/shaders/occupancy.comp)", err);
}

static veil_result upload(veil_ev* ev, const float* density, const char* what, veil_error* err)
{
    const int* d = ev->grid.dims;
    glTextureSubImage3D(ev->tex, 0, 0, 0, 0, d[0], d[1], d[2], GL_RED, GL_FLOAT, density);
    return veil_gl_check(what, err);
}

veil_result veil_ev_build_scene(veil_ev* ev, const veil_scene_volume* v, int n_lights, unsigned long long budget,
                                veil_ev_report* rep, veil_error* err)
{
    memset(rep, 0, sizeof *rep);
    if (!v->has_volume) {
        veil_ev_clear(ev);
        return VEIL_OK;
    }
    const veil_grid* g = &v->grid;
    if (v->sparse) {
        veil_ev_clear(ev);
        veil_result r = build_sparse(ev, v, n_lights, budget, err);
        if (r != VEIL_OK) veil_ev_clear(ev);
        rep->vdb_voxels = v->vdb_voxels;
        rep->bytes = r == VEIL_OK ? ev->sparse.bytes : 0;
        return r;
    }
    veil_rbf_bins bins = {0};
    float* density = NULL;
    veil_result r = make(ev, g, n_lights, budget, err);
    if (r == VEIL_OK && v->vdb_count > 0) {
        density = calloc(veil_grid_voxels(g), sizeof(float));
        if (!density) r = veil_fail(err, VEIL_ERR_OOM, "out of memory for a %zu-voxel volume", veil_grid_voxels(g));
        if (r == VEIL_OK) r = veil_scene_volume_add_vdbs(v, density, err);
        if (r == VEIL_OK) r = upload(ev, density, "uploading the resampled grids", err);
    }
    size_t n = v->particle_count;
    if (r == VEIL_OK && n > 0) r = veil_rbf_bin(g, v->particles, n, &bins, err);
    if (r == VEIL_OK && n > 0) r = veil_inject_rbf_gpu(ev->inject, &ev->inject_octants, g, &bins, ev->tex, splat_evals(ev), err);
    if (r == VEIL_OK) r = build_occupancy(ev, err);
    float* emission = NULL;
    if (r == VEIL_OK) r = veil_scene_volume_emission(v, &emission, err);
    if (r == VEIL_OK && emission) {
        r = veil_gl_texture3d(GL_RGBA32F, g->dims, "veil emission", &ev->emission, err);
        if (r == VEIL_OK) {
            glTextureSubImage3D(ev->emission, 0, 0, 0, 0, g->dims[0], g->dims[1], g->dims[2], GL_RGBA, GL_FLOAT,
                                emission);
            r = veil_gl_check("uploading the emission", err);
        }
        if (r == VEIL_OK) r = veil_emission_lights(g, emission, v->emission_lights, ev->lights, &ev->light_count, err);
    }
    free(emission);
    if (r != VEIL_OK) veil_ev_clear(ev);
    free(density);
    veil_rbf_bins_free(&bins);
    rep->particles = n;
    rep->vdb_voxels = v->vdb_voxels;
    if (r == VEIL_OK) {
        size_t b = 1;
        for (int a = 0; a < 3; ++a) b *= (size_t)((g->dims[a] + VEIL_BRICK - 1) / VEIL_BRICK);
        rep->bytes = veil_grid_voxels(g) * (ev->emission ? 20 : 4) + b * 4;
    }
    return r;
}

veil_result veil_ev_build_density(veil_ev* ev, const veil_grid* g, const float* density, int n_lights,
                                  unsigned long long budget, veil_error* err)
{
    veil_result r = make(ev, g, n_lights, budget, err);
    if (r == VEIL_OK) r = upload(ev, density, "uploading the extinction volume", err);
    if (r == VEIL_OK) r = build_occupancy(ev, err);
    if (r != VEIL_OK) veil_ev_clear(ev);
    return r;
}

veil_result veil_ev_splat_readback(veil_ev* ev, const veil_grid* g, const veil_particle* p, size_t n, float* density,
                                   veil_error* err)
{
    veil_rbf_bins bins = {0};
    GLuint tex = 0;
    veil_result r = veil_rbf_bin(g, p, n, &bins, err);
    if (r == VEIL_OK) r = veil_gl_texture3d(GL_R32F, g->dims, "veil extinction volume (read back)", &tex, err);
    if (r == VEIL_OK) {
        static const GLfloat zero = 0.0f;
        glClearTexImage(tex, 0, GL_RED, GL_FLOAT, &zero);
        r = veil_inject_rbf_gpu(ev->inject, &ev->inject_octants, g, &bins, tex, splat_evals(ev), err);
    }
    if (r == VEIL_OK) r = veil_gl_read_texture(tex, GL_RED, veil_grid_voxels(g), density, "reading back the EV", err);
    glDeleteTextures(1, &tex);
    veil_rbf_bins_free(&bins);
    return r;
}
