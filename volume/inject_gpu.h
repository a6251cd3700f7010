/* veil — the RBF splat on the GPU (volume/shaders/inject_rbf.comp): adds
 * binned particles to an r32f 3D texture of the grid's size, exactly as
 * veil_inject_rbf_cpu() does. Needs a current GL context. */
#ifndef VEIL_INJECT_GPU_H
#define VEIL_INJECT_GPU_H

#include <epoxy/gl.h>

#include "volume.h"

/* In dispatches of at most dispatch_evals particle-voxel evaluations
 * (VEIL_SPLAT_DISPATCH_EVALS on a GPU, VEIL_SPLAT_SOFTWARE_EVALS on a
 * software rasteriser: volume/volume.h), runs of bricks in their order (at
 * least one); with a progress sink each is finished and reported, and a cancel
 * found there stops the splat (VEIL_ERR_CANCELLED, the texture partly
 * made). */
veil_result veil_inject_rbf_gpu(GLuint program, const veil_grid* g, const veil_rbf_bins* bins,
                                GLuint ev_texture, size_t dispatch_evals, veil_error* err);

#endif
