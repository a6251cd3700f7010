/* veil — the RBF splat on the GPU (volume/shaders/inject_rbf.comp): adds
 * binned particles to an r32f 3D texture of the grid's size, exactly as
 * veil_inject_rbf_cpu() does. Needs a current GL context. */
#ifndef VEIL_INJECT_GPU_H
#define VEIL_INJECT_GPU_H

#include <epoxy/gl.h>

#include "volume.h"

veil_result veil_inject_rbf_gpu(GLuint program, const veil_grid* g, const veil_rbf_bins* bins,
                                GLuint ev_texture, veil_error* err);

#endif
