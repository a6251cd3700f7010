/* A frame whose caller keeps R, G, B, A alone (veil_render_opts.flat_only, the CLI without --aovs;
 * issue 42) reads back only what later steps need, and its R, G, B, A are bit for bit those of the
 * full frame: with the light cache, with the screen-space spread (which reads the march's T, S and Q
 * where the march left them, and T and Q's P on the CPU for its decision), in front of a frame (veil
 * fog: T), with an environment light (T, read by the march itself) and with a deep
 * image (T). Every frame renders with one renderer, so the march's images are kept between frames
 * of one size and made anew at another: the last frame, at a size seen before, equals a fresh
 * renderer's. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "support/check.h"
#include "frame/renderer.h"
#include "io/image.h"
#include "io/scene.h"

static const char* const BASE =
    "{\"camera\": {\"position\": [0, 0.3, 3], \"look_at\": [0, 0, 0], \"width\": 40, \"height\": 30},"
    " \"medium\": {\"sigma_s\": [3, 3, 3], \"sigma_a\": [0.1, 0.1, 0.1], \"sources\": [{\"type\": \"rbf\","
    " \"particles\": [{\"center\": [0, 0, 0], \"amplitude\": 2, \"sharpness\": 3},"
    " {\"center\": [0.5, 0.2, 0], \"amplitude\": 1, \"sharpness\": 5}]}]},"
    " \"lights\": [{\"type\": \"directional\", \"direction\": [0.3, -1, 0.2], \"irradiance\": [2, 2, 2]}%s]%s}";

typedef struct variant {
    const char* name;
    const char* lights; /* more lights */
    const char* rest;   /* more top-level keys */
    int behind, deep;
    int need_t, need_s, need_q; /* what the flat frame must still read back */
} variant;

static int same_floats(const float* a, const float* b, size_t n)
{
    return a && b && !memcmp(a, b, n * sizeof *a);
}

static void render_pair(veil_renderer* ren, const variant* v, const char* map_dir, int w, int h)
{
    char json[2048], lights[512];
    snprintf(lights, sizeof lights, v->lights, map_dir);
    snprintf(json, sizeof json, BASE, lights, v->rest);
    veil_error err = {0};
    veil_scene s;
    veil_result r = veil_scene_parse_in(v->name, json, strlen(json), map_dir, &s, &err);
    CHECK(r == VEIL_OK, "%s: %s", v->name, err.msg);
    if (r != VEIL_OK) return;
    const size_t px = (size_t)w * (size_t)h;
    float* behind = calloc(px * 4, sizeof *behind);
    float* dist = calloc(px, sizeof *dist);
    for (size_t i = 0; i < px; ++i) {
        for (int c = 0; c < 3; ++c) behind[4 * i + c] = 0.2f + 0.1f * (float)c + 0.5f * (float)(i % 7) / 7.0f;
        behind[4 * i + 3] = 1.0f;
        dist[i] = i % 3 ? 3.1f : INFINITY;
    }
    veil_render_opts o = {.width = w, .height = h, .behind = v->behind ? behind : NULL,
                          .behind_distance = v->behind ? dist : NULL, .deep = v->deep};
    veil_image_set full = {0}, flat = {0};
    r = veil_render_scene_images(ren, &s, &o, &full, NULL, &err);
    CHECK(r == VEIL_OK, "%s, full: %s", v->name, err.msg);
    o.flat_only = 1;
    veil_result r2 = veil_render_scene_images(ren, &s, &o, &flat, NULL, &err);
    CHECK(r2 == VEIL_OK, "%s, flat: %s", v->name, err.msg);
    if (r == VEIL_OK && r2 == VEIL_OK) {
        CHECK(same_floats(full.rgba, flat.rgba, px * 4), "%s at %dx%d: the flat frame's R, G, B, A differ from the "
              "full frame's", v->name, w, h);
        CHECK(full.aov_t && full.aov_s && full.aov_v && full.aov_z, "%s: the full frame lacks an AOV", v->name);
        CHECK(!flat.aov_v && !flat.aov_z, "%s: the flat frame read back the volumetric image or made Z", v->name);
        CHECK(!!flat.aov_t == v->need_t, "%s: the flat frame %s T", v->name, flat.aov_t ? "read back" : "lacks");
        CHECK(!!flat.aov_s == v->need_s, "%s: the flat frame %s S", v->name, flat.aov_s ? "read back" : "lacks");
        CHECK(!!flat.aov_q == v->need_q, "%s: the flat frame %s Q", v->name, flat.aov_q ? "read back" : "lacks");
        if (v->deep)
            CHECK(flat.deep.counts && full.deep.total == flat.deep.total &&
                  same_floats(full.deep.samples, flat.deep.samples, full.deep.total * VEIL_DEEP_CHANNELS),
                  "%s: the deep images differ", v->name);
        if (v->need_q || v->behind) /* the spread ran (reading S, T and Q where the march left them): it added light */
            CHECK(flat.aov_m != NULL, "%s: the spread did not run (the test needs it to)", v->name);
    }
    veil_image_set_free(&full);
    veil_image_set_free(&flat);
    veil_scene_free(&s);
    free(behind);
    free(dist);
}

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    char dir[] = "/tmp/veil_flat_onlyXXXXXX";
    CHECK(mkdtemp(dir) != NULL, "%s", "mkdtemp");
    /* an environment map of 8 x 4 texels, each its own colour */
    float map[8 * 4 * 4];
    for (int i = 0; i < 32; ++i)
        for (int c = 0; c < 4; ++c) map[4 * i + c] = c == 3 ? 1.0f : 0.05f * (float)(1 + (i * (c + 2)) % 11);
    char map_path[256];
    snprintf(map_path, sizeof map_path, "%s/sky.exr", dir);
    veil_error err = {0};
    CHECK(veil_write_exr(map_path, 8, 4, map, &err) == VEIL_OK, "%s", err.msg);
    const variant variants[] = {
        {"the light cache", "", "", 0, 0, 0, 0, 0},
        {"the spread", "", ", \"multiple_scattering\": {\"volumetric\": false}", 0, 0, 1, 0, 1},
        {"in front of a frame", "", "", 1, 0, 1, 0, 0},
        {"an environment", ", {\"type\": \"environment\", \"file\": \"%s/sky.exr\"}", "", 0, 0, 1, 0, 0},
        {"a deep image", "", "", 0, 1, 1, 0, 0},
    };
    veil_renderer* ren = NULL;
    CHECK(veil_renderer_create(gl, &ren, &err) == VEIL_OK, "%s", err.msg);
    for (size_t i = 0; ren && i < sizeof variants / sizeof *variants; ++i) render_pair(ren, &variants[i], dir, 40, 30);
    if (ren) render_pair(ren, &variants[0], dir, 24, 18); /* another size: the images made anew */
    /* the first size again (made anew once more), and a fresh renderer's frame of it: the same bits */
    veil_renderer* fresh = NULL;
    CHECK(veil_renderer_create(gl, &fresh, &err) == VEIL_OK, "%s", err.msg);
    char json[2048];
    snprintf(json, sizeof json, BASE, "", "");
    veil_scene s;
    if (ren && fresh && veil_scene_parse("again", json, strlen(json), &s, &err) == VEIL_OK) {
        veil_render_opts o = {.width = 40, .height = 30, .flat_only = 1};
        float *a = NULL, *b = NULL;
        CHECK(veil_render_scene(ren, &s, &o, &a, NULL, &err) == VEIL_OK, "%s", err.msg);
        CHECK(veil_render_scene(fresh, &s, &o, &b, NULL, &err) == VEIL_OK, "%s", err.msg);
        CHECK(same_floats(a, b, 40 * 30 * 4), "%s", "a kept renderer's frame differs from a fresh renderer's");
        free(a);
        free(b);
        veil_scene_free(&s);
    }
    veil_renderer_destroy(fresh);
    veil_renderer_destroy(ren);
    unlink(map_path);
    rmdir(dir);
    veil_gl_destroy(gl);
    return check_finish();
}
