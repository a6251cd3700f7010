/* veil — the order of the one-pass methods (private to propagate/): which
 * voxels each pass of an ordered sweep computes. The CPU and GPU versions
 * walk the same plan. */
#ifndef VEIL_OPV_PLAN_H
#define VEIL_OPV_PLAN_H

#include "opv.h"
#include "opv_blocks.glsl.h"

/* Gather sweep: pass m computes the voxels at up-wind Manhattan distance m.
 * Each pass enumerates the two axes other than `solve` over the grid and
 * solves for the coordinate on `solve` (two solutions for a point light). */
typedef struct veil__gather_plan {
    int first, last; /* shells m */
    int solve;       /* axis solved for */
} veil__gather_plan;

void veil__gather_plan_make(const veil_grid* g, const veil_index_light* l, veil__gather_plan* p);
/* Up-wind distance of voxel x along axis a (directional: from the light-facing face). */
int veil__gather_dist(const veil_grid* g, const veil_index_light* l, int a, int x);
/* The coordinate(s) on `solve` of the shell-m voxels with the other two
 * coordinates given in x (x[solve] ignored); returns how many (0..2). */
int veil__gather_solve(const veil_grid* g, const veil_index_light* l, const veil__gather_plan* p, int m,
                       const int x[3], int out[2]);

/* Semi-Lagrangian, point light: shell s = the voxels with integer
 * Chebyshev distance max_a |x_a - c_a| = s from the light's voxel c. A
 * voxel steps along the axis where that distance is largest (ties: the
 * larger real offset to the light), so it reads only voxels whose distance
 * on that axis is s-1 and whose other coordinates moved at most one voxel
 * toward the light: their distances stay at most what they were, or become
 * 1 from 0, below s for s >= 2. Hence within shell s the voxels
 * with k axes at distance s read only voxels with fewer: each shell runs in
 * three sub-passes, k = 1 (faces), 2 (edges), 3 (corners), each a list of
 * boxes. Shells 0 and 1 (the 27 voxels around the light, where stepping
 * toward the light can move away from c) are the near field, integrated
 * directly.
 * With characteristics k >= 2 voxels long the reads are simpler still: the
 * crossing point Q lies k voxels nearer on axis a, and on another axis b
 * |Q_b - S_b| = |e_b| (1 - k/|e_a|) <= |e_a| - k, so the voxels read have
 * distance at most s - k + 1 < s on every axis: all in earlier shells (a
 * path that ends within k voxels is integrated without reading any). */
/* VEIL_SL_MAX_BOXES (opv_blocks.glsl.h): the edges of a cube, the most boxes of a sub-pass. */

typedef struct veil__box {
    int lo[3], n[3]; /* voxels lo .. lo + n - 1, clipped to the grid */
} veil__box;

/* Shells s0..s1 (s0 >= 2) that meet the grid. */
void veil__sl_shell_range(const veil_grid* g, const veil_index_light* l, int* s0, int* s1);
/* The non-empty boxes of sub-pass k (1..3) of shell s; returns the count. */
int veil__sl_boxes(const veil_grid* g, const veil_index_light* l, int s, int k, veil__box out[VEIL_SL_MAX_BOXES]);
/* The near field (shells 0 and 1), clipped; returns 0 when empty. */
int veil__sl_near_box(const veil_grid* g, const veil_index_light* l, veil__box* out);
/* Sun: slices along the dominant axis, from the light-facing side. */
int veil__sl_sun_axis(const veil_index_light* l);
/* The box of slice k (0 = the light-facing side). */
void veil__sl_sun_slice(const veil_grid* g, const veil_index_light* l, int k, veil__box* out);

#endif
