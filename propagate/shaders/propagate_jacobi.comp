// veil — one Jacobi step of the axis-neighbour gather (published, or with
// the corrected step length) for up to four lights at once (light c in
// channel c). Reads the previous step from u_src, writes u_dst; raises
// `changed` when any value moved by more than the tolerance (jb.params.y).
// The update is veil_gather_cell() in propagate/opv_schemes.glsl.h, shared
// with the C version; the block is veil_jacobi_block
// (propagate/opv_blocks.glsl.h).
layout(local_size_x = VEIL_BRICK, local_size_y = VEIL_BRICK, local_size_z = VEIL_BRICK) in;

layout(binding = VEIL_IMAGE_EV, r32f) readonly uniform image3D u_ev;
layout(binding = VEIL_IMAGE_OPV_SRC, rgba32f) readonly uniform image3D u_src;
layout(binding = VEIL_IMAGE_OPV_DST, rgba32f) writeonly uniform image3D u_dst;
layout(std430, binding = VEIL_BIND_FLAGS) buffer Flags { uint changed; };

//@include propagate/opv_blocks.glsl.h
layout(std140, binding = VEIL_UBO_PROPAGATE) uniform veil_jacobi_ubo { veil_jacobi_block jb; };

int g_channel; // the light being gathered (read by VEIL_DIN)

#define VEIL_CTX_PARAM
#define VEIL_CTX_ARG
// the grid's size, copied from the block once an invocation (main) so that
// the scheme's per-sample reads come from a register (a uniform block read
// after an image store is read again)
ivec3 g_dims;
#define VEIL_DIMS(a) g_dims[a]
#define VEIL_RHO(i, j, k) imageLoad(u_ev, ivec3(i, j, k)).r
#define VEIL_DIN(i, j, k) imageLoad(u_src, ivec3(i, j, k))[g_channel]
//@include propagate/opv_schemes.glsl.h

void main()
{
    ivec3 x = ivec3(gl_GlobalInvocationID);
    g_dims = jb.dims.xyz;
    if (any(greaterThanEqual(x, g_dims))) return;
    vec4 old = imageLoad(u_src, x);
    vec4 result = vec4(0.0);
    for (int c = 0; c < jb.dims.w; ++c) {
        g_channel = c;
        result[c] = veil_gather_cell(x.x, x.y, x.z, jb.cell[c].w, jb.light[c].x, jb.light[c].y, jb.light[c].z,
                                     jb.cell[c].x, jb.cell[c].y, jb.cell[c].z, jb.params.x, jb.mode.x);
    }
    imageStore(u_dst, x, result);
    vec4 delta = abs(result - old);
    if (max(max(delta.x, delta.y), max(delta.z, delta.w)) > jb.params.y) changed = 1u;
}
