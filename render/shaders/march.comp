// veil — single-scattering ray marcher, one invocation per pixel.
// The medium: the extinction volume (EV, trilinear over the box its voxel
// centres span) plus up to VEIL_MAX_FOGS analytic exponential fogs, each in
// its box. A ray is marched over the span of those boxes; where it is in
// none of them it jumps ahead. Steps are u.march.x (m) inside the EV's box and
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
// density (volume/shaders/occupancy.comp) every sample in it would add
// nothing, so without fog the march jumps to where the ray leaves the brick.
// Volumetric multiple scattering (u.octave.w = N > 1 octaves): the octave
// approximation (Wrenninge et al. 2013): beside each light's single
// in-scattering E exp(-sigma_t D) p(g), the octaves i = 1..N-1 add
// (b albedo)^i E exp(-a^i sigma_t D) p(c^i g): light that scattered more
// often reaches deeper (a < 1), is weaker (b < 1, and each scattering keeps
// the albedo sigma_s / sigma_t of it) and less peaked (c < 1).
// The screen-space pass's source (aov_q): the part of each step's single
// scattering that is scattered, not absorbed, on its way to the camera,
// J (exp(-sigma_a P) - exp(-sigma_t P)) with J the step's light before
// attenuation and P the density integral from the camera to the step; its
// alpha is the luminance-weighted mean of that P.
// The light cache (u.diffusion.w = VEIL_FIELD_CACHE; cache_in): its lobes
// per step, weighted by the transmittance of a reduced extinction that
// carries the forward peak of the phase function along the ray; the march
// then ends where that transmittance, not T, is negligible (single
// scattering stops where T is). With u.march.y > 0 the later light is not
// read from its lobe but gathered towards the camera before the march
// (render/shaders/cache_gather.comp, the cache's slab 4; render/march.h):
// then the plain T, and no peak carried.
// Emission (med.shape.w, in the variant compiled with VEIL_MARCH_EMISSION):
// the EV's emission texture eps per step, integrated in closed form like
// in-scattering, added to L (the medium's own light).
// Over a sparse volume (VEIL_SPARSE, volume/sparse.h) the EV, the optical
// depths, the escape field and the emission are atlases of the kept bricks
// (volume/shaders/sparse_common.glsl), and the bricks and nodes not kept are
// skipped (they hold neither density nor emission).
// Output: rgb = L + L_v + T * background, a = 1 - mean(T). With u.limits.x
// the march ends at the first step boundary at or beyond it (the same steps);
// with u.flags.w each pixel's ray ends exactly at the distance in u_limit (a
// surface of a frame rendered elsewhere: `veil fog`).
// Deep samples (VEIL_MARCH_DEEP = R, the raw samples a pixel; render/deep.h): the ray's stretches of
// medium, each closed where its opacity crosses a multiple of 1/R of the pixel's, where the ray leaves
// the medium into empty space (a step with no density nor emission, or a jump over an empty brick) and at
// the end; the R-th keeps accumulating to the end (the flatten stays exact). A sample: its colour, what
// the stretch adds to L + Lv divided by the mean transmittance Tm at its front; A = 1 - Tm(back) / Tm(front)
// (the mean over channels: chromatic extinction is carried by the colour, not by A; the product of the
// samples' 1 - A is Tm at the ray's end, so the flattened alpha is 1 - mean T); Z and ZBack the planar
// depths (along the view axis, as the flat image's Z) of its first and last step with medium.
// Compiled in for a large frame (render/march.c: the march's programs),
// since llvmpipe runs both sides of every branch it cannot fold, texture
// reads included: the lights (VEIL_LIGHT_LIST: each one's kind and
// light-space grid), which field u_phi holds (VEIL_MARCH_FIELD, a
// VEIL_FIELD_*, as u.diffusion.w) and whether the cache's later light is
// gathered (VEIL_MARCH_GATHER, as u.march.y > 0). The generic program reads
// all three from the blocks. (The field compiled into the generic light loop
// came out wrong on llvmpipe of Mesa 22.3: the cache's light 8x too dark on
// fog_lights, single scattering exact; the two are compiled in together.)
#ifdef VEIL_MARCH_FIELD
#define MARCH_FIELD_IS(kind) (VEIL_MARCH_FIELD == (kind))
#define MARCH_GATHER (VEIL_MARCH_GATHER != 0)
#ifdef VEIL_MARCH_OCTAVES /* a cache of the environment's first scattering alone (render/march.c): octaves beside it */
#define MARCH_CACHE_ONLY 0
#else
#define MARCH_CACHE_ONLY (VEIL_MARCH_FIELD == VEIL_FIELD_CACHE) /* no escape field, no octaves */
#endif
#else
#define MARCH_FIELD_IS(kind) (u.diffusion.w == float(kind))
#define MARCH_GATHER (u.march.y > 0.0)
#define MARCH_CACHE_ONLY 0
#endif
layout(local_size_x = VEIL_MARCH_GROUP, local_size_y = VEIL_MARCH_GROUP) in;

layout(binding = VEIL_IMAGE_OUT, rgba32f) writeonly uniform image2D u_out;     // rgb radiance, a = 1 - mean T
layout(binding = VEIL_IMAGE_AOV_T, rgba32f) writeonly uniform image2D u_aov_t; // rgb T, a = P (density m)
layout(binding = VEIL_IMAGE_AOV_S, rgba32f) writeonly uniform image2D u_aov_s; // rgb single scattering, a = depth (m)
layout(binding = VEIL_IMAGE_AOV_V, rgba32f) writeonly uniform image2D u_aov_v; // rgb volumetric multiple scattering
layout(binding = VEIL_IMAGE_AOV_Q, rgba32f) writeonly uniform image2D u_aov_q; // rgb out-scattered single, a = its P
layout(binding = VEIL_TEX_OCC) uniform sampler3D u_occ; // max density per VEIL_BRICK^3 brick (ring included)
layout(binding = VEIL_TEX_LIMIT) uniform sampler2D u_limit; // u.flags.w: distance (m) where each pixel's ray ends
layout(binding = VEIL_TEX_DIFFUSION) uniform sampler3D u_phi; // u.diffusion.w: multiply scattered fluence (W/m^2)
layout(binding = VEIL_TEX_EMISSION) uniform sampler3D u_emission; // med.shape.w: emission eps (W m^-3 sr^-1)
layout(std140, binding = VEIL_UBO_MARCH) uniform veil_march_ubo { veil_march_block u; };
#ifdef VEIL_MARCH_DEEP
layout(std430, binding = VEIL_BIND_DEEP_COUNT) writeonly buffer veil_deep_count { uint deep_count[]; };
layout(std430, binding = VEIL_BIND_DEEP_SAMPLES) writeonly buffer veil_deep_samples { float deep_samples[]; };
// one pixel's deep state (render/deep.h): samples written, the open stretch's front (ray distance, mean T,
// L + Lv there) and its last step's end
uint d_pixel = 0u, d_n = 0u;
bool d_open = false, d_matter = false;
float d_t0 = 0.0, d_t1 = 0.0, d_T0 = 1.0, d_along = 1.0;
vec3 d_L0 = vec3(0.0);

float deep_mean(vec3 T) { return (T.r + T.g + T.b) / 3.0; }

// opens a stretch at ray distance t unless one is open (before the step adds anything)
void deep_open(float t, vec3 T, vec3 L, vec3 Lv)
{
    d_matter = true;
    if (d_open) return;
    d_open = true;
    d_t0 = t, d_t1 = t;
    d_T0 = deep_mean(T);
    d_L0 = L + Lv;
}

void deep_close(vec3 T, vec3 L, vec3 Lv)
{
    if (!d_open) return;
    d_open = false;
    uint i = (d_pixel * uint(VEIL_MARCH_DEEP) + d_n) * uint(VEIL_DEEP_SAMPLE_FLOATS);
    if (d_pixel >= uint(deep_count.length()) || i + 5u >= uint(deep_samples.length())) return;
    vec3 c = (L + Lv - d_L0) / d_T0;
    deep_samples[i + 0u] = c.r;
    deep_samples[i + 1u] = c.g;
    deep_samples[i + 2u] = c.b;
    deep_samples[i + 3u] = clamp(1.0 - deep_mean(T) / d_T0, 0.0, 1.0); // T <= T0, but a GPU's division may round over
    deep_samples[i + 4u] = d_t0 * d_along;
    deep_samples[i + 5u] = d_t1 * d_along;
    ++d_n;
}

// after a step ending at te: extend the open stretch over it, or close it at a gap; close it where its
// opacity crossed a multiple of 1/R (unless it is the last one a pixel may have, or what follows is
// below VEIL_DEEP_MIN_T)
void deep_step(float te, vec3 T, vec3 L, vec3 Lv)
{
    if (!d_matter) {
        if (d_n + 1u < uint(VEIL_MARCH_DEEP) && deep_mean(T) >= VEIL_DEEP_MIN_T) deep_close(T, L, Lv);
        return;
    }
    d_matter = false;
    d_t1 = te;
    float R = float(VEIL_MARCH_DEEP), Tm = deep_mean(T);
    if (d_n + 1u < uint(VEIL_MARCH_DEEP) && Tm >= VEIL_DEEP_MIN_T && floor(R * (1.0 - Tm)) > floor(R * (1.0 - d_T0)))
        deep_close(T, L, Lv);
}
#endif
//@include propagate/shaders/lit_medium.glsl

uint hash32(uint x)
{
    x ^= x >> 16; x *= 0x7feb352du;
    x ^= x >> 15; x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

// Light l's part of in_scattered at x: its single scattering added to
// `sum`, its octaves to `multi`. `kind`, `grid` and k as light_at_kind and
// ev_depth_in take them.
void light_in(int l, int kind, bool grid, int k, vec3 x, vec3 dir, float p_cam, int octaves, vec3 albedo, vec3 floor_t,
              bool use_escape, float escape, inout vec3 sum, inout vec3 multi)
{
    vec3 travel, E;
    float len;
    if (!light_at_kind(l, kind, x, travel, E, len)) return;
    float D = depth_to_light_in(l, grid, kind != VEIL_LIGHT_DIRECTIONAL, k, x, travel, len);
    float cos_theta = clamp(dot(travel, -dir), -1.0, 1.0);
    sum += E * exp(-med.sigma_t.rgb * D) * veil_phase_hg(cos_theta, med.shape.z);
    // the chance that light on the two legs through x (from the light,
    // to the camera) scattered again: no medium around x, no higher orders
    // (D + p_cam kept finite: 0 * inf would be NaN where sigma_s = 0)
    // or, with the escape field, the chance averaged over all directions
    // (without a field, e.g. a fog box too large for a grid, the legs serve)
    float gate = use_escape ? escape
               : 1.0 - exp(-dot(med.sigma_s.rgb, vec3(1.0 / 3.0)) * min(D + p_cam, INF));
    // the legs' gate counts once; the escape field's chance is paid per further scattering
#if !MARCH_CACHE_ONLY /* with a cache, never the octaves (render/march.c) */
    float a = 1.0, g = med.shape.z, per = use_escape ? gate : 1.0;
    vec3 b = vec3(use_escape ? 1.0 : gate);
    for (int i = 1; i < octaves; ++i) {
        a *= u.octave.x, g *= u.octave.z;
        b *= u.octave.y * per * albedo;
        vec3 att = exp(-max(a * med.sigma_t.rgb, floor_t) * D);
        multi += b * E * att * veil_phase_hg(cos_theta, g);
    }
#endif
}

// Light scattered towards -dir at x: single scattering returned, the
// octaves' estimate of the higher orders in `multi`.
vec3 in_scattered(vec3 x, vec3 dir, float p_cam, out vec3 multi)
{
    vec3 sum = vec3(0.0);
    multi = vec3(0.0);
    int octaves = int(u.octave.w);
    // each further scattering keeps the single-scattering albedo of the light
    vec3 albedo = med.sigma_s.rgb / max(med.sigma_t.rgb, vec3(1e-30));
    // light that scattered many times is attenuated as diffusion attenuates
    // it, sqrt(3 sigma_a sigma_tr) (sigma_tr = sigma_a + sigma_s (1 - g)):
    // an octave's reduced extinction a^i sigma_t never goes below that
    vec3 sigma_a = max(med.sigma_t.rgb - med.sigma_s.rgb, 0.0);
    vec3 floor_t = sqrt(3.0 * sigma_a * (sigma_a + med.sigma_s.rgb * (1.0 - med.shape.z)));
    bool use_escape = MARCH_FIELD_IS(VEIL_FIELD_ESCAPE);
    float escape = 0.0;
#if !MARCH_CACHE_ONLY
    if (use_escape) {
#ifdef VEIL_SPARSE
        // the field lives in the kept bricks; elsewhere (fog) the legs serve
        vec3 q = (x - sp.origin.xyz) / sp.origin.w;
        ivec3 b = sp_brick(q);
        int region;
        uint slot = sp_slot(b, region);
        use_escape = slot != 0u;
        if (use_escape) escape = texture(u_phi, sp_escape_uvw(slot, b, q)).r;
#else
        escape = texture(u_phi, (x - u.diffusion.xyz) * u.diffusion_inv.xyz).r;
#endif
    }
#endif
#ifdef VEIL_LIGHT_LIST
    // each light with its kind and grid as constants (render/march.c)
#define VEIL_LIGHT(l, kind, k) \
    light_in(l, kind, (k) >= 0, max(k, 0), x, dir, p_cam, octaves, albedo, floor_t, use_escape, escape, sum, multi);
    VEIL_LIGHT_LIST
#undef VEIL_LIGHT
#else
    // the lights read from the OPVs, then those in light-space grids (suns,
    // point and spot lights): two loops, so that neither runs the other's
    // lookup (ev_depth_in)
    for (int i = 0; i < opv_lights(); ++i) {
        int l = opv_light(i);
        light_in(l, int(med.lights[l].position.w), false, 0, x, dir, p_cam, octaves, albedo, floor_t, use_escape, escape, sum, multi);
    }
    for (int k = 0; k < grid_suns(); ++k) {
        int l = grid_sun_light(k);
        light_in(l, int(med.lights[l].position.w), true, k, x, dir, p_cam, octaves, albedo, floor_t, use_escape, escape, sum,
                 multi);
    }
#endif
    // the diffusion estimate: the fluence of light scattered at least once,
    // scattered again, isotropically, towards the camera
    if (MARCH_FIELD_IS(VEIL_FIELD_FLUENCE))
        multi += texture(u_phi, (x - u.diffusion.xyz) * u.diffusion_inv.xyz).rgb * (1.0 / (4.0 * VEIL_PI));
    return sum;
}

//@include render/shaders/cache_read.glsl

// Distance to the nearest point or spot light (INF without one).
float nearest_light(vec3 x)
{
    float d = INF;
    for (int l = 0; l < med.counts.x; ++l)
        if (int(med.lights[l].position.w) != VEIL_LIGHT_DIRECTIONAL) d = min(d, distance(x, med.lights[l].position.xyz));
    return d;
}

void main()
{
    ivec2 p = ivec2(gl_GlobalInvocationID.xy) + ivec2(0, u.size.z); // a band of rows (render/march.h)
    if (any(greaterThanEqual(p, u.size.xy))) return;
    vec2 s = vec2(2.0 * (float(p.x) + 0.5) / float(u.size.xy.x) - 1.0,
                  1.0 - 2.0 * (float(p.y) + 0.5) / float(u.size.xy.y));
    vec3 dir = normalize(u.cam_fwd.xyz + s.x * u.cam_right.xyz + s.y * u.cam_up.xyz);
    vec3 T = vec3(1.0), L = vec3(0.0), Lv = vec3(0.0), Q = vec3(0.0);
    // the light cache's forward peak f (cache_in: g^2 of the phase function; 0 for g <= 0, and without a
    // cache, where T_red is T) and the transmittance of the reduced extinction sigma_t - f sigma_s that
    // carries the later light along the ray: the march goes on until it, not T, is negligible
    bool cache = MARCH_FIELD_IS(VEIL_FIELD_CACHE);
    // (with the gather, u.march.y > 0, the later light towards the camera is gathered: no peak carried)
    bool gather = cache && MARCH_GATHER;
    float f_peak = cache && !gather ? max(med.shape.z, 0.0) * max(med.shape.z, 0.0) : 0.0;
    vec3 T_red = vec3(1.0);
    float q_p = 0.0, q_w = 0.0;        // luminance-weighted P of Q
    float P = 0.0;                     // density integral along the ray (density m)
    float depth_sum = 0.0, depth_w = 0.0; // extinction-weighted distance

    // the span of the boxes the ray meets
    vec2 ev = med.counts.z != 0 ? box_hit(u.cam_pos.xyz, dir, med.box_min.xyz, med.box_max.xyz, 0.0, INF) : vec2(INF, -INF);
    float t_begin = ev.x < ev.y ? ev.x : INF, t_end = ev.x < ev.y ? ev.y : -INF;
    for (int f = 0; f < med.counts.y; ++f) {
        vec2 fs = box_hit(u.cam_pos.xyz, dir, med.fogs[f].box_min.xyz, med.fogs[f].box_max.xyz, 0.0, INF);
        if (fs.x < fs.y) {
            t_begin = min(t_begin, fs.x);
            t_end = max(t_end, fs.y);
        }
    }
    // the camera's clip planes, distances along its view axis (up x right): the ray's share of them
    float along = dot(dir, normalize(cross(u.cam_up.xyz, u.cam_right.xyz)));
    t_begin = max(t_begin, u.cam_right.w / along);
    t_end = min(t_end, u.cam_up.w / along);
    // a surface behind the medium (veil fog): the ray ends there, exactly
    if (u.flags.w != 0u) t_end = min(t_end, texelFetch(u_limit, p, 0).r);
    uint h = hash32(uint(p.x) + hash32(uint(p.y) + hash32(u.flags.z)));
    float jitter = (float(h >> 8) + 1.0) * (1.0 / 16777216.0); // (0, 1]
    float t = t_begin;
    bool first = true, stop = false;
#ifdef VEIL_MARCH_DEEP
    d_pixel = uint(p.y - u.size.z) * uint(u.size.x) + uint(p.x);
    d_along = along;
#endif
    while (t < t_end && t < u.limits.x) {
        vec3 x0 = u.cam_pos.xyz + dir * t;
        bool in_ev = med.counts.z != 0 && t >= ev.x && t < ev.y;
        if (in_ev && u.flags.y != 0u) {
#ifdef VEIL_SPARSE
            // a brick not kept, or a whole empty node: jump to where the ray leaves it
            vec3 q = (x0 - sp.origin.xyz) / sp.origin.w;
            ivec3 b = sp_brick(q);
            int region;
            if (sp_slot(b, region) == 0u) {
                float exit_t = t + sp_region_exit(q, dir, b, region) * sp.origin.w;
                t = max(exit_t, t) + max(1e-4 * u.march.x, 2.4e-7 * abs(t));
#ifdef VEIL_MARCH_DEEP
                deep_step(t, T, L, Lv); // a gap: closes the open stretch
#endif
                continue;
            }
#else
            ivec3 b = ivec3(floor(((x0 - med.tex_min.xyz) / med.shape.y - 0.5) / float(VEIL_BRICK)));
            b = clamp(b, ivec3(0), textureSize(u_occ, 0) - 1);
            if (texelFetch(u_occ, b, 0).r <= 0.0) {
                vec3 lo = med.tex_min.xyz + (vec3(b * VEIL_BRICK) + 0.5) * med.shape.y;
                float exit_t = box_hit(u.cam_pos.xyz, dir, lo, lo + float(VEIL_BRICK) * med.shape.y, t, INF).y;
                // past the exit by a hair that float t can hold (t + 1e-4 step may round to t)
                t = max(exit_t, t) + max(1e-4 * u.march.x, 2.4e-7 * abs(t));
#ifdef VEIL_MARCH_DEEP
                deep_step(t, T, L, Lv); // a gap: closes the open stretch
#endif
                continue;
            }
#endif
        }
        float step = in_ev ? u.march.x
                           : max(u.march.x, min(VEIL_FOG_STEP_FRACTION * max(t, u.march.x), 0.25 * nearest_light(x0)));
        // past where T ends single scattering only the cache's later light goes on: steps of half its cell
        if (cache && max(T.r, max(T.g, T.b)) < VEIL_MIN_TRANSMITTANCE)
            step = max(step, 0.5 / (u.diffusion_inv.z * u.diffusion_inv.w));
        if (first) step *= jitter;
        first = false;
        float te = min(t + step, t_end);
        if (!in_ev && med.counts.z != 0 && t < ev.x) te = min(te, ev.x); // do not step over the EV's entry
        float dt = te - t;
        vec3 x = u.cam_pos.xyz + dir * (0.5 * (t + te));
        float rho_dt = in_ev ? ev_density(x) * dt : 0.0;
        rho_dt = min(rho_dt + fog_integral(u.cam_pos.xyz, dir, t, te), INF); // finite, as D in in_scattered
#ifdef VEIL_MARCH_EMISSION /* a variant: llvmpipe runs a masked-off texture read anyway (10 % of the march) */
        if (in_ev && med.shape.w != 0.0) {
            // emission eps constant over the step, attenuated within it as in-scattering is:
            // T eps dt (1 - exp(-x)) / x per channel (dt where the step has no density)
#ifdef VEIL_SPARSE
            vec3 q = (x - sp.origin.xyz) / sp.origin.w;
            ivec3 eb = sp_brick(q);
            int region;
            uint slot = sp_slot(eb, region);
            vec3 eps = slot == 0u ? vec3(0.0) : texture(u_emission, sp_atlas_uvw(slot, eb, q)).rgb;
#else
            vec3 eps = texture(u_emission, (x - med.tex_min.xyz) * med.tex_inv_size.xyz).rgb;
#endif
            vec3 opt = med.sigma_t.rgb * rho_dt;
#ifdef VEIL_MARCH_DEEP
            if (any(greaterThan(eps, vec3(0.0)))) deep_open(t, T, L, Lv);
#endif
            L += T * eps * dt * vec3(veil_step_integral(opt.r), veil_step_integral(opt.g), veil_step_integral(opt.b));
        }
#endif
        if (rho_dt > 0.0) {
#ifdef VEIL_MARCH_DEEP
            deep_open(t, T, L, Lv);
#endif
            vec3 opt = med.sigma_t.rgb * rho_dt;
            vec3 frac = vec3(veil_step_integral(opt.r), veil_step_integral(opt.g), veil_step_integral(opt.b));
            // sigma_s (rho_dt frac) = sigma_s (1 - exp(-opt)) / sigma_t <= 1: in this order (precise:
            // not reassociated) nothing overflows; rho_dt * L_in first can (dense fog near a light),
            // and 0 * inf in a channel without scattering is NaN
            precise vec3 j = med.sigma_s.rgb * (rho_dt * frac);
            precise vec3 w = T * j;
            vec3 multi;
            float p_mid = min(P + 0.5 * rho_dt, INF); // finite, as D: a channel with sigma = 0 gets exp(0)
            // past where the light's own transmittance ends the march, only the cache's later light goes on
            multi = vec3(0.0);
            vec3 single = max(T.r, max(T.g, T.b)) >= VEIL_MIN_TRANSMITTANCE ? in_scattered(x, dir, p_mid, multi) : vec3(0.0);
            L += w * single;
            Lv += w * multi;
            vec3 opt_red = (med.sigma_t.rgb - f_peak * med.sigma_s.rgb) * rho_dt;
            if (cache) {
                vec3 frac_red = vec3(veil_step_integral(opt_red.r), veil_step_integral(opt_red.g), veil_step_integral(opt_red.b));
                precise vec3 j_red = med.sigma_s.rgb * (rho_dt * frac_red);
                precise vec3 w_red = T_red * j_red;
                Lv += w_red * cache_in(x, dir, f_peak, gather);
            }
            T_red *= vec3(veil_step_transmittance(opt_red.r), veil_step_transmittance(opt_red.g),
                          veil_step_transmittance(opt_red.b));
            vec3 q = j * single * max(exp(-(med.sigma_t.rgb - med.sigma_s.rgb) * p_mid) - exp(-med.sigma_t.rgb * p_mid), 0.0);
            float yq = dot(q, vec3(VEIL_LUM_R, VEIL_LUM_G, VEIL_LUM_B));
            Q += q;
            q_p += yq * p_mid;
            q_w += yq;
            vec3 T_next = T * vec3(veil_step_transmittance(opt.r), veil_step_transmittance(opt.g), veil_step_transmittance(opt.b));
            float absorbed = dot(T - T_next, vec3(1.0 / 3.0)); // chance the first interaction is in this step
            depth_sum += absorbed * 0.5 * (t + te);
            depth_w += absorbed;
            P += rho_dt;
            T = T_next;
            stop = max(T_red.r, max(T_red.g, T_red.b)) < VEIL_MIN_TRANSMITTANCE;
        }
#ifdef VEIL_MARCH_DEEP
        deep_step(te, T, L, Lv);
#endif
        t = te;
        if (stop) break;
    }
#ifdef VEIL_MARCH_DEEP
    deep_close(T, L, Lv);
    if (d_pixel < uint(deep_count.length())) deep_count[d_pixel] = d_n;
#endif
    // the cache's part may dip below 0 where its lobe's correction outweighs what came along the ray
    // (a noisy or coarse lobe); radiance is not negative
    Lv = max(Lv, vec3(0.0));
    // T <= 1 by construction (veil_step_transmittance); alpha held in [0, 1] against the mean's rounding
    imageStore(u_out, p, vec4(L + Lv + T * u.background.rgb, veil_alpha(T.r, T.g, T.b)));
    imageStore(u_aov_v, p, vec4(Lv, 0.0));
    imageStore(u_aov_q, p, vec4(Q, q_w > 0.0 ? min(q_p / q_w, INF) : 0.0));
    imageStore(u_aov_t, p, vec4(T, min(P, INF)));
    imageStore(u_aov_s, p, vec4(L, depth_w > 0.0 ? depth_sum / depth_w : 0.0));
}
