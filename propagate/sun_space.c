#include "sun_space.h"

#include <math.h>
#include <string.h>

static void normalise(double v[3])
{
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int a = 0; a < 3; ++a) v[a] /= n;
}

static void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Unit axes: e[2] the travel direction, e[0] and e[1] across it. */
static void frame(const float travel[3], double e[3][3])
{
    for (int a = 0; a < 3; ++a) e[2][a] = travel[a];
    normalise(e[2]);
    int least = 0; /* the coordinate axis least aligned with the light: far from parallel to it */
    for (int a = 1; a < 3; ++a)
        if (fabs(e[2][a]) < fabs(e[2][least])) least = a;
    double ax[3] = {0, 0, 0};
    ax[least] = 1.0;
    cross(e[2], ax, e[0]);
    normalise(e[0]);
    cross(e[2], e[0], e[1]);
}

veil_result veil_sun_space_make(const veil_grid* g, const float travel[3], float across, float along, int panels,
                                int max_axis, size_t max_nodes, veil_sun_space* out, veil_error* err)
{
    memset(out, 0, sizeof *out);
    double len = sqrt((double)travel[0] * travel[0] + (double)travel[1] * travel[1] + (double)travel[2] * travel[2]);
    if (!(len > 0.0) || !isfinite(len) || !(across > 0.0f) || !(along > 0.0f) || !isfinite(across) ||
        !isfinite(along))
        return veil_fail(err, VEIL_ERR_INVALID, "light-space grid: direction (%g, %g, %g), spacing %g, %g voxels",
                         travel[0], travel[1], travel[2], across, along);
    double e[3][3];
    frame(travel, e);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int corner = 0; corner < 8; ++corner) {
        double p[3];
        for (int a = 0; a < 3; ++a) p[a] = (corner >> a) & 1 ? g->dims[a] - 1 : 0;
        for (int r = 0; r < 3; ++r) {
            double d = e[r][0] * p[0] + e[r][1] * p[1] + e[r][2] * p[2];
            lo[r] = d < lo[r] ? d : lo[r];
            hi[r] = d > hi[r] ? d : hi[r];
        }
    }
    const double h[3] = {across, across, along};
    size_t total = 1;
    for (int r = 0; r < 3; ++r) {
        /* nodes 0 .. n-1 span at least [lo, hi]: floor(range / h) + 1 steps */
        double n = floor((hi[r] - lo[r]) / h[r]) + 2.0;
        if (n > max_axis)
            return veil_fail(err, VEIL_ERR_LIMIT, "light-space grid: %.0f nodes on axis %d (most %d)", n, r, max_axis);
        out->nodes[r] = (int)n;
        total *= (size_t)n;
        if (total > max_nodes)
            return veil_fail(err, VEIL_ERR_LIMIT, "light-space grid: more than %zu nodes", max_nodes);
    }
    for (int a = 0; a < 3; ++a) {
        out->origin[a] = (float)(lo[0] * e[0][a] + lo[1] * e[1][a] + lo[2] * e[2][a]);
        for (int r = 0; r < 3; ++r) out->axis[r][a] = (float)(h[r] * e[r][a]);
    }
    int least = (int)ceil(along);
    out->panels = panels > least ? panels : least;
    return VEIL_OK;
}

size_t veil_sun_space_nodes(const veil_sun_space* s)
{
    return (size_t)s->nodes[0] * (size_t)s->nodes[1] * (size_t)s->nodes[2];
}

void veil_sun_space_to_texture(const veil_grid* g, const veil_sun_space* s, float m[3][4])
{
    /* index u = (x - grid origin) / voxel - 1/2; node coordinate r = (u - origin) . axis_r / |axis_r|^2;
     * texture coordinate (r + 1/2) / nodes_r */
    for (int r = 0; r < 3; ++r) {
        double len2 = 0.0;
        for (int a = 0; a < 3; ++a) len2 += (double)s->axis[r][a] * s->axis[r][a];
        double k = 1.0 / (len2 * s->nodes[r]), c = 0.0;
        for (int a = 0; a < 3; ++a) {
            m[r][a] = (float)(k * s->axis[r][a] / g->voxel);
            c -= k * s->axis[r][a] * ((double)g->origin[a] / g->voxel + 0.5 + s->origin[a]);
        }
        m[r][3] = (float)(c + 0.5 / s->nodes[r]);
    }
}

/* Trilinear density at index coordinate p, clamped into the box (as a
 * clamp-to-edge fetch of a texture is). */
static float density_at(const veil_grid* g, const float* rho, const float p[3])
{
    int i0[3], i1[3];
    float f[3];
    for (int a = 0; a < 3; ++a) {
        float q = fminf(fmaxf(p[a], 0.0f), (float)(g->dims[a] - 1));
        float fl = floorf(q);
        i0[a] = (int)fl;
        i1[a] = i0[a] + 1 < g->dims[a] ? i0[a] + 1 : i0[a];
        f[a] = q - fl;
    }
    const size_t nx = (size_t)g->dims[0], nxy = nx * (size_t)g->dims[1];
#define V(i, j, k) rho[(size_t)(k) * nxy + (size_t)(j) * nx + (size_t)(i)]
    float c00 = V(i0[0], i0[1], i0[2]) + f[0] * (V(i1[0], i0[1], i0[2]) - V(i0[0], i0[1], i0[2]));
    float c10 = V(i0[0], i1[1], i0[2]) + f[0] * (V(i1[0], i1[1], i0[2]) - V(i0[0], i1[1], i0[2]));
    float c01 = V(i0[0], i0[1], i1[2]) + f[0] * (V(i1[0], i0[1], i1[2]) - V(i0[0], i0[1], i1[2]));
    float c11 = V(i0[0], i1[1], i1[2]) + f[0] * (V(i1[0], i1[1], i1[2]) - V(i0[0], i1[1], i1[2]));
#undef V
    float c0 = c00 + f[1] * (c10 - c00), c1 = c01 + f[1] * (c11 - c01);
    return c0 + f[2] * (c1 - c0);
}

void veil_sun_space_cpu(const veil_grid* g, const float* rho, const veil_sun_space* s, float* out)
{
    const float* ax = s->axis[2];
    float step = sqrtf(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]) * g->voxel; /* m per node step */
    for (int j = 0; j < s->nodes[1]; ++j)
        for (int i = 0; i < s->nodes[0]; ++i) {
            float p0[3];
            for (int a = 0; a < 3; ++a) p0[a] = s->origin[a] + (float)i * s->axis[0][a] + (float)j * s->axis[1][a];
            /* the column's span in the box, in node steps: [enter, leave] */
            float enter = 0.0f, leave = (float)(s->nodes[2] - 1);
            for (int a = 0; a < 3; ++a) {
                float hi = (float)(g->dims[a] - 1);
                if (ax[a] == 0.0f) {
                    if (p0[a] < 0.0f || p0[a] > hi) leave = -1.0f;
                    continue;
                }
                float t0 = (0.0f - p0[a]) / ax[a], t1 = (hi - p0[a]) / ax[a];
                enter = fmaxf(enter, fminf(t0, t1));
                leave = fminf(leave, fmaxf(t0, t1));
            }
            float D = 0.0f, s_last = -1.0f, f_last = 0.0f;
            size_t at = (size_t)j * (size_t)s->nodes[0] + (size_t)i;
            const size_t plane = (size_t)s->nodes[0] * (size_t)s->nodes[1];
            out[at] = 0.0f;
            for (int k = 1; k < s->nodes[2]; ++k) {
                float lo = fmaxf((float)(k - 1), enter), hi = fminf((float)k, leave);
                if (lo < hi) {
                    float w = (hi - lo) / (float)s->panels, sum = 0.0f;
                    for (int q = 0; q < s->panels; ++q) {
                        float a = lo + (float)q * w, b = q + 1 == s->panels ? hi : lo + (float)(q + 1) * w;
                        float m = 0.5f * (a + b), pa[3], pm[3], pb[3];
                        for (int c = 0; c < 3; ++c) {
                            pa[c] = p0[c] + a * ax[c];
                            pm[c] = p0[c] + m * ax[c];
                            pb[c] = p0[c] + b * ax[c];
                        }
                        float fa = a == s_last ? f_last : density_at(g, rho, pa);
                        float fm = density_at(g, rho, pm), fb = density_at(g, rho, pb);
                        sum += (b - a) * (fa + 4.0f * fm + fb);
                        s_last = b;
                        f_last = fb;
                    }
                    D += sum * (step / 6.0f);
                }
                out[(size_t)k * plane + at] = D;
            }
        }
}
