// veil — what the light cache's passes share (included after
// propagate/shaders/lit_medium.glsl): the cache block, the medium's density
// anywhere (the EV inside its box, plus every fog in its box) and, with
// emission, the EV's emission. volumetric/cache.h has the method.
#ifndef VEIL_CACHE_COMMON_GLSL
#define VEIL_CACHE_COMMON_GLSL
layout(std140, binding = VEIL_UBO_CACHE) uniform veil_cache_ubo { veil_cache_block cb; };
layout(binding = VEIL_TEX_EMISSION) uniform sampler3D u_emission; // W m^-3 sr^-1 on the EV's grid (or atlas)

bool in_ev_box(vec3 x)
{
    return med.counts.z != 0 && all(greaterThanEqual(x, med.box_min.xyz)) && all(lessThanEqual(x, med.box_max.xyz));
}

// A fog's density at x (0 outside its box); the exponent capped as in
// veil_exp_fog_integral.
float fog_density(int f, vec3 x)
{
    if (any(lessThan(x, med.fogs[f].box_min.xyz)) || any(greaterThan(x, med.fogs[f].box_max.xyz))) return 0.0;
    float k = med.fogs[f].origin.w * dot(x - med.fogs[f].origin.xyz, med.fogs[f].direction.xyz);
    return med.fogs[f].direction.w * exp(-max(k, -VEIL_FOG_MAX_EXPONENT));
}

// The medium's density at x: the EV (trilinear, as the march reads it) and the fogs.
float cache_density(vec3 x)
{
    float d = in_ev_box(x) ? ev_density(x) : 0.0;
    for (int f = 0; f < med.counts.y; ++f) d += fog_density(f, x);
    return d;
}

// The EV's emission at x (inside its box), as the march reads it.
vec3 cache_emission(vec3 x)
{
#ifdef VEIL_SPARSE
    vec3 q = (x - sp.origin.xyz) / sp.origin.w;
    ivec3 b = sp_brick(q);
    int region;
    uint slot = sp_slot(b, region);
    return slot == 0u ? vec3(0.0) : texture(u_emission, sp_atlas_uvw(slot, b, q)).rgb;
#else
    return texture(u_emission, (x - med.tex_min.xyz) * med.tex_inv_size.xyz).rgb;
#endif
}
#endif
