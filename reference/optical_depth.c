#include "optical_depth.h"

#include <math.h>

/* 3-point Gauss-Legendre on [-1, 1]: nodes 0, +-sqrt(3/5), weights 8/9, 5/9
 * (exact for polynomials of degree <= 5). */
#define GL3_NODE 0.774596669241483377036
#define GL3_W_OUTER (5.0 / 9.0)
#define GL3_W_CENTER (8.0 / 9.0)

/* The midpoint rule refuses more steps than this along one path. */
#define MIDPOINT_MAX_STEPS 1099511627776.0 /* 2^40 */

/* Neumaier's compensated sum: s + c carries the running total. */
typedef struct ksum {
    double s, c;
} ksum;

static void ksum_add(ksum* k, double v)
{
    double t = k->s + v;
    if (fabs(k->s) >= fabs(v))
        k->c += (k->s - t) + v;
    else
        k->c += (v - t) + k->s;
    k->s = t;
}

static double ksum_value(const ksum* k) { return k->s + k->c; }

double veil_ev_sample(const veil_grid* g, const float* rho, const double x[3])
{
    const double h = (double)g->voxel;
    int i0[3], i1[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
        const double lo = (double)g->origin[a];
        const int n = g->dims[a];
        /* the medium spans the voxel centres: [lo + h/2, lo + (n - 1/2) h] */
        if (!(x[a] >= lo + 0.5 * h && x[a] <= lo + ((double)n - 0.5) * h)) return 0.0; /* also rejects NaN */
        double u = (x[a] - lo) / h - 0.5;
        if (u < 0.0) u = 0.0;
        if (u > (double)(n - 1)) u = (double)(n - 1);
        if (n == 1) {
            i0[a] = i1[a] = 0;
            f[a] = 0.0;
            continue;
        }
        int i = (int)floor(u);
        if (i > n - 2) i = n - 2;
        i0[a] = i;
        i1[a] = i + 1;
        f[a] = u - (double)i;
    }
    const size_t nx = (size_t)g->dims[0], ny = (size_t)g->dims[1];
#define V(i, j, k) ((double)rho[((size_t)(k) * ny + (size_t)(j)) * nx + (size_t)(i)])
    double c00 = V(i0[0], i0[1], i0[2]) + f[0] * (V(i1[0], i0[1], i0[2]) - V(i0[0], i0[1], i0[2]));
    double c10 = V(i0[0], i1[1], i0[2]) + f[0] * (V(i1[0], i1[1], i0[2]) - V(i0[0], i1[1], i0[2]));
    double c01 = V(i0[0], i0[1], i1[2]) + f[0] * (V(i1[0], i0[1], i1[2]) - V(i0[0], i0[1], i1[2]));
    double c11 = V(i0[0], i1[1], i1[2]) + f[0] * (V(i1[0], i1[1], i1[2]) - V(i0[0], i1[1], i1[2]));
#undef V
    double c0 = c00 + f[1] * (c10 - c00);
    double c1 = c01 + f[1] * (c11 - c01);
    return c0 + f[2] * (c1 - c0);
}

/* Clips the parametric line p(t) = x + t d, t in [*t0, *t1], to the closed
 * box (slab test). Returns 0 when nothing of it is inside. */
static int clip_to_box(const veil_grid* g, const double x[3], const double d[3], double* t0,
                       double* t1)
{
    const double h = (double)g->voxel;
    for (int a = 0; a < 3; ++a) {
        const double lo = (double)g->origin[a] + 0.5 * h;
        const double hi = (double)g->origin[a] + ((double)g->dims[a] - 0.5) * h;
        if (d[a] == 0.0) {
            if (!(x[a] >= lo && x[a] <= hi)) return 0;
            continue;
        }
        double ta = (lo - x[a]) / d[a], tb = (hi - x[a]) / d[a];
        if (ta > tb) {
            double s = ta;
            ta = tb;
            tb = s;
        }
        if (ta > *t0) *t0 = ta;
        if (tb < *t1) *t1 = tb;
    }
    return *t0 < *t1;
}

/* Integral of the density along p(t) = x + t d over [ta, tb], where the
 * field is one cubic in t: 3-point Gauss-Legendre, times |d| for arc length. */
static double gl3_piece(const veil_grid* g, const float* rho, const double x[3], const double d[3],
                        double ta, double tb)
{
    const double mid = 0.5 * (ta + tb), half = 0.5 * (tb - ta);
    const double tn[3] = {mid - half * GL3_NODE, mid, mid + half * GL3_NODE};
    const double wn[3] = {GL3_W_OUTER, GL3_W_CENTER, GL3_W_OUTER};
    double s = 0.0;
    for (int q = 0; q < 3; ++q) {
        double p[3] = {x[0] + tn[q] * d[0], x[1] + tn[q] * d[1], x[2] + tn[q] * d[2]};
        s += wn[q] * veil_ev_sample(g, rho, p);
    }
    return s * half;
}

/* Exact integral along x + t d, t in [t0, t1] (already inside the box):
 * walks the voxel-centre plane crossings of the three axes in order (a merge
 * of three monotone sequences, nothing allocated) and integrates each piece
 * between consecutive crossings exactly. */
static double integrate_exact(const veil_grid* g, const float* rho, const double x[3],
                              const double d[3], double t0, double t1)
{
    const double h = (double)g->voxel;
    double u0[3], du[3], next[3];
    int k[3], step[3];
    for (int a = 0; a < 3; ++a) {
        const int n = g->dims[a];
        u0[a] = ((x[a] - (double)g->origin[a]) / h) - 0.5; /* u(t) = u0 + t du */
        du[a] = d[a] / h;
        next[a] = INFINITY;
        step[a] = 0;
        k[a] = 0;
        if (du[a] == 0.0) continue;
        const double us = u0[a] + t0 * du[a];
        if (du[a] > 0.0) {
            double kk = floor(us) + 1.0; /* first centre plane strictly ahead */
            if (kk < 0.0) kk = 0.0;
            if (kk > (double)(n - 1)) continue;
            k[a] = (int)kk;
            step[a] = 1;
        } else {
            double kk = ceil(us) - 1.0;
            if (kk > (double)(n - 1)) kk = (double)(n - 1);
            if (kk < 0.0) continue;
            k[a] = (int)kk;
            step[a] = -1;
        }
        next[a] = ((double)k[a] - u0[a]) / du[a];
    }
    const double speed = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    ksum sum = {0.0, 0.0};
    double t = t0;
    for (;;) {
        double tn = t1;
        for (int a = 0; a < 3; ++a)
            if (next[a] < tn) tn = next[a];
        if (tn > t) ksum_add(&sum, gl3_piece(g, rho, x, d, t, tn));
        if (tn >= t1) break;
        if (tn > t) t = tn;
        for (int a = 0; a < 3; ++a) {
            if (next[a] > tn) continue;
            k[a] += step[a];
            if (k[a] < 0 || k[a] > g->dims[a] - 1)
                next[a] = INFINITY;
            else
                next[a] = ((double)k[a] - u0[a]) / du[a];
        }
    }
    return ksum_value(&sum) * speed;
}

static double integrate_midpoint(const veil_grid* g, const float* rho, const double x[3],
                                 const double d[3], double t0, double t1, double steps_per_voxel)
{
    const double speed = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    const double len = (t1 - t0) * speed;
    double nd = ceil(steps_per_voxel * len / (double)g->voxel);
    if (!(nd >= 1.0)) nd = 1.0;
    if (nd > MIDPOINT_MAX_STEPS) return NAN;
    const size_t n = (size_t)nd;
    const double ht = (t1 - t0) / (double)n;
    ksum sum = {0.0, 0.0};
    for (size_t i = 0; i < n; ++i) {
        double t = t0 + ((double)i + 0.5) * ht;
        double p[3] = {x[0] + t * d[0], x[1] + t * d[1], x[2] + t * d[2]};
        ksum_add(&sum, veil_ev_sample(g, rho, p));
    }
    return ksum_value(&sum) * ht * speed;
}

/* The path for a light as x + t d, t in [0, *tmax]; returns 0 if invalid. */
static int light_path(const veil_light* light, const double x[3], double d[3], double* tmax)
{
    switch (light->type) {
    case VEIL_LIGHT_POINT:
    case VEIL_LIGHT_SPOT:
        for (int a = 0; a < 3; ++a) d[a] = (double)light->position[a] - x[a];
        *tmax = 1.0;
        return 1;
    case VEIL_LIGHT_DIRECTIONAL: {
        double n2 = 0.0;
        for (int a = 0; a < 3; ++a) n2 += (double)light->direction[a] * (double)light->direction[a];
        if (!(n2 > 0.0) || !isfinite(n2)) return 0;
        const double inv = 1.0 / sqrt(n2);
        for (int a = 0; a < 3; ++a) d[a] = -(double)light->direction[a] * inv;
        *tmax = INFINITY;
        return 1;
    }
    default:
        return 0;
    }
}

double veil_ref_segment_optical_depth(const veil_grid* g, const float* rho, const double a[3],
                                      const double b[3])
{
    const double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double t0 = 0.0, t1 = 1.0;
    if (!clip_to_box(g, a, d, &t0, &t1)) return 0.0;
    return integrate_exact(g, rho, a, d, t0, t1);
}

double veil_ref_optical_depth(const veil_grid* g, const float* rho, const veil_light* light,
                              const double x[3], double steps_per_voxel)
{
    (void)steps_per_voxel;
    double d[3], t0 = 0.0, t1;
    if (!light_path(light, x, d, &t1)) return NAN;
    if (!clip_to_box(g, x, d, &t0, &t1)) return 0.0;
    return integrate_exact(g, rho, x, d, t0, t1);
}

double veil_ref_optical_depth_midpoint(const veil_grid* g, const float* rho, const veil_light* light,
                                       const double x[3], double steps_per_voxel)
{
    double d[3], t0 = 0.0, t1;
    if (!(steps_per_voxel > 0.0) || !light_path(light, x, d, &t1)) return NAN;
    if (!clip_to_box(g, x, d, &t0, &t1)) return 0.0;
    return integrate_midpoint(g, rho, x, d, t0, t1, steps_per_voxel);
}
