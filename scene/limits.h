/* veil — what the float pipeline can carry, decided in one place (issues
 * 12 and 22): the scene and particle readers refuse anything beyond these
 * at load, naming the field, and the grid readers refuse or clamp voxels
 * (below), so that no stage meets an overflow late.
 *
 * Positions (camera, lights, particle centres, fog origins and boxes,
 * generator boxes), m: |x| <= VEIL_MAX_COORD on every axis. Stages form
 * sums and differences of two positions (boxes, a particle's centre plus
 * its cut-off radius, brick ranges: <= 2e15) and squared distances
 * (<= 3 (2e15)^2 = 1.2e31), all far under FLT_MAX = 3.4e38, and voxel
 * indices of them only after dividing by a voxel fitted to the same box.
 * A particle centre at 3.4e38 overflowed such a sum to inf, and its
 * conversion to int crashed veil_rbf_bin. So every path through the scene
 * is shorter than its box's diagonal, L <= 2 sqrt(3) 1e15 = 3.5e15 m.
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
 * at (1e-3 voxel)^2; for voxels >= 1 mm that is E <= 1e12 I, so I <= 1e20
 * keeps every pixel under 2.6e37. A light of 3.4e38 made Inf pixels.
 * (Voxels are not bounded below: under 1 mm, a light of 1e20 W/sr within
 * 1e-3 voxel of a sample is beyond this derivation.)
 *
 * The medium (issue 22). sigma_a and sigma_s (m^-1 per unit density) and a
 * temperature grid's emission coefficient k (the same unit): <=
 * VEIL_MAX_SIGMA. Every density a source contributes: a VDB voxel times
 * its density_scale (and density_scale itself), a particle's amplitude, a
 * fog's density at its origin plane: <= VEIL_MAX_DENSITY. A voxel of the
 * extinction volume sums at most 8 VDB sources and 1e7 particles, so its
 * density is <= 1e17 and its extinction sigma_t rho <= 2e10 x 1e17 =
 * 2e27 m^-1; the march's density integral along a ray, P, and each step's
 * rho dt are <= 1e17 x 3.5e15 = 3.5e32 (density m): finite. The octaves'
 * floor sqrt(3 sigma_a (sigma_a + sigma_s (1 - g))) forms 9 sigma^2 <=
 * 9e20. Optical depths sigma_t P may still pass FLT_MAX (a voxel of 1e17
 * over 3.5e15 m): the march and the propagation hold them at FLT_MAX
 * (min(..., INF)), an opaque path, and exp(-inf) = 0. sigma_s = 3e38 made
 * the octaves' floor inf and then inf x 0: NaN pixels. A mean free path
 * of 1e-20 m (both bounds at once) is beyond any medium.
 * Fog falloff b (m^-1) <= VEIL_MAX_FALLOFF: the march forms k = b <x - o, n>
 * at both ends of a step and their difference, <= 2 x 1e20 x 3.5e15 =
 * 7e35 (falloff 3e38 gave inf - inf).
 *
 * Emission, W m^-3 sr^-1: eps = emission.scale x value x emission.color
 * (each factor, and scale x color, <= VEIL_MAX_EMISSION; a voxel whose eps
 * would pass it is refused). The march adds sum T eps dt (1 - e^-x) / x <=
 * eps L <= 1e21 x 3.5e15 = 3.5e36 along a ray, which with the lights'
 * 2.6e37 and the background's 1e20 stays under FLT_MAX. A temperature
 * grid emits k rho B(kelvin), capped at max(1e21, sigma_a rho B): with
 * Kirchhoff's k = sigma_a (the default), or any k <= sigma_a, never capped,
 * its sum <= B sum T (sigma_a / sigma_t)(1 - e^-x) <= B <= 2.2e9; a larger k
 * (<= 1e10, at rho <= 1e10 and B <= 2.2e9: up to 2.2e29, finite) is. The emission's lights
 * (volume/emission_lights.h) carry sum eps dV, capped at VEIL_MAX_LIGHT so
 * that the lights' derivation above holds for them (a voxel of 1e15 m has
 * dV = 1e45: eps dV overflowed a float to inf; a +inf heat voxel made the
 * light's position NaN, the propagation's shells ran for 200 s and 657
 * pixels were NaN).
 *
 * Temperature, K: kelvin = temperature.scale x value + offset <=
 * VEIL_MAX_KELVIN, hotter than any flame (< 4e3 K), explosion (~1e4 K) or
 * lightning channel (3e4 K); |scale| and |offset| <= it as well (a value
 * of 1 maps within it). The blackbody radiance is tabulated to it
 * (volume/blackbody.h: one interpolation a voxel; computed directly, each
 * voxel cost 471 exponentials) and is below the Rayleigh-Jeans line,
 * B_rgb(T) <= 2.2e4 T W m^-2 sr^-1 (2.2e9 at 1e5 K). Kelvin <= 0 emits
 * nothing.
 *
 * Background radiance (W m^-2 sr^-1, per channel) <= VEIL_MAX_BACKGROUND:
 * it adds T x background to every pixel.
 *
 * The screen-space spread's numbers (multiple_scattering: c, mask_epsilon,
 * the separation's thresholds and widths, thin_threshold) <=
 * VEIL_MAX_SPREAD: the spread forms c 2^k (k <= 12) and T / (1 + eps),
 * thresholds plus widths, <= 4.1e33.
 *
 * Grid values (volume/vdb_volume.h): a voxel (or active tile) that is not a
 * number or infinite is refused when the grid is opened (io/vdb.h), with
 * the file, the grid and how many; a density or emission voxel below 0 is
 * read as 0 (negative density or emission has no meaning: it made negative
 * radiance) and --stats says how many; a voxel whose density, emission or
 * temperature passes the bounds above is refused with the count. */
#ifndef VEIL_LIMITS_H
#define VEIL_LIMITS_H

#define VEIL_MAX_COORD 1e15
/* A grid's voxel, the |determinant| of its index-to-world map (m^3), is at
 * least this (issue 41): OpenVDB's affine maps refuse a smaller one as
 * nearly singular (3 x its double tolerance of 1e-15; a cube of 14.4 um a
 * side), so a grid from memory or a VDB source's "transform" below it is
 * refused by name instead of failing in OpenVDB. */
#define VEIL_MIN_VOXEL_VOLUME 3e-15
/* And its smallest edge at least this fraction of the largest |coordinate|
 * of the grid's box: positions are single precision past the reader (the
 * volume's grid, the shaders), 2^-24 of their size apart at worst, so a
 * voxel spans at least 16 of those steps (a sample's place in its voxel
 * known to 1/16 at worst). A 1e-4 m voxel at 9e14 m made a grid of no width
 * (OpenVDB: "Non-zero scale values required"). */
#define VEIL_MIN_VOXEL_RELATIVE 0x1p-20
#define VEIL_MIN_SHARPNESS 1e-29
#define VEIL_MAX_LIGHT 1e20
#define VEIL_MAX_SIGMA 1e10
#define VEIL_MAX_DENSITY 1e10
#define VEIL_MAX_FALLOFF 1e20
#define VEIL_MAX_EMISSION 1e21
#define VEIL_MAX_KELVIN 1e5
#define VEIL_MAX_BACKGROUND 1e20
#define VEIL_MAX_SPREAD 1e30

#endif
