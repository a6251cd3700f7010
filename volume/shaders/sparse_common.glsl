// veil — the sparse extinction volume as the shaders read it (included;
// volume/sparse.h has the layout, volume/sparse.c the C twin of the
// lookup). Index coordinates q: voxel i's centre at i + 0.5, one unit a
// voxel edge (sp.origin.w metres). The atlas is bound where a dense EV is.
#ifndef VEIL_SPARSE_COMMON_GLSL
#define VEIL_SPARSE_COMMON_GLSL
layout(binding = VEIL_TEX_EV) uniform sampler3D u_ev;
layout(binding = VEIL_TEX_SPARSE_TOP) uniform usamplerBuffer u_sp_top;
layout(binding = VEIL_TEX_SPARSE_NODES) uniform usamplerBuffer u_sp_nodes;
layout(std140, binding = VEIL_UBO_SPARSE) uniform veil_sparse_ubo { veil_sparse_block sp; };
//@include volume/shaders/box_hit.glsl

// The brick whose interpolation cell holds q.
ivec3 sp_brick(vec3 q)
{
    return ivec3(floor((q - 0.5) / float(VEIL_BRICK)));
}

// Slot + 1 of brick b, 0 when it is not kept; `region` is then the edge (in
// bricks) of the empty cube around it that a ray may skip: a node, or the brick.
uint sp_slot(ivec3 b, out int region)
{
    region = 1;
    if (any(lessThan(b, ivec3(0))) || any(greaterThanEqual(b, sp.bricks.xyz))) return 0u;
    ivec3 n = b / VEIL_SPARSE_NODE;
    uint node = texelFetch(u_sp_top, n.x + sp.top.x * (n.y + sp.top.y * n.z)).r;
    if (node == 0u) {
        region = VEIL_SPARSE_NODE;
        return 0u;
    }
    ivec3 l = b - n * VEIL_SPARSE_NODE;
    return texelFetch(u_sp_nodes, int(node - 1u) * VEIL_SPARSE_NODE_BRICKS + l.x + VEIL_SPARSE_NODE * (l.y + VEIL_SPARSE_NODE * l.z)).r;
}

// The slot's corner in the atlas, in bricks.
vec3 sp_corner(uint slot)
{
    uint k = slot - 1u, ax = uint(sp.atlas.x), ay = uint(sp.atlas.y);
    return vec3(uvec3(k % ax, (k / ax) % ay, k / (ax * ay)));
}

// q's place in brick b, [0, 8] (a hair outside is the face's value).
vec3 sp_local(ivec3 b, vec3 q)
{
    return clamp(q - 0.5 - vec3(b * VEIL_BRICK), 0.0, float(VEIL_BRICK));
}

// Normalised atlas coordinates of q in slot `slot` (brick b): texel j of a
// brick is voxel 8b + j, its centre at j + 0.5.
vec3 sp_atlas_uvw(uint slot, ivec3 b, vec3 q)
{
    return (sp_corner(slot) * float(VEIL_SPARSE_APRON) + sp_local(b, q) + 0.5) * sp.inv_atlas.xyz;
}

// ... and in the escape field's atlas (VEIL_SPARSE_ESCAPE texels a brick, every 4 voxels).
vec3 sp_escape_uvw(uint slot, ivec3 b, vec3 q)
{
    float per = float(VEIL_SPARSE_ESCAPE), step = float(VEIL_BRICK) / (per - 1.0);
    return (sp_corner(slot) * per + sp_local(b, q) / step + 0.5) * sp.inv_atlas.xyz * (float(VEIL_SPARSE_APRON) / per);
}

float sp_density(vec3 q)
{
    ivec3 b = sp_brick(q);
    int region;
    uint slot = sp_slot(b, region);
    return slot == 0u ? 0.0 : texture(u_ev, sp_atlas_uvw(slot, b, q)).r;
}

// Distance along unit d from p to where it leaves the cube of `region`
// bricks that holds brick b.
float sp_region_exit(vec3 p, vec3 d, ivec3 b, int region)
{
    vec3 lo = vec3((b / region) * region * VEIL_BRICK) + 0.5;
    vec3 hi = lo + float(region * VEIL_BRICK);
    vec3 inv = 1.0 / d;
    vec3 t = max((mix(lo, hi, greaterThan(d, vec3(0.0))) - p) * inv, 0.0);
    t = mix(t, vec3(INF), equal(d, vec3(0.0)));
    return min(min(t.x, t.y), t.z);
}

// The same for a brick b found a hair ahead of p (at p + d ahead): a face
// that p sits on and that the ray leaves along a component too small to
// move it off that face in float (so the brick ahead is still b) does not
// end the region, since 0 there would step a hair at a time (a sun 1e-8 off
// an axis made the optical depth of a 113x224x114 smoke take 100 s instead
// of 1); the other faces do, and the next lookup finds where the ray is.
float sp_region_exit_ahead(vec3 p, vec3 d, ivec3 b, int region)
{
    vec3 lo = vec3((b / region) * region * VEIL_BRICK) + 0.5;
    vec3 hi = lo + float(region * VEIL_BRICK);
    vec3 t = (mix(lo, hi, greaterThan(d, vec3(0.0))) - p) / d;
    t = mix(t, vec3(INF), lessThanEqual(t, vec3(0.0)));
    t = mix(t, vec3(INF), equal(d, vec3(0.0))); // (0 / 0 is NaN there)
    return min(min(t.x, t.y), t.z);
}

// The density integral (density x voxels) along q + t d (d unit) for t in
// [t0, t1], within the box of voxel centres: brick by brick, midpoint steps
// of at most h voxels, bricks and nodes not kept skipped (their density is 0).
float sp_integral(vec3 q, vec3 d, float t0, float t1, float h)
{
    vec2 s = box_hit(q, d, vec3(0.5), sp.dims.xyz - 0.5, t0, t1);
    float sum = 0.0, t = s.x;
    while (t < s.y) {
        // the brick ahead of t (t itself may sit on the face it just crossed)
        float ahead = max(1e-3, 4.8e-7 * t);
        vec3 p = q + d * t;
        ivec3 b = sp_brick(q + d * (t + ahead));
        int region;
        uint slot = sp_slot(b, region);
        float te = min(t + max(sp_region_exit_ahead(p, d, b, slot == 0u ? region : 1), ahead), s.y);
        if (slot != 0u) {
            int n = int(ceil((te - t) / h));
            float dt = (te - t) / float(max(n, 1));
            vec3 base = sp_corner(slot) * float(VEIL_SPARSE_APRON) + 0.5;
            for (int i = 0; i < n; ++i) {
                vec3 x = q + d * (t + (float(i) + 0.5) * dt);
                sum += texture(u_ev, (base + sp_local(b, x)) * sp.inv_atlas.xyz).r * dt;
            }
        }
        t = te;
    }
    return sum;
}
#endif
