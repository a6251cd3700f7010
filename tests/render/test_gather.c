/* The light cache's later light gathered towards the camera
 * (render/shaders/cache_gather.comp), against closed forms on a cache made
 * by hand.
 *
 * The medium: a fog box of density 1 (zero falloff), chromatic sigma_s,
 * sigma_a 0.1, HG g. The cache: the same in every cell, the once-scattered
 * fluence phi1 and the later phi2 with their fluxes F1, F2, each cell
 * wholly free and holding density. The light the cache scatters at y
 * towards w is then the same everywhere,
 *   J(w) = phi1 HG(F1^ . w; g mu1) + phi2 [HG(F2^ . w; g mu2) - f HG(F2^ . w; mu2)]
 * (cache_read.glsl; mu = |F| / lum(phi), 0 without flux: isotropic lobes),
 * f = g^2 the later light's forward peak, carried along the gather's rays
 * by the reduced extinction s_r = sigma_t - f sigma_s. The light arriving at x
 * travelling along w, from the box behind x, is then in closed form
 *   L2(x, w) = sigma_s J(w) (1 - exp(-s_r d(x, -w))) / s_r
 * (d the distance from x to the box's side along -w; the box is the grid),
 * and the gather's value at x is its phase-weighted mean towards the camera,
 *   S(x) = integral over w of HG(w . (-v); g) L2(x, w) dw,
 * v the direction from the camera to x: here a quadrature in double (the
 * HG's inverse CDF at 512 midpoints in cos, 256 in azimuth).
 *
 * 1. Every cell's S against that (g 0.6 at 64 and 9 rays a cell — an odd
 *    side gives the two techniques unequal shares of the strata, which the
 *    weights must follow — and g 0 with steps of two cells).
 *    The gather's estimate of a cell is unbiased (its steps integrate a
 *    constant source through constant density exactly; its directions are a
 *    randomly shifted stratified set from the two techniques, each
 *    direction's weight the phase function over their mean pdf). Two seeds
 *    give two independent estimates a, b of each cell: over a layer of N
 *    cells (one z), the mean of (a + b) / 2 - S has the standard error
 *    sqrt(sum (a - b)^2) / (2 N), and must be within 5.5 of them (N = 64,
 *    t with 64 degrees of freedom: under 1e-6 to fail by chance) plus the
 *    floats' rounding, 1e-5 S (a few dozen steps of 2^-24). Taking the
 *    rays towards the camera instead of away from it (a sign) fails the
 *    layers nearest and furthest from the camera by far.
 * 2. The same seed gives the same values, bit for bit.
 * 3. The march reads them where they are: a grid of 72 x 8 x 8 cells is
 *    gathered on 48 cells along x (gather_cells), 1.5 of the cache's a
 *    side each: 48 x 6 x 6 of them (the last, along y and z, partly
 *    outside the grid), and a pixel's
 *    march against the integral of T sigma_s rho S along its ray, S read
 *    trilinearly from those gathered cells as the GPU left them (so no
 *    sampling error): the march takes midpoint steps of at most Delta; a
 *    midpoint step of a function with Lipschitz constant K is off by at
 *    most K Delta^2 / 4, summed over the steps: K Delta chord / 4, with K
 *    measured on the CPU integrand (finite differences on a grid 16 x finer
 *    than a cell), plus rounding 1e-5. With phi1 = 0 the pixel is the
 *    gathered light alone; reading the cells at the cache's scale instead
 *    of the gather's puts it far off. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "gpu/gl_util.h"
#include "render/march.h"
#include "volumetric/volumetric.h"

#define PI 3.14159265358979323846

typedef struct box_case {
    double g, step;
    int dims[3];
    float lo[3], h;
    float phi1[3], phi2[3];
    float F1[3], F2[3]; /* the luminance-weighted flux of each (0: isotropic lobes) */
    float cam[3];
} box_case;

static const float SIGMA_S[3] = {0.8f, 1.0f, 1.2f}, SIGMA_A = 0.1f;

static double hg_cos(double g, double xi)
{
    if (fabs(g) < 1e-3) return 1.0 - 2.0 * xi;
    double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * xi);
    double c = (1.0 + g * g - s * s) / (2.0 * g);
    return c < -1.0 ? -1.0 : c > 1.0 ? 1.0 : c;
}

/* Distance from x along unit d to the side of the box [lo, hi]. */
static double box_exit(const double x[3], const double d[3], const double lo[3], const double hi[3])
{
    double t = INFINITY;
    for (int a = 0; a < 3; ++a) {
        if (d[a] > 0.0) t = fmin(t, (hi[a] - x[a]) / d[a]);
        if (d[a] < 0.0) t = fmin(t, (lo[a] - x[a]) / d[a]);
    }
    return t;
}

static double lum(const float v[3]) { return 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]; }

/* The HG of cache_read.glsl's cache_lobe: about the flux F of fluence phi, at w (the direction scattered to). */
static double lobe(const float phi[3], const float F[3], const double w[3], double g)
{
    double fl = sqrt((double)F[0] * F[0] + (double)F[1] * F[1] + (double)F[2] * F[2]), pl = lum(phi);
    double gc = pl > 0.0 && fl > 0.0 ? fmin(fl / pl, 1.0) : 0.0;
    double c = fl > 0.0 ? (F[0] * w[0] + F[1] * w[1] + F[2] * w[2]) / fl : 1.0;
    double gg = g * gc, d = 1.0 + gg * gg - 2.0 * gg * c;
    return (1.0 - gg * gg) / (4.0 * PI * d * sqrt(d));
}

/* S(x) per channel (header). */
static void expected(const box_case* bc, const double x[3], double out[3])
{
    double lo[3], hi[3], v[3], n = 0.0;
    for (int a = 0; a < 3; ++a) {
        lo[a] = bc->lo[a], hi[a] = bc->lo[a] + bc->dims[a] * (double)bc->h;
        v[a] = x[a] - bc->cam[a], n += v[a] * v[a];
    }
    for (int a = 0; a < 3; ++a) v[a] /= sqrt(n);
    /* a frame about -v */
    double ax[3] = {-v[0], -v[1], -v[2]}, t[3] = {1, 0, 0};
    if (fabs(ax[0]) > 0.9) t[0] = 0, t[1] = 1;
    double e1[3] = {ax[1] * t[2] - ax[2] * t[1], ax[2] * t[0] - ax[0] * t[2], ax[0] * t[1] - ax[1] * t[0]};
    double l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (int a = 0; a < 3; ++a) e1[a] /= l1;
    double e2[3] = {ax[1] * e1[2] - ax[2] * e1[1], ax[2] * e1[0] - ax[0] * e1[2], ax[0] * e1[1] - ax[1] * e1[0]};
    const double f = bc->g > 0.0 ? bc->g * bc->g : 0.0;
    const int M = 512, P = 256;
    double sum[3] = {0, 0, 0};
    for (int i = 0; i < M; ++i) {
        double ct = hg_cos(bc->g, (i + 0.5) / M), st = sqrt(fmax(1.0 - ct * ct, 0.0));
        for (int j = 0; j < P; ++j) {
            double ph = 2.0 * PI * (j + 0.5) / P, w[3], d[3];
            for (int a = 0; a < 3; ++a) w[a] = ax[a] * ct + (e1[a] * cos(ph) + e2[a] * sin(ph)) * st, d[a] = -w[a];
            double s = box_exit(x, d, lo, hi);
            const double lb1 = lobe(bc->phi1, bc->F1, w, bc->g), lb2 = lobe(bc->phi2, bc->F2, w, bc->g);
            const double l2_peak = lobe(bc->phi2, bc->F2, w, 1.0);
            for (int c = 0; c < 3; ++c) {
                double st_ = SIGMA_S[c] + SIGMA_A, sr = st_ - f * SIGMA_S[c];
                double J = bc->phi1[c] * lb1 + bc->phi2[c] * (lb2 - f * l2_peak);
                sum[c] += SIGMA_S[c] * J * (1.0 - exp(-sr * s)) / sr;
            }
        }
    }
    for (int c = 0; c < 3; ++c) out[c] = sum[c] / ((double)M * P);
}

static veil_source g_fog;
static veil_scene g_scene;

static void setup_scene(const box_case* bc)
{
    memset(&g_scene, 0, sizeof g_scene);
    g_fog = (veil_source){.type = VEIL_SOURCE_EXPONENTIAL,
                          .fog = {.density = 1.0f, .falloff = 0.0f, .direction = {0, 1, 0}}};
    for (int a = 0; a < 3; ++a) {
        g_fog.fog.bounds[0][a] = bc->lo[a];
        g_fog.fog.bounds[1][a] = bc->lo[a] + (float)bc->dims[a] * bc->h;
    }
    for (int c = 0; c < 3; ++c) g_scene.medium.sigma_s[c] = SIGMA_S[c], g_scene.medium.sigma_a[c] = SIGMA_A;
    g_scene.medium.phase = bc->g > 0.0 ? (veil_phase){.type = VEIL_PHASE_HG, .g = (float)bc->g}
                                       : (veil_phase){.type = VEIL_PHASE_ISOTROPIC};
    g_scene.medium.sources = &g_fog;
    g_scene.medium.source_count = 1;
    veil_multiple_defaults(&g_scene.multiple);
}

/* The hand-made cache: VEIL_CACHE_SLABS grids (core/shared.glsl.h), slab 4 zero. */
static GLuint make_cache(const box_case* bc, veil_volumetric_field* f)
{
    const int nx = bc->dims[0], ny = bc->dims[1], nz = bc->dims[2];
    const size_t cells = (size_t)nx * ny * nz;
    float* t = calloc(cells * 4 * VEIL_CACHE_SLABS, sizeof *t);
    for (size_t k = 0; t && k < cells; ++k) {
        float* s0 = &t[4 * k];
        for (int c = 0; c < 3; ++c) {
            s0[c] = bc->phi1[c] + bc->phi2[c];                      /* all the light */
            t[4 * (cells + k) + c] = bc->F1[c] + bc->F2[c];         /* its flux */
            t[4 * (2 * cells + k) + c] = bc->phi2[c];               /* the later light */
            t[4 * (3 * cells + k) + c] = bc->F2[c];                 /* its flux */
        }
        t[4 * (cells + k) + 3] = 1.0f;     /* wholly free */
        t[4 * (2 * cells + k) + 3] = 1.0f; /* holds density (the majorant) */
    }
    GLuint tex = 0;
    veil_error err = {0};
    const int stacked[3] = {nx, ny, VEIL_CACHE_SLABS * nz};
    CHECK(t && veil_gl_texture3d(GL_RGBA32F, stacked, "test cache", &tex, &err) == VEIL_OK, "%s", err.msg);
    if (tex) glTextureSubImage3D(tex, 0, 0, 0, 0, nx, ny, VEIL_CACHE_SLABS * nz, GL_RGBA, GL_FLOAT, t);
    free(t);
    memset(f, 0, sizeof *f);
    f->texture = tex, f->depth = nz, f->kind = VEIL_FIELD_CACHE;
    for (int a = 0; a < 3; ++a) f->tex_min[a] = bc->lo[a], f->tex_inv[a] = 1.0f / ((float)bc->dims[a] * bc->h);
    return tex;
}

/* One march (and its gather) of a w x h image; the image's rgba (caller frees) and slab 4 into out. */
static int g_gather_cells; /* the march's gather_cells (0: its default) */

static float* march(veil_march* m, const box_case* bc, const veil_volumetric_field* f, int rays, uint32_t seed,
                    int w, int h, const float look_at[3], float fov, float* out)
{
    GLuint opv[VEIL_MAX_OPV_TEXTURES] = {0};
    veil_camera cam = {.position = {bc->cam[0], bc->cam[1], bc->cam[2]},
                       .look_at = {look_at[0], look_at[1], look_at[2]}, .up = {0, 1, 0}, .fov_y_deg = fov,
                       .width = w, .height = h};
    veil_march_desc d = {.medium = {.scene = &g_scene, .opv = opv}, .camera = &cam, .width = w, .height = h,
                         .step_voxels = 0.5f, .seed = seed, .no_background = 1, .field = f,
                         .gather_rays = rays, .gather_step = (float)bc->step, .gather_cells = g_gather_cells};
    veil_image_set im = {0};
    veil_error err = {0};
    CHECK(veil_march_run(m, &d, &im, &err) == VEIL_OK, "march: %s", err.msg);
    const size_t cells = (size_t)bc->dims[0] * bc->dims[1] * bc->dims[2];
    float* all = malloc(cells * 4 * VEIL_CACHE_SLABS * sizeof *all);
    if (all) {
        glGetTextureImage(f->texture, 0, GL_RGBA, GL_FLOAT, (GLsizei)(cells * 4 * VEIL_CACHE_SLABS * sizeof *all), all);
        memcpy(out, all + 4 * 4 * cells, 4 * cells * sizeof *out);
    }
    free(all);
    float* rgba = im.rgba;
    im.rgba = NULL;
    veil_image_set_free(&im);
    return rgba;
}

static void cells_against_closed_form(veil_march* m, const box_case* bc, int rays, const char* name)
{
    setup_scene(bc);
    veil_volumetric_field f;
    GLuint tex = make_cache(bc, &f);
    const int nx = bc->dims[0], ny = bc->dims[1], nz = bc->dims[2];
    const size_t cells = (size_t)nx * ny * nz;
    float *a = calloc(4 * cells, sizeof *a), *b = calloc(4 * cells, sizeof *b), *a2 = calloc(4 * cells, sizeof *a2);
    const float origin[3] = {0, 0, 0};
    free(march(m, bc, &f, rays, 1, 1, 1, origin, 120.0f, a));
    free(march(m, bc, &f, rays, 2, 1, 1, origin, 120.0f, b));
    free(march(m, bc, &f, rays, 1, 1, 1, origin, 120.0f, a2));
    CHECK(a && b && a2 && memcmp(a, a2, 4 * cells * sizeof *a) == 0, "%s: the same seed gives the same cells", name);
    int finite = 1, layers_ok = 0;
    double worst = 0.0;
    for (int z = 0; z < nz && a && b; ++z) {
        double err[3] = {0, 0, 0}, dd[3] = {0, 0, 0}, want_mean[3] = {0, 0, 0};
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) {
                size_t k = (size_t)x + (size_t)nx * ((size_t)y + (size_t)ny * z);
                double p[3] = {bc->lo[0] + (x + 0.5) * bc->h, bc->lo[1] + (y + 0.5) * bc->h, bc->lo[2] + (z + 0.5) * bc->h};
                double want[3];
                expected(bc, p, want);
                for (int c = 0; c < 3; ++c) {
                    finite &= isfinite(a[4 * k + c]) && isfinite(b[4 * k + c]) && a[4 * k + c] >= 0.0f;
                    err[c] += 0.5 * (a[4 * k + c] + b[4 * k + c]) - want[c];
                    dd[c] += (double)(a[4 * k + c] - b[4 * k + c]) * (a[4 * k + c] - b[4 * k + c]);
                    want_mean[c] += want[c];
                }
            }
        const double N = (double)nx * ny;
        int ok = 1;
        for (int c = 0; c < 3; ++c) {
            double se = sqrt(dd[c]) / (2.0 * N), e = err[c] / N, tol = 5.5 * se + 1e-5 * want_mean[c] / N;
            ok &= fabs(e) <= tol;
            worst = fmax(worst, fabs(e) / tol);
            if (fabs(e) > tol)
                fprintf(stderr, "%s: layer z %d ch %d: gathered mean off by %.4g (S %.5g), bound %.3g (se %.3g)\n",
                        name, z, c, e, want_mean[c] / N, tol, se);
        }
        layers_ok += ok;
    }
    CHECK(finite, "%s: every gathered cell finite and >= 0", name);
    CHECK(layers_ok == nz, "%s: %d of %d layers within 5.5 standard errors of the closed form", name, layers_ok, nz);
    printf("%s: %d layers of %dx%d cells against the closed form, worst at %.2f of its bound\n", name, nz, nx, ny,
           worst);
    free(a), free(b), free(a2);
    glDeleteTextures(1, &tex);
}

/* Trilinear read of the gathered cells (gdims) at x, as cache_read.glsl reads them. */
static void gathered_at(const box_case* bc, const float* s4, const int gd[3], double sc, const double x[3], double out[3])
{
    double t[3];
    int i0[3], i1[3];
    double fr[3];
    for (int a = 0; a < 3; ++a) {
        t[a] = (x[a] - bc->lo[a]) / (bc->h * sc);
        t[a] = fmin(fmax(t[a], 0.5), gd[a] - 0.5) - 0.5;
        i0[a] = (int)floor(t[a]), fr[a] = t[a] - i0[a];
        i1[a] = i0[a] + 1 < gd[a] ? i0[a] + 1 : i0[a];
    }
    const int nx = bc->dims[0], ny = bc->dims[1];
    for (int c = 0; c < 3; ++c) {
        double v = 0.0;
        for (int q = 0; q < 8; ++q) {
            int ix = q & 1 ? i1[0] : i0[0], iy = q & 2 ? i1[1] : i0[1], iz = q & 4 ? i1[2] : i0[2];
            double wgt = (q & 1 ? fr[0] : 1 - fr[0]) * (q & 2 ? fr[1] : 1 - fr[1]) * (q & 4 ? fr[2] : 1 - fr[2]);
            v += wgt * s4[4 * ((size_t)ix + (size_t)nx * ((size_t)iy + (size_t)ny * iz)) + c];
        }
        out[c] = v;
    }
}

static void march_reads_gathered(veil_march* m)
{
    box_case bc = {.g = 0.6, .step = 2.0, .dims = {72, 8, 8}, .lo = {-4.5f, -0.25f, -0.25f}, .h = 0.125f,
                   .phi1 = {0, 0, 0}, .phi2 = {1.0f, 2.0f, 1.5f}, .cam = {0.7f, 0.3f, 3.0f}};
    setup_scene(&bc);
    veil_volumetric_field f;
    GLuint tex = make_cache(&bc, &f);
    const size_t cells = (size_t)72 * 8 * 8;
    float* s4 = calloc(4 * cells, sizeof *s4);
    const float look[3] = {-2.0f, 0.0f, 0.0f};
    g_gather_cells = 48;
    float* px = march(m, &bc, &f, 16, 1, 1, 1, look, 20.0f, s4);
    g_gather_cells = 0;
    const veil_march_gather lg = veil_march_last_gather(m);
    const double sc = lg.scale;
    const int gd[3] = {48, 6, 6}; /* ceil(8 / 1.5) = 6 */
    CHECK(lg.scale == 1.5f && lg.dims[0] == gd[0] && lg.dims[1] == gd[1] && lg.dims[2] == gd[2],
          "a 72-cell grid gathered on 48 cells a side: cells of %g, %dx%dx%d of them", (double)lg.scale, lg.dims[0],
          lg.dims[1], lg.dims[2]);
    if (px && s4) {
        /* the pixel's ray: the 1x1 camera looks along its forward axis */
        double o[3] = {bc.cam[0], bc.cam[1], bc.cam[2]}, d[3], n = 0.0;
        for (int a = 0; a < 3; ++a) d[a] = look[a] - o[a], n += d[a] * d[a];
        for (int a = 0; a < 3; ++a) d[a] /= sqrt(n);
        double lo[3], hi[3];
        for (int a = 0; a < 3; ++a) lo[a] = bc.lo[a], hi[a] = bc.lo[a] + bc.dims[a] * (double)bc.h;
        double t0 = 0.0, t1 = INFINITY;
        for (int a = 0; a < 3; ++a) {
            double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
            t0 = fmax(t0, fmin(ta, tb)), t1 = fmin(t1, fmax(ta, tb));
        }
        CHECK(t0 < t1, "the pixel's ray crosses the box");
        const double dt = bc.h / 16.0;
        const int steps = (int)ceil((t1 - t0) / dt);
        double want[3] = {0, 0, 0}, K[3] = {0, 0, 0}, prev[3] = {0, 0, 0};
        for (int i = 0; i < steps; ++i) {
            double tm = t0 + (i + 0.5) * (t1 - t0) / steps, x[3], s[3];
            for (int a = 0; a < 3; ++a) x[a] = o[a] + d[a] * tm;
            gathered_at(&bc, s4, gd, sc, x, s);
            for (int c = 0; c < 3; ++c) {
                double st = SIGMA_S[c] + SIGMA_A, T = exp(-st * (tm - t0));
                double fv = T * SIGMA_S[c] * s[c];
                want[c] += fv * (t1 - t0) / steps;
                if (i > 0) K[c] = fmax(K[c], fabs(fv - prev[c]) / ((t1 - t0) / steps));
                prev[c] = fv;
            }
        }
        /* the march's steps in fog without a volume: at most max(VEIL_FOG_MIN_STEP, 0.02 t) */
        const double delta = fmax(VEIL_FOG_MIN_STEP, 0.02 * t1);
        for (int c = 0; c < 3; ++c) {
            double tol = K[c] * delta * (t1 - t0) / 4.0 + 1e-5 * want[c];
            CHECK(fabs(px[c] - want[c]) <= tol, "march ch %d: %.6g against the gathered cells' integral %.6g (bound %.3g)",
                  c, px[c], want[c], tol);
            printf("march reads the gathered cells (1.5^3 cache cells each), ch %d: %.6g against %.6g, bound %.2g\n", c,
                   px[c], want[c], tol);
        }
    }
    free(px);
    free(s4);
    glDeleteTextures(1, &tex);
}

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_march* m = NULL;
    CHECK(veil_march_create(&m, &err) == VEIL_OK, "%s", err.msg);
    if (m) {
        box_case hg6 = {.g = 0.6, .step = 1.0, .dims = {8, 8, 8}, .lo = {-1, -1, -1}, .h = 0.25f,
                        .phi1 = {0.5f, 1.0f, 1.5f}, .phi2 = {2.0f, 1.0f, 0.5f}, .cam = {0.3f, 0.2f, 3.0f}};
        cells_against_closed_form(m, &hg6, 64, "HG 0.6, steps of a cell, 64 rays");
        cells_against_closed_form(m, &hg6, 9, "HG 0.6, steps of a cell, 9 rays");
        /* peaked light: the lobes' mean cosines 0.8 and 0.5 (luminance), across the camera's view */
        box_case peaked = hg6;
        peaked.g = 0.85;
        const double l1 = lum(peaked.phi1), l2 = lum(peaked.phi2);
        const float F1[3] = {(float)(0.8 * l1 * 0.6), (float)(-0.8 * l1 * 0.8), 0.0f};
        const float F2[3] = {(float)(0.5 * l2 * 0.6), (float)(-0.5 * l2 * 0.8), 0.0f};
        memcpy(peaked.F1, F1, sizeof F1), memcpy(peaked.F2, F2, sizeof F2);
        cells_against_closed_form(m, &peaked, 64, "HG 0.85, peaked light across the view, 64 rays");
        cells_against_closed_form(m, &peaked, 9, "HG 0.85, peaked light across the view, 9 rays");
        box_case iso = hg6;
        iso.g = 0.0, iso.step = 2.0;
        cells_against_closed_form(m, &iso, 64, "isotropic, steps of two cells, 64 rays");
        march_reads_gathered(m);
    }
    veil_march_destroy(m);
    veil_gl_destroy(gl);
    return check_finish();
}
