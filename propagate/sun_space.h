/* veil — optical depth of a directional light (a sun) in the light's own
 * grid: the deep-shadow-map layout (Lokovic & Veach 2000). The grid's third
 * axis c runs along the light's travel direction, so the optical depth of
 * every node of a column is one prefix sum down the column:
 *   D(node k) = D(node k-1) + integral of density over the step from k-1 to k,
 * D(node 0) = 0 (the first plane lies in front of the whole medium). Each
 * step is integrated with composite Simpson panels, clipped to the medium's
 * box, so the only errors are Simpson's on the trilinear field (exact
 * where the field along the line is one cubic; the kinks where the line
 * crosses a voxel-centre plane leave O(panel^2) per kink) and the lookup's
 * trilinear interpolation between nodes. About two density fetches per
 * panel, against ~16 per voxel of the semi-Lagrangian gather on the EV's
 * grid (opv.h).
 *
 * Geometry: positions are index coordinates of the EV's grid (voxel i's
 * centre at i; the medium spans [0, dims - 1]). Node (i, j, k) lies at
 * origin + i axis[0] + j axis[1] + k axis[2]; axis[0], axis[1] are
 * orthogonal to the light, `across` voxels long, axis[2] is the travel
 * direction, `along` voxels long. The nodes cover the projection of the
 * medium's box with one node to spare on the high side of each axis, so
 * any point of the box has all eight nodes of its lookup.
 */
#ifndef VEIL_SUN_SPACE_H
#define VEIL_SUN_SPACE_H

#include <stddef.h>

#include "../core/result.h"
#include "../volume/volume.h"

typedef struct veil_sun_space {
    int nodes[3];      /* along a, b, c */
    float origin[3];   /* node (0, 0, 0), index coordinates */
    float axis[3][3];  /* index-space step between neighbouring nodes along a, b, c */
    int panels;        /* Simpson panels per step along c, each at most one voxel long */
} veil_sun_space;

/* Defaults, chosen from the measurements in docs/performance.md. */
#define VEIL_SUN_DEFAULT_ACROSS 0.5f
#define VEIL_SUN_DEFAULT_ALONG 4.0f
#define VEIL_SUN_DEFAULT_PANELS 1
/* A light-space grid has at most VEIL_SUN_MAX_NODES nodes (4 bytes each:
 * 512 MiB) and at most VEIL_SUN_NODES_PER_VOXEL per voxel of the EV; where
 * the spacing asked for would exceed either, opv_set.c widens the spacing
 * across the light until it fits (the stage report says so). */
#define VEIL_SUN_MAX_NODES ((size_t)1 << 27)
/* GL 4.5's least GL_MAX_3D_TEXTURE_SIZE: what a plan made without a GL assumes. */
#define VEIL_GL_MIN_3D_TEXTURE 2048
#define VEIL_SUN_NODES_PER_VOXEL 32

/* The light-space grid of grid g for a sun whose light travels along
 * `travel` (any non-zero vector), with nodes `across` voxels apart across
 * the light and `along` voxels apart along it (both > 0) and `panels`
 * Simpson panels a step (raised to ceil(along) so that none is longer than
 * a voxel: the occupancy skip needs that). max_axis: the most nodes one
 * axis may have (the GL's 3D texture limit). VEIL_ERR_LIMIT when the grid
 * would exceed max_axis or max_nodes. */
veil_result veil_sun_space_make(const veil_grid* g, const float travel[3], float across, float along, int panels,
                                int max_axis, size_t max_nodes, veil_sun_space* out, veil_error* err);

size_t veil_sun_space_nodes(const veil_sun_space* s);

/* World position x -> the light-space texture's coordinates:
 * tex = m[r][0..2] . x + m[r][3] (rows a, b, c), node i's centre at (i + 0.5) / nodes. */
void veil_sun_space_to_texture(const veil_grid* g, const veil_sun_space* s, float m[3][4]);

/* The C twin of propagate/shaders/sun_prefix.comp: the same panels, the
 * density by trilinear interpolation of rho (veil_grid_voxels floats, x
 * fastest) in float, clamped to the box as the GPU's clamped fetch is.
 * out: veil_sun_space_nodes floats, a fastest, D in density * m. */
void veil_sun_space_cpu(const veil_grid* g, const float* rho, const veil_sun_space* s, float* out);

#endif
