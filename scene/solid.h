/* veil — the surfaces of a frame rendered elsewhere (veil fog) as the
 * lights and the light cache see them.
 *
 * A frame's depth says where the camera's rays meet a surface; the medium's
 * light also meets those surfaces: facades shadow the fog from the sun, and
 * the ground and walls absorb light that wanders through the fog (without
 * them the medium's light under veil fog was 1.09x Cycles' at night and 2.2x
 * by day: docs/accuracy.md, "veil fog against Cycles"). Nothing else in a
 * frame says where the surfaces are, so
 * the frame's depth is made a solid, the way screen-space methods read a
 * depth buffer:
 *
 *   - Each pixel's cone, from its distance d along the ray to d + t, is
 *     solid: t is how far its four neighbours' distances differ from its own
 *     (so neighbouring cones overlap on a continuous surface, however
 *     grazing), at least 2 voxels and at most VEIL_SOLID_MAX_THICKNESS
 *     voxels (where the depth jumps: an object's edge, not its back).
 *   - It is voxelised on a grid over the box of the pixels whose surface
 *     lies inside the medium's boxes (the others are left out: a surface
 *     outside the medium casts nothing either), at most VEIL_SOLID_MAX_DIM
 *     voxels an axis, then grown by one voxel on every side, so a path
 *     stepped at half a voxel cannot pass through it.
 *   - Voxels within VEIL_SOLID_LIGHT_CLEAR voxels of a point or spot light
 *     are cleared (a lamp on a wall would otherwise sit inside its own wall).
 *
 * Surfaces the camera does not see (behind it, off the frame, or hidden)
 * are not there; nor is what lies beyond the solid's thickness.
 *
 * What reads it:
 *   - the march (propagate/shaders/lit_medium.glsl, light_at): a shadow map
 *     per light, VEIL_SOLID_MAP^2 texels, the distance along the light's path
 *     to the first solid voxel (a sun: orthographic over the solid's box;
 *     a point or spot light: octahedral directions about it), read with four
 *     taps weighted bilinearly;
 *   - the light cache's photons (volumetric/shaders/cache_trace.comp): a
 *     photon whose path reaches a solid voxel is absorbed there; each cell
 *     keeps the part of it outside the solid, by which the march divides
 *     (volumetric/shaders/cache_resolve.comp).
 */
#ifndef VEIL_SOLID_H
#define VEIL_SOLID_H

#include <stddef.h>
#include <stdint.h>

#include "../core/result.h"
#include "../core/shared.glsl.h"
#include "camera.h"
#include "light.h"

#define VEIL_SOLID_MAX_DIM 256
#define VEIL_SOLID_MAX_THICKNESS 8
#define VEIL_SOLID_LIGHT_CLEAR 2

typedef struct veil_solid {
    int dims[3];            /* voxels an axis; 0: no solid (no finite depth inside the medium's boxes) */
    float origin[3], voxel; /* the grid's min corner and voxel edge (m) */
    unsigned char* voxels;  /* dims[0] dims[1] dims[2], x fastest: 1 solid, 0 not */
    size_t solid_count;
    /* shadow maps, one a light (in the order given), VEIL_SOLID_MAP^2 each, x fastest: the distance along
     * the light's path to the first solid (m; a sun: dot(x, travel); a point light: from the light),
     * VEIL_SOLID_FAR where none */
    int maps;
    float* depth;
    float rows[VEIL_MAX_LIGHTS][2][4]; /* a sun's map coordinates (0..1): dot(x, row.xyz) + row.w */
    /* a point counts as lit up to bias[l][0] + bias[l][1] r beyond the first solid (m; r: its distance along
     * the light's path) */
    float bias[VEIL_MAX_LIGHTS][2];
} veil_solid;

#define VEIL_SOLID_FAR 1e30f

/* The solid of a frame seen by camera c (width x height, distance along each
 * pixel's ray in m, +inf where nothing is hit), on a grid over the part of
 * its box inside [box_lo, box_hi], with the shadow maps of the n lights.
 * No finite depth in the box: dims all 0, no error. */
veil_result veil_solid_build(const veil_camera* c, int width, int height, const float* distance, const float box_lo[3],
                             const float box_hi[3], const veil_light* lights, int n, veil_solid* out, veil_error* err);
void veil_solid_free(veil_solid* s);

/* 1 when x lies in a solid voxel. */
int veil_solid_at(const veil_solid* s, const float x[3]);

/* The first solid along p + t d, t in [0, t_max] (d unit), stepped at half
 * a voxel as the photons step it; t_max (or more) when there is none. */
float veil_solid_hit(const veil_solid* s, const float p[3], const float d[3], float t_max);

/* What the march's shadow test gives at x for light l (0..1), as the shader
 * computes it (tests compare the two). */
float veil_solid_visibility(const veil_solid* s, const veil_light* l, int index, const float x[3]);

/* A hash of what the solid is made from (the volumetric stage's key). */
uint64_t veil_solid_key(uint64_t key, int width, int height, const float* distance);

#endif
