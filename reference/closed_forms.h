/* veil — closed-form line integrals of analytic media, in double precision.
 *
 * Ground truth that does not go through the voxel grid: the exact integral
 * along a segment of the RBF particles' Gaussians (no cut-off) and of an
 * exponential fog. Used to measure voxelisation error (grid reference vs
 * these) and, through them, the whole pipeline.
 *
 * Units: positions in metres; densities unitless (as the particles'
 * amplitudes); a line integral is density * m. Segments are given by their
 * endpoints a -> b; a == b gives 0. Nothing is allocated or retained; every
 * function is reentrant. Tiny results may flush to zero (or lose relative
 * accuracy) below the normal double range, ~2.2e-308.
 */
#ifndef VEIL_REFERENCE_CLOSED_FORMS_H
#define VEIL_REFERENCE_CLOSED_FORMS_H

#include <stddef.h>

#include "../volume/rbf.h"

/* Integral over the segment a -> b of c * exp(-s^2 |x - p|^2) for one
 * particle (c = amplitude, s = sharpness, p = centre), with no cut-off:
 * with w = (b - a)/|b - a|, the closest approach d and the abscissae
 * u0, u1 = s * (0 or |b - a| - s0) of the ends relative to it,
 *   c exp(-s^2 d^2) / s * integral_{u0}^{u1} exp(-u^2) du,
 * the last factor as sqrt(pi)/2 times erf(u1) + erf(-u0) when the segment
 * passes the closest point, erfc(u0) - erfc(u1) (or the mirror) when both
 * ends are on one side (no cancellation: erfc(u1) <= e^{-(u1^2-u0^2)}
 * erfc(u0)), and 12-point Gauss-Legendre about the midpoint when the piece
 * is short (|u1 - u0| <= 1 and |u1^2 - u0^2| <= 2), where the erfc
 * difference would cancel. Sharpness 0 gives c |b - a|.
 * Accuracy: for results >= 1e-290 c/s, relative error <= 2^-52 (24 +
 * 8 s^2 R^2), R = max(|a - p|, |b - p|): the R term is the sensitivity of
 * exp and erfc to the rounding of the exponent s^2 d^2 and of u0, u1, which
 * are O(s R) (so ~1e-13 at s R = 25, where the result is ~e^-625). Smaller
 * results may lose relative accuracy or flush to 0; never negative or NaN.
 * tests/reference/test_reference.c measures at most 0.44 of this bound. */
double veil_gaussian_line_integral(const veil_particle* p, const double a[3], const double b[3]);

/* Sum over n particles of veil_gaussian_line_integral (compensated sum). */
double veil_rbf_line_integral(const veil_particle* p, size_t n, const double a[3], const double b[3]);

/* Integral over the segment a -> b of the exponential fog
 *   rho(x) = rho0 * exp(-falloff * <x - o, nrm>)
 * (nrm is meant to be a unit vector, the direction in which the density
 * falls; the formula is used with nrm as given). With L = |b - a|,
 * k0 = falloff <a - o, nrm>, k1 = falloff <b - o, nrm>, m L = k1 - k0:
 *   rho0 * L * exp(-min(k0, k1)) * E(|m L|),  E(y) = -expm1(-y) / y, E(0) = 1,
 * i.e. the exponential is taken at the denser end, so E is in (0, 1] and
 * nothing overflows unless the result does (then +inf). k0, k1 and m L are
 * formed in double-double arithmetic (error-free sums and Dekker products),
 * and exp(-min k) is split as 2^q exp(r), |r| <= ln2/2, so the rounding of
 * a large exponent costs nothing.
 * Accuracy: for rho0 >= 0, finite inputs with |coordinates| < 1e150, and a
 * result in the normal double range, relative error <= 16 * 2^-53
 * (1.8e-15); the budget is in closed_forms.c. */
double veil_exp_fog_line_integral(double rho0, double falloff, const double nrm[3], const double o[3],
                                  const double a[3], const double b[3]);

#endif
