#include "opv_gpu.h"

#include "../gpu/gl_util.h"
#include "../gpu/programs.h"
#include "opv_plan.h"

veil_result veil_opv_programs_create(veil_opv_programs* p, veil_error* err)
{
    p->jacobi = p->sweep = p->sweep_one = 0;
    veil_result r = veil_gpu_program("propagate/shaders/propagate_jacobi.comp", &p->jacobi, err);
    if (r == VEIL_OK) r = veil_gpu_program("propagate/shaders/propagate_sweep.comp", &p->sweep, err);
    if (r != VEIL_OK) veil_opv_programs_destroy(p);
    return r;
}

void veil_opv_programs_destroy(veil_opv_programs* p)
{
    glDeleteProgram(p->jacobi);
    glDeleteProgram(p->sweep);
    glDeleteProgram(p->sweep_one);
    p->jacobi = p->sweep = p->sweep_one = 0;
}

static GLint loc(GLuint prog, const char* name) { return glGetUniformLocation(prog, name); }

/* ---- Jacobi ------------------------------------------------------------ */

static void jacobi_lights(GLuint prog, const veil_index_light* lights, int count)
{
    GLint types[4] = {0, 0, 0, 0}, cells[12] = {0};
    GLfloat v[12] = {0};
    for (int c = 0; c < count; ++c) {
        types[c] = lights[c].type;
        for (int a = 0; a < 3; ++a) {
            v[3 * c + a] = lights[c].v[a];
            cells[3 * c + a] = lights[c].c[a];
        }
    }
    glProgramUniform1i(prog, loc(prog, "u_count"), count);
    glProgramUniform1iv(prog, loc(prog, "u_type"), 4, types);
    glProgramUniform3fv(prog, loc(prog, "u_light"), 4, v);
    glProgramUniform3iv(prog, loc(prog, "u_cell"), 4, cells);
}

static void jacobi_texture(GLuint prog, const veil_grid* g, GLuint target, GLuint scratch, GLuint flags, int max_it,
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

static veil_result run_jacobi(GLuint prog, const veil_grid* g, const veil_index_light* lights, int n_lights,
                              const veil_opv_params* params, const GLuint* opv, int* iterations, veil_error* err)
{
    int max_it = params->max_iterations > 0 ? params->max_iterations : veil_opv_exact_iterations(g);
    GLuint scratch = 0, flags = 0;
    veil_result r = veil_gl_texture3d(GL_RGBA32F, g->dims, "veil OPV scratch", &scratch, err);
    if (r == VEIL_OK) r = veil_gl_buffer(NULL, 0, GL_DYNAMIC_STORAGE_BIT, "veil Jacobi flags", &flags, err);
    if (r == VEIL_OK) {
        glUseProgram(prog);
        glProgramUniform1i(prog, loc(prog, "u_corrected"), params->method == VEIL_OPV_JACOBI_CORRECTED);
        glProgramUniform1f(prog, loc(prog, "u_tolerance"), params->tolerance);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_FLAGS, flags);
        for (int t = 0; 4 * t < n_lights; ++t) {
            int count = n_lights - 4 * t < 4 ? n_lights - 4 * t : 4, it = 0;
            jacobi_lights(prog, lights + 4 * t, count);
            jacobi_texture(prog, g, opv[t], scratch, flags, max_it, &it);
            if (it > *iterations) *iterations = it;
        }
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_FLAGS, 0);
        glBindImageTexture(VEIL_IMAGE_OPV_SRC, 0, 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
    }
    glDeleteTextures(1, &scratch);
    glDeleteBuffers(1, &flags);
    return r;
}

/* ---- ordered one-pass methods ------------------------------------------ */

static void dispatch_boxes(GLuint prog, int mode, const veil__box* boxes, int count)
{
    GLint lo[3 * VEIL_SL_MAX_BOXES], n[3 * VEIL_SL_MAX_BOXES];
    int most = 0;
    for (int b = 0; b < count; ++b) {
        for (int a = 0; a < 3; ++a) {
            lo[3 * b + a] = boxes[b].lo[a];
            n[3 * b + a] = boxes[b].n[a];
        }
        int size = boxes[b].n[0] * boxes[b].n[1] * boxes[b].n[2];
        most = size > most ? size : most;
    }
    glProgramUniform1i(prog, loc(prog, "u_mode"), mode);
    glProgramUniform3iv(prog, loc(prog, "u_box_lo"), count, lo);
    glProgramUniform3iv(prog, loc(prog, "u_box_n"), count, n);
    glDispatchCompute(veil_groups(most, VEIL_SWEEP_GROUP), 1, (GLuint)count);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
}

static int sweep_light(GLuint prog, const veil_grid* g, const veil_index_light* L, veil_opv_method method)
{
    glProgramUniform1i(prog, loc(prog, "u_type"), L->type);
    glProgramUniform3fv(prog, loc(prog, "u_light"), 1, L->v);
    glProgramUniform3iv(prog, loc(prog, "u_cell"), 1, L->c);
    int passes = 0;
    if (method == VEIL_OPV_SWEEP) {
        veil__gather_plan plan;
        veil__gather_plan_make(g, L, &plan);
        int u = plan.solve == 0 ? 1 : 0, w = plan.solve == 2 ? 1 : 2;
        glProgramUniform1i(prog, loc(prog, "u_mode"), 0);
        glProgramUniform1i(prog, loc(prog, "u_solve"), plan.solve);
        for (int m = plan.first; m <= plan.last; ++m, ++passes) {
            glProgramUniform1i(prog, loc(prog, "u_shell"), m);
            glDispatchCompute(veil_groups(g->dims[u] * g->dims[w], VEIL_SWEEP_GROUP), 1, 1);
            glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        }
        return passes;
    }
    veil__box box;
    if (L->type == VEIL_LIGHT_DIRECTIONAL) {
        int a = veil__sl_sun_axis(L);
        for (int k = 0; k < g->dims[a]; ++k, ++passes) {
            veil__sl_sun_slice(g, L, k, &box);
            dispatch_boxes(prog, 2, &box, 1);
        }
        return passes;
    }
    if (veil__sl_near_box(g, L, &box)) {
        dispatch_boxes(prog, 1, &box, 1);
        ++passes;
    }
    int s0, s1;
    veil__sl_shell_range(g, L, &s0, &s1);
    for (int s = s0; s <= s1; ++s)
        for (int k = 1; k <= 3; ++k) {
            veil__box boxes[VEIL_SL_MAX_BOXES];
            int nb = veil__sl_boxes(g, L, s, k, boxes);
            if (nb == 0) continue;
            dispatch_boxes(prog, 2, boxes, nb);
            ++passes;
        }
    return passes;
}

veil_result veil_opv_gpu(veil_opv_programs* p, const veil_grid* g, GLuint ev, const veil_index_light* lights,
                         int n_lights, const veil_opv_params* params, const GLuint* opv, int* iterations,
                         veil_error* err)
{
    int most = 0;
    veil_result r = VEIL_OK;
    veil_opv_params resolved = *params;
    resolved.method = veil_opv_method_resolve(params->method);
    if (resolved.method == VEIL_OPV_LIGHT_SPACE) resolved.method = VEIL_OPV_SEMI_LAGRANGIAN; /* on the grid */
    params = &resolved;
    glBindImageTexture(VEIL_IMAGE_EV, ev, 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32F);
    if (params->method == VEIL_OPV_JACOBI || params->method == VEIL_OPV_JACOBI_CORRECTED) {
        GLuint prog = p->jacobi;
        glProgramUniform3i(prog, loc(prog, "u_dims"), g->dims[0], g->dims[1], g->dims[2]);
        glProgramUniform1f(prog, loc(prog, "u_voxel"), g->voxel);
        r = run_jacobi(prog, g, lights, n_lights, params, opv, &most, err);
    } else if (params->method == VEIL_OPV_SWEEP || params->method == VEIL_OPV_SEMI_LAGRANGIAN) {
        static const GLfloat zero[4] = {0, 0, 0, 0};
        for (int t = 0; 4 * t < n_lights && r == VEIL_OK; ++t) {
            GLint format = 0;
            glGetTextureLevelParameteriv(opv[t], 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
            int one = format == GL_R32F; /* one light: channel 0 of an r32f texture */
            if (one && !p->sweep_one)
                r = veil_gpu_program_variant("propagate/shaders/propagate_sweep.comp", "#define VEIL_OPV_ONE_CHANNEL 1\n",
                                             "one light", &p->sweep_one, err);
            if (r != VEIL_OK) break;
            GLuint prog = one ? p->sweep_one : p->sweep;
            glUseProgram(prog);
            glProgramUniform3i(prog, loc(prog, "u_dims"), g->dims[0], g->dims[1], g->dims[2]);
            glProgramUniform1f(prog, loc(prog, "u_voxel"), g->voxel);
            glProgramUniform1f(prog, loc(prog, "u_exit_steps"), veil_opv_exit_steps(params));
            glProgramUniform1i(prog, loc(prog, "u_characteristic"), veil_opv_characteristic(params));
            glClearTexImage(opv[t], 0, one ? GL_RED : GL_RGBA, GL_FLOAT, zero);
            glBindImageTexture(VEIL_IMAGE_OPV_DST, opv[t], 0, GL_TRUE, 0, GL_READ_WRITE, one ? GL_R32F : GL_RGBA32F);
            for (int c = 0; c < 4 && 4 * t + c < n_lights; ++c) {
                if (lights[4 * t + c].elsewhere) continue; /* its channel stays 0 */
                glProgramUniform1i(prog, loc(prog, "u_channel"), c);
                int passes = sweep_light(prog, g, &lights[4 * t + c], params->method);
                most = passes > most ? passes : most;
            }
        }
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
