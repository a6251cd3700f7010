/* The published Jacobi gather in a homogeneous medium, point light at the
 * centre of the centre voxel (CPU version; tests/propagate/test_propagate_gpu.c shows
 * the GPU version equal to it).
 *
 * Closed form of the scheme itself: every up-wind step moves exactly one
 * voxel toward the light and adds h*rho, and the weights of a voxel sum to
 * one, so every path from voxel d (index offset from the light) to the light
 * has |d|_1 steps and D = rho * h * |d|_1: the Manhattan distance. On the
 * axes that equals the true rho * |S - X|; off the axes the error against
 * the Euclidean rho * h * |d|_2 is printed (issue 3 fixes it).
 * Rounding: D is a chain of |d|_1 float additions of h*rho and convex
 * combinations of such chains, each step adding at most 2 ulp (one add, one
 * weighted sum) of relative error: |D - ref| <= 2 |d|_1 2^-23 ref. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "support/check.h"
#include "propagate/opv.h"

int main(void)
{
    enum { N = 33, C = 16 };
    const float rho0 = 2.0f;
    veil_grid g = {.dims = {N, N, N}, .origin = {0, 0, 0}, .voxel = 1.0f / N};
    size_t nv = veil_grid_voxels(&g);
    float* rho = malloc(nv * sizeof(float));
    float* D = malloc(nv * sizeof(float));
    for (size_t v = 0; v < nv; ++v) rho[v] = rho0;
    veil_light light = {.type = VEIL_LIGHT_POINT, .position = {(C + 0.5f) / N, (C + 0.5f) / N, (C + 0.5f) / N}};
    veil_index_light L;
    veil_light_to_index(&light, g.dims, g.origin, g.voxel, &L);
    CHECK(fabsf(L.v[0] - C) < 1e-5f, "light index position %g", L.v[0]);

    veil_opv_params exact = {.method = VEIL_OPV_JACOBI};
    int iters = 0;
    veil_error err = {0};
    CHECK(veil_opv_cpu(&g, rho, &L, 1, &exact, D, &iters, &err) == VEIL_OK, "%s", err.msg);

    int bad_axis = 0, bad_l1 = 0;
    double se = 0.0;
    size_t off = 0;
    for (int k = 0; k < N; ++k)
        for (int j = 0; j < N; ++j)
            for (int i = 0; i < N; ++i) {
                int di = abs(i - C), dj = abs(j - C), dk = abs(k - C);
                int l1 = di + dj + dk;
                double got = D[((size_t)k * N + j) * N + i];
                double manhattan = rho0 * g.voxel * l1;
                double euclid = rho0 * g.voxel * sqrt((double)di * di + dj * dj + dk * dk);
                double tol = 2.0 * l1 * 0x1p-23 * manhattan;
                if (fabs(got - manhattan) > tol) ++bad_l1;
                int axis = (di == 0) + (dj == 0) + (dk == 0) >= 2;
                if (axis && fabs(got - euclid) > tol) ++bad_axis;
                if (!axis) {
                    se += (got - euclid) * (got - euclid) / (euclid * euclid);
                    ++off;
                }
            }
    CHECK(bad_axis == 0, "%d on-axis voxels differ from rho |S - X|", bad_axis);
    CHECK(bad_l1 == 0, "%d voxels differ from the scheme's closed form rho h |d|_1", bad_l1);
    printf("published Jacobi, homogeneous %d^3, point light at the centre voxel:\n", N);
    printf("  on the axes: exact to rounding; off the axes: rms relative error %.1f %% over %zu voxels\n",
           100.0 * sqrt(se / off), off);
    printf("  exact fixed point after %d Jacobi iterations\n", iters);

    /* With the renderer's tolerance (tau changes < 1e-4 for sigma_t = 1) it
     * stops no later than the exact run, and within that tolerance of it. */
    veil_opv_params tol = {.method = VEIL_OPV_JACOBI, .tolerance = 1e-4f};
    float* D2 = malloc(nv * sizeof(float));
    int iters2 = 0;
    veil_opv_cpu(&g, rho, &L, 1, &tol, D2, &iters2, &err);
    double worst = 0.0;
    for (size_t v = 0; v < nv; ++v) worst = fmax(worst, fabs(D2[v] - D[v]));
    printf("  with tolerance 1e-4: %d iterations, largest difference from the fixed point %.3g\n", iters2, worst);
    CHECK(iters2 <= iters, "tolerance run took more iterations (%d > %d)", iters2, iters);
    /* From D = 0, a voxel at |d|_1 = m holds its final value from step m + 1
     * on and grows by exactly h*rho (0.06 here, > tol) at every step before,
     * so no checked step can pass the tolerance before all voxels are final:
     * the tolerance run must equal the exact one. */
    CHECK(worst == 0.0, "tolerance run is %g from the fixed point", worst);
    free(D2);
    free(rho);
    free(D);
    return check_finish();
}
