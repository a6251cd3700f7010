/* A light-space grid on the GPU (propagate/shaders/sun_prefix.comp)
 * against its C twin (veil_sun_space_cpu), on puffs of smoke with empty
 * space between them: three suns, and two point lights' perspective grids
 * (one inside the box, all six faces; one outside it).
 *
 * 1. Skipping empty bricks changes nothing: a skipped panel lies where
 *    the field is 0 (shader comment), so it adds exactly 0 either way and
 *    the two read-backs are bit for bit equal.
 * 2. GPU against C. The only difference is the density fetch: the GPU's
 *    trilinear filter, whose weights the GL leaves to the implementation
 *    (8 fractional bits on common hardware: a fetch may be off by 2^-9 of
 *    the difference between its neighbouring voxels, at most rho_max), and
 *    float rounding in another order (2^-22 of D per step, the C twin's
 *    test bound). Summed over a column's panels, |D_gpu - D_cpu| <=
 *    2^-9 rho_max * (length in the box) + (nodes_c + 8) 2^-22 D.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "support/puffs.h"
#include "frame/renderer.h"
#include "propagate/opv_set.h"
#include "propagate/sun_space.h"

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_opv_set* set = NULL;
    CHECK(veil_opv_set_create(&set, &err) == VEIL_OK, "%s", err.msg);
    veil_grid g = {.dims = {40, 34, 30}, .origin = {-1, 0, 1}, .voxel = 0.05f};
    const puff p[3] = {{{8, 9, 7}, 2.0}, {{30, 12, 20}, 1.5}, {{18, 26, 14}, 2.5}};
    float rmax;
    float* rho = puffs_density(&g, p, 3, &rmax); /* cut at 3 radii: empty bricks between */
    const float dirs[3][3] = {{-0.5f, -0.6f, -0.62f}, {0.3f, -1.0f, 0.2f}, {0.0f, 0.0f, 1.0f}};
    const float spacing[3][2] = {{0.5f, 4.0f}, {1.0f, 1.0f}, {0.7f, 2.5f}};
    GLint max_axis = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max_axis);
    const float points[2][3] = {{20.3f, 16.8f, 15.1f}, {-12.0f, 40.0f, 8.0f}}; /* index coordinates */
    for (int d = 0; d < 5 && set; ++d) {
        veil_sun_space s;
        if (d < 3)
            CHECK(veil_sun_space_make(&g, dirs[d], spacing[d][0], spacing[d][1], 1, max_axis, VEIL_SUN_MAX_NODES, &s,
                                      &err) == VEIL_OK, "%s", err.msg);
        else
            CHECK(veil_point_space_make(&g, points[d - 3], 0.5f, 2.0f, 1, max_axis, VEIL_SUN_MAX_NODES, &s, &err) ==
                      VEIL_OK, "%s", err.msg);
        size_t n = veil_sun_space_nodes(&s);
        float* cpu = malloc(n * sizeof *cpu);
        float* skip = malloc(n * sizeof *skip);
        float* noskip = malloc(n * sizeof *noskip);
        veil_sun_space_cpu(&g, rho, &s, cpu);
        CHECK(veil_opv_set_sun_readback(set, &g, rho, &s, 1, skip, &err) == VEIL_OK, "%s", err.msg);
        CHECK(veil_opv_set_sun_readback(set, &g, rho, &s, 0, noskip, &err) == VEIL_OK, "%s", err.msg);
        CHECK(!memcmp(skip, noskip, n * sizeof *skip), "dir %d: skipping empty bricks changed the optical depth", d);
        const float* a = s.axis[2];
        double step = (s.perspective ? s.dz : sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])) * g.voxel, worst = 0, dmax = 0;
        double box = sqrt((double)g.dims[0] * g.dims[0] + g.dims[1] * g.dims[1] + g.dims[2] * g.dims[2]) * g.voxel;
        size_t bad = 0;
        for (size_t i = 0; i < n; ++i) {
            double e = fabs((double)skip[i] - cpu[i]);
            double bound = 0x1p-9 * rmax * box + (s.nodes[2] + 8) * 0x1p-22 * fabs(cpu[i]);
            bad += !(e <= bound);
            worst = fmax(worst, e);
            dmax = fmax(dmax, cpu[i]);
        }
        printf("dir %d: %d x %d x %d nodes, step %.3g m, D up to %.3g, |GPU - C| up to %.3g (bound %.3g)\n", d, s.nodes[0],
               s.nodes[1], s.nodes[2], step, dmax, worst, 0x1p-9 * rmax * box);
        CHECK(bad == 0, "dir %d: %zu nodes differ from the C twin beyond the bound (worst %.3g)", d, bad, worst);
        CHECK(dmax > 0.05, "dir %d: the puffs cast no shadow (D up to %.3g)", d, dmax);
        free(cpu);
        free(skip);
        free(noskip);
    }
    free(rho);
    veil_opv_set_destroy(set);
    veil_gl_destroy(gl);
    return check_finish();
}
