/* The march compiled for a frame's lights (render/march.h,
 * VEIL_MARCH_LIGHT_LIST_WORK: each light's kind and light-space grid, the
 * field and the gather as constants) against the generic march that reads
 * them from its blocks: the same frame, every buffer, per pixel.
 *
 * The two programs run the same operations in the same order on the same
 * inputs; only the compiler's folding differs (a constant kind removes a
 * select, a constant channel a swizzle), which may fuse a multiply and an
 * add where the other does not. Each such step differs by at most one
 * rounding, 2^-24 relative; a pixel sums at most a few thousand of them (its
 * steps, about 200 here, times a few operations a light), so the two agree
 * to 2^-24 * 2000 = 1.2e-4 relative, and to 1e-6 of the frame's peak where
 * terms of both signs cancel (the cache's lobe). A light taken from the
 * wrong texture, channel, kind or grid changes a pixel by far more.
 * Scenes: every kind of light, each way its optical depth is kept (the
 * default method: the first four, point, sun, spot and point, in
 * light-space grids, the perspective form for the point and spot lights,
 * and a fifth, a sun, on the EV's grid; `semi-lagrangian`: all five on the
 * EV's grid, two OPV textures), fog around the volume, and each field the
 * march reads (the cache, with and without the gather, the octaves with
 * their escape field, none). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "support/check.h"
#include "frame/renderer.h"
#include "io/scene.h"
#include "render/march.h"

enum { W = 40, H = 30 };

static const char* const LIGHTS[5] = {
    "{\"type\": \"point\", \"position\": [-0.9, 0.1, 0.3], \"intensity\": [6, 3, 1]}",
    "{\"type\": \"directional\", \"direction\": [0.3, -0.75, 0.6], \"irradiance\": [2.6, 2.5, 2.3]}",
    "{\"type\": \"spot\", \"position\": [0, 1.4, 0.2], \"direction\": [0, -1, 0], \"intensity\": [4, 4, 6],"
    " \"inner_angle_deg\": 15, \"outer_angle_deg\": 30}",
    "{\"type\": \"point\", \"position\": [1.0, 0.3, -0.2], \"intensity\": [1, 2.5, 8]}",
    "{\"type\": \"directional\", \"direction\": [-0.6, -0.5, -0.6], \"irradiance\": [0.8, 0.9, 1.0]}"};

/* The scene: an RBF puff cluster, fog or not, phase g, multiple scattering's settings. */
static void scene_json(char* out, size_t cap, int fog, double g, const char* multiple, int lights)
{
    char ls[1024] = "\"lights\": [";
    for (int i = 0; i < lights && i < 5; ++i) strcat(strcat(ls, i ? ", " : ""), LIGHTS[i]);
    strcat(ls, "]");
    snprintf(out, cap,
             "{\"camera\": {\"position\": [0, 0.6, 4.2], \"look_at\": [0, 0, 0], \"fov_y_deg\": 40, \"width\": %d, \"height\": %d},"
             " \"medium\": {\"sigma_a\": [0.1, 0.1, 0.1], \"sigma_s\": [1.4, 1.5, 1.6], \"phase\": {\"type\": \"hg\", \"g\": %g},"
             " \"max_resolution\": 40, \"sources\": [{\"type\": \"rbf_random\", \"count\": 60, \"seed\": 7,"
             " \"bounds\": [[-1.2, -0.4, -0.6], [1.2, 0.5, 0.6]], \"radius\": [0.1, 0.3], \"amplitude\": [0.3, 1.0]}%s]},"
             " %s, \"multiple_scattering\": %s, \"background\": {\"color\": [0.01, 0.02, 0.03]}}",
             W, H, g,
             fog ? ", {\"type\": \"exponential\", \"density\": 0.05, \"falloff\": 0.5, \"direction\": [0, 1, 0],"
                   " \"origin\": [0, -1, 0], \"bounds\": [[-3, -1, -3], [3, 2, 3]]}"
                 : "",
             ls, multiple);
}

static int render(veil_renderer* r, const char* json, veil_opv_method method, veil_image_set* out)
{
    veil_error err = {0};
    veil_scene s;
    if (veil_scene_parse("lights scene", json, strlen(json), &s, &err) != VEIL_OK) {
        CHECK(0, "scene: %s", err.msg);
        return 0;
    }
    const veil_render_opts o = {.width = W, .height = H, .method = method};
    const int ok = veil_render_scene_images(r, &s, &o, out, NULL, &err) == VEIL_OK;
    CHECK(ok, "render: %s", err.msg);
    veil_scene_free(&s);
    return ok;
}

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_renderer* r = NULL;
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    static const struct {
        const char* name;
        int fog, lights;
        double g;
        const char* multiple;
        veil_opv_method method;
    } cases[] = {
        {"5 lights, the cache", 0, 5, 0.35, "{}", 0},
        {"5 lights, semi-lagrangian, the cache", 0, 5, 0.35, "{}", VEIL_OPV_SEMI_LAGRANGIAN},
        {"5 lights and fog, the cache", 1, 5, 0.35, "{}", 0},
        {"3 lights, the cache gathered (g 0.8)", 0, 3, 0.8, "{}", 0},
        {"5 lights, the octaves", 0, 5, 0.35, "{\"volumetric_method\": \"octave\"}", 0},
        {"2 lights, single scattering", 0, 2, 0.35, "{\"volumetric\": false}", 0},
    };
    char json[4096];
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        scene_json(json, sizeof json, cases[c].fog, cases[c].g, cases[c].multiple, cases[c].lights);
        veil_image_set generic = {0}, listed = {0};
        veil_march_set_light_list_work(UINT64_MAX);
        const int a = render(r, json, cases[c].method, &generic);
        veil_march_set_light_list_work(1);
        const int b = a && render(r, json, cases[c].method, &listed);
        veil_march_set_light_list_work(0);
        if (!b) continue;
        const float* ga[5] = {generic.rgba, generic.aov_t, generic.aov_s, generic.aov_v, generic.aov_q};
        const float* la[5] = {listed.rgba, listed.aov_t, listed.aov_s, listed.aov_v, listed.aov_q};
        const size_t n = (size_t)W * H * 4;
        double worst = 0.0, peak = 0.0, sum = 0.0;
        for (int i = 0; i < 5; ++i)
            for (size_t k = 0; k < n; ++k) peak = fmax(peak, fabs(ga[i][k]));
        for (int i = 0; i < 5; ++i)
            for (size_t k = 0; k < n; ++k) {
                const double d = fabs((double)la[i][k] - ga[i][k]), bound = 1.2e-4 * fabs(ga[i][k]) + 1e-6 * peak;
                CHECK(isfinite(la[i][k]) && d <= bound, "%s: buffer %d value %zu: %g compiled for the lights, %g generic",
                      cases[c].name, i, k, la[i][k], ga[i][k]);
                if (!(d <= bound)) break;
                worst = fmax(worst, d / bound);
            }
        for (size_t k = 0; k < n; ++k) sum += generic.aov_s[k];
        CHECK(sum > 0.0, "%s: no single scattering proves nothing", cases[c].name);
        printf("%-40s agree (worst difference %.3g of its bound)\n", cases[c].name, worst);
        veil_image_set_free(&generic);
        veil_image_set_free(&listed);
    }
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
    return check_finish();
}
