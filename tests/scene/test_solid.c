/* A frame's surfaces as a solid (scene/solid.h), on the CPU: a camera
 * looking along f at a wall across its whole frame, at Z = D along f (each
 * pixel's distance D / cos of its angle off f), for f along each axis both
 * ways and one oblique. h is the solid's voxel, b a light's bias.
 * 1. Nothing passes: every segment from a point in front of the wall to one
 *    behind its solid (Z = D + 12 h; the solid ends by D + 10 h: at most 8
 *    voxels of thickness, one of growth, one of the voxel's own extent),
 *    both inside the frame's cone, crosses the plane Z = D inside the frame
 *    (the cone is convex), so veil_solid_hit must find solid on it. The solid
 *    is at least 4 voxels thick across (2 of thickness and one of growth each
 *    side), and the path is sampled every half voxel, so none may be missed.
 * 2. Nothing intrudes: a point at Z < D - 3.5 h is free. A voxel is solid
 *    when it or a neighbour holds a surface point; two voxels whose indices
 *    differ by at most 1 on each axis are at most 2 sqrt(3) h < 3.5 h apart
 *    along f.
 * 3. Shadows (veil_solid_visibility, what the march's shader computes):
 *    - a sun beyond the wall, shining towards the camera: every point in
 *      front of the wall, within 0.7 of the cone (so that the map's four taps,
 *      a texel apart, all meet the wall too), is dark from Z < D - b - h (its
 *      path to the sun meets the wall inside the frame; the first solid along
 *      the light is the solid's far side, at Z >= D, found within half a
 *      voxel);
 *    - a sun behind the camera: every point in front of the wall is lit (the
 *      first solid along its light is beyond it);
 *    - a lamp beyond the wall on the axis (Z = D + 3): the same points dark;
 *    - a lamp in front of it (Z = D / 2): the points between it and the wall
 *      lit, the points behind the wall (Z = D + 12 h, within 0.5 of the cone:
 *      their path from the lamp crosses the wall inside the frame) dark.
 *      Lamps on six axes and an oblique put the octahedral map's every
 *      quadrant and both hemispheres to use.
 * 4. A lamp on the wall itself: the voxels about it are free.
 * 5. No finite depth in the medium's box: no solid, no error.
 * 6. The key follows the depth. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "support/check.h"
#include "core/hash.h"
#include "scene/solid.h"

enum { W = 64, H = 48 };
static const float D = 10.0f;

static unsigned rng_state = 12345u;
static float rnd(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (float)(rng_state >> 8) / 16777216.0f;
}

/* The point at depth Z along f on the ray through image point (sx, sy) in [-1, 1]. */
static void point_at(const veil_camera_basis* b, float sx, float sy, float Z, float x[3])
{
    float dir[3], c = 0.0f;
    for (int a = 0; a < 3; ++a) dir[a] = b->fwd[a] + sx * b->right[a] + sy * b->up[a];
    for (int a = 0; a < 3; ++a) c += dir[a] * b->fwd[a];
    float n = sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    for (int a = 0; a < 3; ++a) x[a] = b->pos[a] + dir[a] / n * (Z / (c / n));
}

static void one_view(const float f[3], const char* name)
{
    veil_error err = {0};
    veil_camera cam = {.position = {1.0f, -2.0f, 0.5f}, .fov_y_deg = 40.0f, .width = W, .height = H};
    for (int a = 0; a < 3; ++a) cam.look_at[a] = cam.position[a] + f[a];
    cam.up[0] = 0.0f, cam.up[1] = 1.0f, cam.up[2] = 0.0f;
    if (fabsf(f[1]) > 0.9f) cam.up[1] = 0.0f, cam.up[2] = 1.0f;
    veil_camera_basis b;
    CHECK(veil_camera_make_basis(&cam, W, H, &b, &err) == VEIL_OK, "%s", err.msg);
    float* dist = malloc(sizeof(float) * W * H);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float dir[3];
            veil_camera_ray(&b, W, H, x, y, dir);
            dist[y * W + x] = D / (dir[0] * b.fwd[0] + dir[1] * b.fwd[1] + dir[2] * b.fwd[2]);
        }
    veil_light lights[4] = {{.type = VEIL_LIGHT_DIRECTIONAL, .color = {1, 1, 1}},
                            {.type = VEIL_LIGHT_DIRECTIONAL, .color = {1, 1, 1}},
                            {.type = VEIL_LIGHT_POINT, .color = {1, 1, 1}},
                            {.type = VEIL_LIGHT_POINT, .color = {1, 1, 1}}};
    for (int a = 0; a < 3; ++a) {
        lights[0].direction[a] = -b.fwd[a]; /* from beyond the wall, towards the camera */
        lights[1].direction[a] = b.fwd[a];  /* from behind the camera */
        lights[2].position[a] = b.pos[a] + (D + 3.0f) * b.fwd[a];
        lights[3].position[a] = b.pos[a] + 0.5f * D * b.fwd[a];
    }
    const float lo[3] = {-100, -100, -100}, hi[3] = {100, 100, 100};
    veil_solid s;
    CHECK(veil_solid_build(&cam, W, H, dist, lo, hi, lights, 4, &s, &err) == VEIL_OK, "%s", err.msg);
    CHECK(s.voxels && s.solid_count > 0 && s.maps == 4, "%s: a solid (%zu voxels) and 4 maps", name, s.solid_count);
    if (!s.voxels) {
        free(dist);
        return;
    }
    const float h = s.voxel;
    int misses = 0, intrusions = 0, lit_wrong[4] = {0, 0, 0, 0}, behind_wrong = 0;
    const int N = 4000;
    for (int i = 0; i < N; ++i) {
        float A[3], B[3], seg[3];
        float za = D * (0.2f + 0.75f * rnd());
        point_at(&b, 1.8f * rnd() - 0.9f, 1.8f * rnd() - 0.9f, za, A);
        point_at(&b, 1.8f * rnd() - 0.9f, 1.8f * rnd() - 0.9f, D + 12.0f * h, B);
        float len = 0.0f;
        for (int a = 0; a < 3; ++a) seg[a] = B[a] - A[a], len += seg[a] * seg[a];
        len = sqrtf(len);
        for (int a = 0; a < 3; ++a) seg[a] /= len;
        if (za < D - 3.5f * h && !(veil_solid_hit(&s, A, seg, len) < len)) ++misses;
        /* 2. free in front */
        float P[3], Z = D * 0.2f + (D * 0.8f - 3.5f * h) * rnd();
        point_at(&b, 2.0f * rnd() - 1.0f, 2.0f * rnd() - 1.0f, Z, P);
        intrusions += veil_solid_at(&s, P);
        /* 3. shadows of points in front, within 0.7 of the cone */
        float Q[3], Zq = D * 0.2f + D * 0.75f * rnd();
        point_at(&b, 1.4f * rnd() - 0.7f, 1.4f * rnd() - 0.7f, Zq, Q);
        for (int l = 0; l < 4; ++l) {
            float dq = 0.0f;
            for (int a = 0; a < 3; ++a) dq += (Q[a] - lights[l].position[a]) * (Q[a] - lights[l].position[a]);
            float bias = s.bias[l][0] + s.bias[l][1] * sqrtf(dq);
            float v = veil_solid_visibility(&s, &lights[l], l, Q);
            if (l == 0 || l == 2) lit_wrong[l] += Zq < D - bias - h && v != 0.0f;
            else lit_wrong[l] += Zq < D - 3.5f * h && Zq > 0.5f * D * (l == 3) && v < 1.0f - 1e-6f; /* the taps'
                                                                                         weights sum to 1 in float */
        }
        /* behind the wall, from the lamp in front */
        float R[3];
        point_at(&b, rnd() - 0.5f, rnd() - 0.5f, D + 12.0f * h, R);
        behind_wrong += veil_solid_visibility(&s, &lights[3], 3, R) != 0.0f;
    }
    CHECK(misses == 0, "%s: %d of %d segments through the wall found no solid (voxel %g m)", name, misses, N, h);
    CHECK(intrusions == 0, "%s: %d of %d points more than 3.5 voxels in front of the wall are solid", name,
          intrusions, N);
    CHECK(lit_wrong[0] == 0, "%s: the sun beyond the wall lights %d of %d points in front of it", name, lit_wrong[0], N);
    CHECK(lit_wrong[1] == 0, "%s: the sun behind the camera leaves %d of %d points in front of the wall dark", name,
          lit_wrong[1], N);
    CHECK(lit_wrong[2] == 0, "%s: the lamp beyond the wall lights %d of %d points in front of it", name, lit_wrong[2], N);
    CHECK(lit_wrong[3] == 0, "%s: the lamp in front of the wall leaves %d of %d points before the wall dark", name,
          lit_wrong[3], N);
    CHECK(behind_wrong == 0, "%s: the lamp in front of the wall lights %d of %d points behind it", name, behind_wrong, N);
    printf("%s: %dx%dx%d voxels of %.4g m, %zu solid; biases %.3g / %.3g m; %d segments, points and shadows checked\n",
           name, s.dims[0], s.dims[1], s.dims[2], (double)h, s.solid_count, (double)s.bias[0][0],
           (double)s.bias[2][0], N);
    veil_solid_free(&s);

    /* 4. a lamp on the wall: its surroundings free */
    veil_light on_wall = {.type = VEIL_LIGHT_POINT, .color = {1, 1, 1}};
    for (int a = 0; a < 3; ++a) on_wall.position[a] = b.pos[a] + D * b.fwd[a];
    CHECK(veil_solid_build(&cam, W, H, dist, lo, hi, &on_wall, 1, &s, &err) == VEIL_OK, "%s", err.msg);
    CHECK(s.voxels && !veil_solid_at(&s, on_wall.position), "%s: the lamp on the wall sits in solid", name);
    veil_solid_free(&s);
    free(dist);
}

int main(void)
{
    const float views[7][3] = {{0, 0, -1}, {0, 0, 1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0},
                               {0.48f, -0.6f, -0.64f}};
    const char* names[7] = {"-z", "+z", "+x", "-x", "+y", "-y", "oblique"};
    for (int v = 0; v < 7; ++v) one_view(views[v], names[v]);

    /* 5. nothing finite inside the box: no solid */
    veil_error err = {0};
    veil_camera cam = {.position = {0, 0, 0}, .look_at = {0, 0, -1}, .up = {0, 1, 0}, .fov_y_deg = 40.0f,
                       .width = W, .height = H};
    float* dist = malloc(sizeof(float) * W * H);
    for (int i = 0; i < W * H; ++i) dist[i] = INFINITY;
    const float lo[3] = {-100, -100, -100}, hi[3] = {100, 100, 100}, small_lo[3] = {-1, -1, -1}, small_hi[3] = {1, 1, 1};
    veil_solid s;
    CHECK(veil_solid_build(&cam, W, H, dist, lo, hi, NULL, 0, &s, &err) == VEIL_OK && !s.voxels && s.dims[0] == 0,
          "all +inf: no solid expected (%d voxels)", s.dims[0]);
    for (int i = 0; i < W * H; ++i) dist[i] = 50.0f;
    CHECK(veil_solid_build(&cam, W, H, dist, small_lo, small_hi, NULL, 0, &s, &err) == VEIL_OK && !s.voxels,
          "surfaces outside the medium's box: no solid expected");

    /* 6. the key */
    uint64_t k0 = veil_solid_key(VEIL_FNV_OFFSET, W, H, dist), k1 = veil_solid_key(VEIL_FNV_OFFSET, W, H, dist);
    dist[W * H / 2] = 49.0f;
    uint64_t k2 = veil_solid_key(VEIL_FNV_OFFSET, W, H, dist);
    CHECK(k0 == k1 && k0 != k2 && veil_solid_key(VEIL_FNV_OFFSET, W, H, NULL) == VEIL_FNV_OFFSET,
          "the key follows the depth (and is the given key without one)");
    free(dist);
    return check_finish();
}
