#include "inject_gpu.h"

#include <string.h>

#include "../core/progress.h"
#include "../gpu/gl_util.h"
#include "../gpu/programs.h"

veil_result veil_inject_rbf_gpu(GLuint program, GLuint* program_octants, const veil_grid* g, const veil_rbf_bins* b,
                                GLuint ev_texture, size_t dispatch_evals, veil_error* err)
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
        /* Without a progress sink: whole layers of bricks, as many a dispatch as keep its particle-voxel
         * evaluations under VEIL_SPLAT_DISPATCH_EVALS (a GPU watchdog stops a dispatch of a few seconds; at
         * least one layer), a work group a brick. With one: runs of bricks in their (CSR) order under
         * dispatch_evals (on a software rasteriser a dispatch is also how late a cancel is seen), one brick
         * at least, at most the work groups a dispatch may count along x (GL guarantees 65535; 8 a brick
         * with octants), and a run of crowded bricks (VEIL_SPLAT_OCTANTS_FROM list entries a brick or more)
         * split into octants (inject_rbf.comp). Measured on llvmpipe (docs/performance.md, "Cancel"): short
         * dispatches cost the cloud's splat a third more, and a software rasteriser balances its threads
         * over a 3-D dispatch of whole layers better than over a long run (10^6 particles: 46 s against
         * 98 s), so the runs only where a cancel may come. */
        const int report = veil_progress_wanted();
        const size_t nb_all = nb, per_brick = VEIL_BRICK * VEIL_BRICK * VEIL_BRICK, most = 65535 / 8;
        const size_t layer = (size_t)b->bricks[0] * (size_t)b->bricks[1];
        const size_t cap = (report ? dispatch_evals : VEIL_SPLAT_DISPATCH_EVALS) / per_brick; /* list entries */
        const double all = (double)b->list_len * per_brick;
        double done = 0.0;
        if (report) veil_progress("RBF splat", 0.0, all);
        size_t k = 0;
        while (k < nb_all) {
            size_t k1 = k + 1;
            GLuint groups[3] = {1, 1, 1};
            int octants = 0;
            if (!report) { /* whole layers from k (a layer's first brick) */
                k1 = k + layer;
                while (k1 < nb_all && (size_t)(b->start[k1 + layer] - b->start[k]) <= cap) k1 += layer;
                groups[0] = (GLuint)b->bricks[0], groups[1] = (GLuint)b->bricks[1], groups[2] = (GLuint)((k1 - k) / layer);
            } else { /* the last k1 in (k, k + most] whose entries from k fit the cap (k + 1 whatever it holds) */
                size_t lo = k + 1, hi = k + most < nb_all ? k + most : nb_all;
                while (lo < hi) {
                    const size_t mid = lo + (hi - lo + 1) / 2;
                    if ((size_t)(b->start[mid] - b->start[k]) <= cap) lo = mid;
                    else hi = mid - 1;
                }
                k1 = lo;
                octants = b->start[k1] - b->start[k] >= (uint32_t)(k1 - k) * VEIL_SPLAT_OCTANTS_FROM;
                groups[0] = (GLuint)((octants ? 8 : 1) * (k1 - k));
            }
            if (octants && !*program_octants) {
                r = veil_gpu_program_variant("volume/shaders/inject_rbf.comp", "#define VEIL_SPLAT_OCTANTS 1\n",
                                             "octants", program_octants, err);
                if (r != VEIL_OK) break;
            }
            blk.dims[3] = (int)k; /* this dispatch's first brick */
            glNamedBufferSubData(block, 0, sizeof blk.dims, blk.dims);
            glUseProgram(octants ? *program_octants : program);
            glDispatchCompute(groups[0], groups[1], groups[2]);
            glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                            GL_TEXTURE_UPDATE_BARRIER_BIT);
            glFlush();
            done += (double)(b->start[k1] - b->start[k]) * per_brick;
            k = k1;
            if (report) { /* what is reported is done: the dispatch is finished first */
                glFinish();
                veil_progress("RBF splat", done, all);
                if (veil_progress_cancelled() && k < nb_all) {
                    r = veil_fail(err, VEIL_ERR_CANCELLED, "cancelled by the progress callback during the RBF "
                                  "splat (%.3g of %.3g evaluations done)", done, all);
                    break;
                }
            }
        }
        for (GLuint i = 0; i < 3; ++i) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_PARTICLES + i, 0);
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_GRID, 0);
        glBindImageTexture(VEIL_IMAGE_EV, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
        glUseProgram(0);
        if (r == VEIL_OK) r = veil_gl_check("RBF splat dispatch (volume/shaders/inject_rbf.comp)", err);
    }
    glDeleteBuffers(3, buf);
    glDeleteBuffers(1, &block);
    return r;
}
