#include "opv_gpu.h"

#include <string.h>

#include "../gpu/gl_util.h"
#include "../gpu/programs.h"
#include "opv_plan.h"

veil_result veil_opv_programs_create(veil_opv_programs* p, veil_error* err)
{
    p->jacobi = p->sweep = p->sweep_one = p->jacobi_block = 0;
    veil_pass_run_init(&p->sweep_run, sizeof(veil_sweep_block), "veil sweep blocks");
    veil_result r = veil_gpu_program("propagate/shaders/propagate_jacobi.comp", &p->jacobi, err);
    if (r == VEIL_OK) r = veil_gpu_program("propagate/shaders/propagate_sweep.comp", &p->sweep, err);
    if (r == VEIL_OK)
        r = veil_gl_buffer(NULL, sizeof(veil_jacobi_block), GL_DYNAMIC_STORAGE_BIT, "veil Jacobi block",
                           &p->jacobi_block, err);
    if (r != VEIL_OK) veil_opv_programs_destroy(p);
    return r;
}

void veil_opv_programs_destroy(veil_opv_programs* p)
{
    glDeleteProgram(p->jacobi);
    glDeleteProgram(p->sweep);
    glDeleteProgram(p->sweep_one);
    glDeleteBuffers(1, &p->jacobi_block);
    veil_pass_run_free(&p->sweep_run);
    p->jacobi = p->sweep = p->sweep_one = p->jacobi_block = 0;
}

/* ---- Jacobi ------------------------------------------------------------ */

/* The block of one texture's lights (at most 4). */
static void jacobi_block_fill(const veil_grid* g, const veil_opv_params* params, const veil_index_light* lights,
                              int count, veil_jacobi_block* b)
{
    memset(b, 0, sizeof *b);
    b->dims[0] = g->dims[0], b->dims[1] = g->dims[1], b->dims[2] = g->dims[2], b->dims[3] = count;
    b->mode[0] = params->method == VEIL_OPV_JACOBI_CORRECTED;
    b->params[0] = g->voxel;
    b->params[1] = params->tolerance;
    for (int c = 0; c < count; ++c) {
        for (int a = 0; a < 3; ++a) {
            b->light[c][a] = lights[c].v[a];
            b->cell[c][a] = lights[c].c[a];
        }
        b->cell[c][3] = lights[c].type;
    }
}

static void jacobi_texture(const veil_grid* g, GLuint target, GLuint scratch, GLuint flags, int max_it,
                           int* iterations)
{
    static const GLfloat zero[4] = {0, 0, 0, 0};
    glClearTexImage(target, 0, GL_RGBA, GL_FLOAT, zero);
    glClearTexImage(scratch, 0, GL_RGBA, GL_FLOAT, zero);
    GLuint src = target, dst = scratch;
    int it = 0;
    while (it < max_it) {
        int check = (it % VEIL_JACOBI_CHECK_EVERY) == VEIL_JACOBI_CHECK_EVERY - 1;
        if (check) {
            const GLuint z = 0;
            glClearNamedBufferData(flags, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &z);
        }
        glBindImageTexture(VEIL_IMAGE_OPV_SRC, src, 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
        glBindImageTexture(VEIL_IMAGE_OPV_DST, dst, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glDispatchCompute(veil_groups(g->dims[0], VEIL_BRICK), veil_groups(g->dims[1], VEIL_BRICK),
                          veil_groups(g->dims[2], VEIL_BRICK));
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT |
                        GL_SHADER_STORAGE_BARRIER_BIT);
        GLuint t = src;
        src = dst;
        dst = t;
        ++it;
        if (check) {
            GLuint changed = 1;
            glGetNamedBufferSubData(flags, 0, sizeof changed, &changed);
            if (!changed) break;
        }
    }
    if (src != target) /* the newest step is in the scratch texture */
        glCopyImageSubData(src, GL_TEXTURE_3D, 0, 0, 0, 0, target, GL_TEXTURE_3D, 0, 0, 0, 0, g->dims[0],
                           g->dims[1], g->dims[2]);
    *iterations = it;
}

static veil_result run_jacobi(veil_opv_programs* p, const veil_grid* g, const veil_index_light* lights, int n_lights,
                              const veil_opv_params* params, const GLuint* opv, int* iterations, veil_error* err)
{
    int max_it = params->max_iterations > 0 ? params->max_iterations : veil_opv_exact_iterations(g);
    GLuint scratch = 0, flags = 0;
    veil_result r = veil_gl_texture3d(GL_RGBA32F, g->dims, "veil OPV scratch", &scratch, err);
    if (r == VEIL_OK) r = veil_gl_buffer(NULL, 0, GL_DYNAMIC_STORAGE_BIT, "veil Jacobi flags", &flags, err);
    if (r == VEIL_OK) {
        glUseProgram(p->jacobi);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_FLAGS, flags);
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_PROPAGATE, p->jacobi_block);
        for (int t = 0; 4 * t < n_lights; ++t) {
            int count = n_lights - 4 * t < 4 ? n_lights - 4 * t : 4, it = 0;
            veil_jacobi_block b;
            jacobi_block_fill(g, params, lights + 4 * t, count, &b);
            glNamedBufferSubData(p->jacobi_block, 0, sizeof b, &b);
            jacobi_texture(g, opv[t], scratch, flags, max_it, &it);
            if (it > *iterations) *iterations = it;
        }
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_PROPAGATE, 0);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_FLAGS, 0);
        glBindImageTexture(VEIL_IMAGE_OPV_SRC, 0, 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
    }
    glDeleteTextures(1, &scratch);
    glDeleteBuffers(1, &flags);
    return r;
}

/* ---- ordered one-pass methods ------------------------------------------ */

/* Adds a pass of `mode` over boxes[0..count) to run (work group z takes
 * box z), with base's texture, light and channel. */
static veil_result add_boxes(veil_pass_run* run, const veil_sweep_block* base, int mode, const veil__box* boxes,
                             int count, veil_error* err)
{
    int most = 0;
    for (int b = 0; b < count; ++b) {
        int size = boxes[b].n[0] * boxes[b].n[1] * boxes[b].n[2];
        most = size > most ? size : most;
    }
    void* mem = NULL;
    veil_result r = veil_pass_run_add(run, veil_groups(most, VEIL_SWEEP_GROUP), 1, (GLuint)count, &mem, err);
    if (r != VEIL_OK) return r;
    veil_sweep_block* blk = mem;
    *blk = *base;
    blk->pass[0] = mode;
    for (int b = 0; b < count; ++b)
        for (int a = 0; a < 3; ++a) {
            blk->boxes[b].lo[a] = boxes[b].lo[a];
            blk->boxes[b].n[a] = boxes[b].n[a];
        }
    return VEIL_OK;
}

/* The passes of light L in their order, into run (emptied first); base
 * holds the texture's settings and the light's channel, and gets the light. */
static veil_result plan_light(veil_pass_run* run, veil_sweep_block* base, const veil_grid* g,
                              const veil_index_light* L, veil_opv_method method, veil_error* err)
{
    veil_pass_run_clear(run);
    for (int a = 0; a < 3; ++a) {
        base->light[a] = L->v[a];
        base->cell[a] = L->c[a];
    }
    base->light[3] = 0.0f;
    base->cell[3] = L->type;
    veil_result r = VEIL_OK;
    if (method == VEIL_OPV_SWEEP) {
        veil__gather_plan plan;
        veil__gather_plan_make(g, L, &plan);
        int u = plan.solve == 0 ? 1 : 0, w = plan.solve == 2 ? 1 : 2;
        for (int m = plan.first; m <= plan.last && r == VEIL_OK; ++m) {
            void* mem = NULL;
            r = veil_pass_run_add(run, veil_groups(g->dims[u] * g->dims[w], VEIL_SWEEP_GROUP), 1, 1, &mem, err);
            if (r != VEIL_OK) break;
            veil_sweep_block* blk = mem;
            *blk = *base;
            blk->pass[0] = 0, blk->pass[1] = m, blk->pass[2] = plan.solve;
        }
        return r;
    }
    veil__box box;
    if (L->type == VEIL_LIGHT_DIRECTIONAL) {
        int a = veil__sl_sun_axis(L);
        for (int k = 0; k < g->dims[a] && r == VEIL_OK; ++k) {
            veil__sl_sun_slice(g, L, k, &box);
            r = add_boxes(run, base, 2, &box, 1, err);
        }
        return r;
    }
    if (veil__sl_near_box(g, L, &box)) r = add_boxes(run, base, 1, &box, 1, err);
    int s0, s1;
    veil__sl_shell_range(g, L, &s0, &s1);
    for (int s = s0; s <= s1 && r == VEIL_OK; ++s)
        for (int k = 1; k <= 3 && r == VEIL_OK; ++k) {
            veil__box boxes[VEIL_SL_MAX_BOXES];
            int nb = veil__sl_boxes(g, L, s, k, boxes);
            if (nb > 0) r = add_boxes(run, base, 2, boxes, nb, err);
        }
    return r;
}

veil_result veil_opv_gpu(veil_opv_programs* p, const veil_grid* g, GLuint ev, const veil_index_light* lights,
                         int n_lights, const veil_opv_params* params, const GLuint* opv, int* iterations,
                         veil_error* err)
{
    int most = 0;
    veil_result r = VEIL_OK;
    if (params->method <= VEIL_OPV_DEFAULT || params->method >= VEIL_OPV_METHOD_COUNT)
        return veil_fail(err, VEIL_ERR_INVALID, "propagate: method %d is not a resolved method (veil_opv_method_resolve)",
                         (int)params->method);
    veil_opv_params on_grid = *params;
    if (on_grid.method == VEIL_OPV_LIGHT_SPACE) on_grid.method = VEIL_OPV_SEMI_LAGRANGIAN; /* a sun kept on the grid */
    params = &on_grid;
    glBindImageTexture(VEIL_IMAGE_EV, ev, 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32F);
    if (params->method == VEIL_OPV_JACOBI || params->method == VEIL_OPV_JACOBI_CORRECTED) {
        r = run_jacobi(p, g, lights, n_lights, params, opv, &most, err);
    } else if (params->method == VEIL_OPV_SWEEP || params->method == VEIL_OPV_SEMI_LAGRANGIAN) {
        static const GLfloat zero[4] = {0, 0, 0, 0};
        veil_sweep_block blk;
        memset(&blk, 0, sizeof blk);
        blk.dims[0] = g->dims[0], blk.dims[1] = g->dims[1], blk.dims[2] = g->dims[2];
        blk.params[0] = g->voxel;
        blk.params[1] = veil_opv_exit_steps(params);
        blk.pass[3] = veil_opv_characteristic(params);
        for (int t = 0; 4 * t < n_lights && r == VEIL_OK; ++t) {
            GLint format = 0;
            glGetTextureLevelParameteriv(opv[t], 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
            int one = format == GL_R32F; /* one light: channel 0 of an r32f texture */
            if (one && !p->sweep_one)
                r = veil_gpu_program_variant("propagate/shaders/propagate_sweep.comp", "#define VEIL_OPV_ONE_CHANNEL 1\n",
                                             "one light", &p->sweep_one, err);
            if (r != VEIL_OK) break;
            glUseProgram(one ? p->sweep_one : p->sweep);
            glClearTexImage(opv[t], 0, one ? GL_RED : GL_RGBA, GL_FLOAT, zero);
            glBindImageTexture(VEIL_IMAGE_OPV_DST, opv[t], 0, GL_TRUE, 0, GL_READ_WRITE, one ? GL_R32F : GL_RGBA32F);
            for (int c = 0; c < 4 && 4 * t + c < n_lights && r == VEIL_OK; ++c) {
                if (lights[4 * t + c].elsewhere) continue; /* its channel stays 0 */
                blk.dims[3] = c;
                r = plan_light(&p->sweep_run, &blk, g, &lights[4 * t + c], params->method, err);
                if (r == VEIL_OK) r = veil_pass_run_upload(&p->sweep_run, err);
                if (r != VEIL_OK) break;
                for (size_t k = 0; k < p->sweep_run.count; ++k) { /* each pass reads only earlier passes' voxels */
                    veil_pass_run_dispatch(&p->sweep_run, VEIL_UBO_PROPAGATE, k);
                    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
                }
                int passes = (int)p->sweep_run.count;
                most = passes > most ? passes : most;
            }
        }
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_PROPAGATE, 0);
    } else {
        r = veil_fail(err, VEIL_ERR_INVALID, "unknown propagation method %d", (int)params->method);
    }
    glBindImageTexture(VEIL_IMAGE_EV, 0, 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32F);
    glBindImageTexture(VEIL_IMAGE_OPV_DST, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glUseProgram(0);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    if (r == VEIL_OK) r = veil_gl_check("optical-depth propagation (propagate/shaders/)", err);
    if (iterations) *iterations = most;
    return r;
}
