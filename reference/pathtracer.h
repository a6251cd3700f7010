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
 *  - Point and spot lights, with light_sampling MIS (the default): on every
 *    segment of the path (the camera ray and each ray leaving a scattering
 *    vertex, so at every order) the light of each point/spot light l
 *    scattered once more on that segment,
 *      A_l = int_a^b T(t) sigma_s(t) Lnee_l(t) dt,
 *    is estimated by two strategies combined with the balance heuristic
 *    (Veach's multi-sample MIS, one sample of each):
 *      (d) next-event estimation at the walk's own scattering point t_d,
 *          weighted w_d = q_d / (q_d + P_l p_e,l);
 *      (e) one equiangular sample t_e a segment (Kulla & Fajardo, EGSR
 *          2012), towards light l chosen with probability P_l proportional
 *          to its power (sum of the channels) times (theta_b - theta_a) / D
 *          = int_a^b dt / r^2, on [a, b], the part of the segment where the
 *          walk can collide (from the first entry into the volume's box or
 *          a fog's box to the last exit): beta T(t_e) sigma_s(t_e)
 *          Lnee_l(t_e) / (P_l p_e,l + q_d), i.e. f / (P_l p_e,l) times
 *          w_e = P_l p_e,l / (q_d + P_l p_e,l).
 *    p_e,l is the equiangular density (veil_pt_equiangular_pdf) and q_d the
 *    density of the walk's scattering points: with spectral tracking the
 *    sum of the channel throughputs never changes, so the walk from a
 *    vertex with throughput beta scatters at t with density exactly
 *      q_d(t) = sum_c beta_c sigma_s,c rho(t) T_c(t) / sum_c beta_c
 *    (each channel's estimate is unbiased, E[beta'_c; scatter in dt] =
 *    beta_c sigma_s,c rho T_c dt; summed over c this is sum beta times the
 *    probability). w_d + w_e = 1 at every t, so the sum is unbiased for A_l
 *    whatever the densities; that they are the true ones keeps the variance
 *    low. T in (e) and in q_d is exact (the volume integrated per trilinear
 *    cell, the fog in closed form), deterministic, so the weights form a
 *    partition of unity and T / q_d, hence the estimate, stays bounded in
 *    thick media (ratio tracking there, unbiased but noisy, gave
 *    fireflies). The choice of l and [a, b] depend only on the segment.
 *    The equiangular point is a scattering vertex of order depth + 1,
 *    counted exactly when the walk's own collision on that segment would
 *    be, and (e) is added whatever the walk then does (scatter, absorb,
 *    escape): it is an independent second estimate. The walk itself
 *    (continuation, both Russian roulettes) is the same in both modes. A
 *    segment whose line passes within VEIL_PT_EQ_MIN_PERP (relative) of a
 *    light, or that meets no medium, has no equiangular strategy for that
 *    light (p_e = 0, so w_d = 1).
 *    Directional lights keep next-event estimation alone (weight 1).
 *    light_sampling DISTANCE is the estimator without (e): next-event
 *    estimation at the walk's scattering points only, weight 1 (the same
 *    random numbers, hence the same rgba up to rounding, as before MIS).
 *    What MIS does not remove: near a point light the radiance along a
 *    direction passing at distance D from it grows as 1/D, so a vertex near
 *    the light whose phase-sampled direction passes very close to it still
 *    carries a large (now exact-for-that-direction) value; its variance
 *    over directions diverges logarithmically and is the same for both
 *    strategies. At all orders in dense media around a light that term
 *    dominates (docs/accuracy.md has numbers); sampling directions towards
 *    the light as well would be the next step.
 *  - Emission (a vdb source's "emission" grid): on every segment of the
 *    path (the camera ray and each ray leaving a scattering vertex) the
 *    emitted radiance integrated along it, int T eps dt, deterministic
 *    (veil__pt_emission: exact T, eps trilinear at quarter-voxel steps), times
 *    the throughput; it counts when it reaches the camera after at most
 *    max_order scatterings (direct emission is order 0).
 *  - Continuation: the phase function sampled exactly (weight 1).
 *  - Path length: absorption is sampled as an event (the path ends with
 *    probability P_absorb: Russian roulette on absorption), and from the
 *    PT_RR_DEPTH-th vertex on a path continues with probability 0.95 and
 *    weight 1/0.95, so even an albedo-1 medium of any density ends paths
 *    after ~20 more vertices on average (unbiased, at some variance in the
 *    highest orders).
 *  - The background: background * T along the camera ray, T exact by
 *    default (the trilinear volume integrated exactly, as
 *    reference/optical_depth.h, plus the fog closed form: zero variance);
 *    with `stochastic_background` it is the delta-tracking escape estimate
 *    instead (tests check that estimator against closed forms). The
 *    background is what is seen behind the medium; it does not light the
 *    medium, as in the GPU pipeline, unless `environment` is set (the
 *    white-furnace test: then escaping paths of every order see it).
 *
 * Order: max_order = 1 counts the light scattered once (the GPU marcher's
 * quantity), K counts 1..K scatterings, 0 all of them.
 *
 * Determinism: pixel p's samples come from a generator seeded by (seed, p)
 * alone, so the image does not depend on the thread count or scheduling.
 *
 * Output: rgba as the GPU renderer's (a = 1 - mean transmittance of the
 * camera ray, exact unless stochastic_background), and per pixel the
 * standard error of the R, G, B means: sqrt(sample variance / n), n the
 * samples kept (spp less dropped ones), spp >= 2. The sample variance says
 * nothing when every sample of a channel was the same value (at low spp,
 * typically all 0: no sample scattered towards a light); the standard
 * error reported then is
 *  - 0 when the pixel's estimate could not have varied: its camera ray
 *    crosses no medium (exact transmittance 1 in every channel), or the
 *    scene has no light of non-zero colour, no environment and an exact
 *    background;
 *  - otherwise (an "unresolved" channel, counted in
 *    veil_pt_stats.unresolved_pixels) the bound R_c sqrt(p / n), with R_c
 *    the range (max - min) of the single-sample values of channel c over
 *    the whole image and p = 3/n, or, with an exact background and no
 *    equiangular sampling (light_sampling DISTANCE, or no point or spot
 *    light), min(3/n, 1 - mean_c T_c) (T the camera ray's exact
 *    transmittance). Why: an outcome unseen in n trials has probability
 *    p <= 3/n at 95 % confidence (the rule of three); where a sample can
 *    only differ from 0 after a real collision on the camera ray, p is also
 *    at most that collision's probability, 1 - mean_c T_c for the walk
 *    started with throughput (1, 1, 1) (spectral tracking keeps the sum of
 *    the throughputs, so the escape probability is sum_c T_c / 3); a sample
 *    that deviates by at most R with probability p has variance <= p R^2,
 *    so the mean's standard error is <= sqrt(p R^2 / n). (With MIS an
 *    equiangular sample can light a sample without any collision, so only
 *    the rule of three applies.) R_c is an assumption (the scale of a
 *    deviation as seen elsewhere in the image, the only evidence there
 *    is), not a proof: in a 1x1 image, or when no pixel saw light, it is 0
 *    and so is the bound; unresolved_pixels says how many pixels rest on
 *    it.
 * The bound is deterministic (a max and a min do not depend on the order
 * of the threads).
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
/* The equiangular strategy is left out for a light closer to the ray's line
 * than this fraction of its distance from the ray's origin: there the
 * density concentrates within ~1e-9 of the distance around the foot, where
 * the double-precision sample position (relative rounding 1e-16) still
 * resolves it 1e7 times finer than its width; at 0 (the light on the ray)
 * the density is a delta and the radiance integral diverges anyway. */
#define VEIL_PT_EQ_MIN_PERP 1e-9

/* How light from point and spot lights is sampled (see above). Zero means
 * the default, MIS; veil_pt_stats.light_sampling says what was used. */
typedef enum veil_pt_light_sampling {
    VEIL_PT_LIGHT_SAMPLING_DEFAULT = 0,
    VEIL_PT_LIGHT_SAMPLING_DISTANCE = 1, /* next-event estimation at delta-tracking collisions only */
    VEIL_PT_LIGHT_SAMPLING_MIS = 2       /* plus equiangular samples, balance heuristic */
} veil_pt_light_sampling;

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
    int light_sampling;    /* veil_pt_light_sampling; 0: MIS */
    /* NULL, or width*height bytes set to 1 where a channel's standard
     * error is the bound below ("unresolved"), 0 where it is a sample
     * estimate: `veil reference` writes it as the channel stderr.bound, so
     * that a comparison does not take a bound for noise. */
    unsigned char* unresolved;
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
    uint64_t unresolved_pixels; /* pixels with a channel whose samples were all equal but could have varied (above) */
    int light_sampling;       /* the veil_pt_light_sampling used (0 resolved) */
} veil_pt_stats;

/* Renders into newly malloc'd *rgba (4 floats a pixel) and *stderr_rgb
 * (3 floats a pixel), top row first (free() both). VEIL_ERR_INVALID for
 * spp < 2, a bad image size or camera, or an unknown light_sampling. */
veil_result veil_pt_render(const veil_pt_medium* m, const veil_scene* s, const veil_pt_opts* opts, float** rgba,
                           float** stderr_rgb, veil_pt_stats* stats, veil_error* err);

/* Building blocks, exposed for tests. ---------------------------------- */

/* Henyey-Greenstein sampling: given u1, u2 in [0, 1) and the unit direction
 * `dir` the path travels in, a unit direction whose cosine with dir has the
 * HG density veil_phase_hg (isotropic for g = 0), azimuth uniform. */
void veil_pt_sample_hg(const double dir[3], double g, double u1, double u2, double out[3]);

/* Equiangular sampling of a distance t in [a, b] along the ray o + t d
 * (d unit; metres) towards a point light at `light` (Kulla & Fajardo 2012):
 * with t0 the ray parameter of the foot of the perpendicular from the light
 * and D its length, t = t0 + D tan(theta), theta uniform between
 * theta_a = atan((a - t0) / D) and theta_b = atan((b - t0) / D), so
 *   p_e(t) = D / ((theta_b - theta_a) (D^2 + (t - t0)^2))   (m^-1),
 * the 1/r^2 of the light's falloff up to a constant. b may be INFINITY
 * (theta_b = pi/2). */
typedef struct veil_pt_equiangular {
    double t0;               /* foot of the perpendicular (m along the ray) */
    double D;                /* distance of the light from the ray's line (m), > 0 */
    double a, b;             /* the range (m) */
    double theta_a, theta_b; /* rad, theta_a < theta_b */
} veil_pt_equiangular;

/* Sets *e up; 0 (and *e unusable) when a < b fails, when the light is
 * closer to the ray's line than VEIL_PT_EQ_MIN_PERP times its distance
 * from o (D -> 0: the density would be a delta) or when the two angles
 * round to one. Never NaN for finite input. */
int veil_pt_equiangular_init(const double o[3], const double d[3], const double light[3], double a, double b,
                             veil_pt_equiangular* e);
/* The sample for u in [0, 1): t in [a, b], and *pdf = p_e(t). */
double veil_pt_equiangular_sample(const veil_pt_equiangular* e, double u, double* pdf);
/* p_e(t); 0 outside [a, b]. */
double veil_pt_equiangular_pdf(const veil_pt_equiangular* e, double t);

#endif
