/* The medium's emission as point lights (volume/emission_lights.h), on
 * emission grids made here:
 * - the total intensity is conserved: sum over lights of I equals sum of
 *   eps dV over the grid (to float rounding: 1e-6 relative), for every
 *   count of lights 1..16;
 * - one emitting voxel is one light at its centre, of intensity eps h^3 and
 *   radius sqrt(5/9 x 0.6) (3 / (4 pi))^(1/3) h (a ball of its volume);
 * - two emitting voxels apart make two lights, each at its voxel's centre
 *   with its own power (the k-d split never leaves a side empty);
 * - a grid without emission gives no light;
 * - intensities within VEIL_MAX_LIGHT (scene/limits.h, issue 22): a voxel
 *   of 1e14 m emitting 1e21 W m^-3 sr^-1 (eps dV = 1e63, infinite as a
 *   float), and an infinite eps dV among the points (the sparse path's
 *   list), make finite lights of at most 1e20 W/sr, colour kept, at the
 *   voxel's centre: they made an infinite light (a NaN position once
 *   summed with another). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "core/shared.glsl.h"
#include "scene/limits.h"
#include "volume/emission_lights.h"

static float* grid_rgba(const veil_grid* g)
{
    return calloc(veil_grid_voxels(g) * 4, sizeof(float));
}

static void set(const veil_grid* g, float* rgba, int x, int y, int z, float r, float gr, float b)
{
    float* e = rgba + 4 * ((size_t)x + (size_t)g->dims[0] * ((size_t)y + (size_t)g->dims[1] * (size_t)z));
    e[0] = r, e[1] = gr, e[2] = b;
}

int main(void)
{
    veil_grid g = {.dims = {16, 12, 10}, .origin = {-1.0f, 0.5f, 2.0f}, .voxel = 0.1f};
    float* rgba = grid_rgba(&g);
    veil_light l[VEIL_MAX_LIGHTS];
    int n = -1;
    veil_error err = {0};
    double h3 = (double)g.voxel * g.voxel * g.voxel;

    CHECK(veil_emission_lights(&g, rgba, 8, l, &n, &err) == VEIL_OK && n == 0, "no emission: %d lights", n);

    /* one voxel */
    set(&g, rgba, 3, 4, 5, 2.0f, 1.0f, 0.5f);
    CHECK(veil_emission_lights(&g, rgba, 8, l, &n, &err) == VEIL_OK && n == 1, "one voxel: %d lights", n);
    float c[3];
    veil_grid_center(&g, 3, 4, 5, c);
    double r = sqrt(5.0 / 9.0 * 0.6) * pow(3.0 / (4.0 * VEIL_PI), 1.0 / 3.0) * g.voxel;
    if (n == 1) {
        for (int a = 0; a < 3; ++a) CHECK(fabsf(l[0].position[a] - c[a]) <= 1e-6f, "position[%d] %g vs %g", a, l[0].position[a], c[a]);
        CHECK(fabs(l[0].color[0] - 2.0 * h3) <= 1e-6 * 2.0 * h3 && fabs(l[0].color[2] - 0.5 * h3) <= 1e-6 * 0.5 * h3,
              "intensity %g, %g vs eps h^3 %g, %g", l[0].color[0], l[0].color[2], 2.0 * h3, 0.5 * h3);
        CHECK(fabs(l[0].radius - r) <= 1e-6 * r, "radius %g vs %g", l[0].radius, r);
        CHECK(l[0].type == VEIL_LIGHT_POINT, "type %d", l[0].type);
    }

    /* two voxels apart: two lights, one on each */
    memset(rgba, 0, veil_grid_voxels(&g) * 4 * sizeof(float));
    set(&g, rgba, 1, 2, 3, 1.0f, 2.0f, 3.0f);
    set(&g, rgba, 14, 9, 7, 4.0f, 4.0f, 4.0f);
    CHECK(veil_emission_lights(&g, rgba, 2, l, &n, &err) == VEIL_OK && n == 2, "two voxels: %d lights", n);
    float c1[3], c2[3];
    veil_grid_center(&g, 1, 2, 3, c1);
    veil_grid_center(&g, 14, 9, 7, c2);
    for (int i = 0; i < n; ++i) {
        int first = fabsf(l[i].position[0] - c1[0]) < 1e-6f;
        const float* want = first ? c1 : c2;
        for (int a = 0; a < 3; ++a) CHECK(fabsf(l[i].position[a] - want[a]) <= 1e-6f, "light %d axis %d", i, a);
        double p = (first ? 1.0 : 4.0) * h3;
        CHECK(fabs(l[i].color[0] - p) <= 1e-6 * p, "light %d: power %g vs %g", i, l[i].color[0], p);
    }

    /* two blobs: voxels x in 0..2 (value 1) and x in 12..15 (value 3), y = z = 0..1 */
    memset(rgba, 0, veil_grid_voxels(&g) * 4 * sizeof(float));
    double total[3] = {0, 0, 0};
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y) {
            for (int x = 0; x < 3; ++x) set(&g, rgba, x, y, z, 1.0f, 1.0f, 1.0f);
            for (int x = 12; x < 16; ++x) set(&g, rgba, x, y, z, 3.0f, 3.0f, 3.0f);
        }
    for (size_t i = 0; i < veil_grid_voxels(&g); ++i)
        for (int k = 0; k < 3; ++k) total[k] += rgba[4 * i + (size_t)k] * h3;
    /* conservation for every count */
    for (int k = 1; k <= VEIL_MAX_LIGHTS; ++k) {
        CHECK(veil_emission_lights(&g, rgba, k, l, &n, &err) == VEIL_OK && n == k, "%d lights asked, %d made", k, n);
        double sum[3] = {0, 0, 0};
        for (int i = 0; i < n; ++i)
            for (int a = 0; a < 3; ++a) sum[a] += l[i].color[a];
        for (int a = 0; a < 3; ++a)
            CHECK(fabs(sum[a] - total[a]) <= 1e-6 * total[a], "k %d: power %g vs %g", k, sum[a], total[a]);
        /* each light inside the blobs' box (a centroid of some of their voxels) */
        for (int i = 0; i < n; ++i)
            CHECK(l[i].position[1] >= g.origin[1] && l[i].position[1] <= g.origin[1] + 2 * g.voxel, "k %d light %d y %g",
                  k, i, l[i].position[1]);
    }
    free(rgba);

    /* issue 22: eps dV beyond a float, from a huge voxel or an infinite value */
    veil_grid huge = {.dims = {4, 4, 4}, .origin = {-2e14f, -2e14f, -2e14f}, .voxel = 1e14f};
    rgba = grid_rgba(&huge);
    set(&huge, rgba, 1, 2, 3, 1e21f, 5e20f, 0.0f);
    CHECK(veil_emission_lights(&huge, rgba, 1, l, &n, &err) == VEIL_OK && n == 1, "huge voxels: %d lights", n);
    if (n == 1) {
        veil_grid_center(&huge, 1, 2, 3, c);
        CHECK(l[0].color[0] == (float)VEIL_MAX_LIGHT && fabsf(l[0].color[1] - 0.5f * (float)VEIL_MAX_LIGHT) <= 1e-6f * 1e20f &&
                  l[0].color[2] == 0.0f, "huge voxel: intensity %g %g %g, expected 1e20, 5e19, 0 (its colour kept)",
              l[0].color[0], l[0].color[1], l[0].color[2]);
        for (int a = 0; a < 3; ++a)
            CHECK(l[0].position[a] == c[a], "huge voxel: position[%d] %g, expected its centre %g", a, l[0].position[a], c[a]);
        CHECK(isfinite(l[0].radius) && l[0].radius > 0.0f, "huge voxel: radius %g", l[0].radius);
    }
    /* with a dim voxel beside it: both saturate; finite, within the bound, inside the grid */
    set(&huge, rgba, 3, 3, 3, 1.0f, 1.0f, 1.0f);
    CHECK(veil_emission_lights(&huge, rgba, 1, l, &n, &err) == VEIL_OK && n == 1, "two huge voxels: %d lights", n);
    for (int a = 0; n == 1 && a < 3; ++a)
        CHECK(l[0].color[a] <= (float)VEIL_MAX_LIGHT && isfinite(l[0].position[a]) &&
                  l[0].position[a] >= huge.origin[a] && l[0].position[a] <= huge.origin[a] + 4 * huge.voxel,
              "two huge voxels: intensity[%d] %g, position %g", a, l[0].color[a], l[0].position[a]);
    free(rgba);
    const float pts[12] = {0.0f, 0.0f, 0.0f, INFINITY, 1.0f, 1.0f, 1.0f, 0.0f, 0.0f, 2.0f, 2.0f, 2.0f};
    CHECK(veil_emission_lights_points(pts, 2, 1.0f, 1, l, &n, &err) == VEIL_OK && n == 1, "infinite point: %d lights", n);
    if (n == 1) {
        CHECK(l[0].color[0] <= (float)VEIL_MAX_LIGHT && isfinite(l[0].color[0]) && l[0].color[1] > 0.0f,
              "an infinite eps dV: intensity %g %g %g, within 1e20", l[0].color[0], l[0].color[1], l[0].color[2]);
        for (int a = 0; a < 3; ++a) CHECK(isfinite(l[0].position[a]), "infinite point: position[%d] %g", a, l[0].position[a]);
    }
    return check_finish();
}
