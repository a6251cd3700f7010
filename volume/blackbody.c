#include "blackbody.h"

#include <math.h>
#include <stdlib.h>

#include "../scene/limits.h"

/* A piecewise Gaussian: sigma1 left of the peak mu, sigma2 right of it (nm). */
static double lobe(double l, double mu, double s1, double s2)
{
    double t = (l - mu) / (l < mu ? s1 : s2);
    return exp(-0.5 * t * t);
}

/* CIE 1931 2-degree matching functions, Wyman, Sloan and Shirley's
 * multi-lobe fit (lambda in nm). */
static void cie(double l, double xyz[3])
{
    xyz[0] = 1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) - 0.065 * lobe(l, 501.1, 20.4, 26.2);
    xyz[1] = 0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1);
    xyz[2] = 1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8);
}

static void blackbody_xyz(double kelvin, double xyz[3])
{
    xyz[0] = xyz[1] = xyz[2] = 0.0;
    if (!(kelvin > 0.0) || !isfinite(kelvin)) return;
    const double h = 6.62607015e-34, c = 299792458.0, k = 1.380649e-23;
    for (int nm = 360; nm <= 830; ++nm) {
        double l = nm * 1e-9;
        double e = expm1(h * c / (l * k * kelvin)); /* inf for cold: B = 0 */
        double B = 2.0 * h * c * c / (l * l * l * l * l) / e;
        if (!(B > 0.0) || !isfinite(B)) continue;
        double w[3];
        cie((double)nm, w);
        for (int a = 0; a < 3; ++a) xyz[a] += B * w[a] * 1e-9; /* d lambda = 1 nm */
    }
}

void veil_blackbody_rgb(double kelvin, double rgb[3])
{
    double xyz[3];
    blackbody_xyz(kelvin, xyz);
    /* XYZ -> linear sRGB / Rec.709, D65 */
    rgb[0] = 3.2404542 * xyz[0] - 1.5371385 * xyz[1] - 0.4985314 * xyz[2];
    rgb[1] = -0.9692660 * xyz[0] + 1.8760108 * xyz[1] + 0.0415560 * xyz[2];
    rgb[2] = 0.0556434 * xyz[0] - 0.2040259 * xyz[1] + 1.0572252 * xyz[2];
    for (int a = 0; a < 3; ++a) rgb[a] = rgb[a] > 0.0 && isfinite(rgb[a]) ? rgb[a] : 0.0;
}

void veil_blackbody_xy(double kelvin, double* x, double* y)
{
    double xyz[3];
    blackbody_xyz(kelvin, xyz);
    double s = xyz[0] + xyz[1] + xyz[2];
    *x = s > 0.0 ? xyz[0] / s : 0.0;
    *y = s > 0.0 ? xyz[1] / s : 0.0;
}

/* Entry i's kelvin: linear, then geometric. */
static double node(int i)
{
    if (i < VEIL_BLACKBODY_LINEAR) return i * VEIL_BLACKBODY_STEP;
    return VEIL_BLACKBODY_LINEAR_END * pow(VEIL_BLACKBODY_RATIO, i - (VEIL_BLACKBODY_LINEAR - 1));
}

double* veil_blackbody_table(void)
{
    double* table = malloc(VEIL_BLACKBODY_ENTRIES * 3 * sizeof *table);
    for (int i = 0; table && i < VEIL_BLACKBODY_ENTRIES; ++i) veil_blackbody_rgb(node(i), table + 3 * i);
    return table;
}

void veil_blackbody_lookup(const double* table, double kelvin, double rgb[3])
{
    if (!(kelvin > 0.0)) {
        rgb[0] = rgb[1] = rgb[2] = 0.0;
        return;
    }
    int i;
    if (kelvin < VEIL_BLACKBODY_LINEAR_END) {
        i = (int)(kelvin / VEIL_BLACKBODY_STEP);
    } else {
        double u = log(kelvin / VEIL_BLACKBODY_LINEAR_END) / log(VEIL_BLACKBODY_RATIO);
        if (!(u < VEIL_BLACKBODY_GEOMETRIC)) {
            veil_blackbody_rgb(kelvin, rgb);
            return;
        }
        i = VEIL_BLACKBODY_LINEAR - 1 + (int)u;
        /* u's rounding may put kelvin a hair outside [node(i), node(i + 1)]: step to the right one */
        if (i > VEIL_BLACKBODY_LINEAR - 1 && kelvin < node(i)) --i;
        if (i + 1 < VEIL_BLACKBODY_ENTRIES - 1 && kelvin >= node(i + 1)) ++i;
    }
    if (i >= VEIL_BLACKBODY_ENTRIES - 1) {
        veil_blackbody_rgb(kelvin, rgb);
        return;
    }
    double t0 = node(i), f = (kelvin - t0) / (node(i + 1) - t0);
    for (int c = 0; c < 3; ++c) rgb[c] = table[3 * i + c] + f * (table[3 * (i + 1) + c] - table[3 * i + c]);
}
