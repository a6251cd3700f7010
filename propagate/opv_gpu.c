#include "opv_gpu.h"

#include "../render/gl_util.h"

static void set_lights(GLuint prog, const veil_opv_light* lights, int count)
{
    GLint types[4] = {0, 0, 0, 0};
    GLfloat v[12] = {0};
    for (int c = 0; c < count; ++c) {
        types[c] = lights[c].type;
        for (int a = 0; a < 3; ++a) v[3 * c + a] = lights[c].v[a];
    }
    glProgramUniform1i(prog, glGetUniformLocation(prog, "u_count"), count);
    glProgramUniform1iv(prog, glGetUniformLocation(prog, "u_type"), 4, types);
    glProgramUniform3fv(prog, glGetUniformLocation(prog, "u_light"), 4, v);
}

static veil_result run_texture(GLuint prog, const veil_grid* g, GLuint ev, GLuint target, GLuint scratch,
                               GLuint flags, int max_it, int* iterations)
{
    static const GLfloat zero[4] = {0, 0, 0, 0};
    glClearTexImage(target, 0, GL_RGBA, GL_FLOAT, zero);
    glClearTexImage(scratch, 0, GL_RGBA, GL_FLOAT, zero);
    glBindImageTexture(VEIL_IMAGE_EV, ev, 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32F);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_FLAGS, flags);
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
    return VEIL_OK;
}

veil_result veil_opv_jacobi_gpu(GLuint prog, const veil_grid* g, GLuint ev, const veil_opv_light* lights,
                                int n_lights, const veil_opv_params* params, const GLuint* opv,
                                int* iterations, veil_error* err)
{
    int max_it = params->max_iterations > 0 ? params->max_iterations : veil_opv_exact_iterations(g);
    GLuint scratch = 0, flags = 0;
    veil_result r = veil_gl_texture3d(GL_RGBA32F, g->dims, "veil OPV scratch", &scratch, err);
    if (r == VEIL_OK) r = veil_gl_buffer(NULL, 0, GL_DYNAMIC_STORAGE_BIT, "veil Jacobi flags", &flags, err);
    int most = 0;
    if (r == VEIL_OK) {
        glUseProgram(prog);
        glProgramUniform3i(prog, glGetUniformLocation(prog, "u_dims"), g->dims[0], g->dims[1], g->dims[2]);
        glProgramUniform1f(prog, glGetUniformLocation(prog, "u_voxel"), g->voxel);
        glProgramUniform1f(prog, glGetUniformLocation(prog, "u_tolerance"), params->tolerance);
        for (int t = 0; 4 * t < n_lights && r == VEIL_OK; ++t) {
            int count = n_lights - 4 * t < 4 ? n_lights - 4 * t : 4;
            set_lights(prog, lights + 4 * t, count);
            int it = 0;
            r = run_texture(prog, g, ev, opv[t], scratch, flags, max_it, &it);
            if (it > most) most = it;
        }
        glBindImageTexture(VEIL_IMAGE_EV, 0, 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32F);
        glBindImageTexture(VEIL_IMAGE_OPV_SRC, 0, 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
        glBindImageTexture(VEIL_IMAGE_OPV_DST, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_FLAGS, 0);
        glUseProgram(0);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
        if (r == VEIL_OK) r = veil_gl_check("optical-depth propagation (propagate/shaders/propagate_jacobi.comp)", err);
    }
    glDeleteTextures(1, &scratch);
    glDeleteBuffers(1, &flags);
    if (iterations) *iterations = most;
    return r;
}
