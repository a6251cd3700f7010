// veil — optical depth over a sparse volume (volume/sparse.h), brick by
// brick in the order the light reaches them: one work group a kept brick,
// one invocation a texel of its atlas (voxel 8b + j, j in 0..8). Each
// texel's path to the light is marched through its own brick (midpoint
// steps of VEIL_SPARSE_OD_STEP voxels), then through the bricks and nodes
// without density (skipped), and ends where it enters a kept brick: there
// the optical depth that brick already holds (computed in an earlier pass:
// a brick nearer the light in the pass order, opv_set.c) is read, trilinear
// on the face it enters (a semi-Lagrangian step a brick long). Or it ends
// at the light or the box's edge. D in density m, in channel od.pass.x.
layout(local_size_x = VEIL_SPARSE_APRON, local_size_y = VEIL_SPARSE_APRON, local_size_z = VEIL_SPARSE_APRON) in;
layout(binding = VEIL_IMAGE_SPARSE_OUT, rgba32f) uniform image3D u_out;
layout(binding = VEIL_TEX_SPARSE_COORDS) uniform isamplerBuffer u_sp_coords;
layout(binding = VEIL_TEX_SPARSE_LIST) uniform isamplerBuffer u_list; // slot indices, pass by pass
layout(binding = VEIL_TEX_OPV0) uniform sampler3D u_depth;            // u_out, sampled: earlier passes' bricks
// od.light: xyz: a point light's position in index coordinates (voxel i's
// centre at i + 0.5), or a sun's unit direction towards it; w: VEIL_LIGHT_*.
// od.pass: x: the channel, 0..3; y: this pass's first entry of u_list.
//@include propagate/opv_blocks.glsl.h
layout(std140, binding = VEIL_UBO_PROPAGATE) uniform veil_sparse_od_ubo { veil_sparse_od_block od; };
//@include volume/shaders/sparse_common.glsl

void main()
{
    int k = texelFetch(u_list, od.pass.y + int(gl_WorkGroupID.x)).r;
    ivec3 j = ivec3(gl_LocalInvocationID);
    ivec3 b = texelFetch(u_sp_coords, k).xyz;
    ivec3 corner = ivec3(k % sp.atlas.x, (k / sp.atlas.x) % sp.atlas.y, k / (sp.atlas.x * sp.atlas.y)) * VEIL_SPARSE_APRON;
    vec3 q = vec3(b * VEIL_BRICK + j) + 0.5;
    vec3 d = od.light.xyz;
    float len = INF;
    if (int(od.light.w) != VEIL_LIGHT_DIRECTIONAL) {
        vec3 to = od.light.xyz - q;
        len = length(to);
        d = len > 0.0 ? to / len : vec3(0.0, 0.0, 1.0);
    }
    vec2 s = box_hit(q, d, vec3(0.5), sp.dims.xyz - 0.5, 0.0, len);
    float D = 0.0;
    if (s.x < s.y) {
        // through its own brick (a texel on a face it leaves along a component too small to move it off
        // in float stays in its brick: to the next face then, or it would read its own unmade depth)
        float t = min(sp_brick(q + d * 1e-3) == b ? sp_region_exit_ahead(q, d, b, 1) : sp_region_exit(q, d, b, 1), s.y);
        D = sp_integral(q, d, 0.0, t, VEIL_SPARSE_OD_STEP) * sp.origin.w;
        // past the bricks without density, to the first kept one: its optical depth where the path enters it
        while (t < s.y) {
            float ahead = max(1e-3, 4.8e-7 * t);
            ivec3 nb = sp_brick(q + d * (t + ahead));
            int region;
            uint slot = sp_slot(nb, region);
            if (slot != 0u) {
                D += texture(u_depth, sp_atlas_uvw(slot, nb, q + d * t))[od.pass.x];
                break;
            }
            t += max(sp_region_exit_ahead(q + d * t, d, nb, region), ahead);
        }
    }
    vec4 all = imageLoad(u_out, corner + j);
    all[od.pass.x] = D;
    imageStore(u_out, corner + j, all);
}
