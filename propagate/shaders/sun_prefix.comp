// veil — a sun's optical depth in its light-space grid (propagate/sun_space.h):
// one invocation per column (a, b), a prefix sum down the column along the
// light's travel, node by node, each step integrated with u_panels Simpson
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

uniform ivec3 u_dims;   // the EV's voxels
uniform ivec3 u_nodes;  // light-space nodes along a, b, c
uniform vec3 u_origin;  // node (0, 0, 0), index coordinates
uniform vec3 u_axis_a;  // index-space steps between nodes
uniform vec3 u_axis_b;
uniform vec3 u_axis_c;
uniform int u_panels;
uniform float u_step;   // m per node step along c
uniform int u_skip;     // 1: consult the occupancy bricks

float density(vec3 p) { return texture(u_ev, (p + 0.5) / vec3(u_dims)).r; }

bool empty(vec3 m)
{
    if (u_skip == 0) return false;
    ivec3 b = ivec3(floor((m + 0.5) / float(VEIL_BRICK)));
    b = clamp(b, ivec3(0), textureSize(u_occ, 0) - 1);
    return texelFetch(u_occ, b, 0).r <= 0.0;
}

void main()
{
    ivec2 ab = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(ab, u_nodes.xy))) return;
    vec3 p0 = u_origin + float(ab.x) * u_axis_a + float(ab.y) * u_axis_b;
    // the column's span inside the box, in node steps
    float enter = 0.0, leave = float(u_nodes.z - 1);
    for (int a = 0; a < 3; ++a) {
        float hi = float(u_dims[a] - 1);
        if (u_axis_c[a] == 0.0) {
            if (p0[a] < 0.0 || p0[a] > hi) leave = -1.0;
            continue;
        }
        float t0 = (0.0 - p0[a]) / u_axis_c[a], t1 = (hi - p0[a]) / u_axis_c[a];
        enter = max(enter, min(t0, t1));
        leave = min(leave, max(t0, t1));
    }
    float D = 0.0, s_last = -1.0, f_last = 0.0;
    imageStore(u_out, ivec3(ab, 0), vec4(0.0));
    int first = max(1, int(floor(enter)));     // nodes before the box: 0
    int last = min(u_nodes.z - 1, int(ceil(leave)));
    for (int k = 1; k < first && k < u_nodes.z; ++k) imageStore(u_out, ivec3(ab, k), vec4(0.0));
    for (int k = first; k <= last; ++k) {
        float lo = max(float(k - 1), enter), hi = min(float(k), leave);
        if (lo < hi) {
            float w = (hi - lo) / float(u_panels), sum = 0.0;
            for (int q = 0; q < u_panels; ++q) {
                float a = lo + float(q) * w, b = q + 1 == u_panels ? hi : lo + float(q + 1) * w;
                float m = 0.5 * (a + b);
                if (empty(p0 + m * u_axis_c)) {
                    s_last = b;
                    f_last = 0.0;
                    continue;
                }
                float fa = a == s_last ? f_last : density(p0 + a * u_axis_c);
                float fb = density(p0 + b * u_axis_c);
                sum += (b - a) * (fa + 4.0 * density(p0 + m * u_axis_c) + fb);
                s_last = b;
                f_last = fb;
            }
            D += sum * (u_step / 6.0);
        }
        imageStore(u_out, ivec3(ab, k), vec4(D));
    }
    for (int k = max(last + 1, first); k < u_nodes.z; ++k) imageStore(u_out, ivec3(ab, k), vec4(D));
}
