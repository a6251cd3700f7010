/* The reference path tracer (reference/pathtracer.h) against closed forms.
 *
 * Each Monte Carlo check asserts |estimate - exact| <= 4 standard errors,
 * where the standard error is the tracer's own per-pixel sqrt(s^2 / n) (a
 * 4-sigma deviation of a mean of n >= 10^4 samples has probability ~6e-5;
 * the seeds are fixed, so a pass or a failure is reproducible). The exact
 * values are computed here, independently of the library:
 *  - Beer-Lambert: a slab of constant density, T = exp(-sigma_t L);
 *  - exponential fog: D = rho0 e^{-b y_c} (e^{-b d_y t_a} - e^{-b d_y t_b}) / (b d_y);
 *  - a Gaussian particle: its line integral by erf (the tracer sees the
 *    voxelised particle, so the bound adds the voxelisation difference
 *    |T(D_trilinear) - T(D_erf)|, computed exactly);
 *  - the airlight of an isotropic point light in a homogeneous medium
 *    (Sun et al. 2005): L = sigma_s I e^{-sigma_t D cos g} / (2 pi D sin g)
 *    [F(sigma_t D sin g, xi_1) - F(sigma_t D sin g, g/2)], F(u, v) =
 *    int_0^v exp(-u tan x) dx (derived in airlight() below);
 *  - albedo 1 (white furnace): a medium lit by a uniform background of
 *    radiance 1 and absorbing nothing shows radiance 1 everywhere; the same
 *    with an environment light of radiance 1 (MIS of the map and the phase);
 *  - a map lit only in a small cap overhead against a directional light of
 *    its irradiance (its width's effect bounded in test_env_sun);
 *  - Henyey-Greenstein sampling: a chi-square test on equal-probability
 *    bins of the analytic CDF (bin edges by bisection on the CDF, not by the
 *    sampler's inverse).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "core/rng.h"
#include "io/scene.h"
#include "reference/optical_depth.h"
#include "reference/pathtracer.h"
#include "support/airlight.h"
#include "support/scene_util.h"
#include "volume/scene_volume.h"

/* One pixel (the camera's forward ray) with n samples, seed `seed`, lights sampled as `sampling` says
 * (0: the default, MIS). */
static void render1_as(const veil_pt_medium* m, const veil_scene* s, int spp, int max_order, int stochastic, int env,
                       int sampling, uint64_t seed, double mean[4], double se[3], veil_pt_stats* st)
{
    veil_pt_opts o = {0};
    o.width = o.height = 1;
    o.spp = spp;
    o.max_order = max_order;
    o.seed = seed;
    o.stochastic_background = stochastic;
    o.environment = env;
    o.light_sampling = sampling;
    float *rgba = NULL, *e = NULL;
    veil_error err = {0};
    veil_result r = veil_pt_render(m, s, &o, &rgba, &e, st, &err);
    CHECK(r == VEIL_OK, "render: %s", err.msg);
    for (int c = 0; c < 4; ++c) mean[c] = rgba ? rgba[c] : NAN;
    for (int c = 0; c < 3; ++c) se[c] = e ? e[c] : NAN;
    CHECK(st->cut_walks == 0 && st->dropped_samples == 0 && st->majorant_misses == 0,
          "walk safeguards: %llu cut, %llu dropped, %llu majorant misses", (unsigned long long)st->cut_walks,
          (unsigned long long)st->dropped_samples, (unsigned long long)st->majorant_misses);
    free(rgba);
    free(e);
}

static void render1(const veil_pt_medium* m, const veil_scene* s, int spp, int max_order, int stochastic, int env,
                    double mean[4], double se[3], veil_pt_stats* st)
{
    render1_as(m, s, spp, max_order, stochastic, env, 0, 7, mean, se, st);
}

static void within_4_sigma(const char* what, const double got[3], const double se[3], const double want[3],
                           const double extra[3])
{
    for (int c = 0; c < 3; ++c) {
        double tol = 4.0 * se[c] + (extra ? extra[c] : 0.0) + 1e-6 * fabs(want[c]); /* + float output rounding */
        CHECK(fabs(got[c] - want[c]) <= tol, "%s ch %d: %.7g vs exact %.7g (diff %.3g, 4 se %.3g, tol %.3g)", what,
              c, got[c], want[c], fabs(got[c] - want[c]), 4 * se[c], tol);
        /* the test must have power: 4 standard errors under 10 % of the value */
        CHECK(se[c] > 0.0 && 4.0 * se[c] < 0.1 * fabs(want[c]), "%s ch %d: standard error %.3g", what, c, se[c]);
    }
    printf("  %-34s %.6f %.6f %.6f  (exact %.6f %.6f %.6f, se %.1e)\n", what, got[0], got[1], got[2], want[0],
           want[1], want[2], se[0]);
}

/* ---- Beer-Lambert slab --------------------------------------------------- */

static const char* slab_json =
    "{\"camera\":{\"position\":[1,1,-3],\"look_at\":[1,1,1],\"fov_y_deg\":30,\"width\":1,\"height\":1},"
    "\"medium\":{\"sigma_a\":[0.1,0.3,0.0],\"sigma_s\":[0.5,0.2,0.9],\"sources\":[]},"
    "\"lights\":[],\"background\":{\"color\":[1.0,0.5,0.25]}}";

/* The slab of test_slab, test_sun_single and test_env_sun: 4^3 voxels of density 1, edge 0.5 m, from the
 * origin (the medium is the box of the centres, [0.25, 1.75]^3). */
static veil_pt_medium* slab_medium(const veil_scene* s)
{
    veil_grid g = {{4, 4, 4}, {0, 0, 0}, 0.5f};
    float rho[64];
    for (int i = 0; i < 64; ++i) rho[i] = 1.0f;
    veil_pt_medium* m = NULL;
    veil_error err = {0};
    CHECK(veil_pt_medium_from_density(s, &g, rho, &m, &err) == VEIL_OK, "%s", err.msg);
    return m;
}

static void test_slab(void)
{
    veil_scene s = test_parse_scene(slab_json);
    /* 4^3 voxels of density 1, edge 0.5: the medium is the box of the
     * centres, [0.25, 1.75]^3, so the ray along z crosses L = 1.5 m */
    veil_pt_medium* m = slab_medium(&s);
    double want[3], mean[4], se[3];
    for (int c = 0; c < 3; ++c)
        want[c] = s.background[c] * exp(-((double)s.medium.sigma_a[c] + s.medium.sigma_s[c]) * 1.5);
    veil_pt_stats st;
    render1(m, &s, 40000, 1, 1, 0, mean, se, &st);
    within_4_sigma("Beer-Lambert slab (delta tracking)", mean, se, want, NULL);
    /* exact background: zero variance, the closed form to float rounding */
    render1(m, &s, 4, 1, 0, 0, mean, se, &st);
    double A = 1.0;
    for (int c = 0; c < 3; ++c) {
        CHECK(fabs(mean[c] - want[c]) <= 2e-7 * want[c], "exact slab ch %d: %.9g vs %.9g", c, mean[c], want[c]);
        CHECK(se[c] == 0.0, "exact slab ch %d: standard error %g", c, se[c]);
        A -= want[c] / s.background[c] / 3.0;
    }
    CHECK(fabs(mean[3] - A) <= 2e-7, "exact slab alpha %.9g vs %.9g", mean[3], A);
    veil_pt_medium_free(m);
    veil_scene_free(&s);
}

/* Single scattering of a sun: the slab's box lit straight from above, seen
 * along a horizontal ray at height y = 1 (the test of
 * tests/render/test_single_scatter.c): with D = 1.75 - y the density crossed
 * towards the sun and C = 1.5 the chord, phase angle 90 degrees,
 *   L = sigma_s p(0) E e^{-sigma_t D} (1 - e^{-sigma_t C}) / sigma_t + bg e^{-sigma_t C}.
 * This exercises next-event estimation and ratio tracking through the
 * volume (the fogs' transmittance is closed form). */
static void test_sun_single(void)
{
    veil_scene s = test_parse_scene(
        "{\"camera\":{\"position\":[-3,1,1],\"look_at\":[1,1,1],\"width\":1,\"height\":1},"
        "\"medium\":{\"sigma_a\":[0.1,0.3,0.0],\"sigma_s\":[0.5,0.2,0.9],\"phase\":{\"type\":\"hg\",\"g\":0.3},"
        "\"sources\":[]},\"lights\":[{\"type\":\"directional\",\"direction\":[0,-1,0],\"irradiance\":[2,3,4]}],"
        "\"background\":{\"color\":[0.2,0.2,0.2]}}");
    veil_pt_medium* m = slab_medium(&s);
    const double gg = 0.3, p0 = (1 - gg * gg) / (4 * VEIL_PI * pow(1 + gg * gg, 1.5)), D = 0.75, C = 1.5;
    double want[3], mean[4], se[3];
    for (int c = 0; c < 3; ++c) {
        double st_c = (double)s.medium.sigma_a[c] + s.medium.sigma_s[c];
        want[c] = s.medium.sigma_s[c] * p0 * s.lights[0].color[c] * exp(-st_c * D) * (1 - exp(-st_c * C)) / st_c +
                  s.background[c] * exp(-st_c * C);
    }
    veil_pt_stats st;
    render1(m, &s, 40000, 1, 0, 0, mean, se, &st);
    within_4_sigma("sun, single scattering (ratio tr.)", mean, se, want, NULL);
    veil_pt_medium_free(m);
    veil_scene_free(&s);
}

/* ---- exponential fog ----------------------------------------------------- */

static void test_exp_fog(void)
{
    /* tests/data/scenes/slanted_fog.json: fog of density 0.8 e^{-1.5 y} in the box
     * [-5, 5] x [-1, 3] x [-5, 5] (lo, hi, b and rho0 below), seen along a slanted ray */
    veil_scene s = test_load_scene("slanted_fog.json");
    veil_pt_medium* m = NULL;
    veil_error err = {0};
    CHECK(veil_pt_medium_from_scene(&s, &m, &err) == VEIL_OK, "%s", err.msg);
    double o[3], d[3];
    test_camera_ray(&s, o, d);
    double lo[3] = {-5, -1, -5}, hi[3] = {5, 3, 5}, ta = 0, tb = INFINITY;
    for (int k = 0; k < 3; ++k) {
        double a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
        ta = fmax(ta, fmin(a, b));
        tb = fmin(tb, fmax(a, b));
    }
    const double b = 1.5, rho0 = 0.8f; /* the scene's float */
    double D = rho0 * exp(-b * o[1]) * (exp(-b * d[1] * ta) - exp(-b * d[1] * tb)) / (b * d[1]);
    double want[3], mean[4], se[3];
    for (int c = 0; c < 3; ++c) want[c] = exp(-((double)s.medium.sigma_a[c] + s.medium.sigma_s[c]) * D);
    veil_pt_stats st;
    render1(m, &s, 400000, 1, 1, 0, mean, se, &st);
    within_4_sigma("exponential fog transmittance", mean, se, want, NULL);
    render1(m, &s, 2, 1, 0, 0, mean, se, &st);
    for (int c = 0; c < 3; ++c)
        CHECK(fabs(mean[c] - want[c]) <= 2e-7 * want[c], "exact fog ch %d: %.9g vs %.9g", c, mean[c], want[c]);
    veil_pt_medium_free(m);
    veil_scene_free(&s);
}

/* ---- a Gaussian particle ----------------------------------------------------- */

static void test_gaussian(void)
{
    veil_scene s = test_parse_scene(
        "{\"camera\":{\"position\":[0.1,0.05,-3],\"look_at\":[0.1,0.05,0],\"width\":1,\"height\":1},"
        "\"medium\":{\"sigma_a\":[0.3,0.3,0.3],\"sigma_s\":[0.4,0.7,1.0],\"max_resolution\":128,\"sources\":[{\"type\":"
        "\"rbf\",\"particles\":[{\"center\":[0,0,0],\"amplitude\":2.0,\"sharpness\":3.0}]}]},"
        "\"lights\":[],\"background\":{\"color\":[1,1,1]}}");
    veil_scene_volume v;
    veil_error err = {0};
    float* rho = NULL;
    CHECK(veil_scene_volume_open(&s, &v, &err) == VEIL_OK, "%s", err.msg);
    CHECK(veil_scene_volume_density(&v, &rho, &err) == VEIL_OK, "%s", err.msg);
    veil_pt_medium* m = NULL;
    CHECK(veil_pt_medium_from_density(&s, &v.grid, rho, &m, &err) == VEIL_OK, "%s", err.msg);
    /* the z line at distance d from the centre: c sqrt(pi) / a e^{-a^2 d^2}
     * (erf(a z1) - erf(a z0)) / 2 over the grid's box */
    const double c0 = 2.0, a = 3.0, d2 = 0.1 * 0.1 + 0.05 * 0.05;
    double zlo = v.grid.origin[2] + 0.5 * v.grid.voxel, zhi = v.grid.origin[2] + (v.grid.dims[2] - 0.5) * v.grid.voxel;
    double D_erf = c0 * sqrt(VEIL_PI) / a * exp(-a * a * d2) * 0.5 * (erf(a * zhi) - erf(a * zlo));
    double pa[3] = {0.1, 0.05, -3}, pb[3] = {0.1, 0.05, 3};
    double D_tri = veil_ref_segment_optical_depth(&v.grid, rho, pa, pb);
    double want[3], extra[3], mean[4], se[3];
    for (int c = 0; c < 3; ++c) {
        double st_c = (double)s.medium.sigma_a[c] + s.medium.sigma_s[c];
        want[c] = exp(-st_c * D_erf);
        extra[c] = fabs(exp(-st_c * D_tri) - want[c]);
    }
    printf("  Gaussian: D_erf %.8f, D_trilinear %.8f (voxelisation %.2e relative, voxel %.4f m)\n", D_erf, D_tri,
           fabs(D_tri - D_erf) / D_erf, v.grid.voxel);
    veil_pt_stats st;
    render1(m, &s, 40000, 1, 1, 0, mean, se, &st);
    within_4_sigma("Gaussian line integral (erf)", mean, se, want, extra);
    veil_pt_medium_free(m);
    free(rho);
    veil_scene_volume_close(&v);
    veil_scene_free(&s);
}

/* ---- airlight (Sun et al. 2005) ---------------------------------------------- */

static void test_airlight(void)
{
    /* tests/data/scenes/airlight_point.json: viewer at the origin looking along
     * (2, 0.5, 0); a point light of intensity 10 at (0, 1, 0); homogeneous fog of
     * density 1 filling [-20, 20]^3: the ray leaves it at x = 20 */
    veil_scene s = test_load_scene("airlight_point.json");
    veil_pt_medium* m = NULL;
    veil_error err = {0};
    CHECK(veil_pt_medium_from_scene(&s, &m, &err) == VEIL_OK, "%s", err.msg);
    double len = sqrt(4.25), cg = 0.5 / len, gam = acos(cg), T = 20.0 / (2.0 / len);
    double want[3], mean[4], se[3];
    for (int c = 0; c < 3; ++c)
        want[c] = airlight(s.medium.sigma_s[c], (double)s.medium.sigma_a[c] + s.medium.sigma_s[c], 10.0, 1.0, gam, T);
    veil_pt_stats st;
    render1(m, &s, 100000, 1, 0, 0, mean, se, &st);
    within_4_sigma("airlight, point light (Sun 2005)", mean, se, want, NULL);
    veil_pt_medium_free(m);
    veil_scene_free(&s);
}

/* ---- white furnace -------------------------------------------------------------- */

static void test_furnace(const char* what, double g, double scale, int spp)
{
    char json[1024];
    snprintf(json, sizeof json,
             "{\"camera\":{\"position\":[0.2,0.1,-3],\"look_at\":[0,0,0],\"width\":1,\"height\":1},"
             "\"medium\":{\"sigma_a\":[0,0,0],\"sigma_s\":[%g,%g,%g],\"phase\":{\"type\":\"hg\",\"g\":%g},"
             "\"max_resolution\":32,\"sources\":[{\"type\":\"rbf\",\"particles\":[{\"center\":[0,0,0],"
             "\"amplitude\":3.0,\"sharpness\":2.0}]},{\"type\":\"exponential\",\"density\":0.3,\"falloff\":0.5,"
             "\"direction\":[0,1,0],\"origin\":[0,0,0],\"bounds\":[[-2,-2,-2],[2,2,2]]}]},"
             "\"lights\":[],\"background\":{\"color\":[1,1,1]}}",
             0.5 * scale, 1.0 * scale, 2.0 * scale, g);
    veil_scene s = test_parse_scene(json);
    veil_pt_medium* m = NULL;
    veil_error err = {0};
    CHECK(veil_pt_medium_from_scene(&s, &m, &err) == VEIL_OK, "%s", err.msg);
    double want[3] = {1, 1, 1}, mean[4], se[3];
    veil_pt_stats st;
    render1(m, &s, spp, 0, 1, 1, mean, se, &st);
    within_4_sigma(what, mean, se, want, NULL);
    printf("    (%.2f tentative collisions per path)\n", (double)st.collisions / (double)st.paths);
    veil_pt_medium_free(m);
    veil_scene_free(&s);
}

/* ---- the environment light (scene/environment.h) ---------------------------------- */

/* One pixel as render1 (seed 11), with the environment sampled as `sampling` says (MIS: the map and the
 * phase function; DISTANCE: the phase function alone). */
static void render_env(const veil_pt_medium* m, const veil_scene* s, int spp, int max_order, int sampling,
                       double mean[4], double se[3])
{
    veil_pt_stats st;
    render1_as(m, s, spp, max_order, 0, 0, sampling, 11, mean, se, &st);
}

/* The white furnace lit by an environment light of radiance 1 (not the background): every pixel 1, with
 * the map's samples and the phase's combined by MIS, and with the phase's alone. */
static void test_env_furnace(void)
{
    veil_scene s = test_parse_scene(
        "{\"camera\":{\"position\":[0.2,0.1,-3],\"look_at\":[0,0,0],\"width\":1,\"height\":1},"
        "\"medium\":{\"sigma_a\":[0,0,0],\"sigma_s\":[0.5,1,2],\"phase\":{\"type\":\"hg\",\"g\":0.6},"
        "\"max_resolution\":32,\"sources\":[{\"type\":\"rbf\",\"particles\":[{\"center\":[0,0,0],"
        "\"amplitude\":3.0,\"sharpness\":2.0}]}]},"
        "\"lights\":[{\"type\":\"environment\",\"color\":[1,1,1]}]}");
    veil_pt_medium* m = NULL;
    veil_error err = {0};
    CHECK(veil_pt_medium_from_scene(&s, &m, &err) == VEIL_OK, "%s", err.msg);
    double want[3] = {1, 1, 1}, mean[4], se[3];
    render_env(m, &s, 40000, 0, VEIL_PT_LIGHT_SAMPLING_MIS, mean, se);
    within_4_sigma("environment furnace, MIS", mean, se, want, NULL);
    render_env(m, &s, 40000, 0, VEIL_PT_LIGHT_SAMPLING_DISTANCE, mean, se);
    within_4_sigma("environment furnace, phase alone", mean, se, want, NULL);
    veil_pt_medium_free(m);
    veil_scene_free(&s);
}

/* test_sun_single's slab lit by a map whose only light is a cap around +Y: its first J of H rows (a
 * polar cap of half-angle theta_c = pi J / H, radiance Lc), against the closed form of a directional
 * light of the cap's irradiance E = Lc 2 pi (1 - cos theta_c) shining straight down. The map is sampled
 * (MIS: a 0.35-degree cap is found by the map's samples; the phase's almost never find it). What the
 * cap's width changes, bounded and added to the tolerance:
 *  - the phase function, p(mu) at mu = cos(scattering angle) = omega . x_hat within sin(theta_c) of 0:
 *    its first-order term averages to 0 over the cap (symmetric about +Y: whole rows), the rest is at
 *    most (1/2) max|p''| sin^2(theta_c), relative to p(0): p = k (a - b mu)^(-3/2), a = 1 + g^2,
 *    b = 2g, p'' = (15/4) b^2 k (a - b mu)^(-7/2);
 *  - the optical depth to the slab's top, D / cos(theta) instead of D: T changes by at most a relative
 *    sigma_t D (1 / cos(theta_c) - 1);
 *  - points of the chord within D tan(theta_c) of its ends may see the light leave by a side face
 *    instead: at most that share of the chord, 2 D tan(theta_c) / C, of the whole value. */
static void test_env_sun(void)
{
    veil_scene s = test_parse_scene(
        "{\"camera\":{\"position\":[-3,1,1],\"look_at\":[1,1,1],\"width\":1,\"height\":1},"
        "\"medium\":{\"sigma_a\":[0.1,0.3,0.0],\"sigma_s\":[0.5,0.2,0.9],\"phase\":{\"type\":\"hg\",\"g\":0.3},"
        "\"sources\":[]},\"lights\":[{\"type\":\"environment\",\"color\":[1,1,1]}],"
        "\"background\":{\"color\":[0.2,0.2,0.2]}}");
    const int W = 2048, H = 1024, J = 2;
    const double Lc[3] = {2000, 3000, 4000};
    veil_environment* env = &s.environment;
    free(env->rgb);
    env->rgb = calloc((size_t)W * H * 3, sizeof *env->rgb);
    CHECK(env->rgb != NULL, "out of memory");
    if (!env->rgb) return;
    env->width = W, env->height = H;
    for (int j = 0; j < J; ++j)
        for (int i = 0; i < W; ++i)
            for (int c = 0; c < 3; ++c) env->rgb[3 * ((size_t)j * W + i) + c] = (float)Lc[c];
    veil_pt_medium* m = slab_medium(&s);
    const double gg = 0.3, p0 = (1 - gg * gg) / (4 * VEIL_PI * pow(1 + gg * gg, 1.5)), D = 0.75, C = 1.5;
    const double tc = VEIL_PI * J / H, a = 1 + gg * gg, b = 2 * gg;
    const double p2 = 3.75 * b * b * (1 - gg * gg) / (4 * VEIL_PI) * pow(a - b * sin(tc), -3.5);
    double want[3], extra[3], mean[4], se[3];
    for (int c = 0; c < 3; ++c) {
        double st_c = (double)s.medium.sigma_a[c] + s.medium.sigma_s[c];
        double E = Lc[c] * 2 * VEIL_PI * (1 - cos(tc));
        double lit = s.medium.sigma_s[c] * p0 * E * exp(-st_c * D) * (1 - exp(-st_c * C)) / st_c;
        want[c] = lit + s.background[c] * exp(-st_c * C);
        extra[c] = lit * (0.5 * p2 * sin(tc) * sin(tc) / p0 + st_c * D * (1 / cos(tc) - 1) + 2 * D * tan(tc) / C);
    }
    render_env(m, &s, 40000, 1, VEIL_PT_LIGHT_SAMPLING_MIS, mean, se);
    within_4_sigma("environment: a cap overhead, single", mean, se, want, extra);
    veil_pt_medium_free(m);
    veil_scene_free(&s);
}

/* ---- HG sampling -------------------------------------------------------------------- */

/* The HG CDF in mu = cos(theta) from -1 (g != 0), and 1-2u inverse for g = 0. */
static double hg_cdf(double mu, double g)
{
    if (g == 0.0) return 0.5 * (mu + 1.0);
    return (1.0 - g * g) / (2.0 * g) * (1.0 / sqrt(1.0 + g * g - 2.0 * g * mu) - 1.0 / (1.0 + g));
}

/* Chi-square on K equal-probability mu bins x 8 azimuth bins. (The
 * sampler inverts the CDF exactly, so mu falls in bin i exactly when the
 * first uniform is in [i/K, (i+1)/K): the statistic is then the same for
 * every g, and a wrong inverse or azimuth shows as a large one.): 8K - 1
 * degrees of freedom; the critical value at p = 1e-6 from the
 * Wilson-Hilferty approximation k (1 - 2/(9k) + z sqrt(2/(9k)))^3, z = 4.753. */
static void test_hg_sampling(double g)
{
    enum { K = 32, P = 8, N = 256000 };
    double edge[K + 1];
    edge[0] = -1.0;
    edge[K] = 1.0;
    for (int i = 1; i < K; ++i) { /* bisection on the CDF: independent of the sampler's inverse */
        double lo = -1.0, hi = 1.0;
        for (int it = 0; it < 100; ++it) {
            double mid = 0.5 * (lo + hi);
            if (hg_cdf(mid, g) < (double)i / K) lo = mid; else hi = mid;
        }
        edge[i] = 0.5 * (lo + hi);
    }
    static int count[K][P];
    memset(count, 0, sizeof count);
    double dir[3] = {1.0 / sqrt(14.0), 2.0 / sqrt(14.0), 3.0 / sqrt(14.0)};
    double e1[3] = {2.0 / sqrt(5.0), -1.0 / sqrt(5.0), 0.0}; /* perpendicular to dir */
    double e2[3] = {dir[1] * e1[2] - dir[2] * e1[1], dir[2] * e1[0] - dir[0] * e1[2], dir[0] * e1[1] - dir[1] * e1[0]};
    uint64_t state = 12345;
    int bad_norm = 0;
    for (int i = 0; i < N; ++i) {
        double u[2];
        for (int k = 0; k < 2; ++k) u[k] = veil_rng_double53(&state);
        double w[3];
        veil_pt_sample_hg(dir, g, u[0], u[1], w);
        double n2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
        bad_norm += !(fabs(n2 - 1.0) < 1e-12);
        double mu = w[0] * dir[0] + w[1] * dir[1] + w[2] * dir[2];
        double phi = atan2(w[0] * e2[0] + w[1] * e2[1] + w[2] * e2[2], w[0] * e1[0] + w[1] * e1[1] + w[2] * e1[2]);
        int b = 0;
        while (b < K - 1 && mu > edge[b + 1]) ++b;
        int p = (int)floor((phi + VEIL_PI) / (2.0 * VEIL_PI) * P);
        p = p < 0 ? 0 : (p >= P ? P - 1 : p);
        ++count[b][p];
    }
    double chi2 = 0.0, expect = (double)N / (K * P);
    for (int b = 0; b < K; ++b)
        for (int p = 0; p < P; ++p) chi2 += (count[b][p] - expect) * (count[b][p] - expect) / expect;
    double k = K * P - 1, z = 4.753;
    double crit = k * pow(1.0 - 2.0 / (9.0 * k) + z * sqrt(2.0 / (9.0 * k)), 3.0);
    CHECK(bad_norm == 0, "g %g: %d sampled directions not of unit length", g, bad_norm);
    CHECK(chi2 < crit, "g %g: chi-square %.1f over %d bins exceeds %.1f (p = 1e-6)", g, chi2, K * P, crit);
    printf("  HG sampling g = %+5.2f: chi-square %.1f (dof %.0f, critical %.1f)\n", g, chi2, k, crit);
}

/* ---- determinism --------------------------------------------------------------------- */

static void test_determinism(void)
{
    veil_scene s = test_parse_scene(
        "{\"camera\":{\"position\":[0,0.3,-3],\"look_at\":[0,0,0],\"width\":12,\"height\":9},"
        "\"medium\":{\"sigma_a\":[0.1,0.1,0.1],\"sigma_s\":[1,1.2,1.4],\"phase\":{\"type\":\"hg\",\"g\":0.4},"
        "\"max_resolution\":24,\"sources\":[{\"type\":\"rbf_random\",\"count\":40,\"seed\":3,"
        "\"bounds\":[[-1,-0.5,-1],[1,0.5,1]],\"radius\":[0.1,0.4],\"amplitude\":[0.5,2]}]},"
        "\"lights\":[{\"type\":\"point\",\"position\":[0.5,1,0],\"intensity\":[4,4,4]},"
        "{\"type\":\"spot\",\"position\":[-2,1,0],\"direction\":[1,-0.5,0],\"intensity\":[9,9,9],"
        "\"inner_angle_deg\":10,\"outer_angle_deg\":30},{\"type\":\"directional\",\"direction\":[0,-1,0.2],"
        "\"irradiance\":[1,1,1]}],\"background\":{\"color\":[0.1,0.1,0.1]}}");
    veil_pt_medium* m = NULL;
    veil_error err = {0};
    CHECK(veil_pt_medium_from_scene(&s, &m, &err) == VEIL_OK, "%s", err.msg);
    float *a = NULL, *ae = NULL, *b = NULL, *be = NULL, *c = NULL, *ce = NULL;
    veil_pt_opts o = {0};
    o.spp = 8;
    o.seed = 99;
    o.threads = 1;
    veil_pt_stats st;
    CHECK(veil_pt_render(m, &s, &o, &a, &ae, &st, &err) == VEIL_OK, "%s", err.msg);
    o.threads = 3;
    CHECK(veil_pt_render(m, &s, &o, &b, &be, &st, &err) == VEIL_OK, "%s", err.msg);
    o.seed = 100;
    CHECK(veil_pt_render(m, &s, &o, &c, &ce, &st, &err) == VEIL_OK, "%s", err.msg);
    size_t n = 12 * 9;
    CHECK(a && b && !memcmp(a, b, n * 4 * sizeof(float)) && !memcmp(ae, be, n * 3 * sizeof(float)),
          "1 and 3 threads give different images");
    CHECK(a && c && memcmp(a, c, n * 4 * sizeof(float)) != 0, "seeds 99 and 100 give the same image");
    int finite = 1;
    for (size_t i = 0; a && i < n * 4; ++i) finite &= isfinite(a[i]) && a[i] >= 0.0f;
    CHECK(finite, "non-finite or negative values in the image");
    o.spp = 1;
    float *x = NULL, *xe = NULL;
    CHECK(veil_pt_render(m, &s, &o, &x, &xe, &st, &err) == VEIL_ERR_INVALID, "spp 1 must be refused");
    free(a), free(ae), free(b), free(be), free(c), free(ce);
    veil_pt_medium_free(m);
    veil_scene_free(&s);
}

int main(void)
{
    test_slab();
    test_sun_single();
    test_exp_fog();
    test_gaussian();
    test_airlight();
    test_furnace("white furnace, g = 0.6", 0.6, 1.0, 40000);
    test_furnace("white furnace, g = -0.8, dense", -0.8, 4.0, 160000);
    test_env_furnace();
    test_env_sun();
    static const double gs[] = {-0.99, -0.7, -0.3, 0.0, 1e-4, 0.1, 0.5, 0.9, 0.99};
    for (size_t i = 0; i < sizeof gs / sizeof gs[0]; ++i) test_hg_sampling(gs[i]);
    test_determinism();
    return check_finish();
}
