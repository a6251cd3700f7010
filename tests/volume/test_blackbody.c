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
 *   and 6000 K the ratio of Y exceeds 2^4 = 16 (Wien's side).
 * - The table (issue 22): veil_blackbody_lookup equals veil_blackbody_rgb
 *   between its nodes within the bound its header derives, as a fraction of
 *   the brightest channel: in the geometric steps from 20 000 K to
 *   VEIL_MAX_KELVIN (the hottest a grid may be) 2.5e-5 (we allow 5e-5); in
 *   the 10 K steps from 1000 K, where B ~ T^a with a up to h c / (lambda k T)
 *   = 24 at 1000 K and 600 nm, (10 / T)^2 / 8 a (a - 1) = 7e-3 (we allow
 *   1e-2). Planck's law lies under the Rayleigh-Jeans line: B_rgb(T) <=
 *   2.2e4 T at every T (scene/limits.h). */
#include <math.h>
#include <stdio.h>

#include "support/check.h"
#include <stdlib.h>

#include "scene/limits.h"
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

    double* table = veil_blackbody_table();
    CHECK(table != NULL, "table");
    if (!table) return check_finish();
    double worst_lin = 0.0, worst_geo = 0.0, worst_rj = 0.0;
    int geo_points = 0;
    for (double t = 1000.0; t <= VEIL_MAX_KELVIN; t *= 1.0007) { /* not on the nodes: 1.0007 is no step's ratio */
        double want[3], got[3];
        veil_blackbody_rgb(t, want);
        veil_blackbody_lookup(table, t, got);
        double most = fmax(want[0], fmax(want[1], want[2])) + 1e-9;
        for (int c = 0; c < 3; ++c) {
            /* against the brightest channel: a channel clamped at Rec.709's gamut (blue under ~1900 K)
             * has a kink at 0 that interpolation rounds off, by as much as the next node's value */
            double e = fabs(got[c] - want[c]) / most;
            if (t < VEIL_BLACKBODY_LINEAR_END) worst_lin = fmax(worst_lin, e);
            else worst_geo = fmax(worst_geo, e);
            worst_rj = fmax(worst_rj, want[c] / t);
        }
        geo_points += t >= VEIL_BLACKBODY_LINEAR_END;
    }
    double at[3], direct[3];
    veil_blackbody_lookup(table, VEIL_MAX_KELVIN, at);
    veil_blackbody_rgb(VEIL_MAX_KELVIN, direct);
    CHECK(geo_points > 1000, "the geometric part is sampled (%d points)", geo_points);
    CHECK(worst_lin <= 1e-2, "table from 1000 to 20 000 K: relative error %.3g (derived: 7e-3)", worst_lin);
    CHECK(worst_geo <= 5e-5, "table from 20 000 K to 1e5 K: relative error %.3g (derived: 2.5e-5)", worst_geo);
    CHECK(fabs(at[2] - direct[2]) <= 5e-5 * direct[2], "1e5 K from the table: %g, computed %g", at[2], direct[2]);
    CHECK(worst_rj <= 2.2e4, "B_rgb(T) / T up to %.4g, over the Rayleigh-Jeans bound 2.2e4 of scene/limits.h", worst_rj);
    for (double t = 1e6; t <= 1e30; t *= 10.0) {
        veil_blackbody_rgb(t, at);
        for (int c = 0; c < 3; ++c) worst_rj = fmax(worst_rj, at[c] / t);
    }
    CHECK(worst_rj <= 2.2e4, "B_rgb(T) / T up to %.4g beyond 1e6 K, over 2.2e4", worst_rj);
    printf("blackbody table: relative error %.2g below 20 000 K, %.2g to 1e5 K; B / T at most %.4g\n", worst_lin,
           worst_geo, worst_rj);
    free(table);
    return check_finish();
}
