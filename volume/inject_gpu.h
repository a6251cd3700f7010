/* veil — the RBF splat on the GPU (volume/shaders/inject_rbf.comp): adds
 * binned particles to an r32f 3D texture of the grid's size, exactly as
 * veil_inject_rbf_cpu() does. Needs a current GL context. */
#ifndef VEIL_INJECT_GPU_H
#define VEIL_INJECT_GPU_H

#include <epoxy/gl.h>

#include "volume.h"

/* program: inject_rbf.comp, a work group a brick; *program_octants: its
 * VEIL_SPLAT_OCTANTS variant (made here when first needed), eight a brick,
 * for a run of bricks of VEIL_SPLAT_OCTANTS_FROM list entries a brick or
 * more (a software rasteriser runs a work group on one thread: a dispatch's
 * last crowded bricks kept one thread busy while the others waited: 10^6
 * particles splat in 37 s with octants, 46-98 s without; light bricks keep
 * whole-brick groups, whose overhead is an eighth: the cloud scene's splat
 * takes 150 ms so, 190 ms in octants). In dispatches of runs of bricks in
 * their order (at least one) of at most VEIL_SPLAT_DISPATCH_EVALS
 * particle-voxel evaluations, or, with a progress sink, of dispatch_evals
 * (VEIL_SPLAT_SOFTWARE_EVALS on a software rasteriser: volume/volume.h):
 * each is then finished and reported, and a cancel found there stops the
 * splat (VEIL_ERR_CANCELLED, the texture partly made). */
#define VEIL_SPLAT_OCTANTS_FROM 256
veil_result veil_inject_rbf_gpu(GLuint program, GLuint* program_octants, const veil_grid* g,
                                const veil_rbf_bins* bins, GLuint ev_texture, size_t dispatch_evals,
                                veil_error* err);

#endif
