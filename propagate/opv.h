/* veil — optical-depth volumes (OPV): for each light S and voxel centre X,
 * D(X, S) = integral of density along the segment from X to S (density·m).
 * The optical depth per colour channel is tau = sigma_t * D, so one OPV
 * serves every channel of a single medium. Four lights share an RGBA
 * texture on the GPU (light 4t+c in channel c of texture t).
 *
 * The scheme here is the published ping-pong gather (Jacobi): each voxel
 * takes the cosine-weighted mean, over its up-wind axis neighbours (those
 * toward the light), of neighbour value + density along the step, where the
 * step is one voxel whatever the light direction (so the path measured is
 * Manhattan, not Euclidean: a known error that is measured, not hidden).
 * Details of this implementation:
 *  - the density along a step is the trapezoid h (rho(X) + rho(N)) / 2;
 *    a neighbour outside the grid holds D = 0 and the step to the box face
 *    is h/2 with rho(X);
 *  - a point light's own voxel (|d_a| <= 1/2 voxel on every axis) gets the
 *    straight segment rho(X) |X - S|; an axis with |d_a| <= 1/2 has no
 *    up-wind neighbour;
 *  - directional lights use the constant direction toward the light.
 * From D = 0 the iteration reaches its fixed point exactly after at most
 * dims.x + dims.y + dims.z + 1 steps (each dependency moves one voxel
 * toward the light); it stops earlier when no value changed by more than
 * `tolerance` in a checked step.
 */
#ifndef VEIL_OPV_H
#define VEIL_OPV_H

#include "../core/result.h"
#include "../core/shared.glsl.h"
#include "../io/scene.h"
#include "../volume/volume.h"

/* A light in voxel index space (voxel i's centre at coordinate i). */
typedef struct veil_opv_light {
    int type;   /* VEIL_LIGHT_POINT or VEIL_LIGHT_DIRECTIONAL */
    float v[3]; /* point: position (index units); directional: unit vector toward the light */
} veil_opv_light;

void veil_opv_light_from_world(const veil_grid* g, const veil_light* l, veil_opv_light* out);

/* Jacobi steps between convergence checks (each check is a GPU read-back). */
#define VEIL_JACOBI_CHECK_EVERY 8

typedef struct veil_opv_params {
    float tolerance;    /* stop when a checked step changes no D by more than this (density·m); 0: run to the exact fixed point */
    int max_iterations; /* 0: dims.x + dims.y + dims.z + 1 (exact) */
} veil_opv_params;

int veil_opv_exact_iterations(const veil_grid* g);

/* CPU reference of the GPU scheme: out holds n_lights * voxels floats,
 * light-major, x fastest. *iterations receives the steps run. */
veil_result veil_opv_jacobi_cpu(const veil_grid* g, const float* rho, const veil_opv_light* lights,
                                int n_lights, const veil_opv_params* params, float* out,
                                int* iterations, veil_error* err);

#endif
