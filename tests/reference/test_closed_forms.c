/* The closed forms of reference/closed_forms.h (the Gaussian line
 * integral, the exponential-fog line integral) agree with independent
 * double-double quadratures to their stated bounds, including the
 * degenerate and extreme cases.
 *
 * u = 2^-53 is the unit roundoff; every tolerance below is derived in the
 * comment next to it. Random inputs come from a fixed SplitMix64 stream.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "reference/closed_forms.h"
#include "reference/optical_depth.h"
#include "support/seeded_random.h"
#include "volume/volume.h"

#define U 1.1102230246251565e-16 /* 2^-53 */

/* ---- double-double arithmetic for the reference quadratures ------------ */
/* (each operation its own statement: the build disables FP contraction) */

typedef struct dd {
    double hi, lo;
} dd;

static dd dd_two_sum(double a, double b)
{
    const double s = a + b;
    const double v = s - a;
    const double ea = a - (s - v);
    const double eb = b - v;
    return (dd){s, ea + eb};
}

static dd dd_two_prod(double a, double b)
{
    const double p = a * b;
    const double ca = 134217729.0 * a, cb = 134217729.0 * b;
    const double ah = ca - (ca - a), bh = cb - (cb - b);
    const double al = a - ah, bl = b - bh;
    double e = ah * bh - p;
    e = e + ah * bl;
    e = e + al * bh;
    e = e + al * bl;
    return (dd){p, e};
}

static dd dd_add(dd x, dd y)
{
    const dd s = dd_two_sum(x.hi, y.hi);
    const double lo = s.lo + (x.lo + y.lo);
    return dd_two_sum(s.hi, lo);
}

static dd dd_mul(dd x, dd y)
{
    dd p = dd_two_prod(x.hi, y.hi);
    const double cross = x.hi * y.lo + x.lo * y.hi;
    return dd_two_sum(p.hi, p.lo + cross);
}

static dd dd_mul_d(dd x, double y) { return dd_mul(x, (dd){y, 0.0}); }

static dd dd_sqrt(dd x) /* one Newton step from the double root */
{
    const double s = sqrt(x.hi);
    const dd s2 = dd_two_prod(s, s);
    const double r = ((x.hi - s2.hi) - s2.lo + x.lo) / (2.0 * s);
    return dd_two_sum(s, r);
}

/* 10-point Gauss-Legendre on [-1, 1], the positive half (node, weight). */
static const double gl10[5][2] = {
    {0.973906528517171720078, 0.0666713443086881375936},
    {0.865063366688984510732, 0.149451349150580593146},
    {0.679409568299024406234, 0.219086362515982043996},
    {0.433395394129247190799, 0.269266719309996355091},
    {0.148874338981631210885, 0.295524224714752870174},
};

/* The panel [ta, tb] (doubles) as exact mid and half-width in dd, and
 * node j (sign sg) = mid + sg * z_j * half, in dd: the node positions carry
 * no rounding larger than ~2^-100, so steep integrands (|slope| up to 1e3
 * per unit parameter) are sampled where the weights assume. */
static dd panel_node(dd mid, dd half, double z) { return dd_add(mid, dd_mul_d(half, z)); }

static void panel(double ta, double tb, dd* mid, dd* half)
{
    dd w = dd_two_sum(tb, -ta);
    w.hi *= 0.5;
    w.lo *= 0.5;
    *half = w;
    *mid = dd_add((dd){ta, 0.0}, w);
}

/* ---- 3. Gaussian line integral ------------------------------------------ */

/* Reference: integral over tau in [0, 1] of c exp(-s^2 |a + tau (b - a) - p|^2)
 * times |b - a|, all in double-double (a - p and b - a exact), by 10-point
 * Gauss-Legendre on panels of width 0.5 / (1 + |u|) in the abscissa
 * u = s * (distance along the line from the closest point), so the exponent
 * changes by <= 1 across a panel: the rule's truncation error is then
 * < 1e-25 (Bernstein-ellipse bound with rho = 20). Its rounding: exp of the
 * double-rounded exponent (< 1 ulp = 2u) times (1 - exponent.lo), the
 * weights (1u), the panel sums in double (<= 2u relative, positive terms):
 * <= 5u. */
static double gauss_ref(const veil_particle* p, const double a[3], const double b[3])
{
    dd diff[3], ap[3], l2 = {0.0, 0.0};
    for (int k = 0; k < 3; ++k) {
        diff[k] = dd_two_sum(b[k], -a[k]);
        ap[k] = dd_two_sum(a[k], -(double)p->center[k]);
        l2 = dd_add(l2, dd_mul(diff[k], diff[k]));
    }
    if (l2.hi == 0.0) return 0.0;
    const dd len = dd_sqrt(l2);
    const double s2 = (double)p->sharpness * (double)p->sharpness; /* exact: 24-bit float squared */
    const double scale = (double)p->sharpness * len.hi;          /* du / dtau */
    double proj = 0.0;
    for (int k = 0; k < 3; ++k) proj += ap[k].hi * diff[k].hi;
    const double tstar = -proj / l2.hi;
    dd total = {0.0, 0.0};
    double ta = 0.0;
    while (ta < 1.0) {
        const double u = scale * (ta - tstar);
        const double dt = 0.5 / ((1.0 + fabs(u)) * scale);
        const double tb = dt >= 1.0 - ta ? 1.0 : ta + dt;
        dd mid, half;
        panel(ta, tb, &mid, &half);
        double sum = 0.0;
        for (int j = 0; j < 5; ++j)
            for (int sg = -1; sg <= 1; sg += 2) {
                const dd t = panel_node(mid, half, sg * gl10[j][0]);
                dd e = {0.0, 0.0};
                for (int k = 0; k < 3; ++k) {
                    const dd r = dd_add(ap[k], dd_mul(diff[k], t));
                    e = dd_add(e, dd_mul(r, r));
                }
                e = dd_mul_d(e, s2);
                sum += gl10[j][1] * (exp(-e.hi) * (1.0 - e.lo));
            }
        total = dd_add(total, dd_mul_d(half, sum));
        ta = tb;
    }
    return dd_mul(total, len).hi * (double)p->amplitude;
}

static veil_particle random_particle(void)
{
    veil_particle p;
    for (int k = 0; k < 3; ++k) p.center[k] = (float)rnd_in(-1.0, 1.0);
    p.sharpness = (float)(1.0 / rnd_log(0.05, 2.0));
    p.amplitude = (float)rnd_log(0.1, 10.0);
    return p;
}

/* a point at abscissa u (in 1/s units) along w from the centre, offset by
 * dperp (in 1/s units) along a unit vector perpendicular to w */
static void gauss_point(const veil_particle* p, const double w[3], const double perp[3], double u, double dperp,
                        double out[3])
{
    const double r = 1.0 / p->sharpness;
    for (int k = 0; k < 3; ++k) out[k] = p->center[k] + r * (u * w[k] + dperp * perp[k]);
}

static void perpendicular(const double w[3], double perp[3])
{
    double v[3];
    rnd_unit(v);
    const double c = dot3(v, w);
    for (int k = 0; k < 3; ++k) v[k] -= c * w[k];
    const double n = sqrt(dot3(v, v));
    for (int k = 0; k < 3; ++k) perp[k] = v[k] / n;
}

/* Bound (closed_forms.h): 2^-52 (24 + 8 s^2 R^2) for the closed form, plus
 * the reference's 5u. */
static void test_gaussian(void)
{
    static const char* names[] = {"random", "through centre", "tail, one side", "far line", "short", "zero length"};
    double worst[6] = {0}, worst_ratio[6] = {0}, worst_near = 0.0;
    int count[6] = {0}, underflows = 0;
    for (int cs = 0; cs < 1500; ++cs) {
        const int kind = cs < 400 ? 0 : cs < 600 ? 1 : cs < 900 ? 2 : cs < 1100 ? 3 : cs < 1450 ? 4 : 5;
        veil_particle p = random_particle();
        double a[3], b[3], w[3], perp[3];
        rnd_unit(w);
        perpendicular(w, perp);
        switch (kind) {
        case 0:
            for (int k = 0; k < 3; ++k) {
                a[k] = rnd_in(-3.0, 3.0);
                b[k] = rnd_in(-3.0, 3.0);
            }
            break;
        case 1: /* through the centre (to rounding) */
            gauss_point(&p, w, perp, -rnd_in(0.0, 5.0), 0.0, a);
            gauss_point(&p, w, perp, rnd_in(0.0, 5.0), 0.0, b);
            break;
        case 2: { /* both ends on one side, far out: erfc(u0) - erfc(u1) */
            const double u0 = rnd_in(2.0, 25.0), du = rnd_log(1e-3, 10.0), dp = rnd_in(0.0, 1.0);
            gauss_point(&p, w, perp, u0, dp, a);
            gauss_point(&p, w, perp, u0 + du, dp, b);
            if (cs % 2) { /* the mirror: u1 <= 0 */
                double t[3];
                memcpy(t, a, sizeof t);
                memcpy(a, b, sizeof t);
                memcpy(b, t, sizeof t);
            }
            break;
        }
        case 3: { /* a line far from the centre: e^{-(s d)^2} down to e^{-576} */
            const double dp = rnd_in(5.0, 24.0);
            gauss_point(&p, w, perp, rnd_in(-10.0, 5.0), dp, a);
            gauss_point(&p, w, perp, rnd_in(-5.0, 10.0), dp, b);
            break;
        }
        case 4: { /* short: s L in [1e-9, 1] anywhere within |u| <= 20 */
            const double u0 = rnd_in(-20.0, 20.0), du = rnd_log(1e-9, 1.0), dp = rnd_in(0.0, 10.0);
            gauss_point(&p, w, perp, u0, dp, a);
            gauss_point(&p, w, perp, u0 + du, dp, b);
            break;
        }
        default:
            for (int k = 0; k < 3; ++k) a[k] = b[k] = rnd_in(-2.0, 2.0);
            break;
        }
        const double got = veil_gaussian_line_integral(&p, a, b);
        const double ref = gauss_ref(&p, a, b);
        ++count[kind];
        if (kind == 5) {
            CHECK(got == 0.0, "gaussian: zero-length segment gave %.17g", got);
            continue;
        }
        double c[3] = {p.center[0], p.center[1], p.center[2]};
        const double tiny = 1e-290 * p.amplitude / p.sharpness; /* below it: no relative claim */
        if (ref < tiny) {
            ++underflows;
            CHECK(got >= 0.0 && got <= 2.0 * tiny, "gaussian (%s) case %d: %.17g, reference %.17g (tiny)",
                  names[kind], cs, got, ref);
            continue;
        }
        const double sr = p.sharpness * fmax(dist3(a, c), dist3(b, c));
        const double bound = 2.0 * U * (24.0 + 8.0 * sr * sr) + 5.0 * U;
        const double rel = fabs(got - ref) / ref;
        worst[kind] = fmax(worst[kind], rel);
        worst_ratio[kind] = fmax(worst_ratio[kind], rel / bound);
        if (sr < 3.0) worst_near = fmax(worst_near, rel);
        CHECK(isfinite(got) && rel <= bound,
              "gaussian (%s) case %d: %.17g, reference %.17g, rel %.3g > bound %.3g (s R = %.3g)", names[kind], cs,
              got, ref, rel, bound, sr);
    }
    for (int k = 0; k < 6; ++k)
        printf("gaussian %-15s %4d segments: max relative error %.3g, max error/bound %.3f\n", names[k], count[k],
               worst[k], worst_ratio[k]);
    printf("gaussian: %d results below 1e-290 c/s (checked >= 0 and tiny); max relative error with s R < 3: %.3g\n",
           underflows, worst_near);
    /* underflow: s d = 40, e^{-1600}: 0 (or a denormal), never NaN */
    veil_particle p = {{0, 0, 0}, 1.0f, 1.0f};
    const double a[3] = {-5, 40, 0}, b[3] = {5, 40, 0};
    const double v = veil_gaussian_line_integral(&p, a, b);
    CHECK(v >= 0.0 && v < 1e-300, "gaussian: underflow case gave %g", v);
    /* the sum over particles equals the sum of the parts (3u: compensated) */
    veil_particle ps[3] = {random_particle(), random_particle(), random_particle()};
    const double a2[3] = {-2, -1, 0.5}, b2[3] = {2, 1.5, -0.5};
    double parts = 0.0;
    for (int i = 0; i < 3; ++i) parts += veil_gaussian_line_integral(&ps[i], a2, b2);
    CHECK(check_close(veil_rbf_line_integral(ps, 3, a2, b2), parts, 0.0, 4.0 * U), "rbf sum");
}

/* ---- 4. exponential fog -------------------------------------------------- */

/* Reference: rho0 |b - a| times the integral over tau in [0, 1] of
 * exp(-(falloff <a + tau (b - a) - o, n> - shift)), in double-double, by
 * 10-point Gauss-Legendre on equal panels over which the exponent changes
 * by <= 1/2 (truncation < 1e-30), integrated from the denser end and
 * stopped once the integrand is below 1e-30 of its start (the dropped tail
 * is < 1e-30 * 2 |mL| <= 4e-27 relative). Rounding as for the Gaussian:
 * <= 5u. `shift` (exact) keeps e^{-k} in range for results near overflow. */
static double fog_ref(double rho0, double falloff, const double n[3], const double o[3], const double a_in[3],
                      const double b_in[3], double shift)
{
    const double* a = a_in;
    const double* b = b_in;
    double ml = 0.0;
    for (int k = 0; k < 3; ++k) ml += falloff * (b[k] - a[k]) * n[k];
    if (ml < 0.0) { /* start at the denser end */
        a = b_in;
        b = a_in;
        ml = -ml;
    }
    dd diff[3], ao[3], l2 = {0.0, 0.0};
    for (int k = 0; k < 3; ++k) {
        diff[k] = dd_two_sum(b[k], -a[k]);
        ao[k] = dd_two_sum(a[k], -o[k]);
        l2 = dd_add(l2, dd_mul(diff[k], diff[k]));
    }
    if (l2.hi == 0.0) return 0.0;
    const dd len = dd_sqrt(l2);
    const double np = ceil(ml / 0.5) > 1.0 ? ceil(ml / 0.5) : 1.0;
    dd total = {0.0, 0.0};
    double f_first = -1.0;
    for (double ip = 0.0; ip < np; ip += 1.0) {
        const double ta = ip / np, tb = ip + 1.0 >= np ? 1.0 : (ip + 1.0) / np;
        dd mid, half;
        panel(ta, tb, &mid, &half);
        double sum = 0.0, f_start = 0.0;
        for (int j = 0; j < 5; ++j)
            for (int sg = -1; sg <= 1; sg += 2) {
                const dd t = panel_node(mid, half, sg * gl10[j][0]);
                dd e = {0.0, 0.0};
                for (int k = 0; k < 3; ++k) e = dd_add(e, dd_mul_d(dd_add(ao[k], dd_mul(diff[k], t)), n[k]));
                e = dd_add(dd_mul_d(e, falloff), (dd){-shift, 0.0});
                const double f = exp(-e.hi) * (1.0 - e.lo);
                if (j == 0 && sg == -1) f_start = f;
                sum += gl10[j][1] * f;
            }
        total = dd_add(total, dd_mul_d(half, sum));
        if (f_first < 0.0) f_first = f_start;
        if (f_start < 1e-30 * f_first) break;
    }
    return dd_mul(total, len).hi * rho0;
}

/* exponent at the denser end, in plain double (for choosing cases) */
static double fog_kmin(double falloff, const double n[3], const double o[3], const double a[3], const double b[3])
{
    const double ao[3] = {a[0] - o[0], a[1] - o[1], a[2] - o[2]}, bo[3] = {b[0] - o[0], b[1] - o[1], b[2] - o[2]};
    return fmin(falloff * dot3(ao, n), falloff * dot3(bo, n));
}

/* Bound (closed_forms.h): 16u for the closed form, plus the reference's 5u:
 * 21u = 2.3e-15. */
static void test_exp_fog(void)
{
    static const char* names[] = {"generic", "<w,n> = 0", "|mL| tiny", "|mL| ~ 1e3"};
    const double bound = 21.0 * U;
    double worst[4] = {0};
    int count[4] = {0};
    for (int cs = 0; cs < 12000; ++cs) {
        const int kind = cs < 4000 ? 0 : cs < 6000 ? 1 : cs < 9000 ? 2 : 3;
        double n[3], o[3], a[3], b[3], w[3], falloff = 0.0, len;
        const double rho0 = rnd_log(1e-3, 1e3);
        for (int k = 0; k < 3; ++k) {
            o[k] = rnd_in(-2.0, 2.0);
            a[k] = rnd_in(-5.0, 5.0);
        }
        rnd_unit(n);
        rnd_unit(w);
        len = rnd_log(1e-3, 10.0);
        switch (kind) {
        case 0:
            falloff = rnd_log(1e-3, 1e2) * (rnd() < 0.5 ? -1.0 : 1.0);
            for (int k = 0; k < 3; ++k) b[k] = a[k] + len * w[k];
            break;
        case 1: { /* n an axis and b - a in the plane: <b - a, n> = 0 exactly */
            const int ax = cs % 3;
            for (int k = 0; k < 3; ++k) n[k] = k == ax ? (cs % 2 ? 1.0 : -1.0) : 0.0;
            for (int k = 0; k < 3; ++k) b[k] = k == ax ? a[k] : a[k] + len * w[k];
            falloff = rnd_log(1e-3, 1e2);
            break;
        }
        case 2: { /* m L ~ 1e-12 .. 1e-8: either a tiny falloff, or w almost perpendicular to n */
            const double target = rnd_log(1e-12, 1e-8) * (rnd() < 0.5 ? -1.0 : 1.0);
            if (cs % 2) {
                const double c = dot3(w, n);
                for (int k = 0; k < 3; ++k) w[k] -= c * n[k];
                const double nw = sqrt(dot3(w, w));
                for (int k = 0; k < 3; ++k) w[k] = w[k] / nw * sqrt(1.0 - 1e-16) + 1e-8 * n[k];
                falloff = target / (len * 1e-8);
            } else {
                falloff = target / (len * dot3(w, n));
            }
            for (int k = 0; k < 3; ++k) b[k] = a[k] + len * w[k];
            break;
        }
        default: { /* |m L| in [300, 3000], both signs */
            double c = dot3(w, n);
            if (fabs(c) < 0.1) c = c < 0.0 ? -0.1 : 0.1;
            falloff = rnd_log(300.0, 3000.0) / (len * c) * (rnd() < 0.5 ? -1.0 : 1.0);
            for (int k = 0; k < 3; ++k) b[k] = a[k] + len * w[k];
            break;
        }
        }
        /* move o along n so that the denser end's exponent is in [-600, 600]:
         * the result is then well inside the normal double range */
        const double want = rnd_in(-600.0, 600.0), have = fog_kmin(falloff, n, o, a, b);
        if (isfinite(have) && falloff != 0.0) {
            const double shift = (want - have) / falloff;
            for (int k = 0; k < 3; ++k) o[k] -= shift * n[k];
        }
        const double got = veil_exp_fog_line_integral(rho0, falloff, n, o, a, b);
        const double ref = fog_ref(rho0, falloff, n, o, a, b, 0.0);
        const double rel = fabs(got - ref) / ref;
        ++count[kind];
        worst[kind] = fmax(worst[kind], rel);
        CHECK(ref > 0.0 && isfinite(got) && rel <= bound, "exp fog (%s) case %d: %.17g, reference %.17g, rel %.3g",
              names[kind], cs, got, ref, rel);
    }
    for (int k = 0; k < 4; ++k)
        printf("exp fog %-11s %5d segments: max relative error %.3g (%.2f u; bound 21 u)\n", names[k], count[k],
               worst[k], worst[k] / U);

    /* range: the denser end at e^{720} (exp alone would overflow) but
     * |mL| = 8e5 brings the result to ~e^{720}/1e6 = e^{706}: finite and
     * accurate. Checked in log space against the reference scaled by
     * e^{-720}: the log of a number near e^{706} is exact to ~1 ulp(706) =
     * 1.1e-13, so 1e-12. */
    const double n[3] = {0, 0, 1}, o[3] = {0, 0, 0};
    const double a[3] = {0.1, 0.2, -0.00072}, b[3] = {0.1, 0.2, 0.8}; /* k from -720 to 8e5 at falloff 1e6 */
    const double v = veil_exp_fog_line_integral(1.0, 1e6, n, o, a, b);
    const double r = fog_ref(1.0, 1e6, n, o, a, b, -720.0); /* = result * e^{-720} */
    CHECK(isfinite(v) && fabs((log(v) - 720.0) - log(r)) < 1e-12, "exp fog near overflow: %.17g (log %.17g vs %.17g)",
          v, log(v) - 720.0, log(r));
    /* the same with the segment reversed (density increasing along a -> b) */
    const double v2 = veil_exp_fog_line_integral(1.0, 1e6, n, o, b, a);
    CHECK(v2 == v, "exp fog: reversing the segment changed %.17g to %.17g", v, v2);
    /* true overflow: the denser end at e^{760}, |mL| = 40 */
    const double c3[3] = {0, 0, -7.6}, d3[3] = {0, 0, -7.2};
    const double vo = veil_exp_fog_line_integral(1.0, 100.0, n, o, c3, d3);
    CHECK(vo == INFINITY, "exp fog: e^760 should overflow to +inf, got %g", vo);
    /* true underflow: e^{-800}: 0 */
    const double e3[3] = {0, 0, 8.0}, f3[3] = {0, 0, 9.0};
    const double vu = veil_exp_fog_line_integral(1.0, 100.0, n, o, e3, f3);
    CHECK(vu == 0.0, "exp fog: e^-800 should underflow to 0, got %g", vu);
    /* zero length, zero falloff */
    CHECK(veil_exp_fog_line_integral(2.0, 5.0, n, o, a, a) == 0.0, "exp fog: zero length");
    const double g3[3] = {1.0, 2.0, 3.0}, h3[3] = {1.0, 2.0, 11.0};
    CHECK(veil_exp_fog_line_integral(2.0, 0.0, n, o, g3, h3) == 2.0 * 8.0, "exp fog: zero falloff is rho0 * L");
}

int main(void)
{
    test_gaussian();
    test_exp_fog();
    return check_finish();
}
