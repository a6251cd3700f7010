// veil — the diffusion estimate, step 1: per cell of the diffusion grid,
// the density (the EV averaged over the cell: one trilinear read at the
// centre of a 2x2x2 block of voxels, plus the fogs at the centre) and the
// source of once-scattered light,
//   S = sigma_s rho sum_l E_l exp(-sigma_t D_l)     (W/m^3, per channel)
// with D_l the density integral to light l, as the march reads it.
layout(local_size_x = VEIL_DIFFUSION_GROUP, local_size_y = VEIL_DIFFUSION_GROUP, local_size_z = VEIL_DIFFUSION_GROUP) in;
layout(binding = VEIL_IMAGE_DIFF_SRC, rgba32f) writeonly uniform image3D u_src;
layout(std140, binding = VEIL_UBO_DIFFUSION) uniform veil_diffusion_ubo { veil_diffusion_block dg; };
//@include propagate/shaders/lit_medium.glsl

float fog_density(vec3 x)
{
    float rho = 0.0;
    for (int f = 0; f < med.counts.y; ++f) {
        if (any(lessThan(x, med.fogs[f].box_min.xyz)) || any(greaterThan(x, med.fogs[f].box_max.xyz))) continue;
        float k = med.fogs[f].origin.w * dot(x - med.fogs[f].origin.xyz, med.fogs[f].direction.xyz);
        rho += med.fogs[f].direction.w * exp(-max(k, -VEIL_FOG_MAX_EXPONENT));
    }
    return rho;
}

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dg.dims.xyz))) return;
    vec3 x = dg.origin.xyz + vec3(c) * dg.origin.w;
    float rho = fog_density(x);
    if (med.counts.z != 0 && all(greaterThanEqual(x, med.box_min.xyz)) && all(lessThanEqual(x, med.box_max.xyz)))
        rho += texture(u_ev, (x - med.tex_min.xyz) * med.tex_inv_size.xyz).r;
    vec3 S = vec3(0.0);
    if (rho > 0.0)
        for (int l = 0; l < med.counts.x; ++l) {
            vec3 travel, E;
            float len;
            if (!light_at(l, x, travel, E, len)) continue;
            S += E * exp(-med.sigma_t.rgb * depth_to_light(l, x, travel, len));
        }
    imageStore(u_src, c, vec4(med.sigma_s.rgb * rho * S, rho));
}
