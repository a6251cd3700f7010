/* veil — the gathering filter: the exact spatially varying Gaussian spread
 * that the screen-space MIP chains (render/spread.h) approximate (Iser &
 * Elek 2018, 4.2, "gathering"; slow: O(pixels x W^2)).
 *
 * Each source pixel y spreads its light L(y) over the image with a
 * normalised 2D Gaussian of standard deviation W(y) pixels, integrated over
 * each destination pixel's area (so W -> 0 keeps it in its own pixel, and
 * the weights over the infinite lattice sum to 1 exactly):
 *   out(x) = sum_y L(y) g_W(y)(x1 - y1) g_W(y)(x2 - y2),
 *   g_W(d) = Phi((d + 1/2) / W) - Phi((d - 1/2) / W).
 * Light spread beyond the image is lost, as in the MIP chains. Each source
 * is cut at VEIL_GATHER_SIGMAS standard deviations: the mass dropped is
 * below 2 Phi(-6) = 2e-9 per axis. Summed per destination (gathering)
 * or per source (splatting), the result is the same; this splats.
 */
#ifndef VEIL_REFERENCE_GATHER_H
#define VEIL_REFERENCE_GATHER_H

#include "../core/result.h"

#define VEIL_GATHER_SIGMAS 6.0

/* L: rgba per pixel (rgb spread; a ignored), W: w*h spreads in pixels
 * (>= 0, finite), out: rgba (a = 0). */
veil_result veil_gather_spread(int w, int h, const float* L, const float* W, float* out, veil_error* err);

/* The 1D weight g_W(d) above (W = 0: 1 at d = 0, else 0). */
double veil_gather_weight(int d, double W);

#endif
