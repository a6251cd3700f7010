/* veil — RBF (Gaussian) particles as plain data, and the seeded procedural
 * generators that make them.
 *
 * A particle is an isotropic Gaussian  rho(x) = c * exp(-a^2 |x - b|^2)
 * with amplitude c (density units, i.e. multiplied by the medium's sigma in
 * m^-1), sharpness a (m^-1) and centre b (m). Densities of particles add.
 * Where a particle is cut off when it is splatted is volume/rbf.h's
 * business; files of particles are io/particles.h's.
 */
#ifndef VEIL_PARTICLE_H
#define VEIL_PARTICLE_H

#include <stddef.h>
#include <stdint.h>

typedef struct veil_particle {
    float center[3]; /* m */
    float amplitude; /* density at the centre (unitless density) */
    float sharpness; /* a, m^-1: density c*exp(-a^2 r^2) */
} veil_particle;

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

/* Seeded value-noise fBm in [0, 1) at x: `octaves` octaves (frequency x2,
 * weight x0.5 each), normalised by the sum of the weights. Integer hashing
 * and float arithmetic in a fixed order: the same on every machine. */
float veil_particles_fbm(uint64_t seed, int octaves, const float x[3]);

/* amplitude *= (1 - amount) + amount * fbm(seed, octaves, center / scale),
 * for each particle; amount in [0, 1], scale > 0. */
void veil_particles_modulate(veil_particle* p, size_t n, uint64_t seed, float scale, int octaves, float amount);

#endif
