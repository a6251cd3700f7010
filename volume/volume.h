/* veil — the extinction volume (EV): a dense grid of density over a
 * world-space box, and the RBF splat that fills it.
 *
 * Geometry: cubic voxels of edge `voxel` (m); voxel (i,j,k) holds the
 * density at its centre origin + (i + 0.5) * voxel (likewise j, k). The
 * medium is the trilinear interpolation of these samples over the box they
 * span, from the first centre to the last, and there is no medium outside
 * it (the OpenVDB convention: values are samples at voxel centres). So a
 * ray that leaves the centres' box has left the medium, and every voxel on
 * the box's faces is on the medium's boundary. Values are unitless density:
 * extinction is sigma_t = (sigma_a + sigma_s) * density, per colour
 * channel, in m^-1.
 *
 * The splat is particles x footprint, not particles x grid: particles are
 * binned into VEIL_BRICK^3 bricks that their cut-off ball touches, and each
 * voxel sums only its brick's list, in particle order. The CPU and GPU
 * versions do exactly the same float operations in the same order.
 */
#ifndef VEIL_VOLUME_H
#define VEIL_VOLUME_H

#include <stddef.h>
#include <stdint.h>

#include "../core/result.h"
#include "rbf.h"

typedef struct veil_grid {
    int dims[3];      /* voxels per axis, >= 1 */
    float origin[3];  /* world min corner (m) */
    float voxel;      /* voxel edge (m), > 0 */
} veil_grid;

/* Fits a grid whose voxel centres span the box [lo, hi], with
 * `max_resolution` (>= 2) voxels along its longest side (centred, so the
 * span exceeds the box by less than a voxel). */
veil_result veil_grid_fit(const float lo[3], const float hi[3], int max_resolution,
                          veil_grid* out, veil_error* err);

size_t veil_grid_voxels(const veil_grid* g);
/* The medium's box: from the first voxel centre to the last (m). */
void veil_grid_medium_box(const veil_grid* g, float lo[3], float hi[3]);
/* World position of voxel (i, j, k)'s centre, computed as the shaders do. */
void veil_grid_center(const veil_grid* g, int i, int j, int k, float out[3]);

/* Particles binned into bricks (CSR lists) and packed for the GPU. */
typedef struct veil_rbf_bins {
    int bricks[3];         /* bricks per axis: ceil(dims / VEIL_BRICK) */
    uint32_t* start;       /* bricks+1 offsets into list */
    uint32_t* list;        /* particle indices, ascending within a brick */
    size_t list_len;
    float* packed;         /* 8 floats a particle: cx,cy,cz,c, a^2, r_cut^2, 0, 0 */
    size_t particle_count;
} veil_rbf_bins;

/* The splat's work, known once the particles are binned: every voxel of a
 * brick evaluates every particle of its list, 512 x (list entries)
 * Gaussians. Above VEIL_SPLAT_MAX_EVALS (10^7 particles of a few bricks
 * each come to ~1e11) the bin is refused with the numbers, before any
 * memory is taken for the lists; VEIL_SPLAT_MAX_ENTRIES bounds the lists'
 * memory (1 GiB). llvmpipe splats 2e8 evaluations a second on this
 * project's 2-core machines (10^6 particles, 9.4e9 evaluations, in 46 s),
 * so the cap is about 3 minutes there (a desktop GPU: about a second).
 * The GPU splat is split into dispatches of at most VEIL_SPLAT_DISPATCH_EVALS
 * (runs of bricks; one brick more when one brick holds more); on a software rasteriser
 * of VEIL_SPLAT_SOFTWARE_EVALS, each also how late a cancel is seen there
 * (issue 41: within 1 s): 2^25, about 0.2 s. */
#define VEIL_SPLAT_MAX_EVALS ((size_t)1 << 35)
#define VEIL_SPLAT_MAX_ENTRIES ((size_t)1 << 28)
#define VEIL_SPLAT_DISPATCH_EVALS ((size_t)1 << 28)
#define VEIL_SPLAT_SOFTWARE_EVALS ((size_t)1 << 25)

veil_result veil_rbf_bin(const veil_grid* g, const veil_particle* p, size_t n,
                         veil_rbf_bins* out, veil_error* err);
void veil_rbf_bins_free(veil_rbf_bins* b);

/* CPU splat: adds the particles to rho (veil_grid_voxels floats, x fastest). */
void veil_inject_rbf_cpu(const veil_grid* g, const veil_rbf_bins* b, float* rho);

#endif
