/* veil fog's renderer path (frame/renderer.h: opts.behind and
 * opts.behind_distance) against closed forms. Homogeneous fog of density 1
 * filling a box around the camera, no lights; the frame behind it is one
 * colour C at one Z depth D, so pixel p's ray meets it at d = D / cos(off
 * axis) and the density integral along the ray is P = d.
 * 1. Multiple scattering off: the pixel is exp(-sigma_t d) C exactly up to
 *    rounding (the fog's integral is closed form per step; about 8 ulp per
 *    step over N steps: 8 (N + 4) 2^-23 relative, N < 400 here), P = d and
 *    the march ends at d (depth of first interaction < d).
 * 2. The screen-space spread on (volumetric off, no lights): the surface's
 *    scattered light L_sc = (exp(-sigma_a P) - exp(-sigma_t P)) C is blurred.
 *    The chains average non-negative weights that sum to 1 away from the
 *    image's edges (a constant stays constant), and the leak mask keeps
 *    every pixel whole in the levels it is read from, so the centre pixel's
 *    spread light lies within [min, max] of L_sc over the image, up to float
 *    rounding (1e-5 relative, as tests/render/test_spread.c); the composed pixel is
 *    T C plus it: the paper's L_at + L'_sc. Nothing is lost or created:
 *    as C -> the frame, out -> exp(-sigma_a d) C within that range.
 * 3. A ray with nothing behind (+inf) goes on through the fog until it is
 *    opaque.
 * 4. The frame's surfaces shadow the fog (scene/solid.h), single scattering
 *    alone: a fog box from the wall's plane (z = -D - 0.05) to z = 1 and a
 *    sun with irradiance E.
 *    - Shining from behind the camera (travelling -z): the fog in front of
 *      the wall is all lit (its light's first solid is the wall, beyond it),
 *      so each pixel is the closed form of a sun through a slab:
 *        sigma_s E p(w_z) e^(-sigma_t) (1 - e^(-sigma_t (1 + |w_z|) d)) /
 *        (sigma_t (1 + |w_z|))
 *      (the light's path to the box's face z = 1 is 1 + t |w_z|). The march
 *      takes the light constant over a step, sampled at its middle: relative
 *      error (k dt)^2 / 24 with k = sigma_t |w_z| <= 0.7 and steps of at most
 *      VEIL_FOG_STEP_FRACTION d = 0.1 m, 2e-5; with the rounding of case 1.
 *      Fog the solid shadowed in front of the wall (it reaches 3.5 voxels in
 *      front) would cost up to 1 %.
 *    - Shining from beyond the wall (travelling +z): every point in front of
 *      it is dark but for those within b + h of the wall (b the light's
 *      bias, h the solid's voxel; the first solid along the light is the
 *      wall's far side, found within half a voxel), so each pixel's single
 *      scattering is at most sigma_s E p (b + h) / |w_z| (T and the light's
 *      transmittance <= 1): a few % of what it is unshadowed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "support/check.h"
#include "frame/renderer.h"
#include "scene/camera.h"
#include "scene/solid.h"

enum { W = 64, H = 48 };

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_renderer* r = NULL;
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    if (!r) return check_finish();
    veil_source fog = {.type = VEIL_SOURCE_EXPONENTIAL,
                       .fog = {.density = 1.0f, .falloff = 0.0f, .direction = {0, 1, 0},
                               .bounds = {{-50, -50, -50}, {50, 50, 50}}}};
    veil_scene s = {0};
    s.camera = (veil_camera){.position = {0, 0, 0}, .look_at = {0, 0, -1}, .up = {0, 1, 0}, .fov_y_deg = 12.0f,
                             .width = W, .height = H};
    const float sa[3] = {0.05f, 0.1f, 0.2f}, ss[3] = {0.3f, 0.4f, 0.5f}, C[3] = {2.0f, 1.0f, 0.5f};
    for (int c = 0; c < 3; ++c) s.medium.sigma_a[c] = sa[c], s.medium.sigma_s[c] = ss[c];
    s.medium.phase = (veil_phase){VEIL_PHASE_HG, 0.3f};
    s.medium.sources = &fog;
    s.medium.source_count = 1;
    veil_multiple_defaults(&s.multiple);
    s.multiple.screen_space = 0, s.multiple.volumetric = 0;
    s.multiple.levels = 3;
    const float D = 5.0f;
    float* frame = malloc((size_t)W * H * 4 * sizeof *frame);
    float* dist = malloc((size_t)W * H * sizeof *dist);
    veil_camera_basis b;
    CHECK(veil_camera_make_basis(&s.camera, W, H, &b, &err) == VEIL_OK, "%s", err.msg);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float dir[3];
            veil_camera_ray(&b, W, H, x, y, dir);
            size_t i = (size_t)y * W + (size_t)x;
            dist[i] = D / (dir[0] * b.fwd[0] + dir[1] * b.fwd[1] + dir[2] * b.fwd[2]);
            for (int c = 0; c < 3; ++c) frame[4 * i + c] = C[c];
            frame[4 * i + 3] = 1.0f;
        }
    dist[0] = INFINITY; /* the top-left pixel sees no surface */
    veil_image_set im = {0};
    veil_render_opts o = {.behind = frame, .behind_distance = dist};
    CHECK(veil_render_scene_images(r, &s, &o, &im, NULL, &err) == VEIL_OK, "%s", err.msg);
    double worst = 0.0;
    const double tol = 8.0 * (400 + 4) * pow(2.0, -23);
    for (size_t i = 1; im.rgba && i < (size_t)W * H; ++i) {
        double P = im.aov_t[4 * i + 3];
        CHECK(fabs(P - dist[i]) <= tol * dist[i], "pixel %zu: P = %.7g, distance %.7g", i, P, dist[i]);
        for (int c = 0; c < 3; ++c) {
            double want = exp(-(double)(sa[c] + ss[c]) * dist[i]) * C[c];
            double rel = fabs(im.rgba[4 * i + c] - want) / want;
            if (rel > worst) worst = rel;
        }
    }
    CHECK(worst <= tol, "MS off: worst relative error of exp(-sigma_t d) C: %.3g > %.3g", worst, tol);
    if (im.rgba) {
        /* it goes on until every channel's T < VEIL_MIN_TRANSMITTANCE: exp(-0.35 P) < 1e-4 at P > 26.3 */
        double P0 = im.aov_t[3], Tmax = fmax(im.aov_t[0], fmax(im.aov_t[1], im.aov_t[2]));
        CHECK(P0 > 2.0 * D && Tmax < 2e-4, "nothing behind: the ray goes on past %g m (P = %g, T %g)", D, P0, Tmax);
    }
    printf("MS off: worst relative error %.3g (bound %.3g)\n", worst, tol);

    /* 2. the spread */
    s.multiple.screen_space = 1;
    dist[0] = dist[1];
    veil_image_set im2 = {0};
    CHECK(veil_render_scene_images(r, &s, &o, &im2, NULL, &err) == VEIL_OK, "%s", err.msg);
    if (im2.rgba && im2.aov_m) {
        size_t ctr = (size_t)(H / 2) * W + W / 2;
        for (int c = 0; c < 3; ++c) {
            double lo = INFINITY, hi = 0.0;
            for (size_t i = 0; i < (size_t)W * H; ++i) {
                double P = im2.aov_t[4 * i + 3];
                double lsc = (exp(-(double)sa[c] * P) - exp(-(double)(sa[c] + ss[c]) * P)) * C[c];
                lo = fmin(lo, lsc), hi = fmax(hi, lsc);
            }
            double got = im2.aov_m[4 * ctr + c];
            CHECK(got >= lo * (1.0 - 1e-5) && got <= hi * (1.0 + 1e-5),
                  "channel %d: spread light %.7g outside [%.7g, %.7g] (min, max of L_sc)", c, got, lo, hi);
            double T = im2.aov_t[4 * ctr + c];
            double composed = im2.rgba[4 * ctr + c];
            CHECK(fabs(composed - (T * C[c] + got)) <= 1e-5 * composed, "channel %d: composed %.7g != T C + spread %.7g",
                  c, composed, T * C[c] + got);
            printf("channel %d: spread %.6g in [%.6g, %.6g]; composed %.6g, exp(-sigma_a d) C = %.6g (level %.2f)\n", c,
                   got, lo, hi, composed, exp(-(double)sa[c] * dist[ctr]) * C[c], im2.aov_m[4 * ctr + 3]);
        }
    } else {
        CHECK(0, "the spread did not run");
    }
    veil_image_set_free(&im);
    veil_image_set_free(&im2);

    /* 4. shadows of the frame's surfaces */
    s.multiple.screen_space = 0;
    dist[0] = dist[1];
    fog.fog.bounds[0][2] = -D - 0.05f, fog.fog.bounds[1][2] = 1.0f;
    veil_light sun = {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0, 0, -1}, .color = {1.0f, 2.0f, 3.0f}};
    s.lights = &sun;
    s.light_count = 1;
    for (int back = 0; back < 2; ++back) {
        sun.direction[2] = back ? 1.0f : -1.0f;
        veil_solid so; /* the solid the renderer makes, for its voxel and bias */
        CHECK(veil_solid_build(&s.camera, W, H, dist, fog.fog.bounds[0], fog.fog.bounds[1], &sun, 1, &so, &err) ==
                  VEIL_OK && so.voxels, "the solid: %s", err.msg);
        const double h = so.voxel, bias = so.bias[0][0];
        veil_solid_free(&so);
        veil_image_set im4 = {0};
        CHECK(veil_render_scene_images(r, &s, &o, &im4, NULL, &err) == VEIL_OK, "%s", err.msg);
        double worst4 = 0.0, worst_ratio = 0.0;
        const double tol4 = 2e-5 + 8.0 * (400 + 4) * pow(2.0, -23);
        for (int y = 0; im4.aov_s && y < H; ++y)
            for (int x = 0; x < W; ++x) {
                size_t i = (size_t)y * W + (size_t)x;
                float w[3];
                veil_camera_ray(&b, W, H, x, y, w);
                double wz = fabs(w[2]), d = dist[i];
                double p = veil_phase_hg(sun.direction[2] * -w[2], s.medium.phase.g);
                for (int c = 0; c < 3; ++c) {
                    double st = (double)sa[c] + ss[c], got = im4.aov_s[4 * i + c];
                    if (!back) {
                        double k = st * (1.0 + wz);
                        double want = ss[c] * sun.color[c] * p * exp(-st) * (1.0 - exp(-k * d)) / k;
                        worst4 = fmax(worst4, fabs(got - want) / want);
                    } else {
                        double bound = ss[c] * sun.color[c] * p * (bias + h) / wz;
                        double open = ss[c] * sun.color[c] * p * exp(-st * (D + 0.05 - wz * d)) * d; /* lower bound */
                        worst_ratio = fmax(worst_ratio, got / bound);
                        if (x == W / 2 && y == H / 2)
                            CHECK(bound < 0.1 * open, "the bound %.4g is not far below the unshadowed light %.4g",
                                  bound, open);
                    }
                }
            }
        if (!back) {
            CHECK(worst4 <= tol4, "lit from the camera's side: single scattering off the closed form by %.3g > %.3g "
                  "(the frame's solid shadows the fog before it?)", worst4, tol4);
            printf("shadows: lit from the camera's side, worst relative error %.3g (bound %.3g)\n", worst4, tol4);
        } else {
            CHECK(worst_ratio <= 1.0 + 1e-4, "lit from beyond the wall: single scattering %.3g x its bound "
                  "sigma_s E p (b + h) / |w_z| (b %.3g m, h %.3g m)", worst_ratio, bias, h);
            printf("shadows: lit from beyond the wall, at most %.3g of the bound (b %.3g m, h %.3g m)\n", worst_ratio,
                   bias, h);
        }
        veil_image_set_free(&im4);
    }
    free(frame);
    free(dist);
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
    return check_finish();
}
