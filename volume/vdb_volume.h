/* veil — an OpenVDB grid (io/vdb.h) resampled onto the extinction volume's
 * axis-aligned grid (volume/volume.h).
 *
 * The VDB's density field is the trilinear interpolation of its samples at
 * integer index points, mapped to world by its affine transform; it is 0
 * beyond the neighbours of the outermost active voxels. Its mass (the
 * integral of density over space, in density x m^3) is exactly
 * sum(values) x |det M| for such a field, since each trilinear "hat"
 * integrates to one voxel's volume.
 *
 * veil_vdb_to_grid sets each target voxel to the mean of that field over
 * the voxel's cube (a box filter) when the target's voxels are larger than
 * the VDB's (reducing), and to the field at the voxel's centre (k = 1: the
 * trilinear field, no extra blur) when they are not (the same size under a
 * rotation, or enlarging). With the box filter sum(density) x voxel^3 equals the
 * VDB's mass whenever the target's cubes cover the field's support
 * (veil_vdb_world_support). The mean is estimated with k^3 samples on a
 * regular k x k x k lattice at the centres of the cube's sub-cells
 * (midpoint rule), k = ceil(VEIL_VDB_SAMPLES_PER_VOXEL x target voxel /
 * smallest VDB voxel edge), at least 1, at most VEIL_VDB_MAX_SUPERSAMPLE.
 * Over the whole target the samples form one lattice of spacing s =
 * voxel / k; when s is h/m for a whole m (VDB voxel edge h, axis-aligned
 * VDB, e.g. targets 2x, 2.5x, 3x, 4x coarser), the sum of a hat over such a
 * lattice is exactly m for any offset, so the mass is exact up to float
 * rounding; otherwise the error is an aliasing term (the field's spectrum
 * near the VDB lattice's frequencies, weighted by sinc^2 of the offset),
 * small for smooth fields and measured by tests/io/test_vdb.c.
 *
 * The samples interpolate the VDB's values read into a dense array over the
 * index box they reach (at most VEIL_VDB_MAX_DENSE_VOXELS, else
 * VEIL_ERR_LIMIT with the numbers), one thread per core over target slabs;
 * each target voxel is summed by one thread in a fixed order, so the result
 * does not depend on the thread count.
 *
 * Exact copy: when the transform is a uniform scale (equal to the target's
 * voxel) plus a translation that puts the target's voxel centres on index
 * points (within VEIL_VDB_ALIGN_TOL voxel), the values are copied. That is
 * point sampling rather than the box filter, and keeps the mass exactly as
 * well (each value stands for one voxel of the same volume).
 *
 * The caller owns `density`; the dense copy of the VDB values is allocated
 * and freed inside veil_vdb_to_grid, after its size has been checked.
 */
#ifndef VEIL_VDB_VOLUME_H
#define VEIL_VDB_VOLUME_H

#include <stddef.h>

#include "../core/result.h"
#include "../io/vdb.h"
#include "volume.h"

/* Samples of the box filter per VDB voxel edge: 2 makes the sample lattice
 * a whole refinement of the VDB's for the common 1x..8x ratios (see above). */
#define VEIL_VDB_SAMPLES_PER_VOXEL 2
/* At most 16^3 = 4096 samples per target voxel (16x downsampling at the
 * full rate; beyond, fewer samples per VDB voxel). */
#define VEIL_VDB_MAX_SUPERSAMPLE 16
/* At most this many field samples per resampling (about a minute on two
 * cores at ~70 M samples/s): k is lowered to fit, and a target/VDB overlap
 * too large even at k = 1 is refused with the numbers. */
#define VEIL_VDB_MAX_SAMPLES ((size_t)1 << 32)
/* At most this many VDB values read densely for the box filter: 2^30
 * floats, 4 GiB, a 1024^3 index box. */
#define VEIL_VDB_MAX_DENSE_VOXELS ((size_t)1 << 30)
/* Target centres within this many voxels of index points count as on them
 * (float grid origins carry ~1e-7 relative rounding). */
#define VEIL_VDB_ALIGN_TOL 1e-3

/* The world AABB (m) of the active voxels' sample points (the 8 corners of
 * the index bbox under the transform). The field reaches one VDB voxel
 * beyond it, fading to 0: a grid fitted to this box drops that fade.
 * VEIL_ERR_INVALID for an empty grid (check veil_vdb_index_bbox first) or a
 * non-affine transform. */
veil_result veil_vdb_world_bounds(const veil_vdb* v, float lo[3], float hi[3], veil_error* err);

/* The world AABB (m) outside which the field is 0: the index bbox grown by
 * one voxel on each side, transformed. Same errors as above. */
veil_result veil_vdb_world_support(const veil_vdb* v, float lo[3], float hi[3], veil_error* err);

/* How veil_vdb_to_grid would resample v onto g. */
typedef struct veil_vdb_resample_plan {
    int exact_copy;       /* 1: values copied (the exact path) */
    int k;                /* samples per target voxel edge (1 for a copy) */
    int lo[3], hi[3];     /* target voxels touched, inclusive; lo > hi when none */
    size_t samples;       /* field samples (or values copied) */
    int dense_lo[3], dense_hi[3]; /* box filter: the VDB index box read densely */
    size_t dense_voxels;  /* its size, <= VEIL_VDB_MAX_DENSE_VOXELS */
} veil_vdb_resample_plan;

veil_result veil_vdb_plan_resample(const veil_vdb* v, const veil_grid* g, veil_vdb_resample_plan* plan,
                                   veil_error* err);

/* Adds density_scale x the box-filtered field (above) to `density`
 * (veil_grid_voxels(g) floats, x fastest). Voxels whose cube misses the
 * field's support are left untouched. Values below 0 read as 0 (a density
 * or an emission: scene/limits.h). */
veil_result veil_vdb_to_grid(const veil_vdb* v, float density_scale, const veil_grid* g, float* density,
                             veil_error* err);
/* The same keeping values below 0 (a temperature grid, whose offset may
 * make them hot). */
veil_result veil_vdb_to_grid_signed(const veil_vdb* v, float scale, const veil_grid* g, float* out, veil_error* err);

/* What a grid's values are, for the bounds of scene/limits.h. */
typedef enum veil_values_kind {
    VEIL_VALUES_DENSITY,     /* value x scale (density_scale) <= VEIL_MAX_DENSITY */
    VEIL_VALUES_EMISSION,    /* value x scale (the largest of emission.scale x color) <= VEIL_MAX_EMISSION */
    VEIL_VALUES_TEMPERATURE, /* scale x value + offset (kelvin) <= VEIL_MAX_KELVIN */
} veil_values_kind;

/* Checks the values v holds (veil_vdb_value_range: all finite once opened)
 * against the bound of their kind, a density or emission value below 0
 * counting as 0 (as veil_vdb_to_grid reads it). Over it: VEIL_ERR_INVALID
 * naming the file, the grid, how many voxels pass the bound and the
 * largest value they make ("...: grid 'heat': 1 voxel emits too much: value
 * x emission.scale x color up to 3e+38 W m^-3 sr^-1, over the bound of
 * 1e+21 W m^-3 sr^-1 (scene/limits.h)"). Cheap: the range was found when
 * the grid was opened; only a refusal counts. */
veil_result veil_vdb_check_values(const veil_vdb* v, veil_values_kind kind, double scale, double offset,
                                  veil_error* err);

/* The grid's lattice: 1 and its smallest voxel edge (the world length of
 * one index step along the shortest index axis, m) when it has active
 * voxels and an affine transform, else 0. *axis_aligned is 1 when the
 * transform is a uniform scale plus a translation (the voxels are
 * axis-aligned cubes of edge *edge), and origin is then the world position
 * of index (0, 0, 0). */
int veil_vdb_lattice(const veil_vdb* v, double* edge, double origin[3], int* axis_aligned);

#endif
