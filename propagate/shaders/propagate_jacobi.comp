// veil — one Jacobi step of the axis-neighbour gather (published, or with
// the corrected step length) for up to four lights at once (light c in
// channel c). Reads the previous step from u_src, writes u_dst; raises
// `changed` when any value moved by more than u_tolerance. The update is
// veil_gather_cell() in propagate/opv_schemes.glsl.h, shared with the C
// version.
layout(local_size_x = VEIL_BRICK, local_size_y = VEIL_BRICK, local_size_z = VEIL_BRICK) in;

layout(binding = VEIL_IMAGE_EV, r32f) readonly uniform image3D u_ev;
layout(binding = VEIL_IMAGE_OPV_SRC, rgba32f) readonly uniform image3D u_src;
layout(binding = VEIL_IMAGE_OPV_DST, rgba32f) writeonly uniform image3D u_dst;
layout(std430, binding = VEIL_BIND_FLAGS) buffer Flags { uint changed; };

uniform ivec3 u_dims;
uniform float u_voxel;
uniform int u_count;          // lights in this texture, 1..4
uniform int u_corrected;      // 0: one voxel per step (published); 1: corrected step length
uniform int u_type[4];        // VEIL_LIGHT_POINT / VEIL_LIGHT_DIRECTIONAL
uniform vec3 u_light[4];      // point: index-space position; directional: unit vector toward the light
uniform ivec3 u_cell[4];      // point: the light's voxel
uniform float u_tolerance;

int g_channel; // the light being gathered (read by VEIL_DIN)

#define VEIL_CTX_PARAM
#define VEIL_CTX_ARG
#define VEIL_DIMS(a) u_dims[a]
#define VEIL_RHO(i, j, k) imageLoad(u_ev, ivec3(i, j, k)).r
#define VEIL_DIN(i, j, k) imageLoad(u_src, ivec3(i, j, k))[g_channel]
//@include propagate/opv_schemes.glsl.h

void main()
{
    ivec3 x = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(x, u_dims))) return;
    vec4 old = imageLoad(u_src, x);
    vec4 result = vec4(0.0);
    for (int c = 0; c < u_count; ++c) {
        g_channel = c;
        result[c] = veil_gather_cell(x.x, x.y, x.z, u_type[c], u_light[c].x, u_light[c].y, u_light[c].z,
                                     u_cell[c].x, u_cell[c].y, u_cell[c].z, u_voxel, u_corrected);
    }
    imageStore(u_dst, x, result);
    vec4 delta = abs(result - old);
    if (max(max(delta.x, delta.y), max(delta.z, delta.w)) > u_tolerance) changed = 1u;
}
