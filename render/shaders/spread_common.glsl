// veil — what the spread passes share (included with //@include).
layout(std140, binding = VEIL_UBO_SPREAD) uniform veil_spread_ubo { veil_spread_block u; };

float lum(vec3 c) { return dot(c, vec3(VEIL_LUM_R, VEIL_LUM_G, VEIL_LUM_B)); }

// Tap i of the 1D filter.
float tap(int i) { return i < 4 ? u.weights_lo[i] : u.weights_hi[i - 4]; }

// The level to read for a density integral P seen at s pixels per metre.
float level_of(float P, float s)
{
    float W = veil_spread_width(P, u.sigma_a.w, u.sigma_s.w, u.params.z) * s;
    return veil_spread_level(W, u.params.x, float(u.mode.z));
}
