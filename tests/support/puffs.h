/* veil tests — three Gaussian puffs of smoke sampled at the voxels of a
 * grid (trilinear between them: kinks at every voxel plane), each cut at
 * `cut` radii (0: not cut) so that bricks between them hold nothing. */
#ifndef VEIL_TEST_PUFFS_H
#define VEIL_TEST_PUFFS_H

#include <math.h>
#include <stdlib.h>

#include "volume/volume.h"

/* centres (voxel indices) and radii (voxels) */
typedef struct puff {
    double c[3], r;
} puff;

/* malloc'd density of g (x fastest); *rmax its largest value */
static inline float* puffs_density(const veil_grid* g, const puff p[3], double cut, float* rmax)
{
    float* rho = malloc(veil_grid_voxels(g) * sizeof *rho);
    *rmax = 0.0f;
    for (int k = 0; rho && k < g->dims[2]; ++k)
        for (int j = 0; j < g->dims[1]; ++j)
            for (int i = 0; i < g->dims[0]; ++i) {
                double v = 0;
                for (int b = 0; b < 3; ++b) {
                    double dx = i - p[b].c[0], dy = j - p[b].c[1], dz = k - p[b].c[2];
                    double r2 = dx * dx + dy * dy + dz * dz;
                    if (cut <= 0 || r2 < cut * cut * p[b].r * p[b].r) v += exp(-r2 / (p[b].r * p[b].r));
                }
                rho[((size_t)k * g->dims[1] + j) * g->dims[0] + i] = (float)v;
                *rmax = fmaxf(*rmax, (float)v);
            }
    return rho;
}

#endif
