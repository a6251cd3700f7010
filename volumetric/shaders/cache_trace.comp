// veil — the light cache's photons (volumetric/cache.h): one invocation a
// photon of one source (a sun, a point or spot light, the medium's
// emission, or the environment's rest), traced through the medium by
// delta tracking against the cells' majorants, scoring the track-length estimator of the fluence and
// its flux in every cell it crosses after its first scattering (from its
// start for emission and the environment's rest: the cache then carries
// their every order).
//
// Colour: one path for the three channels (spectral tracking, Kutz et al.
// 2017, with probabilities from the history-aware average): at a tentative
// collision the photon is absorbed, scattered or goes on with probabilities
//   P_x = sum_c w_c sigma_x,c / (sigma_bar sum_c w_c)
// (sigma_n,c = sigma_bar - sigma_t,c, the null part) and each weight w_c
// becomes w_c sigma_x,c / (sigma_bar P_x): unbiased per channel, and the
// weights' sum never changes (so every weight stays below the photon's
// first power summed over the channels: the bound the fixed point is cut
// to). A grey medium keeps the weights: analog absorption.
// Determinism: the random numbers of photon n come from (seed, source, n)
// alone, and the sums are integers: the cache does not depend on the order
// the GPU runs the photons in.
layout(local_size_x = VEIL_CACHE_GROUP) in;
//@include propagate/shaders/lit_medium.glsl
//@include volumetric/shaders/cache_common.glsl
layout(std430, binding = VEIL_BIND_CACHE_SUM) coherent buffer veil_cache_sums { uint sums[]; };
layout(std430, binding = VEIL_BIND_CACHE_CELL) readonly buffer veil_cache_cells { vec2 cells[]; };
layout(std430, binding = VEIL_BIND_CACHE_EMIT) readonly buffer veil_cache_emit { uvec4 emitters[]; };
layout(std430, binding = VEIL_BIND_CACHE_COUNT) coherent buffer veil_cache_count { uint counts[]; };

//@include volumetric/shaders/cache_random.glsl

// A signed 64-bit add of v to the word pair at k (low word first): the low
// word's atomic returns what it held, so its carry is known; the high word
// gets the carry and v's sign extension. Any order of adds gives the same sum.
// One for each buffer (GLSL passes no buffer to a function): add64 on the
// cells' sums, add64c on the counts (the energy account).
#define VEIL_ADD64(NAME, WORDS)                                              \
    void NAME(uint k, int v)                                                 \
    {                                                                        \
        if (v == 0) return;                                                  \
        uint u = uint(v);                                                    \
        uint old = atomicAdd(WORDS[k], u);                                   \
        uint hi = (v < 0 ? 0xffffffffu : 0u) + (old + u < old ? 1u : 0u);    \
        if (hi != 0u) atomicAdd(WORDS[k + 1u], hi);                          \
    }
VEIL_ADD64(add64, sums)
VEIL_ADD64(add64c, counts)

// The photon's visit to one cell so far: its pieces' w len (rgb) and
// lum(w) len d, added to the cell's sums once, when it leaves the cell
// (or ends): a photon that collides many times in a cell pays one set of
// atomics for the visit, not one a piece.
vec3 visit_phi, visit_flux;
// Which sums the photon's pieces go to: those of the light scattered once
// (emission: not yet scattered), or, from its next scattering on, the
// later ones (the march gives the two lobes different phase functions).
bool later;
// The photon's energy account (core/shared.glsl.h): its sums so far, in W (the track length in W m).
vec3 acc_in, acc_out, acc_absorbed, acc_coll, acc_track, acc_later_in, acc_later_track;
float visit_len;
bool visit_any;

// The visit's sums into cell c (in units: W/m^2 times the fixed point's units per W/m^2).
void flush(ivec3 c, bool odd)
{
    if (!visit_any) return;
    uint k0 = (uint(c.x) + uint(cb.dims.x) * (uint(c.y) + uint(cb.dims.y) * uint(c.z))) * uint(VEIL_CACHE_WORDS);
    uint k = k0 + (later ? uint(VEIL_CACHE_LATER) : 0u);
    float u = cb.scale.z * cb.scale.x; // units per W m of weight times length
    float xi = rnd();
    vec3 p = visit_phi * u, f = visit_flux * u;
    add64(k + 0u, veil_cache_fixed(p.r, xi));
    add64(k + 2u, veil_cache_fixed(p.g, xi));
    add64(k + 4u, veil_cache_fixed(p.b, xi));
    add64(k + 6u, veil_cache_fixed(f.x, xi));
    add64(k + 8u, veil_cache_fixed(f.y, xi));
    add64(k + 10u, veil_cache_fixed(f.z, xi));
    if (odd) add64(k0 + 12u, veil_cache_fixed(dot(p, vec3(VEIL_LUM_R, VEIL_LUM_G, VEIL_LUM_B)), xi));
    if (max(p.r, max(p.g, p.b)) > float(VEIL_CACHE_VISIT_DIAGONALS << VEIL_CACHE_FIXED_BITS))
        atomicAdd(counts[1], 1u);
    visit_phi = vec3(0.0), visit_flux = vec3(0.0);
    visit_len = 0.0;
    visit_any = false;
}

// A piece of path of length len in cell c, weights w, along d: added to the
// visit, which is flushed before it holds more than VEIL_CACHE_VISIT_DIAGONALS
// cell diagonals of path (the fixed point's headroom).
void visit(ivec3 c, vec3 w, vec3 d, float len, bool odd)
{
    if (visit_len + len > float(VEIL_CACHE_VISIT_DIAGONALS) * 1.7320508 * cb.origin.w) flush(c, odd);
    visit_phi += w * len;
    acc_track += w * len;
    if (later) acc_later_track += w * len;
    visit_flux += dot(w, vec3(VEIL_LUM_R, VEIL_LUM_G, VEIL_LUM_B)) * len * d;
    visit_len += len;
    visit_any = true;
}

// The photon's energy account, added when it ends (the groups: photon n mod VEIL_CACHE_ENERGY_GROUPS).
void account(uint n)
{
    if (!(max(acc_in.r, max(acc_in.g, acc_in.b)) > 0.0)) return;
    uint k = 4u + (n % uint(VEIL_CACHE_ENERGY_GROUPS)) * uint(6 * VEIL_CACHE_ENERGY_KINDS);
    float u = cb.power.w, xi = rnd();
    for (int c = 0; c < 3; ++c) {
        add64c(k + uint(6 * VEIL_CACHE_ENERGY_IN + 2 * c), veil_cache_fixed(acc_in[c] * u, xi));
        add64c(k + uint(6 * VEIL_CACHE_ENERGY_OUT + 2 * c), veil_cache_fixed(acc_out[c] * u, xi));
        add64c(k + uint(6 * VEIL_CACHE_ENERGY_ABSORBED + 2 * c), veil_cache_fixed(acc_absorbed[c] * u, xi));
        add64c(k + uint(6 * VEIL_CACHE_ENERGY_COLLISIONS + 2 * c), veil_cache_fixed(acc_coll[c] * u * (1.0 / 65536.0), xi));
        add64c(k + uint(6 * VEIL_CACHE_ENERGY_TRACK + 2 * c),
               veil_cache_fixed(acc_track[c] * u / (65536.0 * 1.7320508 * cb.origin.w), xi));
        add64c(k + uint(6 * VEIL_CACHE_ENERGY_LATER_IN + 2 * c), veil_cache_fixed(acc_later_in[c] * u, xi));
        add64c(k + uint(6 * VEIL_CACHE_ENERGY_LATER_TRACK + 2 * c),
               veil_cache_fixed(acc_later_track[c] * u / (65536.0 * 1.7320508 * cb.origin.w), xi));
    }
}

// A direction scattered from d by Henyey-Greenstein g (inverting its CDF in cos).
vec3 scatter_hg(vec3 d, float g)
{
    float cos_t = hg_cos(g, rnd());
    return around(d, cos_t, 2.0 * VEIL_PI * rnd());
}

// Photon n, from its start to its end; a photon cut at the step cap is counted, its account left out.
// Where a frame's surfaces are given (veil fog), a photon that meets them is absorbed there: the
// light they send back is the frame's, spread by the screen-space pass.
void trace(uint n)
{
    float h = cb.origin.w;
    vec3 grid_hi = cb.origin.xyz + vec3(cb.dims.xyz) * h;
    vec3 pos, dir, w = cb.power.rgb;
    bool scored = false, odd = (n & 1u) != 0u;
    if (cb.source.x == uint(VEIL_CACHE_SUN)) {
        pos = cb.src0.xyz + rnd() * cb.src1.xyz + rnd() * cb.src2.xyz;
        dir = cb.src3.xyz;
    } else if (cb.source.x == uint(VEIL_CACHE_CONE)) {
        pos = cb.src0.xyz;
        dir = around(cb.src1.xyz, 1.0 - rnd() * (1.0 - cb.src1.w), 2.0 * VEIL_PI * rnd());
        int l = int(cb.source.y);
        if (int(med.lights[l].position.w) == VEIL_LIGHT_SPOT)
            w *= veil_spot_falloff(dot(dir, med.lights[l].direction.xyz), med.lights[l].direction.w, med.lights[l].color.w);
    } else if (cb.source.x == uint(VEIL_CACHE_ENV)) {
        // the environment's rest: a texel block by its CDF (binary search, as the emission's), a direction
        // uniform in solid angle within it, a start on the disc across it that covers the grid's bounding
        // sphere, upstream of it
        float xi = rnd();
        int a = 0, b = cb.dims.w - 1;
        while (a < b) {
            int m = (a + b) / 2;
            if (uintBitsToFloat(emitters[2 * m].y) > xi) b = m; else a = m + 1;
        }
        int k = int(uintBitsToFloat(emitters[2 * a].x)), f = int(cb.src3.w);
        int mw = int(cb.src1.w), mh = int(cb.src2.w), tw = (mw + f - 1) / f;
        int bi = k % tw, bj = k / tw;
        float phi = 2.0 * VEIL_PI * mix(float(bi * f), float(min((bi + 1) * f, mw)), rnd()) / float(mw);
        float c0 = cos(VEIL_PI * float(bj * f) / float(mh)), c1 = cos(VEIL_PI * float(min((bj + 1) * f, mh)) / float(mh));
        float ct = mix(c0, c1, rnd()), st = sqrt(max(1.0 - ct * ct, 0.0));
        vec3 sky = normalize(-st * cos(phi) * cb.src1.xyz + ct * cb.src2.xyz - st * sin(phi) * cb.src3.xyz);
        float r = cb.src0.w;
        pos = cb.src0.xyz + sky * r + around(sky, 0.0, 2.0 * VEIL_PI * rnd()) * (r * sqrt(rnd()));
        dir = -sky;
        w *= uintBitsToFloat(emitters[2 * a + 1].xyz);
        scored = true; // its light has not scattered yet: the cache carries every order of it
    } else {
        // an emitting cell by its CDF (binary search for the first entry above xi), uniform within it
        float xi = rnd();
        int a = 0, b = cb.dims.w - 1;
        while (a < b) {
            int m = (a + b) / 2;
            if (uintBitsToFloat(emitters[m].y) > xi) b = m; else a = m + 1;
        }
        uint k = emitters[a].x;
        ivec3 c = ivec3(int(k % uint(cb.dims.x)), int((k / uint(cb.dims.x)) % uint(cb.dims.y)),
                        int(k / uint(cb.dims.x * cb.dims.y)));
        pos = cb.origin.xyz + (vec3(c) + vec3(rnd(), rnd(), rnd())) * h;
        w *= in_ev_box(pos) ? cache_emission(pos) / uintBitsToFloat(emitters[a].z) : vec3(0.0);
        dir = around(vec3(0.0, 0.0, 1.0), 1.0 - 2.0 * rnd(), 2.0 * VEIL_PI * rnd());
        scored = true;
    }
    later = false;
    if (!(max(w.r, max(w.g, w.b)) > 0.0)) return;
    vec2 span = box_hit(pos, dir, cb.origin.xyz, grid_hi, 0.0, INF);
    if (span.x >= span.y) return;
    if (scored) acc_in = w; // the emission's (and the environment's) light enters the account at its start
    pos += dir * span.x;
    ivec3 c = clamp(ivec3(floor((pos - cb.origin.xyz) / h)), ivec3(0), cb.dims.xyz - 1);
    ivec3 step_dir = ivec3(sign(dir));
    float tau = -log(1.0 - rnd()); // the majorant's optical depth to the next tentative collision
    float g = cb.sigma_s.w;
    int steps = 0;
    const int cap = int(cb.seed.z);
    visit_phi = vec3(0.0), visit_flux = vec3(0.0);
    visit_len = 0.0;
    visit_any = false;
    for (; steps < cap; ++steps) {
        // where the path leaves cell c
        vec3 lo = cb.origin.xyz + vec3(c) * h;
        vec3 t3 = vec3(INF);
        for (int a = 0; a < 3; ++a)
            if (dir[a] != 0.0) t3[a] = max(((dir[a] > 0.0 ? lo[a] + h : lo[a]) - pos[a]) / dir[a], 0.0);
        float t_exit = min(t3.x, min(t3.y, t3.z));
        int axis = t3.x == t_exit ? 0 : (t3.y == t_exit ? 1 : 2);
        uint k = uint(c.x) + uint(cb.dims.x) * (uint(c.y) + uint(cb.dims.y) * uint(c.z));
        float maj = cells[k].x * cb.scale.w;
        if (maj > 0.0) maj = max(maj, cb.sigma_a.w);
#ifdef VEIL_SOLID
        // a frame's surface (veil fog, scene/solid.h) before the next collision or the cell's side absorbs it
        float t_next = maj * t_exit <= tau ? t_exit : tau / maj;
        float t_solid = solid_hit(pos, dir, t_next);
        if (t_solid < t_next) {
            if (scored) {
                visit(c, w, dir, t_solid, odd);
                acc_absorbed = w;
            }
            break;
        }
#endif
        if (maj * t_exit <= tau) { // no collision in the cell: on to the next
            if (scored) visit(c, w, dir, t_exit, odd);
            flush(c, odd);
            tau -= maj * t_exit;
            pos += dir * t_exit;
            c[axis] += step_dir[axis];
            if (c[axis] < 0 || c[axis] >= cb.dims[axis]) {
                if (scored) acc_out = w;
                break;
            }
            continue;
        }
        float t = tau / maj;
        if (scored) visit(c, w, dir, t, odd);
        pos += dir * t;
        // a tentative collision: absorbed, scattered or null
        float rho = cache_density(pos);
        if (rho * cb.scale.w > maj * 1.0001) atomicAdd(counts[2], 1u); // a majorant that is not one (a bug)
        vec3 s_s = rho * cb.sigma_s.rgb, s_a = rho * cb.sigma_a.rgb;
        vec3 s_n = max(vec3(maj) - s_s - s_a, vec3(0.0));
        float sw = maj * (w.r + w.g + w.b);
        float p_s = dot(w, s_s) / sw, p_a = dot(w, s_a) / sw, p_n = dot(w, s_n) / sw;
        if (scored) acc_coll += w * (s_s + s_a) / maj;
        float xi = rnd() * (p_s + p_a + p_n); // their sum is 1 but for rounding
        if (xi < p_a) { // absorbed (the visit so far is flushed below)
            if (scored) acc_absorbed = w * s_a / (maj * p_a);
            break;
        }
        if (xi < p_a + p_s) {
            w *= s_s / (maj * p_s);
            if (cb.seed.w != 0u) break; // the first scattering ends it (flushed below; its later light is not kept)
            dir = scatter_hg(dir, g);
            step_dir = ivec3(sign(dir));
            if (!scored) acc_in = w;
            else if (!later) {
                flush(c, odd); // what was scattered once ends here
                later = true;
                acc_later_in = w;
            }
            scored = true;
        } else {
            w *= s_n / (maj * p_n);
        }
        tau = -log(1.0 - rnd());
    }
    flush(c, odd); // the last visit: absorbed, or cut (a path that left the grid has flushed already)
    if (steps == cap) {
        atomicAdd(counts[0], 1u);
        acc_in = vec3(0.0), acc_out = vec3(0.0), acc_absorbed = vec3(0.0), acc_coll = vec3(0.0), acc_track = vec3(0.0);
        acc_later_in = vec3(0.0), acc_later_track = vec3(0.0);
    }
}

void main()
{
    uint n = cb.source.z + gl_GlobalInvocationID.x;
    state = mix32(cb.seed.x ^ mix32(cb.seed.y * 0x9e3779b9u ^ mix32(n)));
    acc_in = vec3(0.0), acc_out = vec3(0.0), acc_absorbed = vec3(0.0), acc_coll = vec3(0.0), acc_track = vec3(0.0);
    acc_later_in = vec3(0.0), acc_later_track = vec3(0.0);
    if (n >= cb.source.w) return;
    trace(n);
    account(n);
}
