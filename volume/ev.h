/* veil — the extinction volume (EV) on the GPU, behind one handle.
 *
 * Today the EV is dense: an r32f 3D texture of the grid's size (density,
 * unitless; sigma_t = (sigma_a + sigma_s) * density, m^-1) and its
 * occupancy bricks (volume/shaders/occupancy.comp: the largest density in
 * each VEIL_BRICK^3 brick and the voxel ring around it, so the marcher may
 * skip bricks without density). Or it is sparse (volume/sparse.h: a scene
 * volume with v->sparse): an atlas of the bricks that hold density and the
 * tables that find them, behind the same calls (veil_ev_texture is then
 * the atlas, veil_ev_occupancy 0, and veil_ev_sparse_of says the rest). The handle owns its textures and programs and needs the GL context
 * that was current when it was created; it does not know about caching:
 * frame/ decides when to rebuild it (the key is the caller's).
 */
#ifndef VEIL_EV_H
#define VEIL_EV_H

#include <epoxy/gl.h>
#include <stdint.h>

#include "../core/result.h"
#include "scene_volume.h"
#include "sparse.h"
#include "volume.h"

typedef struct veil_ev veil_ev;

/* What a build did, for the stage report. */
typedef struct veil_ev_report {
    size_t particles;  /* RBF particles splatted */
    size_t vdb_voxels; /* active voxels of the OpenVDB grids resampled */
    size_t bytes;      /* GPU bytes of the volume (texture and occupancy, or atlas and tables) */
} veil_ev_report;

/* The emission of the scene's grids as point lights (volume/emission_lights.h,
 * at most v->emission_lights of them), made with the emission texture; *n = 0
 * when there is none. */
const veil_light* veil_ev_emission_lights(const veil_ev* ev, int* n);

/* A sparse EV's GPU objects. */
typedef struct veil_ev_sparse {
    GLuint atlas;              /* r32f 3D: the kept bricks' texels (also veil_ev_texture) */
    GLuint top, nodes, coords; /* buffer textures: r32ui, r32ui, rgba32i (core/shared.glsl.h) */
    GLuint buffers[3];         /* their storage */
    GLuint ubo;                /* veil_sparse_block */
    veil_sparse_block block;
    int atlas_texels[3];
    size_t slots;              /* bricks kept */
    size_t bytes;              /* GPU bytes of all of the above */
    size_t voxels;             /* non-zero voxels copied */
    int32_t* bricks;           /* on the CPU too: 4 ints a slot (its brick), for ordering passes */
} veil_ev_sparse;

/* NULL for a dense EV (or none). */
const veil_ev_sparse* veil_ev_sparse_of(const veil_ev* ev);
/* Binds the tables (VEIL_TEX_SPARSE_TOP, _NODES, _COORDS) and the block
 * (VEIL_UBO_SPARSE) for a pass; NULL unbinds them. */
void veil_ev_sparse_bind(const veil_ev_sparse* sp);

veil_result veil_ev_create(veil_ev** out, veil_error* err); /* compiles the inject and occupancy programs */
/* The device is a software rasteriser: the RBF splat goes in shorter dispatches (volume/volume.h). */
void veil_ev_set_software(veil_ev* ev, int software);
/* Tests: every splat's dispatches of at most `evals` evaluations (0: the device's again). */
void veil_ev_set_splat_evals(size_t evals);
void veil_ev_destroy(veil_ev* ev);                          /* accepts NULL */

/* Drops the volume (an empty medium: no texture at all). */
void veil_ev_clear(veil_ev* ev);

/* The volume's grid (NULL when the EV holds none) and textures (0 when none). */
const veil_grid* veil_ev_grid(const veil_ev* ev);
GLuint veil_ev_texture(const veil_ev* ev);
GLuint veil_ev_occupancy(const veil_ev* ev);
/* The emission (rgba32f, eps per channel, W m^-3 sr^-1) of the scene's vdb
 * sources' "emission" grids on the same grid; 0 when there is none. */
GLuint veil_ev_emission(const veil_ev* ev);

/* The GPU bytes of an EV of grid g plus the optical-depth textures of
 * n_lights lights (and their scratch texture), refused with the numbers
 * when over `budget` bytes or the address space: checked before anything
 * is made. */
veil_result veil_ev_check_budget(const veil_grid* g, int n_lights, unsigned long long budget, veil_error* err);

/* Builds the EV of a scene's voxelised sources (v->has_volume): the OpenVDB
 * grids resampled on the CPU and uploaded, the RBF particles splatted on
 * the GPU, then the occupancy bricks. On failure the EV is empty. */
veil_result veil_ev_build_scene(veil_ev* ev, const veil_scene_volume* v, int n_lights,
                                unsigned long long budget, veil_ev_report* rep, veil_error* err);

/* Builds the EV from a density given on grid g (veil_grid_voxels floats). */
veil_result veil_ev_build_density(veil_ev* ev, const veil_grid* g, const float* density, int n_lights,
                                  unsigned long long budget, veil_error* err);

/* The RBF splat alone, read back into density (veil_grid_voxels floats):
 * tests compare it with the C splat. Leaves the EV as it was. */
veil_result veil_ev_splat_readback(veil_ev* ev, const veil_grid* g, const veil_particle* p, size_t n,
                                   float* density, veil_error* err);

#endif
