/* veil — the renderer: runs a scene's pipeline on the GPU, frame after
 * frame, doing only the work a frame needs.
 *
 * A frame is a walk over the table of stages (frame/stages.h: inject,
 * propagate, volumetric, render, spread), each row a key from
 * descriptions, a GPU-free decision (ran / cached / skipped, and why), a
 * build and its report. The renderer owns the GPU objects that hold the
 * stages' results between frames and the keys they were made with, so a
 * frame whose keys match reuses them (a turntable: only the camera moves,
 * so inject, propagate and the volumetric field run once). `--explain`
 * (frame/plan.h) walks the same table with the same decisions and no GPU.
 *
 * A renderer needs the veil_gl context that was current when it was
 * created (its memory budget bounds the volumes). Returned buffers are
 * malloc'd, top row first.
 */
#ifndef VEIL_RENDERER_H
#define VEIL_RENDERER_H

#include <stdint.h>

#include "../core/result.h"
#include "../gpu/gl_context.h"
#include "../propagate/opv.h"
#include "../render/image_set.h"
#include "../render/march.h"
#include "../scene/scene.h"
#include "../volume/scene_volume.h"
#include "../volume/volume.h"
#include "stage.h"
#include "stages.h"

typedef struct veil_renderer veil_renderer;

veil_result veil_renderer_create(const veil_gl* gl, veil_renderer** out, veil_error* err);
/* A renderer that makes its own GL context (desc may be NULL) when a frame
 * first needs the GPU: after inject has opened the sources and estimated
 * their work, so that a volume refused on the CPU never costs a context
 * (the CLI's; VEIL_ERR_GPU then comes from the first render). */
veil_result veil_renderer_create_deferred(const veil_gl_desc* desc, veil_renderer** out, veil_error* err);
void veil_renderer_destroy(veil_renderer* r); /* accepts NULL */

/* The whole pipeline for a scene, into an image set (*images is freed
 * first; stats may be NULL). */
veil_result veil_render_scene_images(veil_renderer* r, const veil_scene* s, const veil_render_opts* opts,
                                     veil_image_set* images, veil_render_stats* stats, veil_error* err);

/* The same, keeping only the radiance and alpha (*rgba: width*height*4 floats). */
veil_result veil_render_scene(veil_renderer* r, const veil_scene* s, const veil_render_opts* opts,
                              float** rgba, veil_render_stats* stats, veil_error* err);

/* Same, with the density given on a grid instead of injected from the
 * scene's sources (tests, and later other sources); its inject key hashes
 * the grid and the density. */
veil_result veil_render_density(veil_renderer* r, const veil_scene* s, const veil_grid* g,
                                const float* density, const veil_render_opts* opts, float** rgba,
                                veil_render_stats* stats, veil_error* err);

/* Stage access for tests: GPU splat read back (veil_grid_voxels floats) and
 * GPU propagation read back (n_lights * voxels floats, light-major). */
veil_result veil_renderer_inject(veil_renderer* r, const veil_grid* g, const veil_particle* p, size_t n,
                                 float* density, veil_error* err);
veil_result veil_renderer_propagate(veil_renderer* r, const veil_grid* g, const float* density,
                                    const veil_index_light* lights, int n_lights, const veil_opv_params* params,
                                    float* out, int* iterations, veil_error* err);

#endif
