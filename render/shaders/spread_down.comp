// veil — screen-space multiple scattering, step 2 (Iser & Elek 2018, 4.2-4.3):
// level k = u.mode.w of every chain from level k - 1, one invocation per
// texel of level k. G is the separable filter of u.mode.x taps (2, 4, 6;
// weights u.weights_*) centred on the level-(k-1) texels 2i, 2i + 1, so
// each texel of level k - 1 gives a quarter of itself to level k (in the
// interior; texels beyond the chain are 0: light spread off the image
// leaves it). Per tap:
//   L_sc^k   = (M L_sc^(k-1)) * G,  M = smoothstep(T / (1 + eps), T, W^(k-1))
//              (the leak mask; 1 without it), T = c 2^(k-1), or c 2^k when
//              levels are interpolated cubically (a pixel is then read from
//              one level above its own too).
// The mask. The paper writes smoothstep(T, (1 + eps) T, W) with T = c 2^(k-1):
// read so, a pixel of spread W = c 2^j, which reads level j, enters level
// j at smoothstep(W/2, 3W/2, W) = 1/2 and half of its light is lost (on a
// constant-W image: 42 % RMSE against the gathering filter, tests/render/
// test_spread.c). A pixel must be whole in every level it is read from
// (j and j + 1 for a fractional level, one more for cubic interpolation)
// and may fade from the levels above: so the ramp ends at T.
//   W^k      = (Y W^(k-1)) * U / Y * U,  Y = lum(L_sc^(k-1))  (else W * U)
//   P^k      = P^(k-1) * G  (and P s likewise: s is read as (P s) / P)
//   L_ssc^k  = L_ssc^(k-1) * G,  P_ssc^k = (Y_ssc P_ssc) * U / Y_ssc * U
// U is the uniform filter over the same taps; where Y * U = 0 it falls
// back to the plain mean.
layout(local_size_x = VEIL_SPREAD_GROUP, local_size_y = VEIL_SPREAD_GROUP) in;
//@include render/shaders/spread_common.glsl

layout(binding = VEIL_SPREAD_TEX_SC) uniform sampler2D t_sc;
layout(binding = VEIL_SPREAD_TEX_P) uniform sampler2D t_p;
layout(binding = VEIL_SPREAD_TEX_SSC) uniform sampler2D t_ssc;
layout(binding = VEIL_SPREAD_OUT_SC, rgba32f) writeonly uniform image2D u_sc;
layout(binding = VEIL_SPREAD_OUT_P, rgba32f) writeonly uniform image2D u_p;
layout(binding = VEIL_SPREAD_OUT_SSC, rgba32f) writeonly uniform image2D u_ssc;

void main()
{
    int k = u.mode.w;
    ivec2 size = u.size.zw >> k, src_size = u.size.zw >> (k - 1);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, size))) return;
    int taps = u.mode.x;
    bool sep = u.flags.w != 0u;
    float T = u.params.x * exp2(float(u.mode.y == VEIL_INTERP_CUBIC_BICUBIC ? k : k - 1));
    vec3 L = vec3(0.0), Ls = vec3(0.0);
    vec2 Pc = vec2(0.0);
    float yw = 0.0, y = 0.0, wsum = 0.0, n = 0.0, ysp = 0.0, ys = 0.0, psum = 0.0;
    for (int j = 0; j < taps; ++j) {
        int sy = 2 * p.y + j - (taps / 2 - 1);
        if (sy < 0 || sy >= src_size.y) continue;
        for (int i = 0; i < taps; ++i) {
            int sx = 2 * p.x + i - (taps / 2 - 1);
            if (sx < 0 || sx >= src_size.x) continue;
            ivec2 s = ivec2(sx, sy);
            float g = tap(i) * tap(j);
            vec4 a = texelFetch(t_sc, s, k - 1);
            float M = u.flags.x != 0u ? smoothstep(T / (1.0 + u.params.y), T, a.a) : 1.0;
            L += g * M * a.rgb;
            float ya = lum(a.rgb);
            yw += ya * a.a;
            y += ya;
            wsum += a.a;
            n += 1.0;
            Pc += g * texelFetch(t_p, s, k - 1).xy;
            if (sep) {
                vec4 b = texelFetch(t_ssc, s, k - 1);
                Ls += g * b.rgb;
                float yb = lum(b.rgb);
                ysp += yb * b.a;
                ys += yb;
                psum += b.a;
            }
        }
    }
    float W = u.flags.y != 0u && y > 0.0 ? yw / y : (n > 0.0 ? wsum / n : 0.0);
    imageStore(u_sc, p, vec4(L, W));
    imageStore(u_p, p, vec4(Pc, 0.0, 0.0));
    if (sep) imageStore(u_ssc, p, vec4(Ls, ys > 0.0 ? ysp / ys : (n > 0.0 ? psum / n : 0.0)));
}
