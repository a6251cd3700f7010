/* veil — blackbody radiance as linear Rec.709 RGB, for temperature grids.
 *
 * Planck's law B(lambda, T) = 2 h c^2 / lambda^5 / (exp(h c / (lambda k T)) - 1)
 * (W m^-2 sr^-1 per m of wavelength) integrated against the CIE 1931 2-degree
 * colour-matching functions over 360-830 nm in 1 nm steps gives X, Y, Z in
 * W m^-2 sr^-1 (radiometric: no 683 lm/W); the matching functions are the
 * multi-lobe Gaussian fit of Wyman, Sloan and Shirley (JCGT 2013), within
 * about 1 % of the tabulated curves. X, Y, Z go to linear Rec.709 (sRGB
 * primaries, white point D65) by the standard matrix; a colour outside the
 * Rec.709 gamut (deep red at low T) has its negative channels clamped to 0.
 * So an emission of intensity 1 is the blackbody's own radiance as a
 * camera with Rec.709 primaries would record it, in W m^-2 sr^-1. Planck's
 * law lies under the Rayleigh-Jeans line 2 c k T / lambda^4, so each channel
 * grows at most linearly in T: B_rgb(T) <= 2.2e4 T (scene/limits.h).
 */
#ifndef VEIL_BLACKBODY_H
#define VEIL_BLACKBODY_H

/* rgb of a blackbody at `kelvin` (0 for kelvin <= 0 or NaN; finite for any
 * finite kelvin). */
void veil_blackbody_rgb(double kelvin, double rgb[3]);

/* The same tabulated, so that a grid's voxels cost one interpolation each
 * (computed, each costs 471 exponentials): every VEIL_BLACKBODY_STEP K up to
 * VEIL_BLACKBODY_LINEAR_END, then at geometric steps of VEIL_BLACKBODY_RATIO
 * up to VEIL_MAX_KELVIN (scene/limits.h), the hottest a grid may be.
 * veil_blackbody_table: VEIL_BLACKBODY_ENTRIES x 3 doubles, malloc'd (NULL
 * out of memory); veil_blackbody_lookup interpolates linearly in kelvin
 * between entries (beyond the table: veil_blackbody_rgb). Linear
 * interpolation between nodes 1 % apart errs by (0.01 T)^2 / 8 |B''|, and
 * B grows as T^a with a < 2 over the geometric part, so |B''| <= 2 B / T^2:
 * under 2.5e-5 of B there (tests/volume/test_blackbody.c). */
#define VEIL_BLACKBODY_STEP 10.0
#define VEIL_BLACKBODY_LINEAR_END 20000.0
#define VEIL_BLACKBODY_LINEAR 2001 /* 0, 10, ..., 20 000 K */
#define VEIL_BLACKBODY_RATIO 1.01
#define VEIL_BLACKBODY_GEOMETRIC 162 /* 20 000 x 1.01^i, i = 1..162: to 1.004e5 K >= VEIL_MAX_KELVIN */
#define VEIL_BLACKBODY_ENTRIES (VEIL_BLACKBODY_LINEAR + VEIL_BLACKBODY_GEOMETRIC)
double* veil_blackbody_table(void);
void veil_blackbody_lookup(const double* table, double kelvin, double rgb[3]);

/* CIE xyz chromaticity of the same integral (for tests); x = y = 0 when
 * there is no radiance. */
void veil_blackbody_xy(double kelvin, double* x, double* y);

#endif
