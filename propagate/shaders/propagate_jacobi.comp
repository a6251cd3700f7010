// veil — one Jacobi step of the published ping-pong gather for up to four
// lights at once (light c in channel c). Reads the previous step from
// u_src, writes u_dst; raises flags[0] when any value moved by more than
// u_tolerance. Mirrors gather() in propagate/opv_cpu.c operation for
// operation (see propagate/opv.h for the scheme).
layout(local_size_x = VEIL_BRICK, local_size_y = VEIL_BRICK, local_size_z = VEIL_BRICK) in;

layout(binding = VEIL_IMAGE_EV, r32f) readonly uniform image3D u_ev;
layout(binding = VEIL_IMAGE_OPV_SRC, rgba32f) readonly uniform image3D u_src;
layout(binding = VEIL_IMAGE_OPV_DST, rgba32f) writeonly uniform image3D u_dst;
layout(std430, binding = VEIL_BIND_FLAGS) buffer Flags { uint changed; };

uniform ivec3 u_dims;
uniform float u_voxel;
uniform int u_count;          // lights in this texture, 1..4
uniform int u_type[4];        // VEIL_LIGHT_POINT / VEIL_LIGHT_DIRECTIONAL
uniform vec3 u_light[4];      // point: index-space position; directional: unit vector toward the light
uniform float u_tolerance;

float gather(ivec3 x, int c, float r)
{
    precise vec3 d = u_type[c] == VEIL_LIGHT_POINT ? u_light[c] - vec3(x) : u_light[c];
    float lim = u_type[c] == VEIL_LIGHT_POINT ? 0.5 : 0.0;
    float h = u_voxel;
    precise float wsum = 0.0;
    for (int a = 0; a < 3; ++a)
        if (abs(d[a]) > lim) wsum += abs(d[a]);
    if (wsum == 0.0) {
        precise float len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        precise float inside = r * (h * len);
        return inside;
    }
    precise float acc = 0.0;
    for (int a = 0; a < 3; ++a) {
        if (!(abs(d[a]) > lim)) continue;
        ivec3 n = x;
        n[a] += d[a] > 0.0 ? 1 : -1;
        precise float term;
        if (n[a] < 0 || n[a] >= u_dims[a]) {
            term = 0.5 * h * r;
        } else {
            float rn = imageLoad(u_ev, n).r;
            term = imageLoad(u_src, n)[c] + 0.5 * h * (r + rn);
        }
        acc += (abs(d[a]) / wsum) * term;
    }
    return acc;
}

void main()
{
    ivec3 x = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(x, u_dims))) return;
    float r = imageLoad(u_ev, x).r;
    vec4 old = imageLoad(u_src, x);
    vec4 result = vec4(0.0);
    for (int c = 0; c < u_count; ++c) result[c] = gather(x, c, r);
    imageStore(u_dst, x, result);
    vec4 delta = abs(result - old);
    if (max(max(delta.x, delta.y), max(delta.z, delta.w)) > u_tolerance) changed = 1u;
}
