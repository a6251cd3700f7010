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
#include "../scene/light.h"
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

/* ---- the census: what the gather will make, counted before it starts ----
 *
 * The gather visits every non-zero voxel of the grids, an active tile's
 * voxels one by one, and makes a brick for each 8^3 block they fall in: a
 * 594-byte file whose one active tile covers a 4096^3 box asks for 512^3
 * bricks (275 GB), and grew ~90 MB/s until the machine ran out. The census
 * counts them first from the trees, a tile as its box (veil_vdb_each_box):
 * the distinct bricks of the leaves' voxels and every brick the tiles
 * cover, of each density and emission grid (a temperature grid adds to the
 * bricks the others keep and makes none; its tiles' voxels are counted,
 * the gather visits them too). That is the most the gather makes before
 * the dilation (volume/sparse.c, dilate) keeps some bricks below them; the
 * dilation adds at most 7 a brick, in practice a few per cent. It is over
 * the cap below too when the voxels to visit one by one (leaves' and
 * tiles', every grid) are more than the cap's bricks hold.
 *
 * VEIL_SPARSE_MAX_BRICKS: more than that is refused before anything is
 * expanded. With a light, the work budget below refuses far fewer: each
 * brick sends 729 texel rays to each light, and no scene measured averaged
 * under 12 units a ray (its own brick's samples), so 2^18 bricks are
 * 2^18 x 729 x 12 x VEIL_SPARSE_UNIT_SECONDS = 92 s, over twice the
 * budget. Without one (nothing to propagate), the cap is what bounds the
 * gather and the atlas: 2 KiB of values, 2.9 KiB of atlas and ~60 bytes of
 * coordinates and hash a brick, 1.3 GB at the cap (5 times that with an
 * emission grid, whose rgb rides in the same bricks), before ev.c weighs
 * the textures against the device's memory; and the census's own tables
 * (a 16-byte key at half load, a 16-byte coordinate: 12 MiB). Real
 * volumes keep far fewer: the shared smoke.vdb 3 211 bricks, the bench's
 * 10^6-voxel plume 2 617, tests' 4096^3 puffs 694: 80 times and more
 * under the cap. */
#define VEIL_SPARSE_MAX_BRICKS ((size_t)1 << 18)

typedef struct veil_sparse_census {
    uint64_t leaves;      /* leaf nodes with a non-zero active voxel, every grid */
    uint64_t leaf_voxels; /* their non-zero active voxels */
    uint64_t tiles;       /* active tiles of a non-zero value */
    double tile_voxels;   /* the voxels they stand for */
    double bricks;        /* the bricks the gather makes, at most: the leaves' distinct ones and the tiles' (counted
                             up to the cap: past it, at least this many) */
    int over;             /* 1: over VEIL_SPARSE_MAX_BRICKS, in bricks or voxels to visit (coords, lookups NULL) */
    const char* worst;    /* the file whose grid the count was in when it went over (owned by the volume) */
    /* when not over: the bricks themselves, for the work estimate */
    size_t count;         /* distinct bricks (count <= bricks) */
    int32_t* coords;      /* 4 ints a brick (x, y, z, 0), in no particular order */
    int brick_dims[3];    /* bricks a side: ceil(dims / 8) */
    int top[3];           /* nodes a side: ceil(brick_dims / VEIL_SPARSE_NODE) */
    int dims[3];          /* the grid's voxels */
    uint64_t* keys;       /* the set of bricks (open addressing, packed brick + 1; 0: empty) */
    size_t key_cap;       /* a power of two */
    uint8_t* node_bits;   /* a bit a node: it holds a brick */
} veil_sparse_census;

/* The census of v's grids on v->grid (v->sparse). VEIL_ERR_OOM only for
 * its own tables; over the cap is not an error here (out->over), callers
 * refuse with veil_sparse_census_check. */
veil_result veil_sparse_census_of(const struct veil_scene_volume* v, veil_sparse_census* out, veil_error* err);
void veil_sparse_census_free(veil_sparse_census* c); /* accepts a zeroed one */
/* VEIL_ERR_LIMIT with the numbers when c is over VEIL_SPARSE_MAX_BRICKS. */
veil_result veil_sparse_census_check(const veil_sparse_census* c, veil_error* err);

/* ---- the work of a frame, estimated from the census ----------------------
 *
 * What the GPU spends on a sparse volume is its rays, not its bytes: 120 k
 * voxels in 2 000 leaves scattered over a 16384^3 box (3 MB) took 52 s of
 * CPU (70-110 s on this 2-core machine) for a 64x48 frame, most of it the
 * optical depth's ~3 400 passes whose texels each march to the box's edge
 * (few kept bricks to stop at), and the escape field's 14 rays a point.
 * So the estimate walks the shaders' own loops on the census's bricks: for
 * VEIL_SPARSE_ESTIMATE_BRICKS of them, spread over the list, one ray from
 * the brick's middle to each light (propagate_sparse.comp: its own brick
 * at VEIL_SPARSE_OD_STEP, then a step a region to the first kept brick)
 * and the 14 rays of escape.comp (a step a region, a sample a voxel in
 * kept bricks, to the box's edge). A unit is a step or a sample; the
 * frame's work is
 *   PASS_SECONDS x passes + UNIT_SECONDS x (texel rays x their mean units
 *                                           + escape rays x theirs)
 * with the passes counted as propagate/opv_set.c orders them
 * (veil_opv_sparse_passes), 729 texel rays a brick a light, and 27 x 14
 * escape rays a brick (volumetric/volumetric.h). Over MAX_SECONDS it is
 * refused with the numbers, before the gather.
 *
 * The constants are CPU time of the reference driver (llvmpipe on this
 * project's 2-core machine; CPU time, since wall time there depends on
 * what else runs), measured per stage (a render less one without the
 * volumetric field, less one without lights) over ten sparse scenes: the
 * shared smoke.vdb with 2 lights (4.4 s measured, 5.4 s estimated) and 16
 * lights (16.4 s whole render, 23.6 s estimated), the bench's 10^6-voxel
 * plume (2.6 / 3.3 s), tests' puffs (1.2 / 1.1 s), the pyro plume with its
 * 8 emission lights (1.6 s whole render / 0.9 s), and 200 to 2 000 leaves
 * scattered over 4096^3 and 16384^3 boxes under a sun and a point light
 * (3.2 to 16.2 s / 4.5 to 20.3 s): a unit costs 2.5e-8 to 4.5e-8 s, and
 * the estimate lands at 0.9 to 1.7 times the measure (over it but for the
 * puffs; the emission's lights are guessed at the grid's middle, before
 * the gather makes them). PASS_SECONDS: the
 * puffs' 144 passes took 0.3 s beyond their rays (a dispatch and a barrier
 * each on llvmpipe). The budget, 40 s of one core (about 20 s on the
 * machine's two), is the splat's half a minute (volume/volume.h); real
 * volumes are far under it (the smoke with 2 lights 7 times, with 16
 * lights 1.7 times, the plume 12, the puffs 36), and the scattered 16384^3
 * grid above estimates 78 s: refused, in 0.3 s and 200 MB. The estimate
 * itself walks at most 32 x (lights + 14) rays. */
#define VEIL_SPARSE_ESTIMATE_BRICKS 32
#define VEIL_SPARSE_PASS_SECONDS 2e-3
#define VEIL_SPARSE_UNIT_SECONDS 4e-8
#define VEIL_SPARSE_MAX_SECONDS 40.0

typedef struct veil_sparse_work {
    double bricks;        /* the census's bricks (before the dilation) */
    int dims[3];          /* the grid's voxels */
    int lights;           /* lights whose optical depth is marched (the emission's included) */
    double passes;        /* optical-depth passes, all lights */
    double od_rays;       /* texel rays to the lights: 729 a brick a light */
    double od_units;      /* ... their mean units */
    double escape_rays;   /* escape.comp's rays (0 without the escape field) */
    double escape_units;  /* ... their mean units */
    double seconds;       /* veil_sparse_work_check: the estimate, CPU seconds of the reference driver */
} veil_sparse_work;

/* The mean units of a texel's ray to light l (in the grid's index space,
 * veil_light_to_index), and of an escape-field ray; 0 over the cap. */
double veil_sparse_od_units(const veil_sparse_census* c, const veil_index_light* l);
double veil_sparse_escape_units(const veil_sparse_census* c);

/* Sets w->seconds; VEIL_ERR_LIMIT with the numbers over the budget. */
veil_result veil_sparse_work_check(veil_sparse_work* w, veil_error* err);

/* Builds the sparse volume of v's VDB grids on v->grid (v->sparse set).
 * The atlas is at most max_side texels a side (GL_MAX_3D_TEXTURE_SIZE);
 * more bricks than it holds is VEIL_ERR_LIMIT with the numbers. */
veil_result veil_sparse_build(const struct veil_scene_volume* v, int max_side, veil_sparse* out, veil_error* err);

/* Internal to sparse.c and sparse_census.c: a brick's key in their hashes
 * (21 bits an axis, bricks < 2^21 a side; 0 means empty), and the index offset of a VDB's
 * voxels on the sparse grid of v (VEIL_ERR_INVALID when they are off it). */
struct veil_vdb;
static inline uint64_t veil__sparse_pack(const int b[3])
{
    return ((uint64_t)(uint32_t)b[0] | (uint64_t)(uint32_t)b[1] << 21 | (uint64_t)(uint32_t)b[2] << 42) + 1;
}
veil_result veil__sparse_offset_of(const struct veil_scene_volume* v, const struct veil_vdb* vdb, int off[3],
                                   veil_error* err);
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
