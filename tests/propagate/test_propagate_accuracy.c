/* Accuracy of the optical-depth methods (C versions; tests/propagate/test_propagate_gpu.c
 * shows the GPU versions equal to these bit for bit).
 *
 * 1. Exactness. Homogeneous medium, axis-aligned directional light: every
 *    method must give D = rho h k, k the voxels between X and the face the
 *    light enters by. Each step adds h rho (the trapezoid of equal values,
 *    or a trilinear read of equal values, within 2 ulp), so after k steps
 *    |D - rho h k| <= 4 k 2^-24 rho h k.
 * 2. One pass is the fixed point. The ordered sweep computes the corrected
 *    gather in dependency order, so it must equal Jacobi-corrected run to
 *    its exact fixed point, bit for bit, on any medium and light.
 * 3. A derived bound for the semi-Lagrangian method: homogeneous medium
 *    (density rho), point light inside it, so D = rho r exactly (r = |S-X|).
 *    Each step reads D bilinearly on a voxel-spaced stencil; for
 *    f = rho |S - X| the second derivatives across the ray are rho/r, so the
 *    interpolation error of a step is at most (h^2/8)(2 rho / r_s), r_s the
 *    nearest stencil point's distance. Errors pass through later steps
 *    unamplified (each is a convex combination plus a positive term) and
 *    add up. Steps within VEIL_SL_DEFAULT_EXIT_STEPS (8) voxels of the light
 *    integrate directly, exactly for a constant density, so interpolating
 *    steps have r >= 8h and r_s >= r - sqrt(2) h >= 0.8 r. Each step brings
 *    the path at least h nearer the light, so over the path
 *    sum 1/r_k <= (1/h)(1 + ln(r/h)), and
 *      |D - rho r| <= 1.25 (rho h / 4) (1 + ln(r / h))
 *    plus rounding (32 ulp a step, see test_propagate_gpu.c). That is for
 *    characteristics one voxel long; longer ones (the default is
 *    VEIL_SL_DEFAULT_CHARACTERISTIC) interpolate once per k voxels and
 *    integrate exactly in between, so the same bound holds with room. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "propagate/opv_plan.h"
#include "propagate/opv.h"

static const veil_opv_method methods[] = {VEIL_OPV_JACOBI, VEIL_OPV_JACOBI_CORRECTED, VEIL_OPV_SWEEP,
                                          VEIL_OPV_SEMI_LAGRANGIAN};

static void test_axis_aligned(void)
{
    veil_grid g = {.dims = {13, 11, 9}, .origin = {-1.0f, 0.5f, 2.0f}, .voxel = 0.37f};
    size_t nv = veil_grid_voxels(&g);
    const float rho0 = 1.7f;
    float* rho = malloc(nv * sizeof(float));
    float* D = malloc(nv * sizeof(float));
    for (size_t v = 0; v < nv; ++v) rho[v] = rho0;
    for (int m = 0; m < 4; ++m)
        for (int axis = 0; axis < 3; ++axis)
            for (int sign = -1; sign <= 1; sign += 2) {
                veil_light l = {.type = VEIL_LIGHT_DIRECTIONAL};
                l.direction[axis] = (float)sign; /* travels along +-axis */
                veil_index_light ol;
                veil_light_to_index(&l, g.dims, g.origin, g.voxel, &ol);
                veil_opv_params p = {.method = methods[m]};
                veil_error err = {0};
                int it = 0;
                veil_result r = veil_opv_cpu(&g, rho, &ol, 1, &p, D, &it, &err);
                CHECK(r == VEIL_OK, "%s: veil_opv_cpu: %s: %s", veil_opv_method_name(methods[m]), veil_result_name(r),
                      err.msg);
                if (r != VEIL_OK) continue; /* D is unwritten */
                int bad = 0;
                for (int k = 0; k < g.dims[2]; ++k)
                    for (int j = 0; j < g.dims[1]; ++j)
                        for (int i = 0; i < g.dims[0]; ++i) {
                            int x[3] = {i, j, k};
                            /* light travels +axis: it enters by the face x = 0 */
                            int steps = sign > 0 ? x[axis] : g.dims[axis] - 1 - x[axis];
                            double expect = (double)rho0 * g.voxel * steps;
                            double got = D[((size_t)k * g.dims[1] + j) * g.dims[0] + i];
                            if (!(fabs(got - expect) <= 4.0 * steps * 0x1p-24 * expect)) ++bad;
                        }
                CHECK(bad == 0, "%s, light along %c%c: %d voxels not exact", veil_opv_method_name(methods[m]),
                      sign > 0 ? '+' : '-', "xyz"[axis], bad);
            }
    free(rho);
    free(D);
}

static void test_sweep_is_fixed_point(void)
{
    veil_grid g = {.dims = {21, 16, 13}, .origin = {0, 0, 0}, .voxel = 0.05f};
    size_t nv = veil_grid_voxels(&g);
    veil_rbf_random_desc d = {.count = 50, .seed = 9, .bounds = {{0, 0, 0}, {1.0f, 0.75f, 0.6f}},
                              .radius = {0.05f, 0.2f}, .amplitude = {0.5f, 3.0f}};
    veil_particle p[50];
    veil_rbf_random_generate(&d, p);
    veil_rbf_bins bins;
    veil_error err = {0};
    veil_result rb = veil_rbf_bin(&g, p, d.count, &bins, &err);
    CHECK(rb == VEIL_OK, "veil_rbf_bin: %s: %s", veil_result_name(rb), err.msg);
    if (rb != VEIL_OK) return;
    float* rho = calloc(nv, sizeof(float));
    veil_inject_rbf_cpu(&g, &bins, rho);
    veil_rbf_bins_free(&bins);
    const veil_light world[3] = {
        {.type = VEIL_LIGHT_POINT, .position = {0.52f, 0.41f, 0.33f}},
        {.type = VEIL_LIGHT_POINT, .position = {-0.7f, 1.3f, 0.2f}},
        {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0.48f, -0.8f, 0.36f}},
    };
    veil_index_light lights[3];
    for (int l = 0; l < 3; ++l) veil_light_to_index(&world[l], g.dims, g.origin, g.voxel, &lights[l]);
    float* a = malloc(3 * nv * sizeof(float));
    float* b = malloc(3 * nv * sizeof(float));
    int it_j = 0, it_s = 0;
    /* a failed propagation leaves a or b unwritten: report it rather than compare garbage */
    veil_result rj =
        veil_opv_cpu(&g, rho, lights, 3, &(veil_opv_params){.method = VEIL_OPV_JACOBI_CORRECTED}, a, &it_j, &err);
    CHECK(rj == VEIL_OK, "veil_opv_cpu (Jacobi-corrected): %s: %s", veil_result_name(rj), err.msg);
    veil_result rs = veil_opv_cpu(&g, rho, lights, 3, &(veil_opv_params){.method = VEIL_OPV_SWEEP}, b, &it_s, &err);
    CHECK(rs == VEIL_OK, "veil_opv_cpu (sweep): %s: %s", veil_result_name(rs), err.msg);
    if (rj == VEIL_OK && rs == VEIL_OK)
        CHECK(memcmp(a, b, 3 * nv * sizeof(float)) == 0, "the sweep differs from the Jacobi fixed point");
    printf("sweep: %d passes; Jacobi-corrected: %d iterations to the same fixed point\n", it_s, it_j);
    free(a);
    free(b);
    free(rho);
}

static void test_sl_bound(void)
{
    enum { N = 48 };
    veil_grid g = {.dims = {N, N, N}, .origin = {0, 0, 0}, .voxel = 1.0f / N};
    size_t nv = veil_grid_voxels(&g);
    const float rho0 = 2.0f;
    float* rho = malloc(nv * sizeof(float));
    float* D = malloc(nv * sizeof(float));
    for (size_t v = 0; v < nv; ++v) rho[v] = rho0;
    const float pos[3][3] = {{0.53f, 0.47f, 0.51f}, {0.3f, 0.71f, 0.45f}, {0.2f, 0.2f, 0.8f}};
    for (int q = 0; q < 3; ++q) {
        veil_light l = {.type = VEIL_LIGHT_POINT, .position = {pos[q][0], pos[q][1], pos[q][2]}};
        veil_index_light ol;
        veil_light_to_index(&l, g.dims, g.origin, g.voxel, &ol);
        veil_error err = {0};
        int it = 0;
        veil_result res = veil_opv_cpu(
            &g, rho, &ol, 1, &(veil_opv_params){.method = VEIL_OPV_SEMI_LAGRANGIAN, .characteristic = 1}, D, &it, &err);
        CHECK(res == VEIL_OK, "light %d: veil_opv_cpu: %s: %s", q, veil_result_name(res), err.msg);
        if (res != VEIL_OK) continue; /* D is unwritten */
        double h = g.voxel, worst = 0.0, se = 0.0;
        int bad = 0;
        size_t n = 0;
        for (int k = 0; k < N; ++k)
            for (int j = 0; j < N; ++j)
                for (int i = 0; i < N; ++i) {
                    double x[3] = {(i + 0.5) * h, (j + 0.5) * h, (k + 0.5) * h}, r = 0.0;
                    for (int a = 0; a < 3; ++a) r += (x[a] - l.position[a]) * (x[a] - l.position[a]);
                    r = sqrt(r);
                    if (r < 2.0 * h) continue; /* the near field: direct quadrature */
                    double got = D[((size_t)k * N + j) * N + i], exact = rho0 * r;
                    double bound = 1.25 * (rho0 * h / 4.0) * (1.0 + log(r / h)) + 32.0 * 3 * N * 0x1p-24 * exact;
                    if (!(fabs(got - exact) <= bound)) ++bad;
                    worst = fmax(worst, fabs(got - exact) / bound);
                    se += (got - exact) * (got - exact) / (exact * exact);
                    ++n;
                }
        printf("semi-Lagrangian, homogeneous %d^3, point light %d inside: largest error %.2f of the bound, "
               "rms relative error %.3f %%\n",
               N, q, worst, 100.0 * sqrt(se / n));
        CHECK(bad == 0, "light %d: %d voxels beyond the interpolation bound", q, bad);
    }
    free(rho);
    free(D);
}

/* A point light 1e15 m away on every axis (scene/limits.h's largest
 * position) over a 8^3 grid of 1 cm voxels: its voxel index is 1e17, and
 * the sweep's shells (Manhattan distances to it) once summed three of them
 * in int: undefined behaviour (issue 12, defect 7; fatal under UBSan). The
 * plan must span exactly the grid's 7 + 7 + 7 shells, from a positive first. */
static void test_far_light(void)
{
    veil_grid g = {.dims = {8, 8, 8}, .origin = {0, 0, 0}, .voxel = 0.01f};
    for (int s = -1; s <= 1; s += 2) {
        veil_light l = {.type = VEIL_LIGHT_POINT, .position = {s * 1e15f, s * 1e15f, s * 1e15f}, .color = {1, 1, 1}};
        veil_index_light ol;
        veil_light_to_index(&l, g.dims, g.origin, g.voxel, &ol);
        veil__gather_plan p;
        veil__gather_plan_make(&g, &ol, &p);
        CHECK(p.first > 0 && p.last - p.first == 21, "light at %g: shells %d .. %d", s * 1e15, p.first, p.last);
        for (int a = 0; a < 3; ++a)
            CHECK(s > 0 ? ol.c[a] == 7 + VEIL_INDEX_LIGHT_FAR : ol.c[a] == -VEIL_INDEX_LIGHT_FAR, "c[%d] = %d", a, ol.c[a]);
    }
}

int main(void)
{
    test_far_light();
    test_axis_aligned();
    test_sweep_is_fixed_point();
    test_sl_bound();
    return check_finish();
}
