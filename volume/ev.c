#include "ev.h"

#include <stdlib.h>
#include <string.h>

#include "../gpu/gl_util.h"
#include "../gpu/programs.h"
#include "inject_gpu.h"

struct veil_ev {
    GLuint inject, occupancy; /* programs */
    GLuint tex, occ;          /* the volume and its occupancy bricks */
    GLuint emission;          /* rgba32f emission (0: none) */
    int present;
    veil_grid grid;
};

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
}

void veil_ev_destroy(veil_ev* ev)
{
    if (!ev) return;
    veil_ev_clear(ev);
    glDeleteProgram(ev->inject);
    glDeleteProgram(ev->occupancy);
    free(ev);
}

int veil_ev_present(const veil_ev* ev) { return ev->present; }
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
    veil_result r = veil_gl_texture3d(GL_R32F, b, "veil occupancy bricks", &ev->occ, err);
    if (r != VEIL_OK) return r;
    GLuint p = ev->occupancy;
    glUseProgram(p);
    glProgramUniform3i(p, glGetUniformLocation(p, "u_dims"), ev->grid.dims[0], ev->grid.dims[1], ev->grid.dims[2]);
    glProgramUniform3i(p, glGetUniformLocation(p, "u_bricks"), b[0], b[1], b[2]);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    glBindImageTexture(VEIL_IMAGE_EV, ev->tex, 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32F);
    glBindImageTexture(VEIL_IMAGE_OUT, ev->occ, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    glDispatchCompute(veil_groups(b[0], VEIL_OCCUPANCY_GROUP), veil_groups(b[1], VEIL_OCCUPANCY_GROUP),
                      veil_groups(b[2], VEIL_OCCUPANCY_GROUP));
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glBindImageTexture(VEIL_IMAGE_EV, 0, 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32F);
    glBindImageTexture(VEIL_IMAGE_OUT, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    glUseProgram(0);
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
    if (r == VEIL_OK && n > 0) r = veil_inject_rbf_gpu(ev->inject, g, &bins, ev->tex, err);
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
    }
    free(emission);
    if (r != VEIL_OK) veil_ev_clear(ev);
    free(density);
    veil_rbf_bins_free(&bins);
    rep->particles = n;
    rep->vdb_voxels = v->vdb_voxels;
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
        r = veil_inject_rbf_gpu(ev->inject, g, &bins, tex, err);
    }
    if (r == VEIL_OK) r = veil_gl_read_texture(tex, GL_RED, veil_grid_voxels(g), density, "reading back the EV", err);
    glDeleteTextures(1, &tex);
    veil_rbf_bins_free(&bins);
    return r;
}
