/* veil — the light cache: the light that scattered at least once, traced
 * from every source by photons on the GPU, kept on a coarse grid the march
 * samples (VEIL_FIELD_CACHE, volumetric/volumetric.h). Part of the
 * volumetric stage; internal to volumetric/.
 *
 * What it holds, per cell of a grid over the medium (the EV's box and the
 * fogs' boxes): the fluence phi (W/m^2, rgb) of light that has scattered at
 * least once — for the medium's emission, of all its light, scattered or
 * not — and the luminance-weighted flux F (W/m^2, a vector); and the same
 * two of the later light alone, scattered more than once (emission: at
 * least once). The march (render/shaders/march.comp, cache_in) adds per
 * unit length, for the light scattered once,
 *   sigma_s rho phi p_HG(F^ . w_o; g |F| / phi_lum):
 * its radiance taken as one Henyey-Greenstein lobe about F with mean
 * cosine |F| / phi (an HG lobe's first moment is g times its axis),
 * scattered by the medium's HG(g); HG convolved with HG is HG with the
 * product of the g's (their Legendre coefficients g^l multiply). The later
 * light the same, but with the phase function's forward peak (f = g^2, as
 * delta-Eddington) carried along the camera's ray by a reduced extinction
 * instead of by the lobe. So the march's own single scattering (exact, with
 * the optical depths) plus the cache's orders >= 2 count every order once.
 *
 * The estimator (volumetric/shaders/cache_trace.comp): photons start at a
 * source with power Phi (a sun: on a rectangle across its light covering
 * the grid's box, E A / N each; a point or spot light: in a cone covering
 * the box, or the whole sphere from inside, I Omega / N each, a spot's
 * falloff applied per photon; emission: in a cell chosen with probability
 * p_k proportional to its emission weight, 4 pi V eps(x) / (p_k N); the
 * environment's rest: a texel block k of solid angle Omega_k with
 * probability p_k proportional to its luminance times Omega_k, a direction
 * uniform in it, a start uniform on the disc of area A = pi r^2 across it
 * that covers the grid's bounding sphere (radius r), L_k Omega_k A /
 * (p_k N) each), are
 * tracked by delta tracking against the cells' majorants (cache_bounds.comp),
 * and every piece of path of length l in a cell of volume V adds w l / V to
 * its fluence (the track-length estimator: E[sum of l] over photons is the
 * fluence times V) and lum(w) l omega / V to its flux.
 *
 * The fixed point: a piece of path scores at most s_max = 3 Phi_max
 * sqrt(3) h / V (a photon's channel weights sum to at most 3 Phi_max and
 * never grow, cache_trace.comp; a piece is at most a cell's diagonal); a
 * photon's visit to a cell is added once, before it holds more than
 * VEIL_CACHE_VISIT_DIAGONALS (2^10) diagonals of path. With
 * 2^VEIL_CACHE_FIXED_BITS (2^20) units to s_max, one add is at most 2^30
 * units, an int32, and a cell's signed 64-bit sum holds 2^33 adds. Each add
 * is floor(s u + xi): unbiased, within one unit (s_max 2^-20) of s; the
 * noise it adds is below 1/2 unit per add in standard deviation, ~5e-7 of a
 * piece's largest score.
 */
#ifndef VEIL_CACHE_H
#define VEIL_CACHE_H

#include <epoxy/gl.h>
#include <stdint.h>

#include "../core/result.h"
#include "../core/shared.glsl.h"
#include "../propagate/lit_medium.h"

/* The cache's budget and the one random stream it draws from. */
typedef struct veil_cache_settings {
    long long photons; /* in all, shared among the sources by their power (>= 1) */
    int cells;         /* along the grid's longest side (4..512) */
    uint32_t seed;     /* the same seed, medium and lights give the same cache, bit for bit */
    int emission;      /* 1: the medium's emission is a source (the cache carries all its light) */
    int environment;   /* 1: the scene environment's rest is a source (scene/environment.h: the cache carries all
                          its light; its bright part is the median cut's lights) */
    size_t env_texels; /* its photon table's texels at most (0: VEIL_ENV_TABLE_TEXELS; a larger map is averaged
                          over blocks) */
} veil_cache_settings;

typedef struct veil_cache_report {
    int dims[3];
    float cell;            /* m */
    long long photons;     /* traced, all sources */
    int sources;           /* lights (and the emission) that sent photons */
    double noise;          /* the cells' relative noise, fluence-weighted RMS (odd against even photons) */
    double bytes;          /* device memory while it is built (sums, majorants, the two fields) */
    unsigned cut, clamped; /* photons cut at `cap` steps; scores over the fixed point's bound */
    unsigned misses;       /* tentative collisions where the density was above the cell's majorant (a bug if not 0) */
    int cap;               /* a photon's step cap */
    double steps;          /* the steps a photon takes, as estimated from the cells' majorants */
    long long asked;       /* the photons the budget asked for (more than `photons`: the medium is thick) */
    int too_thick;         /* 1: even VEIL_CACHE_MIN_PHOTONS would take over the budget: no cache (*tex 0), or,
                              with the environment's rest, its photons alone, each to its first scattering */
    double env_rest[3];    /* the environment's rest a source: its integral over the sphere (W/m^2), else 0 */
    /* The energy account (core/shared.glsl.h), W per channel: [VEIL_CACHE_ENERGY_IN] the light that
     * scattered (or was emitted), [_OUT] what of it left the grid, [_ABSORBED] what was absorbed,
     * [_COLLISIONS] the collision estimator of the integral of sigma_t phi (W), [_TRACK] the track length
     * sum, the integral of phi (W m: the cells' fluence times their volume, summed); [_LATER_IN] and
     * [_LATER_TRACK] the same two of the later light (scattered again; emission: scattered); in all and per group
     * of photons (photon n in group n mod VEIL_CACHE_ENERGY_GROUPS). Photons cut at `cap` are left out. */
    double energy[VEIL_CACHE_ENERGY_KINDS][3];
    double energy_groups[VEIL_CACHE_ENERGY_GROUPS][VEIL_CACHE_ENERGY_KINDS][3];
} veil_cache_report;

/* Programs of the cache's passes (dense, and sparse made when first needed; the photons' also with a frame's
 * solid, trace[2 + sparse]: scene/solid.h). */
typedef struct veil_cache_programs {
    GLuint bounds[2], trace[4], resolve, ubo;
} veil_cache_programs;

veil_result veil__cache_programs(veil_cache_programs* p, int sparse, int solid, veil_error* err);
void veil__cache_programs_free(veil_cache_programs* p);

/* At most this many cells (196 bytes each while built: the 64-bit sums,
 * majorant, free part and the texture; its 80 kept: 822 MB and 335 MB): a
 * grid that would have more is made coarser until it fits. */
#define VEIL_CACHE_MAX_CELLS (1 << 22)

/* The grid: its min corner lo, cell edge h and dims, over the EV's box and
 * the fogs' boxes (the EV's alone when they would be wider than
 * VEIL_DIFFUSION_MAX_EXTENT), `cells` along the longest side (fewer when
 * that would be over VEIL_CACHE_MAX_CELLS). 0: none. */
int veil__cache_grid(const veil_lit_medium* md, int cells, float lo[3], float* h, int dims[3]);

/* Builds the cache of md on the grid (lo, h, dims) into a new rgba32f
 * texture of dims[0] x dims[1] x VEIL_CACHE_SLABS dims[2] texels (core/shared.glsl.h): the fluence rgb (a: the
 * odd photons' luminance fluence) at z < dims[2], the flux xyz above. The
 * medium block mu is md's (veil_lit_medium_fill). */
veil_result veil__cache_build(veil_cache_programs* p, const veil_lit_medium* md, const veil_medium_block* mu,
                              const float lo[3], float h, const int dims[3], const veil_cache_settings* s,
                              GLuint* tex, veil_cache_report* rep, veil_error* err);

#endif
