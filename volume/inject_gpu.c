#include "inject_gpu.h"

#include <string.h>

#include "../core/progress.h"
#include "../gpu/gl_util.h"

veil_result veil_inject_rbf_gpu(GLuint program, const veil_grid* g, const veil_rbf_bins* b,
                                GLuint ev_texture, veil_error* err)
{
    size_t nb = (size_t)b->bricks[0] * b->bricks[1] * b->bricks[2];
    GLuint buf[3] = {0, 0, 0}, block = 0;
    veil_grid_block blk;
    memset(&blk, 0, sizeof blk);
    for (int a = 0; a < 3; ++a) {
        blk.dims[a] = g->dims[a];
        blk.bricks[a] = b->bricks[a];
        blk.origin[a] = g->origin[a];
    }
    blk.origin[3] = g->voxel;
    veil_result r = veil_gl_buffer(b->packed, b->particle_count * 8 * sizeof(float), 0, "veil particles", &buf[0], err);
    if (r == VEIL_OK) r = veil_gl_buffer(b->start, (nb + 1) * sizeof(uint32_t), 0, "veil brick starts", &buf[1], err);
    if (r == VEIL_OK) r = veil_gl_buffer(b->list, b->list_len * sizeof(uint32_t), 0, "veil brick lists", &buf[2], err);
    if (r == VEIL_OK) r = veil_gl_buffer(&blk, sizeof blk, GL_DYNAMIC_STORAGE_BIT, "veil splat block", &block, err);
    if (r == VEIL_OK) {
        glUseProgram(program);
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_GRID, block);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_PARTICLES, buf[0]);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_BRICK_START, buf[1]);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_BRICK_LIST, buf[2]);
        glBindImageTexture(VEIL_IMAGE_EV, ev_texture, 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32F);
        /* layers of bricks, as many per dispatch as keep its particle-voxel evaluations under
         * VEIL_SPLAT_DISPATCH_EVALS (a GPU watchdog stops a dispatch of a few seconds; each
         * layer alone is under it whenever the whole splat is under VEIL_SPLAT_MAX_EVALS) */
        size_t layer = (size_t)b->bricks[0] * (size_t)b->bricks[1];
        const double all = (double)b->list_len * VEIL_BRICK * VEIL_BRICK * VEIL_BRICK;
        double done = 0.0;
        const int report = veil_progress_wanted();
        if (report) veil_progress("RBF splat", 0.0, all);
        int z = 0;
        while (z < b->bricks[2]) {
            int z1 = z;
            size_t work = 0;
            do {
                work += (size_t)(b->start[layer * (size_t)(z1 + 1)] - b->start[layer * (size_t)z1]) *
                        VEIL_BRICK * VEIL_BRICK * VEIL_BRICK;
                ++z1;
            } while (z1 < b->bricks[2] &&
                     work + (size_t)(b->start[layer * (size_t)(z1 + 1)] - b->start[layer * (size_t)z1]) *
                                VEIL_BRICK * VEIL_BRICK * VEIL_BRICK <= VEIL_SPLAT_DISPATCH_EVALS);
            blk.dims[3] = z; /* this dispatch's first layer */
            glNamedBufferSubData(block, 0, sizeof blk.dims, blk.dims);
            glDispatchCompute((GLuint)b->bricks[0], (GLuint)b->bricks[1], (GLuint)(z1 - z));
            glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                            GL_TEXTURE_UPDATE_BARRIER_BIT);
            glFlush();
            z = z1;
            done += (double)work;
            if (report) { /* what is reported is done: the dispatch is finished first */
                glFinish();
                veil_progress("RBF splat", done, all);
            }
        }
        for (GLuint i = 0; i < 3; ++i) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_PARTICLES + i, 0);
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_GRID, 0);
        glBindImageTexture(VEIL_IMAGE_EV, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
        glUseProgram(0);
        r = veil_gl_check("RBF splat dispatch (volume/shaders/inject_rbf.comp)", err);
    }
    glDeleteBuffers(3, buf);
    glDeleteBuffers(1, &block);
    return r;
}
