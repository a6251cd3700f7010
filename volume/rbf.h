/* veil — RBF (Gaussian) particles: the density they describe, where it may be
 * cut off, and the seeded procedural generator.
 *
 * A particle is an isotropic Gaussian  rho(x) = c * exp(-a^2 |x - b|^2)
 * with amplitude c (density units, i.e. multiplied by the medium's sigma in
 * m^-1), sharpness a (m^-1) and centre b (m). Densities of particles add.
 *
 * Each Gaussian is splatted only inside the ball where it is at least
 * VEIL_RBF_CUTOFF times its peak: radius r_cut = sqrt(-ln(VEIL_RBF_CUTOFF))/a.
 * The mass beyond the cut is erfc-small: for the 3D Gaussian the fraction of
 * the integral outside r_cut is erfc(k) + 2k/sqrt(pi) e^{-k^2}, k = a r_cut,
 * which for CUTOFF = 1e-4 (k = 3.035) is 3.6e-4 (and every point outside the
 * ball receives less than 1e-4 of that particle's peak density).
 */
#ifndef VEIL_RBF_H
#define VEIL_RBF_H

#include <stddef.h>
#include <stdint.h>

#include "../core/result.h"
#include "../core/shared.glsl.h"

/* VEIL_RBF_CUTOFF (core/shared.glsl.h): fraction of a particle's peak
 * density below which it is not splatted. */

typedef struct veil_particle {
    float center[3]; /* m */
    float amplitude; /* density at the centre (unitless density) */
    float sharpness; /* a, m^-1: density c*exp(-a^2 r^2) */
} veil_particle;

/* Distance from the centre beyond which the particle is not splatted (m). */
float veil_rbf_cutoff_radius(const veil_particle* p);

/* Density of a set of particles at x (all particles, cut as the splat cuts). */
float veil_rbf_density(const veil_particle* p, size_t count, const float x[3]);

/* Seeded random particle cloud ("rbf_random" source). Radius r means
 * sharpness 1/r; centres uniform in bounds, radius and amplitude uniform in
 * their ranges, drawn in that order per particle from a SplitMix64 stream
 * (24-bit uniform floats), so the same seed gives the same particles on
 * every machine and compiler. */
typedef struct veil_rbf_random_desc {
    uint32_t count;
    uint64_t seed;
    float bounds[2][3]; /* min corner, max corner (m) */
    float radius[2];    /* r0, r1 (m), 0 < r0 <= r1 */
    float amplitude[2]; /* c0, c1, 0 <= c0 <= c1 */
} veil_rbf_random_desc;

/* Writes desc->count particles to out (caller-allocated). */
void veil_rbf_random_generate(const veil_rbf_random_desc* desc, veil_particle* out);

/* World-space box that holds every particle's cut-off ball; returns 0 when
 * count is 0 (box untouched). */
int veil_rbf_bounds(const veil_particle* p, size_t count, float lo[3], float hi[3]);

#endif
