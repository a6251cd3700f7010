/* veil — splatting RBF (Gaussian) particles: where each may be cut off, and
 * the box their cut-off balls fill.
 *
 * A particle (scene/particle.h) is an isotropic Gaussian
 * rho(x) = c * exp(-a^2 |x - b|^2).
 *
 * Each Gaussian is splatted only inside the ball where it is at least
 * VEIL_RBF_CUTOFF times its peak: radius r_cut = sqrt(-ln(VEIL_RBF_CUTOFF))/a.
 * The mass beyond the cut is erfc-small: for the 3D Gaussian the fraction of
 * the integral outside r_cut is erfc(k) + 2k/sqrt(pi) e^{-k^2}, k = a r_cut,
 * which for CUTOFF = 1e-4 (k = 3.035) is 3.6e-4 (and every point outside the
 * ball receives less than 1e-4 of that particle's peak density).
 */
#ifndef VEIL_RBF_H
#define VEIL_RBF_H

#include <stddef.h>
#include <stdint.h>

#include "../core/result.h"
#include "../core/shared.glsl.h"
#include "../scene/particle.h"

/* VEIL_RBF_CUTOFF (core/shared.glsl.h): fraction of a particle's peak
 * density below which it is not splatted. */

/* Distance from the centre beyond which the particle is not splatted (m). */
float veil_rbf_cutoff_radius(const veil_particle* p);

/* World-space box that holds every particle's cut-off ball; returns 0 when
 * count is 0 (box untouched). */
int veil_rbf_bounds(const veil_particle* p, size_t count, float lo[3], float hi[3]);

#endif
