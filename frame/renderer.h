/* veil — the renderer: runs a scene's pipeline on the GPU, frame after
 * frame, doing only the work a frame needs.
 *
 *   sources --inject--> extinction volume (volume/ev.h)
 *           --propagate--> optical-depth volumes (propagate/opv_set.h)
 *           --march--> image set (render/march.h, render/image_set.h)
 *
 * Each stage has one shape (frame/stage.h): its key is computed from
 * descriptions — the inject key from the sources' descriptions and the VDB
 * files' identities (volume/scene_volume.h: no file is opened to form it),
 * each OPV texture's key from the inject key, the method and its lights'
 * geometry (not their colour) — and a frame whose keys match what the
 * renderer keeps reuses it (a turntable: only the camera moves, so inject
 * and propagate run once). Lights that add nothing (zero colour, or a spot
 * whose cone misses the volume) get no OPV and are not marched; an empty
 * medium makes no EV and no OPV. The stats carry each stage's report.
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

/* Jacobi stops when a checked step changes no optical depth sigma_t * D by
 * more than this (unitless): well under the 8-bit resolution of a preview. */
#define VEIL_OPV_TAU_TOLERANCE 1e-4f

typedef struct veil_renderer veil_renderer;

/* Zero means "default" in every field; veil_render_opts_resolve() says
 * what zero resolves to. */
typedef struct veil_render_opts {
    int width, height;      /* 0: the camera's */
    float step_voxels;      /* 0: the quality rung's */
    uint32_t seed;          /* jitter seed */
    veil_opv_method method; /* 0: the quality rung's */
    veil_quality quality;   /* UNSET: the scene's "quality", else VEIL_QUALITY_DEFAULT */
    float sun_across, sun_along; /* light-space grids' node spacing (voxels); 0: the rung's */
    const veil_camera* camera; /* NULL: the scene's (turntables move it) */
    int no_skip;            /* 1: march through empty bricks too (to measure what skipping saves) */
    /* > 0: rays stop at the first step boundary at or beyond this distance
     * from the camera (m); the steps before it are the same as without it,
     * so alpha (1 - mean T) is the transmittance of a prefix of the same
     * march (tests of T along rays). 0: no limit. */
    float max_distance;
    /* A frame rendered elsewhere (veil fog): width*height RGBA radiance of
     * the surfaces behind the medium (replacing the scene's background;
     * the screen-space spread blurs it) and, per pixel, their distance
     * along the camera ray (m, >= 0, +inf: nothing there), where each ray
     * ends. NULL: the scene's background at infinity. */
    const float* behind;
    const float* behind_distance;
} veil_render_opts;

/* opts (NULL: all defaults) with every zero replaced by what it means for
 * scene s: the one place defaults are resolved. */
veil_render_opts veil_render_opts_resolve(const veil_render_opts* opts, const veil_scene* s);

typedef struct veil_render_stats {
    veil_stage_report stage[VEIL_STAGE_COUNT];
    double inject_ms, propagate_ms, render_ms; /* = stage[...].ms */
    int width, height;    /* the image's size */
    int has_volume;       /* 0: nothing to inject (empty medium) */
    int inject_cached;    /* the EV was reused */
    veil_grid grid;       /* the EV's geometry when has_volume */
    size_t particles;
    size_t vdb_voxels;    /* active voxels of the OpenVDB grids (0 when cached) */
    int lights_used;      /* lights that reach the medium and add light (with the emission's) */
    int emission_lights;  /* of them, the medium's emission as lights (volume/emission_lights.h) */
    int fogs;             /* analytic fogs (closed form, never voxelised) */
    int opv_computed, opv_cached; /* OPV textures made / reused */
    veil_opv_method method;
    int propagate_iterations; /* Jacobi steps or sweep passes (most of any light) */
} veil_render_stats;

veil_result veil_renderer_create(const veil_gl* gl, veil_renderer** out, veil_error* err);
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

/* The lights of s that add light inside the box of g (NULL: fog only, no
 * box), in scene order, into out (VEIL_MAX_LIGHTS): zero colour never
 * does; a spot whose outer cone misses the box's bounding sphere does not. */
int veil_render_lights(const veil_scene* s, const veil_grid* g, veil_light* out);

/* The propagation parameters for s under resolved options o: the method,
 * the light-space spacing, the Jacobi tolerance on D that keeps sigma_t D
 * within VEIL_OPV_TAU_TOLERANCE, and (grid g, a device budget of `budget`
 * bytes; NULL or 0: none) the memory left for the suns' grids. */
veil_opv_params veil_render_opv_params(const veil_scene* s, const veil_render_opts* o, const veil_grid* g,
                                       unsigned long long budget);

/* What a rung of the quality ladder sets (each 0 left to the options). */
typedef struct veil_quality_rung {
    float step_voxels;
    veil_opv_method method;
    float sun_across, sun_along;
} veil_quality_rung;
const veil_quality_rung* veil_quality_rung_of(veil_quality q); /* UNSET: the default rung */

/* Stage access for tests: GPU splat read back (veil_grid_voxels floats) and
 * GPU propagation read back (n_lights * voxels floats, light-major). */
veil_result veil_renderer_inject(veil_renderer* r, const veil_grid* g, const veil_particle* p, size_t n,
                                 float* density, veil_error* err);
veil_result veil_renderer_propagate(veil_renderer* r, const veil_grid* g, const float* density,
                                    const veil_opv_light* lights, int n_lights, const veil_opv_params* params,
                                    float* out, int* iterations, veil_error* err);

#endif
