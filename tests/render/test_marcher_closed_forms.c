/* The GPU ray marcher (render/shaders/march.comp) against closed forms,
 * each within a step-error bound derived here for the marcher's own steps.
 *
 * 1. Airlight of an isotropic point light in homogeneous fog (Sun et al.
 *    2005, tests/support/airlight.h). With no volume the marcher takes steps
 *    Delta <= max(s0, 0.02 t) (s0 = VEIL_FOG_MIN_STEP, t the step's start)
 *    and for fog of density 1 computes exactly sigma_s g(m) int_step
 *    e^{-sigma_t t} dt, with g(t) = I e^{-sigma_t d(t)} / (4 pi d(t)^2) taken
 *    at the step's midpoint m. The exact value has g(t) inside the integral;
 *    expanding g about m, per step of half-length a = Delta/2:
 *      |int e^{-st} (t - m) dt| = e^{-sm} |int_{-a}^{a} u e^{-su} du|
 *                              <= e^{-sm} a^2 sinh(s a) <= e^{-sm} s a^3 cosh(s a),
 *      int e^{-st} (t - m)^2 dt <= e^{-s(m - a)} 2 a^3 / 3,
 *    so the error of a step is at most
 *      Delta^3 e^{-s(m - a)} (s |g'(m)| cosh(s a) / 8 + max|g''| / 12 / 2)
 *    (s = sigma_t), and summed over steps, with Delta <= w(t) =
 *    max(s0, 0.02 t) for every t in the step:
 *      |E| <= sigma_s int w(t)^2 phi(t) dt,  phi(t) = max over |u - t| <= w(t) of
 *             e^{-s(u - w)} (s |g'(u)| cosh(s w / 2) / 8 + |g''(u)| / 24),
 *    which the test evaluates with g', g'' by finite differences in double
 *    (the max over the window on a grid 40x finer than w). Float rounding
 *    adds 8 (N + 4) 2^-23 relative (tests/render/test_single_scatter.c), N bounded
 *    by the number of steps of length max(s0, min(0.02 t, 0.25 h)) (h the
 *    light's distance to the ray: the nearest-light term never goes below
 *    it), plus the 1e-6 of veil_step_integral's series.
 * 2. A Gaussian particle, voxelised, seen through: T = exp(-sigma_t D) with
 *    D its erf line integral. The marcher samples the trilinear field at
 *    step midpoints: |sum rho(m_i) Delta_i - int rho| <= sum Delta_i
 *    osc_i(rho) <= Delta_max TV(rho), TV the total variation along the ray
 *    (measured on a fine grid: the field is a smooth cubic per cell). The
 *    GPU's texture filter may round the interpolation weights to 8 bits:
 *    a further |d rho| <= 2^-8 * 3 * (largest neighbour difference) per
 *    sample. Voxelisation adds |D_trilinear - D_erf| (exact, reference/).
 * 3. Beer-Lambert through exponential fog along a slanted ray: every step's
 *    fog integral is the closed form, so only rounding remains:
 *    |D_gpu - D| <= 8 (N + 4) 2^-23 D with N <= chord / s0 + 2.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "reference/closed_forms.h"
#include "reference/optical_depth.h"
#include "frame/renderer.h"
#include "support/airlight.h"
#include "support/scene_util.h"
#include "volume/scene_volume.h"

static veil_renderer* ren;

static void render1(const veil_scene* s, float out[4], float step_voxels)
{
    veil_render_opts o = {0};
    o.width = o.height = 1;
    o.step_voxels = step_voxels;
    float* img = NULL;
    veil_error err = {0};
    veil_result r = veil_render_scene(ren, s, &o, &img, NULL, &err);
    CHECK(r == VEIL_OK, "render: %s", err.msg);
    for (int c = 0; c < 4; ++c) out[c] = img ? img[c] : NAN;
    free(img);
}

/* g(t) of the airlight: I e^{-s d} / (4 pi d^2), d the distance to the light */
typedef struct air {
    double o[3], d[3], S[3], I, st;
} air;

static double air_g(const air* a, double t)
{
    double d2 = 0.0;
    for (int k = 0; k < 3; ++k) d2 += (a->o[k] + t * a->d[k] - a->S[k]) * (a->o[k] + t * a->d[k] - a->S[k]);
    return a->I * exp(-a->st * sqrt(d2)) / (4.0 * VEIL_PI * d2);
}

static void test_airlight_gpu(void)
{
    /* tests/data/scenes/airlight_point.json: viewer at the origin looking along
     * (2, 0.5, 0); a point light of intensity 10 at (0, 1, 0); homogeneous fog of
     * density 1 filling [-20, 20]^3: the ray leaves it at x = 20 */
    veil_scene s = test_single_scattering(test_load_scene("airlight_point.json"));
    float px[4];
    render1(&s, px, 0.0f);
    air a;
    test_camera_ray(&s, a.o, a.d);
    a.S[0] = 0, a.S[1] = 1, a.S[2] = 0;
    a.I = 10.0;
    double D = 1.0, cg = a.d[1], gam = acos(cg), T = 20.0 / a.d[0], h = D * sin(gam);
    const double s0 = VEIL_FOG_MIN_STEP;
    /* N: steps of the smallest length the marcher can take, plus the jittered first and the clipped last */
    double n_steps = 2.0;
    for (double t = 0.0; t < T; t += fmax(s0, fmin(0.02 * t, 0.25 * h))) n_steps += 1.0;
    for (int c = 0; c < 3; ++c) {
        double ss = s.medium.sigma_s[c];
        a.st = (double)s.medium.sigma_a[c] + ss;
        double want = airlight(ss, a.st, a.I, D, gam, T);
        double bound = 0.0, dt = 1e-3;
        for (double t = 0.5 * dt; t < T; t += dt) { /* midpoint rule of the bound's integral, dt << w */
            double w = fmax(s0, 0.02 * t), phi = 0.0, du = w / 40.0;
            for (double u = fmax(0.0, t - w); u <= fmin(T, t + w); u += du) {
                const double e = 1e-4;
                double g1 = (air_g(&a, u + e) - air_g(&a, u - e)) / (2 * e);
                double g2 = (air_g(&a, u + e) - 2 * air_g(&a, u) + air_g(&a, u - e)) / (e * e);
                double v = exp(-a.st * (u - w)) * (a.st * fabs(g1) * cosh(0.5 * a.st * w) / 8.0 + fabs(g2) / 24.0);
                phi = fmax(phi, v);
            }
            bound += ss * w * w * phi * dt;
        }
        double tol = bound + (8.0 * (n_steps + 4) * 0x1p-23 + 1e-6) * want;
        double err = fabs(px[c] - want);
        CHECK(err <= tol, "airlight ch %d: GPU %.7g vs closed form %.7g: error %.3g > bound %.3g", c, px[c], want,
              err, tol);
        printf("  airlight ch %d: GPU %.7f closed form %.7f, error %.2e, derived bound %.2e (step %.2e)\n", c, px[c],
               want, err, tol, bound);
    }
    veil_scene_free(&s);
}

/* cam_z: where the camera is on the z axis; step: in voxels. The far
 * camera with a small step is where t + 1e-4 step can round back to t in
 * the marcher's empty-brick skip (fixed there; this geometry did not
 * trigger the old stall, bench/accuracy's vdb-smoke at step 0.125 did). */
static void test_gaussian_gpu(double cam_z, float step_voxels)
{
    char json[1024];
    snprintf(json, sizeof json,
        "{\"camera\":{\"position\":[0.1,0.05,%g],\"look_at\":[0.1,0.05,0],\"width\":1,\"height\":1},"
        "\"medium\":{\"sigma_a\":[0.3,0.3,0.3],\"sigma_s\":[0.4,0.7,1.0],\"max_resolution\":64,\"sources\":[{\"type\":"
        "\"rbf\",\"particles\":[{\"center\":[0,0,0],\"amplitude\":2.0,\"sharpness\":3.0}]}]},"
        "\"lights\":[],\"background\":{\"color\":[1,1,1]}}", cam_z);
    veil_scene s = test_parse_scene_single(json);
    veil_scene_volume v;
    veil_error err = {0};
    float* rho = NULL;
    CHECK(veil_scene_volume_open(&s, &v, &err) == VEIL_OK, "%s", err.msg);
    CHECK(veil_scene_volume_density(&v, &rho, &err) == VEIL_OK, "%s", err.msg);
    float px[4];
    render1(&s, px, step_voxels);
    double o[3], d[3];
    test_camera_ray(&s, o, d);
    const veil_grid* g = &v.grid;
    double h = g->voxel, zlo = g->origin[2] + 0.5 * h, zhi = g->origin[2] + (g->dims[2] - 0.5) * h;
    const double c0 = 2.0, a = 3.0;
    double d2 = o[0] * o[0] + o[1] * o[1];
    double D_erf = c0 * sqrt(VEIL_PI) / a * exp(-a * a * d2) * 0.5 * (erf(a * zhi) - erf(a * zlo));
    double pa[3] = {o[0], o[1], cam_z}, pb[3] = {o[0], o[1], -cam_z};
    double D_tri = veil_ref_segment_optical_depth(g, rho, pa, pb);
    /* total variation along the ray, and the largest neighbour difference */
    double tv = 0.0, prev = 0.0, jump = 0.0;
    for (double z = zlo; z <= zhi; z += h / 200.0) {
        double x[3] = {o[0], o[1], z};
        double r = veil_ev_sample(g, rho, x);
        tv += fabs(r - prev);
        prev = r;
    }
    tv += prev;
    size_t n = veil_grid_voxels(g);
    for (size_t i = 0; i + 1 < n; ++i) jump = fmax(jump, fabs(rho[i + 1] - rho[i]));
    for (size_t i = 0; i + (size_t)g->dims[0] < n; ++i) jump = fmax(jump, fabs(rho[i + g->dims[0]] - rho[i]));
    size_t slab = (size_t)g->dims[0] * (size_t)g->dims[1];
    for (size_t i = 0; i + slab < n; ++i) jump = fmax(jump, fabs(rho[i + slab] - rho[i]));
    double step = step_voxels * h, chord = zhi - zlo, n_steps = chord / step + 2;
    double dD = step * tv + 0x1p-8 * 3.0 * jump * chord + 8.0 * (n_steps + 4) * 0x1p-23 * D_tri;
    double A = 1.0, A_bound = 0.0;
    for (int c = 0; c < 3; ++c) {
        double st = (double)s.medium.sigma_a[c] + s.medium.sigma_s[c];
        double want = exp(-st * D_erf);
        /* |e^{-x} - e^{-y}| <= |x - y| e^{-min(x, y)} */
        double tol = st * (fabs(D_tri - D_erf) + dD) * exp(-st * (fmin(D_tri, D_erf) - dD)) + 8.0 * (n_steps + 4) * 0x1p-23;
        CHECK(fabs(px[c] - want) <= tol, "Gaussian ch %d: GPU %.7g vs erf %.7g (error %.3g > bound %.3g)", c, px[c],
              want, fabs(px[c] - want), tol);
        printf("  Gaussian (camera at %g m, step %g) ch %d: GPU T %.7f erf %.7f, error %.2e, bound %.2e (voxelisation %.1e, steps %.1e)\n", -cam_z,
               (double)step_voxels, c, px[c], want, fabs(px[c] - want), tol, st * fabs(D_tri - D_erf), st * dD);
        A -= want / 3.0;
        A_bound += tol / 3.0;
    }
    CHECK(fabs(px[3] - A) <= A_bound, "Gaussian alpha %.7g vs %.7g", px[3], A);
    free(rho);
    veil_scene_volume_close(&v);
    veil_scene_free(&s);
}

static void test_fog_slant_gpu(void)
{
    /* tests/data/scenes/slanted_fog.json: fog of density 0.8 e^{-1.5 y} in the box
     * [-5, 5] x [-1, 3] x [-5, 5] (lo, hi, b and rho0 below), seen along a slanted ray */
    veil_scene s = test_single_scattering(test_load_scene("slanted_fog.json"));
    float px[4];
    render1(&s, px, 0.0f);
    double o[3], d[3], lo[3] = {-5, -1, -5}, hi[3] = {5, 3, 5}, ta = 0, tb = INFINITY;
    test_camera_ray(&s, o, d);
    for (int k = 0; k < 3; ++k) {
        double a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
        ta = fmax(ta, fmin(a, b));
        tb = fmin(tb, fmax(a, b));
    }
    const double b = 1.5, rho0 = 0.8f;
    double D = rho0 * exp(-b * o[1]) * (exp(-b * d[1] * ta) - exp(-b * d[1] * tb)) / (b * d[1]);
    double n_steps = (tb - ta) / VEIL_FOG_MIN_STEP + 2;
    for (int c = 0; c < 3; ++c) {
        double st = (double)s.medium.sigma_a[c] + s.medium.sigma_s[c], want = exp(-st * D);
        double tol = (st * 8.0 * (n_steps + 4) * 0x1p-23 * D + 8.0 * (n_steps + 4) * 0x1p-23) * want;
        CHECK(fabs(px[c] - want) <= tol, "slanted fog ch %d: GPU %.8g vs %.8g (error %.3g > %.3g)", c, px[c], want,
              fabs(px[c] - want), tol);
        printf("  slanted fog ch %d: GPU T %.8f closed form %.8f, error %.2e, bound %.2e\n", c, px[c], want,
               fabs(px[c] - want), tol);
    }
    veil_scene_free(&s);
}

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    if (veil_renderer_create(gl, &ren, &err) != VEIL_OK) {
        fprintf(stderr, "renderer: %s\n", err.msg);
        return 1;
    }
    test_airlight_gpu();
    test_gaussian_gpu(-3.0, VEIL_DEFAULT_STEP_VOXELS);
    test_gaussian_gpu(-60.0, 0.125f);
    test_fog_slant_gpu();
    veil_renderer_destroy(ren);
    veil_gl_destroy(gl);
    return check_finish();
}
