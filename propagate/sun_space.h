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

/* Point and spot lights get the perspective form of the same layout: six
 * faces of a cube around the light (axis x, y, z, each signed), face f =
 * 2 axis + (sign < 0), each a frustum whose columns are rays from the
 * light. Column (i, j) of face f runs along the direction
 *   d = sign e_axis + u e_(axis+1)%3 + v e_(axis+2)%3,  u = u0 + i du, v = v0 + j du,
 * its node k at light + (z0 + k dz) d: z is the depth along the face's
 * axis (voxels), so every column's nodes lie on the face's planes of
 * constant depth, and the march's lookup is the sun's (D on the plane
 * towards the light, bilinear in (u, v), plus the stretch back) with
 * (u, v, z) in place of (a, b, c). A face holds the window of (u, v) in
 * [-1, 1]^2 that the medium's box covers, nodes du apart where du =
 * across / (the face's deepest point in the box), so columns are at most
 * `across` voxels apart anywhere in the box; faces that see none of the
 * box are left out. Node plane 0 of a face lies at the light (z0 = 0) or
 * in front of the whole box, so D there is 0 either way. The faces share
 * one texture: columns along a and b (each face's nu x nv of them from
 * (0, 0), the rest 0), the faces' planes one after another along c. */
typedef struct veil_point_face {
    int nu, nv, nz;  /* columns along u and v, node planes; nz = 0: the face sees no box, and is absent */
    int first;       /* its first plane in the texture */
    float u0, v0;    /* column (0, 0) */
    float du;        /* between columns, in u and in v */
    float z0;        /* depth of plane 0, voxels */
} veil_point_face;

typedef struct veil_sun_space {
    int nodes[3];      /* along a, b, c (perspective: the shared texture's, as above) */
    float origin[3];   /* node (0, 0, 0), index coordinates (perspective: the light) */
    float axis[3][3];  /* index-space step between neighbouring nodes along a, b, c (perspective: 0) */
    int panels;        /* Simpson panels per step along c, each at most one voxel long (perspective: the
                          least; a column takes at least ceil(its step's length)) */
    float across;      /* the spacing across the light asked for (voxels) */
    /* perspective only: */
    int perspective;   /* 1: a point or spot light's faces, 0: a sun */
    float dz;          /* depth between planes, voxels */
    veil_point_face face[6];
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

/* The perspective grid of a point or spot light at index coordinates
 * `light` (anywhere: inside the box too), columns at most `across` voxels
 * apart in the box, planes `along` voxels apart in depth; the rest as
 * veil_sun_space_make. VEIL_ERR_LIMIT also when the light sees none of the
 * box (it cannot: only a light on the box's surface exactly). */
veil_result veil_point_space_make(const veil_grid* g, const float light[3], float across, float along, int panels,
                                  int max_axis, size_t max_nodes, veil_sun_space* out, veil_error* err);

size_t veil_sun_space_nodes(const veil_sun_space* s);

/* A perspective grid's face at the index-space offset w from its light:
 * the face f, and the depth z and (u, v) of w in its frame. */
static inline int veil_point_face_of(const float w[3], float* z, float* u, float* v)
{
    float x = w[0] < 0 ? -w[0] : w[0], y = w[1] < 0 ? -w[1] : w[1], q = w[2] < 0 ? -w[2] : w[2];
    int a = x >= y && x >= q ? 0 : y >= q ? 1 : 2;
    float d = a == 0 ? x : a == 1 ? y : q;
    *z = d;
    d = d > 1e-6f ? d : 1e-6f;
    *u = w[(a + 1) % 3] / d;
    *v = w[(a + 2) % 3] / d;
    return 2 * a + (w[a] < 0);
}

/* World position x -> the light-space texture's coordinates (suns only):
 * tex = m[r][0..2] . x + m[r][3] (rows a, b, c), node i's centre at (i + 0.5) / nodes. */
void veil_sun_space_to_texture(const veil_grid* g, const veil_sun_space* s, float m[3][4]);

/* The C twin of propagate/shaders/sun_prefix.comp (both forms): the same panels, the
 * density by trilinear interpolation of rho (veil_grid_voxels floats, x
 * fastest) in float, clamped to the box as the GPU's clamped fetch is.
 * out: veil_sun_space_nodes floats, a fastest, D in density * m. */
void veil_sun_space_cpu(const veil_grid* g, const float* rho, const veil_sun_space* s, float* out);

/* The columns of face f (a sun: its one "face", f ignored) as the prefix
 * sum walks them, in the floats both the shader's block and the C twin
 * use: column (i, j)'s node 0 at frame[0] + i frame[1] + j frame[2], its
 * step between nodes frame[3] + i frame[4] + j frame[5] (index space). */
void veil_sun_space_columns(const veil_sun_space* s, int f, float frame[6][3]);

/* D (density * m) from index position y in the box to the light, as the
 * march reads a perspective grid (propagate/shaders/lit_medium.glsl): D on
 * y's face's node plane towards the light, bilinear in (u, v), plus the
 * density over the stretch back to y, at most `room` metres of it (the
 * path's part in the box), midpoint rule in `pieces` pieces. D: the grid's
 * nodes (veil_sun_space_cpu or read back). The C twin of the shader's
 * lookup, for tests and bench/sun_space. */
float veil_point_space_depth(const veil_grid* g, const float* rho, const veil_sun_space* s, const float* D,
                             const float y[3], float room, int pieces);

/* The prefix sums' work for a perspective grid: the length of all its
 * columns inside the box, in voxels (each voxel of it about two density
 * fetches, Simpson panels of at most a voxel). */
double veil_point_space_work(const veil_grid* g, const veil_sun_space* s);

/* The longest piece of a perspective grid's stretch back (voxels): two
 * pieces of at most 2 voxels at the default planes 2 voxels apart erred
 * 0.20 / 0.30 % on the shared smoke at 128^3 (a light inside the box /
 * outside), pieces of at most a voxel 0.20 / 0.30 %, one piece 0.43 / 0.37 %
 * (bench/sun_space, docs/performance.md). */
#define VEIL_POINT_PIECE 2.0f

/* Pieces for the stretch back of a perspective grid:
 * ceil(dz |d|max / VEIL_POINT_PIECE), |d|max over its columns. */
int veil_point_space_pieces(const veil_sun_space* s);

#endif
