// veil — the slab test every pass that clips rays to boxes uses (included;
// guarded, so a shader may meet it twice through its includes).
#ifndef VEIL_BOX_HIT_GLSL
#define VEIL_BOX_HIT_GLSL
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
#endif
