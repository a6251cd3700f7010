/* veil — the sparse extinction volume: only the bricks that hold density.
 *
 * A VDB's bounding box can be far larger than its active voxels (puffs of
 * smoke scattered over a 4096^3 index box hold well under 1 % of it). The
 * dense EV would hold every voxel of the box; the sparse one keeps the
 * VEIL_BRICK^3 bricks whose interpolation cell holds density:
 *
 * - Brick b covers the sample points q (index coordinates, voxel i's centre
 *   at i + 0.5) with floor((q - 0.5) / 8) = b: its trilinear stencils read
 *   voxels 8b .. 8b + 8 per axis. So a brick is kept when any of those
 *   9^3 voxels is not 0 (its own 8^3, or the first voxel of a brick above it
 *   on some axis), and every sample point in a brick that is not kept is 0
 *   exactly: skipping it changes nothing.
 * - Each kept brick (a slot) is stored in an atlas as 9^3 texels (its 8^3
 *   voxels and that apron), so the GPU's trilinear filter at (slot corner
 *   + q - 0.5 - 8b + 0.5) reads exactly the dense field's 8 voxels.
 * - A brick is found through two tables: a top table over nodes of
 *   VEIL_SPARSE_NODE^3 bricks (0: the node is empty, else node + 1) and one
 *   table per non-empty node (0: the brick is empty, else slot + 1). An
 *   empty node lets a ray skip 128 voxels at once, an empty brick 8.
 *
 * Values are the VDB grids' voxels copied (times each source's
 * density_scale, summed where grids overlap), and the emission of their
 * emission and temperature grids per voxel as the dense path forms it, in
 * an rgba atlas of the same layout (a brick is kept where it holds density
 * or emission). A sparse volume needs every grid of the scene on one
 * lattice (the same axis-aligned cubic voxel and whole-voxel offsets), no
 * particles, and a temperature grid only with one vdb source; anything else
 * is dense (volume/scene_volume.h says which and why).
 */
#ifndef VEIL_SPARSE_H
#define VEIL_SPARSE_H

#include <stddef.h>
#include <stdint.h>

#include "../core/result.h"
#include "../core/shared.glsl.h"
#include "volume.h"

struct veil_scene_volume;

/* A grid at most this many voxels a side (its top table then holds at
 * most 256^3 entries, 64 MiB). */
#define VEIL_SPARSE_MAX_SIDE (1 << 15)

typedef struct veil_sparse {
    veil_grid grid;       /* the dense grid it stands for */
    int bricks[3];        /* ceil(dims / 8) */
    int top[3];           /* ceil(bricks / VEIL_SPARSE_NODE) */
    uint32_t* top_table;  /* top[0] top[1] top[2] entries, x fastest: 0 or node + 1 */
    uint32_t* nodes;      /* node_count * VEIL_SPARSE_NODE_BRICKS entries, x fastest: 0 or slot + 1 */
    size_t node_count;
    size_t count;         /* slots (bricks kept) */
    int32_t* coords;      /* 4 ints a slot: its brick x, y, z, and 0 */
    int atlas[3];         /* the atlas, in bricks */
    float* texels;        /* the atlas: 9 atlas[0] x 9 atlas[1] x 9 atlas[2] floats, x fastest */
    size_t voxels;        /* non-zero voxels copied */
    float* emission_texels; /* with emission: 4 floats a texel of the atlas (eps rgb, 0), else NULL */
    float* emitters;      /* the emitting voxels: 6 floats each, centre (m) and eps dV (W/sr) */
    size_t emitter_count;
} veil_sparse;

/* Builds the sparse volume of v's VDB grids on v->grid (v->sparse set).
 * The atlas is at most max_side texels a side (GL_MAX_3D_TEXTURE_SIZE);
 * more bricks than it holds is VEIL_ERR_LIMIT with the numbers. */
veil_result veil_sparse_build(const struct veil_scene_volume* v, int max_side, veil_sparse* out, veil_error* err);
void veil_sparse_free(veil_sparse* s); /* accepts a zeroed one */

/* The atlas's texels per axis (9 atlas[a]). */
void veil_sparse_atlas_texels(const veil_sparse* s, int out[3]);

/* Bytes the GPU holds for it: the atlas, the tables and the slots' bricks
 * (optical depths add 16 bytes a texel per 4 lights). */
size_t veil_sparse_bytes(const veil_sparse* s);

/* Slot + 1 of brick b, 0 when it is not kept (or outside the grid). */
uint32_t veil_sparse_slot(const veil_sparse* s, const int b[3]);

/* The density at index point q (the C twin of the shaders' lookup:
 * volume/shaders/sparse_common.glsl); 0 in bricks not kept. */
float veil_sparse_sample(const veil_sparse* s, const float q[3]);

/* The shaders' uniform block. */
void veil_sparse_block_fill(const veil_sparse* s, veil_sparse_block* out);

#endif
