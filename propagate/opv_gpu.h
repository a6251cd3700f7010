/* veil — the published Jacobi gather on the GPU
 * (propagate/shaders/propagate_jacobi.comp), four lights per rgba32f
 * texture, ping-pong between the caller's texture and a scratch one.
 * Same scheme and same float operations as veil_opv_jacobi_cpu(). */
#ifndef VEIL_OPV_GPU_H
#define VEIL_OPV_GPU_H

#include <epoxy/gl.h>

#include "opv.h"

/* Fills opv[t] (ceil(n_lights/4) rgba32f textures of the grid's size, made
 * by the caller) for lights 4t..4t+3; ev is the r32f density texture.
 * *iterations: the most Jacobi steps any texture needed. */
veil_result veil_opv_jacobi_gpu(GLuint program, const veil_grid* g, GLuint ev, const veil_opv_light* lights,
                                int n_lights, const veil_opv_params* params, const GLuint* opv,
                                int* iterations, veil_error* err);

#endif
