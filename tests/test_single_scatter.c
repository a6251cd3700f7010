/* Closed-form single scattering: a homogeneous box [0,1]^3 (density 1) lit
 * from above by a directional light, seen along horizontal rays at depth h
 * below the top face. Along such a ray the light reaching every point has
 * crossed h of medium, the phase angle is 90 degrees, and
 *   L = sigma_s p(0) E exp(-sigma_t h) (1 - exp(-sigma_t D)) / sigma_t
 *       + background exp(-sigma_t D),
 * with D the ray's chord through the box.
 *
 * Why the GPU marcher should meet it to rounding: h is chosen at a voxel
 * centre, where the optical depth of an axis-aligned directional light is
 * exact for every propagation method (the top voxels lie on the medium's
 * face, D = 0, and each voxel down adds one voxel of density) and the
 * texture is read at a texel centre;
 * the medium is constant, and each step integrates its in-scattering in
 * closed form, so the step size introduces no error here. What remains is
 * float rounding: per step a few operations of about 1 ulp and exp() within
 * 3 + 2|x| ulp (|x| < 1 here), about 8 ulp, accumulating over the N steps:
 * |L_gpu - L| <= 8 (N + 4) 2^-23 L. */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "render/camera.h"
#include "render/renderer.h"

static double hg(double c, double g) { return (1 - g * g) / (4 * VEIL_PI * pow(1 + g * g - 2 * g * c, 1.5)); }

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_renderer* r = NULL;
    veil_error err = {0};
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);

    /* 17 voxel centres per axis at 0, 1/16, ..., 1: the medium is [0,1]^3 */
    enum { N = 17, W = 33, H = 33 };
    const int row_voxel = 9; /* the camera's height is this voxel row's centre */
    veil_grid g = {.dims = {N, N, N}, .origin = {-0.5f / 16, -0.5f / 16, -0.5f / 16}, .voxel = 1.0f / 16};
    float* rho = malloc(N * N * N * sizeof(float));
    for (int v = 0; v < N * N * N; ++v) rho[v] = 1.0f;
    const float y = row_voxel / 16.0f, depth = 1.0f - y;

    veil_light sun = {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0, -1, 0}, .color = {1.0f, 2.0f, 3.0f}};
    veil_scene s = {0};
    s.camera = (veil_camera){.position = {0.5f, y, -2.0f}, .look_at = {0.5f, y, 0.0f}, .up = {0, 1, 0},
                             .fov_y_deg = 20.0f, .width = W, .height = H};
    s.medium.sigma_a[0] = 0.1f, s.medium.sigma_a[1] = 0.2f, s.medium.sigma_a[2] = 0.3f;
    s.medium.sigma_s[0] = 0.5f, s.medium.sigma_s[1] = 1.0f, s.medium.sigma_s[2] = 2.0f;
    s.medium.phase = (veil_phase){.type = VEIL_PHASE_HG, .g = 0.3f};
    s.lights = &sun;
    s.light_count = 1;
    s.background[0] = 0.2f, s.background[1] = 0.3f, s.background[2] = 0.4f;

    float* img = NULL;
    veil_render_stats st;
    CHECK(veil_render_density(r, &s, &g, rho, &(veil_render_opts){.seed = 1}, &img, &st, &err) == VEIL_OK, "%s",
          err.msg);
    veil_camera_basis cam;
    veil_camera_make_basis(&s.camera, W, H, &cam, &err);
    const int py = H / 2; /* sy = 0 exactly: horizontal rays */
    double worst = 0.0;
    int bad = 0, checked = 0;
    for (int px = 0; px < W && img; ++px) {
        float dir[3];
        veil_camera_ray(&cam, W, H, px, py, dir);
        /* chord through the box, slab test in double */
        double t0 = 0, t1 = INFINITY;
        for (int a = 0; a < 3; ++a) {
            if (dir[a] == 0) continue;
            double ta = (0 - cam.pos[a]) / dir[a], tb = (1 - cam.pos[a]) / dir[a];
            t0 = fmax(t0, fmin(ta, tb));
            t1 = fmin(t1, fmax(ta, tb));
        }
        double D = t1 > t0 ? t1 - t0 : 0.0;
        double steps = D / (VEIL_DEFAULT_STEP_VOXELS * g.voxel) + 1;
        for (int c = 0; c < 3; ++c) {
            double st_c = (double)s.medium.sigma_a[c] + s.medium.sigma_s[c];
            double L = s.medium.sigma_s[c] * hg(0.0, 0.3) * sun.color[c] * exp(-st_c * depth) *
                           (1 - exp(-st_c * D)) / st_c +
                       s.background[c] * exp(-st_c * D);
            double got = img[(py * W + px) * 4 + c];
            double tol = 8.0 * (steps + 4) * 0x1p-23 * L;
            double e = fabs(got - L);
            worst = fmax(worst, e / L);
            if (!(e <= tol)) {
                if (bad < 5) fprintf(stderr, "pixel %d ch %d: got %.9g expected %.9g (tol %.3g)\n", px, c, got, L, tol);
                ++bad;
            }
            ++checked;
        }
        double A = 1.0;
        for (int c = 0; c < 3; ++c) A -= exp(-((double)s.medium.sigma_a[c] + s.medium.sigma_s[c]) * D) / 3.0;
        double got_a = img[(py * W + px) * 4 + 3];
        if (!(fabs(got_a - A) <= 8.0 * (steps + 4) * 0x1p-23)) {
            fprintf(stderr, "pixel %d alpha: got %.9g expected %.9g\n", px, got_a, A);
            ++bad;
        }
    }
    printf("closed-form single scattering: %d values, largest relative error %.3g\n", checked, worst);
    CHECK(checked == 3 * W, "only %d values checked", checked);
    CHECK(bad == 0, "%d values outside the rounding bound", bad);
    free(img);
    free(rho);
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
    return check_finish();
}
