// veil — optical depth in a light-space grid (propagate/sun_space.h): a
// sun's, or one face of a point or spot light's. One invocation per column
// (a, b), a prefix sum down the column along the light's travel, node by
// node, each step integrated with Simpson panels clipped to the medium's
// box; D in density * m. Panels whose occupancy brick is empty add nothing
// and fetch nothing: a panel is at most one voxel long, so it lies within
// half a voxel of its midpoint m, and the brick b = floor((m + 1/2) /
// VEIL_BRICK) has 8b - 1/2 <= m < 8b + 15/2, whose zero region [8b - 1,
// 8b + 8] (the brick and its ring: volume/shaders/occupancy.comp) then
// holds the whole panel.
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = VEIL_TEX_EV) uniform sampler3D u_ev;   // density, trilinear
layout(binding = VEIL_TEX_OCC) uniform sampler3D u_occ; // max density per brick, ring included
layout(binding = VEIL_IMAGE_OPV_DST, r32f) writeonly uniform image2DArray u_out; // a layer a node plane

//@include propagate/opv_blocks.glsl.h
layout(std140, binding = VEIL_UBO_PROPAGATE) uniform veil_sun_ubo { veil_sun_block sb; };
// The block's fields, copied once an invocation (main) so that the loops
// read registers: a uniform block read after an image store is read again.
ivec3 g_dims;   // the EV's voxels
ivec3 g_nodes;  // columns along a, b; nodes along c
vec3 g_origin;  // node (0, 0, 0), index coordinates
vec3 g_axis_a;  // index-space steps between columns
vec3 g_axis_b;
vec3 g_axis_c;  // between nodes down column (0, 0)
int g_panels;
float g_step;   // m per node step along c
int g_skip;     // 1: consult the occupancy bricks

float density(vec3 p) { return texture(u_ev, (p + 0.5) / vec3(g_dims)).r; }

bool empty(vec3 m)
{
    if (g_skip == 0) return false;
    ivec3 b = ivec3(floor((m + 0.5) / float(VEIL_BRICK)));
    b = clamp(b, ivec3(0), textureSize(u_occ, 0) - 1);
    return texelFetch(u_occ, b, 0).r <= 0.0;
}

void main()
{
    g_dims = sb.dims.xyz, g_panels = sb.dims.w;
    g_nodes = sb.nodes.xyz, g_skip = sb.nodes.w & 1;
    g_origin = sb.origin.xyz, g_step = sb.origin.w;
    g_axis_a = sb.axis[0].xyz, g_axis_b = sb.axis[1].xyz, g_axis_c = sb.axis[2].xyz;
    const bool perspective = (sb.nodes.w & 2) != 0;
    const int first = sb.place.x;
    ivec2 ab = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(ab, sb.place.yz))) return;
    if (any(greaterThanEqual(ab, g_nodes.xy))) { // a perspective face's texture past its window
        for (int k = 0; k < g_nodes.z; ++k) imageStore(u_out, ivec3(ab, first + k), vec4(0.0));
        return;
    }
    vec3 p0 = g_origin + float(ab.x) * g_axis_a + float(ab.y) * g_axis_b;
    if (perspective) { // each column its own step, its panels at most a voxel
        g_axis_c += float(ab.x) * sb.spread[0].xyz + float(ab.y) * sb.spread[1].xyz;
        float len = length(g_axis_c);
        g_panels = max(g_panels, int(ceil(len)));
        g_step = len * sb.spread[0].w;
    }
    // the column's span inside the box, in node steps
    float enter = 0.0, leave = float(g_nodes.z - 1);
    for (int a = 0; a < 3; ++a) {
        float hi = float(g_dims[a] - 1);
        if (g_axis_c[a] == 0.0) {
            if (p0[a] < 0.0 || p0[a] > hi) leave = -1.0;
            continue;
        }
        float t0 = (0.0 - p0[a]) / g_axis_c[a], t1 = (hi - p0[a]) / g_axis_c[a];
        enter = max(enter, min(t0, t1));
        leave = min(leave, max(t0, t1));
    }
    float D = 0.0, s_last = -1.0, f_last = 0.0;
    imageStore(u_out, ivec3(ab, first), vec4(0.0));
    int from = max(1, int(floor(enter)));     // nodes before the box: 0
    int last = min(g_nodes.z - 1, int(ceil(leave)));
    for (int k = 1; k < from && k < g_nodes.z; ++k) imageStore(u_out, ivec3(ab, first + k), vec4(0.0));
    for (int k = from; k <= last; ++k) {
        float lo = max(float(k - 1), enter), hi = min(float(k), leave);
        if (lo < hi) {
            float w = (hi - lo) / float(g_panels), sum = 0.0;
            for (int q = 0; q < g_panels; ++q) {
                float a = lo + float(q) * w, b = q + 1 == g_panels ? hi : lo + float(q + 1) * w;
                float m = 0.5 * (a + b);
                if (empty(p0 + m * g_axis_c)) {
                    s_last = b;
                    f_last = 0.0;
                    continue;
                }
                float fa = a == s_last ? f_last : density(p0 + a * g_axis_c);
                float fb = density(p0 + b * g_axis_c);
                sum += (b - a) * (fa + 4.0 * density(p0 + m * g_axis_c) + fb);
                s_last = b;
                f_last = fb;
            }
            D += sum * (g_step / 6.0);
        }
        imageStore(u_out, ivec3(ab, first + k), vec4(D));
    }
    for (int k = max(last + 1, from); k < g_nodes.z; ++k) imageStore(u_out, ivec3(ab, first + k), vec4(D));
}
