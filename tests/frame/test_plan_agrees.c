/* The plan and the render cannot drift apart: `--explain` walks the same
 * table of stages (frame/stages.h) with the same keys and decisions as the
 * renderer. For each scene (the example scenes given as arguments, and the
 * demo with the volumetric estimate off and with the diffusion method), two
 * frames of an orbit are rendered on one renderer, and every stage's status
 * and key on frame 0 and on frame 1 must equal what veil_plan_reports()
 * says, without a GPU, for the first frame and for the frames after it.
 * The scenes are chosen so that no build learns what the descriptions do
 * not say (no emission, no view that is optically thin only after the
 * march). Anti-vacuity: across the scenes every status (ran, cached,
 * skipped) is compared at least once, and so is every stage with a key. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "frame/plan.h"
#include "frame/renderer.h"
#include "io/scene.h"
#include "scene/camera.h"

static int seen_status[3], seen_key[VEIL_STAGE_COUNT];

static void compare(const char* what, long frame, const veil_stage_report* plan, const veil_render_stats* st)
{
    for (int i = 0; i < VEIL_STAGE_COUNT; ++i) {
        const veil_stage_report* a = &plan[i];
        const veil_stage_report* b = &st->stage[i];
        CHECK(a->status == b->status, "%s, frame %ld, %s: the plan says %s (%s), the render %s (%s)", what, frame,
              veil_stage_name((veil_stage_id)i), veil_stage_status_name(a->status), a->why,
              veil_stage_status_name(b->status), b->why);
        CHECK(a->key == b->key, "%s, frame %ld, %s: key %016llx in the plan, %016llx in the render", what, frame,
              veil_stage_name((veil_stage_id)i), (unsigned long long)a->key, (unsigned long long)b->key);
        if (a->status == b->status) seen_status[a->status] = 1;
        if (a->key && a->key == b->key) seen_key[i] = 1;
    }
}

/* Each case on a renderer of its own: a kept result of the case before would
 * (rightly) be reused, and the plan describes a run from nothing kept. */
static void one(veil_gl* gl, veil_scene* s, const char* what)
{
    veil_error err = {0};
    veil_renderer* r = NULL;
    if (veil_renderer_create(gl, &r, &err) != VEIL_OK) {
        CHECK(0, "%s: %s", what, err.msg);
        return;
    }
    veil_stage_report first[VEIL_STAGE_COUNT], later[VEIL_STAGE_COUNT];
    veil_render_opts o = {.width = 24, .height = 18, .seed = 1};
    CHECK(veil_plan_reports(s, &o, first, later, &err) == VEIL_OK, "%s: %s", what, err.msg);
    for (long frame = 0; frame < 2; ++frame) {
        veil_camera cam = veil_camera_of_frame(&s->camera, frame, 4);
        o.camera = &cam;
        float* rgba = NULL;
        veil_render_stats st;
        CHECK(veil_render_scene(r, s, &o, &rgba, &st, &err) == VEIL_OK, "%s, frame %ld: %s", what, frame, err.msg);
        free(rgba);
        compare(what, frame, frame == 0 ? first : later, &st);
    }
    veil_renderer_destroy(r);
    printf("%s: inject %s/%s, propagate %s/%s, volumetric %s/%s, render %s, spread %s\n", what,
           veil_stage_status_name(first[0].status), veil_stage_status_name(later[0].status),
           veil_stage_status_name(first[1].status), veil_stage_status_name(later[1].status),
           veil_stage_status_name(first[2].status), veil_stage_status_name(later[2].status),
           veil_stage_status_name(first[3].status), veil_stage_status_name(first[4].status));
}

int main(int argc, char** argv)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    CHECK(argc >= 2, "usage: test_plan_agrees DEMO.json [MORE.json ...]");
    for (int a = 1; a < argc; ++a) {
        veil_scene s;
        if (veil_scene_load(argv[a], &s, &err) != VEIL_OK) {
            CHECK(0, "%s: %s", argv[a], err.msg);
            continue;
        }
        one(gl, &s, argv[a]);
        if (a == 1) { /* the first scene again, with its volumetric stage changed */
            s.multiple.volumetric = 0;
            one(gl, &s, "the first scene, volumetric estimate off");
            s.multiple.volumetric = 1;
            s.multiple.volumetric_method = VEIL_VOLUMETRIC_DIFFUSION;
            one(gl, &s, "the first scene, the diffusion field");
        }
        veil_scene_free(&s);
    }
    CHECK(seen_status[VEIL_STAGE_RAN] && seen_status[VEIL_STAGE_CACHED] && seen_status[VEIL_STAGE_SKIPPED],
          "not every status was compared (ran %d, cached %d, skipped %d)", seen_status[VEIL_STAGE_RAN],
          seen_status[VEIL_STAGE_CACHED], seen_status[VEIL_STAGE_SKIPPED]);
    CHECK(seen_key[VEIL_STAGE_INJECT] && seen_key[VEIL_STAGE_PROPAGATE] && seen_key[VEIL_STAGE_VOLUMETRIC],
          "a keyed stage was never compared (inject %d, propagate %d, volumetric %d)", seen_key[VEIL_STAGE_INJECT],
          seen_key[VEIL_STAGE_PROPAGATE], seen_key[VEIL_STAGE_VOLUMETRIC]);
    veil_gl_destroy(gl);
    return check_finish();
}
