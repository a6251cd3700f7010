/* veil — a scene's voxelised sources, gathered once for every renderer.
 *
 * The extinction volume of a scene is made from its RBF particles (explicit
 * and generated) and its OpenVDB grids; analytic fog is never voxelised.
 * veil_scene_volume_open() collects the particles, opens the grids, fits
 * the grid that holds them all (over the union of the particles' cut-off
 * boxes and the grids' supports: at the VDBs' native resolution, or
 * medium.max_resolution voxels along the longest side; see below) and forms
 * a content key. The GPU renderer
 * then splats the particles on the GPU; the CPU reference
 * (veil_scene_volume_density) splats them with veil_inject_rbf_cpu. Both
 * resample the grids with veil_vdb_to_grid first, so the two see the same
 * volume (the splats agree to ~1e-6 relative, tests/volume/test_inject_gpu.c).
 */
#ifndef VEIL_SCENE_VOLUME_H
#define VEIL_SCENE_VOLUME_H

#include <stddef.h>
#include <stdint.h>

#include "../core/result.h"
#include "../scene/scene.h"
#include "../io/vdb.h"
#include "volume.h"

/* At most this many OpenVDB grids in one scene. */
#define VEIL_MAX_VDB_SOURCES 8

/* One emitting grid of a vdb source. */
typedef struct veil_emission_source {
    veil_vdb* grid;        /* the emission or temperature grid (owned) */
    int temperature;       /* 0: eps = factor * value; 1: blackbody of kelvin = t_scale * value + t_offset */
    float factor[3];       /* emission: scale * color; temperature: k (m^-1 per unit density) per channel */
    float t_scale, t_offset;
    int density;           /* temperature: the index in vdbs[] of the source's density grid */
} veil_emission_source;

typedef struct veil_scene_volume {
    veil_particle* particles; /* all RBF particles (owned) */
    size_t particle_count;
    veil_vdb* vdbs[VEIL_MAX_VDB_SOURCES]; /* opened grids (owned) */
    float vdb_scale[VEIL_MAX_VDB_SOURCES]; /* their density_scale */
    int vdb_count;
    size_t vdb_voxels; /* active voxels over all grids */
    uint64_t key;      /* veil_scene_volume_key() of the scene */
    int has_volume;    /* 0: nothing to voxelise (then `grid` is unset) */
    int sparse;        /* 1: the grid is held sparse (volume/sparse.h): its box may be far over the dense cap */
    veil_grid grid;
    /* How the grid was chosen, for --stats: "native: ..." or "resampled: ...",
     * and the files' grids that were not read ("; read 'density', not: vel (vec3s)") */
    char resolution[416];
    char velocity_read[VEIL_MAX_VDB_SOURCES][96]; /* each vdb's velocity grid when blurred ("": none) */
    double blur_seconds; /* the CPU time the blurs were estimated to take (volume/motion_blur.h's budget) */
    char motion[256]; /* the sources' motion blur, "; source 0 blurred by 'vel': 4 samples, ..." ("": none) */
    /* Emission ("emission" and "temperature" of vdb sources); the grid
     * above covers their supports too. */
    veil_emission_source emission[2 * VEIL_MAX_VDB_SOURCES];
    int emission_count;
    float sigma_a[3]; /* the medium's, for temperature grids' Kirchhoff emission */
    int emission_lights; /* multiple_scattering.emission_lights: the emission as at most this many lights */
} veil_scene_volume;

/* The emission on v->grid: a newly calloc'd *rgba (4 floats a voxel: the
 * emission coefficient eps per channel, W m^-3 sr^-1, and 0), each grid
 * resampled as the density is (veil_vdb_to_grid: an emission value below 0
 * reads 0). A temperature grid emits k rho B_rgb(kelvin) (volume/blackbody.h:
 * veil_blackbody_table), capped at VEIL_MAX_EMISSION (scene/limits.h).
 * NULL when there is none. */
veil_result veil_scene_volume_emission(const veil_scene_volume* v, float** rgba, veil_error* err);

/* What that adds per voxel, for the sparse volume too: eps (W m^-3 sr^-1)
 * of emission source es where its grid reads `value` and its density is
 * rho (a temperature grid emits only where rho > 0), with the blackbody
 * table of veil_emission_table (veil_blackbody_table; malloc'd, NULL out
 * of memory). */
double* veil_emission_table(void);
void veil_emission_eps(const veil_scene_volume* v, const veil_emission_source* es, const double* table, float value,
                       float rho, float eps[3]);

/* Native resolution. When the scene gives no medium.max_resolution and has
 * VDB sources, the grid takes the finest VDB voxel edge (not the default
 * 128 voxels), placed on the lattice of the first VDB with that edge whose
 * voxels are axis-aligned cubes, so that its values are copied exactly
 * (volume/vdb_volume.h); a rotated or sheared VDB is resampled at its own
 * voxel edge (the field at each centre). Above VEIL_NATIVE_MAX_VOXELS voxels (or 2048 a
 * side) the grid is resampled down to fit, and says so. An explicit
 * max_resolution is a cap the user chose: the grid is fitted to it as
 * before. */
#define VEIL_NATIVE_MAX_VOXELS ((size_t)1 << 27) /* 512 MiB of float density */

/* The key of the volume a scene's sources make, from their descriptions
 * alone: the resolution, explicit particles, the random generators'
 * parameters, each VDB file's identity (path, size, modification time,
 * inode; never its bytes), grid name, scale and level-set mode, and for a
 * source that is motion-blurred (volume/motion_blur.h) its velocity's grid,
 * unit and scale with the camera's shutter and the scene's fps. Nothing is
 * opened, so a cached volume is recognised in microseconds whatever the
 * files' sizes. Analytic fog is not part of it (never voxelised). */
uint64_t veil_scene_volume_key(const veil_scene* s);

/* 0 when no source of the scene is voxelised (fog only, or no source):
 * then there is nothing to open. */
int veil_scene_volume_needed(const veil_scene* s);

/* Errors name the source (`medium.sources[i]: ...`). On failure *out is
 * left closed (nothing to free). */
veil_result veil_scene_volume_open(const veil_scene* s, veil_scene_volume* out, veil_error* err);
void veil_scene_volume_close(veil_scene_volume* v); /* accepts a zeroed one */

/* Adds the resampled OpenVDB grids to density (veil_grid_voxels(&v->grid)
 * floats). */
veil_result veil_scene_volume_add_vdbs(const veil_scene_volume* v, float* density, veil_error* err);

/* The whole volume on the CPU: grids resampled, particles splatted, into a
 * newly calloc'd *density (free() it). Needs v->has_volume. */
veil_result veil_scene_volume_density(const veil_scene_volume* v, float** density, veil_error* err);

#endif
