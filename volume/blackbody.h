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
 * camera with Rec.709 primaries would record it, in W m^-2 sr^-1.
 */
#ifndef VEIL_BLACKBODY_H
#define VEIL_BLACKBODY_H

/* rgb of a blackbody at `kelvin` (0 for kelvin <= 0 or NaN; finite for any
 * finite kelvin). */
void veil_blackbody_rgb(double kelvin, double rgb[3]);

/* CIE xyz chromaticity of the same integral (for tests); x = y = 0 when
 * there is no radiance. */
void veil_blackbody_xy(double kelvin, double* x, double* y);

#endif
