/* veil — the volumetric stage: light scattered more than once, computed
 * once per volume and lights, with no camera (a turntable reuses it). It
 * sits between propagate/ (whose optical depths it reads) and render/
 * (whose march reads its field), and never includes render/.
 *
 * A field is one rgba32f 3D texture of one kind (veil_field_kind):
 *
 * - VEIL_FIELD_ESCAPE, the octave estimate's gate: per point, the chance
 *   that light scattered there scatters again before it leaves the medium
 *   (volumetric/shaders/escape.comp; no light involved). On a grid of at most
 *   VEIL_ESCAPE_CELLS cells along the longest side over a dense volume, or
 *   VEIL_SPARSE_ESCAPE^3 points a kept brick over a sparse one.
 * - VEIL_FIELD_FLUENCE, the diffusion estimate: on a coarse grid over the
 *   medium (cells of two EV voxels, at most `diffusion_cells` along the
 *   longest side; for analytic fog only, the first fog's box when it is
 *   under VEIL_DIFFUSION_MAX_EXTENT), the source of once-scattered light
 *   S = sigma_s rho sum_l E_l exp(-sigma_t D_l) is formed from the same
 *   optical depths the march reads (volumetric/shaders/diffusion_source.comp),
 *   and the steady diffusion equation
 *     -div(D grad phi) + sigma_a rho phi = S,  D = 1 / (3 (sigma_a + sigma_s (1 - g)) rho)
 *   is relaxed by red-black SOR (volumetric/shaders/diffusion_sor.comp;
 *   phi = 0 beyond the grid). The march then adds sigma_s rho phi / (4 pi)
 *   as in-scattering (the multiply scattered light, isotropic): orders >= 2.
 *
 * - VEIL_FIELD_CACHE, the light cache (volumetric/cache.h): the fluence and
 *   flux of light scattered at least once, traced by photons from every
 *   light (and the medium's emission) on a grid over the medium; the march
 *   scatters it once more (orders >= 2).
 *
 * docs/multiple-scattering.md has the derivation and the measurements.
 * The stage's key and decision are frame/'s (frame/stages.c); this module
 * builds what it is asked for and keeps it under the key it is given.
 * Needs the GL context current at creation.
 */
#ifndef VEIL_VOLUMETRIC_H
#define VEIL_VOLUMETRIC_H

#include <epoxy/gl.h>
#include <stdint.h>

#include "../core/result.h"
#include "../core/shared.glsl.h"
#include "../propagate/lit_medium.h"
#include "cache.h"

#define VEIL_ESCAPE_CELLS 32 /* the escape field's cells along the longest side */
#define VEIL_DIFFUSION_OMEGA 1.9f      /* SOR over-relaxation (optimal ~ 2 / (1 + sin(pi / n)), n ~ 64) */
/* A cell whose transport optical thickness (sigma_a + sigma_s (1 - g)) rho h
 * is below this is vacuum for the diffusion (which does not hold there):
 * light leaves the medium through its faces with the Marshak flux phi / 2. */
#define VEIL_DIFFUSION_VACUUM 0.001f

/* A field as the march reads it. */
typedef struct veil_volumetric_field {
    GLuint texture;       /* rgba32f 3D, 0: none */
    int depth;            /* the light cache: its grid's cells along z (the texture stacks VEIL_CACHE_SLABS grids); else 0 */
    veil_field_kind kind; /* VEIL_FIELD_NONE when texture is 0 */
    float tex_min[3];     /* texture coordinates are (x - tex_min) * tex_inv */
    float tex_inv[3];
    int first_only;       /* the light cache of a medium too thick for photons: the environment's rest alone, to its
                             first scattering (volumetric/cache.h); the march's octaves stand in for the higher orders */
} veil_volumetric_field;

/* What the stage is asked to build (frame/ decides; none of it is the camera's). */
typedef struct veil_volumetric_desc {
    veil_field_kind kind;     /* FLUENCE or ESCAPE */
    veil_lit_medium medium;   /* the EV, the lights and their optical depths */
    int diffusion_cells;      /* the fluence grid's cells along the longest side (8..256) */
    int diffusion_iterations; /* red-black sweeps; 0: 3 x the longest side */
    veil_cache_settings cache; /* VEIL_FIELD_CACHE: photons, cells, seed, whether emission is a source */
} veil_volumetric_desc;

typedef struct veil_volumetric veil_volumetric;

typedef struct veil_volumetric_report {
    int dims[3];
    float cell;      /* m */
    int iterations;  /* red-black sweeps */
    int cached;      /* 1: the key matched what was kept */
    int skipped;     /* 1: no grid (no medium, or a fog box too large; the diffusion solve over a sparse volume) */
    int sparse;      /* 1: over a sparse volume (the escape field per kept brick, 3^3 points each) */
    uint64_t key;
    veil_cache_report cache; /* VEIL_FIELD_CACHE: what the photons did (kept with the field) */
} veil_volumetric_report;

veil_result veil_volumetric_create(veil_volumetric** out, veil_error* err);
void veil_volumetric_destroy(veil_volumetric* v); /* accepts NULL */
void veil_volumetric_clear(veil_volumetric* v);   /* forget the kept field */

/* Brings the field d asks for up to date, keyed by `key` (frame/'s hash of
 * everything it depends on: veil_volumetric_key()); fills *field (texture 0
 * when skipped). */
veil_result veil_volumetric_update(veil_volumetric* v, const veil_volumetric_desc* d, uint64_t key,
                                   veil_volumetric_field* field, veil_volumetric_report* rep, veil_error* err);

/* The dense grid the field d asks for would have (GPU-free): its first
 * cell's centre lo (m), cell edge *h (m) and dims; 0 when there is none (no
 * medium, or a fog box over VEIL_DIFFUSION_MAX_EXTENT). A sparse volume's
 * escape field is laid per kept brick instead. */
int veil_volumetric_grid(const veil_volumetric_desc* d, float lo[3], float* h, int dims[3]);

/* The rays the escape field casts over a sparse volume of `bricks` kept
 * bricks: VEIL_SPARSE_ESCAPE^3 points a brick, each marched along the 6
 * axes and the 8 diagonals (shaders/escape.comp); for the frame's work
 * estimate (volume/sparse.h). */
#define VEIL_ESCAPE_DIRECTIONS 14
double veil_volumetric_sparse_escape_rays(double bricks);

/* The red-black sweeps the fluence on a grid of dims takes (0 for the escape field). */
int veil_volumetric_sweeps(const veil_volumetric_desc* d, const int dims[3]);

/* The kept field (texture 0: none). */
const veil_volumetric_field* veil_volumetric_field_of(const veil_volumetric* v);

/* The key of the field d asks for over a volume of key ev_key: the volume,
 * the medium's coefficients and phase, the fogs, the grid settings and the
 * kind, and (the fluence only: the escape field needs no light) the lights'
 * geometry and colour. Never the camera. From descriptions only. */
uint64_t veil_volumetric_key(uint64_t ev_key, const veil_volumetric_desc* d);

/* The field read back (dims[0]*dims[1]*dims[2]*4 floats, rgb phi), for
 * tests; NULL when there is none. Caller frees. */
float* veil_volumetric_readback(const veil_volumetric* v, int dims[3]);
/* The light cache's flux read back the same way (xyz, w 0); NULL for other fields. */
float* veil_volumetric_readback_flux(const veil_volumetric* v, int dims[3]);
/* The light cache's later light (scattered more than once; emission: scattered) read back the same
 * way (rgb phi, w 0); NULL for other fields. */
float* veil_volumetric_readback_later(const veil_volumetric* v, int dims[3]);

#endif
