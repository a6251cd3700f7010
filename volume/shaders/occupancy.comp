// veil — occupancy bricks of the extinction volume: for each VEIL_BRICK^3
// brick, the largest density of its voxels and of the one-voxel ring
// around them (the trilinear stencil of any point whose index coordinate u
// has floor(u) inside the brick reaches one voxel beyond it). 0 means no
// sample taken in the brick can see any medium: the marcher skips it.
layout(local_size_x = VEIL_OCCUPANCY_GROUP, local_size_y = VEIL_OCCUPANCY_GROUP, local_size_z = VEIL_OCCUPANCY_GROUP) in;

layout(binding = VEIL_IMAGE_EV, r32f) readonly uniform image3D u_ev;
layout(binding = VEIL_IMAGE_OUT, r32f) writeonly uniform image3D u_occ;

layout(std140, binding = VEIL_UBO_GRID) uniform veil_grid_ubo { veil_grid_block gb; }; // dims, bricks

void main()
{
    ivec3 b = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(b, gb.bricks.xyz))) return;
    ivec3 lo = max(b * VEIL_BRICK - 1, ivec3(0));
    ivec3 hi = min(b * VEIL_BRICK + VEIL_BRICK, gb.dims.xyz - 1);
    float m = 0.0;
    for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x) m = max(m, imageLoad(u_ev, ivec3(x, y, z)).r);
    imageStore(u_occ, b, vec4(m));
}
