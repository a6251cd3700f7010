/* Motion blur in the rendered image (volume/motion_blur.h), on
 * make_test_vdbs's blur.vdb (a Gaussian puff, voxel h = 0.125 m, and a
 * value-0 "anchor" source that fixes the volume's box, so that every render
 * below marches the same lattice with the same steps):
 *
 *   test_motion_blur DATA_DIR
 *
 * 1. Zero velocity ("vel_zero") under an open shutter: the same image, bit
 *    for bit, as the scene without a shutter.
 *
 * 2. A constant velocity ("vel", 1 m a frame along x) over the shutter
 *    [1/16, 9/16] frames: D = 4 voxels, so N = 4 and t_k = 1/8 .. 4/8
 *    (veil_motion_blur_times), shifts of s_k = 1, 2, 3, 4 whole voxels. The
 *    blurred render against the mean of the four renders of the puff moved
 *    by s_k h (a "transform"), per pixel, in the transmittance T (the
 *    medium is a grey absorber: T = exp(-tau), the same in every channel).
 *
 *    Why they differ, and by how much. Each shifted volume holds the grid's
 *    values copied onto the one lattice, the blurred one their mean (the
 *    blur's samples fall on index points: tests/volume/test_motion_blur.c
 *    shows it is that mean to an ulp). The march's steps are the same in
 *    every render (same box, same seed), and its optical depth is linear in
 *    the volume's values (trilinear filtering, midpoint sums), so the
 *    blurred render's tau_b = mean_k tau_k. But its T_b = exp(-tau_b),
 *    while the mean render is mean_k exp(-tau_k). With f(tau) = e^-tau,
 *    Taylor about the mean tau' with a remainder at some xi between tau_k
 *    and tau':
 *      mean_k f(tau_k) - f(tau') = mean_k f''(xi_k) (tau_k - tau')^2 / 2,
 *    and 0 < f''(xi) = e^-xi <= e^-min_k tau_k, so
 *      0 <= mean_k T_k - T_b <= e^{-min_k tau_k} Var_k(tau_k) / 2
 *    (Jensen's gap of the convex e^-tau), Var over the N renders (1/N). The
 *    renders' tau_k = -ln T_k give the bound per pixel.
 *
 *    Rounding: T is a product of one factor e^-x a step. GLSL 4.5 (4.7.1)
 *    allows exp 3 + 2|x| ulp, x = sigma rho dt <= 2 x 1 x h/2 here, so
 *    <= 3.25; the product rounds by 0.5 ulp; x itself carries the
 *    volume's rounding to float (0.5 ulp of the mean) and the filter's
 *    arithmetic (a few ulp): ROUNDING_ULPS = 8 ulp of T a step, over the
 *    steps a ray can take (the box's diagonal over the default rung's
 *    half-voxel step, plus the jittered first one).
 *
 * 3. Anti-vacuity: the bound must bite (pixels where it is far above the
 *    rounding), and the blur must change the image far beyond it. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "frame/renderer.h"
#include "io/scene.h"
#include "volume/motion_blur.h"

enum { W = 48, H = 32, N = 4 };
/* ulp of T a march step (above) */
#define ROUNDING_ULPS 8.0
/* the anchor's voxels at index -16 and 16 on each axis: the volume's box is 33 voxels and the
 * trilinear ring, 35 a side at most; the default rung's step is half a voxel */
#define BOX_VOXELS 35.0
#define STEP_VOXELS 0.5

static const char* g_dir;

static veil_result render(veil_renderer* r, const char* puff, const char* camera, veil_image_set* im,
                          veil_error* err)
{
    char json[8192];
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0.3, 0.1, 9], \"look_at\": [0.3, 0.1, 0], \"fov_y_deg\": 20, "
             "\"width\": %d, \"height\": %d%s},"
             " \"medium\": {\"sigma_a\": [2, 2, 2], \"sigma_s\": [0, 0, 0], \"sources\": ["
             "{\"type\": \"vdb\", \"file\": \"%s/blur.vdb\"%s},"
             " {\"type\": \"vdb\", \"file\": \"%s/blur.vdb\", \"grid\": \"anchor\"}]},"
             " \"multiple_scattering\": {\"volumetric\": false, \"screen_space\": false}}",
             W, H, camera, g_dir, puff, g_dir);
    veil_scene s;
    veil_result res = veil_scene_parse("blur.json", json, strlen(json), &s, err);
    if (res != VEIL_OK) return res;
    memset(im, 0, sizeof *im);
    res = veil_render_scene_images(r, &s, &(veil_render_opts){.seed = 5}, im, NULL, err);
    veil_scene_free(&s);
    return res;
}

int main(int argc, char** argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_motion_blur DATA_DIR\n");
        return 2;
    }
    g_dir = argv[1];
    veil_gl* gl = check_gpu_or_skip();
    veil_renderer* r = NULL;
    veil_error err = {0};
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    if (!r) return check_finish();

    /* 1. zero velocity */
    veil_image_set still = {0}, zero = {0};
    CHECK(render(r, "", "", &still, &err) == VEIL_OK, "%s", err.msg);
    CHECK(render(r, ", \"velocity\": {\"grid\": \"vel_zero\"}", ", \"shutter\": [-0.5, 0.5]", &zero, &err) == VEIL_OK,
          "%s", err.msg);
    const size_t px = (size_t)W * H;
    if (still.rgba && zero.rgba) {
        CHECK(!memcmp(still.rgba, zero.rgba, px * 4 * sizeof(float)) &&
                  !memcmp(still.aov_t, zero.aov_t, px * 4 * sizeof(float)),
              "a zero velocity changed the image");
        printf("zero velocity: the image bit for bit\n");
    }
    veil_image_set_free(&zero);

    /* 2. a constant velocity against the mean of the shifted renders */
    const float shutter[2] = {0.0625f, 0.5625f};
    const int n = veil_motion_blur_samples(4.0);
    double t[VEIL_BLUR_MAX_SAMPLES];
    veil_motion_blur_times(shutter, n, t);
    CHECK(n == N, "N = %d", n);
    veil_image_set blurred = {0}, shifted[N];
    memset(shifted, 0, sizeof shifted);
    CHECK(render(r, ", \"velocity\": {\"grid\": \"vel\", \"unit\": \"frame\"}", ", \"shutter\": [0.0625, 0.5625]",
                 &blurred, &err) == VEIL_OK,
          "%s", err.msg);
    int ok = blurred.aov_t != NULL && still.aov_t != NULL;
    for (int k = 0; k < N && n == N; ++k) {
        /* the shift of time t_k: 1 m a frame, in metres */
        char puff[256];
        snprintf(puff, sizeof puff, ", \"transform\": [[1, 0, 0, %.17g], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]",
                 1.0 * t[k]);
        CHECK(render(r, puff, "", &shifted[k], &err) == VEIL_OK, "shift %d: %s", k, err.msg);
        ok &= shifted[k].aov_t != NULL;
    }
    if (ok && n == N) {
        const double steps = BOX_VOXELS * sqrt(3.0) / STEP_VOXELS + 1.0;
        size_t bad = 0, biting = 0, changed = 0;
        double worst = -INFINITY, worst_bound = 0.0, most_gap = 0.0;
        for (size_t i = 0; i < px; ++i) {
            double tau[N], mean_t = 0.0, mean_tau = 0.0, min_tau = INFINITY, var = 0.0;
            for (int k = 0; k < N; ++k) {
                const double T = shifted[k].aov_t[4 * i];
                tau[k] = -log(T);
                mean_t += T / N, mean_tau += tau[k] / N, min_tau = fmin(min_tau, tau[k]);
            }
            for (int k = 0; k < N; ++k) var += (tau[k] - mean_tau) * (tau[k] - mean_tau) / N;
            const double tb = blurred.aov_t[4 * i], gap = mean_t - tb;
            const double jensen = exp(-min_tau) * var / 2.0;
            const double rounding = steps * ROUNDING_ULPS * FLT_EPSILON * fmax(mean_t, tb);
            if (!(gap >= -rounding && gap <= jensen + rounding)) {
                if (bad++ < 5)
                    fprintf(stderr, "pixel %zu: mean T_k %.7g, T_b %.7g: gap %.3g outside [-%.3g, %.3g]\n", i, mean_t,
                            tb, gap, rounding, jensen + rounding);
            }
            if (gap - jensen > worst) worst = gap - jensen, worst_bound = jensen;
            most_gap = fmax(most_gap, gap);
            biting += jensen > 100.0 * rounding;
            changed += fabs(tb - still.aov_t[4 * i]) > 10.0 * (jensen + rounding) + 0.01;
        }
        printf("constant velocity: %zu pixels, largest Jensen gap %.4g, %zu where the bound is over 100x the "
               "rounding, %zu changed by the blur beyond 10x the bound; worst gap - bound %.3g (bound %.3g)\n",
               px, most_gap, biting, changed, worst, worst_bound);
        CHECK(bad == 0, "%zu pixels outside 0 <= mean_k T_k - T_b <= e^-min tau Var(tau) / 2 (+ rounding)", bad);
        CHECK(biting > 20, "the Jensen bound bites at %zu pixels only: the test is vacuous", biting);
        CHECK(changed > 20, "the blur changed %zu pixels only", changed);
    }
    for (int k = 0; k < N; ++k) veil_image_set_free(&shifted[k]);
    veil_image_set_free(&blurred);
    veil_image_set_free(&still);
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
    return check_finish();
}
