/* The light cache (volumetric/cache.h).
 * 1. The fixed point (CPU, the shared function the shader calls): each add
 *    floor(s u + xi) is within one unit of s u for every xi in [0, 1), and
 *    unbiased: over the M-point lattice xi = (k + 1/2) / M its mean is s u
 *    within 1 / (2M) (floor(s + xi) averaged over a uniform lattice counts
 *    the lattice points at or above 1 - frac(s): frac(s) M of them, within
 *    a half point); values past +-2^31 are clamped, never wrapped.
 * 2. Determinism: the same seed gives the same cache bit for bit (the sums
 *    are integers, so the order the GPU runs photons in does not matter);
 *    another seed gives another.
 * 3. No order counted twice: a homogeneous fog box (isotropic, albedo 0.95)
 *    under a sun, rendered with the march (order 1, exact) plus the cache
 *    (orders >= 2) against the reference path tracer at all orders. The
 *    image means must agree within
 *      4 sqrt(se_ref^2 + (noise M)^2) + (1 - exp(-sigma_t h)) M / 2
 *    with se_ref the standard error of the reference's mean (its pixels'
 *    standard errors, independent), M the mean of the cache's part and
 *    noise the cache's own estimate of its cells' relative noise (a
 *    positively weighted mean of noisy cells has at most their RMS relative
 *    noise), plus the cells' averaging: within one cell of edge h the
 *    fluence changes by at most a factor exp(sigma_t h) along the light
 *    (the steepest it can: no scattering gain), and the trilinear read of
 *    cell means is off by at most that change, half of it on a mean over
 *    a ray (the linear part cancels). Counting order 1 twice would add the
 *    single scattering's mean, which the test first checks is far above
 *    that bound. Both ways the march reads the later light: from its lobe,
 *    and gathered towards the camera (render/shaders/cache_gather.comp, 16
 *    rays a cell, asked for: the default gathers only where g >= 1/sqrt(2)),
 *    whose own noise enters as the spread of 8 renders
 *    with other seeds over the same cache (their mean: 5.5 standard errors,
 *    t with 7 degrees of freedom).
 * 4. Energy, in a closed case: a fog box of albedo 1 (no absorption,
 *    chromatic sigma_s, HG g 0.85) under a sun straight down. The cache's
 *    energy account (core/shared.glsl.h) must show what enters the medium
 *    leave it: the light that scattered, E A (1 - exp(-sigma_s L)) per
 *    channel in closed form (A the box's top, L its height), all of it
 *    leaving the grid and none absorbed. With absorption, what scattered =
 *    what left + what was absorbed. And the fluence the march reads holds
 *    the photons' track length (its cells times their volume), whose sigma_t
 *    times it the collision estimator measures independently. Then the
 *    same for an absorbing height fog (density exp(-0.8 y), HG 0.6): the
 *    column's optical depth in closed form, the collisions left out (their
 *    sigma_t varies within a cell). Tolerances:
 *    from the spread of the 8 groups of photons (photon n in group n mod 8),
 *    a sum's standard error sqrt(8 s^2) with s^2 the groups' sample
 *    variance (7 degrees of freedom: |t| > 5.41 has probability 1e-3), so
 *    5.5 standard errors, of paired differences where two sums are
 *    compared; a photon's channel weights sum to a constant
 *    (cache_trace.comp), so albedo 1 conserves each photon's sum exactly
 *    but for the fixed point's and the floats' rounding (Hoeffding over the
 *    photons, derived where it is checked).
 * 5. A frame's surfaces absorb photons (veil fog: scene/solid.h): the fog
 *    box of 4 (albedo 1, chromatic sigma_s, HG 0.5) under the sun straight
 *    down, over a floor at y = 0 seen by a camera above it. A photon that
 *    reaches the floor before it scatters is gone (never counted); one that
 *    scatters is counted once, and then leaves the grid or ends in the
 *    floor. Against an analog Monte Carlo of the same slab on the CPU (per
 *    channel: the fraction of what scattered that the floor absorbs, a
 *    binomial with its standard error) at the floor's lowest and highest
 *    height as the photons meet it (vertical paths stepped at half a voxel
 *    over the solid's top: within half a voxel below it): the GPU's fraction
 *    lies between the two within 5.5 combined standard errors (the groups'
 *    spread, as in 4). Without the floor it would be 0 (albedo 1). What
 *    scattered is E A (1 - exp(-sigma_s (1 - y))) for y between those
 *    heights, and what scattered = what left + what was absorbed. The cells
 *    keep their sums, whose volume integral is the track length as in 4,
 *    and beside them (the flux's alpha) their part outside the solid, 4^3
 *    points a cell, which the march divides by. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "frame/renderer.h"
#include "reference/pathtracer.h"
#include "scene/solid.h"
#include "volumetric/volumetric.h"

static void fixed_point(void)
{
    const float s_values[] = {0.0f, 0.3f, 0.5f, 1.0f, 7.25f, -0.3f, -7.75f, 1234.567f, -98765.4f, 1e-6f, 1073741824.0f};
    const int M = 1000;
    int ok = 1;
    for (size_t i = 0; i < sizeof s_values / sizeof *s_values; ++i) {
        float s = s_values[i];
        double sum = 0.0;
        for (int k = 0; k < M; ++k) {
            float xi = ((float)k + 0.5f) / (float)M;
            int v = veil_cache_fixed(s, xi);
            ok &= fabs((double)v - (double)s) < 1.0 + 1e-6 * fabs(s); /* float s + xi rounds at 2^24 and up */
            sum += v;
        }
        double mean = sum / M;
        double tol = 0.5 / M + 1e-6 * fabs(s);
        CHECK(fabs(mean - s) <= tol, "fixed point: mean of floor(%g + xi) over %d points %.9g (tolerance %.3g)", s, M,
              mean, tol);
    }
    CHECK(ok, "fixed point: some add was a unit or more away from its score");
    CHECK(veil_cache_fixed(3e9f, 0.5f) == 2147483520 && veil_cache_fixed(-3e9f, 0.5f) == -2147483520,
          "fixed point: out-of-range scores clamped (%d, %d)", veil_cache_fixed(3e9f, 0.5f),
          veil_cache_fixed(-3e9f, 0.5f));
    printf("fixed point: unbiased within 1/(2M) and within one unit, clamped past 2^31\n");
}

static veil_source fog_box(void)
{
    return (veil_source){.type = VEIL_SOURCE_EXPONENTIAL,
                         .fog = {.density = 1.0f, .falloff = 0.0f, .direction = {0, 1, 0},
                                 .bounds = {{-1, -1, -1}, {1, 1, 1}}}};
}

static void determinism(veil_volumetric* d)
{
    veil_error err = {0};
    veil_source fog = fog_box();
    veil_light lights[2] = {{.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0.3f, -0.8f, 0.5f}, .color = {1, 2, 3}},
                            {.type = VEIL_LIGHT_POINT, .position = {0.2f, 0.1f, 0.0f}, .color = {2, 2, 1}}};
    float n = sqrtf(0.09f + 0.64f + 0.25f);
    for (int a = 0; a < 3; ++a) lights[0].direction[a] /= n;
    veil_scene s = {0};
    for (int c = 0; c < 3; ++c) s.medium.sigma_s[c] = 1.0f + 0.2f * (float)c, s.medium.sigma_a[c] = 0.1f;
    s.medium.phase = (veil_phase){.type = VEIL_PHASE_HG, .g = 0.5f};
    s.medium.sources = &fog;
    s.medium.source_count = 1;
    veil_multiple_defaults(&s.multiple);
    GLuint opv[VEIL_MAX_OPV_TEXTURES] = {0};
    veil_volumetric_desc vd = {.kind = VEIL_FIELD_CACHE,
                               .medium = {.scene = &s, .lights = lights, .light_count = 2, .opv = opv},
                               .cache = {.photons = 1 << 15, .cells = 12, .seed = 7}};
    float* out[3] = {NULL, NULL, NULL};
    int dims[3] = {0, 0, 0};
    for (int run = 0; run < 3; ++run) {
        vd.cache.seed = run < 2 ? 7u : 8u;
        veil_volumetric_field f;
        veil_volumetric_report rep;
        CHECK(veil_volumetric_update(d, &vd, 200 + (uint64_t)run, &f, &rep, &err) == VEIL_OK, "%s", err.msg);
        CHECK(rep.cache.photons >= (1 << 15) - 2 && rep.cache.sources == 2 && rep.cache.cut == 0 &&
                  rep.cache.clamped == 0 && rep.cache.misses == 0,
              "run %d: %lld photons from %d sources, %u cut, %u clamped, %u majorant misses", run, rep.cache.photons,
              rep.cache.sources, rep.cache.cut, rep.cache.clamped, rep.cache.misses);
        out[run] = veil_volumetric_readback(d, dims);
        CHECK(out[run] != NULL, "the cache was read back (run %d)", run);
        if (run == 0) {
            /* the flux: finite, and along the sun's travel on the whole (its mean against the sun's direction) */
            float* F = veil_volumetric_readback_flux(d, dims);
            CHECK(F != NULL, "the flux was read back");
            double along = 0.0;
            int finite = 1;
            for (size_t i = 0; F && i < (size_t)dims[0] * dims[1] * dims[2]; ++i) {
                finite &= isfinite(F[4 * i]) && isfinite(F[4 * i + 1]) && isfinite(F[4 * i + 2]);
                along += F[4 * i] * lights[0].direction[0] + F[4 * i + 1] * lights[0].direction[1] +
                         F[4 * i + 2] * lights[0].direction[2];
            }
            CHECK(finite && along > 0.0, "the flux is finite and runs with the sun (sum of F . sun %g)", along);
            free(F);
        }
    }
    if (out[0] && out[1] && out[2]) {
        size_t bytes = (size_t)dims[0] * dims[1] * dims[2] * 4 * sizeof(float);
        double sum = 0.0;
        int finite = 1;
        for (size_t i = 0; i < bytes / sizeof(float); ++i) {
            finite &= isfinite(out[0][i]) && out[0][i] >= 0.0f;
            sum += out[0][i];
        }
        CHECK(finite && sum > 0.0, "the fluence is finite, >= 0 and not all 0 (sum %g)", sum);
        CHECK(memcmp(out[0], out[1], bytes) == 0, "the same seed gave another cache");
        CHECK(memcmp(out[0], out[2], bytes) != 0, "another seed gave the same cache");
        printf("determinism: seed 7 twice bit-identical (%dx%dx%d cells), seed 8 differs\n", dims[0], dims[1], dims[2]);
    }
    for (int i = 0; i < 3; ++i) free(out[i]);
}

/* The sum over the groups of sum_i k[i] x kind[i] (n terms) in channel ch, and its standard error from
 * the groups' spread: paired, so what the terms share cancels group by group. */
static double group_sum(const veil_cache_report* c, int n, const int* kind, const double* k, int ch, double* se)
{
    const int G = VEIL_CACHE_ENERGY_GROUPS;
    double v[VEIL_CACHE_ENERGY_GROUPS], mean = 0.0, ss = 0.0;
    for (int g = 0; g < G; ++g) {
        v[g] = 0.0;
        for (int i = 0; i < n; ++i) v[g] += k[i] * c->energy_groups[g][kind[i]][ch];
        mean += v[g] / G;
    }
    for (int g = 0; g < G; ++g) ss += (v[g] - mean) * (v[g] - mean);
    *se = sqrt(G * ss / (G - 1));
    return mean * G;
}

/* How far the cells' fluence times volume may be from the photons' track length (4 says why): the fixed
 * point's rounding (Hoeffding) and the floats'. A: the sun's cross-section, h: the cell. */
static double track_tolerance(const veil_cache_report* c, double A, double h, double track)
{
    double phi_max = 3.0 * A / (double)c->photons;
    double unit_cells = 3.0 * phi_max * sqrt(3.0) * h / 1048576.0, unit_acc = 65536.0 * unit_cells;
    double n_cells = (double)c->photons * (c->cap + 1.0), n_acc = (double)c->photons;
    return 2.0 * sqrt(2.0 * log(2.0 / 1e-9)) * (sqrt(n_cells) * unit_cells + sqrt(n_acc) * unit_acc) +
           (c->cap * ldexp(1.0, -24) + 1728.0 * 6e-8) * track;
}

static void energy(veil_volumetric* d)
{
    veil_error err = {0};
    veil_light sun = {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0.0f, -1.0f, 0.0f}, .color = {1.0f, 2.0f, 3.0f}};
    const float sigma_s[3] = {1.0f, 0.6f, 0.3f}, sigma_a[3] = {0.25f, 0.1f, 0.4f}; /* both chromatic */
    const char* const names[3] = {"albedo 1", "absorbing", "height fog"};
    for (int kase = 0; kase < 3; ++kase) {
        /* 0: homogeneous, albedo 1; 1: homogeneous, absorbing; 2: absorbing height fog, density exp(-0.8 y) */
        const int absorbing = kase >= 1, height = kase == 2;
        const double falloff = height ? 0.8 : 0.0;
        veil_source fog = fog_box();
        fog.fog.falloff = (float)falloff;
        veil_scene s = {0};
        for (int c = 0; c < 3; ++c) s.medium.sigma_s[c] = sigma_s[c], s.medium.sigma_a[c] = absorbing ? sigma_a[c] : 0.0f;
        s.medium.phase = (veil_phase){.type = VEIL_PHASE_HG, .g = height ? 0.6f : 0.85f};
        s.medium.sources = &fog;
        s.medium.source_count = 1;
        veil_multiple_defaults(&s.multiple);
        GLuint opv[VEIL_MAX_OPV_TEXTURES] = {0};
        veil_volumetric_desc vd = {.kind = VEIL_FIELD_CACHE,
                                   .medium = {.scene = &s, .lights = &sun, .light_count = 1, .opv = opv},
                                   .cache = {.photons = 1 << 18, .cells = 12, .seed = 11}};
        veil_volumetric_field f;
        veil_volumetric_report rep;
        CHECK(veil_volumetric_update(d, &vd, 300 + (uint64_t)kase, &f, &rep, &err) == VEIL_OK, "%s", err.msg);
        const veil_cache_report* c = &rep.cache;
        CHECK(c->cut == 0 && c->misses == 0, "energy: %u photons cut, %u majorant misses", c->cut, c->misses);
        int dims[3] = {0, 0, 0};
        float* phi = veil_volumetric_readback(d, dims);
        CHECK(phi != NULL && dims[0] == 12 && dims[1] == 12 && dims[2] == 12, "the cache read back (%dx%dx%d)",
              dims[0], dims[1], dims[2]);
        float* later = veil_volumetric_readback_later(d, dims);
        CHECK(later != NULL, "the cache's later light read back");
        /* the column's density integral from y = 1 down to -1: L = 2, or (e^0.8 - e^-0.8) / 0.8 */
        const double A = 4.0, L = height ? (exp(falloff) - exp(-falloff)) / falloff : 2.0, V = pow(2.0 / 12.0, 3.0);
        double sum_in = 0.0, sum_out = 0.0;
        for (int ch = 0; ch < 3; ++ch) {
            double st = (double)s.medium.sigma_s[ch] + s.medium.sigma_a[ch], se;
            double want = sun.color[ch] * A * (s.medium.sigma_s[ch] / st) * (1.0 - exp(-st * L));
            const int k_in[1] = {VEIL_CACHE_ENERGY_IN};
            const int k_bal[3] = {VEIL_CACHE_ENERGY_IN, VEIL_CACHE_ENERGY_OUT, VEIL_CACHE_ENERGY_ABSORBED};
            const int k_coll[2] = {VEIL_CACHE_ENERGY_COLLISIONS, VEIL_CACHE_ENERGY_TRACK};
            const double one[1] = {1.0}, bal_k[3] = {1.0, -1.0, -1.0}, coll_k[2] = {1.0, -st};
            double in = group_sum(c, 1, k_in, one, ch, &se);
            CHECK(fabs(in - want) <= 5.5 * se, "%s, channel %d: scattered %.6g W, closed form %.6g (5.5 se %.3g)",
                  names[kase], ch, in, want, 5.5 * se);
            /* what scattered = what left + what was absorbed: in - out - absorbed, paired by group */
            double out = c->energy[VEIL_CACHE_ENERGY_OUT][ch], ab = c->energy[VEIL_CACHE_ENERGY_ABSORBED][ch];
            double bal = group_sum(c, 3, k_bal, bal_k, ch, &se), tol = 5.5 * se;
            CHECK(fabs(bal) <= tol, "%s, channel %d: scattered %.6g W, left %.6g + absorbed %.6g: off by %.3g > %.3g",
                  names[kase], ch, in, out, ab, bal, tol);
            if (absorbing)
                CHECK(ab > 0.1 * in, "channel %d: absorbed %.4g of %.4g W (albedo %.2f)", ch, ab, in,
                      s.medium.sigma_s[ch] / st);
            else
                CHECK(ab == 0.0, "channel %d: %.4g W absorbed at albedo 1", ch, ab);
            /* the fluence's cells hold the track length; sigma_t times it is what the collisions measure */
            double cells = 0.0, cells_later = 0.0;
            for (size_t k = 0; phi && k < 12 * 12 * 12; ++k) cells += phi[4 * k + ch] * V;
            for (size_t k = 0; later && k < 12 * 12 * 12; ++k) cells_later += later[4 * k + ch] * V;
            double track = c->energy[VEIL_CACHE_ENERGY_TRACK][ch];
            double track_later = c->energy[VEIL_CACHE_ENERGY_LATER_TRACK][ch];
            /* the same pieces of path, rounded apart. The fixed point: each add within one unit, unbiased,
             * independent of the others of this channel (its own random number); Hoeffding over the adds
             * (the cells': at most a visit a step, cap + 1 a photon; the account's: one a photon) gives
             * sqrt(2 ln(2/1e-9)) sqrt(n_c u_c^2 + n_a u_a^2), at most half of what is taken here. The
             * floats: a photon's track length is a float sum of at most cap pieces (recursive summation of
             * positive terms: within cap 2^-24 of it), and each cell a float in the texture (2^-24 of it;
             * 1728 cells taken at 6e-8 of the whole, a bound as loose) */
            double tol_t = track_tolerance(c, A, 2.0 / 12.0, track);
            CHECK(fabs(cells - track) <= tol_t, "channel %d: the cells' fluence times volume %.9g W m, the photons' "
                  "track length %.9g: off by %.3g > %.3g", ch, cells, track, cells - track, tol_t);
            /* the later light alone (its pieces are a subset of the same adds: the same bound holds) */
            CHECK(track_later > 0.05 * track && track_later < track, "channel %d: the later light's track %.4g of %.4g",
                  ch, track_later, track);
            CHECK(fabs(cells_later - track_later) <= tol_t, "channel %d: the later light's cells %.9g W m, its "
                  "track length %.9g: off by %.3g > %.3g", ch, cells_later, track_later, cells_later - track_later,
                  tol_t);
            if (!height) {
                /* Where the once-scattered light ends: what scatters a second time has the mean
                 * sigma_s x its track length (each tentative collision scatters w sigma_s / sigma_bar in the
                 * mean, and tentative collisions come at rate sigma_bar along the track), paired by group.
                 * Split at the wrong scattering, or a visit scored to the wrong lobe, it is not. */
                const int k_split[3] = {VEIL_CACHE_ENERGY_LATER_IN, VEIL_CACHE_ENERGY_TRACK, VEIL_CACHE_ENERGY_LATER_TRACK};
                const double split_k[3] = {1.0, -s.medium.sigma_s[ch], s.medium.sigma_s[ch]};
                double split = group_sum(c, 3, k_split, split_k, ch, &se);
                CHECK(fabs(split) <= 5.5 * se, "%s, channel %d: scattered again %.6g W, sigma_s x the once-scattered "
                      "track %.6g: off by %.3g > %.3g", names[kase], ch, c->energy[VEIL_CACHE_ENERGY_LATER_IN][ch],
                      s.medium.sigma_s[ch] * (track - track_later), split, 5.5 * se);
            }
            if (!height) { /* sigma_t the same everywhere: the two estimate one integral */
                double coll = group_sum(c, 2, k_coll, coll_k, ch, &se);
                CHECK(fabs(coll) <= 5.5 * se, "channel %d: collision estimator - sigma_t x track length = %.4g "
                      "(5.5 se %.3g; track %.6g W m)", ch, coll, 5.5 * se, track);
            }
            sum_in += in, sum_out += out;
            printf("energy (%s) channel %d: scattered %.5g W (closed form %.5g), left %.5g, absorbed %.4g; track "
                   "%.8g W m, cells %.8g (bound %.2g); scattered again %.5g W, later track %.6g W m\n", names[kase],
                   ch, in, want, out, ab, track, cells, tol_t, c->energy[VEIL_CACHE_ENERGY_LATER_IN][ch], track_later);
        }
        if (!absorbing) {
            /* each photon's channel sum is kept exactly: only the rounding separates in from out. Units of the
             * account: a photon's channel weight <= 3 phi_max = 2^20 units, phi_max the largest channel of
             * a photon's power, here E_max A / N. A photon's six adds (in, out; three channels) share one
             * random number, so its rounding error, within (-6, 6) units, is what is independent: Hoeffding
             * over N photons, P(|sum| >= t) <= 2 exp(-2 t^2 / (N 12^2)), t = 6 sqrt(2 N ln(2/1e-9)) units.
             * The floats: each step's update w_c *= s_c / (sigma_bar P) rounds each of the three channels
             * within 2^-24 of itself, so the weights' sum moves by at most 3 2^-24 of it a step, at most
             * cap steps: 3 cap 2^-24 of what scattered. */
            double unit = 3.0 * 3.0 * A / (double)c->photons / 1048576.0;
            double bound = 6.0 * sqrt(2.0 * (double)c->photons * log(2.0 / 1e-9)) * unit +
                           3.0 * c->cap * ldexp(1.0, -24) * sum_in;
            CHECK(fabs(sum_out - sum_in) <= bound, "albedo 1: the channels' sum %.9g W in, %.9g out: off by %.3g > "
                  "%.3g (the fixed point's rounding)", sum_in, sum_out, sum_out - sum_in, bound);
            printf("energy: albedo 1, %.9g W scattered, %.9g W left (rounding bound %.2g)\n", sum_in, sum_out, bound);
        }
        free(phi);
        free(later);
    }
}

static unsigned mc_state = 99u;
static double mc_rnd(void)
{
    mc_state = mc_state * 1664525u + 1013904223u;
    return ((double)(mc_state >> 8) + 0.5) / 16777216.0;
}

/* The analog walk of 5 on the CPU, one channel: photons in through the top of [-1, 1]^3 going down, scattered
 * (HG g) at rate sigma_s, absorbed by the floor at y_floor, gone through the box's other faces. The fraction of
 * those that scattered that the floor absorbs, and its standard error. */
static double mc_floor(double sigma_s, double g, double y_floor, int n, double* se)
{
    long scattered = 0, absorbed = 0;
    for (int i = 0; i < n; ++i) {
        double p[3] = {2.0 * mc_rnd() - 1.0, 1.0, 2.0 * mc_rnd() - 1.0}, d[3] = {0.0, -1.0, 0.0};
        double t = -log(mc_rnd()) / sigma_s;
        if (1.0 - t <= y_floor) continue;
        p[1] -= t;
        ++scattered;
        for (;;) {
            /* HG about d */
            double xi = mc_rnd(), s = (1.0 - g * g) / (1.0 - g + 2.0 * g * xi);
            double ct = (1.0 + g * g - s * s) / (2.0 * g), st = sqrt(fmax(0.0, 1.0 - ct * ct)), ph = 6.283185307179586 * mc_rnd();
            double a[3] = {fabs(d[0]) < 0.9 ? 1.0 : 0.0, fabs(d[0]) < 0.9 ? 0.0 : 1.0, 0.0}, u[3], v[3];
            u[0] = d[1] * a[2] - d[2] * a[1], u[1] = d[2] * a[0] - d[0] * a[2], u[2] = d[0] * a[1] - d[1] * a[0];
            double un = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            for (int k = 0; k < 3; ++k) u[k] /= un;
            v[0] = d[1] * u[2] - d[2] * u[1], v[1] = d[2] * u[0] - d[0] * u[2], v[2] = d[0] * u[1] - d[1] * u[0];
            for (int k = 0; k < 3; ++k) d[k] = ct * d[k] + st * (cos(ph) * u[k] + sin(ph) * v[k]);
            /* to the floor, to the box's faces */
            double t_floor = d[1] < 0.0 ? (p[1] - y_floor) / -d[1] : INFINITY, t_box = INFINITY;
            for (int k = 0; k < 3; ++k)
                if (d[k] != 0.0) t_box = fmin(t_box, ((d[k] > 0.0 ? 1.0 : -1.0) - p[k]) / d[k]);
            t = -log(mc_rnd()) / sigma_s;
            if (t >= fmin(t_floor, t_box)) {
                absorbed += t_floor < t_box;
                break;
            }
            for (int k = 0; k < 3; ++k) p[k] += t * d[k];
        }
    }
    double f = (double)absorbed / (double)scattered;
    *se = sqrt(f * (1.0 - f) / (double)scattered);
    return f;
}

static void floor_absorbs(veil_volumetric* d)
{
    veil_error err = {0};
    veil_source fog = fog_box();
    veil_light sun = {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0.0f, -1.0f, 0.0f}, .color = {1.0f, 2.0f, 3.0f}};
    veil_scene s = {0};
    const float sigma_s[3] = {1.0f, 0.6f, 0.3f}, g = 0.5f;
    for (int c = 0; c < 3; ++c) s.medium.sigma_s[c] = sigma_s[c];
    s.medium.phase = (veil_phase){.type = VEIL_PHASE_HG, .g = g};
    s.medium.sources = &fog;
    s.medium.source_count = 1;
    veil_multiple_defaults(&s.multiple);
    /* the floor, seen from 3 m above: each pixel's distance to y = 0 */
    enum { FW = 64 };
    veil_camera cam = {.position = {0, 3, 0}, .look_at = {0, 0, 0}, .up = {0, 0, -1}, .fov_y_deg = 60.0f,
                       .width = FW, .height = FW};
    veil_camera_basis b;
    CHECK(veil_camera_make_basis(&cam, FW, FW, &b, &err) == VEIL_OK, "%s", err.msg);
    float* dist = malloc(sizeof(float) * FW * FW);
    for (int y = 0; y < FW; ++y)
        for (int x = 0; x < FW; ++x) {
            float w[3];
            veil_camera_ray(&b, FW, FW, x, y, w);
            dist[y * FW + x] = 3.0f / -w[1];
        }
    veil_solid so;
    CHECK(veil_solid_build(&cam, FW, FW, dist, fog.fog.bounds[0], fog.fog.bounds[1], &sun, 1, &so, &err) == VEIL_OK &&
              so.voxels, "the floor's solid: %s", err.msg);
    free(dist);
    if (!so.voxels) return;
    /* the floor's height as vertical paths meet it, and within half a voxel below */
    double y_lo = INFINITY, y_hi = -INFINITY;
    const float down[3] = {0.0f, -1.0f, 0.0f};
    for (int j = 0; j < 40; ++j)
        for (int i = 0; i < 40; ++i) {
            float p[3] = {-0.99f + 1.98f * (float)i / 39.0f, 1.0f, -0.99f + 1.98f * (float)j / 39.0f};
            double y = 1.0 - veil_solid_hit(&so, p, down, 2.0f);
            y_lo = fmin(y_lo, y), y_hi = fmax(y_hi, y);
        }
    y_lo -= 0.5 * so.voxel, y_hi += 0.5 * so.voxel;
    CHECK(y_lo > -0.1 && y_hi < 0.1, "the floor is at y = 0: met between %g and %g", y_lo, y_hi);
    GLuint tex[2] = {0, 0}, opv[VEIL_MAX_OPV_TEXTURES] = {0};
    CHECK(veil_lit_medium_solid_textures(&so, tex, &err) == VEIL_OK, "%s", err.msg);
    veil_volumetric_desc vd = {.kind = VEIL_FIELD_CACHE,
                               .medium = {.scene = &s, .lights = &sun, .light_count = 1, .opv = opv, .solid = &so,
                                          .solid_voxels = tex[0], .solid_maps = tex[1]},
                               .cache = {.photons = 1 << 18, .cells = 12, .seed = 13}};
    veil_volumetric_field f;
    veil_volumetric_report rep;
    CHECK(veil_volumetric_update(d, &vd, 400, &f, &rep, &err) == VEIL_OK, "%s", err.msg);
    const veil_cache_report* c = &rep.cache;
    int dims[3] = {0, 0, 0};
    float* phi = veil_volumetric_readback(d, dims);
    CHECK(c->cut == 0 && c->misses == 0 && phi && dims[0] == 12 && dims[1] == 12 && dims[2] == 12,
          "the floor's cache: %u cut, %u misses, %dx%dx%d cells", c->cut, c->misses, dims[0], dims[1], dims[2]);
    /* each cell's part outside the solid */
    const double h = 2.0 / 12.0, V = h * h * h;
    double free_part[12 * 12 * 12];
    float* flux = veil_volumetric_readback_flux(d, dims);
    for (int k = 0; k < 12 * 12 * 12; ++k) {
        int cc[3] = {k % 12, k / 12 % 12, k / 144}, in = 0;
        for (int q = 0; q < 64; ++q) {
            float x[3];
            for (int a = 0; a < 3; ++a) x[a] = -1.0f + ((float)cc[a] + (((q >> (2 * a)) & 3) + 0.5f) / 4.0f) * (float)h;
            in += veil_solid_at(&so, x);
        }
        free_part[k] = 1.0 - in / 64.0;
    }
    int wrong = 0, partial = 0;
    for (int k = 0; flux && k < 12 * 12 * 12; ++k) {
        wrong += flux[4 * k + 3] != (float)free_part[k];
        partial += free_part[k] > 0.0 && free_part[k] < 1.0;
    }
    CHECK(flux && wrong == 0 && partial >= 144, "floor: %d cells' free part (the flux's alpha) is not the solid's "
          "(%d cells part solid)", wrong, partial);
    free(flux);
    for (int ch = 0; ch < 3; ++ch) {
        double se_g, se_lo, se_hi;
        const int k_in[1] = {VEIL_CACHE_ENERGY_IN}, k_ab[1] = {VEIL_CACHE_ENERGY_ABSORBED};
        const int k_bal[3] = {VEIL_CACHE_ENERGY_IN, VEIL_CACHE_ENERGY_OUT, VEIL_CACHE_ENERGY_ABSORBED};
        const double one[1] = {1.0}, bal_k[3] = {1.0, -1.0, -1.0};
        double in = group_sum(c, 1, k_in, one, ch, &se_g);
        double want_lo = sun.color[ch] * 4.0 * (1.0 - exp(-sigma_s[ch] * (1.0 - y_hi)));
        double want_hi = sun.color[ch] * 4.0 * (1.0 - exp(-sigma_s[ch] * (1.0 - y_lo)));
        CHECK(in >= want_lo - 5.5 * se_g && in <= want_hi + 5.5 * se_g, "floor, channel %d: scattered %.6g W, "
              "closed form %.6g .. %.6g (5.5 se %.3g)", ch, in, want_lo, want_hi, 5.5 * se_g);
        double bal = group_sum(c, 3, k_bal, bal_k, ch, &se_g);
        CHECK(fabs(bal) <= 5.5 * se_g, "floor, channel %d: scattered - left - absorbed = %.3g > %.3g", ch, bal,
              5.5 * se_g);
        double ab = group_sum(c, 1, k_ab, one, ch, &se_g);
        double frac = ab / in, se_frac = se_g / in; /* in's own spread is small beside it: a ratio of sums */
        double f_lo = mc_floor(sigma_s[ch], g, y_hi, 400000, &se_lo), f_hi = mc_floor(sigma_s[ch], g, y_lo, 400000, &se_hi);
        double lo = fmin(f_lo, f_hi) - 5.5 * sqrt(se_frac * se_frac + se_lo * se_lo);
        double hi = fmax(f_lo, f_hi) + 5.5 * sqrt(se_frac * se_frac + se_hi * se_hi);
        CHECK(frac >= lo && frac <= hi, "floor, channel %d: the floor absorbs %.5f of what scattered; the CPU walk "
              "%.5f .. %.5f (allowed %.5f .. %.5f)", ch, frac, f_lo, f_hi, lo, hi);
        double cells = 0.0, track = c->energy[VEIL_CACHE_ENERGY_TRACK][ch];
        for (int k = 0; k < 12 * 12 * 12; ++k) cells += phi[4 * k + ch] * V;
        double tol_t = track_tolerance(c, 4.0, h, track);
        CHECK(fabs(cells - track) <= tol_t, "floor, channel %d: the cells' sums times their volume %.9g W m, "
              "the track %.9g: off by %.3g > %.3g", ch, cells, track, cells - track, tol_t);
        printf("floor, channel %d: scattered %.5g W (closed form %.5g .. %.5g), the floor absorbs %.4f of it (CPU "
               "walk %.4f .. %.4f, se %.4f / %.4f); cells x volume %.7g, track %.7g\n", ch, in, want_lo, want_hi,
               frac, f_lo, f_hi, se_frac, se_lo, cells, track);
    }
    free(phi);
    glDeleteTextures(2, tex);
    veil_solid_free(&so);
}

/* 6. The environment's rest as a source: a map with a smooth sky and a bright disc (so that the clip takes
 * its top off), turned and Z-up, over an absorbing fog box that is not a cube. Its photons start on a disc
 * across their direction, from a table of texel blocks (scene/environment.h); the CPU samples the same map
 * through its own distribution (veil_env_sample, the reference's), independently. Two integrals checked:
 *  - what enters the grid (the account's "in": the environment's light counts from its start): the
 *    integral of R(w) A(w) over directions, R the rest and A the box's area seen along w (the faces'
 *    areas times |w . n|), by the CPU's Monte Carlo over R / pdf;
 *  - the track length of the light not yet scattered (the account's track less its later part), which is
 *    the integral over the box of its fluence: of R(w) exp(-sigma_t s) over directions and the box's
 *    points, s the way from the point to the box's side towards w; the CPU samples w and a point.
 * Both paired by group on the GPU side (5.5 standard errors of the groups' spread, as in 4) and the CPU's
 * own standard error beside it in quadrature. A wrong frame, disc, block or weight moves either. The map
 * is constant over blocks of 4 x 4 texels, so that the table's blocks of 4 (asked for by a small table)
 * hold the same map as blocks of 1: the one CPU integral checks both. */
static void environment_rest(veil_volumetric* d, int block)
{
    veil_error err = {0};
    veil_source fog = fog_box();
    const float lo[3] = {-1.0f, -0.5f, -1.5f}, hi[3] = {1.0f, 0.5f, 1.5f};
    for (int a = 0; a < 3; ++a) fog.fog.bounds[0][a] = lo[a], fog.fog.bounds[1][a] = hi[a];
    veil_scene s = {0};
    const float sigma_s[3] = {0.5f, 0.35f, 0.2f}, sigma_a[3] = {0.1f, 0.2f, 0.3f};
    for (int c = 0; c < 3; ++c) s.medium.sigma_s[c] = sigma_s[c], s.medium.sigma_a[c] = sigma_a[c];
    s.medium.phase = (veil_phase){.type = VEIL_PHASE_HG, .g = 0.5f};
    s.medium.sources = &fog;
    s.medium.source_count = 1;
    veil_multiple_defaults(&s.multiple);
    veil_environment* e = &s.environment;
    const int W = 96, H = 48;
    e->present = 1, e->width = W, e->height = H, e->rotation_deg = 30.0f, e->up_z = 1;
    e->rgb = malloc((size_t)W * H * 3 * sizeof *e->rgb);
    for (int j = 0; e->rgb && j < H; ++j)
        for (int i = 0; i < W; ++i) { /* constant over blocks of 4 x 4 texels: the same map in blocks of up to 4 */
            double t = VEIL_PI * (j / 4 * 4 + 2) / H, p = 2.0 * VEIL_PI * (i / 4 * 4 + 2) / W;
            double m[3] = {-sin(t) * cos(p), cos(t), -sin(t) * sin(p)};
            int sun = m[0] * 0.6 + m[1] * 0.8 > cos(10.0 * VEIL_PI / 180.0);
            float* x = e->rgb + 3 * ((size_t)j * W + i);
            x[0] = sun ? 400.0f : (float)(0.3 + 0.2 * m[1] + 0.1 * m[0]);
            x[1] = sun ? 380.0f : (float)(0.4 + 0.2 * m[1]);
            x[2] = sun ? 300.0f : (float)(0.7 + 0.1 * m[1] - 0.1 * m[2]);
        }
    static const int rungs[1] = {8};
    veil_env_make_cuts(e, 8, rungs, 1);
    CHECK(e->rgb && veil_env_dist_make(e, &err) == VEIL_OK, "the map: %s", err.msg);
    double rest[3], all[3];
    veil_env_part_integral(e, 0, rest);
    veil_env_integral(e, all);
    CHECK(rest[1] < 0.5 * all[1] && rest[1] > 0.05 * all[1], "the clip takes the disc's top off: the rest %.4g of %.4g",
          rest[1], all[1]);
    GLuint opv[VEIL_MAX_OPV_TEXTURES] = {0};
    /* the photons' table in blocks of block x block texels (a table smaller than the map asks for them) */
    const size_t texels = (size_t)(W / block) * (size_t)(H / block);
    veil_volumetric_desc vd = {.kind = VEIL_FIELD_CACHE,
                               .medium = {.scene = &s, .lights = NULL, .light_count = 0, .opv = opv},
                               .cache = {.photons = 1 << 18, .cells = 12, .seed = 17, .environment = 1,
                                         .env_texels = texels}};
    veil_volumetric_field f;
    veil_volumetric_report rep;
    CHECK(veil_volumetric_update(d, &vd, 500 + (uint64_t)block, &f, &rep, &err) == VEIL_OK, "%s", err.msg);
    const veil_cache_report* c = &rep.cache;
    CHECK(c->cut == 0 && c->misses == 0 && c->sources == 1 && c->photons > 0,
          "the environment's cache: %u cut, %u misses, %d sources, %lld photons", c->cut, c->misses, c->sources,
          c->photons);
    /* the CPU's integrals, N samples: the area seen and, at a point uniform in the box, exp(-sigma_t s) */
    enum { N = 1 << 20 };
    const double area[3] = {(hi[1] - lo[1]) * (hi[2] - lo[2]), (hi[0] - lo[0]) * (hi[2] - lo[2]),
                            (hi[0] - lo[0]) * (hi[1] - lo[1])};
    const double vol = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    double sum_in[3] = {0}, sq_in[3] = {0}, sum_tr[3] = {0}, sq_tr[3] = {0};
    mc_state = 4242u;
    for (int n = 0; n < N; ++n) {
        double w[3], L[3];
        double pdf = veil_env_sample(e, mc_rnd(), mc_rnd(), mc_rnd(), w);
        veil_env_radiance(e, w, L);
        double l = 0.2126 * L[0] + 0.7152 * L[1] + 0.0722 * L[2];
        double keep = l > e->clip ? e->clip / l : 1.0;
        double seen = fabs(w[0]) * area[0] + fabs(w[1]) * area[1] + fabs(w[2]) * area[2];
        double x[3], s_up = INFINITY;
        for (int a = 0; a < 3; ++a) {
            x[a] = lo[a] + mc_rnd() * (hi[a] - lo[a]);
            if (w[a] != 0.0) s_up = fmin(s_up, ((w[a] > 0.0 ? hi[a] : lo[a]) - x[a]) / w[a]);
        }
        for (int ch = 0; ch < 3; ++ch) {
            double r = L[ch] * keep / pdf, v_in = r * seen, v_tr = r * vol * exp(-(sigma_s[ch] + sigma_a[ch]) * s_up);
            sum_in[ch] += v_in, sq_in[ch] += v_in * v_in;
            sum_tr[ch] += v_tr, sq_tr[ch] += v_tr * v_tr;
        }
    }
    for (int ch = 0; ch < 3; ++ch) {
        double m_in = sum_in[ch] / N, m_tr = sum_tr[ch] / N;
        double se_in_cpu = sqrt((sq_in[ch] / N - m_in * m_in) / (N - 1.0));
        double se_tr_cpu = sqrt((sq_tr[ch] / N - m_tr * m_tr) / (N - 1.0));
        const int k_in[1] = {VEIL_CACHE_ENERGY_IN}, k_tr[2] = {VEIL_CACHE_ENERGY_TRACK, VEIL_CACHE_ENERGY_LATER_TRACK};
        const int k_bal[3] = {VEIL_CACHE_ENERGY_IN, VEIL_CACHE_ENERGY_OUT, VEIL_CACHE_ENERGY_ABSORBED};
        const double one[1] = {1.0}, diff[2] = {1.0, -1.0}, bal_k[3] = {1.0, -1.0, -1.0};
        double se_in, se_tr, se_bal;
        double in = group_sum(c, 1, k_in, one, ch, &se_in);
        double tr = group_sum(c, 2, k_tr, diff, ch, &se_tr);
        double bal = group_sum(c, 3, k_bal, bal_k, ch, &se_bal);
        double tol_in = 5.5 * sqrt(se_in * se_in + se_in_cpu * se_in_cpu);
        double tol_tr = 5.5 * sqrt(se_tr * se_tr + se_tr_cpu * se_tr_cpu);
        CHECK(fabs(in - m_in) <= tol_in, "environment (block %d), channel %d: %.6g W entered the grid, the CPU's "
              "integral %.6g: off by %.3g > %.3g", block, ch, in, m_in, in - m_in, tol_in);
        CHECK(fabs(tr - m_tr) <= tol_tr, "environment (block %d), channel %d: the unscattered light's track %.6g W m, "
              "the CPU's integral %.6g: off by %.3g > %.3g", block, ch, tr, m_tr, tr - m_tr, tol_tr);
        CHECK(fabs(bal) <= 5.5 * se_bal, "environment, channel %d: in - left - absorbed = %.3g > %.3g", ch, bal,
              5.5 * se_bal);
        CHECK(fabs(c->env_rest[ch] - rest[ch]) <= 1e-9 * rest[ch], "the report's rest %.9g, not %.9g", c->env_rest[ch],
              rest[ch]);
        printf("environment (block %d), channel %d: entered %.5g W (CPU %.5g, bound %.2g), unscattered track %.5g W m "
               "(CPU %.5g, bound %.2g)\n", block, ch, in, m_in, tol_in, tr, m_tr, tol_tr);
    }
    veil_env_free(e);
}

static double image_mean(const float* rgba, int n, int stride)
{
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += rgba[stride * i] + rgba[stride * i + 1] + rgba[stride * i + 2];
    return sum / (3.0 * n);
}

static void no_double_count(veil_gl* gl)
{
    veil_error err = {0};
    veil_source fog = fog_box();
    veil_light sun = {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0.3f, -0.8f, 0.5f}, .color = {3, 3, 3}};
    float n = sqrtf(0.09f + 0.64f + 0.25f);
    for (int a = 0; a < 3; ++a) sun.direction[a] /= n;
    veil_scene s = {0};
    s.camera = (veil_camera){.position = {0, 0.5f, 4.5f}, .look_at = {0, 0, 0}, .up = {0, 1, 0}, .fov_y_deg = 34,
                             .width = 24, .height = 18};
    for (int c = 0; c < 3; ++c) s.medium.sigma_s[c] = 1.0f, s.medium.sigma_a[c] = 0.05f;
    s.medium.phase = (veil_phase){.type = VEIL_PHASE_ISOTROPIC};
    s.medium.sources = &fog;
    s.medium.source_count = 1;
    s.lights = &sun;
    s.light_count = 1;
    veil_multiple_defaults(&s.multiple);
    s.multiple.screen_space = 0;
    s.multiple.volumetric_method = VEIL_VOLUMETRIC_CACHE;
    s.multiple.cache_photons = 1 << 19;
    s.multiple.cache_cells = 24;
    const int pixels = s.camera.width * s.camera.height;

    /* the reference, all orders */
    veil_pt_medium* m = NULL;
    float *ref = NULL, *se = NULL;
    CHECK(veil_pt_medium_from_scene(&s, &m, &err) == VEIL_OK, "%s", err.msg);
    veil_pt_opts o = {.spp = 256, .max_order = 0, .seed = 5};
    CHECK(m && veil_pt_render(m, &s, &o, &ref, &se, NULL, &err) == VEIL_OK, "%s", err.msg);
    veil_pt_medium_free(m);

    veil_renderer* r = NULL;
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    double noise = 0.0, cell = 0.0; /* the cache's, from its report in the first mode (cached in the second) */
    for (int mode = 0; mode < 2; ++mode) {
    /* mode 0: the later light from its lobe; 1: gathered towards the camera (16 rays a cell), which adds
     * its own noise: NS renders with other seeds (the same cache: it is seeded per volume) give NS means whose
     * spread s_g is that noise's; their mean has standard error s_g / sqrt(NS), taken 5.5 times (t with 7
     * degrees of freedom) in quadrature beside the rest */
    enum { NS = 8 };
    s.multiple.cache_gather_rays = mode == 0 ? -1 : 16; /* (isotropic: the default would not gather) */
    veil_image_set im = {0};
    veil_render_stats st = {0};
    double got_s[NS] = {0}, got = 0.0, gather_se = 0.0, multi = 0.0;
    const int renders = mode == 0 ? 1 : NS;
    for (int i = 0; i < renders; ++i) {
        veil_image_set_free(&im);
        CHECK(r && veil_render_scene_images(r, &s, &(veil_render_opts){.seed = 3u + (uint32_t)i}, &im, &st, &err) ==
                       VEIL_OK, "%s", err.msg);
        got_s[i] = im.rgba ? image_mean(im.rgba, pixels, 4) : 0.0;
        CHECK((strstr(st.stage[VEIL_STAGE_RENDER].why, "gathered towards the camera") != NULL) == (mode == 1),
              "mode %d: the render stage %s the later light: %s", mode, mode ? "gathers" : "does not gather",
              st.stage[VEIL_STAGE_RENDER].why);
        got += got_s[i] / renders;
        multi += (im.aov_v ? image_mean(im.aov_v, pixels, 4) : 0.0) / renders;
    }
    if (renders > 1) {
        double v = 0.0;
        for (int i = 0; i < renders; ++i) v += (got_s[i] - got) * (got_s[i] - got);
        gather_se = 5.5 / 4.0 * sqrt(v / (renders - 1) / renders); /* in units of the 4 below */
    }
    if (ref && se && im.rgba) {
        double want = image_mean(ref, pixels, 4);
        double single = image_mean(im.aov_s, pixels, 4);
        double var = 0.0;
        for (int i = 0; i < 3 * pixels; ++i) var += (double)se[i] * se[i];
        double se_mean = sqrt(var) / (3.0 * pixels);
        /* the cache's noise and cell, from its report (the volumetric stage's "why") */
        const char* why = st.stage[VEIL_STAGE_VOLUMETRIC].why;
        const char* at = strstr(why, "cells of ");
        if (at) cell = atof(at + 9);
        at = strstr(why, "noise ");
        if (at) noise = atof(at + 6) / 100.0;
        CHECK(cell > 0.0 && noise > 0.0, "the volumetric stage reports the cache: %s", why);
        double tol = 4.0 * sqrt(se_mean * se_mean + noise * multi * noise * multi + gather_se * gather_se) +
                     0.5 * (1.0 - exp(-1.05 * cell)) * multi;
        CHECK(single > 3.0 * tol, "the single scattering (mean %.5g) is far above the bound %.3g", single, tol);
        const char* how = mode == 0 ? "lobe" : "gathered";
        CHECK(fabs(got - want) <= tol,
              "%s: march + cache mean %.6g vs all orders %.6g: off by %.3g > %.3g (single %.5g, cache %.5g)", how, got,
              want, got - want, tol, single, multi);
        printf("no double counting (%s): march + cache %.6g, reference %.6g (se %.2g), bound %.3g; single %.5g, cache "
               "%.5g (noise %.2g %% a cell, cells of %.3g m; the gather's se %.2g)\n",
               how, got, want, se_mean, tol, single, multi, 100 * noise, cell, gather_se / (5.5 / 4.0));
    }
    veil_image_set_free(&im);
    }
    veil_renderer_destroy(r);
    free(ref);
    free(se);
}

int main(void)
{
    fixed_point();
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_volumetric* d = NULL;
    CHECK(veil_volumetric_create(&d, &err) == VEIL_OK, "%s", err.msg);
    if (d) determinism(d);
    if (d) energy(d);
    if (d) floor_absorbs(d);
    if (d) environment_rest(d, 1);
    if (d) environment_rest(d, 4);
    veil_volumetric_destroy(d);
    no_double_count(gl);
    veil_gl_destroy(gl);
    return check_finish();
}
