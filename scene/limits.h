/* veil — what the float pipeline can carry, decided in one place (issue
 * 12): the scene and particle readers refuse anything beyond these at
 * load, naming the field, so that no stage meets an overflow late.
 *
 * Positions (camera, lights, particle centres, fog origins and boxes,
 * generator boxes), m: |x| <= VEIL_MAX_COORD on every axis. Stages form
 * sums and differences of two positions (boxes, a particle's centre plus
 * its cut-off radius, brick ranges: <= 2e15) and squared distances
 * (<= 3 (2e15)^2 = 1.2e31), all far under FLT_MAX = 3.4e38, and voxel
 * indices of them only after dividing by a voxel fitted to the same box.
 * A particle centre at 3.4e38 overflowed such a sum to inf, and its
 * conversion to int crashed veil_rbf_bin.
 *
 * Particle sharpness (m^-2) >= VEIL_MIN_SHARPNESS: the cut-off radius
 * sqrt(ln(1 / VEIL_RBF_CUTOFF) / s) = 3.03 / sqrt(s) stays <= VEIL_MAX_COORD
 * (s >= 9.2e-30).
 *
 * Light intensity (W/sr) and irradiance (W/m^2), per channel: <=
 * VEIL_MAX_LIGHT. The march's radiance is at most the in-scattered
 * radiance (sigma_s / sigma_t <= 1 per step, sum of T(1 - e^-x) <= 1):
 * 16 lights x E x the phase function's peak (HG, g = 0.99: 1.6e3) x the
 * octaves (sum of b^i <= 10) = 2.6e5 E, with E = I / r^2 and r^2 floored
 * at (1e-3 voxel)^2; for voxels >= 1 um that is E <= 1e12 I, so I <= 1e20
 * keeps every pixel under 2.6e37. A light of 3.4e38 made Inf pixels.
 */
#ifndef VEIL_LIMITS_H
#define VEIL_LIMITS_H

#define VEIL_MAX_COORD 1e15
#define VEIL_MIN_SHARPNESS 1e-29
#define VEIL_MAX_LIGHT 1e20

#endif
