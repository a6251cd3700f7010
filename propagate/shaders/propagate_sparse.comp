// veil — optical depth over a sparse volume (volume/sparse.h): for each
// texel of the atlas (voxel 8b + j of the brick b in its slot, j in 0..8),
// the density integral from its centre to each of up to 4 lights, marched
// through the bricks on the way (volume/shaders/sparse_common.glsl:
// midpoint steps of VEIL_SPARSE_OD_STEP voxels, empty bricks and nodes
// skipped), times the voxel edge: D in density m, light c in channel c. Only
// where the medium is: the march reads it in kept bricks and marches the
// path itself anywhere else.
layout(local_size_x = VEIL_SPARSE_GROUP, local_size_y = VEIL_SPARSE_GROUP, local_size_z = VEIL_SPARSE_GROUP) in;
layout(binding = VEIL_IMAGE_SPARSE_OUT, rgba32f) writeonly uniform image3D u_out;
layout(binding = VEIL_TEX_SPARSE_COORDS) uniform isamplerBuffer u_sp_coords;
// xyz: a point light's position in index coordinates (voxel i's centre at
// i + 0.5), or a sun's unit direction towards it; w: VEIL_LIGHT_*
uniform vec4 u_light[4];
uniform int u_count;
//@include volume/shaders/sparse_common.glsl

void main()
{
    ivec3 texel = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(texel, sp.atlas.xyz * VEIL_SPARSE_APRON))) return;
    ivec3 c = texel / VEIL_SPARSE_APRON;
    int k = c.x + sp.atlas.x * (c.y + sp.atlas.y * c.z);
    if (k >= sp.bricks.w) return;
    ivec3 b = texelFetch(u_sp_coords, k).xyz;
    vec3 q = vec3(b * VEIL_BRICK + texel - c * VEIL_SPARSE_APRON) + 0.5;
    vec4 D = vec4(0.0);
    for (int l = 0; l < u_count; ++l) {
        vec3 d = u_light[l].xyz;
        float len = INF;
        if (int(u_light[l].w) != VEIL_LIGHT_DIRECTIONAL) {
            vec3 to = u_light[l].xyz - q;
            len = length(to);
            d = len > 0.0 ? to / len : vec3(0.0, 0.0, 1.0);
        }
        D[l] = sp_integral(q, d, 0.0, len, VEIL_SPARSE_OD_STEP) * sp.origin.w;
    }
    imageStore(u_out, texel, D);
}
