/* veil — would 16-bit half floats do for the extinction volume (EV, r32f
 * density) and the optical-depth volume (OPV, rgba32f D per light)?
 *
 *   half_float [--n N] [--no-gpu]      (N^3 grids, default 64)
 *
 * Half rounding is emulated on the CPU (half_bits/half_value below: round
 * to nearest even, overflow to inf, subnormals; checked against known
 * values, every half code, every rounding boundary, and the compiler's
 * _Float16 where it has one). Then, on the homogeneous, rbf-fog and smoke
 * media of bench/media.h (2 m box):
 *  1. EV: each density scale 1e-6 ... 1e6 times the medium, stored as half:
 *     relative error of the voxel densities, and of the exact optical depth
 *     (reference/optical_depth.h) through the rounded field at sampled
 *     points toward three lights; overflowed (> 65504 -> inf), subnormal
 *     (< 2^-14 = 6.1e-5: fewer significant bits) and flushed (< 2^-25 ->
 *     0) voxels; and the same with a scale factor (rho / rho_max stored).
 *  2. OPV: D from veil_opv_cpu (the default method) rounded to half, and
 *     T = exp(-sigma_t D): the error in T per decade of tau = sigma_t D
 *     against the model |dT| <= T tau 2^-11; then D's range over voxel
 *     sizes 1e-4 ... 1e4 m and density scales 1e-6 ... 1e6 (D is in
 *     density * m: it scales with both; sigma_t is set so that a path
 *     across the box at the peak density has tau = 4, so only the half
 *     range changes T); and storing tau instead of D.
 *  3. GPU (skipped with --no-gpu or without GL 4.5): the driver's own
 *     float -> half conversion (texture upload, imageStore) against the
 *     emulation; what trilinear filtering makes of an inf texel; and the
 *     renderer's image when the EV or the OPV holds inf.
 * Output: plain-text tables on stdout (docs/results/half-float.txt).
 * Exit status 1 when the emulation fails its self-test. */
#include <epoxy/gl.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "media.h"
#include "propagate/opv.h"
#include "reference/optical_depth.h"
#include "gpu/gl_context.h"
#include "gpu/gl_util.h"
#include "frame/renderer.h"

#define HALF_MAX 65504.0
#define HALF_MIN_NORMAL 0x1p-14 /* 6.1e-5 */
#define HALF_EPS 0x1p-11        /* unit roundoff: relative error of a rounded normal half */
#define SAMPLES 400
#define N_MEDIA 3

static const int media[N_MEDIA] = {MEDIUM_HOMOGENEOUS, MEDIUM_RBF_FOG, MEDIUM_SMOKE};
static const char* const media_names[N_MEDIA] = {"homogeneous", "rbf-fog", "smoke"};

/* inside the medium, ~1 box width outside it, and a sun (as bench/propagation.c) */
static const veil_light lights[3] = {
    {.type = VEIL_LIGHT_POINT, .position = {0.0637f, 0.1437f, -0.0533f}, .color = {1, 1, 1}},
    {.type = VEIL_LIGHT_POINT, .position = {-2.83f, 1.61f, 1.17f}, .color = {1, 1, 1}},
    {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0.48f, -0.8f, 0.36f}, .color = {1, 1, 1}},
};

/* ---- half precision, emulated --------------------------------------------- */

static uint32_t bits_of(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static float float_of(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* float -> IEEE binary16, round to nearest, ties to even; overflow to inf. */
static uint16_t half_bits(float f)
{
    const uint32_t x = bits_of(f), sign = (x >> 16) & 0x8000u, ax = x & 0x7fffffffu;
    if (ax > 0x7f800000u) return (uint16_t)(sign | 0x7e00u | ((ax >> 13) & 0x3ffu)); /* NaN stays NaN */
    if (ax >= 0x477ff000u) return (uint16_t)(sign | 0x7c00u); /* >= 65520 (the tie above 65504): inf */
    if (ax >= 0x38800000u) {                                  /* normal half: >= 2^-14 */
        uint32_t h = (ax - 0x38000000u) >> 13, rem = ax & 0x1fffu; /* rebias 127 -> 15 */
        if (rem > 0x1000u || (rem == 0x1000u && (h & 1u))) ++h;    /* a carry moves into the exponent */
        return (uint16_t)(sign | h);
    }
    if (ax <= 0x33000000u) return (uint16_t)sign; /* <= 2^-25: 0 (2^-25 itself ties to the even 0) */
    /* subnormal half: units of 2^-24; the float is m 2^(e - 150), m with its hidden bit */
    const uint32_t e = ax >> 23, m = (ax & 0x7fffffu) | 0x800000u, shift = 126u - e; /* 14 ... 24 */
    uint32_t h = m >> shift, rem = m & ((1u << shift) - 1u), halfway = 1u << (shift - 1u);
    if (rem > halfway || (rem == halfway && (h & 1u))) ++h;
    return (uint16_t)(sign | h);
}

static float half_value(uint16_t h)
{
    const uint32_t sign = (uint32_t)(h & 0x8000u) << 16, e = (h >> 10) & 0x1fu, m = h & 0x3ffu;
    if (e == 0) return sign ? -ldexpf((float)m, -24) : ldexpf((float)m, -24);
    if (e == 31) return float_of(sign | 0x7f800000u | (m << 13));
    return float_of(sign | ((e + 112u) << 23) | (m << 13));
}

static float to_half(float f) { return half_value(half_bits(f)); }

/* Rounded toward zero, overflow clamped to 65504: what llvmpipe's imageStore
 * to an r16f image does (section 3 measures it). Finite f >= 0 only. */
static float to_half_rtz(float f)
{
    if (f >= 65504.0f) return 65504.0f;
    float h = to_half(f);
    if (h > f) h = half_value((uint16_t)(half_bits(f) - 1u)); /* rounded up: take the code below */
    return h;
}

static int selftest(void)
{
    static const struct {
        float f;
        uint16_t h;
    } known[] = {
        {1.0f, 0x3c00}, {-2.0f, 0xc000}, {0.1f, 0x2e66}, {1.0f / 3.0f, 0x3555}, {65504.0f, 0x7bff},
        {65519.996f, 0x7bff}, {65520.0f, 0x7c00}, {1e5f, 0x7c00}, {INFINITY, 0x7c00}, {-INFINITY, 0xfc00},
        {0x1p-14f, 0x0400}, {0x1.ff8p-15f, 0x03ff}, {0x1p-24f, 0x0001}, {0x1p-25f, 0x0000},
        {0x1.8p-25f, 0x0001}, {0x1.8p-24f, 0x0002}, {0x1p-26f, 0x0000}, {6.0e-8f, 0x0001}, {2.9e-8f, 0x0000},
        {1.0f + 0x1p-11f, 0x3c00}, {1.0f + 0x3p-11f, 0x3c02}, {0x1.ffep0f, 0x4000}, {-0.0f, 0x8000},
        {0.0f, 0x0000},
    };
    int fails = 0, checks = 0;
    for (size_t i = 0; i < sizeof known / sizeof known[0]; ++i, ++checks)
        if (half_bits(known[i].f) != known[i].h) {
            printf("  self-test: %a -> 0x%04x, expected 0x%04x\n", known[i].f, half_bits(known[i].f), known[i].h);
            ++fails;
        }
    uint16_t nan = half_bits(NAN);
    checks++, fails += !((nan & 0x7c00u) == 0x7c00u && (nan & 0x3ffu) && isnan(half_value(nan)));
    /* every finite code round-trips; between neighbours, the midpoint goes to
     * the even code and the floats just beside it to the nearer code (the
     * midpoint of two halves is exact in float: 11 vs 24 significant bits) */
    for (uint32_t h = 0; h < 0x7c00u; ++h) {
        const float f = half_value((uint16_t)h), fn = half_value((uint16_t)(h + 1));
        checks += 2;
        fails += half_bits(f) != h;
        fails += half_bits(-f) != (h | 0x8000u);
        if (h == 0x7bffu) break; /* above 65504 the known values check the overflow threshold (65520) */
        const float mid = 0.5f * (f + fn);
        const uint32_t even = (h & 1u) ? h + 1 : h;
        checks += 3;
        fails += half_bits(mid) != even;
        fails += half_bits(nextafterf(mid, 0.0f)) != h;
        fails += half_bits(nextafterf(mid, INFINITY)) != h + 1;
    }
    int compiler = 0;
#ifdef __FLT16_MAX__
    /* the compiler's conversion on 4M pseudo-random float bit patterns */
    uint32_t s = 12345u;
    for (int i = 0; i < 4000000; ++i, ++checks) {
        s = s * 1664525u + 1013904223u;
        float f = float_of(s);
        if (isnan(f)) continue;
        volatile _Float16 c = (_Float16)f;
        float cf = (float)c;
        if (bits_of(cf) != bits_of(to_half(f))) ++fails;
    }
    compiler = 1;
#endif
    printf("half conversion self-test: %d checks (known values, all %u finite codes and rounding boundaries%s), "
           "%d failures\n\n",
           checks, 0x7c00u, compiler ? ", 4M random floats against the compiler's _Float16" : "", fails);
    return fails;
}

/* ---- section 1: the extinction volume ------------------------------------- */

static uint64_t rng_state = 0x5eed0f0bULL;
static double uniform01(void) { return veil_rng_double53(&rng_state); }

typedef struct depth_err {
    double max_rel, max_dT;
    int nonfinite;
} depth_err;

/* Exact optical depth through `test` against `ref` at the sample points,
 * and the transmittance error it makes with extinction sigma_t per unit density. */
static depth_err depth_errors(const veil_grid* g, const float* ref, const float* test, const double (*pts)[3],
                              double sigma_t)
{
    depth_err e = {0};
    for (int l = 0; l < 3; ++l)
        for (int i = 0; i < SAMPLES; ++i) {
            double d0 = veil_ref_optical_depth(g, ref, &lights[l], pts[i], 1.0);
            double d1 = veil_ref_optical_depth(g, test, &lights[l], pts[i], 1.0);
            if (!isfinite(d1)) {
                ++e.nonfinite;
                continue;
            }
            e.max_dT = fmax(e.max_dT, fabs(exp(-sigma_t * d1) - exp(-sigma_t * d0)));
            if (d0 > 0.0) e.max_rel = fmax(e.max_rel, fabs(d1 - d0) / d0);
        }
    return e;
}

static void ev_section(const veil_grid* g, float* const base[N_MEDIA])
{
    size_t nv = veil_grid_voxels(g);
    double(*pts)[3] = malloc(SAMPLES * sizeof *pts);
    float *f = malloc(nv * sizeof(float)), *h = malloc(nv * sizeof(float)), *hs = malloc(nv * sizeof(float));
    for (int i = 0; i < SAMPLES; ++i)
        for (int a = 0; a < 3; ++a) pts[i][a] = BOX_LO + BOX_WIDTH * uniform01();
    printf("== 1. EV: density stored as half (GL_R16F) instead of float ==\n");
    printf("rel err: |half(rho) - rho| / rho over voxels with rho > 0; %%sub: voxels 0 < rho < 2^-14 (subnormal);\n"
           "%%zero: rho > 0 flushed to 0; %%inf: rho > 65504 -> inf. D: exact optical depth through the half field\n"
           "against the float field, %d points x 3 lights: max relative error, how many came out inf or NaN, and\n"
           "max |dT| with sigma_t = 4 / (box width * peak) (a path across the box at the peak has tau = 4).\n"
           "'scaled': rho / peak stored in half and multiplied by the peak when read.\n",
           SAMPLES);
    printf("%-12s %6s %9s %9s %9s %6s %6s %6s | %9s %6s %9s | %9s %9s\n", "medium", "scale", "peak", "max rel",
           "rms rel", "%sub", "%zero", "%inf", "D max rel", "nonfin", "max |dT|", "scaled D", "max |dT|");
    for (int m = 0; m < N_MEDIA; ++m) {
        for (int e = -6; e <= 6; ++e) {
            double scale = pow(10.0, e), peak = 0.0, max_rel = 0.0, sum2 = 0.0;
            size_t nz = 0, sub = 0, zero = 0, inf = 0;
            for (size_t v = 0; v < nv; ++v) {
                f[v] = (float)((double)base[m][v] * scale);
                peak = fmax(peak, f[v]);
            }
            for (size_t v = 0; v < nv; ++v) {
                h[v] = to_half(f[v]);
                hs[v] = (float)((double)to_half((float)(f[v] / peak)) * peak);
                if (!(f[v] > 0.0f)) continue;
                ++nz;
                if (isinf(h[v])) {
                    ++inf;
                    continue;
                }
                sub += h[v] < HALF_MIN_NORMAL && h[v] > 0.0f;
                zero += h[v] == 0.0f;
                double r = fabs((double)h[v] - f[v]) / f[v];
                max_rel = fmax(max_rel, r);
                sum2 += r * r;
            }
            const double sigma_t = 4.0 / (BOX_WIDTH * peak);
            depth_err d = depth_errors(g, f, h, (const double(*)[3])pts, sigma_t);
            depth_err ds = depth_errors(g, f, hs, (const double(*)[3])pts, sigma_t);
            printf("%-12s %6.0e %9.3g %9.3g %9.3g %6.2f %6.2f %6.2f | %9.3g %6d %9.3g | %9.3g %9.3g\n",
                   media_names[m], scale, peak, max_rel, sqrt(sum2 / (double)(nz - inf ? nz - inf : 1)),
                   100.0 * sub / nz, 100.0 * zero / nz, 100.0 * inf / nz, d.max_rel, d.nonfinite, d.max_dT,
                   ds.max_rel, ds.max_dT);
            if (ds.nonfinite) printf("  (scaled: %d non-finite)\n", ds.nonfinite);
        }
    }
    printf("(a normal half is within 2^-11 = %.3g of its float, so D, a positive combination of voxel values, is too)\n\n",
           HALF_EPS);
    free(pts);
    free(f);
    free(h);
    free(hs);
}

/* ---- section 2: the optical-depth volume ---------------------------------- */

#define TAU_DECADES 9 /* bins [1e-4, 1e-3) ... [1e4, 1e5) */

static void opv_section(const veil_grid* g, float* const base[N_MEDIA])
{
    size_t nv = veil_grid_voxels(g);
    veil_index_light ol[3];
    for (int l = 0; l < 3; ++l) veil_light_to_index(&lights[l], g->dims, g->origin, g->voxel, &ol[l]);
    float* D[N_MEDIA];
    double peak[N_MEDIA];
    veil_opv_params params = {.method = VEIL_OPV_DEFAULT};
    for (int m = 0; m < N_MEDIA; ++m) {
        veil_error err = {0};
        D[m] = malloc(3 * nv * sizeof(float));
        int it = 0;
        if (!D[m] || veil_opv_cpu(g, base[m], ol, 3, &params, D[m], &it, &err) != VEIL_OK) {
            fprintf(stderr, "half_float: propagation failed: %s\n", err.msg);
            exit(1);
        }
        peak[m] = 0.0;
        for (size_t v = 0; v < nv; ++v) peak[m] = fmax(peak[m], base[m][v]);
    }

    /* 2a: the error in T per decade of tau (all media, lights and voxels, a
     * sweep of sigma_t so that every decade is filled) */
    printf("== 2. OPV: optical depth D (density * m) stored as half (GL_RGBA16F) instead of float ==\n");
    double dmin = INFINITY, dmax = 0.0;
    for (int m = 0; m < N_MEDIA; ++m)
        for (size_t v = 0; v < 3 * nv; ++v)
            if (D[m][v] > 0.0f) dmin = fmin(dmin, D[m][v]), dmax = fmax(dmax, D[m][v]);
    printf("2a. T = exp(-sigma_t D) against T from half(D), per decade of tau = sigma_t D (box 2 m, voxel %.4g m,\n"
           "positive D in [%.3g, %.3g], those >= 2^-14 (normal halves) here; sigma_t swept 1e-5 ... 1e6 per m);\n"
           "model: |dT| <= T tau 2^-11 (columns with T > 1e-30)\n",
           g->voxel, dmin, dmax);
    double bmax[TAU_DECADES] = {0}, brel[TAU_DECADES] = {0}, bmodel[TAU_DECADES] = {0};
    long bn[TAU_DECADES] = {0};
    for (int m = 0; m < N_MEDIA; ++m)
        for (size_t v = 0; v < 3 * nv; ++v) {
            const double d = D[m][v], dh = to_half(D[m][v]);
            if (!(d >= HALF_MIN_NORMAL)) continue; /* the model is for normal halves; 2b shows the rest */
            for (int k = -20; k <= 24; ++k) { /* sigma_t 1e-5 ... 1e6 m^-1, quarter decades */
                double st = pow(10.0, k / 4.0), tau = st * d;
                int b = (int)floor(log10(tau)) + 4;
                if (b < 0 || b >= TAU_DECADES) continue;
                double T = exp(-tau), dT = fabs(exp(-st * dh) - T);
                bmax[b] = fmax(bmax[b], dT);
                if (T > 1e-30) brel[b] = fmax(brel[b], dT / T), bmodel[b] = fmax(bmodel[b], dT / (T * tau * HALF_EPS));
                ++bn[b];
            }
        }
    printf("%-16s %10s %12s %12s %14s\n", "tau", "samples", "max |dT|", "max |dT|/T", "max |dT|/model");
    for (int b = 0; b < TAU_DECADES; ++b)
        printf("[%7.0e,%6.0e) %10ld %12.3g %12.3g %14.3f\n", pow(10.0, b - 4), pow(10.0, b - 3), bn[b], bmax[b],
               brel[b], bmodel[b]);
    printf("(max of T tau 2^-11 over tau is e^-1 2^-11 = %.3g at tau = 1; an 8-bit display step is 1/255 = %.3g)\n\n",
           exp(-1.0) * HALF_EPS, 1.0 / 255.0);

    /* 2b: D's range: the medium scaled in density and in size */
    printf("2b. the same media and lights at other voxel sizes and density scales: D = D_base * scale * voxel / "
           "voxel_base,\nsigma_t = 4 / (box width * peak density) (tau is the same in every cell; only half's range "
           "differs).\nCell: max |dT| over all voxels and lights; (o) overflow: some D > 65504 stored as inf (T = 0);\n"
           "(u) underflow: some D subnormal or flushed to 0, and max |dT| above the normal-range bound e^-1 2^-11.\n");
    static const double scales[7] = {1e-6, 1e-4, 1e-2, 1, 1e2, 1e4, 1e6};
    for (int m = 0; m < N_MEDIA; ++m) {
        printf("%s: voxel (m) \\ density scale\n%10s", media_names[m], "");
        for (int c = 0; c < 7; ++c) printf(" %12.0e", scales[c]);
        printf("\n");
        for (int ve = -4; ve <= 4; ++ve) {
            const double voxel = pow(10.0, ve);
            printf("%10.0e", voxel);
            for (int c = 0; c < 7; ++c) {
                const double k = scales[c] * voxel / g->voxel;
                const double st = 4.0 / (g->dims[0] * voxel * peak[m] * scales[c]);
                double worst = 0.0;
                int over = 0, under = 0;
                for (size_t v = 0; v < 3 * nv; ++v) {
                    const float d = (float)(D[m][v] * k);
                    if (!(d > 0.0f)) continue;
                    const float dh = to_half(d);
                    over |= isinf(dh);
                    under |= dh < HALF_MIN_NORMAL;
                    worst = fmax(worst, fabs(exp(-st * (double)dh) - exp(-st * (double)d)));
                }
                under &= worst > 1.1 * exp(-1.0) * HALF_EPS;
                printf(" %8.2g%s", worst, over ? "(o) " : under ? "(u) " : "    ");
            }
            printf("\n");
        }
    }
    /* 2c: tau instead of D: sigma_t,max * D is unitless and independent of the scene's scale */
    double worst_tau = 0.0;
    for (int m = 0; m < N_MEDIA; ++m) {
        const double st = 4.0 / (BOX_WIDTH * peak[m]);
        for (size_t v = 0; v < 3 * nv; ++v) {
            const float tau = (float)(st * D[m][v]);
            worst_tau = fmax(worst_tau, fabs(exp(-(double)to_half(tau)) - exp(-(double)tau)));
        }
    }
    printf("2c. storing tau = sigma_t,max D (unitless) in half instead of D: max |dT| = %.3g at every voxel size and\n"
           "density scale (tau does not change with them); tau > 65504 would still overflow, but T = exp(-65504) = 0 "
           "there.\n\n",
           worst_tau);
    for (int m = 0; m < N_MEDIA; ++m) free(D[m]);
}

/* 2d: the OPV is not only stored: propagation reads the D of the voxels
 * upwind and adds to it, so a half texture rounds at every step. For a sun
 * along -y the update is the recurrence D_j = D_{j+1} + h (rho_j +
 * rho_{j+1}) / 2 down each column; run in float and with every stored D
 * rounded (to nearest even, and toward zero as llvmpipe's imageStore does). */
static void propagation_section(void)
{
    static const int sizes[3] = {64, 256, 1024};
    printf("2d. propagating through a half texture: a sun along -y, D_j = D_(j+1) + h (rho_j + rho_(j+1)) / 2 "
           "down each\ncolumn with every stored D rounded; errors against the float recurrence; density 0.7 x the "
           "medium's,\nsigma_t = 4 / (box width * peak); 16 x N x 16 columns for N > 64\n");
    printf("%-12s %5s | %10s %10s | %10s %10s\n", "medium", "N", "RNE D rel", "RNE |dT|", "RTZ D rel", "RTZ |dT|");
    for (int m = 0; m < N_MEDIA; ++m)
        for (int si = 0; si < 3; ++si) {
            const int n = sizes[si];
            veil_grid g = bench_grid(n);
            g.dims[0] = g.dims[2] = n > 64 ? 16 : n; /* 16 x n x 16 columns for the larger grids */
            g.origin[0] = g.origin[2] = -g.voxel * g.dims[0] / 2.0f;
            veil_error err = {0};
            float* rho = make_medium(media[m], &g, &err);
            if (!rho) {
                fprintf(stderr, "half_float: %s\n", err.msg);
                exit(1);
            }
            double peak = 0.0, rel[2] = {0, 0}, dT[2] = {0, 0};
            for (size_t v = 0; v < veil_grid_voxels(&g); ++v) peak = fmax(peak, rho[v]);
            const double st = 4.0 / (BOX_WIDTH * 0.7 * peak);
            for (int k = 0; k < g.dims[2]; ++k)
                for (int i = 0; i < g.dims[0]; ++i) {
                    float df = 0.0f, dh[2] = {0.0f, 0.0f};
                    for (int j = g.dims[1] - 2; j >= 0; --j) {
                        const size_t a = ((size_t)k * g.dims[1] + j) * g.dims[0] + i, b = a + g.dims[0];
                        /* times 0.7: density 1 and voxels of 2^-k m would add exactly */
                        const float step = g.voxel * (0.7f * rho[a] + 0.7f * rho[b]) * 0.5f;
                        df = df + step;
                        dh[0] = to_half(dh[0] + step);
                        dh[1] = to_half_rtz(dh[1] + step);
                        for (int r = 0; r < 2; ++r) {
                            if (df > 0.0f) rel[r] = fmax(rel[r], fabs((double)dh[r] - df) / df);
                            dT[r] = fmax(dT[r], fabs(exp(-st * dh[r]) - exp(-st * df)));
                        }
                    }
                }
            printf("%-12s %5d | %10.3g %10.3g | %10.3g %10.3g\n", media_names[m], n, rel[0], dT[0], rel[1], dT[1]);
            free(rho);
        }
    printf("(one rounding of the final D: relative error <= 2^-11 = %.3g, |dT| <= %.3g; section 2a)\n\n", HALF_EPS,
           exp(-1.0) * HALF_EPS);
}

/* ---- section 3: on the GPU ------------------------------------------------ */

static const char store_src[] =
    "layout(local_size_x = 64) in;\n"
    "layout(std430, binding = 0) readonly buffer In { float vals[]; };\n"
    "layout(binding = 0, r16f) writeonly uniform image3D u_img;\n"
    "uniform int u_n;\n"
    "void main() { int i = int(gl_GlobalInvocationID.x); if (i < u_n) imageStore(u_img, ivec3(i, 0, 0), vec4(vals[i])); }\n";

static const char filter_src[] =
    "layout(local_size_x = 1) in;\n"
    "layout(std430, binding = 0) readonly buffer In { float xs[]; };\n"
    "layout(std430, binding = 1) writeonly buffer Out { float res[]; };\n"
    "uniform sampler3D u_tex;\n"
    "void main() { int i = int(gl_GlobalInvocationID.x); res[i] = texture(u_tex, vec3(xs[i], 0.5, 0.5)).r; }\n";

/* Test values: every kind of float around half's range. */
static int gpu_values(float* v, int cap)
{
    int n = 0;
    static const float fixed[] = {1.0f, 0.1f, 1.0f / 3.0f, 65504.0f, 65519.0f, 65520.0f, 1e5f, 3e38f,
                                  0x1p-14f, 0x1p-24f, 0x1p-25f, 0x1.8p-25f, 6e-8f, 1e-9f, 1.0f + 0x1p-11f,
                                  1.0f + 0x3p-11f, 0x1.ffep0f};
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; ++i) v[n++] = fixed[i];
    while (n < cap) v[n++] = (float)pow(10.0, -9.0 + 15.0 * uniform01()); /* 1e-9 ... 1e6 */
    return n;
}

static void gpu_conversion(veil_error* err)
{
    enum { NV = 2048 };
    float vals[NV], back[NV];
    int n = gpu_values(vals, NV), dims[3] = {NV, 1, 1};
    GLuint tex = 0, prog = 0, buf = 0;
    /* (i) upload: glTextureSubImage3D converting float data to GL_R16F */
    if (veil_gl_texture3d(GL_R16F, dims, "half probe", &tex, err) != VEIL_OK) return;
    glTextureSubImage3D(tex, 0, 0, 0, 0, NV, 1, 1, GL_RED, GL_FLOAT, vals);
    glGetTextureImage(tex, 0, GL_RED, GL_FLOAT, (GLsizei)sizeof back, back);
    int up_bad = 0, up_trunc = 0;
    for (int i = 0; i < n; ++i) {
        if (bits_of(back[i]) == bits_of(to_half(vals[i]))) continue;
        ++up_bad;
        up_trunc += fabsf(back[i]) <= fabsf(vals[i]); /* rounded toward zero */
        if (up_bad <= 3) printf("  upload: %.9g -> %.9g (emulated %.9g)\n", vals[i], back[i], to_half(vals[i]));
    }
    /* (ii) a shader's imageStore to an r16f image */
    int st_bad = 0, st_trunc = 0;
    if (veil_gl_compute_program("bench/half_float.c (store)", store_src, &prog, err) == VEIL_OK &&
        veil_gl_buffer(vals, sizeof vals, 0, "half probe values", &buf, err) == VEIL_OK) {
        glUseProgram(prog);
        glProgramUniform1i(prog, glGetUniformLocation(prog, "u_n"), n);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buf);
        glBindImageTexture(0, tex, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R16F);
        glDispatchCompute(veil_groups(n, 64), 1, 1);
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
        glGetTextureImage(tex, 0, GL_RED, GL_FLOAT, (GLsizei)sizeof back, back);
        for (int i = 0; i < n; ++i) {
            if (bits_of(back[i]) == bits_of(to_half(vals[i]))) continue;
            ++st_bad;
            st_trunc += fabsf(back[i]) <= fabsf(vals[i]);
            if (st_bad <= 3) printf("  imageStore: %.9g -> %.9g (emulated %.9g)\n", vals[i], back[i], to_half(vals[i]));
        }
        glUseProgram(0);
    }
    printf("driver float -> half: texture upload %d of %d values differ from round-to-nearest-even (%d of them "
           "toward zero);\nimageStore in a shader %d differ (%d toward zero)\n",
           up_bad, n, up_trunc, st_bad, st_trunc);
    glDeleteProgram(prog);
    glDeleteBuffers(1, &buf);
    glDeleteTextures(1, &tex);
}

/* Trilinear filtering between an inf texel and a 1. */
static void gpu_filter(GLenum format, const char* name, veil_error* err)
{
    static const float texels[2] = {INFINITY, 1.0f};
    /* texel centres at x = 0.25 (inf) and 0.75 (1): weights of the 1 of 0, 1/4, 1/2, 1 */
    static const float xs[4] = {0.25f, 0.375f, 0.5f, 0.75f};
    float res[4] = {0};
    int dims[3] = {2, 1, 1};
    GLuint tex = 0, prog = 0, bin = 0, bout = 0;
    if (veil_gl_texture3d(format, dims, "inf probe", &tex, err) == VEIL_OK &&
        veil_gl_compute_program("bench/half_float.c (filter)", filter_src, &prog, err) == VEIL_OK &&
        veil_gl_buffer(xs, sizeof xs, 0, "xs", &bin, err) == VEIL_OK &&
        veil_gl_buffer(NULL, sizeof res, GL_DYNAMIC_STORAGE_BIT, "res", &bout, err) == VEIL_OK) {
        glTextureSubImage3D(tex, 0, 0, 0, 0, 2, 1, 1, GL_RED, GL_FLOAT, texels);
        glUseProgram(prog);
        glBindTextureUnit(0, tex);
        glProgramUniform1i(prog, glGetUniformLocation(prog, "u_tex"), 0);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, bin);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bout);
        glDispatchCompute(4, 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glGetNamedBufferSubData(bout, 0, sizeof res, res);
        glUseProgram(0);
        glBindTextureUnit(0, 0);
        printf("%s texels {inf, 1} filtered with weight of the 1 = 0, 1/4, 1/2, 1: %g %g %g %g\n", name, res[0], res[1],
               res[2], res[3]);
    }
    glDeleteProgram(prog);
    glDeleteBuffers(1, &bin);
    glDeleteBuffers(1, &bout);
    glDeleteTextures(1, &tex);
}

/* The renderer with inf in the EV (what an overflowed half EV would hold),
 * and with an EV whose optical depth overflows to inf (float32 here, as a
 * half OPV would at 65504): how many pixels come out NaN? */
static void gpu_render(veil_gl* gl, veil_error* err)
{
    enum { N = 16, W = 32, H = 24 };
    veil_renderer* r = NULL;
    if (veil_renderer_create(gl, &r, err) != VEIL_OK) return;
    veil_grid g = {.dims = {N, N, N}, .origin = {-N / 2, -N / 2, -N / 2}, .voxel = 1.0f}; /* 1 m voxels */
    float* rho = malloc(N * N * N * sizeof(float));
    veil_light sun = {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0, -1, 0}, .color = {1, 1, 1}};
    veil_scene s = {0};
    s.camera = (veil_camera){.position = {3, 2, -40}, .look_at = {0, 0, 0}, .up = {0, 1, 0}, .fov_y_deg = 35,
                             .width = W, .height = H};
    s.background[0] = s.background[1] = s.background[2] = 0.5f;
    s.lights = &sun;
    s.light_count = 1;
    s.medium.phase.type = VEIL_PHASE_ISOTROPIC;
    for (int c = 0; c < 2; ++c) {
        float sigma;
        if (c == 0) { /* density 1 with one inf voxel; tau across the box 0.8 */
            for (int v = 0; v < N * N * N; ++v) rho[v] = 1.0f;
            rho[(N / 2 * N + N / 2) * N + N / 2] = INFINITY;
            sigma = 0.025f;
        } else { /* density 1e38: D passes FLT_MAX = 3.4e38 (-> inf) after 3.4 m below the top face;
                  * sigma_t 1e-38 keeps every march step's tau finite (0.5) */
            for (int v = 0; v < N * N * N; ++v) rho[v] = 1e38f;
            sigma = 0.5e-38f;
        }
        for (int k = 0; k < 3; ++k) s.medium.sigma_a[k] = s.medium.sigma_s[k] = sigma;
        float* img = NULL;
        veil_render_stats st;
        int nan = 0, inf = 0, dnan = 0, dinf = 0;
        float* D = malloc(N * N * N * sizeof(float));
        veil_index_light ol;
        veil_light_to_index(&sun, g.dims, g.origin, g.voxel, &ol);
        veil_opv_params params = {.method = VEIL_OPV_DEFAULT};
        int it = 0;
        if (D && veil_renderer_propagate(r, &g, rho, &ol, 1, &params, D, &it, err) == VEIL_OK)
            for (int v = 0; v < N * N * N; ++v) dnan += isnan(D[v]), dinf += isinf(D[v]);
        free(D);
        if (veil_render_density(r, &s, &g, rho, &(veil_render_opts){.seed = 1}, &img, &st, err) == VEIL_OK) {
            for (int p = 0; p < 4 * W * H; ++p) nan += isnan(img[p]), inf += isinf(img[p]);
            printf("renderer, %s: OPV %d inf, %d NaN of %d voxels; image %d NaN, %d inf of %d values\n",
                   c == 0 ? "EV of density 1 with one inf voxel" : "EV whose optical depth overflows to inf", dinf,
                   dnan, N * N * N, nan, inf, 4 * W * H);
        }
        free(img);
    }
    free(rho);
    veil_renderer_destroy(r);
}

static void gpu_section(void)
{
    veil_gl* gl = NULL;
    veil_error err = {0};
    printf("== 3. on the GPU ==\n");
    if (veil_gl_create(&(veil_gl_desc){0}, &gl, &err) != VEIL_OK) {
        printf("skipped: no GL 4.5 context (%s)\n", err.msg);
        return;
    }
    printf("device: %s\n", veil_gl_get_info(gl)->renderer);
    gpu_conversion(&err);
    gpu_filter(GL_R16F, "GL_R16F", &err);
    gpu_filter(GL_R32F, "GL_R32F", &err);
    gpu_render(gl, &err);
    if (err.msg[0]) printf("error: %s\n", err.msg);
    veil_gl_destroy(gl);
}

int main(int argc, char** argv)
{
    int n = 64, gpu = 1;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--n") == 0 && i + 1 < argc) n = atoi(argv[++i]);
        else if (strcmp(argv[i], "--no-gpu") == 0) gpu = 0;
        else {
            fprintf(stderr, "usage: half_float [--n N] [--no-gpu]\n");
            return 2;
        }
    }
    if (n < 4 || n > 512) {
        fprintf(stderr, "half_float: --n must be in 4 ... 512\n");
        return 2;
    }
    if (selftest()) return 1;
    printf("memory per voxel: EV 4 -> 2 bytes; OPV 16 -> 8 bytes per 4 lights (4 -> 2 per light). A 256^3 grid "
           "with 16 lights:\nEV 64 -> 32 MiB, OPVs 1024 -> 512 MiB (plus the renderer's scratch texture, 256 -> 128 "
           "MiB).\n\n");
    veil_grid g = bench_grid(n);
    float* base[N_MEDIA];
    for (int m = 0; m < N_MEDIA; ++m) {
        veil_error err = {0};
        base[m] = make_medium(media[m], &g, &err);
        if (!base[m]) {
            fprintf(stderr, "half_float: %s\n", err.msg);
            return 1;
        }
    }
    printf("grid %d^3 over a %.0f m box (voxel %.4g m)\n\n", n, (double)BOX_WIDTH, g.voxel);
    ev_section(&g, base);
    opv_section(&g, base);
    propagation_section();
    if (gpu) gpu_section();
    for (int m = 0; m < N_MEDIA; ++m) free(base[m]);
    return 0;
}
