/* veil — the std140 uniform blocks of the optical-depth passes
 * (propagate/shaders/), declared once for the C that fills them
 * (opv_gpu.c, opv_set.c) and the shaders that read them (each pulls this
 * file in with //@include). Every pass binds its block at
 * VEIL_UBO_PROPAGATE (core/shared.glsl.h) for its dispatches only, from a
 * buffer its owner keeps (veil_opv_programs, veil_opv_set); passes that
 * follow one another (a sweep's shells, a sparse volume's levels) have a
 * block each in one buffer (gpu/pass_run.h).
 *
 * Only 16-byte members, so C and GLSL lay them out alike; the C side
 * checks each block's size and offsets below.
 * Index coordinates as in propagate/opv.h (voxel i's centre at i) unless a
 * block says otherwise; D in density m.
 */
#ifndef VEIL_OPV_BLOCKS_GLSL_H
#define VEIL_OPV_BLOCKS_GLSL_H

#ifndef VEIL_GLSL
#include <stddef.h>

#include "../core/shared.glsl.h"
#endif

/* The most boxes of one semi-Lagrangian sub-pass: the edges of a cube
 * (propagate/opv_plan.h). */
#define VEIL_SL_MAX_BOXES 12

/* One Jacobi step (propagate_jacobi.comp) for up to four lights, light c
 * in channel c. The lights are veil_index_light (scene/light.h). */
VEIL_STRUCT_BEGIN(veil_jacobi_block)
    VEIL_IV4(dims);    /* xyz: the EV's voxels; w: lights in this texture, 1..4 */
    VEIL_IV4(mode);    /* x: 1: the corrected step length, 0: one voxel a step (published); yzw: - */
    VEIL_V4(params);   /* x: voxel edge (m); y: tolerance, a checked step that moves no D by more is
                          the last (density m); zw: - */
    VEIL_V4(light[4]); /* xyz: veil_index_light.v; w: - */
    VEIL_IV4(cell[4]); /* xyz: veil_index_light.c; w: its type, VEIL_LIGHT_POINT or VEIL_LIGHT_DIRECTIONAL */
VEIL_STRUCT_END(veil_jacobi_block)

/* Voxels lo .. lo + n - 1 of one box of a semi-Lagrangian pass. */
VEIL_STRUCT_BEGIN(veil_sweep_box)
    VEIL_IV4(lo); /* xyz: the first voxel; w: - */
    VEIL_IV4(n);  /* xyz: voxels per axis; w: - */
VEIL_STRUCT_END(veil_sweep_box)

/* One pass of an ordered method (propagate_sweep.comp) for one light:
 * each pass of a light has its own copy, in one buffer (gpu/pass_run.h). */
VEIL_STRUCT_BEGIN(veil_sweep_block)
    VEIL_IV4(dims);   /* xyz: the EV's voxels; w: the channel written, 0..3 */
    VEIL_V4(params);  /* x: voxel edge (m); y: exit steps (veil_opv_exit_steps); zw: - */
    VEIL_V4(light);   /* xyz: veil_index_light.v; w: - */
    VEIL_IV4(cell);   /* xyz: veil_index_light.c; w: its type */
    VEIL_IV4(pass);   /* x: 0: a gather shell, 1: the semi-Lagrangian near field (box 0), 2: semi-Lagrangian
                         boxes; y: the gather's Manhattan shell; z: the axis it solves for; w: voxels between
                         interpolations (veil_opv_characteristic) */
    veil_sweep_box boxes[VEIL_SL_MAX_BOXES]; /* modes 1 and 2: work group z takes box z */
VEIL_STRUCT_END(veil_sweep_block)

/* One dispatch over a sparse volume (propagate_sparse.comp): one light, the
 * bricks of one level (at most 65535 of them). Sparse index coordinates: voxel i's centre at i + 0.5
 * (volume/shaders/sparse_common.glsl). */
VEIL_STRUCT_BEGIN(veil_sparse_od_block)
    VEIL_V4(light); /* xyz: a point light's position, or a sun's unit vector toward it; w: its type */
    VEIL_IV4(pass); /* x: the channel written, 0..3; y: this pass's first entry of the slot list; zw: - */
VEIL_STRUCT_END(veil_sparse_od_block)

/* The prefix sums of a light-space grid (sun_prefix.comp,
 * propagate/sun_space.h): a sun's grid, or one face of a point light's
 * (veil_sun_space_columns: column (a, b) from origin + a axis[0] + b axis[1],
 * step axis[2] + a spread[0] + b spread[1]). */
VEIL_STRUCT_BEGIN(veil_sun_block)
    VEIL_IV4(dims);    /* xyz: the EV's voxels; w: Simpson panels per step along c (the least) */
    VEIL_IV4(nodes);   /* xyz: columns along a, b and nodes along c written; w: bit 0: skip the panels of
                          empty occupancy bricks, bit 1: perspective (a step per column, panels to match) */
    VEIL_V4(origin);   /* xyz: node (0, 0, 0); w: metres per node step along c (a sun's) */
    VEIL_V4(axis[3]);  /* xyz: the index-space steps, as above; w: - */
    VEIL_V4(spread[2]); /* xyz: as above; [0].w: the voxel edge (m) */
    VEIL_IV4(place);   /* x: the first plane written; yz: the columns the dispatch covers (those past
                          nodes.xy get 0); w: - */
VEIL_STRUCT_END(veil_sun_block)

#ifndef VEIL_GLSL
/* std140 as the shaders see it: every member 16 bytes, arrays of them
 * 16 bytes a stride, so each C offset is the GLSL one. */
_Static_assert(sizeof(veil_jacobi_block) == 16 * 11, "veil_jacobi_block: std140 size");
_Static_assert(offsetof(veil_jacobi_block, cell) == 16 * 7, "veil_jacobi_block: std140 offset of cell");
_Static_assert(sizeof(veil_sweep_box) == 32, "veil_sweep_box: std140 size");
_Static_assert(sizeof(veil_sweep_block) == 16 * 5 + 32 * VEIL_SL_MAX_BOXES, "veil_sweep_block: std140 size");
_Static_assert(offsetof(veil_sweep_block, pass) == 16 * 4, "veil_sweep_block: std140 offset of pass");
_Static_assert(offsetof(veil_sweep_block, boxes) == 16 * 5, "veil_sweep_block: std140 offset of boxes");
_Static_assert(sizeof(veil_sparse_od_block) == 32, "veil_sparse_od_block: std140 size");
_Static_assert(offsetof(veil_sparse_od_block, pass) == 16, "veil_sparse_od_block: std140 offset of pass");
_Static_assert(sizeof(veil_sun_block) == 16 * 9, "veil_sun_block: std140 size");
_Static_assert(offsetof(veil_sun_block, place) == 16 * 8, "veil_sun_block: std140 offset of place");
#endif

#endif
