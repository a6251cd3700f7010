/* veil — optical-depth volumes (OPV): for each light S and voxel centre X,
 * D(X, S) = integral of density along the segment from X to S (density·m).
 * The optical depth per colour channel is tau = sigma_t * D, so one OPV
 * serves every channel of a single medium. Four lights share an RGBA
 * texture on the GPU (light 4t+c in channel c of texture t).
 *
 * Methods (each with a GPU version and a C version doing the same float
 * operations; the per-voxel updates are in opv_schemes.glsl.h):
 *  - VEIL_OPV_JACOBI: the published ping-pong gather. Each voxel takes the
 *    cosine-weighted mean over its up-wind axis neighbours of neighbour
 *    value + density along one voxel, iterated until a checked step changes
 *    nothing by more than `tolerance`. One voxel per step whatever the
 *    direction: in effect it measures Manhattan distance (56 % rms error in
 *    a homogeneous medium around a point light).
 *  - VEIL_OPV_JACOBI_CORRECTED: the same gather with the step length
 *    h |d|_2 / sum|d_a|, the expected Euclidean progress of a step.
 *  - VEIL_OPV_SWEEP: the corrected gather computed in dependency order: the
 *    voxels at Manhattan distance m from the light's voxel (for a sun, from
 *    the light-facing corner) depend only on distance m-1, so one pass over
 *    m reaches the Jacobi fixed point exactly (bit for bit).
 *  - VEIL_OPV_SEMI_LAGRANGIAN: follows the true light direction to the
 *    next voxel plane along its dominant axis and interpolates D there
 *    bilinearly (plus the trapezoid of the density on the way), in one
 *    ordered pass: slices along the sun's dominant axis, or Chebyshev
 *    shells around a point light's voxel (see opv_plan.h for why each
 *    voxel reads only voxels already done); the 27 voxels around a point
 *    light integrate their segment directly (VEIL_NEAR_SAMPLES points).
 *  - VEIL_OPV_LIGHT_SPACE: each sun (up to VEIL_MAX_SUNS) in its own
 *    light-space grid, one prefix sum down each column (sun_space.h);
 *    point and spot lights, further suns and sparse volumes as
 *    VEIL_OPV_SEMI_LAGRANGIAN. The functions of this header work on the
 *    EV's grid only: for them it is VEIL_OPV_SEMI_LAGRANGIAN; opv_set.h
 *    makes the light-space grids.
 * Spot lights propagate as point lights (the cone only weights the marcher).
 */
#ifndef VEIL_OPV_H
#define VEIL_OPV_H

#include "../core/result.h"
#include "../core/shared.glsl.h"
#include "../scene/light.h"
#include "../scene/scene.h"
#include "../volume/volume.h"
#include "sun_space.h"

typedef enum veil_opv_method {
    VEIL_OPV_DEFAULT = 0, /* resolves to VEIL_OPV_DEFAULT_METHOD */
    VEIL_OPV_JACOBI,
    VEIL_OPV_JACOBI_CORRECTED,
    VEIL_OPV_SWEEP,
    VEIL_OPV_SEMI_LAGRANGIAN,
    VEIL_OPV_LIGHT_SPACE,
    VEIL_OPV_METHOD_COUNT
} veil_opv_method;

/* The default, chosen from the measurements in docs/performance.md. */
#define VEIL_OPV_DEFAULT_METHOD VEIL_OPV_LIGHT_SPACE

/* The default made explicit. A frame resolves it once, in its plan
 * (frame/stages.h, veil_render_opts_resolve); inside propagate/ a method is
 * always resolved already (veil_opv_set_update and veil_opv_gpu refuse
 * VEIL_OPV_DEFAULT), except at the two doors tests and benchmarks use
 * directly, veil_opv_cpu and veil_opv_set_propagate_readback, which
 * resolve it themselves. */
static inline veil_opv_method veil_opv_method_resolve(veil_opv_method m)
{
    return m == VEIL_OPV_DEFAULT ? VEIL_OPV_DEFAULT_METHOD : m;
}

/* "jacobi", "jacobi-corrected", "sweep", "semi-lagrangian", "light-space" ("default" for 0) */
const char* veil_opv_method_name(veil_opv_method m);
/* 1 on success; names as above */
int veil_opv_method_parse(const char* name, veil_opv_method* out);

/* The lights work in voxel index space: veil_index_light, made from a
 * scene's veil_light by veil_light_to_index() (scene/light.h). */

/* Jacobi steps between convergence checks (each check is a GPU read-back). */
#define VEIL_JACOBI_CHECK_EVERY 8

typedef struct veil_opv_params {
    veil_opv_method method;
    float tolerance;    /* Jacobi: stop when a checked step changes no D by more than this (density·m); 0: exact fixed point */
    int max_iterations; /* Jacobi: 0 = dims.x + dims.y + dims.z + 1 (enough for the exact fixed point) */
    float exit_steps;   /* semi-Lagrangian: integrate directly when the crossing point would lie within
                           this many voxels of the path's end; 0 = VEIL_SL_DEFAULT_EXIT_STEPS, >= 1 */
    int characteristic; /* semi-Lagrangian: voxels between interpolations (1, or 2 and more);
                           0 = VEIL_SL_DEFAULT_CHARACTERISTIC */
    float sun_across;   /* light-space: node spacing across the light (voxels); 0 = VEIL_SUN_DEFAULT_ACROSS */
    float sun_along;    /* ... along the light (voxels); 0 = VEIL_SUN_DEFAULT_ALONG */
    int sun_panels;     /* ... Simpson panels per step along it; 0 = VEIL_SUN_DEFAULT_PANELS */
    double sun_bytes;   /* ... the most GPU memory all of a scene's grids may take (bytes); 0: no limit
                           beyond VEIL_SUN_MAX_NODES (frame/ gives what the device's budget leaves) */
} veil_opv_params;

/* Chosen from the measurements in docs/performance.md. */
#define VEIL_SL_DEFAULT_EXIT_STEPS 8.0f
#define VEIL_SL_DEFAULT_CHARACTERISTIC 16

static inline float veil_opv_exit_steps(const veil_opv_params* p)
{
    return p->exit_steps >= 1.0f ? p->exit_steps : VEIL_SL_DEFAULT_EXIT_STEPS;
}

static inline int veil_opv_characteristic(const veil_opv_params* p)
{
    return p->characteristic >= 1 ? p->characteristic : VEIL_SL_DEFAULT_CHARACTERISTIC;
}

static inline float veil_opv_sun_across(const veil_opv_params* p)
{
    return p->sun_across > 0.0f ? p->sun_across : VEIL_SUN_DEFAULT_ACROSS;
}
static inline float veil_opv_sun_along(const veil_opv_params* p)
{
    return p->sun_along > 0.0f ? p->sun_along : VEIL_SUN_DEFAULT_ALONG;
}
/* A point or spot light's grid (the perspective form of sun_space.h):
 * columns at least VEIL_POINT_ACROSS_SCALE times a sun's spacing apart at
 * the far side of the box (finer nearer the light), planes half as far
 * apart as a sun's (its stretch back runs up to sqrt(3) times the planes'
 * spacing), and wider still where the columns' length in the box would
 * exceed veil_opv_point_work voxels per voxel of the EV: VEIL_POINT_WORK at
 * the default spacing, scaled with the rung's work (the inverse square of
 * its spacing). At 5 the prefix sums cost about what the semi-Lagrangian
 * pass they replace does: measured equal at 4.6 (the demo's lights, inside
 * its box) and 6.7 (the shared smoke's, beside it) columns' voxels a voxel
 * (docs/performance.md, "Point and spot lights in light-space grids"). */
#define VEIL_POINT_ACROSS_SCALE 1.4f
#define VEIL_POINT_WORK 5.0
static inline float veil_opv_point_across(const veil_opv_params* p)
{
    return VEIL_POINT_ACROSS_SCALE * veil_opv_sun_across(p);
}
static inline double veil_opv_point_work(const veil_opv_params* p)
{
    double r = (double)VEIL_SUN_DEFAULT_ACROSS / veil_opv_sun_across(p);
    return VEIL_POINT_WORK * r * r;
}
static inline float veil_opv_point_along(const veil_opv_params* p)
{
    return 0.5f * veil_opv_sun_along(p);
}
static inline int veil_opv_sun_panels(const veil_opv_params* p)
{
    return p->sun_panels > 0 ? p->sun_panels : VEIL_SUN_DEFAULT_PANELS;
}

int veil_opv_exact_iterations(const veil_grid* g);

/* C version of every method: out holds n_lights * voxels floats,
 * light-major, x fastest. *iterations: Jacobi steps, or passes (dispatches
 * on the GPU) of an ordered method. */
veil_result veil_opv_cpu(const veil_grid* g, const float* rho, const veil_index_light* lights, int n_lights,
                         const veil_opv_params* params, float* out, int* iterations, veil_error* err);

#endif
