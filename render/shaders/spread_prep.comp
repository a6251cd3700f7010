// veil — screen-space multiple scattering, step 1 (Iser & Elek 2018, 4.1):
// level 0 of the chains from the march's buffers and the input radiance L.
//   L_sc = exp(-C_a P) (1 - exp(-C_s P)) L  +  Q
// where the first term is the light of the background (or the frame under
// `veil fog`) scattered, not absorbed, on its way to the camera, and Q the
// same for the single scattering (the march's aov_q, with its own P). The
// pixel's P is the luminance-weighted mean of the two P; W = W(P) s in
// pixels, s = 1 / (depth * radians per pixel) converting metres at the
// depth of the scattering to pixels. With separation, bright pixels of L
// with little density in front (mask M) go to their own chain.
// Outside the image (the padding up to a multiple of 2^K) everything is 0.
layout(local_size_x = VEIL_SPREAD_GROUP, local_size_y = VEIL_SPREAD_GROUP) in;
//@include render/shaders/spread_common.glsl

layout(binding = VEIL_SPREAD_IN_L, rgba32f) readonly uniform image2D u_L;
layout(binding = VEIL_SPREAD_IN_T, rgba32f) readonly uniform image2D u_T;
layout(binding = VEIL_SPREAD_IN_S, rgba32f) readonly uniform image2D u_S;
layout(binding = VEIL_SPREAD_IN_Q, rgba32f) readonly uniform image2D u_Q;
layout(binding = VEIL_SPREAD_OUT_SC, rgba32f) writeonly uniform image2D u_sc;
layout(binding = VEIL_SPREAD_OUT_P, rgba32f) writeonly uniform image2D u_p;
layout(binding = VEIL_SPREAD_OUT_SSC, rgba32f) writeonly uniform image2D u_ssc;

void main()
{
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, u.size.zw))) return;
    vec4 sc = vec4(0.0), pp = vec4(0.0), ssc = vec4(0.0);
    if (all(lessThan(p, u.size.xy))) {
        vec3 L = imageLoad(u_L, p).rgb;
        float P = imageLoad(u_T, p).a;
        float depth = imageLoad(u_S, p).a;
        vec4 q = imageLoad(u_Q, p);
        // exp(-C_a P) - exp(-C_t P) = exp(-C_a P) (1 - exp(-C_s P)), >= 0
        vec3 frac = max(exp(-u.sigma_a.rgb * P) - exp(-(u.sigma_a.rgb + u.sigma_s.rgb) * P), 0.0);
        vec3 bg = frac * L;
        float M = 0.0;
        if (u.flags.w != 0u)
            M = smoothstep(u.sep.x, u.sep.x + u.sep.y, lum(L)) * (1.0 - smoothstep(u.sep.z - u.sep.w, u.sep.z, P));
        float yb = lum(bg), yq = lum(q.rgb);
        float Pm = yb + yq > 0.0 ? (yb * P + yq * q.a) / (yb + yq) : P;
        float s = depth > 0.0 ? 1.0 / (depth * u.params.w) : 0.0;
        float W = veil_spread_width(Pm, u.sigma_a.w, u.sigma_s.w, u.params.z) * s;
        sc = vec4((1.0 - M) * bg + q.rgb, W);
        pp = vec4(Pm, Pm * s, 0.0, 0.0);
        ssc = vec4(M * bg, P);
    }
    imageStore(u_sc, p, sc);
    imageStore(u_p, p, pp);
    imageStore(u_ssc, p, ssc);
}
