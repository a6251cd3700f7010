/* veil accuracy benchmark — its scenes and their cached references.
 *
 * Scenes (all rendered at the benchmark's small image size):
 *  - homogeneous: a cube [-1, 1]^3 m of constant density 1, given as a grid
 *    whose voxel centres span exactly that cube at every resolution (so the
 *    trilinear medium is the same cube for every N); a point light inside
 *    it and a directional light. The GPU gets the grid through
 *    veil_render_density; the reference gets a small grid of the same
 *    constant over the same box, which is the same medium exactly.
 *  - rbf-fog: data/scenes/rbf_fog.json (3000 RBF particles).
 *  - vdb-smoke: data/scenes/vdb_smoke.json, whose OpenVDB plume
 *    data/generated/smoke_plume.vdb is written by `make data`.
 *
 * The reference is veil_pt_render with max_order 1 (the marcher's single
 * scattering) on a medium fixed per scene, independent of what the fast
 * path's sweep sets: the exact cube for homogeneous, and the scene's
 * sources voxelised at `ref_res` voxels along the longest side (at least
 * twice the finest the sweep uses) for the others. Each reference is two
 * independent halves (seeds differ), whose difference measures its noise
 * without trusting the per-pixel standard errors (which underestimate a
 * heavy-tailed estimator's spread at low spp). References are cached on
 * disk as EXR (R, G, B, A, stderr.R/G/B) under a name keyed by everything
 * they depend on: the scene file's bytes, the VDB's bytes, the reference's
 * resolution, image size, spp, seed, and the source text of the reference
 * renderer and the volume code (so a change there makes a new reference).
 */
#ifndef VEIL_BENCH_ACCURACY_SCENES_H
#define VEIL_BENCH_ACCURACY_SCENES_H

#include <stdint.h>

#include "core/result.h"
#include "io/scene.h"
#include "volume/volume.h"

enum { ACC_HOMOGENEOUS, ACC_RBF_FOG, ACC_VDB_SMOKE, ACC_SCENE_COUNT };

extern const char* const acc_scene_names[ACC_SCENE_COUNT];

/* The homogeneous cube: half-width and the reference's (exact) grid. */
#define ACC_BOX_HALF 1.0f
#define ACC_BOX_REF_N 8

typedef struct acc_scene {
    int id;
    const char* name;
    veil_scene scene;
    int given_density; /* 1: the homogeneous cube (veil_render_density) */
    int default_res;   /* the scene's medium.max_resolution */
    char source[512];  /* where the scene comes from (one line) */
    uint64_t content_key; /* scene text and data files */
} acc_scene;

/* Loads scene `id`. Messages name the file; a missing generated VDB says to
 * run `make data`. */
veil_result acc_scene_load(int id, acc_scene* out, veil_error* err);
void acc_scene_free(acc_scene* s); /* accepts a zeroed one */

/* The homogeneous cube on an n^3 grid (n >= 2): *g and a newly malloc'd
 * density (free() it); NULL when out of memory. */
float* acc_box_density(int n, veil_grid* g);

typedef struct acc_ref_settings {
    int width, height;
    int spp;     /* in all: two independent halves of spp / 2 each */
    int ref_res; /* voxels along the longest side of the reference's EV; 0: the exact cube */
    uint64_t seed; /* halves: seed and seed + 1 */
} acc_ref_settings;

typedef struct acc_reference {
    int width, height;
    float* rgba;       /* 4 floats a pixel: the mean of the halves */
    float* stderr_rgb; /* 3 floats a pixel: its standard error */
    float* half[2];    /* 4 floats a pixel: the halves (alpha: the mean's) */
    double ms;         /* time it took to make (NAN when unknown) */
    int from_cache;
    int grid_dims[3];  /* the reference's EV (0 when exact) */
    char path[1024];   /* the cache file */
} acc_reference;

/* The reference of s with settings r: read from cache_dir when there, else
 * rendered (progress on stderr) and written there (cache_dir is created;
 * NULL: no cache). The cache file is an EXR with the mean (R, G, B, A,
 * stderr.R/G/B, as `veil reference` writes) and the halves (half0.R, ...). */
veil_result acc_reference_get(const acc_scene* s, const acc_ref_settings* r, const char* cache_dir,
                              acc_reference* out, veil_error* err);
void acc_reference_free(acc_reference* ref);

/* Means of b x b pixel blocks (a partial block at the edge is dropped):
 * newly malloc'd, (w / b) x (h / b) RGBA; NULL when out of memory. */
float* acc_bin_image(const float* rgba, int w, int h, int b);

/* A reference seen by the comparisons: binned (bin x bin pixel means), and
 * its noise on both scales, as relative errors are measured: the rms over
 * pixels and channels of sigma / max(|ref|, floor), floor the default of
 * veil_compare_images (VEIL_COMPARE_FLOOR_FRACTION of the mean RGB).
 * noise_se takes sigma from the per-pixel standard errors; noise_split from
 * the halves, |half0 - half1| / 2 (whose expected square is the variance of
 * their mean), which does not trust the per-pixel variance estimates. */
typedef struct acc_ref_view {
    float *bin, *bin_half[2];
    int bw, bh;
    double floor, noise_se, noise_split, noise_bin;
} acc_ref_view;

int acc_ref_view_make(const acc_reference* ref, int bin, acc_ref_view* v); /* 0 when out of memory */
void acc_ref_view_free(acc_ref_view* v);

#endif
