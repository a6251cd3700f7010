/* The float closed form of exponential fog that the marcher uses
 * (veil_exp_fog_integral, core/shared.glsl.h) against the double one of
 * reference/closed_forms.h (itself checked against double-double
 * quadrature in tests/reference/test_closed_forms.c), on 10^5 seeded random segments:
 * generic ones, ones perpendicular to the falloff direction (<w,n> = 0: no
 * slope at all), nearly perpendicular ones (|k1 - k0| down to 1e-9), very
 * steep ones (|k1 - k0| up to 60), and zero-length ones.
 *
 * Bound on the relative error, for min(k0, k1) >= -VEIL_FOG_MAX_EXPONENT:
 *  - the inputs k0, k1, len are rounded to float: exp(-kmin) moves by
 *    |kmin| 2^-24 relative, (1 - e^-x)/x by at most half the relative change
 *    of x = |k1 - k0|, whose float error is at most (|k0| + |k1|) 2^-24
 *    absolute, and the derivative of the log of (1 - e^-x)/x is at most 1/2;
 *  - the series or the direct form of veil_step_integral: 1e-6 (its comment);
 *  - five roundings of expf and products: 8 2^-24.
 *   |rel| <= 1e-6 + (8 + |kmin| + (|k0| + |k1|) / 2) 2^-24,
 * and, since a float cannot hold values below FLT_MIN (1.2e-38) to full
 * precision (they are denormal, or 0), an absolute FLT_MIN besides: a
 * density integral that small attenuates nothing.
 * Below -VEIL_FOG_MAX_EXPONENT the float version caps the density (fog that
 * dense is opaque); there it must stay finite and not exceed the truth. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "support/check.h"
#include "core/shared.glsl.h"
#include "reference/closed_forms.h"
#include "support/seeded_random.h"

int main(void)
{
    int bad = 0, capped_bad = 0, n_capped = 0;
    double worst = 0.0;
    for (int i = 0; i < 100000; ++i) {
        int kind = i % 5;
        double nrm[3], w[3], a[3], b[3], o[3] = {rnd_in(-5, 5), rnd_in(-5, 5), rnd_in(-5, 5)};
        rnd_unit(nrm);
        rnd_unit(w);
        if (kind == 1 || kind == 2) { /* perpendicular, or nearly: w minus its component along n */
            double d = dot3(w, nrm);
            for (int k = 0; k < 3; ++k) w[k] -= d * nrm[k];
            double l = sqrt(dot3(w, w));
            for (int k = 0; k < 3; ++k) w[k] /= l;
            if (kind == 2)
                for (int k = 0; k < 3; ++k) w[k] += rnd_log(1e-9, 1e-3) * nrm[k];
        }
        double len = kind == 4 ? 0.0 : rnd_log(1e-3, 50.0);
        double falloff = kind == 3 ? rnd_log(1.0, 30.0) : rnd_log(1e-4, 2.0);
        for (int k = 0; k < 3; ++k) {
            a[k] = rnd_in(-10, 10);
            b[k] = a[k] + len * w[k];
        }
        double rho0 = rnd_log(1e-3, 10.0);
        double k0 = falloff * ((a[0] - o[0]) * nrm[0] + (a[1] - o[1]) * nrm[1] + (a[2] - o[2]) * nrm[2]);
        double k1 = falloff * ((b[0] - o[0]) * nrm[0] + (b[1] - o[1]) * nrm[1] + (b[2] - o[2]) * nrm[2]);
        double seg = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (b[2] - a[2]) * (b[2] - a[2]));
        double ref = veil_exp_fog_line_integral(rho0, falloff, nrm, o, a, b);
        float got = veil_exp_fog_integral((float)rho0, (float)k0, (float)k1, (float)seg);
        double kmin = fmin(k0, k1);
        if (kmin < -VEIL_FOG_MAX_EXPONENT) {
            ++n_capped;
            if (!(isfinite(got) && got >= 0 && got <= ref * (1 + 1e-5))) ++capped_bad;
            continue;
        }
        if (ref == 0.0) {
            if (got != 0.0f) ++bad;
            continue;
        }
        double rel = fabs(got - ref) / ref;
        double bound = 1e-6 + (8.0 + fabs(kmin) + 0.5 * (fabs(k0) + fabs(k1))) * 0x1p-24;
        if (!(fabs(got - ref) <= bound * ref + FLT_MIN)) {
            if (bad < 5) fprintf(stderr, "segment %d (kind %d): k0 %.9g k1 %.9g len %.6g: %.9g vs %.9g (rel %.3g > %.3g)\n",
                                 i, kind, k0, k1, seg, (double)got, ref, rel, bound);
            ++bad;
        }
        if (ref >= FLT_MIN) worst = fmax(worst, rel / bound);
    }
    printf("float fog closed form: 100000 segments, largest error %.2f of its bound; %d capped (density above "
           "e^%g), all finite and not above the truth\n", worst, n_capped, VEIL_FOG_MAX_EXPONENT);
    CHECK(bad == 0, "%d segments beyond the bound", bad);
    CHECK(capped_bad == 0, "%d capped segments not finite or above the truth", capped_bad);
    return check_finish();
}
