/* The image set's AOVs against closed forms: homogeneous fog of density rho
 * in the box [0,1]^3 (analytic, falloff 0), a sun from above, horizontal
 * rays at height y through the box from a camera at z = -2. Along a ray the
 * chord is C (entry t0, exit t1) and, per channel, k = sigma_t rho:
 *   T     = exp(-k C)
 *   P     = rho C (density m)
 *   depth = the mean over channels of the first-interaction distance,
 *           weighted by what each channel loses:
 *           sum_c [t0 (1 - e^{-kC}) + 1/k - (C + 1/k) e^{-kC}] / sum_c (1 - e^{-kC})
 *   single + T background = rgb (the compose identity)
 *   Z     = depth x cos(the pixel's ray, the view axis), +infinity on a miss
 * Bounds. T and P: the fog's integral is exact per step, so only rounding:
 * about 8 ulp a step over N steps, 8 (N + 4) 2^-23 relative. depth: the
 * march puts each step's lost transmittance at the step's midpoint; the
 * centroid of an exponential over a step dt sits before the midpoint by
 * dt (1/2 - 1/x + 1/(e^x - 1)) <= dt x / 12 with x = k dt (from
 * 1/x - 1/(e^x - 1) >= 1/2 - x/12), so |depth - exact| <= k_max dt_max^2 / 12
 * plus the rounding of the sums, 8 (N + 4) 2^-23 t1. Pixels whose rays miss
 * the box must read T = 1, P = 0, depth = 0. The set is then written with
 * its AOVs and each channel read back by name must equal its plane. */
#define _DEFAULT_SOURCE /* mkstemps */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "support/check.h"
#include "frame/renderer.h"
#include "io/image.h"
#include "scene/camera.h"

enum { W = 31, H = 23 };

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_renderer* r = NULL;
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    const double rho = 1.5, y = 0.55;
    veil_source fog = {.type = VEIL_SOURCE_EXPONENTIAL,
                       .fog = {.density = (float)rho, .falloff = 0.0f, .direction = {0, 1, 0},
                               .bounds = {{0, 0, 0}, {1, 1, 1}}}};
    veil_light sun = {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0, -1, 0}, .color = {2, 3, 4}};
    veil_scene s = {0};
    s.camera = (veil_camera){.position = {0.5f, (float)y, -2.0f}, .look_at = {0.5f, (float)y, 0.0f},
                             .up = {0, 1, 0}, .fov_y_deg = 40.0f, .width = W, .height = H};
    s.medium.sigma_a[0] = 0.1f, s.medium.sigma_a[1] = 0.3f, s.medium.sigma_a[2] = 0.6f;
    s.medium.sigma_s[0] = 0.5f, s.medium.sigma_s[1] = 1.0f, s.medium.sigma_s[2] = 1.5f;
    s.medium.sources = &fog;
    s.medium.source_count = 1;
    s.lights = &sun;
    s.light_count = 1;
    s.background[0] = 0.2f, s.background[1] = 0.1f, s.background[2] = 0.05f;
    veil_image_set im = {0};
    veil_render_stats st;
    CHECK(r && veil_render_scene_images(r, &s, &(veil_render_opts){.seed = 5}, &im, &st, &err) == VEIL_OK, "%s",
          err.msg);
    CHECK(im.width == W && im.height == H && im.rgba && im.aov_t && im.aov_s, "image set %dx%d", im.width,
          im.height);
    veil_camera_basis cam;
    veil_camera_make_basis(&s.camera, W, H, &cam, &err);
    int hits = 0, misses = 0, bad = 0;
    double worst_depth = 0.0;
    for (int py = 0; py < H && im.aov_s; ++py)
        for (int px = 0; px < W; ++px) {
            float df[3];
            veil_camera_ray(&cam, W, H, px, py, df);
            double t0 = 0, t1 = INFINITY;
            for (int a = 0; a < 3; ++a) {
                if (df[a] == 0) continue;
                double ta = (0 - cam.pos[a]) / df[a], tb = (1 - cam.pos[a]) / df[a];
                t0 = fmax(t0, fmin(ta, tb));
                t1 = fmin(t1, fmax(ta, tb));
            }
            const float* rgba = im.rgba + 4 * (py * W + px);
            const float* at = im.aov_t + 4 * (py * W + px);
            const float* as = im.aov_s + 4 * (py * W + px);
            if (!(t1 > t0 + 1e-3)) { /* a miss (or a graze too thin to judge) */
                if (t1 <= t0) {
                    ++misses;
                    bad += !(at[0] == 1.0f && at[1] == 1.0f && at[2] == 1.0f && at[3] == 0.0f && as[3] == 0.0f &&
                             im.aov_z && isinf(im.aov_z[py * W + px]) && im.aov_z[py * W + px] > 0.0f);
                }
                continue;
            }
            ++hits;
            double C = t1 - t0, dt = fmax(0.01, 0.02 * t1), steps = C / 0.01 + 1;
            double round = 8.0 * (steps + 4) * 0x1p-23, num = 0, den = 0, kmax = 0;
            for (int c = 0; c < 3; ++c) {
                double k = ((double)s.medium.sigma_a[c] + s.medium.sigma_s[c]) * rho, e = exp(-k * C);
                kmax = fmax(kmax, k);
                num += t0 * (1 - e) + 1 / k - (C + 1 / k) * e;
                den += 1 - e;
                if (!check_close(at[c], e, 0, round)) {
                    if (bad++ < 5) fprintf(stderr, "pixel %d,%d T[%d] %.9g, expected %.9g\n", px, py, c, at[c], e);
                }
                double compose = as[c] + at[c] * s.background[c];
                if (!check_close(rgba[c], compose, 0, 4 * 0x1p-23)) {
                    if (bad++ < 5) fprintf(stderr, "pixel %d,%d rgb[%d] %.9g != single + T bg %.9g\n", px, py, c, rgba[c], compose);
                }
            }
            if (!check_close(at[3], rho * C, 0, round)) {
                if (bad++ < 5) fprintf(stderr, "pixel %d,%d P %.9g, expected %.9g\n", px, py, at[3], rho * C);
            }
            double depth = num / den, tol = kmax * dt * dt / 12 + round * t1;
            worst_depth = fmax(worst_depth, fabs(as[3] - depth) / tol);
            if (!(fabs(as[3] - depth) <= tol)) {
                if (bad++ < 5) fprintf(stderr, "pixel %d,%d depth %.9g, expected %.9g (tol %.3g)\n", px, py, as[3], depth, tol);
            }
            /* Z: the depth along the view axis (+z here): depth x the ray's z over its length, the same
             * bound scaled by that cosine (<= 1) plus a float's rounding of the product */
            double n = sqrt((double)df[0] * df[0] + (double)df[1] * df[1] + (double)df[2] * df[2]), cz = df[2] / n;
            float z = im.aov_z ? im.aov_z[py * W + px] : NAN;
            if (!(fabs(z - depth * cz) <= tol * cz + 4 * 0x1p-23 * depth)) {
                if (bad++ < 5) fprintf(stderr, "pixel %d,%d Z %.9g, expected %.9g\n", px, py, z, depth * cz);
            }
        }
    printf("%d hits, %d misses; depth error at most %.3f of its bound\n", hits, misses, worst_depth);
    CHECK(hits > W * H / 4, "only %d pixels see the box", hits);
    CHECK(misses > 0, "no pixel misses the box: the miss case is untested");
    CHECK(bad == 0, "%d AOV values off their closed forms", bad);

    /* written with its AOVs, every channel reads back by name, bit for bit */
    char path[] = "/tmp/veil_image_set_XXXXXX.exr";
    int fd = mkstemps(path, 4);
    CHECK(fd >= 0, "mkstemps");
    if (fd >= 0) close(fd);
    CHECK(veil_image_set_write_exr(&im, path, 1, &err) == VEIL_OK, "%s", err.msg);
    float* plane = malloc(sizeof(float) * W * H);
    for (int c = 0; c < VEIL_IMAGE_SET_CHANNELS && plane; ++c) {
        float* got = NULL;
        int w = 0, h = 0;
        veil_result res = veil_read_exr_channel(path, veil_image_set_channel_names[c], &w, &h, &got, &err);
        CHECK(res == VEIL_OK && w == W && h == H, "channel %s: %s", veil_image_set_channel_names[c], err.msg);
        veil_image_set_plane(&im, c, plane);
        int same = got != NULL;
        for (int i = 0; got && i < W * H; ++i) same = same && got[i] == plane[i];
        CHECK(same, "channel %s differs from its plane", veil_image_set_channel_names[c]);
        free(got);
    }
    free(plane);
    unlink(path);
    veil_image_set_free(&im);
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
    return check_finish();
}
