/* veil — a light, and the one place it is converted. A scene holds its
 * lights as veil_light (io/scene.h reads them from a scene file,
 * volume/emission_lights.h makes them from the medium's emission); every
 * other shape is made from it here:
 *  - veil_light_to_gpu(): the march's std140 light (veil_gpu_light in
 *    core/shared.glsl.h), world units, the spot's cone as cosines;
 *  - veil_light_to_index(): a veil_index_light, the light in the voxel
 *    index space of a grid, which the optical-depth propagation works in
 *    (propagate/opv.h; its shaders take it into their std140 blocks).
 *
 * Units: metres, W/sr for point and spot intensity, W/m^2 for directional
 * irradiance, degrees for the spot's cone; index space: voxel i's centre at
 * coordinate i. No memory is owned.
 */
#ifndef VEIL_LIGHT_H
#define VEIL_LIGHT_H

#include "../core/shared.glsl.h"

/* VEIL_LIGHT_POINT, VEIL_LIGHT_DIRECTIONAL or VEIL_LIGHT_SPOT (core/shared.glsl.h)
 * (the shaders use the same values); at most VEIL_MAX_LIGHTS lights. */
typedef int veil_light_type;

typedef struct veil_light {
    veil_light_type type;
    float position[3];  /* point, spot: m */
    float direction[3]; /* directional, spot: unit vector in which light travels (spot: its axis) */
    float color[3];     /* point, spot: intensity W/sr on the axis; directional: irradiance W/m^2 */
    /* spot: full intensity within inner_angle_deg of the axis, none beyond
     * outer_angle_deg, veil_spot_falloff() between; 0 <= inner < outer <= 180 */
    float inner_angle_deg, outer_angle_deg;
    /* point: 1/r^2 is floored at radius^2 (m; 0 for a scene's lights: a point;
     * the medium's emission as lights, volume/emission_lights.h, has a size) */
    float radius;
} veil_light;

/* A light in the voxel index space of a grid (voxel i's centre at
 * coordinate i), as the optical-depth propagation sees it: spot lights are
 * point lights there (the cone only weights the march), colour is gone. */
typedef struct veil_index_light {
    int type;      /* VEIL_LIGHT_POINT (spot lights too) or VEIL_LIGHT_DIRECTIONAL */
    float v[3];    /* point: position (index units); directional: unit vector toward the light */
    int c[3];      /* point: the light's voxel, floor(v + 1/2), clamped to at most VEIL_INDEX_LIGHT_FAR
                      voxels beyond the grid (light.c says why that changes nothing) */
    int elsewhere; /* 1: its optical depth is kept in a light-space grid; the ordered methods leave its
                      channel 0 (propagate/opv_gpu.c; the Jacobi steps compute all four channels anyway).
                      veil_light_to_index sets 0; propagate/opv_set.c sets it */
} veil_index_light;

/* How far beyond the grid a point light's voxel c may lie on each axis
 * (voxels, 2^20): sums of three distances to it stay far inside int. */
#define VEIL_INDEX_LIGHT_FAR 1048576

/* The spot's cone as cosines: cos(inner_angle_deg), cos(outer_angle_deg),
 * in float, as the march and the path tracer take them. */
float veil_light_cos_inner(const veil_light* l);
float veil_light_cos_outer(const veil_light* l);

/* l as the march's uniform block holds it (core/shared.glsl.h says what
 * each component is). */
void veil_light_to_gpu(const veil_light* l, veil_gpu_light* out);

/* l in the index space of a grid of `dims` voxels whose min corner is at
 * `origin` (m), voxels `voxel` m wide (volume/volume.h's veil_grid:
 * g->dims, g->origin, g->voxel). */
void veil_light_to_index(const veil_light* l, const int dims[3], const float origin[3], float voxel,
                         veil_index_light* out);

#endif
