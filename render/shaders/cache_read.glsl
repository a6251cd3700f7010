// veil — the light cache (volumetric/cache.h) as the march and the gather
// (render/shaders/cache_gather.comp) read it. Included after the march's
// block (u: u.diffusion is the grid's texture origin, u.diffusion_inv its
// scale and nz) and u_phi, the cache's texture: VEIL_CACHE_SLABS grids
// stacked along z (core/shared.glsl.h), each read with z clamped inside its
// own slab so that filtering never crosses into the next.
#ifndef VEIL_CACHE_READ_GLSL
#define VEIL_CACHE_READ_GLSL

// The cache's grids at x, trilinear: the light scattered once (phi1, F1),
// the later light (phi2, F2), the cells' free part (1 without a frame's
// solid) and the gathered later light (slab 4, cache_gather.comp). False
// outside the grid or where no cell is free.
bool cache_fetch(vec3 x, bool want_gathered, out vec3 phi1, out vec3 F1, out vec3 phi2, out vec3 F2, out float free_part, out vec3 gathered)
{
    phi1 = F1 = phi2 = F2 = gathered = vec3(0.0);
    free_part = 0.0;
    vec3 c = (x - u.diffusion.xyz) * u.diffusion_inv.xyz;
    if (!(all(greaterThanEqual(c, vec3(0.0))) && all(lessThanEqual(c, vec3(1.0))))) return false;
    float nz = u.diffusion_inv.w, z = clamp(c.z * nz, 0.5, nz - 0.5);
    const float slabs = float(VEIL_CACHE_SLABS);
    vec4 Fa = texture(u_phi, vec3(c.xy, (z + nz) / (slabs * nz)));
    // the cells hold their sums and (alpha) their part outside a frame's solid (1 without one): the
    // fluence of the fog here is the two interpolated, divided (a lobe's shape is a ratio: unchanged)
    if (!(Fa.w > 0.0)) return false;
    free_part = Fa.w;
    vec3 phi = texture(u_phi, vec3(c.xy, z / (slabs * nz))).rgb;
    phi2 = texture(u_phi, vec3(c.xy, (z + 2.0 * nz) / (slabs * nz))).rgb;
    F2 = texture(u_phi, vec3(c.xy, (z + 3.0 * nz) / (slabs * nz))).xyz;
    if (want_gathered) {
        // the gather's cells (u.limits.yzw) are s (u.march.w) of the cache's a side, from the same
        // corner; the slab's texels past them are never read
        float sc = max(u.march.w, 1.0);
        vec3 n = vec3(textureSize(u_phi, 0).xy, nz), gn = u.limits.yzw;
        vec3 t = clamp(c * n / sc, vec3(0.5), gn - 0.5);
        gathered = texture(u_phi, vec3(t.xy / n.xy, (t.z + 4.0 * nz) / (slabs * nz))).rgb;
    }
    phi1 = max(phi - phi2, vec3(0.0)); // the texture holds all the light and the later light
    F1 = Fa.xyz - F2;
    phi2 = max(phi2, vec3(0.0));
    return true;
}

// The light cache (volumetric/cache.h) towards -dir at x, per unit sigma_s
// rho. It holds two lights, each a fluence phi and a flux F: the light
// scattered once (of the emission: not yet scattered) and the later light
// (scattered more often). Each is taken as one HG lobe about F with mean
// cosine mu = |F| / phi, which the medium's HG(g) scatters into HG(g mu)
// about F (HG convolved with HG is HG with the product of the g's). That is
// how the once-scattered light is used. For the later light it is right
// inside the medium and wrong at its skin, where the light going towards the
// camera is what built up along the ray behind x (docs/multiple-scattering.md,
// "What the error is"). So the phase function is split as delta-Eddington
// splits it (Joseph et al. 1976): p = f delta + (1 - f) p' with f = g^2
// (f_peak in main). The delta's share, f L(x, -dir), is the later light
// arriving along the ray itself: main carries it by integrating with the
// reduced extinction sigma_t - f sigma_s (light scattered into the delta
// keeps its direction).
// Here is the rest: the lobe's scattering less the lobe's own delta share,
// phi (HG(g mu) - f HG(mu)) — exact where the lobe is the radiance, since
// then the two delta terms cancel (a control variate), and negative where the
// lobe is peaked towards the camera (the ray's share makes up for it).
float cache_lobe(vec3 phi, vec3 F, vec3 dir, float g)
{
    float pl = dot(phi, vec3(VEIL_LUM_R, VEIL_LUM_G, VEIL_LUM_B)), fl = length(F);
    float gc = pl > 0.0 && fl > 0.0 ? min(fl / pl, 1.0) : 0.0;
    vec3 axis = fl > 0.0 ? F / fl : vec3(0.0, 0.0, 1.0);
    return veil_phase_hg(dot(axis, -dir), g * gc);
}

// With the gather (u.march.y > 0 rays a cell, `gathered`), the later light
// is not taken from its lobe at x at all: slab 4 holds it scattered towards
// the camera, gathered from the lobes along rays through the medium
// (cache_gather.comp), and f is 0.
vec3 cache_in(vec3 x, vec3 dir, float f, bool use_gathered)
{
    vec3 phi1, F1, phi2, F2, gathered;
    float free_part;
    if (!cache_fetch(x, use_gathered, phi1, F1, phi2, F2, free_part, gathered)) return vec3(0.0);
    float g = med.shape.z;
    if (use_gathered) return (phi1 * cache_lobe(phi1, F1, dir, g) + gathered) / free_part;
    return (phi1 * cache_lobe(phi1, F1, dir, g) + phi2 * (cache_lobe(phi2, F2, dir, g) - f * cache_lobe(phi2, F2, dir, 1.0))) / free_part;
}
#endif
