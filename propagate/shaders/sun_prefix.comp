// veil — a sun's optical depth in its light-space grid (propagate/sun_space.h):
// one invocation per column (a, b), a prefix sum down the column along the
// light's travel, node by node, each step integrated with sb.dims.w Simpson
// panels clipped to the medium's box; D in density * m. Panels whose
// occupancy brick is empty add nothing and fetch nothing: a panel is at
// most one voxel long, so it lies within half a voxel of its midpoint m,
// and the brick b = floor((m + 1/2) / VEIL_BRICK) has 8b - 1/2 <= m <
// 8b + 15/2, whose zero region [8b - 1, 8b + 8] (the brick and its ring:
// volume/shaders/occupancy.comp) then holds the whole panel.
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = VEIL_TEX_EV) uniform sampler3D u_ev;   // density, trilinear
layout(binding = VEIL_TEX_OCC) uniform sampler3D u_occ; // max density per brick, ring included
layout(binding = VEIL_IMAGE_OPV_DST, r32f) writeonly uniform image3D u_out;

// veil_sun_block (propagate/opv_blocks.glsl.h): sb.dims.w Simpson panels a
// step, sb.nodes.w 1 to consult the occupancy, sb.origin.w metres a step
//@include propagate/opv_blocks.glsl.h
layout(std140, binding = VEIL_UBO_PROPAGATE) uniform veil_sun_ubo { veil_sun_block sb; };

float density(vec3 p) { return texture(u_ev, (p + 0.5) / vec3(sb.dims.xyz)).r; }

bool empty(vec3 m)
{
    if (sb.nodes.w == 0) return false;
    ivec3 b = ivec3(floor((m + 0.5) / float(VEIL_BRICK)));
    b = clamp(b, ivec3(0), textureSize(u_occ, 0) - 1);
    return texelFetch(u_occ, b, 0).r <= 0.0;
}

void main()
{
    ivec2 ab = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(ab, sb.nodes.xy))) return;
    vec3 p0 = sb.origin.xyz + float(ab.x) * sb.axis[0].xyz + float(ab.y) * sb.axis[1].xyz;
    // the column's span inside the box, in node steps
    float enter = 0.0, leave = float(sb.nodes.z - 1);
    for (int a = 0; a < 3; ++a) {
        float hi = float(sb.dims[a] - 1);
        if (sb.axis[2][a] == 0.0) {
            if (p0[a] < 0.0 || p0[a] > hi) leave = -1.0;
            continue;
        }
        float t0 = (0.0 - p0[a]) / sb.axis[2][a], t1 = (hi - p0[a]) / sb.axis[2][a];
        enter = max(enter, min(t0, t1));
        leave = min(leave, max(t0, t1));
    }
    float D = 0.0, s_last = -1.0, f_last = 0.0;
    imageStore(u_out, ivec3(ab, 0), vec4(0.0));
    int first = max(1, int(floor(enter)));     // nodes before the box: 0
    int last = min(sb.nodes.z - 1, int(ceil(leave)));
    for (int k = 1; k < first && k < sb.nodes.z; ++k) imageStore(u_out, ivec3(ab, k), vec4(0.0));
    for (int k = first; k <= last; ++k) {
        float lo = max(float(k - 1), enter), hi = min(float(k), leave);
        if (lo < hi) {
            float w = (hi - lo) / float(sb.dims.w), sum = 0.0;
            for (int q = 0; q < sb.dims.w; ++q) {
                float a = lo + float(q) * w, b = q + 1 == sb.dims.w ? hi : lo + float(q + 1) * w;
                float m = 0.5 * (a + b);
                if (empty(p0 + m * sb.axis[2].xyz)) {
                    s_last = b;
                    f_last = 0.0;
                    continue;
                }
                float fa = a == s_last ? f_last : density(p0 + a * sb.axis[2].xyz);
                float fb = density(p0 + b * sb.axis[2].xyz);
                sum += (b - a) * (fa + 4.0 * density(p0 + m * sb.axis[2].xyz) + fb);
                s_last = b;
                f_last = fb;
            }
            D += sum * (sb.origin.w / 6.0);
        }
        imageStore(u_out, ivec3(ab, k), vec4(D));
    }
    for (int k = max(last + 1, first); k < sb.nodes.z; ++k) imageStore(u_out, ivec3(ab, k), vec4(D));
}
