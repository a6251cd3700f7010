// veil — screen-space multiple scattering, step 3 (Iser & Elek 2018, 4.2-4.4):
// per pixel, the level k(P) = clamp(log2(W(P) s / c), 0, K) read through
// the blurred density chain (k' = k(P^[k(P)])), and L'_sc = L_sc^[k'];
// with separation L'_ssc = L_ssc^[k''], k'' = k(P_ssc^[k_ssc]). Fractional
// levels: linear between the two nearest levels, or a cubic B-spline over
// four; within a level bilinear, or the cubic B-spline made of four
// bilinear taps (Sigg & Hadwiger 2005). The samplers clamp to a zero
// border (light spread off the image is gone).
// Output: rgb = L'_sc + L'_ssc, a = k' (for the AOV and the tests).
layout(local_size_x = VEIL_SPREAD_GROUP, local_size_y = VEIL_SPREAD_GROUP) in;
//@include render/shaders/spread_common.glsl

layout(binding = VEIL_SPREAD_TEX_SC) uniform sampler2D t_sc;
layout(binding = VEIL_SPREAD_TEX_P) uniform sampler2D t_p;
layout(binding = VEIL_SPREAD_TEX_SSC) uniform sampler2D t_ssc;
layout(binding = VEIL_SPREAD_OUT, rgba32f) writeonly uniform image2D u_out;

// Chain `which` (0: sc, 1: p, 2: ssc) at integer level l, at x in level-0
// pixel units (pixel centres at i + 0.5).
vec4 at_level(int which, vec2 x, int l, bool cubic)
{
    vec2 size = vec2(u.size.zw >> l);
    vec2 t = x / exp2(float(l));            // level-l texel units
    if (!cubic) {
        vec2 uv = t / size;
        return which == 0 ? textureLod(t_sc, uv, float(l)) : which == 1 ? textureLod(t_p, uv, float(l)) : textureLod(t_ssc, uv, float(l));
    }
    // cubic B-spline over the texel centres i - 1 .. i + 2 around t - 0.5:
    // pairs of taps merge into one bilinear read between them
    vec2 c = t - 0.5, i = floor(c), f = c - i;
    vec2 f2 = f * f, f3 = f2 * f;
    vec2 w0 = (1.0 - 3.0 * f + 3.0 * f2 - f3) / 6.0;
    vec2 w1 = (4.0 - 6.0 * f2 + 3.0 * f3) / 6.0;
    vec2 w2 = (1.0 + 3.0 * f + 3.0 * f2 - 3.0 * f3) / 6.0;
    vec2 w3 = f3 / 6.0;
    vec2 g0 = w0 + w1, g1 = w2 + w3;
    vec2 h0 = (i - 1.0 + 0.5 + w1 / g0) / size; // between centres i - 1 and i
    vec2 h1 = (i + 1.0 + 0.5 + w3 / g1) / size; // between centres i + 1 and i + 2
    vec4 s00, s10, s01, s11;
    float lf = float(l);
    if (which == 0) {
        s00 = textureLod(t_sc, vec2(h0.x, h0.y), lf); s10 = textureLod(t_sc, vec2(h1.x, h0.y), lf);
        s01 = textureLod(t_sc, vec2(h0.x, h1.y), lf); s11 = textureLod(t_sc, vec2(h1.x, h1.y), lf);
    } else if (which == 1) {
        s00 = textureLod(t_p, vec2(h0.x, h0.y), lf); s10 = textureLod(t_p, vec2(h1.x, h0.y), lf);
        s01 = textureLod(t_p, vec2(h0.x, h1.y), lf); s11 = textureLod(t_p, vec2(h1.x, h1.y), lf);
    } else {
        s00 = textureLod(t_ssc, vec2(h0.x, h0.y), lf); s10 = textureLod(t_ssc, vec2(h1.x, h0.y), lf);
        s01 = textureLod(t_ssc, vec2(h0.x, h1.y), lf); s11 = textureLod(t_ssc, vec2(h1.x, h1.y), lf);
    }
    return g0.y * (g0.x * s00 + g1.x * s10) + g1.y * (g0.x * s01 + g1.x * s11);
}

// Chain `which` at the fractional level k with the interpolation of u.mode.y.
vec4 fetch(int which, vec2 x, float k)
{
    int K = u.mode.z, mode = u.mode.y;
    bool cubic = mode != VEIL_INTERP_LINEAR_BILINEAR;
    int l = int(floor(k));
    float f = k - float(l);
    if (mode != VEIL_INTERP_CUBIC_BICUBIC) {
        vec4 a = at_level(which, x, l, cubic);
        return f > 0.0 ? mix(a, at_level(which, x, min(l + 1, K), cubic), f) : a;
    }
    float f2 = f * f, f3 = f2 * f;
    float w[4] = float[4]((1.0 - 3.0 * f + 3.0 * f2 - f3) / 6.0, (4.0 - 6.0 * f2 + 3.0 * f3) / 6.0,
                          (1.0 + 3.0 * f + 3.0 * f2 - 3.0 * f3) / 6.0, f3 / 6.0);
    vec4 sum = vec4(0.0);
    for (int j = 0; j < 4; ++j) sum += w[j] * at_level(which, x, clamp(l - 1 + j, 0, K), true);
    return sum;
}

void main()
{
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, u.size.xy))) return;
    vec2 x = vec2(p) + 0.5;
    vec2 pc = texelFetch(t_p, p, 0).xy;
    float s = pc.x > 0.0 ? pc.y / pc.x : 0.0;
    float k = level_of(pc.x, s);
    if (u.flags.z != 0u) {
        vec2 pb = fetch(1, x, k).xy;
        k = level_of(pb.x, pb.x > 0.0 ? pb.y / pb.x : 0.0);
    }
    vec3 L = fetch(0, x, k).rgb;
    if (u.flags.w != 0u) {
        float Ps = fetch(2, x, u.weights_hi.z).a;
        L += fetch(2, x, level_of(Ps, s)).rgb;
    }
    imageStore(u_out, p, vec4(L, k));
}
