/* veil — the optical-depth methods on the GPU: the Jacobi ping-pong
 * (propagate/shaders/propagate_jacobi.comp, four lights per step) and the
 * ordered one-pass methods (propagate/shaders/propagate_sweep.comp, one
 * light at a time, in place). Same per-voxel code and order as
 * veil_opv_cpu(). Each pass reads its settings from a std140 block
 * (opv_blocks.glsl.h) bound at VEIL_UBO_PROPAGATE while it runs. */
#ifndef VEIL_OPV_GPU_H
#define VEIL_OPV_GPU_H

#include <epoxy/gl.h>

#include "../gpu/pass_run.h"
#include "opv.h"
#include "opv_blocks.glsl.h"

typedef struct veil_opv_programs {
    GLuint jacobi, sweep;
    GLuint sweep_one; /* the sweep on an r32f texture of one light, made when first needed */
    GLuint jacobi_block;     /* the Jacobi step's uniform buffer (veil_jacobi_block) */
    veil_pass_run sweep_run; /* an ordered method's passes for one light (veil_sweep_block each) */
} veil_opv_programs;

veil_result veil_opv_programs_create(veil_opv_programs* p, veil_error* err);
void veil_opv_programs_destroy(veil_opv_programs* p);

/* Fills opv[t] (ceil(n_lights/4) rgba32f textures of the grid's size, made
 * by the caller; for the ordered methods a texture of one light may be
 * r32f) for lights 4t..4t+3; ev is the r32f density texture.
 * *iterations: the most Jacobi steps, or sweep passes, any light needed. */
veil_result veil_opv_gpu(veil_opv_programs* p, const veil_grid* g, GLuint ev, const veil_index_light* lights,
                         int n_lights, const veil_opv_params* params, const GLuint* opv, int* iterations,
                         veil_error* err);

#endif
