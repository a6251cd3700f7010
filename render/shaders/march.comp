// veil — single-scattering ray marcher, one invocation per pixel.
// Marches from the camera through the extinction volume's box to its exit,
// in steps of u_step (m); the first step is shortened by a per-pixel jitter
// in (0, 1] so that step boundaries differ between neighbouring pixels
// (noise, not banding). Each step samples the medium at its midpoint and
// integrates in-scattering over the step in closed form for a medium that
// is constant along the step (exact in homogeneous regions):
//   L += T * sigma_s * L_in * (1 - exp(-sigma_t dt)) / sigma_t
//   T *= exp(-sigma_t dt)
// L_in sums the lights: radiance reaching X, exp(-sigma_t D(X,S)) times
// I/|S-X|^2 (point; spot: times its cone falloff) or E (directional),
// times the phase function.
// Output: rgb = L + T * background, a = 1 - mean(T).
layout(local_size_x = VEIL_MARCH_GROUP, local_size_y = VEIL_MARCH_GROUP) in;

layout(binding = VEIL_IMAGE_OUT, rgba32f) writeonly uniform image2D u_out;
layout(binding = VEIL_TEX_EV) uniform sampler3D u_ev;
uniform sampler3D u_opv[VEIL_MAX_OPV_TEXTURES];

uniform ivec2 u_size;
uniform vec3 u_cam_pos, u_cam_fwd, u_cam_right, u_cam_up; // right/up scaled by tan(fov/2) (and aspect)
uniform int u_has_volume;
uniform vec3 u_box_min, u_box_max;   // the medium: from the first voxel centre to the last (m)
uniform vec3 u_tex_min, u_tex_inv_size; // texture coordinates: (x - u_tex_min) * u_tex_inv_size
uniform vec3 u_sigma_t, u_sigma_s;  // m^-1 per unit density
uniform float u_g;                  // HG asymmetry (0: isotropic)
uniform float u_step;               // m
uniform float u_min_dist2;          // m^2, floor on |S - X|^2 of point lights
uniform uint u_seed;
uniform vec3 u_background;
uniform int u_light_count;
uniform int u_light_type[VEIL_MAX_LIGHTS];
uniform vec3 u_light_pos[VEIL_MAX_LIGHTS];   // point, spot: position (m)
uniform vec3 u_light_dir[VEIL_MAX_LIGHTS];   // directional: unit travel direction; spot: its axis
uniform vec2 u_light_cone[VEIL_MAX_LIGHTS];  // spot: cos(inner angle), cos(outer angle)
uniform vec3 u_light_color[VEIL_MAX_LIGHTS]; // W/sr or W/m^2

uint hash32(uint x)
{
    x ^= x >> 16; x *= 0x7feb352du;
    x ^= x >> 15; x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// Slab test; returns (t_enter, t_exit), empty when t_enter >= t_exit.
vec2 box_hit(vec3 o, vec3 dir, vec3 lo, vec3 hi)
{
    vec3 inv = 1.0 / dir; // +-inf on zero components: the slab test still holds
    vec3 a = (lo - o) * inv, b = (hi - o) * inv;
    vec3 tmin = min(a, b), tmax = max(a, b);
    float t0 = max(max(tmin.x, tmin.y), max(tmin.z, 0.0));
    float t1 = min(min(tmax.x, tmax.y), tmax.z);
    return vec2(t0, t1);
}

vec3 in_scattered(vec3 x, vec3 uvw, vec3 dir)
{
    vec3 sum = vec3(0.0);
    for (int l = 0; l < u_light_count; ++l) {
        float D = texture(u_opv[l / 4], uvw)[l % 4];
        vec3 travel, E;
        if (u_light_type[l] != VEIL_LIGHT_DIRECTIONAL) {
            vec3 to_light = u_light_pos[l] - x;
            float r2 = max(dot(to_light, to_light), u_min_dist2);
            travel = -to_light * inversesqrt(r2);
            E = u_light_color[l] / r2;
            if (u_light_type[l] == VEIL_LIGHT_SPOT)
                E *= veil_spot_falloff(dot(travel, u_light_dir[l]), u_light_cone[l].x, u_light_cone[l].y);
        } else {
            travel = u_light_dir[l];
            E = u_light_color[l];
        }
        float cos_theta = clamp(dot(travel, -dir), -1.0, 1.0);
        sum += E * exp(-u_sigma_t * D) * veil_phase_hg(cos_theta, u_g);
    }
    return sum;
}

void main()
{
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, u_size))) return;
    vec2 s = vec2(2.0 * (float(p.x) + 0.5) / float(u_size.x) - 1.0,
                  1.0 - 2.0 * (float(p.y) + 0.5) / float(u_size.y));
    vec3 dir = normalize(u_cam_fwd + s.x * u_cam_right + s.y * u_cam_up);
    vec3 T = vec3(1.0), L = vec3(0.0);
    if (u_has_volume != 0) {
        vec2 span = box_hit(u_cam_pos, dir, u_box_min, u_box_max);
        uint h = hash32(uint(p.x) + hash32(uint(p.y) + hash32(u_seed)));
        float jitter = (float(h >> 8) + 1.0) * (1.0 / 16777216.0); // (0, 1]
        float t = span.x, seg = jitter * u_step;
        while (t < span.y) {
            float te = min(t + seg, span.y);
            float dt = te - t;
            vec3 x = u_cam_pos + dir * (0.5 * (t + te));
            vec3 uvw = (x - u_tex_min) * u_tex_inv_size;
            float rho = texture(u_ev, uvw).r;
            if (rho > 0.0) {
                vec3 opt = u_sigma_t * (rho * dt);
                vec3 frac = vec3(veil_step_integral(opt.r), veil_step_integral(opt.g), veil_step_integral(opt.b));
                L += T * (u_sigma_s * rho) * in_scattered(x, uvw, dir) * (dt * frac);
                T *= exp(-opt);
                if (max(T.r, max(T.g, T.b)) < VEIL_MIN_TRANSMITTANCE) break;
            }
            t = te;
            seg = u_step;
        }
    }
    imageStore(u_out, p, vec4(L + T * u_background, 1.0 - (T.r + T.g + T.b) / 3.0));
}
