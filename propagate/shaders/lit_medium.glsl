// veil — the medium and its lights as every pass after propagation sees
// them (the march, the volumetric stage; included with //@include): the
// camera-free medium block (veil_medium_block, propagate/lit_medium.h), the
// EV and the optical-depth volumes, fogs in closed form.
// With VEIL_SPARSE the EV is an atlas of bricks (volume/sparse.h), read
// through volume/shaders/sparse_common.glsl, and so are the optical depths.
layout(binding = VEIL_TEX_OPV0) uniform sampler3D u_opv[VEIL_MAX_OPV_TEXTURES];
layout(std140, binding = VEIL_UBO_MEDIUM) uniform veil_medium_ubo { veil_medium_block med; };
//@include volume/shaders/box_hit.glsl
#ifdef VEIL_SPARSE
//@include volume/shaders/sparse_common.glsl
#else
layout(binding = VEIL_TEX_EV) uniform sampler3D u_ev;
// lights' light-space grids, a layer a node plane (the lookup reads one: bilinear, 4 texels)
layout(binding = VEIL_TEX_SUN0) uniform sampler2DArray u_sun[VEIL_MAX_SUNS];
#endif

// The EV's density at x (inside its box).
float ev_density(vec3 x)
{
#ifdef VEIL_SPARSE
    return sp_density((x - sp.origin.xyz) / sp.origin.w);
#else
    return texture(u_ev, (x - med.tex_min.xyz) * med.tex_inv_size.xyz).r;
#endif
}


// Density integral of all fogs along p + t d, t in [t0, t1] (d unit).
float fog_integral(vec3 p, vec3 d, float t0, float t1)
{
    float sum = 0.0;
    for (int f = 0; f < med.counts.y; ++f) {
        vec2 s = box_hit(p, d, med.fogs[f].box_min.xyz, med.fogs[f].box_max.xyz, t0, t1);
        if (s.x >= s.y) continue;
        float b = med.fogs[f].origin.w;
        float k0 = b * dot(p + d * s.x - med.fogs[f].origin.xyz, med.fogs[f].direction.xyz);
        float k1 = b * dot(p + d * s.y - med.fogs[f].origin.xyz, med.fogs[f].direction.xyz);
        sum += veil_exp_fog_integral(med.fogs[f].direction.w, k0, k1, s.y - s.x);
    }
    return sum;
}

// The EV's density integral from x to the light along unit direction `to`
// over length `len` (INF for a sun): the optical-depth volume at x, or at
// the point where that path enters the EV's box. With `grid` true, from
// light-space grid k (light l's: med.sun_of), else from light l's channel of
// the OPVs; `persp`: grid k is a point or spot light's (med.sun_light[k].w).
// A caller that knows `grid` and `persp` when the shader is compiled passes
// constants (the march's light list): llvmpipe runs both sides of a branch
// it cannot fold, and the grid's side cost the march 1.35x in every light's
// lookup (docs/performance.md). Where `persp` is not constant both forms'
// coordinates are computed (arithmetic only) and one texture read serves.
float ev_depth_in(int l, bool grid, bool persp, int k, vec3 x, vec3 to, float len)
{
    if (med.counts.z == 0) return 0.0;
#ifdef VEIL_SPARSE
    // in a kept brick, the optical-depth atlas; elsewhere (fog around the
    // volume) the path to the light, marched through the bricks it meets
    vec3 q = (x - sp.origin.xyz) / sp.origin.w;
    ivec3 b = sp_brick(q);
    int region;
    uint slot = sp_slot(b, region);
    if (slot != 0u) return texture(u_opv[l / 4], sp_atlas_uvw(slot, b, q))[l % 4];
    return sp_integral(q, to, 0.0, min(len / sp.origin.w, INF), VEIL_SPARSE_OD_STEP) * sp.origin.w;
#else
    vec2 s = box_hit(x, to, med.box_min.xyz, med.box_max.xyz, 0.0, len);
    if (s.x > s.y) return 0.0;
    vec3 y = x + to * s.x; // where the path enters the box; s.y - s.x of it lies inside
    if (grid) { // a light in its light-space grid (propagate/sun_space.h)
        // D on the node plane just towards the light (bilinear within the
        // plane, none between planes) plus the density over the stretch
        // back to y, midpoint rule in sun_step.z pieces of at most a voxel:
        // interpolating between planes over-darkened the lit faces, where D
        // rises from 0 within one node spacing (docs/performance.md)
        vec4 p = vec4(y, 1.0);
        vec3 q = vec3(dot(med.sun_map[3 * k], p), dot(med.sun_map[3 * k + 1], p), dot(med.sun_map[3 * k + 2], p));
        float c = q.z * med.sun_step[k].y - 0.5;
        float c0 = max(floor(c), 0.0);
        float back = (c - c0) * med.sun_step[k].x; // m to the plane, towards the light
        q.z = c0;
        if (persp) { // the face of the cube around the light that y lies in, (u, v) and depth z there
            vec3 w = (y - med.sun_light[k].xyz) / med.shape.y, aw = abs(w);
            // the major axis a, and w's components after it in turn (swizzles picked by selects: a
            // vector indexed by a varying int is slow on llvmpipe)
            bool ax = aw.x >= aw.y && aw.x >= aw.z, ay = !ax && aw.y >= aw.z;
            vec3 r = ax ? w.yzx : ay ? w.zxy : w.xyz; // (u, v, signed depth) numerators
            float z = max(abs(r.z), 1e-6);
            vec2 uv = r.xy / z;
            int f = 12 * k + 2 * (2 * (ax ? 0 : ay ? 1 : 2) + (r.z < 0.0 ? 1 : 0));
            vec4 F = med.sun_face[f], P = med.sun_face[f + 1], T = med.sun_map[3 * k];
            float cz = clamp(floor((z - F.w) / T.w), 0.0, P.w - 1.0);
            back = max(z - (F.w + cz * T.w), 0.0) / z * length(w) * med.shape.y;
            vec2 t = clamp((uv - F.xy) / F.z, vec2(0.0), P.yz - 1.0);
            q = vec3((t + 0.5) / T.xy, P.x + cz);
        }
        float D = texture(u_sun[k], q).r;
        // the stretch's part in the box (the medium ends at its faces: a piece across one would
        // count density beyond it)
        back = min(back, s.y - s.x);
        int n = int(med.sun_step[k].z);
        float piece = back / float(n);
        for (int i = 0; i < n && back > 0.0; ++i) D += ev_density(y + to * (piece * (float(i) + 0.5))) * piece;
        return D;
    }
    return texture(u_opv[l / 4], (y - med.tex_min.xyz) * med.tex_inv_size.xyz)[l % 4];
#endif
}

// The light-space grid holding light l, -1 for none (med.sun_of).
int sun_of(int l) { return med.sun_of[l / 4][l % 4] - 1; }

// The lights read from the OPVs (med.on_opv, med.counts.w of them) and those
// from light-space grids (med.counts.x - med.counts.w: grid k holds light
// med.sun_step[k].w, a sun, point or spot light), for loops that take each
// kind apart.
int opv_lights() { return med.counts.w; }
int opv_light(int i) { return med.on_opv[i / 4][i % 4]; }
int grid_suns() { return med.counts.x - med.counts.w; }
int grid_sun_light(int k) { return int(med.sun_step[k].w); }

#ifdef VEIL_SOLID
// The surfaces of a frame under `veil fog` (scene/solid.h): solid voxels,
// and per light the distance along its path to the first of them. A
// variant: without a solid the shaders are compiled without it (llvmpipe
// runs the texture reads of a branch not taken).
layout(binding = VEIL_TEX_SOLID) uniform sampler3D u_solid;
layout(binding = VEIL_TEX_SHADOW) uniform sampler2DArray u_shadow;

// Unit directions on [0, 1]^2, octahedrally (scene/solid.c: oct_encode).
vec2 oct_encode(vec3 w)
{
    vec2 p = w.xy / (abs(w.x) + abs(w.y) + abs(w.z));
    if (w.z < 0.0) p = (1.0 - abs(p.yx)) * vec2(p.x >= 0.0 ? 1.0 : -1.0, p.y >= 0.0 ? 1.0 : -1.0);
    return 0.5 * p + 0.5;
}

// How much of light l reaches x past the frame's solid: its shadow map's
// four nearest texels, each lit where x is no further along the light's
// path than the first solid (plus the bias), weighted bilinearly
// (veil_solid_visibility computes the same).
float solid_visibility(int l, vec3 x)
{
    if (l >= med.solid_dims.w) return 1.0;
    vec2 uv;
    float dist;
    if (int(med.lights[l].position.w) == VEIL_LIGHT_DIRECTIONAL) {
        vec4 p = vec4(x, 1.0);
        uv = vec2(dot(med.shadow[3 * l], p), dot(med.shadow[3 * l + 1], p));
        if (!(all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0))))) return 1.0;
        dist = dot(x, med.lights[l].direction.xyz);
    } else {
        vec3 w = x - med.lights[l].position.xyz;
        dist = length(w);
        if (!(dist > 0.0)) return 1.0;
        uv = oct_encode(w / dist);
    }
    float bias = med.shadow[3 * l + 2].x + med.shadow[3 * l + 2].y * dist;
    vec2 f = uv * float(VEIL_SOLID_MAP) - 0.5, f0 = floor(f), a = f - f0;
    ivec2 i0 = clamp(ivec2(f0), ivec2(0), ivec2(VEIL_SOLID_MAP - 1));
    ivec2 i1 = clamp(ivec2(f0) + 1, ivec2(0), ivec2(VEIL_SOLID_MAP - 1));
    vec4 lit = vec4(dist <= texelFetch(u_shadow, ivec3(i0.x, i0.y, l), 0).r + bias ? 1.0 : 0.0,
                    dist <= texelFetch(u_shadow, ivec3(i1.x, i0.y, l), 0).r + bias ? 1.0 : 0.0,
                    dist <= texelFetch(u_shadow, ivec3(i0.x, i1.y, l), 0).r + bias ? 1.0 : 0.0,
                    dist <= texelFetch(u_shadow, ivec3(i1.x, i1.y, l), 0).r + bias ? 1.0 : 0.0);
    return mix(mix(lit.x, lit.y, a.x), mix(lit.z, lit.w, a.x), a.y);
}

// The first solid along p + t d, t in [0, t_max] (d unit): samples every
// half voxel from where the path enters the solid's box, the first a
// quarter voxel in (veil_solid_hit steps the same); t_max where none.
float solid_hit(vec3 p, vec3 d, float t_max)
{
    float h = med.solid_origin.w;
    if (!(h > 0.0)) return t_max;
    vec3 lo = med.solid_origin.xyz;
    vec2 s = box_hit(p, d, lo, lo + vec3(med.solid_dims.xyz) * h, 0.0, t_max);
    for (float t = s.x + 0.25 * h; t < s.y; t += 0.5 * h) {
        ivec3 c = ivec3(floor((p + d * t - lo) / h));
        if (all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, med.solid_dims.xyz)) && texelFetch(u_solid, c, 0).r > 0.0)
            return t;
    }
    return t_max;
}
#endif

// Light l at x before the medium: the direction it travels, its irradiance
// E (W/m^2: I / r^2 for point and spot lights, with the cone; a sun's own;
// less what a frame's surfaces shadow) and the distance to it (INF for a
// sun). False when it adds nothing here.
// `kind` is light l's (med.lights[l].position.w), a constant where the caller
// knows it (as `grid` in ev_depth_in).
bool light_at_kind(int l, int kind, vec3 x, out vec3 travel, out vec3 E, out float len)
{
    if (kind != VEIL_LIGHT_DIRECTIONAL) {
        vec3 to_light = med.lights[l].position.xyz - x;
        float r2 = max(dot(to_light, to_light),
                       kind == VEIL_LIGHT_POINT ? max(med.shape.x, med.lights[l].direction.w) : med.shape.x);
        len = sqrt(r2);
        travel = -to_light / len;
        E = med.lights[l].color.rgb / r2;
        if (kind == VEIL_LIGHT_SPOT)
            E *= veil_spot_falloff(dot(travel, med.lights[l].direction.xyz), med.lights[l].direction.w, med.lights[l].color.w);
    } else {
        travel = med.lights[l].direction.xyz;
        E = med.lights[l].color.rgb;
        len = INF;
    }
#ifdef VEIL_SOLID
    E *= solid_visibility(l, x);
#endif
    return max(E.r, max(E.g, E.b)) > 0.0;
}

bool light_at(int l, vec3 x, out vec3 travel, out vec3 E, out float len)
{
    return light_at_kind(l, int(med.lights[l].position.w), x, travel, E, len);
}

// The density integral from x to light l (EV and fogs). A fog's closed form
// overflows to +inf for rho0 e^60 len > 3.4e38: kept finite so that a channel
// with sigma_t = 0 gets exp(0) = 1, not exp(0 * inf) = NaN.
// `grid`, `persp` and k as in ev_depth_in.
float depth_to_light_in(int l, bool grid, bool persp, int k, vec3 x, vec3 travel, float len)
{
    return min(ev_depth_in(l, grid, persp, k, x, -travel, len) + fog_integral(x, -travel, 0.0, len), INF);
}

float depth_to_light(int l, vec3 x, vec3 travel, float len)
{
    int k = sun_of(l);
    return depth_to_light_in(l, k >= 0, k >= 0 && med.sun_light[max(k, 0)].w > 0.5, max(k, 0), x, travel, len);
}
