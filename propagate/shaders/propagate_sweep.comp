// veil — one pass of an ordered (one-pass) optical-depth method, for one
// light written into channel u_channel of u_opv in place. Every voxel a pass
// computes depends only on voxels of earlier passes (propagate/opv_plan.h),
// so passes run in order with a barrier between them.
//  u_mode 0: gather sweep, Manhattan shell u_shell: invocations enumerate
//            the plane of the two axes other than u_solve; each solves for
//            its one or two voxels on u_solve (as veil__gather_solve).
//  u_mode 1: semi-Lagrangian near field: box 0, direct integration.
//  u_mode 2: semi-Lagrangian boxes (shell sub-pass or sun slice): the
//            voxels of box gl_WorkGroupID.z, flattened x fastest.
layout(local_size_x = VEIL_SWEEP_GROUP) in;

layout(binding = VEIL_IMAGE_EV, r32f) readonly uniform image3D u_ev;
#ifdef VEIL_OPV_ONE_CHANNEL // a texture of one light: r32f, channel 0
layout(binding = VEIL_IMAGE_OPV_DST, r32f) uniform image3D u_opv;
#else
layout(binding = VEIL_IMAGE_OPV_DST, rgba32f) uniform image3D u_opv;
#endif

uniform ivec3 u_dims;
uniform float u_voxel;
uniform int u_mode;
uniform int u_channel;
uniform int u_type;
uniform vec3 u_light;
uniform ivec3 u_cell;
uniform int u_shell;
uniform int u_solve;
uniform float u_exit_steps;
uniform int u_characteristic;
uniform ivec3 u_box_lo[12];
uniform ivec3 u_box_n[12];

#define VEIL_CTX_PARAM
#define VEIL_CTX_ARG
#define VEIL_DIMS(a) u_dims[a]
#define VEIL_RHO(i, j, k) imageLoad(u_ev, ivec3(i, j, k)).r
#ifdef VEIL_OPV_ONE_CHANNEL
#define VEIL_DIN(i, j, k) imageLoad(u_opv, ivec3(i, j, k)).r
#else
#define VEIL_DIN(i, j, k) imageLoad(u_opv, ivec3(i, j, k))[u_channel]
#endif
//@include propagate/opv_schemes.glsl.h

void store(ivec3 x, float D)
{
#ifdef VEIL_OPV_ONE_CHANNEL
    imageStore(u_opv, x, vec4(D));
#else
    vec4 v = imageLoad(u_opv, x);
    v[u_channel] = D;
    imageStore(u_opv, x, v);
#endif
}

int gather_dist(int a, int x)
{
    if (u_type == VEIL_LIGHT_DIRECTIONAL) {
        if (u_light[a] > 0.0) return u_dims[a] - 1 - x;
        if (u_light[a] < 0.0) return x;
        return 0;
    }
    return abs(x - u_cell[a]);
}

void gather_pass(uint idx)
{
    int s = u_solve, u = s == 0 ? 1 : 0, w = s == 2 ? 1 : 2;
    if (idx >= uint(u_dims[u] * u_dims[w])) return;
    ivec3 x = ivec3(0);
    x[u] = int(idx % uint(u_dims[u]));
    x[w] = int(idx / uint(u_dims[u]));
    int rem = u_shell - gather_dist(u, x[u]) - gather_dist(w, x[w]);
    if (rem < 0) return;
    int cand[2];
    int n = 0;
    if (u_type == VEIL_LIGHT_DIRECTIONAL) {
        cand[n++] = u_light[s] > 0.0 ? u_dims[s] - 1 - rem : rem;
    } else {
        cand[n++] = u_cell[s] - rem;
        if (rem > 0) cand[n++] = u_cell[s] + rem;
    }
    for (int q = 0; q < n; ++q) {
        if (cand[q] < 0 || cand[q] >= u_dims[s]) continue;
        x[s] = cand[q];
        store(x, veil_gather_cell(x.x, x.y, x.z, u_type, u_light.x, u_light.y, u_light.z, u_cell.x, u_cell.y,
                                  u_cell.z, u_voxel, 1));
    }
}

void main()
{
    uint idx = gl_GlobalInvocationID.x;
    if (u_mode == 0) {
        gather_pass(idx);
        return;
    }
    int b = int(gl_WorkGroupID.z);
    ivec3 n = u_box_n[b];
    if (idx >= uint(n.x * n.y * n.z)) return;
    ivec3 x = u_box_lo[b] + ivec3(int(idx % uint(n.x)), int((idx / uint(n.x)) % uint(n.y)), int(idx / uint(n.x * n.y)));
    float D;
    if (u_mode == 1) {
        D = veil_near_cell(x.x, x.y, x.z, u_light.x, u_light.y, u_light.z, u_voxel);
    } else {
        int a = veil_sl_axis(x.x, x.y, x.z, u_type, u_light.x, u_light.y, u_light.z, u_cell.x, u_cell.y, u_cell.z);
        D = veil_sl_cell(x.x, x.y, x.z, a, u_type, u_light.x, u_light.y, u_light.z, u_voxel, u_characteristic,
                         u_exit_steps);
    }
    store(x, D);
}
