// veil — one pass of an ordered (one-pass) optical-depth method, for one
// light written into channel sw.dims.w of u_opv in place. Every voxel a pass
// computes depends only on voxels of earlier passes (propagate/opv_plan.h),
// so passes run in order with a barrier between them. The block,
// veil_sweep_block (propagate/opv_blocks.glsl.h), says which pass:
//  sw.pass.x 0: gather sweep, Manhattan shell sw.pass.y: invocations
//               enumerate the plane of the two axes other than sw.pass.z;
//               each solves for its one or two voxels on that axis (as
//               veil__gather_solve).
//  sw.pass.x 1: semi-Lagrangian near field: box 0, direct integration.
//  sw.pass.x 2: semi-Lagrangian boxes (shell sub-pass or sun slice): the
//               voxels of box gl_WorkGroupID.z, flattened x fastest.
// The light is sw.light.xyz (veil_index_light.v), its voxel sw.cell.xyz and
// its type sw.cell.w.
layout(local_size_x = VEIL_SWEEP_GROUP) in;

layout(binding = VEIL_IMAGE_EV, r32f) readonly uniform image3D u_ev;
#ifdef VEIL_OPV_ONE_CHANNEL // a texture of one light: r32f, channel 0
layout(binding = VEIL_IMAGE_OPV_DST, r32f) uniform image3D u_opv;
#else
layout(binding = VEIL_IMAGE_OPV_DST, rgba32f) uniform image3D u_opv;
#endif

//@include propagate/opv_blocks.glsl.h
layout(std140, binding = VEIL_UBO_PROPAGATE) uniform veil_sweep_ubo { veil_sweep_block sw; };

#define VEIL_CTX_PARAM
#define VEIL_CTX_ARG
// the grid's size, copied from the block once an invocation (main) so that
// the scheme's per-sample reads come from a register (a uniform block read
// after an image store is read again)
ivec3 g_dims;
#define VEIL_DIMS(a) g_dims[a]
#define VEIL_RHO(i, j, k) imageLoad(u_ev, ivec3(i, j, k)).r
#ifdef VEIL_OPV_ONE_CHANNEL
#define VEIL_DIN(i, j, k) imageLoad(u_opv, ivec3(i, j, k)).r
#else
#define VEIL_DIN(i, j, k) imageLoad(u_opv, ivec3(i, j, k))[sw.dims.w]
#endif
//@include propagate/opv_schemes.glsl.h

void store(ivec3 x, float D)
{
#ifdef VEIL_OPV_ONE_CHANNEL
    imageStore(u_opv, x, vec4(D));
#else
    vec4 v = imageLoad(u_opv, x);
    v[sw.dims.w] = D;
    imageStore(u_opv, x, v);
#endif
}

int gather_dist(int a, int x)
{
    if (sw.cell.w == VEIL_LIGHT_DIRECTIONAL) {
        if (sw.light[a] > 0.0) return sw.dims[a] - 1 - x;
        if (sw.light[a] < 0.0) return x;
        return 0;
    }
    return abs(x - sw.cell[a]);
}

void gather_pass(uint idx)
{
    int s = sw.pass.z, u = s == 0 ? 1 : 0, w = s == 2 ? 1 : 2;
    if (idx >= uint(sw.dims[u] * sw.dims[w])) return;
    ivec3 x = ivec3(0);
    x[u] = int(idx % uint(sw.dims[u]));
    x[w] = int(idx / uint(sw.dims[u]));
    int rem = sw.pass.y - gather_dist(u, x[u]) - gather_dist(w, x[w]);
    if (rem < 0) return;
    int cand[2];
    int n = 0;
    if (sw.cell.w == VEIL_LIGHT_DIRECTIONAL) {
        cand[n++] = sw.light[s] > 0.0 ? sw.dims[s] - 1 - rem : rem;
    } else {
        cand[n++] = sw.cell[s] - rem;
        if (rem > 0) cand[n++] = sw.cell[s] + rem;
    }
    for (int q = 0; q < n; ++q) {
        if (cand[q] < 0 || cand[q] >= sw.dims[s]) continue;
        x[s] = cand[q];
        store(x, veil_gather_cell(x.x, x.y, x.z, sw.cell.w, sw.light.x, sw.light.y, sw.light.z, sw.cell.x,
                                  sw.cell.y, sw.cell.z, sw.params.x, 1));
    }
}

void main()
{
    uint idx = gl_GlobalInvocationID.x;
    g_dims = sw.dims.xyz;
    if (sw.pass.x == 0) {
        gather_pass(idx);
        return;
    }
    int b = int(gl_WorkGroupID.z);
    ivec3 n = sw.boxes[b].n.xyz;
    if (idx >= uint(n.x * n.y * n.z)) return;
    ivec3 x = sw.boxes[b].lo.xyz +
              ivec3(int(idx % uint(n.x)), int((idx / uint(n.x)) % uint(n.y)), int(idx / uint(n.x * n.y)));
    float D;
    if (sw.pass.x == 1) {
        D = veil_near_cell(x.x, x.y, x.z, sw.light.x, sw.light.y, sw.light.z, sw.params.x);
    } else {
        int a = veil_sl_axis(x.x, x.y, x.z, sw.cell.w, sw.light.x, sw.light.y, sw.light.z, sw.cell.x, sw.cell.y,
                             sw.cell.z);
        D = veil_sl_cell(x.x, x.y, x.z, a, sw.cell.w, sw.light.x, sw.light.y, sw.light.z, sw.params.x, sw.pass.w,
                         sw.params.y);
    }
    store(x, D);
}
