/* Closed-form single scattering: the medium fills the box [0,1]^3, lit from
 * above by a directional light, seen along horizontal rays at height y.
 * Along such a ray the density rho_y is constant, the light reaching every
 * point has crossed the density integral D_y from y to the top face, the
 * phase angle is 90 degrees, and
 *   L = sigma_s rho_y p(0) E exp(-sigma_t D_y) (1 - exp(-sigma_t rho_y C)) / (sigma_t rho_y)
 *       + background exp(-sigma_t rho_y C),
 * with C the ray's chord through the box. Three media:
 *  1. a voxel grid of density 1 (D_y = 1 - y): the extinction volume, its
 *     optical-depth volume and the march;
 *  2. homogeneous analytic fog (falloff 0), no grid at all: the same closed
 *     form through the fog path of the marcher;
 *  3. exponential fog rho0 exp(-b y): rho_y = rho0 exp(-b y) and
 *     D_y = rho0 (exp(-b y) - exp(-b)) / b;
 *  4. the grid's shadow on fog outside its box (test_shadow_on_fog, below).
 *
 * Why the GPU marcher should meet it to rounding: y is at a voxel centre,
 * where the optical depth of an axis-aligned directional light is exact for
 * every propagation method (the top voxels lie on the medium's face, D = 0,
 * and each voxel down adds one voxel of density) and the texture is read at
 * a texel centre; the fog's optical depths are closed forms; along the ray
 * the medium and the light are constant, and each step integrates its
 * in-scattering in closed form, so the step size introduces no error. What
 * remains is float rounding: per step a few operations of about 1 ulp and
 * exp() within 3 + 2|x| ulp (|x| < 1 here), about 8 ulp, over the N steps:
 * |L_gpu - L| <= 8 (N + 4) 2^-23 L, plus, for exponential fog, the 1e-6
 * relative truncation of the series in veil_exp_fog_integral on the light's
 * path (see core/shared.glsl.h), which moves L by at most sigma_t D_y 1e-6. */
#include <math.h>
#include <stdlib.h>

#include "support/check.h"
#include "scene/camera.h"
#include "frame/renderer.h"

static double hg(double c, double g) { return (1 - g * g) / (4 * VEIL_PI * pow(1 + g * g - 2 * g * c, 1.5)); }

enum { W = 33, H = 33 };

/* Checks the middle row (sy = 0 exactly: horizontal rays) of img. */
static void check_row(const char* what, const veil_scene* s, const float* img, double rho_y, double D_y,
                      double min_step)
{
    veil_error err = {0};
    veil_camera_basis cam;
    veil_camera_make_basis(&s->camera, W, H, &cam, &err);
    const int py = H / 2;
    const veil_light* sun = &s->lights[0];
    double worst = 0.0;
    int bad = 0, checked = 0;
    for (int px = 0; px < W && img; ++px) {
        float dir[3];
        veil_camera_ray(&cam, W, H, px, py, dir);
        double t0 = 0, t1 = INFINITY; /* chord through [0,1]^3, slab test in double */
        for (int a = 0; a < 3; ++a) {
            if (dir[a] == 0) continue;
            double ta = (0 - cam.pos[a]) / dir[a], tb = (1 - cam.pos[a]) / dir[a];
            t0 = fmax(t0, fmin(ta, tb));
            t1 = fmin(t1, fmax(ta, tb));
        }
        double C = t1 > t0 ? t1 - t0 : 0.0, steps = C / min_step + 1;
        double A = 1.0;
        for (int c = 0; c < 3; ++c) {
            double st_c = (double)s->medium.sigma_a[c] + s->medium.sigma_s[c];
            double L = s->medium.sigma_s[c] * rho_y * hg(0.0, s->medium.phase.g) * sun->color[c] *
                           exp(-st_c * D_y) * (1 - exp(-st_c * rho_y * C)) / (st_c * rho_y) +
                       s->background[c] * exp(-st_c * rho_y * C);
            A -= exp(-st_c * rho_y * C) / 3.0;
            double got = img[(py * W + px) * 4 + c];
            double tol = (8.0 * (steps + 4) * 0x1p-23 + st_c * D_y * 1e-6) * L;
            double e = fabs(got - L);
            worst = fmax(worst, e / L);
            if (!(e <= tol)) {
                if (bad < 5) fprintf(stderr, "%s: pixel %d ch %d: got %.9g expected %.9g (tol %.3g)\n", what, px, c, got, L, tol);
                ++bad;
            }
            ++checked;
        }
        double got_a = img[(py * W + px) * 4 + 3];
        if (!(fabs(got_a - A) <= 8.0 * (steps + 4) * 0x1p-23)) {
            fprintf(stderr, "%s: pixel %d alpha: got %.9g expected %.9g\n", what, px, got_a, A);
            ++bad;
        }
    }
    printf("%s: %d values, largest relative error %.3g\n", what, checked, worst);
    CHECK(checked == 3 * W, "%s: only %d values checked", what, checked);
    CHECK(bad == 0, "%s: %d values outside the rounding bound", what, bad);
}

/* 4. The voxel cube [0,1]^3 (density 1) inside homogeneous fog (density
 * rho_f in [-3,4] x [-1,2] x [-1.5,3]); rays at height -0.5 pass under the
 * cube. Where a ray is below the cube's footprint the sun's path crosses the
 * cube too: D = rho_f 2.5 + 1, else rho_f 2.5. Per segment the closed form
 * of the horizontal-ray case applies, entered with the transmittance
 * accumulated so far. The marcher samples the light once per step, so the
 * two steps that straddle the shadow's edges may be lit wrongly: at most
 * their whole in-scattering, sigma_s rho_f p E step T each, with steps of at
 * most max(voxel/2, VEIL_FOG_STEP_FRACTION t_max) outside the cube. */
static void test_shadow_on_fog(veil_renderer* r, veil_scene* s, const veil_grid* g, const float* rho)
{
    const double rho_f = 0.4, y = -0.5, fog_top = 2.0;
    veil_source fog = {.type = VEIL_SOURCE_EXPONENTIAL,
                       .fog = {.density = (float)rho_f, .falloff = 0.0f, .direction = {0, 1, 0},
                               .origin = {0, 0, 0}, .bounds = {{-3, -1, -1.5f}, {4, 2, 3}}}};
    s->medium.sources = &fog;
    s->medium.source_count = 1;
    s->camera.position[1] = (float)y;
    s->camera.look_at[1] = (float)y;
    float* img = NULL;
    veil_render_stats st;
    veil_error err = {0};
    CHECK(veil_render_density(r, s, g, rho, &(veil_render_opts){.seed = 3}, &img, &st, &err) == VEIL_OK, "%s",
          err.msg);
    veil_camera_basis cam;
    veil_camera_make_basis(&s->camera, W, H, &cam, &err);
    const int py = H / 2;
    const veil_light* sun = &s->lights[0];
    const double p0 = hg(0.0, s->medium.phase.g);
    int bad = 0;
    double worst = 0.0;
    for (int px = 0; px < W && img; ++px) {
        float dirf[3];
        veil_camera_ray(&cam, W, H, px, py, dirf);
        double o[3] = {cam.pos[0], cam.pos[1], cam.pos[2]}, d[3] = {dirf[0], dirf[1], dirf[2]};
        /* the ray in the fog box, and below the cube's footprint (x, z in [0, 1]) */
        double f0 = 0, f1 = INFINITY, s0 = 0, s1 = INFINITY;
        for (int a = 0; a < 3; ++a) {
            double ta = (fog.fog.bounds[0][a] - o[a]) / d[a], tb = (fog.fog.bounds[1][a] - o[a]) / d[a];
            if (d[a] != 0) f0 = fmax(f0, fmin(ta, tb)), f1 = fmin(f1, fmax(ta, tb));
            if (a == 1) continue;
            if (d[a] == 0) {
                if (o[a] < 0 || o[a] > 1) s0 = INFINITY;
                continue;
            }
            double ua = (0 - o[a]) / d[a], ub = (1 - o[a]) / d[a];
            s0 = fmax(s0, fmin(ua, ub)), s1 = fmin(s1, fmax(ua, ub));
        }
        s0 = fmax(s0, f0), s1 = fmin(s1, f1);
        double cuts[4] = {f0, s1 > s0 ? s0 : f1, s1 > s0 ? s1 : f1, f1};
        double max_step = fmax(VEIL_DEFAULT_STEP_VOXELS * g->voxel, VEIL_FOG_STEP_FRACTION * f1);
        for (int c = 0; c < 3; ++c) {
            double st_c = (double)s->medium.sigma_a[c] + s->medium.sigma_s[c], k = st_c * rho_f;
            double L = 0.0, T = 1.0;
            for (int seg = 0; seg < 3; ++seg) {
                double len = cuts[seg + 1] - cuts[seg];
                if (len <= 0) continue;
                double D = rho_f * (fog_top - y) + (seg == 1 ? 1.0 : 0.0);
                L += T * s->medium.sigma_s[c] * rho_f * p0 * sun->color[c] * exp(-st_c * D) * (1 - exp(-k * len)) / k;
                T *= exp(-k * len);
            }
            L += s->background[c] * T;
            double edge = s1 > s0 ? 2.0 * s->medium.sigma_s[c] * rho_f * p0 * sun->color[c] * max_step : 0.0;
            double tol = edge + 8.0 * ((f1 - f0) / (VEIL_DEFAULT_STEP_VOXELS * g->voxel) + 4) * 0x1p-23 * L;
            double got = img[(py * W + px) * 4 + c], e = fabs(got - L);
            worst = fmax(worst, e / L);
            if (!(e <= tol)) {
                if (bad < 5) fprintf(stderr, "shadow on fog: pixel %d ch %d: got %.7g expected %.7g (tol %.3g)\n", px, c, got, L, tol);
                ++bad;
            }
        }
    }
    printf("shadow on fog: largest relative error %.3g (edge steps allowed)\n", worst);
    CHECK(bad == 0, "shadow on fog: %d values off", bad);
    free(img);
}

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_renderer* r = NULL;
    veil_error err = {0};
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);

    /* 17 voxel centres per axis at 0, 1/16, ..., 1: the medium is [0,1]^3 */
    enum { N = 17 };
    const int row_voxel = 9; /* the camera's height is this voxel row's centre */
    veil_grid g = {.dims = {N, N, N}, .origin = {-0.5f / 16, -0.5f / 16, -0.5f / 16}, .voxel = 1.0f / 16};
    float* rho = malloc(N * N * N * sizeof(float));
    for (int v = 0; v < N * N * N; ++v) rho[v] = 1.0f;
    const float y = row_voxel / 16.0f;

    veil_light sun = {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0, -1, 0}, .color = {1.0f, 2.0f, 3.0f}};
    veil_scene s = {0};
    s.camera = (veil_camera){.position = {0.5f, y, -2.0f}, .look_at = {0.5f, y, 0.0f}, .up = {0, 1, 0},
                             .fov_y_deg = 20.0f, .width = W, .height = H};
    s.medium.sigma_a[0] = 0.1f, s.medium.sigma_a[1] = 0.2f, s.medium.sigma_a[2] = 0.3f;
    s.medium.sigma_s[0] = 0.5f, s.medium.sigma_s[1] = 1.0f, s.medium.sigma_s[2] = 2.0f;
    s.medium.phase = (veil_phase){.type = VEIL_PHASE_HG, .g = 0.3f};
    s.medium.max_resolution = 16;
    s.lights = &sun;
    s.light_count = 1;
    s.background[0] = 0.2f, s.background[1] = 0.3f, s.background[2] = 0.4f;

    /* 1. the voxel grid */
    float* img = NULL;
    veil_render_stats st;
    CHECK(veil_render_density(r, &s, &g, rho, &(veil_render_opts){.seed = 1}, &img, &st, &err) == VEIL_OK, "%s",
          err.msg);
    check_row("voxel box", &s, img, 1.0, 1.0 - y, VEIL_DEFAULT_STEP_VOXELS * g.voxel);
    free(img);
    img = NULL;

    /* 2. and 3. analytic fog in the same box, no grid: renders through the
     * scene path with an empty medium otherwise */
    const float falloffs[2] = {0.0f, 1.7f};
    const double rho0 = 1.3;
    for (int k = 0; k < 2; ++k) {
        veil_source fog = {.type = VEIL_SOURCE_EXPONENTIAL,
                           .fog = {.density = (float)rho0, .falloff = falloffs[k], .direction = {0, 1, 0},
                                   .origin = {0, 0, 0}, .bounds = {{0, 0, 0}, {1, 1, 1}}}};
        s.medium.sources = &fog;
        s.medium.source_count = 1;
        CHECK(veil_render_scene(r, &s, &(veil_render_opts){.seed = 2}, &img, &st, &err) == VEIL_OK, "%s", err.msg);
        CHECK(!st.has_volume && st.fogs == 1, "fog only: a volume was made (%d) or the fog lost (%d)",
              st.has_volume, st.fogs);
        double b = falloffs[k], rho_y = rho0 * exp(-b * y);
        double D_y = b == 0.0 ? rho0 * (1.0 - y) : rho0 * (exp(-b * y) - exp(-b)) / b;
        check_row(k == 0 ? "homogeneous fog" : "exponential fog", &s, img, rho_y, D_y, VEIL_FOG_MIN_STEP);
        free(img);
        img = NULL;
    }
    test_shadow_on_fog(r, &s, &g, rho);
    free(rho);
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
    return check_finish();
}
