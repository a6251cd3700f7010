// veil — RBF splat into the extinction volume (density, r32f), added to
// what the volume holds (zero, or density from other sources).
// One work group per VEIL_BRICK^3 brick; with VEIL_SPLAT_OCTANTS eight, one an
// octant of it (a software rasteriser runs a work group on one thread: a
// dispatch of a few crowded bricks then keeps every thread busy; the
// octants read their brick's list eight times, so a dispatch of many bricks
// takes the whole-brick groups: volume/inject_gpu.c). Each invocation is one
// voxel and adds the Gaussians of its brick's particle list, in list order.
// Mirrors veil_inject_rbf_cpu() operation for operation; `precise` forbids
// fused multiply-adds so that the cut-off test r^2 <= r_cut^2 decides
// exactly as in C.
#ifdef VEIL_SPLAT_OCTANTS
#define GROUP_SIDE (VEIL_BRICK / 2)
#define GROUPS_A_BRICK 8
#else
#define GROUP_SIDE VEIL_BRICK
#define GROUPS_A_BRICK 1
#endif
layout(local_size_x = GROUP_SIDE, local_size_y = GROUP_SIDE, local_size_z = GROUP_SIDE) in;

struct Particle {
    vec4 center_amp;  // centre (m), amplitude
    vec4 shape;       // a^2 (m^-2), r_cut^2 (m^2), unused, unused
};
layout(std430, binding = VEIL_BIND_PARTICLES) readonly buffer Particles { Particle particles[]; };
layout(std430, binding = VEIL_BIND_BRICK_START) readonly buffer BrickStart { uint brick_start[]; };
layout(std430, binding = VEIL_BIND_BRICK_LIST) readonly buffer BrickList { uint brick_list[]; };
layout(binding = VEIL_IMAGE_EV, r32f) uniform image3D u_ev;

// gb.dims.w: this dispatch's first brick, in the order of the lists (x fastest, then y, then z): a
// dispatch is whole layers of bricks or a run of them, GROUPS_A_BRICK work groups each (the splat is split
// to bound each dispatch's work)
layout(std140, binding = VEIL_UBO_GRID) uniform veil_grid_ubo { veil_grid_block gb; };

void main()
{
    // the work group's place in the dispatch, x fastest: bricks in their order from the first (a dispatch of
    // whole layers is bricks.x x bricks.y x layers, a run of bricks (GROUPS_A_BRICK x n) x 1 x 1)
    const int g = int(gl_WorkGroupID.x + gl_NumWorkGroups.x * (gl_WorkGroupID.y + gl_NumWorkGroups.y * gl_WorkGroupID.z));
    const int first = gb.dims.w + g / GROUPS_A_BRICK, layer = gb.bricks.x * gb.bricks.y;
    const int part = g % GROUPS_A_BRICK; // 0 without octants
    ivec3 b = ivec3(first % gb.bricks.x, (first % layer) / gb.bricks.x, first / layer);
    ivec3 v = b * VEIL_BRICK + GROUP_SIDE * ivec3(part & 1, (part >> 1) & 1, part >> 2) + ivec3(gl_LocalInvocationID);
    if (any(greaterThanEqual(v, gb.dims.xyz))) return;
    uint brick = uint((b.z * gb.bricks.y + b.y) * gb.bricks.x + b.x);
    precise vec3 x = gb.origin.xyz + (vec3(v) + 0.5) * gb.origin.w;
    precise float sum = imageLoad(u_ev, v).r;
    uint end = brick_start[brick + 1u];
    for (uint e = brick_start[brick]; e < end; ++e) {
        Particle p = particles[brick_list[e]];
        precise vec3 d = x - p.center_amp.xyz;
        precise float r2 = d.x * d.x + d.y * d.y + d.z * d.z;
        if (r2 <= p.shape.y) sum += p.center_amp.w * exp(-(p.shape.x * r2));
    }
    imageStore(u_ev, v, vec4(sum));
}
