/* veil benchmarks — the deterministic media the benchmarks measure on. */
#include "media.h"

#include "io/vdb.h"
#include "volume/vdb_volume.h"

#include <math.h>
#include <stdlib.h>

/* ---- value-noise fBm for the smoke stand-in ------------------------------- */

static uint32_t mix32(uint32_t h)
{
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h;
}

/* Value in [0, 1) at an integer lattice point. */
static double lattice(int x, int y, int z, uint32_t seed)
{
    uint32_t h = mix32(seed + 0x68e31da4u);
    h = mix32(h + (uint32_t)x * 0x1b873593u);
    h = mix32(h + (uint32_t)y * 0x19660d1du);
    h = mix32(h + (uint32_t)z * 0x5bd1e995u);
    return (double)(h >> 8) * 0x1p-24;
}

static double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

/* Trilinear interpolation of the lattice values with quintic weights. */
static double value_noise(double x, double y, double z, uint32_t seed)
{
    double fx = floor(x), fy = floor(y), fz = floor(z);
    int ix = (int)fx, iy = (int)fy, iz = (int)fz;
    double u = fade(x - fx), v = fade(y - fy), w = fade(z - fz);
    double c[2][2];
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j) {
            double a = lattice(ix, iy + j, iz + k, seed), b = lattice(ix + 1, iy + j, iz + k, seed);
            c[k][j] = a + (b - a) * u;
        }
    double c0 = c[0][0] + (c[0][1] - c[0][0]) * v, c1 = c[1][0] + (c[1][1] - c[1][0]) * v;
    return c0 + (c1 - c0) * w;
}

#define FBM_OCTAVES 5

/* Five octaves, lacunarity 2, gain 0.5, normalised to [0, 1). */
static double fbm(double x, double y, double z, uint32_t seed)
{
    double sum = 0.0, norm = 0.0, amp = 1.0, f = 1.0;
    for (int o = 0; o < FBM_OCTAVES; ++o) {
        sum += amp * value_noise(x * f, y * f, z * f, seed + 977u * (uint32_t)o);
        norm += amp;
        amp *= 0.5;
        f *= 2.0;
    }
    return sum / norm;
}

static double clamp01(double v) { return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v); }

/* Smoke plume stand-in (world metres, y up, box [-1, 1]^3). A column rises
 * from y = -0.92 to y = 0.83 (t = 0..1 along it), drifting toward +x and
 * swaying in z, radius 0.10 + 0.42 t. fBm n (scrolled with height) makes
 * the edge ragged (radius * (0.7 + 0.6 n)) and carves empty pockets
 * (n < 0.42); the edge is sharp (full density 1/6 of the radius inside).
 * Density 3 at the source thinning to 1.35 at the top, faded over the
 * last 15 % of the height; 0 outside the column. */
static double smoke_density(double x, double y, double z)
{
    double t = (y + 0.92) / 1.75;
    if (t <= 0.0 || t >= 1.0) return 0.0;
    double cx = -0.25 + 0.45 * t * t, cz = 0.12 * sin(4.0 * t);
    double r = 0.10 + 0.42 * t;
    double n = fbm(2.3 * x + 0.7, 2.3 * y - 1.9 * t, 2.3 * z + 0.3, 20240611u);
    double dx = x - cx, dz = z - cz, d = sqrt(dx * dx + dz * dz);
    double edge = clamp01(6.0 * (1.0 - d / (r * (0.7 + 0.6 * n))));
    double puff = clamp01((n - 0.42) / 0.2);
    double top = clamp01((1.0 - t) / 0.15), bottom = clamp01(t / 0.03);
    return 3.0 * (1.0 - 0.55 * t) * edge * puff * top * bottom;
}

veil_grid bench_grid(int n)
{
    veil_grid g = {.dims = {n, n, n}, .origin = {BOX_LO, BOX_LO, BOX_LO}, .voxel = BOX_WIDTH / (float)n};
    return g;
}

/* The density of `medium` on g (veil_grid_voxels floats, x fastest); NULL on
 * failure with the reason in err. */
float* make_medium(int medium, const veil_grid* g, veil_error* err)
{
    size_t nv = veil_grid_voxels(g);
    float* rho = calloc(nv, sizeof(float));
    if (!rho) {
        veil_fail(err, VEIL_ERR_OOM, "out of memory for a %zu-voxel medium", nv);
        return NULL;
    }
    if (medium == MEDIUM_HOMOGENEOUS) {
        for (size_t v = 0; v < nv; ++v) rho[v] = 1.0f;
    } else if (medium == MEDIUM_RBF_FOG) {
        enum { COUNT = 400 };
        veil_rbf_random_desc d = {.count = COUNT, .seed = 7,
                                  .bounds = {{-0.8f, -0.8f, -0.8f}, {0.8f, 0.8f, 0.8f}},
                                  .radius = {0.1f, 0.35f}, .amplitude = {0.3f, 1.2f}};
        veil_particle p[COUNT];
        veil_rbf_random_generate(&d, p);
        veil_rbf_bins bins;
        if (veil_rbf_bin(g, p, COUNT, &bins, err) != VEIL_OK) {
            free(rho);
            return NULL;
        }
        veil_inject_rbf_cpu(g, &bins, rho);
        veil_rbf_bins_free(&bins);
    } else if (medium == MEDIUM_VDB_SMOKE) {
        const char* path = getenv("VEIL_BENCH_VDB") ? getenv("VEIL_BENCH_VDB") : VEIL_BENCH_DEFAULT_VDB;
        veil_vdb* v = NULL;
        float lo[3], hi[3];
        veil_result r = veil_vdb_open(path, NULL, 0, &v, NULL, 0, err);
        if (r == VEIL_OK) r = veil_vdb_world_support(v, lo, hi, err);
        if (r == VEIL_OK) {
            /* the cube enclosing the grid, with the bench grid's dims */
            float side = fmaxf(hi[0] - lo[0], fmaxf(hi[1] - lo[1], hi[2] - lo[2]));
            veil_grid cube = *g;
            cube.voxel = side / (float)(g->dims[0] - 1);
            for (int a = 0; a < 3; ++a) cube.origin[a] = 0.5f * (lo[a] + hi[a]) - 0.5f * (float)g->dims[a] * cube.voxel;
            r = veil_vdb_to_grid(v, 1.0f, &cube, rho, err);
        }
        veil_vdb_close(v);
        if (r != VEIL_OK) {
            free(rho);
            return NULL;
        }
    } else {
        for (int k = 0; k < g->dims[2]; ++k)
            for (int j = 0; j < g->dims[1]; ++j)
                for (int i = 0; i < g->dims[0]; ++i) {
                    float x[3];
                    veil_grid_center(g, i, j, k, x);
                    rho[((size_t)k * g->dims[1] + j) * g->dims[0] + i] = (float)smoke_density(x[0], x[1], x[2]);
                }
    }
    return rho;
}

