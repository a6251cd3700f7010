#include "opv.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void veil_opv_light_from_world(const veil_grid* g, const veil_light* l, veil_opv_light* out)
{
    out->type = l->type;
    if (l->type == VEIL_LIGHT_POINT) {
        for (int a = 0; a < 3; ++a) out->v[a] = (l->position[a] - g->origin[a]) / g->voxel - 0.5f;
    } else {
        for (int a = 0; a < 3; ++a) out->v[a] = -l->direction[a];
    }
}

int veil_opv_exact_iterations(const veil_grid* g)
{
    return g->dims[0] + g->dims[1] + g->dims[2] + 1;
}

static size_t vidx(const veil_grid* g, int i, int j, int k)
{
    return ((size_t)k * g->dims[1] + j) * g->dims[0] + i;
}

/* One voxel's update; mirrors propagate_jacobi.comp operation for operation. */
static float gather(const veil_grid* g, const float* rho, const float* src, const veil_opv_light* L,
                    int i, int j, int k)
{
    const int x[3] = {i, j, k};
    float d[3];
    for (int a = 0; a < 3; ++a) d[a] = L->type == VEIL_LIGHT_POINT ? L->v[a] - (float)x[a] : L->v[a];
    const float lim = L->type == VEIL_LIGHT_POINT ? 0.5f : 0.0f;
    const float h = g->voxel;
    const float r = rho[vidx(g, i, j, k)];
    float wsum = 0.0f;
    for (int a = 0; a < 3; ++a)
        if (fabsf(d[a]) > lim) wsum += fabsf(d[a]);
    if (wsum == 0.0f) /* the light is inside this voxel */
        return r * (h * sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    float acc = 0.0f;
    for (int a = 0; a < 3; ++a) {
        if (!(fabsf(d[a]) > lim)) continue;
        int n[3] = {i, j, k};
        n[a] += d[a] > 0.0f ? 1 : -1;
        float term;
        if (n[a] < 0 || n[a] >= g->dims[a]) {
            term = 0.5f * h * r;
        } else {
            size_t ni = vidx(g, n[0], n[1], n[2]);
            term = src[ni] + 0.5f * h * (r + rho[ni]);
        }
        acc += (fabsf(d[a]) / wsum) * term;
    }
    return acc;
}

veil_result veil_opv_jacobi_cpu(const veil_grid* g, const float* rho, const veil_opv_light* lights,
                                int n_lights, const veil_opv_params* params, float* out,
                                int* iterations, veil_error* err)
{
    size_t nv = veil_grid_voxels(g);
    float* tmp = malloc(nv * sizeof(float));
    if (!tmp) return veil_fail(err, VEIL_ERR_OOM, "out of memory for a %zu-voxel optical-depth volume", nv);
    int max_it = params->max_iterations > 0 ? params->max_iterations : veil_opv_exact_iterations(g);
    int most = 0;
    for (int l = 0; l < n_lights; ++l) {
        float* cur = out + (size_t)l * nv;
        memset(cur, 0, nv * sizeof(float));
        int it = 0;
        while (it < max_it) {
            int check = (it % VEIL_JACOBI_CHECK_EVERY) == VEIL_JACOBI_CHECK_EVERY - 1;
            float change = 0.0f;
            for (int k = 0; k < g->dims[2]; ++k)
                for (int j = 0; j < g->dims[1]; ++j)
                    for (int i = 0; i < g->dims[0]; ++i) {
                        size_t v = vidx(g, i, j, k);
                        tmp[v] = gather(g, rho, cur, &lights[l], i, j, k);
                        change = fmaxf(change, fabsf(tmp[v] - cur[v]));
                    }
            memcpy(cur, tmp, nv * sizeof(float));
            ++it;
            if (check && change <= params->tolerance) break;
        }
        if (it > most) most = it;
    }
    free(tmp);
    if (iterations) *iterations = most;
    return VEIL_OK;
}
