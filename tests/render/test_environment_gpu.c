/* The environment light in the GPU pipeline (scene/environment.h):
 *  - seen behind the medium: with no medium every pixel is the map's radiance along its ray (the march
 *    adds T x radiance with T = 1: one float rounding of the double lookup, 2^-24 relative); a scene
 *    "background" is seen instead when it gives one;
 *  - lighting the medium, "remainder": "lights": a frame with an environment equals, bit for bit, the
 *    frame whose lights are the environment's median cut written out as directional lights (its
 *    "background" black, so that only the lights differ): the pipeline carries it as those lights and
 *    nothing else;
 *  - by default (the light cache the volumetric method), the cut is of the bright part alone and the
 *    cache carries the rest: a constant sky has no bright part, so no light is propagated and the cache
 *    has one source, the environment's, whose light alone lights the medium (the cache's photons
 *    themselves: tests/volumetric/test_cache.c; the bright cut: tests/scene/test_environment.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "frame/renderer.h"
#include "io/scene.h"
#include "scene/camera.h"

enum { W = 40, H = 30 };

static int parse(const char* json, veil_scene* s)
{
    veil_error err = {0};
    veil_result r = veil_scene_parse("environment scene", json, strlen(json), s, &err);
    CHECK(r == VEIL_OK, "scene: %s", err.msg);
    return r == VEIL_OK;
}

static int render(veil_renderer* r, const veil_scene* s, veil_image_set* out)
{
    veil_error err = {0};
    const veil_render_opts o = {.width = W, .height = H};
    const int ok = veil_render_scene_images(r, s, &o, out, NULL, &err) == VEIL_OK;
    CHECK(ok, "render: %s", err.msg);
    return ok;
}

/* A map of smoothly varying radiance (no two texels alike) in place of s's constant sky. */
static void gradient_map(veil_scene* s, int w, int h)
{
    veil_environment* e = &s->environment;
    free(e->rgb);
    e->rgb = malloc((size_t)w * h * 3 * sizeof *e->rgb);
    e->width = w, e->height = h;
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            float* t = e->rgb + 3 * ((size_t)j * w + i);
            t[0] = 0.1f + (float)i / w, t[1] = 0.2f + (float)j / h, t[2] = 0.05f * (float)((i * 7 + j * 3) % 11);
        }
}

static void test_behind(veil_renderer* r)
{
    char json[1024];
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0.3, 0.4, 4], \"look_at\": [0, 0.2, 0], \"fov_y_deg\": 70, \"width\": %d,"
             " \"height\": %d}, \"medium\": {\"sigma_s\": [1, 1, 1], \"sources\": []},"
             " \"lights\": [{\"type\": \"environment\", \"color\": [1, 1, 1], \"rotation_deg\": 25}]}", W, H);
    veil_scene s;
    if (!parse(json, &s)) return;
    gradient_map(&s, 64, 32);
    veil_image_set im = {0};
    if (render(r, &s, &im)) {
        veil_camera_basis b;
        veil_error err = {0};
        CHECK(veil_camera_make_basis(&s.camera, W, H, &b, &err) == VEIL_OK, "%s", err.msg);
        int bad = 0, distinct = 0;
        float first = im.rgba[0];
        for (int py = 0; py < H; ++py)
            for (int px = 0; px < W; ++px) {
                float d[3];
                veil_camera_ray(&b, W, H, px, py, d);
                double n = sqrt((double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2]);
                double dd[3] = {d[0] / n, d[1] / n, d[2] / n}, L[3];
                veil_env_radiance(&s.environment, dd, L);
                const float* p = im.rgba + 4 * ((size_t)py * W + px);
                for (int c = 0; c < 3; ++c) bad += !(fabs(p[c] - L[c]) <= 6e-8 * fabs(L[c]));
                bad += p[3] != 0.0f;
                distinct += p[0] != first;
            }
        CHECK(bad == 0, "%d values differ from the environment along the pixels' rays", bad);
        CHECK(distinct > W * H / 2, "the view sees one texel (%d pixels differ from the first): no test", distinct);
    }
    veil_image_set_free(&im);
    /* a background given: seen instead */
    s.background_set = 1;
    s.background[0] = 0.25f, s.background[1] = 0.5f, s.background[2] = 0.75f;
    if (render(r, &s, &im)) {
        int bad = 0;
        for (size_t i = 0; i < (size_t)W * H; ++i)
            for (int c = 0; c < 3; ++c) bad += im.rgba[4 * i + c] != s.background[c];
        CHECK(bad == 0, "with a background given, %d values are not it", bad);
    }
    veil_image_set_free(&im);
    veil_scene_free(&s);
}

static void test_lights(veil_renderer* r)
{
    static const char* const body =
        "\"medium\": {\"sigma_a\": [0.1, 0.1, 0.1], \"sigma_s\": [1.4, 1.5, 1.6], \"phase\": {\"type\": \"hg\", \"g\": 0.4},"
        " \"max_resolution\": 40, \"sources\": [{\"type\": \"rbf_random\", \"count\": 60, \"seed\": 7,"
        " \"bounds\": [[-1.2, -0.4, -0.6], [1.2, 0.5, 0.6]], \"radius\": [0.1, 0.3], \"amplitude\": [0.3, 1.0]}]},"
        " \"background\": {\"color\": [0, 0, 0]}";
    char json[2048];
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0, 0.6, 4.2], \"look_at\": [0, 0, 0], \"fov_y_deg\": 40, \"width\": %d,"
             " \"height\": %d}, %s, \"lights\": [{\"type\": \"point\", \"position\": [-0.9, 0.1, 0.3], \"intensity\": [6, 3, 1]},"
             " {\"type\": \"environment\", \"color\": [0.4, 0.5, 0.7], \"lights\": 6, \"remainder\": \"lights\"}]}",
             W, H, body);
    veil_scene a, b;
    if (!parse(json, &a)) return;
    const veil_env_cut* cut = veil_env_cut_for(&a.environment, 8); /* its "lights": 6, whatever the rung */
    CHECK(cut && cut->count == 6, "the constant sky cut into %d lights, not 6", cut ? cut->count : -1);
    if (!cut) {
        veil_scene_free(&a);
        return;
    }
    /* b: the point light and the cut's six, as the scene file would give them */
    char lights[2048] = "[{\"type\": \"point\", \"position\": [-0.9, 0.1, 0.3], \"intensity\": [6, 3, 1]}";
    for (int l = 0; l < cut->count; ++l) {
        const veil_light* L = &cut->lights[l];
        size_t n = strlen(lights);
        snprintf(lights + n, sizeof lights - n,
                 ", {\"type\": \"directional\", \"direction\": [%.9g, %.9g, %.9g], \"irradiance\": [%.9g, %.9g, %.9g]}",
                 L->direction[0], L->direction[1], L->direction[2], L->color[0], L->color[1], L->color[2]);
    }
    strcat(lights, "]");
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0, 0.6, 4.2], \"look_at\": [0, 0, 0], \"fov_y_deg\": 40, \"width\": %d,"
             " \"height\": %d}, %s, \"lights\": %s}", W, H, body, lights);
    if (!parse(json, &b)) {
        veil_scene_free(&a);
        return;
    }
    /* the directions as the file rounds them: %.9g of a float reads back as the same float */
    int same = b.light_count == 7;
    for (int l = 0; same && l < 6; ++l) same = !memcmp(&b.lights[l + 1], &cut->lights[l], sizeof(veil_light));
    CHECK(same, "the cut's lights did not read back as themselves: no test");
    veil_image_set ia = {0}, ib = {0};
    if (render(r, &a, &ia) && render(r, &b, &ib)) {
        size_t diff = 0;
        double peak = 0.0;
        for (size_t i = 0; i < (size_t)W * H * 4; ++i) {
            diff += ia.rgba[i] != ib.rgba[i];
            peak = fmax(peak, ia.rgba[i]);
        }
        CHECK(diff == 0, "%zu values differ between the environment and its lights written out", diff);
        CHECK(peak > 0.01, "the environment lit nothing (peak %g): no test", peak);
    }
    veil_image_set_free(&ia);
    veil_image_set_free(&ib);
    veil_scene_free(&a);
    veil_scene_free(&b);
}

/* The default split: the plan, the stages' reports and light where there is nothing else to light. */
static void test_split(veil_renderer* r)
{
    static const char* const body =
        "\"medium\": {\"sigma_a\": [0.1, 0.1, 0.1], \"sigma_s\": [1.4, 1.5, 1.6], \"max_resolution\": 40,"
        " \"sources\": [{\"type\": \"rbf_random\", \"count\": 60, \"seed\": 7, \"bounds\": [[-1.2, -0.4, -0.6],"
        " [1.2, 0.5, 0.6]], \"radius\": [0.1, 0.3], \"amplitude\": [0.3, 1.0]}]}, \"background\": {\"color\": [0, 0, 0]}";
    char json[2048];
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0, 0.6, 4.2], \"look_at\": [0, 0, 0], \"fov_y_deg\": 40, \"width\": %d,"
             " \"height\": %d}, %s, \"lights\": [{\"type\": \"environment\", \"color\": [0.4, 0.5, 0.7]}]}", W, H, body);
    veil_scene a;
    if (!parse(json, &a)) return;
    veil_image_set im = {0};
    veil_render_stats st = {0};
    veil_error err = {0};
    const veil_render_opts o = {.width = W, .height = H};
    CHECK(veil_render_scene_images(r, &a, &o, &im, &st, &err) == VEIL_OK, "render: %s", err.msg);
    if (im.rgba) {
        double peak = 0.0;
        for (size_t i = 0; i < (size_t)W * H; ++i) peak = fmax(peak, im.rgba[4 * i + 1]);
        CHECK(peak > 0.01, "the sky's rest lit nothing (peak %g)", peak);
        CHECK(strstr(st.stage[VEIL_STAGE_PROPAGATE].why, "no light reaches") != NULL,
              "a constant sky propagates no light: %s", st.stage[VEIL_STAGE_PROPAGATE].why);
        CHECK(strstr(st.stage[VEIL_STAGE_VOLUMETRIC].why, "from 1 source (the environment's rest)") != NULL,
              "the cache has the environment's rest as its one source: %s", st.stage[VEIL_STAGE_VOLUMETRIC].why);
    }
    veil_image_set_free(&im);
    veil_scene_free(&a);
}

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_renderer* r = NULL;
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    if (r) {
        test_behind(r);
        test_lights(r);
        test_split(r);
        veil_renderer_destroy(r);
    }
    veil_gl_destroy(gl);
    return check_finish();
}
