#include "rbf.h"

#include <math.h>

float veil_rbf_cutoff_radius(const veil_particle* p)
{
    /* c exp(-a^2 r^2) = CUTOFF c  <=>  r = sqrt(-ln CUTOFF) / a */
    return sqrtf(-logf((float)VEIL_RBF_CUTOFF)) / p->sharpness;
}

float veil_rbf_density(const veil_particle* p, size_t count, const float x[3])
{
    float sum = 0.0f;
    for (size_t i = 0; i < count; ++i) {
        float dx = x[0] - p[i].center[0], dy = x[1] - p[i].center[1], dz = x[2] - p[i].center[2];
        float r2 = dx * dx + dy * dy + dz * dz;
        float rc = veil_rbf_cutoff_radius(&p[i]);
        if (r2 <= rc * rc) sum += p[i].amplitude * expf(-p[i].sharpness * p[i].sharpness * r2);
    }
    return sum;
}

/* SplitMix64 (Steele, Lea, Flood 2014): a 64-bit counter through a mixing
 * function; fixed-width integer arithmetic only, so identical everywhere. */
static uint64_t splitmix64(uint64_t* state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1) with 24 random bits: exactly representable in float. */
static float uniform01(uint64_t* state)
{
    return (float)(splitmix64(state) >> 40) * (1.0f / 16777216.0f);
}

static float lerp(float a, float b, float t) { return a + (b - a) * t; }

void veil_rbf_random_generate(const veil_rbf_random_desc* d, veil_particle* out)
{
    uint64_t state = d->seed;
    for (uint32_t i = 0; i < d->count; ++i) {
        veil_particle* p = &out[i];
        for (int k = 0; k < 3; ++k) p->center[k] = lerp(d->bounds[0][k], d->bounds[1][k], uniform01(&state));
        float r = lerp(d->radius[0], d->radius[1], uniform01(&state));
        p->sharpness = 1.0f / r;
        p->amplitude = lerp(d->amplitude[0], d->amplitude[1], uniform01(&state));
    }
}

int veil_rbf_bounds(const veil_particle* p, size_t count, float lo[3], float hi[3])
{
    if (count == 0) return 0;
    for (int k = 0; k < 3; ++k) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    for (size_t i = 0; i < count; ++i) {
        if (p[i].amplitude <= 0.0f) continue; /* contributes nothing */
        float rc = veil_rbf_cutoff_radius(&p[i]);
        for (int k = 0; k < 3; ++k) {
            lo[k] = fminf(lo[k], p[i].center[k] - rc);
            hi[k] = fmaxf(hi[k], p[i].center[k] + rc);
        }
    }
    return lo[0] <= hi[0];
}
