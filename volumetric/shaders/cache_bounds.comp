// veil — the light cache's first pass (volumetric/cache.h): per cell, the
// majorant of the density the photons meet there and, with emission, a
// weight for choosing where emission photons start.
// The majorant must bound the density at every point of the cell: the EV's
// trilinear density at x is a convex combination of the 8 voxels around x,
// whose centres lie within one voxel of the cell, so the largest voxel
// value in the cell grown by a voxel bounds it; an exponential fog is
// largest at the corner of (cell and fog box) furthest down its gradient;
// fogs and the EV add, so their bounds add.
// The emission weight is the sum over the same voxels of the largest
// channel of the emission: at least every channel of the (trilinear)
// emission anywhere in the cell, so a cell that emits is never chosen with
// probability 0, and a photon's power eps / p stays bounded (cache.c).
layout(local_size_x = VEIL_CACHE_CELL_GROUP, local_size_y = VEIL_CACHE_CELL_GROUP, local_size_z = VEIL_CACHE_CELL_GROUP) in;
//@include propagate/shaders/lit_medium.glsl
//@include volumetric/shaders/cache_common.glsl
layout(std430, binding = VEIL_BIND_CACHE_CELL) writeonly buffer veil_cache_cells { vec2 cells[]; };

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, cb.dims.xyz))) return;
    float h = cb.origin.w;
    vec3 lo = cb.origin.xyz + vec3(c) * h, hi = lo + h;
    float maj = 0.0, emit = 0.0;
    if (med.counts.z != 0 && all(lessThanEqual(lo, med.box_max.xyz)) && all(greaterThanEqual(hi, med.box_min.xyz))) {
        float v = med.shape.y;
        // voxel i's centre at tex_min + (i + 0.5) v; those within a voxel of the cell
        ivec3 n = ivec3(round(1.0 / (med.tex_inv_size.xyz * v)));
        ivec3 i0 = max(ivec3(ceil((lo - v - med.tex_min.xyz) / v - 0.5)), ivec3(0));
        ivec3 i1 = min(ivec3(floor((hi + v - med.tex_min.xyz) / v - 0.5)), n - 1);
        bool emission = cb.dims.w != 0;
#ifdef VEIL_SPARSE
        // brick by brick: a brick not kept holds no density and no emission
        ivec3 b0 = i0 / VEIL_BRICK, b1 = i1 / VEIL_BRICK;
        for (int bz = b0.z; bz <= b1.z; ++bz)
            for (int by = b0.y; by <= b1.y; ++by)
                for (int bx = b0.x; bx <= b1.x; ++bx) {
                    ivec3 b = ivec3(bx, by, bz);
                    int region;
                    uint slot = sp_slot(b, region);
                    if (slot == 0u) continue;
                    ivec3 j0 = max(i0, b * VEIL_BRICK), j1 = min(i1, b * VEIL_BRICK + VEIL_BRICK - 1);
                    for (int z = j0.z; z <= j1.z; ++z)
                        for (int y = j0.y; y <= j1.y; ++y)
                            for (int x = j0.x; x <= j1.x; ++x) {
                                vec3 q = vec3(x, y, z) + 0.5;
                                vec3 uvw = sp_atlas_uvw(slot, b, q);
                                maj = max(maj, texture(u_ev, uvw).r);
                                if (emission) {
                                    vec3 e = texture(u_emission, uvw).rgb;
                                    emit += max(e.r, max(e.g, e.b));
                                }
                            }
                }
#else
        for (int z = i0.z; z <= i1.z; ++z)
            for (int y = i0.y; y <= i1.y; ++y)
                for (int x = i0.x; x <= i1.x; ++x) {
                    maj = max(maj, texelFetch(u_ev, ivec3(x, y, z), 0).r);
                    if (emission) {
                        vec3 e = texelFetch(u_emission, ivec3(x, y, z), 0).rgb;
                        emit += max(e.r, max(e.g, e.b));
                    }
                }
#endif
    }
    for (int f = 0; f < med.counts.y; ++f) {
        vec3 a = max(lo, med.fogs[f].box_min.xyz), b = min(hi, med.fogs[f].box_max.xyz);
        if (any(greaterThan(a, b))) continue;
        vec3 grad = med.fogs[f].origin.w * med.fogs[f].direction.xyz; // k rises along grad
        vec3 x = mix(b, a, greaterThan(grad, vec3(0.0)));             // where k is least
        maj += fog_density(f, clamp(x, med.fogs[f].box_min.xyz, med.fogs[f].box_max.xyz));
    }
    uint k = uint(c.x) + uint(cb.dims.x) * (uint(c.y) + uint(cb.dims.y) * uint(c.z));
    cells[k] = vec2(maj, emit);
}
