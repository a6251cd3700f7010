/* Emission (a vdb source's "emission" grid) in the GPU march and in the
 * reference path tracer, against the closed form of an emissive absorbing
 * slab: emissive_slab.vdb holds "density" and "heat" equal to 1 on the
 * same 20 x 20 x 10 index box (voxel h = 0.1 m; make_test_vdbs). With
 * eps = scale * heat * color and sigma_t = sigma_a * density (no
 * scattering) both fields have the same trilinear profile f along a ray, so
 * eps / sigma_t = eps0 / sigma0 is constant and
 *   L = int eps T dz = (eps0 / sigma0) (1 - T),  T = exp(-sigma0 int f dz),
 * with int f dz = n h for a ray across n samples (the plateau (n - 1) h and
 * two ramps of area h / 2): L = eps0 / sigma0 (1 - exp(-sigma0 n h)), the
 * homogeneous slab's eps / sigma_t (1 - e^{-sigma_t d}) with d = n h.
 * The camera looks along -z through the slab's middle, n = 10.
 * - Reference: deterministic here (no scattering), its quarter-voxel steps
 *   start on a sample plane so every kink of f is a step boundary, and T is
 *   integrated exactly: the closed form to 1e-9 relative.
 * - March: per step it adds T eps dt (1 - e^{-x}) / x and multiplies T by
 *   e^{-x}, x = sigma dt with eps and sigma at the same midpoint, so its
 *   sum telescopes to (eps0 / sigma0) (1 - T_march) exactly up to rounding
 *   (1e-5); and T_march differs from the exact T only by the midpoint rule
 *   on f's four kinks (steps <= h / 2, slope 1 / h): |error of int f| <=
 *   4 (h/2)^2 / (8 h) = h / 8, so |L - closed form| <= eps0 e^{-sigma0 (n h
 *   - h / 8)} h / 8 per channel. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "frame/renderer.h"
#include "io/scene.h"
#include "reference/pathtracer.h"
#include "volume/blackbody.h"

int main(int argc, char** argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_emission VDB_DATA\n");
        return 2;
    }
    char json[8192];
    /* the slab spans x, y in [0, 1.9], z in [0, 0.9]; the camera above it looks down -z */
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0.95, 0.95, 6], \"look_at\": [0.95, 0.95, 0], \"fov_y_deg\": 2,"
             " \"width\": 5, \"height\": 5},"
             " \"medium\": {\"sigma_a\": [0.5, 1, 2], \"sigma_s\": [0, 0, 0],"
             "  \"sources\": [{\"type\": \"vdb\", \"file\": \"%s/emissive_slab.vdb\","
             "   \"emission\": {\"grid\": \"heat\", \"scale\": 2, \"color\": [1, 0.5, 0.25]}}]}}",
             argv[1]);
    veil_scene s;
    veil_error err = {0};
    if (veil_scene_parse("emission.json", json, strlen(json), &s, &err) != VEIL_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    const double sa[3] = {0.5, 1.0, 2.0}, eps0[3] = {2.0, 1.0, 0.5}, h = 0.1, d = 10 * h;
    double want[3];
    for (int c = 0; c < 3; ++c) want[c] = eps0[c] / sa[c] * (1.0 - exp(-sa[c] * d));

    /* the reference */
    veil_pt_medium* m = NULL;
    CHECK(veil_pt_medium_from_scene(&s, &m, &err) == VEIL_OK, "%s", err.msg);
    float *rgba = NULL, *se = NULL;
    veil_pt_opts o = {.spp = 2, .max_order = 1, .seed = 1, .threads = 1};
    CHECK(m && veil_pt_render(m, &s, &o, &rgba, &se, NULL, &err) == VEIL_OK, "%s", err.msg);
    if (rgba)
        for (int c = 0; c < 3; ++c) {
            double got = rgba[4 * 12 + c]; /* the centre pixel of 5x5 */
            CHECK(fabs(got - want[c]) <= 1e-9 * want[c] + 1e-7 * want[c], "reference ch %d: %.9g, closed form %.9g", c,
                  got, want[c]);
            printf("reference ch %d: %.9g, closed form %.9g\n", c, got, want[c]);
        }
    free(rgba);
    free(se);
    veil_pt_medium_free(m);

    /* the march */
    veil_gl* gl = check_gpu_or_skip();
    veil_renderer* r = NULL;
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    s.multiple.volumetric = 0, s.multiple.screen_space = 0;
    veil_image_set im = {0};
    CHECK(r && veil_render_scene_images(r, &s, &(veil_render_opts){.seed = 3}, &im, NULL, &err) == VEIL_OK, "%s",
          err.msg);
    if (im.rgba)
        for (int c = 0; c < 3; ++c) {
            double L = im.aov_s[4 * 12 + c], T = im.aov_t[4 * 12 + c];
            double telescoped = eps0[c] / sa[c] * (1.0 - T);
            CHECK(fabs(L - telescoped) <= 1e-5 * telescoped, "march ch %d: L %.7g vs (eps/sigma)(1 - T) %.7g", c, L,
                  telescoped);
            double bound = eps0[c] * exp(-sa[c] * (d - h / 8)) * h / 8;
            CHECK(fabs(L - want[c]) <= bound + 1e-5 * want[c], "march ch %d: %.7g vs closed form %.7g (bound %.3g)", c,
                  L, want[c], bound);
            printf("march ch %d: %.7g, closed form %.7g, T %.7g (exact %.7g), bound %.3g\n", c, L, want[c], T,
                   exp(-sa[c] * d), bound);
        }
    veil_image_set_free(&im);
    veil_scene_free(&s);

    /* Temperature: "heat" read as kelvin = 1500 * value, emission k rho B(T) with
     * k = sigma_a (Kirchhoff). With eps / sigma_t = B the slab's radiance is
     * B (1 - exp(-sigma_a d)): a thick absorber glows with the blackbody's
     * own radiance. 1500 K is a table entry: B is veil_blackbody_rgb(1500). */
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0.95, 0.95, 6], \"look_at\": [0.95, 0.95, 0], \"fov_y_deg\": 2,"
             " \"width\": 5, \"height\": 5},"
             " \"medium\": {\"sigma_a\": [0.5, 1, 2], \"sigma_s\": [0, 0, 0],"
             "  \"sources\": [{\"type\": \"vdb\", \"file\": \"%s/emissive_slab.vdb\","
             "   \"temperature\": {\"grid\": \"heat\", \"scale\": 1500}}]}}",
             argv[1]);
    CHECK(veil_scene_parse("temperature.json", json, strlen(json), &s, &err) == VEIL_OK, "%s", err.msg);
    double B[3];
    veil_blackbody_rgb(1500.0, B);
    for (int c = 0; c < 3; ++c) want[c] = B[c] * (1.0 - exp(-sa[c] * d));
    m = NULL;
    rgba = se = NULL;
    CHECK(veil_pt_medium_from_scene(&s, &m, &err) == VEIL_OK, "%s", err.msg);
    CHECK(m && veil_pt_render(m, &s, &o, &rgba, &se, NULL, &err) == VEIL_OK, "%s", err.msg);
    for (int c = 0; c < 3 && rgba; ++c) {
        double got = rgba[4 * 12 + c];
        CHECK(fabs(got - want[c]) <= 1e-6 * want[c] + 1e-12, "temperature, reference ch %d: %.9g, B (1 - e^-sa d) %.9g",
              c, got, want[c]);
        printf("temperature 1500 K, reference ch %d: %.7g, closed form %.7g\n", c, got, want[c]);
    }
    free(rgba);
    free(se);
    veil_pt_medium_free(m);
    s.multiple.volumetric = 0, s.multiple.screen_space = 0;
    CHECK(veil_render_scene_images(r, &s, &(veil_render_opts){.seed = 3}, &im, NULL, &err) == VEIL_OK, "%s", err.msg);
    for (int c = 0; c < 3 && im.rgba; ++c) {
        double L = im.aov_s[4 * 12 + c], T = im.aov_t[4 * 12 + c];
        CHECK(fabs(L - B[c] * (1.0 - T)) <= 1e-5 * B[c] * (1.0 - T) + 1e-12, "temperature, march ch %d: %.7g vs B (1 - T) %.7g",
              c, L, B[c] * (1.0 - T));
        printf("temperature 1500 K, march ch %d: %.7g, closed form %.7g\n", c, L, want[c]);
    }
    veil_image_set_free(&im);
    veil_scene_free(&s);
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
    return check_finish();
}
