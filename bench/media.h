/* veil benchmarks — deterministic media on an N^3 grid over the box
 * [BOX_LO, BOX_LO + BOX_WIDTH]^3 (m):
 *  - homogeneous: density 1 everywhere;
 *  - rbf-fog: a seeded RBF particle cloud splatted on the grid on the CPU;
 *  - smoke: a procedural smoke plume (a bent rising column, radius growing
 *    with height, modulated by seeded value-noise fBm) — a STAND-IN for a
 *    real OpenVDB smoke volume;
 *  - smoke-vdb: a real smoke VDB (default ../shared/data/smoke.vdb beside the
 *    checkout, or $VEIL_BENCH_VDB), its "density" grid resampled with mass
 *    conservation onto the N^3 grid over the cube enclosing it, then used on
 *    the bench's box: a uniformly scaled copy (relative errors do not change
 *    with scale). Missing file: make_medium fails with VEIL_ERR_IO. */
#ifndef VEIL_BENCH_MEDIA_H
#define VEIL_BENCH_MEDIA_H

#include "core/result.h"
#include "volume/volume.h"

#define BOX_LO (-1.0f)
#define BOX_WIDTH 2.0f

enum { MEDIUM_HOMOGENEOUS, MEDIUM_RBF_FOG, MEDIUM_SMOKE, MEDIUM_VDB_SMOKE, MEDIUM_COUNT };

veil_grid bench_grid(int n);
/* The density of `medium` on g (veil_grid_voxels floats, x fastest); NULL on
 * failure with the reason in err. */
float* make_medium(int medium, const veil_grid* g, veil_error* err);

#endif
