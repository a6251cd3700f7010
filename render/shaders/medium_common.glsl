// veil — the medium and the lights as the march and the diffusion source
// pass see them (included with //@include): the march's uniform block, the
// EV and the optical-depth volumes, fogs in closed form.
layout(binding = VEIL_TEX_EV) uniform sampler3D u_ev;
layout(binding = VEIL_TEX_OPV0) uniform sampler3D u_opv[VEIL_MAX_OPV_TEXTURES];
layout(std140, binding = VEIL_UBO_MARCH) uniform veil_march_ubo { veil_march_block u; };

const float INF = 3.0e38;


// Slab test of o + t dir, t in [tmin, tmax]; empty when .x >= .y.
vec2 box_hit(vec3 o, vec3 dir, vec3 lo, vec3 hi, float tmin, float tmax)
{
    vec3 inv = 1.0 / dir; // +-inf on zero components: the slab test still holds...
    vec3 a = (lo - o) * inv, b = (hi - o) * inv;
    vec3 t0 = min(a, b), t1 = max(a, b);
    // ...except for o on a slab's plane (0 * inf = NaN): along a zero component
    // the ray is in that slab for every t, or for none
    bvec3 zero_dir = equal(dir, vec3(0.0));
    bvec3 in_slab = bvec3(greaterThanEqual(o, lo).x && lessThanEqual(o, hi).x,
                          greaterThanEqual(o, lo).y && lessThanEqual(o, hi).y,
                          greaterThanEqual(o, lo).z && lessThanEqual(o, hi).z);
    t0 = mix(t0, mix(vec3(INF), vec3(-INF), in_slab), zero_dir);
    t1 = mix(t1, mix(vec3(-INF), vec3(INF), in_slab), zero_dir);
    return vec2(max(max(t0.x, t0.y), max(t0.z, tmin)), min(min(t1.x, t1.y), min(t1.z, tmax)));
}

// Density integral of all fogs along p + t d, t in [t0, t1] (d unit).
float fog_integral(vec3 p, vec3 d, float t0, float t1)
{
    float sum = 0.0;
    for (int f = 0; f < u.size.w; ++f) {
        vec2 s = box_hit(p, d, u.fogs[f].box_min.xyz, u.fogs[f].box_max.xyz, t0, t1);
        if (s.x >= s.y) continue;
        float b = u.fogs[f].origin.w;
        float k0 = b * dot(p + d * s.x - u.fogs[f].origin.xyz, u.fogs[f].direction.xyz);
        float k1 = b * dot(p + d * s.y - u.fogs[f].origin.xyz, u.fogs[f].direction.xyz);
        sum += veil_exp_fog_integral(u.fogs[f].direction.w, k0, k1, s.y - s.x);
    }
    return sum;
}

// The EV's density integral from x to the light along unit direction `to`
// over length `len` (INF for a sun): the optical-depth volume at x, or at
// the point where that path enters the EV's box.
float ev_depth(int l, vec3 x, vec3 to, float len)
{
    if (u.flags.x == 0u) return 0.0;
    vec2 s = box_hit(x, to, u.box_min.xyz, u.box_max.xyz, 0.0, len);
    if (s.x > s.y) return 0.0;
    vec3 y = x + to * s.x;
    return texture(u_opv[l / 4], (y - u.tex_min.xyz) * u.tex_inv_size.xyz)[l % 4];
}

// Light l at x before the medium: the direction it travels, its irradiance
// E (W/m^2: I / r^2 for point and spot lights, with the cone; a sun's own)
// and the distance to it (INF for a sun). False when it adds nothing here.
bool light_at(int l, vec3 x, out vec3 travel, out vec3 E, out float len)
{
    if (int(u.lights[l].position.w) != VEIL_LIGHT_DIRECTIONAL) {
        vec3 to_light = u.lights[l].position.xyz - x;
        float r2 = max(dot(to_light, to_light), u.march.y);
        len = sqrt(r2);
        travel = -to_light / len;
        E = u.lights[l].color.rgb / r2;
        if (int(u.lights[l].position.w) == VEIL_LIGHT_SPOT)
            E *= veil_spot_falloff(dot(travel, u.lights[l].direction.xyz), u.lights[l].direction.w, u.lights[l].color.w);
    } else {
        travel = u.lights[l].direction.xyz;
        E = u.lights[l].color.rgb;
        len = INF;
    }
    return max(E.r, max(E.g, E.b)) > 0.0;
}

// The density integral from x to light l (EV and fogs). A fog's closed form
// overflows to +inf for rho0 e^60 len > 3.4e38: kept finite so that a channel
// with sigma_t = 0 gets exp(0) = 1, not exp(0 * inf) = NaN.
float depth_to_light(int l, vec3 x, vec3 travel, float len)
{
    return min(ev_depth(l, x, -travel, len) + fog_integral(x, -travel, 0.0, len), INF);
}
