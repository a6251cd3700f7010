/* veil tests — the single-scattering airlight of an isotropic point light
 * in a homogeneous medium (Sun, Ramamoorthi, Narasimhan, Nayar 2005), in
 * double precision, as the closed form both renderers are checked against. */
#ifndef VEIL_TEST_AIRLIGHT_H
#define VEIL_TEST_AIRLIGHT_H

#include <math.h>

#include "core/shared.glsl.h"

/* F(u, v) = int_0^v exp(-u tan x) dx, v < pi/2: composite Gauss-Legendre
 * (5 points, 2000 panels; the integrand is smooth and in (0, 1], so this is
 * exact to ~1e-15 here). */
static inline double sun_F(double u, double v)
{
    static const double x5[5] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640, 0.9061798459386640};
    static const double w5[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665, 0.2369268850561891,
                                 0.2369268850561891};
    const int panels = 2000;
    double h = v / panels, sum = 0.0;
    for (int p = 0; p < panels; ++p)
        for (int k = 0; k < 5; ++k) sum += w5[k] * exp(-u * tan(h * (p + 0.5 + 0.5 * x5[k]))) * 0.5 * h;
    return sum;
}

/* Single-scattered radiance at the viewer along a ray of length T from a
 * point light of intensity I at distance D, at angle gam to the ray, in a
 * medium (sigma_s, sigma_t), isotropic phase 1/(4 pi):
 *   L = sigma_s I / (4 pi) int_0^T e^{-sigma_t (t + d(t))} / d(t)^2 dt,
 *   d^2 = D^2 + t^2 - 2 D t cos gam.
 * With h = D sin gam, t = D cos gam + h tan th, d = h / cos th and
 * t + d = D cos gam + h tan(pi/4 + th/2), the substitution
 * xi = pi/4 + th/2 gives
 *   L = sigma_s I e^{-sigma_t D cos gam} / (2 pi h) [F(sigma_t h, xi_1) - F(sigma_t h, gam/2)],
 *   xi_1 = pi/4 + atan((T - D cos gam) / h) / 2. */
static inline double airlight(double sigma_s, double sigma_t, double I, double D, double gam, double T)
{
    double h = D * sin(gam), xi1 = 0.25 * VEIL_PI + 0.5 * atan((T - D * cos(gam)) / h);
    return sigma_s * I * exp(-sigma_t * D * cos(gam)) / (2.0 * VEIL_PI * h) *
           (sun_F(sigma_t * h, xi1) - sun_F(sigma_t * h, 0.5 * gam));
}

#endif
