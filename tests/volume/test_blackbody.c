/* volume/blackbody.h: Planck's law through the CIE 1931 curves to Rec.709.
 * - Chromaticity: CIE illuminant A is by definition a Planckian radiator at
 *   2856 K, (x, y) = (0.44757, 0.40745); the Planckian locus at 6500 K is
 *   (0.3135, 0.3236). The analytic matching functions (Wyman et al. 2013)
 *   follow the tabulated ones to about 1 % of their peak, which moves a
 *   broad spectrum's chromaticity by a few 1e-3: we allow 0.005.
 * - Colour order: red over blue falls as the temperature rises from 2000
 *   to 10 000 K (bluish at the end: R/B < 1); 1000 K is deep red (its blue
 *   is outside Rec.709 and clamped to 0).
 * - Limits: T <= 0 and NaN give 0; 1e6 K is finite; 100 K is below 1e-60
 *   (exp(h c / (lambda k T)) overflows for most wavelengths) without NaN.
 * - Brightness: Y grows as T^4 or faster in the visible tail; between 3000
 *   and 6000 K the ratio of Y exceeds 2^4 = 16 (Wien's side). */
#include <math.h>
#include <stdio.h>

#include "support/check.h"
#include "volume/blackbody.h"

int main(void)
{
    double x, y;
    veil_blackbody_xy(2856.0, &x, &y);
    CHECK(fabs(x - 0.44757) < 0.005 && fabs(y - 0.40745) < 0.005, "2856 K (illuminant A): (%.5f, %.5f)", x, y);
    printf("2856 K: (%.5f, %.5f), illuminant A (0.44757, 0.40745)\n", x, y);
    veil_blackbody_xy(6500.0, &x, &y);
    CHECK(fabs(x - 0.3135) < 0.005 && fabs(y - 0.3236) < 0.005, "6500 K: (%.5f, %.5f)", x, y);
    printf("6500 K: (%.5f, %.5f), Planckian locus (0.3135, 0.3236)\n", x, y);
    double prev = INFINITY;
    double cold[3];
    veil_blackbody_rgb(1000.0, cold);
    CHECK(cold[0] > 10.0 * cold[2], "1000 K is deep red (blue out of gamut: clamped): %g %g %g", cold[0], cold[1],
          cold[2]);
    for (double t = 2000.0; t <= 10000.0; t += 500.0) {
        double rgb[3];
        veil_blackbody_rgb(t, rgb);
        double ratio = rgb[0] / rgb[2];
        CHECK(ratio < prev, "R/B must fall with temperature: %g K gives %g after %g", t, ratio, prev);
        prev = ratio;
        if (t == 10000.0) CHECK(ratio < 1.0, "10 000 K is bluish: R/B %g", ratio);
    }
    double z[3] = {1, 1, 1};
    veil_blackbody_rgb(0.0, z);
    CHECK(z[0] == 0.0 && z[1] == 0.0 && z[2] == 0.0, "0 K emits nothing");
    veil_blackbody_rgb(-5.0, z);
    CHECK(z[0] == 0.0 && z[1] == 0.0 && z[2] == 0.0, "negative kelvin emits nothing");
    veil_blackbody_rgb(NAN, z);
    CHECK(z[0] == 0.0 && z[1] == 0.0 && z[2] == 0.0, "NaN kelvin emits nothing");
    veil_blackbody_rgb(100.0, z);
    CHECK(z[0] >= 0.0 && z[0] < 1e-60 && z[1] >= 0.0 && z[1] < 1e-60 && z[2] >= 0.0 && z[2] < 1e-60,
          "100 K: nothing visible, no NaN (%g %g %g)", z[0], z[1], z[2]);
    veil_blackbody_rgb(1e6, z);
    CHECK(isfinite(z[0]) && isfinite(z[1]) && isfinite(z[2]) && z[2] > 0.0, "1e6 K is finite");
    double a[3], b[3];
    veil_blackbody_rgb(3000.0, a);
    veil_blackbody_rgb(6000.0, b);
    double ya = 0.2126 * a[0] + 0.7152 * a[1] + 0.0722 * a[2], yb = 0.2126 * b[0] + 0.7152 * b[1] + 0.0722 * b[2];
    CHECK(yb / ya > 16.0, "6000 K against 3000 K: %g times as bright, expected more than 16", yb / ya);
    return check_finish();
}
