/* The march in bands of rows (render/march.h, VEIL_MARCH_DISPATCH_WORK):
 * every pixel is computed alone from the same inputs, so a frame marched
 * in 8-row bands must equal, bit for bit, the frame marched in one
 * dispatch; and the bands are reported as they finish (core/progress.h).
 *   test_march_bands SCENE.json   (an RBF scene: a volume to march through) */
#include <stdio.h>
#include <string.h>

#include "support/check.h"
#include "core/progress.h"
#include "frame/renderer.h"
#include "io/scene.h"
#include "render/march.h"

typedef struct rows_log {
    int calls;
    double last, total;
} rows_log;

static void on_progress(void* user, const char* what, double done, double total)
{
    rows_log* l = user;
    if (strcmp(what, "march, rows") != 0) return;
    ++l->calls;
    l->last = done;
    l->total = total;
}

int main(int argc, char** argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s SCENE.json\n", argv[0]);
        return 2;
    }
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_scene s;
    CHECK(veil_scene_load(argv[1], &s, &err) == VEIL_OK, "%s", err.msg);
    veil_renderer* r = NULL;
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    const veil_render_opts o = {.width = 61, .height = 45}; /* 45 rows: the last band is short */
    veil_image_set one = {0}, bands = {0};
    CHECK(veil_render_scene_images(r, &s, &o, &one, NULL, &err) == VEIL_OK, "%s", err.msg);

    veil_march_set_dispatch_work(1); /* the smallest band: VEIL_MARCH_GROUP rows */
    rows_log log = {0};
    void* old_user = NULL;
    veil_progress_fn old = veil_progress_sink(on_progress, &log, &old_user);
    CHECK(veil_render_scene_images(r, &s, &o, &bands, NULL, &err) == VEIL_OK, "%s", err.msg);
    veil_progress_sink(old, old_user, NULL);
    veil_march_set_dispatch_work(0);

    const int expect = 1 + (45 + VEIL_MARCH_GROUP - 1) / VEIL_MARCH_GROUP; /* 0, then each band */
    CHECK(log.calls == expect && log.last == 45 && log.total == 45, "rows reported %d times (expected %d), last %g of %g",
          log.calls, expect, log.last, log.total);
    const size_t n = (size_t)61 * 45 * 4;
    const float* a[5] = {one.rgba, one.aov_t, one.aov_s, one.aov_v, one.aov_q};
    const float* b[5] = {bands.rgba, bands.aov_t, bands.aov_s, bands.aov_v, bands.aov_q};
    double sum = 0.0;
    for (int i = 0; i < 5; ++i) {
        CHECK(a[i] && b[i] && memcmp(a[i], b[i], n * sizeof(float)) == 0, "buffer %d differs between one dispatch and bands", i);
        for (size_t k = 0; a[0] && k < n; ++k) sum += a[0][k];
    }
    CHECK(sum > 0.0, "an empty image proves nothing");
    printf("61x45 in %d bands of %d rows equals one dispatch, bit for bit\n", expect - 1, VEIL_MARCH_GROUP);
    veil_image_set_free(&one);
    veil_image_set_free(&bands);
    veil_renderer_destroy(r);
    veil_scene_free(&s);
    veil_gl_destroy(gl);
    return check_finish();
}
