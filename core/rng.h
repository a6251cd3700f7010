/* veil — the one random generator: SplitMix64 (Steele, Lea, Flood 2014), a
 * 64-bit counter through a mixing function. Fixed-width integer arithmetic
 * only, so a seed gives the same stream on every machine and compiler: the
 * procedural particles, the noise lattice, the path tracer's per-pixel
 * streams and the tests all draw from it.
 */
#ifndef VEIL_RNG_H
#define VEIL_RNG_H

#include <stdint.h>

/* The counter's increment (2^64 / golden ratio, odd). */
#define VEIL_RNG_GAMMA 0x9E3779B97F4A7C15ull

/* SplitMix64's finaliser: a bijective 64-bit mix (also a lattice hash). */
static inline uint64_t veil_mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* The next output of the stream whose state is *state. */
static inline uint64_t veil_splitmix64(uint64_t* state)
{
    return veil_mix64(*state += VEIL_RNG_GAMMA);
}

/* Uniform in [0, 1) with 24 random bits: exactly representable in float. */
static inline float veil_rng_float24(uint64_t* state)
{
    return (float)(veil_splitmix64(state) >> 40) * (1.0f / 16777216.0f);
}

/* Uniform in [0, 1) with 53 random bits: exactly representable in double. */
static inline double veil_rng_double53(uint64_t* state)
{
    return (double)(veil_splitmix64(state) >> 11) * (1.0 / 9007199254740992.0);
}

#endif
