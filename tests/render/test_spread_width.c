/* The screen-space spread's CPU parts: Premoze's width W (core/shared.glsl.h,
 * the same function the shaders run), the level selection, and the
 * gathering reference filter (reference/gather.h).
 *
 * W^2 = 1 / (2 (2 sa / (3 s) + 4 / (s^3 ss (1 - g)))) (Eq. 1 as printed) is
 * evaluated here in double as the ground truth; veil_spread_width computes
 * the algebraically equal k s / (8/s^2 + (4/3) sa k) in float. Rounding: a
 * handful of float operations, each within 2^-24, then a square root that
 * halves the relative error: |rel| <= 8 2^-24 = 4.8e-7 (we allow 1e-6).
 * Limits (each would divide by zero or make 0/0 or inf/inf in Eq. 1 as
 * printed): s -> 0 and s = 0, ss = 0, g = 1 give W = 0; sa = 0 gives
 * s^1.5 sqrt(ss (1 - g) / 8); s -> inf saturates at sqrt(3 s / (4 sa));
 * s = FLT_MAX and tiny s (s^2 underflows) stay finite or 0; no NaN anywhere.
 *
 * The gathering filter on an image whose W is the same everywhere is a
 * convolution with one kernel: checked against that convolution computed
 * separably (rows, then columns: a different loop and summation order),
 * to double rounding carried into float (|rel| <= 2^-23 of the pixel plus
 * 1e-12 absolute for the summation order). Its weights sum to 1 over the
 * lattice within 2 Phi(-6) per axis, and W = 0 is the identity. */
#include <float.h>
#include <math.h>
#include <stdlib.h>

#include "support/check.h"
#include "core/shared.glsl.h"
#include "reference/gather.h"

static double eq1(double s, double sa, double ss, double g)
{
    return sqrt(1.0 / (2.0 * (2.0 * sa / (3.0 * s) + 4.0 / (s * s * s * ss * (1.0 - g)))));
}

static void widths(void)
{
    const double sas[] = {0.001, 0.08, 0.5, 3.0}, sss[] = {0.01, 1.0, 6.0}, gs[] = {-0.5, 0.0, 0.3, 0.9};
    const double svals[] = {1e-3, 0.05, 1.0, 4.5, 80.0, 3000.0};
    double worst = 0.0;
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 3; ++b)
            for (int c = 0; c < 4; ++c)
                for (int d = 0; d < 6; ++d) {
                    double want = eq1(svals[d], sas[a], sss[b], gs[c]);
                    double got = veil_spread_width((float)svals[d], (float)sas[a], (float)sss[b], (float)gs[c]);
                    /* the inputs are rounded to float too: W ~ s^1.5 ss^0.5 at most, 2.5 2^-24 more */
                    double want_f = eq1((float)svals[d], (float)sas[a], (float)sss[b], (float)gs[c]);
                    double rel = fabs(got - want_f) / want_f;
                    if (rel > worst) worst = rel;
                    CHECK(check_close(got, want, 0.0, 1e-6 + 3e-7), "W(s=%g, sa=%g, ss=%g, g=%g) = %.9g, Eq. 1: %.9g",
                          svals[d], sas[a], sss[b], gs[c], got, want);
                }
    CHECK(worst <= 1e-6, "worst relative difference from Eq. 1 (float inputs) %.3g > 1e-6", worst);
    /* limits */
    CHECK(veil_spread_width(0.0f, 0.1f, 1.0f, 0.3f) == 0.0f, "W(P = 0) must be 0");
    CHECK(veil_spread_width(1e-30f, 0.1f, 1.0f, 0.3f) == 0.0f, "W(P = 1e-30: s^2 underflows) must be 0");
    float tiny = veil_spread_width(1e-6f, 0.1f, 1.0f, 0.3f);
    CHECK(tiny >= 0.0f && tiny < 1e-8f, "W(P = 1e-6) = %g: expected ~ (1e-6)^1.5 sqrt(0.7/8) = 3e-10", tiny);
    CHECK(veil_spread_width(2.0f, 0.1f, 0.0f, 0.3f) == 0.0f, "W(sigma_s = 0) must be 0");
    CHECK(veil_spread_width(2.0f, 0.1f, 1e-30f, 0.3f) >= 0.0f, "W(sigma_s = 1e-30) finite");
    CHECK(veil_spread_width(2.0f, 0.1f, 1.0f, 1.0f) == 0.0f, "W(g = 1) must be 0");
    float near1 = veil_spread_width(2.0f, 0.1f, 1.0f, 0.999999f);
    double near1_want = eq1(2.0, 0.1f, 1.0, (double)0.999999f); /* ~ sqrt(2 * 1e-6 / 2) = 1e-3 */
    CHECK(check_close(near1, near1_want, 0.0, 1e-5) && near1 < veil_spread_width(2.0f, 0.1f, 1.0f, 0.9f) / 100.0f,
          "W(g -> 1) = %g: expected Eq. 1's %g, -> 0 as sqrt(1 - g)", near1, near1_want);
    double sa0 = pow(3.0, 1.5) * sqrt(1.5 * (1.0 - 0.3) / 8.0);
    CHECK(check_close(veil_spread_width(3.0f, 0.0f, 1.5f, 0.3f), sa0, 0.0, 1e-6),
          "W(sigma_a = 0) = %g, closed form s^1.5 sqrt(ss (1-g)/8) = %g", veil_spread_width(3.0f, 0.0f, 1.5f, 0.3f),
          sa0);
    double sat = sqrt(3.0 * 1e12 / (4.0 * 0.2));
    CHECK(check_close(veil_spread_width(1e12f, 0.2f, 1.0f, 0.3f), sat, 0.0, 1e-5),
          "W(s = 1e12) = %g: saturates at sqrt(3 s / (4 sa)) = %g", veil_spread_width(1e12f, 0.2f, 1.0f, 0.3f), sat);
    float big = veil_spread_width(FLT_MAX, 0.2f, 1.0f, 0.3f), big0 = veil_spread_width(FLT_MAX, 0.0f, 1.0f, 0.3f);
    CHECK(!isnan(big) && !isnan(big0), "W(s = FLT_MAX) = %g, with sigma_a = 0: %g (no NaN)", big, big0);
    CHECK(!isnan(veil_spread_width(INFINITY, 0.2f, 1.0f, 0.3f)), "W(s = inf) is not NaN");
    /* levels: k = clamp(log2(w / c), 0, K) */
    CHECK(veil_spread_level(0.0f, 0.86f, 7.0f) == 0.0f, "level of W = 0");
    CHECK(veil_spread_level(0.5f, 0.86f, 7.0f) == 0.0f, "level of W < c");
    CHECK(check_close(veil_spread_level(0.86f * 8.0f, 0.86f, 7.0f), 3.0, 1e-6, 0.0), "level of 8 c is 3");
    CHECK(veil_spread_level(INFINITY, 0.86f, 7.0f) == 7.0f, "level of W = inf is K");
    CHECK(veil_spread_level(1e30f, 0.86f, 5.0f) == 5.0f, "level of a huge W is K");
}

static void gather_is_convolution(void)
{
    enum { W = 37, H = 29 };
    const double sigma = 2.3;
    float* L = calloc(W * H * 4, sizeof *L);
    float* Ws = malloc(W * H * sizeof *Ws);
    float* out = malloc(W * H * 4 * sizeof *out);
    double* tmp = calloc(W * H * 3, sizeof *tmp);
    double* conv = calloc(W * H * 3, sizeof *conv);
    if (!L || !Ws || !out || !tmp || !conv) {
        CHECK(0, "out of memory");
        return;
    }
    uint32_t seed = 12345u;
    for (int i = 0; i < W * H; ++i) {
        for (int c = 0; c < 3; ++c) {
            seed = seed * 1664525u + 1013904223u;
            L[4 * i + c] = (seed >> 8) % 5 == 0 ? (float)((seed >> 12) % 1000) / 100.0f : 0.0f;
        }
        Ws[i] = (float)sigma;
    }
    veil_error err = {0};
    CHECK(veil_gather_spread(W, H, L, Ws, out, &err) == VEIL_OK, "%s", err.msg);
    int R = (int)ceil(VEIL_GATHER_SIGMAS * sigma);
    /* rows: tmp(x, y) = sum_u L(u, y) g(x - u); then columns */
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int u = x - R; u <= x + R; ++u)
                if (u >= 0 && u < W)
                    for (int c = 0; c < 3; ++c)
                        tmp[3 * (y * W + x) + c] += L[4 * (y * W + u) + c] * veil_gather_weight(x - u, sigma);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            for (int v = y - R; v <= y + R; ++v)
                if (v >= 0 && v < H)
                    for (int c = 0; c < 3; ++c)
                        conv[3 * (y * W + x) + c] += tmp[3 * (v * W + x) + c] * veil_gather_weight(y - v, sigma);
    double worst = 0.0;
    for (int i = 0; i < W * H; ++i)
        for (int c = 0; c < 3; ++c) {
            double d = fabs(out[4 * i + c] - conv[3 * i + c]);
            double tol = 1.2e-7 * fabs(conv[3 * i + c]) + 1e-12;
            if (d - tol > worst) worst = d - tol;
        }
    CHECK(worst <= 0.0, "gathering differs from the separable convolution by %.3g beyond its bound", worst);
    /* the weights sum to 1 over the lattice (up to the cut at 6 sigma) */
    double sum = 0.0;
    for (int d = -R; d <= R; ++d) sum += veil_gather_weight(d, sigma);
    CHECK(fabs(sum - 1.0) <= 4e-9 + 1e-15, "1D weights sum to %.12f, expected 1 within 2 Phi(-6)", sum);
    /* W = 0: the identity */
    for (int i = 0; i < W * H; ++i) Ws[i] = 0.0f;
    CHECK(veil_gather_spread(W, H, L, Ws, out, &err) == VEIL_OK, "%s", err.msg);
    int same = 1;
    for (int i = 0; i < W * H; ++i)
        for (int c = 0; c < 3; ++c) same &= out[4 * i + c] == L[4 * i + c];
    CHECK(same, "W = 0 must leave every pixel as it is");
    Ws[7] = NAN;
    CHECK(veil_gather_spread(W, H, L, Ws, out, &err) == VEIL_ERR_INVALID, "a NaN spread must be refused");
    free(L), free(Ws), free(out), free(tmp), free(conv);
}

int main(void)
{
    widths();
    gather_is_convolution();
    return check_finish();
}
