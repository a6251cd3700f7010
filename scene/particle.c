/* veil — procedural particles: the seeded random cloud and the fBm value
 * noise that modulates amplitudes (scene/particle.h). */
#include "particle.h"

#include <math.h>

#include "../core/rng.h"

static float lerp(float a, float b, float t) { return a + (b - a) * t; }

void veil_rbf_random_generate(const veil_rbf_random_desc* d, veil_particle* out)
{
    uint64_t state = d->seed;
    for (uint32_t i = 0; i < d->count; ++i) {
        veil_particle* p = &out[i];
        for (int k = 0; k < 3; ++k) p->center[k] = lerp(d->bounds[0][k], d->bounds[1][k], veil_rng_float24(&state));
        float r = lerp(d->radius[0], d->radius[1], veil_rng_float24(&state));
        p->sharpness = 1.0f / r;
        p->amplitude = lerp(d->amplitude[0], d->amplitude[1], veil_rng_float24(&state));
    }
}

/* ---- fBm value noise --------------------------------------------------- */

/* Lattice value in [0, 1), 24 bits: exact as a float. */
static float lattice(uint64_t key, int64_t x, int64_t y, int64_t z)
{
    uint64_t h = veil_mix64(key ^ (uint64_t)x);
    h = veil_mix64(h ^ (uint64_t)y);
    h = veil_mix64(h ^ (uint64_t)z);
    return (float)(h >> 40) * (1.0f / 16777216.0f);
}

/* Trilinear value noise with a smoothstep fade, in [0, 1). */
static float value_noise(uint64_t key, const float x[3])
{
    int64_t i[3];
    float t[3];
    for (int a = 0; a < 3; ++a) {
        float v = x[a];
        if (!(v > -1e15f)) v = -1e15f; /* also NaN */
        if (v > 1e15f) v = 1e15f;
        float fl = floorf(v);
        i[a] = (int64_t)fl;
        float f = v - fl;
        t[a] = f * f * (3.0f - 2.0f * f);
    }
    float c[2][2];
    for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
            c[dz][dy] = lerp(lattice(key, i[0], i[1] + dy, i[2] + dz), lattice(key, i[0] + 1, i[1] + dy, i[2] + dz),
                              t[0]);
    return lerp(lerp(c[0][0], c[0][1], t[1]), lerp(c[1][0], c[1][1], t[1]), t[2]);
}

float veil_particles_fbm(uint64_t seed, int octaves, const float x[3])
{
    float sum = 0.0f, norm = 0.0f, w = 1.0f, freq = 1.0f;
    for (int o = 0; o < octaves; ++o) {
        float y[3] = {x[0] * freq, x[1] * freq, x[2] * freq};
        sum += w * value_noise(veil_mix64(seed + VEIL_RNG_GAMMA * (uint64_t)(o + 1)), y);
        norm += w;
        w *= 0.5f, freq *= 2.0f;
    }
    if (!(norm > 0.0f)) return 0.0f;
    float n = sum / norm;
    return n < 0.99999994f ? (n > 0.0f ? n : 0.0f) : 0.99999994f;
}

void veil_particles_modulate(veil_particle* p, size_t n, uint64_t seed, float scale, int octaves, float amount)
{
    if (!(amount > 0.0f) || !(scale > 0.0f) || octaves < 1) return;
    for (size_t i = 0; i < n; ++i) {
        float x[3] = {p[i].center[0] / scale, p[i].center[1] / scale, p[i].center[2] / scale};
        p[i].amplitude *= (1.0f - amount) + amount * veil_particles_fbm(seed, octaves, x);
    }
}
