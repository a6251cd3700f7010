// veil — the random numbers and directions of the light cache's passes
// (cache_trace.comp's photons, render/shaders/cache_gather.comp's rays):
// a PCG stream in the global `state`, seeded through mix32.
#ifndef VEIL_CACHE_RANDOM_GLSL
#define VEIL_CACHE_RANDOM_GLSL
uint state;

uint mix32(uint x)
{
    x ^= x >> 16; x *= 0x7feb352du;
    x ^= x >> 15; x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// PCG (O'Neill 2014: an LCG step, a permuted output): 24 bits in [0, 1)
float rnd()
{
    state = state * 747796405u + 2891336453u;
    uint w = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    w = (w >> 22u) ^ w;
    return float(w >> 8) * (1.0 / 16777216.0);
}

// A unit vector at cos_t from axis a, azimuth phi.
vec3 around(vec3 a, float cos_t, float phi)
{
    vec3 t = abs(a.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    vec3 e1 = normalize(cross(a, t)), e2 = cross(a, e1);
    float sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
    return normalize(a * cos_t + (e1 * cos(phi) + e2 * sin(phi)) * sin_t);
}

// The cos of Henyey-Greenstein g at its CDF's xi (xi uniform: cos distributed as HG).
float hg_cos(float g, float xi)
{
    if (abs(g) < 1e-3) return 1.0 - 2.0 * xi;
    float s = (1.0 - g * g) / (1.0 - g + 2.0 * g * xi);
    return clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
}
#endif
