/* veil — the reference renderer: a CPU volumetric path tracer.
 *
 * It renders what the GPU pipeline approximates, without its
 * approximations: the same camera (one ray through each pixel's centre, as
 * scene/camera.h; no anti-aliasing, as the marcher), the same lights
 * (point and spot: intensity / r^2 with no distance floor; spot cone
 * falloff veil_spot_falloff; directional: irradiance), the same phase
 * function (isotropic or Henyey-Greenstein), and the same medium: the
 * extinction volume made from the scene's sources (volume/scene_volume.h,
 * splatted on the CPU) read trilinearly over the box of its voxel centres,
 * plus every exponential fog evaluated exactly. sigma_t = (sigma_a +
 * sigma_s) * density per RGB channel.
 *
 * Estimators (all unbiased):
 *  - Free flight: delta tracking against a majorant that is piecewise
 *    constant along the ray: the maximum voxel value of each block of
 *    VEIL_PT_MAJORANT_BLOCK^3 trilinear cells (a DDA walks the blocks),
 *    plus, per fog, the larger of its densities at the piece's two ends
 *    (the fog is exponential along a line, so that is its maximum); pieces
 *    outside the volume are cut where a fog changes by more than 2x.
 *    Colour (spectral tracking, Kutz et al. 2017, with probabilities that
 *    follow the path's throughput): one majorant mu (the largest channel);
 *    at a tentative collision the event x in {absorb, scatter, null} is
 *    chosen with probability P_x = sum_c beta_c sigma_x,c / (mu sum_c
 *    beta_c), and channel c's throughput becomes beta_c sigma_x,c / (mu P_x).
 *    Unbiased per channel; the sum of the throughputs never changes (so it
 *    cannot blow up), and for grey media this is analogue delta tracking.
 *  - Next-event estimation at every scattering vertex, to every light:
 *    transmittance by ratio tracking through the volume (same majorant)
 *    times exp(-sigma_t * D_fog) with D_fog the exact closed form
 *    (reference/closed_forms.h). Ratio tracking plays Russian roulette
 *    once the transmittance is below 0.1 (unbiased).
 *  - Continuation: the phase function sampled exactly (weight 1).
 *  - Path length: absorption is sampled as an event (the path ends with
 *    probability P_absorb: Russian roulette on absorption), and from the
 *    PT_RR_DEPTH-th vertex on a path continues with probability 0.95 and
 *    weight 1/0.95, so even an albedo-1 medium of any density ends paths
 *    after ~20 more vertices on average (unbiased, at some variance in the
 *    highest orders).
 *  - The background: background * T along the camera ray, T exact by
 *    default (reference/optical_depth.h plus the fog closed form: zero
 *    variance); with `stochastic_background` it is the delta-tracking
 *    escape estimate instead (tests check that estimator against closed
 *    forms). The background is what is seen behind the medium; it does not
 *    light the medium, as in the GPU pipeline, unless `environment` is set
 *    (the white-furnace test: then escaping paths of every order see it).
 *
 * Order: max_order = 1 counts the light scattered once (the GPU marcher's
 * quantity), K counts 1..K scatterings, 0 all of them.
 *
 * Determinism: pixel p's samples come from a generator seeded by (seed, p)
 * alone, so the image does not depend on the thread count or scheduling.
 *
 * Output: rgba as the GPU renderer's (a = 1 - mean transmittance of the
 * camera ray, exact unless stochastic_background), and per pixel the
 * standard error of the R, G, B means: sqrt(sample variance / spp), spp >= 2.
 *
 * Safeguards, counted in veil_pt_stats: a walk that takes more than
 * VEIL_PT_MAX_EVENTS tentative collisions is cut (its contribution so far
 * kept); a sample whose estimate is not finite is dropped. Both are 0 in
 * every scene of the tests.
 */
#ifndef VEIL_REFERENCE_PATHTRACER_H
#define VEIL_REFERENCE_PATHTRACER_H

#include <stddef.h>
#include <stdint.h>

#include "../core/result.h"
#include "../scene/scene.h"
#include "../volume/volume.h"

#define VEIL_PT_MAJORANT_BLOCK 4
#define VEIL_PT_MAX_EVENTS 1000000

typedef struct veil_pt_medium veil_pt_medium;

/* The medium of a scene: its sources voxelised on the CPU (as the GPU
 * renderer's grid) and its fogs. */
veil_result veil_pt_medium_from_scene(const veil_scene* s, veil_pt_medium** out, veil_error* err);
/* Same with the density given (copied), as veil_render_density. g may be
 * NULL for no volume (fog only). */
veil_result veil_pt_medium_from_density(const veil_scene* s, const veil_grid* g, const float* density,
                                        veil_pt_medium** out, veil_error* err);
void veil_pt_medium_free(veil_pt_medium* m); /* accepts NULL */
/* The voxel grid (NULL when the medium has none). */
const veil_grid* veil_pt_medium_grid(const veil_pt_medium* m);

typedef struct veil_pt_opts {
    int width, height;     /* 0: the camera's */
    int spp;               /* samples per pixel, >= 2 */
    int max_order;         /* 1: single scattering; K: up to K; 0: unlimited */
    uint64_t seed;
    int threads;           /* 0: one per core */
    const veil_camera* camera; /* NULL: the scene's */
    int stochastic_background; /* see above */
    int environment;       /* 1: background radiance also lights the medium */
    /* Called from one thread now and then (and at the end) with the rows
     * finished so far; may be NULL. */
    void (*progress)(void* user, int rows_done, int rows_total);
    void* progress_user;
} veil_pt_opts;

typedef struct veil_pt_stats {
    double ms;                /* wall time */
    uint64_t paths;           /* camera samples traced */
    uint64_t collisions;      /* tentative collisions, free flight and ratio tracking */
    uint64_t cut_walks;       /* walks cut at VEIL_PT_MAX_EVENTS */
    uint64_t majorant_misses; /* densities found above their majorant (a bug if not 0) */
    uint64_t dropped_samples; /* non-finite samples dropped */
} veil_pt_stats;

/* Renders into newly malloc'd *rgba (4 floats a pixel) and *stderr_rgb
 * (3 floats a pixel), top row first (free() both). VEIL_ERR_INVALID for
 * spp < 2, a bad image size or camera. */
veil_result veil_pt_render(const veil_pt_medium* m, const veil_scene* s, const veil_pt_opts* opts, float** rgba,
                           float** stderr_rgb, veil_pt_stats* stats, veil_error* err);

/* Building blocks, exposed for tests. ---------------------------------- */

/* Henyey-Greenstein sampling: given u1, u2 in [0, 1) and the unit direction
 * `dir` the path travels in, a unit direction whose cosine with dir has the
 * HG density veil_phase_hg (isotropic for g = 0), azimuth uniform. */
void veil_pt_sample_hg(const double dir[3], double g, double u1, double u2, double out[3]);

#endif
