// veil — the octave estimate's gate (volumetric/volumetric.h, "escape" field):
// per cell of a coarse grid over the medium, the chance that light
// scattered there scatters again before it leaves the medium, averaged over
// directions:
//   P_s(x) = mean over k of (1 - exp(-sigma_t tau_k(x)))
// with tau_k the density integral from x along direction k (the 6 axes and
// the 8 diagonals) to the end of the medium: the EV marched at one step per
// voxel (midpoint rule) plus the fogs in closed form. View- and
// light-independent: kept while the volume and the medium are unchanged.
// Over a sparse volume (VEIL_SPARSE) the cells are the kept bricks' own:
// VEIL_SPARSE_ESCAPE^3 points a brick (every 4 voxels), in an atlas laid out
// like the density's; the EV is marched through the bricks it meets.
layout(local_size_x = VEIL_DIFFUSION_GROUP, local_size_y = VEIL_DIFFUSION_GROUP, local_size_z = VEIL_DIFFUSION_GROUP) in;
layout(binding = VEIL_IMAGE_DIFF_PHI, rgba32f) writeonly uniform image3D u_out;
layout(std140, binding = VEIL_UBO_DIFFUSION) uniform veil_diffusion_ubo { veil_diffusion_block dg; };
//@include propagate/shaders/lit_medium.glsl
#ifdef VEIL_SPARSE
layout(binding = VEIL_TEX_SPARSE_COORDS) uniform isamplerBuffer u_sp_coords;
#endif

float ev_integral(vec3 x, vec3 d)
{
    if (med.counts.z == 0) return 0.0;
#ifdef VEIL_SPARSE
    return sp_integral((x - sp.origin.xyz) / sp.origin.w, d, 0.0, INF, 1.0) * sp.origin.w; // a step a voxel, as below
#else
    vec2 s = box_hit(x, d, med.box_min.xyz, med.box_max.xyz, 0.0, INF);
    if (s.x >= s.y) return 0.0;
    float step = med.shape.y, sum = 0.0;
    int n = int(ceil((s.y - s.x) / step));
    float dt = (s.y - s.x) / float(max(n, 1));
    for (int i = 0; i < n; ++i) {
        vec3 p = x + d * (s.x + (float(i) + 0.5) * dt);
        sum += texture(u_ev, (p - med.tex_min.xyz) * med.tex_inv_size.xyz).r * dt;
    }
    return sum;
#endif
}

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dg.dims.xyz))) return;
#ifdef VEIL_SPARSE
    ivec3 brick = c / VEIL_SPARSE_ESCAPE;
    int k = brick.x + sp.atlas.x * (brick.y + sp.atlas.y * brick.z);
    if (k >= sp.bricks.w) return;
    ivec3 b = texelFetch(u_sp_coords, k).xyz;
    vec3 q = vec3(b * VEIL_BRICK + (c - brick * VEIL_SPARSE_ESCAPE) * (VEIL_BRICK / (VEIL_SPARSE_ESCAPE - 1))) + 0.5;
    vec3 x = sp.origin.xyz + q * sp.origin.w;
#else
    vec3 x = dg.origin.xyz + vec3(c) * dg.origin.w;
#endif
    float st = dot(med.sigma_t.rgb, vec3(1.0 / 3.0)), sum = 0.0;
    for (int k = 0; k < 14; ++k) {
        vec3 d = k < 6 ? vec3(k / 2 == 0 ? 1.0 : 0.0, k / 2 == 1 ? 1.0 : 0.0, k / 2 == 2 ? 1.0 : 0.0) * ((k & 1) == 0 ? 1.0 : -1.0)
                       : normalize(vec3((k & 1) == 0 ? 1.0 : -1.0, ((k - 6) & 2) == 0 ? 1.0 : -1.0, ((k - 6) & 4) == 0 ? 1.0 : -1.0));
        float tau = min(ev_integral(x, d) + fog_integral(x, d, 0.0, VEIL_DIFFUSION_MAX_EXTENT), INF);
        sum += 1.0 - exp(-st * tau);
    }
    imageStore(u_out, c, vec4(sum / 14.0, 0.0, 0.0, 0.0));
}
