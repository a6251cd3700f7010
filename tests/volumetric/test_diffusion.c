/* The view-independent fields of volumetric/volumetric.h.
 * 1. The escape field (the octaves' gate) of a constant-density cube
 *    against its closed form: from a cell centre x the density integral
 *    along axis direction +-e_a to the box of the voxel centres is rho
 *    times the distance to that face, along a diagonal rho times the
 *    smallest of the three axis distances times sqrt(3); P_s is the mean
 *    of 1 - exp(-sigma_t tau) over the 6 + 8 directions. The EV is
 *    constant, so the midpoint rule is exact: only float rounding, about
 *    n + 4 ulp over n steps (n <= 40): 1e-5 absolute on a value <= 1.
 * 2. The diffusion fluence of a homogeneous fog box under a sun converges:
 *    the default number of red-black sweeps and four times as many agree
 *    to 1 % of the largest fluence, every value is finite and >= 0, and
 *    the fluence is largest near the lit face (the source decays with
 *    depth as exp(-sigma_t z)). No light: the renderer skips the stage. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "support/check.h"
#include "frame/renderer.h"
#include "gpu/gl_util.h"
#include "volumetric/volumetric.h"

static void escape_cube(veil_volumetric* d)
{
    veil_error err = {0};
    const int N = 16;
    const float rho = 2.0f;
    veil_grid g = {{N, N, N}, {-0.8f, -0.8f, -0.8f}, 0.1f};
    float* dens = malloc((size_t)N * N * N * sizeof *dens);
    for (int i = 0; i < N * N * N; ++i) dens[i] = rho;
    GLuint ev = 0;
    CHECK(veil_gl_texture3d(GL_R32F, g.dims, "test ev", &ev, &err) == VEIL_OK, "%s", err.msg);
    glTextureSubImage3D(ev, 0, 0, 0, 0, N, N, N, GL_RED, GL_FLOAT, dens);
    free(dens);
    veil_scene s = {0};
    s.camera = (veil_camera){.position = {0, 0, 5}, .look_at = {0, 0, 0}, .up = {0, 1, 0}, .fov_y_deg = 40,
                             .width = 8, .height = 8};
    s.medium.sigma_s[0] = s.medium.sigma_s[1] = s.medium.sigma_s[2] = 0.5f;
    s.medium.sigma_a[0] = s.medium.sigma_a[1] = s.medium.sigma_a[2] = 0.25f;
    veil_multiple_defaults(&s.multiple);
    GLuint opv[VEIL_MAX_OPV_TEXTURES] = {0};
    veil_volumetric_desc vd = {.kind = VEIL_FIELD_ESCAPE,
                               .medium = {.scene = &s, .grid = &g, .ev = ev, .opv = opv},
                               .diffusion_cells = s.multiple.diffusion_cells};
    veil_volumetric_field f;
    veil_volumetric_report rep;
    CHECK(veil_volumetric_update(d, &vd, 1, &f, &rep, &err) == VEIL_OK, "%s", err.msg);
    int dims[3];
    float* P = veil_volumetric_readback(d, dims);
    CHECK(P != NULL && f.texture != 0, "an escape field was made");
    float lo[3], hi[3];
    veil_grid_medium_box(&g, lo, hi);
    double st = 0.75, worst = 0.0;
    for (int k = 0; P && k < dims[2]; ++k)
        for (int j = 0; j < dims[1]; ++j)
            for (int i = 0; i < dims[0]; ++i) {
                const int c[3] = {i, j, k};
                double sum = 0.0;
                for (int a = 0; a < 3; ++a) {
                    double x = lo[a] + c[a] * rep.cell, dlo = fmax(x - lo[a], 0.0), dhi = fmax(hi[a] - x, 0.0);
                    sum += 2.0 - exp(-st * rho * dlo) - exp(-st * rho * dhi);
                }
                /* diagonals: each of the 8 sign patterns exits at the nearest face along it */
                for (int sgn = 0; sgn < 8; ++sgn) {
                    double t = INFINITY;
                    for (int a = 0; a < 3; ++a) {
                        double x = lo[a] + c[a] * rep.cell;
                        double dist = (sgn >> a & 1) ? fmax(x - lo[a], 0.0) : fmax(hi[a] - x, 0.0);
                        t = fmin(t, dist * sqrt(3.0));
                    }
                    sum += 1.0 - exp(-st * rho * t);
                }
                double want = sum / 14.0;
                /* cells outside the box (the grid's last one may be) see no medium along some axes */
                int inside = 1;
                for (int a = 0; a < 3; ++a) inside &= lo[a] + c[a] * rep.cell <= hi[a] + 1e-6;
                if (!inside) continue;
                double got = P[4 * (((size_t)k * dims[1] + j) * dims[0] + i)];
                worst = fmax(worst, fabs(got - want));
            }
    CHECK(worst <= 1e-5, "escape field vs closed form: worst difference %.3g > 1e-5", worst);
    printf("escape field %dx%dx%d (cell %.3g m): worst difference from the closed form %.3g\n", dims[0], dims[1],
           dims[2], rep.cell, worst);
    free(P);
    glDeleteTextures(1, &ev);
}

static void fluence_converges(veil_volumetric* d)
{
    veil_error err = {0};
    veil_source fog = {.type = VEIL_SOURCE_EXPONENTIAL,
                       .fog = {.density = 1.0f, .falloff = 0.0f, .direction = {0, 1, 0},
                               .bounds = {{-2, -2, -2}, {2, 2, 2}}}};
    veil_light sun = {.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0, -1, 0}, .color = {1, 2, 3}};
    veil_scene s = {0};
    s.camera = (veil_camera){.position = {0, 0, 9}, .look_at = {0, 0, 0}, .up = {0, 1, 0}, .fov_y_deg = 40,
                             .width = 8, .height = 8};
    for (int c = 0; c < 3; ++c) s.medium.sigma_s[c] = 1.0f, s.medium.sigma_a[c] = 0.1f;
    s.medium.sources = &fog;
    s.medium.source_count = 1;
    s.lights = &sun;
    s.light_count = 1;
    veil_multiple_defaults(&s.multiple);
    s.multiple.volumetric_method = VEIL_VOLUMETRIC_DIFFUSION;
    s.multiple.diffusion_cells = 24;
    GLuint opv[VEIL_MAX_OPV_TEXTURES] = {0};
    veil_volumetric_desc vd = {.kind = VEIL_FIELD_FLUENCE,
                               .medium = {.scene = &s, .lights = &sun, .light_count = 1, .opv = opv},
                               .diffusion_cells = s.multiple.diffusion_cells};
    float* phi[2] = {NULL, NULL};
    int dims[3] = {0, 0, 0};
    for (int run = 0; run < 2; ++run) {
        vd.diffusion_iterations = run == 0 ? 0 : 4 * 3 * 24;
        veil_volumetric_field f;
        veil_volumetric_report rep;
        CHECK(veil_volumetric_update(d, &vd, 100 + (uint64_t)run, &f, &rep, &err) == VEIL_OK, "%s", err.msg);
        phi[run] = veil_volumetric_readback(d, dims);
        CHECK(phi[run] != NULL, "a fluence field was made (run %d)", run);
        printf("fluence run %d: %dx%dx%d cells, %d sweeps\n", run, dims[0], dims[1], dims[2], rep.iterations);
    }
    if (phi[0] && phi[1]) {
        size_t n = (size_t)dims[0] * dims[1] * dims[2];
        double mx = 0.0, diff = 0.0;
        int finite = 1;
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 3; ++c) {
                double a = phi[0][4 * i + c], b = phi[1][4 * i + c];
                finite &= isfinite(a) && a >= 0.0;
                mx = fmax(mx, b);
                diff = fmax(diff, fabs(a - b));
            }
        CHECK(finite, "fluence finite and >= 0");
        CHECK(mx > 0.0 && diff <= 0.01 * mx, "default sweeps vs 4x: differ by %.3g of the largest %.3g", diff, mx);
        /* the column through the centre: top (lit, j = dims-2) above the bottom (j = 1) */
        size_t top = 4 * (((size_t)(dims[2] / 2) * dims[1] + (dims[1] - 2)) * dims[0] + dims[0] / 2);
        size_t bot = 4 * (((size_t)(dims[2] / 2) * dims[1] + 1) * dims[0] + dims[0] / 2);
        CHECK(phi[1][top] > phi[1][bot], "fluence near the lit face %.4g above the far face %.4g", phi[1][top],
              phi[1][bot]);
        printf("fluence: max %.4g, default vs 4x sweeps %.3g; lit side %.4g, far side %.4g\n", mx, diff, phi[1][top],
               phi[1][bot]);
    }
    free(phi[0]);
    free(phi[1]);
}

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_volumetric* d = NULL;
    CHECK(veil_volumetric_create(&d, &err) == VEIL_OK, "%s", err.msg);
    if (d) {
        escape_cube(d);
        fluence_converges(d);
    }
    veil_volumetric_destroy(d);
    veil_gl_destroy(gl);
    return check_finish();
}
