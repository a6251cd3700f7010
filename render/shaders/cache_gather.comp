// veil — the light cache's later light gathered towards the camera, one
// invocation a cell of the cache's grid (render/march.h: the first pass of
// a march with u.march.y > 0 rays a cell). What it writes, slab 4 of the
// cache's texture (core/shared.glsl.h), is what the march adds for the
// light that reaches the camera after three or more scatterings, per unit
// sigma_s rho at the cell's centre x:
//   S(x) = integral over w of p(w . -v) L2(x, w) dw,
//   L2(x, w) = integral over s > 0 of T_red(x, y) sigma_s rho(y) J(y, w) ds,
// y = x - s w, v the direction from the camera to x, w the direction the
// light travels, and J(y, w) the cache's light at y (once scattered and
// later, each its HG lobe, the later one less its forward peak f = g^2:
// render/shaders/cache_read.glsl) scattered towards w, the peak carried
// along the ray by T_red, the transmittance of sigma_t - f sigma_s, as the
// march carries it. L2 is the light scattered at least twice arriving at x: one
// step of the transport equation away from the lobes, so their error at
// the medium's skin — where the light towards the camera is what built up
// along the ray behind x and no lobe about the flux holds it
// (docs/multiple-scattering.md, "What the error is") — is integrated over
// the medium along the ray instead of read at x.
// Estimator: K = n^2 directions a cell, stratified n x n over an inverse
// CDF in cos and the azimuth, the strata shifted by the cell's own random
// offset (Cranley-Patterson); on a checkerboard of the strata the CDF is
// the phase function's about -v or the lobe's of all the light at x (HG of
// its mean cosine about its flux), each ray weighted by the balance
// heuristic in the two's shares. Each ray is marched in steps of u.march.z
// of the cache's cells (split above VEIL_GATHER_MAX_OPT), midpoint density
// (the fogs in closed form), in-scattering integrated over a step as the
// march does, until T_red < VEIL_MIN_TRANSMITTANCE or the grid's edge (or,
// with VEIL_SOLID, a frame's surface). Cells the march never reads are
// skipped (main, seen()). The random numbers of cell c come from (seed, c)
// alone: the same camera and cache give the same slab.
layout(local_size_x = VEIL_GATHER_GROUP, local_size_y = VEIL_GATHER_GROUP, local_size_z = VEIL_GATHER_GROUP) in;
layout(binding = VEIL_TEX_DIFFUSION) uniform sampler3D u_phi; // the cache (slabs 0-3 read)
layout(binding = VEIL_IMAGE_CACHE, rgba32f) writeonly uniform image3D u_cache; // its slab 4 written
layout(std140, binding = VEIL_UBO_MARCH) uniform veil_march_ubo { veil_march_block u; };
//@include propagate/shaders/lit_medium.glsl
//@include render/shaders/cache_read.glsl
//@include volumetric/shaders/cache_random.glsl

// The medium's density integral over [s0, s1] along x + s d.
float density_dt(vec3 x, vec3 d, float s0, float s1)
{
    vec3 y = x + d * (0.5 * (s0 + s1));
    bool in_ev = med.counts.z != 0 && all(greaterThanEqual(y, med.box_min.xyz)) && all(lessThanEqual(y, med.box_max.xyz));
    return (in_ev ? ev_density(y) * (s1 - s0) : 0.0) + fog_integral(x, d, s0, s1);
}

// Whether the march may read the cell at x (rel = x - the camera): some point within r of x in the
// camera's frustum and, along the line to the camera from r nearer, a transmittance the march has not
// stopped at (VEIL_MIN_TRANSMITTANCE in the channel that carries furthest). The march reads a point's
// eight nearest cells, all within a cell's diagonal of it: r is two diagonals.
bool seen(vec3 x, vec3 rel, vec3 lo, vec3 hi, float r, float h)
{
    float dist = length(rel);
    if (dist <= r) return true;
    vec3 f = u.cam_fwd.xyz, e[4] = vec3[4](f + u.cam_right.xyz, f - u.cam_right.xyz, f + u.cam_up.xyz, f - u.cam_up.xyz);
    vec3 across[4] = vec3[4](u.cam_up.xyz, u.cam_up.xyz, u.cam_right.xyz, u.cam_right.xyz);
    if (dot(rel, f) < -r) return false;
    for (int i = 0; i < 4; ++i) {
        vec3 n = normalize(cross(e[i], across[i]));
        if (dot(n, f) < 0.0) n = -n;
        if (dot(rel, n) < -r) return false;
    }
    vec3 to_cam = -rel / dist, x0 = x + to_cam * r;
    vec2 span = box_hit(x0, to_cam, lo, hi, 0.0, dist - r);
    float sigma = min(med.sigma_t.r, min(med.sigma_t.g, med.sigma_t.b)), tau = 0.0;
    for (float s = span.x; s < span.y; s += h) {
        tau += sigma * density_dt(x0, to_cam, s, min(s + h, span.y));
        if (exp(-tau) < VEIL_MIN_TRANSMITTANCE) return false;
    }
    return true;
}

void main()
{
    // the gather's cells (u.limits.yzw): the cache's, or cubes of s (u.march.w >= 1) of the cache's a side
    const float sc = max(u.march.w, 1.0);
    ivec3 dims = ivec3(imageSize(u_cache).xy, int(u.diffusion_inv.w));
    ivec3 gdims = ivec3(u.limits.yzw);
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, gdims))) return;
    // only cells the march reads: those with density within one cell (the majorants, slab 2's alpha)
    bool near = false;
    ivec3 f0 = max(ivec3(floor(vec3(c - 1) * sc)), ivec3(0)), f1 = min(ivec3(ceil(vec3(c + 2) * sc)), dims);
    for (int z = f0.z; z < f1.z && !near; ++z)
        for (int y = f0.y; y < f1.y && !near; ++y)
            for (int x = f0.x; x < f1.x && !near; ++x)
                near = texelFetch(u_phi, ivec3(x, y, z + 2 * dims.z), 0).a > 0.0;
    if (!near) {
        imageStore(u_cache, c + ivec3(0, 0, 4 * dims.z), vec4(0.0));
        return;
    }
    vec3 lo = u.diffusion.xyz, hi = lo + 1.0 / u.diffusion_inv.xyz;
    float h = (hi.x - lo.x) / float(dims.x);
    // its centre, or for a last cell partly past the grid's side (s not dividing the cells) the nearest
    // point half a cache cell inside: the march reads it there, between its neighbour and the side
    vec3 x = lo + min((vec3(c) + 0.5) * sc, vec3(dims) - 0.5) * h;
    vec3 v = x - u.cam_pos.xyz;
    if (!seen(x, v, lo, hi, 2.0 * 1.7320508 * sc * h, h)) {
        imageStore(u_cache, c + ivec3(0, 0, 4 * dims.z), vec4(0.0));
        return;
    }
    v = dot(v, v) > 0.0 ? normalize(v) : u.cam_fwd.xyz; // the camera's ray through x
    state = mix32(u.flags.z ^ mix32(uint(c.x) + uint(gdims.x) * (uint(c.y) + uint(gdims.y) * uint(c.z))) * 0x9e3779b9u);
    int n = max(int(sqrt(u.march.y) + 0.5), 1);
    float g = med.shape.z, ds = h * u.march.z;
    // the later light's forward peak carried along the gather's rays as the march carries it (cache_read.glsl)
    float f_peak = max(g, 0.0) * max(g, 0.0);
    // the light arriving at x as the cache's lobe of all its light there holds it: the second technique
    vec3 phi1, F1, phi2, F2, unused;
    float free_part;
    cache_fetch(x, false, phi1, F1, phi2, F2, free_part, unused);
    vec3 F = F1 + F2;
    float phi_lum = dot(phi1 + phi2, vec3(VEIL_LUM_R, VEIL_LUM_G, VEIL_LUM_B)), F_len = length(F);
    vec3 axis = F_len > 0.0 ? F / F_len : -v;
    float g_in = phi_lum > 0.0 ? clamp(F_len / phi_lum, 0.0, VEIL_GATHER_MAX_LOBE) : 0.0;
    vec2 shift = vec2(rnd(), rnd());
    vec3 sum = vec3(0.0);
    // the two techniques' shares of the n^2 strata (a checkerboard: for odd n the phase function has one more)
    const float c_phase = float((n * n + 1) / 2) / float(n * n), c_light = 1.0 - c_phase;
    for (int i = 0; i < n * n; ++i) {
        vec2 xi = fract((vec2(float(i % n), float(i / n)) + 0.5) / float(n) + shift);
        // the light's direction w, drawn on a checkerboard of the strata as the phase function towards
        // the camera (-v) or as the light's lobe, weighted by the phase function over the two pdfs mixed
        // in their shares (the balance heuristic: a ray the phase function sends where the light is
        // bright is no outlier); the ray goes the other way, d = -w, to where that light comes from
        bool by_phase = ((i % n) + (i / n)) % 2 == 0;
        vec3 w = by_phase ? around(-v, hg_cos(g, xi.x), 2.0 * VEIL_PI * xi.y)
                          : around(axis, hg_cos(g_in, xi.x), 2.0 * VEIL_PI * xi.y);
        float p_phase = veil_phase_hg(dot(w, -v), g), p_light = veil_phase_hg(dot(w, axis), g_in);
        float weight = p_phase / (c_phase * p_phase + c_light * p_light);
        vec3 d = -w;
        float s_end = box_hit(x, d, lo, hi, 0.0, INF).y;
#ifdef VEIL_SOLID
        s_end = solid_hit(x, d, s_end);
#endif
        vec3 T = vec3(1.0), L = vec3(0.0);
        float s = 0.0, first = rnd() * ds;
        while (s < s_end) {
            float s1 = min(s + (s == 0.0 ? first + 1e-6 * h : ds), s_end);
            vec3 y = x + d * (0.5 * (s + s1));
            // a cell without density (its majorant 0) adds nothing
            ivec3 q = clamp(ivec3(floor((y - lo) / h)), ivec3(0), dims - 1);
            float rho_dt = texelFetch(u_phi, q + ivec3(0, 0, 2 * dims.z), 0).a > 0.0 || med.counts.y > 0 ? density_dt(x, d, s, s1) : 0.0;
            // a step thicker than VEIL_GATHER_MAX_OPT (reduced) is split: over a long step through thin
            // dense features the midpoint's (1 - exp(-x)) / x is biased low (concave in the density)
            float split = ceil(dot(med.sigma_t.rgb - f_peak * med.sigma_s.rgb, vec3(1.0 / 3.0)) * rho_dt / VEIL_GATHER_MAX_OPT);
            if (split > 1.0) {
                s1 = s + (s1 - s) / min(split, 8.0);
                y = x + d * (0.5 * (s + s1));
                rho_dt = density_dt(x, d, s, s1);
            }
            if (rho_dt > 0.0) {
                vec3 opt = (med.sigma_t.rgb - f_peak * med.sigma_s.rgb) * rho_dt;
                vec3 frac = vec3(veil_step_integral(opt.r), veil_step_integral(opt.g), veil_step_integral(opt.b));
                L += T * med.sigma_s.rgb * (rho_dt * frac) * cache_in(y, d, f_peak, false);
                T *= exp(-opt);
                if (max(T.r, max(T.g, T.b)) < VEIL_MIN_TRANSMITTANCE) break;
            }
            s = s1;
        }
        sum += weight * L;
    }
    // kept times the cell's free part, as the sums are (cache_resolve.comp): the march divides by the
    // interpolated part, so a cell in a frame's solid, whose rays start in a wall, weighs nothing
    imageStore(u_cache, c + ivec3(0, 0, 4 * dims.z), vec4(sum / float(n * n) * free_part, 0.0));
}
