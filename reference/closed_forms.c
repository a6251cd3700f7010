#include "closed_forms.h"

#include <math.h>

#define SQRT_PI_2 0.886226925452758013649 /* sqrt(pi) / 2 */

/* 12-point Gauss-Legendre on [-1, 1], the positive half (nodes, weights). */
static const double gl12[6][2] = {
    {0.981560634246719250691, 0.0471753363865118271946},
    {0.904117256370474856678, 0.10693932599531843096},
    {0.769902674194304687037, 0.160078328543346226335},
    {0.587317954286617447297, 0.203167426723065921749},
    {0.367831498998180193753, 0.233492536538354808761},
    {0.125233408511468915472, 0.249147045813402785001},
};

/* ---- Gaussian particles ---------------------------------------------- */

/* integral_{m-h}^{m+h} exp(-u^2) du / exp(-m^2) = h * integral_{-1}^{1}
 * exp(-(2 m h z + h^2 z^2)) dz, for |2 m h| <= 1 and h <= 1/2. The
 * integrand is entire and at most e^{|2mh| A + h^2 A^2} on the Bernstein
 * ellipse of parameter 8 (A = 4.06), so the 12-point rule's error is below
 * 64/15 * e^8.2 / 63 * 8^-24 = 5e-20 against an integral >= 2 e^{-1.25}:
 * far below rounding. */
static double gauss_short(double m, double h)
{
    double s = 0.0;
    for (int j = 0; j < 6; ++j) {
        const double z = gl12[j][0];
        const double lin = 2.0 * m * h * z, quad = h * h * z * z;
        s += gl12[j][1] * (exp(-(quad + lin)) + exp(-(quad - lin)));
    }
    return h * s;
}

double veil_gaussian_line_integral(const veil_particle* p, const double a[3], const double b[3])
{
    const double c = (double)p->amplitude, s = fabs((double)p->sharpness);
    double ab[3], l2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        ab[k] = b[k] - a[k];
        l2 += ab[k] * ab[k];
    }
    if (!(l2 > 0.0) || c == 0.0) return 0.0;
    const double len = sqrt(l2);
    if (s == 0.0) return c * len;

    /* x(t) = a + t w; |x - p|^2 = d^2 + (t - s0)^2 */
    double w[3], ac[3], s0 = 0.0;
    for (int k = 0; k < 3; ++k) {
        w[k] = ab[k] / len;
        ac[k] = a[k] - (double)p->center[k];
        s0 -= ac[k] * w[k];
    }
    double d2 = 0.0; /* from the perpendicular vector: no |ac|^2 - s0^2 cancellation */
    for (int k = 0; k < 3; ++k) {
        const double q = ac[k] + s0 * w[k];
        d2 += q * q;
    }
    const double u0 = -s * s0, u1 = s * (len - s0), du = s * len;
    double g, expo = s * s * d2;
    if (du <= 1.0 && ((u0 < 0.0 && u1 > 0.0) || du * fabs(u0 + u1) <= 2.0)) {
        const double m = s * (0.5 * len - s0);
        g = gauss_short(m, 0.5 * du);
        expo += m * m;
    } else if (u0 >= 0.0) {
        g = SQRT_PI_2 * (erfc(u0) - erfc(u1)); /* erfc(u1) <= 0.16 erfc(u0) here */
    } else if (u1 <= 0.0) {
        g = SQRT_PI_2 * (erfc(-u1) - erfc(-u0));
    } else {
        g = SQRT_PI_2 * (erf(u1) + erf(-u0)); /* both terms >= 0 */
    }
    return c * exp(-expo) * (g / s);
}

double veil_rbf_line_integral(const veil_particle* p, size_t n, const double a[3], const double b[3])
{
    double sum = 0.0, comp = 0.0; /* Neumaier */
    for (size_t i = 0; i < n; ++i) {
        const double v = veil_gaussian_line_integral(&p[i], a, b);
        const double t = sum + v;
        if (fabs(sum) >= fabs(v))
            comp += (sum - t) + v;
        else
            comp += (v - t) + sum;
        sum = t;
    }
    return sum + comp;
}

/* ---- Exponential fog -------------------------------------------------- */

/* Double-double helpers. Each operation is its own statement so that no
 * compiler contracts them into fused multiply-adds (which would break the
 * error-free transforms); this file must not be built with -ffast-math. */
typedef struct dd {
    double hi, lo;
} dd;

static dd two_sum(double a, double b)
{
    const double s = a + b;
    const double bb = s - a;
    const double e1 = a - (s - bb);
    const double e2 = b - bb;
    return (dd){s, e1 + e2};
}

/* Veltkamp split: a = hi + lo, each with at most 26 significant bits. */
static void split(double a, double* hi, double* lo)
{
    const double t = 134217729.0 * a; /* 2^27 + 1 */
    const double u = t - a;
    *hi = t - u;
    *lo = a - *hi;
}

static dd two_prod(double a, double b)
{
    const double p = a * b;
    double ah, al, bh, bl;
    split(a, &ah, &al);
    split(b, &bh, &bl);
    const double e1 = ah * bh - p;
    const double e2 = e1 + ah * bl;
    const double e3 = e2 + al * bh;
    const double e4 = e3 + al * bl;
    return (dd){p, e4};
}

static dd dd_add(dd x, dd y)
{
    dd s = two_sum(x.hi, y.hi);
    const double lo = s.lo + (x.lo + y.lo);
    return two_sum(s.hi, lo);
}

/* (dd) x * double y */
static dd dd_mul_d(dd x, double y)
{
    dd p = two_prod(x.hi, y);
    const double lo = p.lo + x.lo * y;
    return two_sum(p.hi, lo);
}

/* scale * <p - q, v>, with p - q exact and relative error ~2^-100. */
static dd scaled_dot(double scale, const double p[3], const double q[3], const double v[3])
{
    dd acc = {0.0, 0.0};
    for (int k = 0; k < 3; ++k) {
        const dd diff = two_sum(p[k], -q[k]);
        dd term = two_prod(diff.hi, v[k]);
        term.lo += diff.lo * v[k];
        acc = dd_add(acc, term);
    }
    return dd_mul_d(acc, scale);
}

/* E(y) = (1 - e^{-y}) / y for y >= 0: in (0, 1], decreasing, E(0) = 1;
 * expm1 keeps full relative accuracy as y -> 0. */
static double exp_mean(double y)
{
    if (y == 0.0) return 1.0;
    return -expm1(-y) / y;
}

/* fdlibm's split of ln 2: LN2_HI has 32 significant bits, so q * LN2_HI is
 * exact for |q| < 2^21. */
#define LN2_HI 6.93147180369123816490e-01
#define LN2_LO 1.90821492927058770002e-10
#define INV_LN2 1.44269504088896338700e+00

/* Error budget (u = 2^-53 per rounding, glibc exp/expm1 < 1 ulp = 2u):
 *   L = sqrt(sum (b-a)^2): differences 1u, squares 1u, sum 2u, sqrt halves
 *     the argument's error and adds 1u                          -> 3u;
 *   E(|mL|): mL has 1u (double-double rounded), and |y E'(y)/E(y)| <= 1,
 *     so 1u; expm1 2u; the division 1u                           -> 4u;
 *   exp(-kmin) = 2^q exp(r): kmin exact to ~2^-100 |k|; r = (t - q LN2_HI)
 *     - q LN2_LO - k.lo: the first difference is exact, then 2 roundings
 *     of ~u |r| <= 0.35u each; exp 2u                           -> 3u;
 *   three products 3u; the final 2^q scaling is exact in the normal range.
 * Total 13u; documented as 16u = 1.8e-15. */
double veil_exp_fog_line_integral(double rho0, double falloff, const double nrm[3], const double o[3],
                                  const double a[3], const double b[3])
{
    double l2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        const double dk = b[k] - a[k];
        l2 += dk * dk;
    }
    if (!(l2 > 0.0) || rho0 == 0.0) return 0.0;
    const double len = sqrt(l2);

    const dd ml = scaled_dot(falloff, b, a, nrm); /* k1 - k0 = m L */
    /* exponent at the denser end: k0 when the density falls along a -> b */
    const dd kmin = ml.hi >= 0.0 ? scaled_dot(falloff, a, o, nrm) : scaled_dot(falloff, b, o, nrm);
    const double e = exp_mean(fabs(ml.hi + ml.lo));

    const double t = -kmin.hi; /* result = rho0 L E exp(t - kmin.lo) */
    const double base = rho0 * len * e;
    if (isnan(t) || isnan(base)) return NAN;
    if (t > 2100.0) return base > 0.0 ? INFINITY : 0.0; /* e^2100 * 1e-323 still overflows */
    if (t < -2100.0) return 0.0;
    const double q = nearbyint(t * INV_LN2);
    const double r = ((t - q * LN2_HI) - q * LN2_LO) - kmin.lo;
    return ldexp(base * exp(r), (int)q);
}
