// veil — single-scattering ray marcher, one invocation per pixel.
// The medium: the extinction volume (EV, trilinear over the box its voxel
// centres span) plus up to VEIL_MAX_FOGS analytic exponential fogs, each in
// its box. A ray is marched over the span of those boxes; where it is in
// none of them it jumps ahead. Steps are u_step (m) inside the EV's box and
// grow with distance outside it (fog: VEIL_FOG_STEP_FRACTION of the
// distance travelled, at most a quarter of the way to the nearest point
// light); the first step is shortened by a per-pixel jitter in (0, 1] so
// step boundaries differ between neighbours (noise, not banding).
// Per step: the EV's density at the midpoint times the step, plus each
// fog's exact integral over the step (closed form), give the step's
// optical thickness x; in-scattering is integrated in closed form for light
// that is constant over the step:
//   L += T * sigma_s * (density integral) * L_in * (1 - exp(-x)) / x
//   T *= exp(-x)
// L_in sums the lights: exp(-sigma_t (D_ev + D_fog)) times I/|S-X|^2 (point;
// spot: times its cone falloff) or E (directional), times the phase
// function. D_ev is read from the optical-depth volume at X, or, outside the
// EV's box, where the path to the light enters the box; D_fog is closed form.
// Empty space: where a brick of the EV and the voxel ring around it hold no
// density (render/shaders/occupancy.comp) every sample in it would add
// nothing, so without fog the march jumps to where the ray leaves the brick.
// Output: rgb = L + T * background, a = 1 - mean(T). With u_stop_t the
// march ends at the first step boundary at or beyond it (the same steps).
layout(local_size_x = VEIL_MARCH_GROUP, local_size_y = VEIL_MARCH_GROUP) in;

layout(binding = VEIL_IMAGE_OUT, rgba32f) writeonly uniform image2D u_out;
layout(binding = VEIL_TEX_EV) uniform sampler3D u_ev;
uniform sampler3D u_opv[VEIL_MAX_OPV_TEXTURES];
layout(binding = VEIL_TEX_OCC) uniform sampler3D u_occ; // max density per VEIL_BRICK^3 brick (ring included)
uniform int u_skip;       // 1: skip bricks of zero density (no fog to sample there)
uniform float u_voxel;    // m

uniform ivec2 u_size;
uniform vec3 u_cam_pos, u_cam_fwd, u_cam_right, u_cam_up; // right/up scaled by tan(fov/2) (and aspect)
uniform int u_has_volume;
uniform vec3 u_box_min, u_box_max;   // the EV's medium: from the first voxel centre to the last (m)
uniform vec3 u_tex_min, u_tex_inv_size; // texture coordinates: (x - u_tex_min) * u_tex_inv_size
uniform vec3 u_sigma_t, u_sigma_s;  // m^-1 per unit density
uniform float u_g;                  // HG asymmetry (0: isotropic)
uniform float u_step;               // m, inside the EV's box (no EV: the fog's smallest step)
uniform float u_min_dist2;          // m^2, floor on |S - X|^2 of point lights
uniform uint u_seed;
uniform vec3 u_background;
uniform float u_stop_t;             // m: no step starts at or beyond it (3e38: no limit)
uniform int u_light_count;
uniform int u_light_type[VEIL_MAX_LIGHTS];
uniform vec3 u_light_pos[VEIL_MAX_LIGHTS];   // point, spot: position (m)
uniform vec3 u_light_dir[VEIL_MAX_LIGHTS];   // directional: unit travel direction; spot: its axis
uniform vec2 u_light_cone[VEIL_MAX_LIGHTS];  // spot: cos(inner angle), cos(outer angle)
uniform vec3 u_light_color[VEIL_MAX_LIGHTS]; // W/sr or W/m^2
uniform int u_fog_count;
uniform float u_fog_density[VEIL_MAX_FOGS];
uniform float u_fog_falloff[VEIL_MAX_FOGS];
uniform vec3 u_fog_dir[VEIL_MAX_FOGS];
uniform vec3 u_fog_origin[VEIL_MAX_FOGS];
uniform vec3 u_fog_min[VEIL_MAX_FOGS], u_fog_max[VEIL_MAX_FOGS];

const float INF = 3.0e38;

uint hash32(uint x)
{
    x ^= x >> 16; x *= 0x7feb352du;
    x ^= x >> 15; x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// Slab test of o + t dir, t in [tmin, tmax]; empty when .x >= .y.
vec2 box_hit(vec3 o, vec3 dir, vec3 lo, vec3 hi, float tmin, float tmax)
{
    vec3 inv = 1.0 / dir; // +-inf on zero components: the slab test still holds
    vec3 a = (lo - o) * inv, b = (hi - o) * inv;
    vec3 t0 = min(a, b), t1 = max(a, b);
    return vec2(max(max(t0.x, t0.y), max(t0.z, tmin)), min(min(t1.x, t1.y), min(t1.z, tmax)));
}

// Density integral of all fogs along p + t d, t in [t0, t1] (d unit).
float fog_integral(vec3 p, vec3 d, float t0, float t1)
{
    float sum = 0.0;
    for (int f = 0; f < u_fog_count; ++f) {
        vec2 s = box_hit(p, d, u_fog_min[f], u_fog_max[f], t0, t1);
        if (s.x >= s.y) continue;
        float b = u_fog_falloff[f];
        float k0 = b * dot(p + d * s.x - u_fog_origin[f], u_fog_dir[f]);
        float k1 = b * dot(p + d * s.y - u_fog_origin[f], u_fog_dir[f]);
        sum += veil_exp_fog_integral(u_fog_density[f], k0, k1, s.y - s.x);
    }
    return sum;
}

// The EV's density integral from x to the light along unit direction `to`
// over length `len` (INF for a sun): the optical-depth volume at x, or at
// the point where that path enters the EV's box.
float ev_depth(int l, vec3 x, vec3 to, float len)
{
    if (u_has_volume == 0) return 0.0;
    vec2 s = box_hit(x, to, u_box_min, u_box_max, 0.0, len);
    if (s.x > s.y) return 0.0;
    vec3 y = x + to * s.x;
    return texture(u_opv[l / 4], (y - u_tex_min) * u_tex_inv_size)[l % 4];
}

vec3 in_scattered(vec3 x, vec3 dir)
{
    vec3 sum = vec3(0.0);
    for (int l = 0; l < u_light_count; ++l) {
        vec3 travel, E;
        float len;
        if (u_light_type[l] != VEIL_LIGHT_DIRECTIONAL) {
            vec3 to_light = u_light_pos[l] - x;
            float r2 = max(dot(to_light, to_light), u_min_dist2);
            len = sqrt(r2);
            travel = -to_light / len;
            E = u_light_color[l] / r2;
            if (u_light_type[l] == VEIL_LIGHT_SPOT)
                E *= veil_spot_falloff(dot(travel, u_light_dir[l]), u_light_cone[l].x, u_light_cone[l].y);
        } else {
            travel = u_light_dir[l];
            E = u_light_color[l];
            len = INF;
        }
        if (max(E.r, max(E.g, E.b)) <= 0.0) continue;
        // a fog's closed form overflows to +inf for rho0 e^60 len > 3.4e38: keep D
        // finite so that a channel with sigma_t = 0 gets exp(0) = 1, not exp(0 * inf) = NaN
        float D = min(ev_depth(l, x, -travel, len) + fog_integral(x, -travel, 0.0, len), INF);
        float cos_theta = clamp(dot(travel, -dir), -1.0, 1.0);
        sum += E * exp(-u_sigma_t * D) * veil_phase_hg(cos_theta, u_g);
    }
    return sum;
}

// Distance to the nearest point or spot light (INF without one).
float nearest_light(vec3 x)
{
    float d = INF;
    for (int l = 0; l < u_light_count; ++l)
        if (u_light_type[l] != VEIL_LIGHT_DIRECTIONAL) d = min(d, distance(x, u_light_pos[l]));
    return d;
}

void main()
{
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, u_size))) return;
    vec2 s = vec2(2.0 * (float(p.x) + 0.5) / float(u_size.x) - 1.0,
                  1.0 - 2.0 * (float(p.y) + 0.5) / float(u_size.y));
    vec3 dir = normalize(u_cam_fwd + s.x * u_cam_right + s.y * u_cam_up);
    vec3 T = vec3(1.0), L = vec3(0.0);

    // the span of the boxes the ray meets
    vec2 ev = u_has_volume != 0 ? box_hit(u_cam_pos, dir, u_box_min, u_box_max, 0.0, INF) : vec2(INF, -INF);
    float t_begin = ev.x < ev.y ? ev.x : INF, t_end = ev.x < ev.y ? ev.y : -INF;
    for (int f = 0; f < u_fog_count; ++f) {
        vec2 fs = box_hit(u_cam_pos, dir, u_fog_min[f], u_fog_max[f], 0.0, INF);
        if (fs.x < fs.y) {
            t_begin = min(t_begin, fs.x);
            t_end = max(t_end, fs.y);
        }
    }
    uint h = hash32(uint(p.x) + hash32(uint(p.y) + hash32(u_seed)));
    float jitter = (float(h >> 8) + 1.0) * (1.0 / 16777216.0); // (0, 1]
    float t = t_begin;
    bool first = true;
    while (t < t_end && t < u_stop_t) {
        vec3 x0 = u_cam_pos + dir * t;
        bool in_ev = u_has_volume != 0 && t >= ev.x && t < ev.y;
        if (in_ev && u_skip != 0) {
            ivec3 b = ivec3(floor(((x0 - u_tex_min) / u_voxel - 0.5) / float(VEIL_BRICK)));
            b = clamp(b, ivec3(0), textureSize(u_occ, 0) - 1);
            if (texelFetch(u_occ, b, 0).r <= 0.0) {
                vec3 lo = u_tex_min + (vec3(b * VEIL_BRICK) + 0.5) * u_voxel;
                float exit_t = box_hit(u_cam_pos, dir, lo, lo + float(VEIL_BRICK) * u_voxel, t, INF).y;
                // past the exit by a hair that float t can hold (t + 1e-4 step may round to t)
                t = max(exit_t, t) + max(1e-4 * u_step, 2.4e-7 * abs(t));
                continue;
            }
        }
        float step = in_ev ? u_step
                           : max(u_step, min(VEIL_FOG_STEP_FRACTION * max(t, u_step), 0.25 * nearest_light(x0)));
        if (first) step *= jitter;
        first = false;
        float te = min(t + step, t_end);
        if (!in_ev && u_has_volume != 0 && t < ev.x) te = min(te, ev.x); // do not step over the EV's entry
        float dt = te - t;
        vec3 x = u_cam_pos + dir * (0.5 * (t + te));
        float rho_dt = in_ev ? texture(u_ev, (x - u_tex_min) * u_tex_inv_size).r * dt : 0.0;
        rho_dt = min(rho_dt + fog_integral(u_cam_pos, dir, t, te), INF); // finite, as D in in_scattered
        if (rho_dt > 0.0) {
            vec3 opt = u_sigma_t * rho_dt;
            vec3 frac = vec3(veil_step_integral(opt.r), veil_step_integral(opt.g), veil_step_integral(opt.b));
            // sigma_s (rho_dt frac) = sigma_s (1 - exp(-opt)) / sigma_t <= 1: in this order (precise:
            // not reassociated) nothing overflows; rho_dt * L_in first can (dense fog near a light),
            // and 0 * inf in a channel without scattering is NaN
            precise vec3 w = T * (u_sigma_s * (rho_dt * frac));
            L += w * in_scattered(x, dir);
            T *= exp(-opt);
            if (max(T.r, max(T.g, T.b)) < VEIL_MIN_TRANSMITTANCE) break;
        }
        t = te;
    }
    imageStore(u_out, p, vec4(L + T * u_background, 1.0 - (T.r + T.g + T.b) / 3.0));
}
