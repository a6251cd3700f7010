/* The C versions of the optical-depth methods: the per-voxel updates come
 * from opv_schemes.glsl.h (the shaders' own code), the order from
 * opv_plan.c (the GPU's dispatch order). */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "opv.h"
#include "opv_plan.h"

typedef struct veil__opv_ctx {
    const float* rho;
    const float* din;
    int dims[3];
} veil__opv_ctx;

#define VEIL_CTX_PARAM const veil__opv_ctx *ctx,
#define VEIL_CTX_ARG ctx,
#define VEIL_DIMS(a) (ctx->dims[(a)])
#define VEIL__IDX(i, j, k) (((size_t)(k) * (size_t)ctx->dims[1] + (size_t)(j)) * (size_t)ctx->dims[0] + (size_t)(i))
#define VEIL_RHO(i, j, k) (ctx->rho[VEIL__IDX(i, j, k)])
#define VEIL_DIN(i, j, k) (ctx->din[VEIL__IDX(i, j, k)])
#include "opv_schemes.glsl.h"

static size_t vox(const veil_grid* g, const int x[3])
{
    return ((size_t)x[2] * (size_t)g->dims[1] + (size_t)x[1]) * (size_t)g->dims[0] + (size_t)x[0];
}

static const char* const method_names[VEIL_OPV_METHOD_COUNT] = {"default", "jacobi", "jacobi-corrected",
                                                                "sweep", "semi-lagrangian", "light-space"};

const char* veil_opv_method_name(veil_opv_method m)
{
    return (unsigned)m < VEIL_OPV_METHOD_COUNT ? method_names[m] : "unknown";
}

int veil_opv_method_parse(const char* name, veil_opv_method* out)
{
    for (int m = 0; m < VEIL_OPV_METHOD_COUNT; ++m)
        if (strcmp(name, method_names[m]) == 0) {
            *out = (veil_opv_method)m;
            return 1;
        }
    return 0;
}

int veil_opv_exact_iterations(const veil_grid* g)
{
    return g->dims[0] + g->dims[1] + g->dims[2] + 1;
}

static void jacobi(const veil_grid* g, const float* rho, const veil_index_light* L, const veil_opv_params* p,
                   float* cur, float* tmp, int* iterations)
{
    veil__opv_ctx ctx = {.rho = rho, .din = cur, .dims = {g->dims[0], g->dims[1], g->dims[2]}};
    size_t nv = veil_grid_voxels(g);
    int corrected = p->method == VEIL_OPV_JACOBI_CORRECTED;
    int max_it = p->max_iterations > 0 ? p->max_iterations : veil_opv_exact_iterations(g);
    memset(cur, 0, nv * sizeof(float));
    int it = 0;
    while (it < max_it) {
        int check = (it % VEIL_JACOBI_CHECK_EVERY) == VEIL_JACOBI_CHECK_EVERY - 1;
        float change = 0.0f;
        size_t v = 0;
        for (int k = 0; k < g->dims[2]; ++k)
            for (int j = 0; j < g->dims[1]; ++j)
                for (int i = 0; i < g->dims[0]; ++i, ++v) {
                    tmp[v] = veil_gather_cell(&ctx, i, j, k, L->type, L->v[0], L->v[1], L->v[2], L->c[0], L->c[1],
                                              L->c[2], g->voxel, corrected);
                    change = fmaxf(change, fabsf(tmp[v] - cur[v]));
                }
        memcpy(cur, tmp, nv * sizeof(float));
        ++it;
        if (check && change <= p->tolerance) break;
    }
    *iterations = it;
}

static void gather_sweep(const veil_grid* g, const float* rho, const veil_index_light* L, float* out, int* passes)
{
    veil__opv_ctx ctx = {.rho = rho, .din = out, .dims = {g->dims[0], g->dims[1], g->dims[2]}};
    veil__gather_plan plan;
    veil__gather_plan_make(g, L, &plan);
    int s = plan.solve, u = s == 0 ? 1 : 0, w = s == 2 ? 1 : 2;
    for (int m = plan.first; m <= plan.last; ++m) {
        for (int b = 0; b < g->dims[w]; ++b)
            for (int a = 0; a < g->dims[u]; ++a) {
                int x[3], sol[2];
                x[u] = a;
                x[w] = b;
                x[s] = 0;
                int n = veil__gather_solve(g, L, &plan, m, x, sol);
                for (int q = 0; q < n; ++q) {
                    x[s] = sol[q];
                    out[vox(g, x)] = veil_gather_cell(&ctx, x[0], x[1], x[2], L->type, L->v[0], L->v[1],
                                                               L->v[2], L->c[0], L->c[1], L->c[2], g->voxel, 1);
                }
            }
    }
    *passes = plan.last - plan.first + 1;
}

/* Runs f over every voxel of a box (x fastest). */
#define FOR_BOX(b, x)                                                                \
    for (x[2] = (b).lo[2]; x[2] < (b).lo[2] + (b).n[2]; ++x[2])                      \
        for (x[1] = (b).lo[1]; x[1] < (b).lo[1] + (b).n[1]; ++x[1])                  \
            for (x[0] = (b).lo[0]; x[0] < (b).lo[0] + (b).n[0]; ++x[0])

static float sl_voxel(const veil__opv_ctx* ctx, const veil_index_light* L, const int x[3], float h, int k,
                      float exit_steps)
{
    int a = veil_sl_axis(x[0], x[1], x[2], L->type, L->v[0], L->v[1], L->v[2], L->c[0], L->c[1], L->c[2]);
    return veil_sl_cell(ctx, x[0], x[1], x[2], a, L->type, L->v[0], L->v[1], L->v[2], h, k, exit_steps);
}

static void semi_lagrangian(const veil_grid* g, const float* rho, const veil_index_light* L, int chars, float exit_steps,
                            float* out, int* passes)
{
    veil__opv_ctx ctx = {.rho = rho, .din = out, .dims = {g->dims[0], g->dims[1], g->dims[2]}};
    int x[3], n = 0;
    veil__box box;
    if (L->type == VEIL_LIGHT_DIRECTIONAL) {
        int a = veil__sl_sun_axis(L);
        for (int k = 0; k < g->dims[a]; ++k, ++n) {
            veil__sl_sun_slice(g, L, k, &box);
            FOR_BOX(box, x) out[vox(g, x)] = sl_voxel(&ctx, L, x, g->voxel, chars, exit_steps);
        }
        *passes = n;
        return;
    }
    if (veil__sl_near_box(g, L, &box)) {
        FOR_BOX(box, x) out[vox(g, x)] = veil_near_cell(&ctx, x[0], x[1], x[2], L->v[0], L->v[1], L->v[2], g->voxel);
        ++n;
    }
    int s0, s1;
    veil__sl_shell_range(g, L, &s0, &s1);
    for (int s = s0; s <= s1; ++s)
        for (int k = 1; k <= 3; ++k) {
            veil__box boxes[VEIL_SL_MAX_BOXES];
            int nb = veil__sl_boxes(g, L, s, k, boxes);
            for (int b = 0; b < nb; ++b) FOR_BOX(boxes[b], x) out[vox(g, x)] = sl_voxel(&ctx, L, x, g->voxel, chars, exit_steps);
            n += nb > 0;
        }
    *passes = n;
}

veil_result veil_opv_cpu(const veil_grid* g, const float* rho, const veil_index_light* lights, int n_lights,
                         const veil_opv_params* params, float* out, int* iterations, veil_error* err)
{
    size_t nv = veil_grid_voxels(g);
    float* tmp = NULL;
    veil_opv_params resolved = *params;
    resolved.method = veil_opv_method_resolve(params->method);
    if (resolved.method == VEIL_OPV_LIGHT_SPACE) resolved.method = VEIL_OPV_SEMI_LAGRANGIAN; /* on the grid */
    params = &resolved;
    if (params->method == VEIL_OPV_JACOBI || params->method == VEIL_OPV_JACOBI_CORRECTED) {
        tmp = malloc(nv * sizeof(float));
        if (!tmp) return veil_fail(err, VEIL_ERR_OOM, "out of memory for a %zu-voxel optical-depth volume", nv);
    } else if ((unsigned)params->method >= VEIL_OPV_METHOD_COUNT) {
        return veil_fail(err, VEIL_ERR_INVALID, "unknown propagation method %d", (int)params->method);
    }
    int most = 0;
    for (int l = 0; l < n_lights; ++l) {
        float* cur = out + (size_t)l * nv;
        int it = 0;
        if (lights[l].elsewhere && params->method != VEIL_OPV_JACOBI && params->method != VEIL_OPV_JACOBI_CORRECTED) {
            memset(cur, 0, nv * sizeof(float));
            continue;
        }
        switch (params->method) {
        case VEIL_OPV_JACOBI:
        case VEIL_OPV_JACOBI_CORRECTED: jacobi(g, rho, &lights[l], params, cur, tmp, &it); break;
        case VEIL_OPV_SWEEP:
            memset(cur, 0, nv * sizeof(float));
            gather_sweep(g, rho, &lights[l], cur, &it);
            break;
        default:
            memset(cur, 0, nv * sizeof(float));
            semi_lagrangian(g, rho, &lights[l], veil_opv_characteristic(params), veil_opv_exit_steps(params), cur,
                            &it);
            break;
        }
        if (it > most) most = it;
    }
    free(tmp);
    if (iterations) *iterations = most;
    return VEIL_OK;
}
