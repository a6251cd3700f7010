// veil — RBF splat into the extinction volume (density, r32f), added to
// what the volume holds (zero, or density from other sources).
// Eight work groups per VEIL_BRICK^3 brick, one an octant of it (a software
// rasteriser runs a work group on one thread: a dispatch of a few crowded
// bricks still keeps every thread busy); each invocation is one voxel and
// adds the Gaussians of its brick's particle list, in list order. Mirrors
// veil_inject_rbf_cpu() operation for operation; `precise` forbids fused
// multiply-adds so that the cut-off test r^2 <= r_cut^2 decides exactly as
// in C.
#define HALF_BRICK (VEIL_BRICK / 2)
layout(local_size_x = HALF_BRICK, local_size_y = HALF_BRICK, local_size_z = HALF_BRICK) in;

struct Particle {
    vec4 center_amp;  // centre (m), amplitude
    vec4 shape;       // a^2 (m^-2), r_cut^2 (m^2), unused, unused
};
layout(std430, binding = VEIL_BIND_PARTICLES) readonly buffer Particles { Particle particles[]; };
layout(std430, binding = VEIL_BIND_BRICK_START) readonly buffer BrickStart { uint brick_start[]; };
layout(std430, binding = VEIL_BIND_BRICK_LIST) readonly buffer BrickList { uint brick_list[]; };
layout(binding = VEIL_IMAGE_EV, r32f) uniform image3D u_ev;

// gb.dims.w: this dispatch's first brick, in the order of the lists (x fastest, then y, then z): a
// dispatch is a run of bricks, eight work groups each along x (the splat is split to bound each
// dispatch's work)
layout(std140, binding = VEIL_UBO_GRID) uniform veil_grid_ubo { veil_grid_block gb; };

void main()
{
    const int first = gb.dims.w + int(gl_WorkGroupID.x) / 8, layer = gb.bricks.x * gb.bricks.y;
    const int octant = int(gl_WorkGroupID.x) % 8;
    ivec3 b = ivec3(first % gb.bricks.x, (first % layer) / gb.bricks.x, first / layer);
    ivec3 v = b * VEIL_BRICK + HALF_BRICK * ivec3(octant & 1, (octant >> 1) & 1, octant >> 2) +
              ivec3(gl_LocalInvocationID);
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
