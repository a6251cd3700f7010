#include "volume.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

veil_result veil_grid_fit(const float lo[3], const float hi[3], int max_resolution,
                          veil_grid* out, veil_error* err)
{
    if (max_resolution < 2)
        return veil_fail(err, VEIL_ERR_INVALID, "max_resolution must be >= 2, got %d", max_resolution);
    float ext[3], longest = 0.0f;
    for (int k = 0; k < 3; ++k) {
        if (!isfinite(lo[k]) || !isfinite(hi[k]) || hi[k] < lo[k])
            return veil_fail(err, VEIL_ERR_INVALID, "volume bounds are not a finite box");
        ext[k] = hi[k] - lo[k];
        longest = fmaxf(longest, ext[k]);
    }
    if (!(longest > 0.0f) || !isfinite(longest))
        return veil_fail(err, VEIL_ERR_INVALID, "volume bounds have zero or infinite size");
    /* max_resolution centres span the longest side: max_resolution - 1 gaps */
    out->voxel = longest / (float)(max_resolution - 1);
    for (int k = 0; k < 3; ++k) {
        int n = (int)ceilf(ext[k] / out->voxel - 1e-4f) + 1; /* tolerate rounding up by 1e-4 voxel */
        if (n < 2) n = 2;
        if (n > max_resolution) n = max_resolution;
        out->dims[k] = n;
        float centre = 0.5f * (lo[k] + hi[k]);
        out->origin[k] = centre - 0.5f * (float)n * out->voxel;
    }
    return VEIL_OK;
}

void veil_grid_medium_box(const veil_grid* g, float lo[3], float hi[3])
{
    for (int a = 0; a < 3; ++a) {
        lo[a] = g->origin[a] + 0.5f * g->voxel;
        hi[a] = g->origin[a] + ((float)g->dims[a] - 0.5f) * g->voxel;
    }
}

size_t veil_grid_voxels(const veil_grid* g)
{
    return (size_t)g->dims[0] * (size_t)g->dims[1] * (size_t)g->dims[2];
}

void veil_grid_center(const veil_grid* g, int i, int j, int k, float out[3])
{
    const int idx[3] = {i, j, k};
    for (int a = 0; a < 3; ++a) out[a] = g->origin[a] + ((float)idx[a] + 0.5f) * g->voxel;
}

/* Voxel index range [*i0, *i1] on one axis whose centres may lie within
 * [c - r, c + r]; empty when *i0 > *i1. One voxel of slack each side: the
 * exact r^2 test in the splat decides. */
static void axis_range(const veil_grid* g, int a, float c, float r, int* i0, int* i1)
{
    double lo = floor((c - r - g->origin[a]) / g->voxel - 0.5) - 1.0;
    double hi = ceil((c + r - g->origin[a]) / g->voxel - 0.5) + 1.0;
    *i0 = lo < 0.0 ? 0 : (int)lo;
    *i1 = hi > g->dims[a] - 1 ? g->dims[a] - 1 : (int)hi;
}

static int particle_bricks(const veil_grid* g, const veil_particle* p, int b0[3], int b1[3])
{
    float rc = veil_rbf_cutoff_radius(p);
    if (!(p->amplitude > 0.0f)) return 0;
    for (int a = 0; a < 3; ++a) {
        int i0, i1;
        axis_range(g, a, p->center[a], rc, &i0, &i1);
        if (i0 > i1) return 0;
        b0[a] = i0 / VEIL_BRICK;
        b1[a] = i1 / VEIL_BRICK;
    }
    return 1;
}

veil_result veil_rbf_bin(const veil_grid* g, const veil_particle* p, size_t n,
                         veil_rbf_bins* out, veil_error* err)
{
    memset(out, 0, sizeof *out);
    size_t nb = 1;
    for (int a = 0; a < 3; ++a) {
        out->bricks[a] = (g->dims[a] + VEIL_BRICK - 1) / VEIL_BRICK;
        nb *= (size_t)out->bricks[a];
    }
    size_t packed_bytes;
    if (n > UINT32_MAX || !veil_mul_sizes(n, 8, sizeof(float), 1, &packed_bytes))
        return veil_fail(err, VEIL_ERR_LIMIT, "%zu particles is too many to bin", n);
    out->start = calloc(nb + 1, sizeof(uint32_t));
    out->packed = malloc(packed_bytes ? packed_bytes : 1);
    if (!out->start || !out->packed) goto oom;
    out->particle_count = n;

    /* pass 1: count per brick (in start[b+1]) */
    size_t total = 0;
    for (size_t i = 0; i < n; ++i) {
        int b0[3], b1[3];
        if (!particle_bricks(g, &p[i], b0, b1)) continue;
        for (int z = b0[2]; z <= b1[2]; ++z)
            for (int y = b0[1]; y <= b1[1]; ++y)
                for (int x = b0[0]; x <= b1[0]; ++x) {
                    size_t b = ((size_t)z * out->bricks[1] + y) * out->bricks[0] + x;
                    out->start[b + 1]++;
                    if (++total > VEIL_SPLAT_MAX_ENTRIES)
                        return veil_rbf_bins_free(out),
                               veil_fail(err, VEIL_ERR_LIMIT,
                                         "%zu particles' footprints cover more than %zu brick entries (the lists "
                                         "would take over 1 GiB; the splat over %.3g particle-voxel evaluations): "
                                         "fewer or smaller particles, or a lower medium.max_resolution", n,
                                         VEIL_SPLAT_MAX_ENTRIES, (double)VEIL_SPLAT_MAX_ENTRIES * 512.0);
                }
    }
    if (total * VEIL_BRICK * VEIL_BRICK * VEIL_BRICK > VEIL_SPLAT_MAX_EVALS) {
        veil_rbf_bins_free(out);
        return veil_fail(err, VEIL_ERR_LIMIT,
                         "%zu particles over %zu brick entries: the splat would evaluate %.3g Gaussians (512 a "
                         "brick entry), over the limit of %.3g (about half a minute on a CPU driver): fewer or "
                         "smaller particles, or a lower medium.max_resolution", n, total,
                         (double)total * 512.0, (double)VEIL_SPLAT_MAX_EVALS);
    }
    for (size_t b = 0; b < nb; ++b) out->start[b + 1] += out->start[b];
    out->list_len = total;
    out->list = malloc((total ? total : 1) * sizeof(uint32_t));
    uint32_t* fill = malloc((nb ? nb : 1) * sizeof(uint32_t));
    if (!out->list || !fill) {
        free(fill);
        goto oom;
    }
    memcpy(fill, out->start, nb * sizeof(uint32_t));
    /* pass 2: fill, particles in ascending order within each brick */
    for (size_t i = 0; i < n; ++i) {
        float rc = veil_rbf_cutoff_radius(&p[i]);
        float* q = out->packed + 8 * i;
        q[0] = p[i].center[0];
        q[1] = p[i].center[1];
        q[2] = p[i].center[2];
        q[3] = p[i].amplitude;
        q[4] = p[i].sharpness * p[i].sharpness;
        q[5] = rc * rc;
        q[6] = q[7] = 0.0f;
        int b0[3], b1[3];
        if (!particle_bricks(g, &p[i], b0, b1)) continue;
        for (int z = b0[2]; z <= b1[2]; ++z)
            for (int y = b0[1]; y <= b1[1]; ++y)
                for (int x = b0[0]; x <= b1[0]; ++x) {
                    size_t b = ((size_t)z * out->bricks[1] + y) * out->bricks[0] + x;
                    out->list[fill[b]++] = (uint32_t)i;
                }
    }
    free(fill);
    return VEIL_OK;
oom:
    veil_rbf_bins_free(out);
    return veil_fail(err, VEIL_ERR_OOM, "out of memory binning %zu particles", n);
}

void veil_rbf_bins_free(veil_rbf_bins* b)
{
    if (!b) return;
    free(b->start);
    free(b->list);
    free(b->packed);
    memset(b, 0, sizeof *b);
}

/* Mirrors volume/shaders/inject_rbf.comp operation for operation. */
void veil_inject_rbf_cpu(const veil_grid* g, const veil_rbf_bins* b, float* rho)
{
    for (int k = 0; k < g->dims[2]; ++k)
        for (int j = 0; j < g->dims[1]; ++j)
            for (int i = 0; i < g->dims[0]; ++i) {
                size_t brick = ((size_t)(k / VEIL_BRICK) * b->bricks[1] + j / VEIL_BRICK) * b->bricks[0] +
                               i / VEIL_BRICK;
                float x[3];
                veil_grid_center(g, i, j, k, x);
                size_t out = ((size_t)k * g->dims[1] + j) * g->dims[0] + i;
                float sum = rho[out];
                for (uint32_t e = b->start[brick]; e < b->start[brick + 1]; ++e) {
                    const float* q = b->packed + 8 * (size_t)b->list[e];
                    float dx = x[0] - q[0], dy = x[1] - q[1], dz = x[2] - q[2];
                    float r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 <= q[5]) sum += q[3] * expf(-(q[4] * r2));
                }
                rho[out] = sum;
            }
}
