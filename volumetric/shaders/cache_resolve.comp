// veil — the light cache's last pass (volumetric/cache.h): each cell's
// 64-bit fixed-point sums turned into the fields the march samples, stacked
// in one texture (core/shared.glsl.h says why): the fluence rgb (W/m^2) with
// the odd photons' luminance fluence beside it (for the noise estimate), and
// nz cells above it the luminance-weighted flux (W/m^2), of all the light;
// above those the same two of the light scattered more than once (for the
// emission: scattered at all). The flux's alpha: the cell's part outside a
// frame's solid (below).
layout(local_size_x = VEIL_CACHE_CELL_GROUP, local_size_y = VEIL_CACHE_CELL_GROUP, local_size_z = VEIL_CACHE_CELL_GROUP) in;
layout(std140, binding = VEIL_UBO_CACHE) uniform veil_cache_ubo { veil_cache_block cb; };
layout(std430, binding = VEIL_BIND_CACHE_SUM) readonly buffer veil_cache_sums { uint sums[]; };
layout(binding = VEIL_IMAGE_CACHE, rgba32f) writeonly uniform image3D u_cache; // fluence below, flux above
// Under veil fog a frame's surfaces are solid (scene/solid.h): the photons'
// track lies in the part of a cell outside them, so the fluence there is
// the sums (per cell volume) divided by that part. The fields are kept as
// the sums, with the free part beside the flux (its alpha): the march
// interpolates both and divides, so that a cell mostly in a wall weighs as
// little as its fog (interpolating fluences would pull the fog by a wall
// towards the wall's empty cells; dividing each cell first would amplify a
// sliver's noise). 1 everywhere without a solid.
layout(std430, binding = VEIL_BIND_CACHE_FREE) readonly buffer veil_cache_free { float free_part[]; };
// The cells' majorant density (cache_bounds.comp), kept as the later fluence's alpha: the gather
// (render/shaders/cache_gather.comp) skips the cells no density is near.
layout(std430, binding = VEIL_BIND_CACHE_CELL) readonly buffer veil_cache_cells { vec2 cells[]; };

// the signed 64-bit sum at word k, in W/m^2: the high word and the low
// word's two halves joined in steps that are exact while |sum| < 2^40 units
// (a negative sum near 0 keeps its low bits), rounded to float's 24 bits after
float sum_at(uint k)
{
    uint lo = sums[k];
    float v = (float(int(sums[k + 1u])) * 65536.0 + float(lo >> 16u)) * 65536.0 + float(lo & 0xffffu);
    return v * cb.scale.y;
}

void main()
{
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, cb.dims.xyz))) return;
    uint k = (uint(c.x) + uint(cb.dims.x) * (uint(c.y) + uint(cb.dims.y) * uint(c.z))) * uint(VEIL_CACHE_WORDS);
    uint l = k + uint(VEIL_CACHE_LATER);
    vec3 phi1 = vec3(sum_at(k), sum_at(k + 2u), sum_at(k + 4u)), flux1 = vec3(sum_at(k + 6u), sum_at(k + 8u), sum_at(k + 10u));
    vec3 phi2 = vec3(sum_at(l), sum_at(l + 2u), sum_at(l + 4u)), flux2 = vec3(sum_at(l + 6u), sum_at(l + 8u), sum_at(l + 10u));
    imageStore(u_cache, c, vec4(phi1 + phi2, sum_at(k + 12u)));
    imageStore(u_cache, c + ivec3(0, 0, cb.dims.z), vec4(flux1 + flux2, free_part[k / uint(VEIL_CACHE_WORDS)]));
    imageStore(u_cache, c + ivec3(0, 0, 2 * cb.dims.z), vec4(phi2, cells[k / uint(VEIL_CACHE_WORDS)].x));
    imageStore(u_cache, c + ivec3(0, 0, 3 * cb.dims.z), vec4(flux2, 0.0));
}
