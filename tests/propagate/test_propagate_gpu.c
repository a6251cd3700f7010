/* The GPU Jacobi gather equals the CPU one, for lights inside and outside
 * the grid and directional ones, five lights (two RGBA textures); an
 * ordered method's light alone (an r32f texture) equals its channel of
 * the shared texture bit for bit.
 *
 * Tolerance: both run the same float operations; GLSL 4.50 allows division
 * 2.5 ulp and sqrt (as 1/inversesqrt) about 3 ulp where C is exact to 0.5,
 * so one gather differs by at most ~8 ulp relative (the weights, one
 * product, two sums). The gather is a convex combination of non-negative
 * terms, so relative differences do not grow through it, only add up along
 * the dependency chain, at most dims.x + dims.y + dims.z steps long:
 * |gpu - cpu| <= 8 * (dims sum) * 2^-23 * cpu, plus the same relative bound
 * on the largest value as an absolute floor for values near 0. */
#include <math.h>
#include <stdlib.h>

#include "support/check.h"
#include "frame/renderer.h"

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_renderer* r = NULL;
    veil_error err = {0};
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);

    veil_grid g = {.dims = {20, 17, 13}, .origin = {0, 0, 0}, .voxel = 0.05f};
    size_t nv = veil_grid_voxels(&g);
    veil_rbf_random_desc d = {.count = 60, .seed = 5, .bounds = {{0, 0, 0}, {1.0f, 0.85f, 0.65f}},
                              .radius = {0.05f, 0.2f}, .amplitude = {0.5f, 4.0f}};
    veil_particle p[60];
    veil_rbf_random_generate(&d, p);
    veil_rbf_bins bins;
    veil_rbf_bin(&g, p, d.count, &bins, &err);
    float* rho = calloc(nv, sizeof(float));
    veil_inject_rbf_cpu(&g, &bins, rho);
    veil_rbf_bins_free(&bins);

    const veil_light world[5] = {
        {.type = VEIL_LIGHT_POINT, .position = {0.52f, 0.41f, 0.33f}},   /* inside, off-centre */
        {.type = VEIL_LIGHT_POINT, .position = {-0.7f, 1.3f, 0.2f}},     /* outside */
        {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0.48f, -0.8f, 0.36f}},
        {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0, 0, 1}},
        {.type = VEIL_LIGHT_POINT, .position = {2.0f, -1.0f, 3.0f}},     /* outside, other corner */
    };
    veil_index_light lights[5];
    for (int l = 0; l < 5; ++l) veil_light_to_index(&world[l], g.dims, g.origin, g.voxel, &lights[l]);

    float* cpu = malloc(5 * nv * sizeof(float));
    float* gpu = malloc(5 * nv * sizeof(float));
    for (int m = VEIL_OPV_JACOBI; m < VEIL_OPV_METHOD_COUNT; ++m) {
        /* per-voxel update: ~8 ulp for the gather; the semi-Lagrangian step
         * adds a bilinear read, a trilinear density and a sqrt: ~32 ulp */
        double ulps = m == VEIL_OPV_SEMI_LAGRANGIAN || m == VEIL_OPV_LIGHT_SPACE ? 32.0 : 8.0;
        double rel = ulps * (g.dims[0] + g.dims[1] + g.dims[2]) * 0x1p-23;
        veil_opv_params exact = {.method = (veil_opv_method)m};
        int it_cpu = 0, it_gpu = 0;
        veil_opv_cpu(&g, rho, lights, 5, &exact, cpu, &it_cpu, &err);
        CHECK(veil_renderer_propagate(r, &g, rho, lights, 5, &exact, gpu, &it_gpu, &err) == VEIL_OK, "%s", err.msg);
        for (int l = 0; l < 5; ++l) {
            double dmax = 0.0, worst = 0.0;
            for (size_t v = 0; v < nv; ++v) dmax = fmax(dmax, cpu[l * nv + v]);
            int bad = 0;
            for (size_t v = 0; v < nv; ++v) {
                double c = cpu[l * nv + v], e = fabs((double)gpu[l * nv + v] - c);
                if (!(e <= rel * (c + dmax))) ++bad;
                worst = fmax(worst, e / (c + dmax));
            }
            printf("%-17s light %d: max D %.4g, largest GPU-CPU difference %.3g of (D + max D)\n",
                   veil_opv_method_name((veil_opv_method)m), l, dmax, worst);
            CHECK(dmax > 0.0, "%s light %d: no optical depth at all", veil_opv_method_name((veil_opv_method)m), l);
            CHECK(bad == 0, "%s light %d: %d voxels differ beyond %.3g relative",
                  veil_opv_method_name((veil_opv_method)m), l, bad, rel);
        }
        printf("%-17s iterations/passes: CPU %d, GPU %d\n", veil_opv_method_name((veil_opv_method)m), it_cpu, it_gpu);
        CHECK(it_cpu == it_gpu, "CPU and GPU took different numbers of steps");
        if (m == VEIL_OPV_JACOBI || m == VEIL_OPV_JACOBI_CORRECTED) continue;
        /* an ordered method keeps a light alone in an r32f texture: the same operations, bit for bit */
        for (int l = 0; l < 5; ++l) {
            int it = 0;
            CHECK(veil_renderer_propagate(r, &g, rho, &lights[l], 1, &exact, cpu, &it, &err) == VEIL_OK, "%s", err.msg);
            size_t differ = 0;
            for (size_t v = 0; v < nv; ++v) differ += cpu[v] != gpu[l * nv + v];
            CHECK(differ == 0, "%s light %d alone (r32f): %zu voxels differ from its channel of the rgba32f texture",
                  veil_opv_method_name((veil_opv_method)m), l, differ);
        }
    }
    free(cpu);
    free(gpu);
    free(rho);
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
    return check_finish();
}
