/* veil — the renderer: runs the pipeline of a scene on the GPU.
 *
 *   particles --inject--> extinction volume (density, r32f 3D texture)
 *             --propagate--> optical-depth volumes (rgba32f, 4 lights each)
 *             --march--> linear RGBA image (rgb radiance, a = 1 - mean T)
 *
 * A renderer owns its compute programs and needs the veil_gl context that
 * was current when it was created. Images are returned as newly malloc'd
 * float RGBA, top row first (free() them).
 *
 * Work a frame does not need is skipped: the EV is kept with a key of the
 * content it was made from (resolution and particles, or the given
 * density), and each OPV texture with a key of the EV, the method and its
 * lights' positions; a later render whose inputs have the same keys (a
 * turntable: only the camera moves) reuses them, and the stats say
 * "cached". Lights that add nothing (zero colour, or a spot whose cone
 * misses the volume) get no OPV and are not marched; an empty medium
 * makes no EV and no OPV.
 */
#ifndef VEIL_RENDERER_H
#define VEIL_RENDERER_H

#include <stdint.h>

#include "../core/result.h"
#include "../io/scene.h"
#include "../propagate/opv.h"
#include "../volume/scene_volume.h"
#include "../volume/volume.h"
#include "gl_context.h"

/* Ray-march step as a fraction of the voxel edge. Half a voxel resolves the
 * trilinear medium between centres; the step error is measured, not assumed. */
#define VEIL_DEFAULT_STEP_VOXELS 0.5f

/* Jacobi stops when a checked step changes no optical depth sigma_t * D by
 * more than this (unitless): well under the 8-bit resolution of a preview. */
#define VEIL_OPV_TAU_TOLERANCE 1e-4f

/* The smallest march step through fog when there is no volume (m). */
#define VEIL_FOG_MIN_STEP 0.01f

/* Point lights closer than this fraction of a voxel count as this far (the
 * 1/r^2 singularity is integrable in the continuum but not in samples). */
#define VEIL_MIN_LIGHT_DISTANCE_VOXELS 1e-3f

typedef struct veil_renderer veil_renderer;

typedef struct veil_render_opts {
    int width, height;      /* 0: the scene camera's */
    float step_voxels;      /* 0: VEIL_DEFAULT_STEP_VOXELS */
    uint32_t seed;          /* jitter seed */
    veil_opv_method method; /* 0: VEIL_OPV_DEFAULT_METHOD */
    const veil_camera* camera; /* NULL: the scene's (turntables move it) */
    int no_skip;            /* 1: march through empty bricks too (to measure what skipping saves) */
    /* > 0: rays stop at the first step boundary at or beyond this distance
     * from the camera (m); the steps before it are the same as without it,
     * so alpha (1 - mean T) is the transmittance of a prefix of the same
     * march (tests of T along rays). 0: no limit. */
    float max_distance;
} veil_render_opts;

typedef struct veil_render_stats {
    double inject_ms, propagate_ms, render_ms; /* wall time, GPU work finished */
    int has_volume;       /* 0: nothing to inject (empty medium) */
    int inject_cached;    /* the EV was reused */
    veil_grid grid;       /* the EV's geometry when has_volume */
    size_t particles;
    size_t vdb_voxels;    /* active voxels of the OpenVDB grids (0 when cached) */
    int lights_used;      /* lights that reach the medium and add light */
    int fogs;             /* analytic fogs (closed form, never voxelised) */
    int opv_computed, opv_cached; /* OPV textures made / reused */
    veil_opv_method method;
    int propagate_iterations; /* Jacobi steps or sweep passes (most of any light) */
} veil_render_stats;

veil_result veil_renderer_create(const veil_gl* gl, veil_renderer** out, veil_error* err);
void veil_renderer_destroy(veil_renderer* r); /* accepts NULL */

/* gl: the current context (its memory budget bounds the volumes). */

/* The whole pipeline for a scene. */
veil_result veil_render_scene(veil_renderer* r, const veil_scene* s, const veil_render_opts* opts,
                              float** rgba, veil_render_stats* stats, veil_error* err);

/* Same, with the density given on a grid instead of injected from the
 * scene's sources (tests, and later other sources). */
veil_result veil_render_density(veil_renderer* r, const veil_scene* s, const veil_grid* g,
                                const float* density, const veil_render_opts* opts, float** rgba,
                                veil_render_stats* stats, veil_error* err);

/* Stage access for tests: GPU splat read back (veil_grid_voxels floats) and
 * GPU Jacobi read back (n_lights * voxels floats, light-major). */
veil_result veil_renderer_inject(veil_renderer* r, const veil_grid* g, const veil_particle* p, size_t n,
                                 float* density, veil_error* err);
veil_result veil_renderer_propagate(veil_renderer* r, const veil_grid* g, const float* density,
                                    const veil_opv_light* lights, int n_lights, const veil_opv_params* params,
                                    float* out, int* iterations, veil_error* err);

#endif
