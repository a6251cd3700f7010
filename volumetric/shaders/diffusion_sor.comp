// veil — the diffusion estimate, step 2: one red-black over-relaxed sweep
// (the cells of parity dg.dims.w) of the steady diffusion equation for the
// fluence phi of light scattered at least once,
//   -div(D grad phi) + sigma_a rho phi = S,   D = 1 / (3 sigma_tr rho)
// (sigma_tr = sigma_a + sigma_s (1 - g), the transport coefficient), per
// channel, on cells of edge h. Diffusion holds in a medium, not in vacuum:
// a cell whose transport optical thickness sigma_tr rho h is below
// dg.sigma_tr.w is vacuum (phi = 0 there, as beyond the grid), and a face
// between the medium and vacuum lets out the Marshak flux J = phi / 2 (the
// extrapolated-boundary condition phi - 2 D dphi/dn = 0): per unit volume
// phi / (2 h), i.e. a conductance D = h / 2 towards phi = 0. Between medium
// cells D is the harmonic mean (flux continuity). Discretised:
//   phi_i = (S_i h^2 + sum_j D_ij phi_j) / (sum_j D_ij + sigma_a rho_i h^2)
layout(local_size_x = VEIL_DIFFUSION_GROUP, local_size_y = VEIL_DIFFUSION_GROUP, local_size_z = VEIL_DIFFUSION_GROUP) in;
layout(binding = VEIL_IMAGE_DIFF_SRC, rgba32f) readonly uniform image3D u_src;
layout(binding = VEIL_IMAGE_DIFF_PHI, rgba32f) uniform image3D u_phi;
layout(std140, binding = VEIL_UBO_DIFFUSION) uniform veil_diffusion_ubo { veil_diffusion_block dg; };

float thickness(float rho) { return dot(dg.sigma_tr.rgb, vec3(1.0 / 3.0)) * rho * dg.origin.w; }

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    c.x = 2 * c.x + ((c.y + c.z + dg.dims.w) & 1); // this sweep's parity: x packed two to one
    if (any(greaterThanEqual(c, dg.dims.xyz))) return;
    vec4 s = imageLoad(u_src, c);
    if (thickness(s.a) < dg.sigma_tr.w) {
        imageStore(u_phi, c, vec4(0.0));
        return;
    }
    float h = dg.origin.w;
    vec3 Di = 1.0 / (3.0 * dg.sigma_tr.rgb * s.a);
    vec3 num = s.rgb * h * h, den = dg.sigma_a.rgb * s.a * h * h;
    const ivec3 nb[6] = ivec3[6](ivec3(1, 0, 0), ivec3(-1, 0, 0), ivec3(0, 1, 0), ivec3(0, -1, 0), ivec3(0, 0, 1), ivec3(0, 0, -1));
    for (int k = 0; k < 6; ++k) {
        ivec3 j = c + nb[k];
        bool inside = all(greaterThanEqual(j, ivec3(0))) && all(lessThan(j, dg.dims.xyz));
        float rho_j = inside ? imageLoad(u_src, j).a : 0.0;
        if (!inside || thickness(rho_j) < dg.sigma_tr.w) {
            den += vec3(0.5 * h); // Marshak: out through this face, to phi = 0
            continue;
        }
        vec3 Dj = 1.0 / (3.0 * dg.sigma_tr.rgb * rho_j);
        vec3 Dij = 2.0 * Di * Dj / (Di + Dj);
        num += Dij * imageLoad(u_phi, j).rgb;
        den += Dij;
    }
    vec3 old = imageLoad(u_phi, c).rgb;
    vec3 phi = max(old + dg.relax.x * (num / den - old), 0.0);
    imageStore(u_phi, c, vec4(phi, 0.0));
}
