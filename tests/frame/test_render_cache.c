/* Work a frame does not need is skipped, and skipping changes nothing:
 *  - a second render with only the camera moved reuses the EV and every
 *    OPV (stats say cached) and equals, bit for bit, a fresh renderer's
 *    image from that camera;
 *  - changing a light's colour re-propagates nothing (D does not depend on
 *    it), moving it re-propagates its texture only;
 *  - a spot aimed away from the medium and a zero-intensity light get no
 *    OPV and leave the image bit for bit as without them;
 *  - an empty medium makes no volume and no OPV: the image is the background;
 *  - skipping empty bricks changes only where the march's steps fall, so a
 *    skipping render differs from a non-skipping one by no more than two
 *    non-skipping renders with different jitter seeds differ (times 2: the
 *    two differences are of the same kind, and rms differences of this size
 *    vary by tens of percent between seeds). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "frame/renderer.h"

static veil_particle parts[3] = {
    {.center = {0.0f, 0.0f, 0.0f}, .amplitude = 1.0f, .sharpness = 3.0f},
    {.center = {0.4f, 0.1f, 0.0f}, .amplitude = 0.7f, .sharpness = 4.0f},
    {.center = {-0.3f, -0.2f, 0.2f}, .amplitude = 0.9f, .sharpness = 5.0f},
};

static void base_scene(veil_scene* s, veil_source* src, veil_light* lights)
{
    memset(s, 0, sizeof *s);
    src->type = VEIL_SOURCE_RBF;
    src->particles = parts;
    src->particle_count = 3;
    s->camera = (veil_camera){.position = {0, 0.3f, 3.0f}, .look_at = {0, 0, 0}, .up = {0, 1, 0},
                              .fov_y_deg = 40, .width = 48, .height = 36};
    for (int c = 0; c < 3; ++c) {
        s->medium.sigma_a[c] = 0.1f;
        s->medium.sigma_s[c] = 1.5f;
    }
    s->medium.phase = (veil_phase){.type = VEIL_PHASE_HG, .g = 0.2f};
    s->medium.max_resolution = 24;
    s->medium.sources = src;
    s->medium.source_count = 1;
    lights[0] = (veil_light){.type = VEIL_LIGHT_POINT, .position = {0.5f, 0.5f, 0.5f}, .color = {3, 2, 1}};
    lights[1] = (veil_light){.type = VEIL_LIGHT_DIRECTIONAL, .direction = {0, -1, 0}, .color = {1, 1, 1}};
    s->lights = lights;
    s->light_count = 2;
    s->background[0] = 0.1f;
}

static int same(const float* a, const float* b, size_t n) { return a && b && memcmp(a, b, n * sizeof(float)) == 0; }

int main(void)
{
    veil_gl* gl = check_gpu_or_skip();
    veil_renderer *r = NULL, *fresh = NULL;
    veil_error err = {0};
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    CHECK(veil_renderer_create(gl, &fresh, &err) == VEIL_OK, "%s", err.msg);
    veil_scene s;
    veil_source src;
    veil_light lights[4];
    base_scene(&s, &src, lights);
    size_t n = 48 * 36 * 4;
    float *a = NULL, *b = NULL, *c = NULL;
    veil_render_stats st;

    CHECK(veil_render_scene(r, &s, NULL, &a, &st, &err) == VEIL_OK, "%s", err.msg);
    /* both lights' optical depths in light-space grids (the default method): two made, no OPV texture */
    CHECK(!st.inject_cached && st.opv_computed + st.grids_computed == 2 && st.lights_used == 2,
          "first render: %d %d %d %d", st.inject_cached, st.opv_computed, st.grids_computed, st.lights_used);

    /* camera moved only */
    veil_camera moved = s.camera;
    moved.position[0] = 1.5f;
    veil_render_opts o = {.camera = &moved};
    CHECK(veil_render_scene(r, &s, &o, &b, &st, &err) == VEIL_OK, "%s", err.msg);
    CHECK(st.inject_cached && st.opv_computed + st.grids_computed == 0 && st.opv_cached + st.grids == 2,
          "camera move re-ran work: %d %d %d %d %d", st.inject_cached, st.opv_computed, st.grids_computed,
          st.opv_cached, st.grids);
    CHECK(veil_render_scene(fresh, &s, &o, &c, &st, &err) == VEIL_OK, "%s", err.msg);
    CHECK(same(b, c, n), "the cached render differs from a fresh one");
    CHECK(!same(a, b, n), "moving the camera changed nothing");
    free(b);
    free(c);
    b = c = NULL;

    /* colour changed: no propagation; position changed: one texture */
    lights[0].color[0] = 5;
    CHECK(veil_render_scene(r, &s, NULL, &b, &st, &err) == VEIL_OK, "%s", err.msg);
    CHECK(st.opv_computed + st.grids_computed == 0, "a colour change re-propagated");
    free(b);
    lights[0].position[1] = 0.6f;
    CHECK(veil_render_scene(r, &s, NULL, &b, &st, &err) == VEIL_OK, "%s", err.msg);
    CHECK(st.opv_computed + st.grids_computed == 1, "a moved light was not re-propagated (%d %d)", st.opv_computed,
          st.grids_computed);
    free(b);
    b = NULL;
    lights[0] = (veil_light){.type = VEIL_LIGHT_POINT, .position = {0.5f, 0.5f, 0.5f}, .color = {3, 2, 1}};

    /* lights that add nothing */
    lights[2] = (veil_light){.type = VEIL_LIGHT_SPOT, .position = {0, 0, 3}, .direction = {0, 0, 1},
                             .color = {50, 50, 50}, .inner_angle_deg = 5, .outer_angle_deg = 10};
    lights[3] = (veil_light){.type = VEIL_LIGHT_POINT, .position = {0.1f, 0, 0}, .color = {0, 0, 0}};
    s.light_count = 4;
    CHECK(veil_render_scene(fresh, &s, NULL, &b, &st, &err) == VEIL_OK, "%s", err.msg);
    CHECK(st.lights_used == 2, "%d lights used, expected 2 (a spot facing away, a black light)", st.lights_used);
    CHECK(same(a, b, n), "lights that add nothing changed the image");
    free(b);
    b = NULL;
    /* the same spot turned toward the medium is used and adds light */
    lights[2].direction[2] = -1;
    CHECK(veil_render_scene(fresh, &s, NULL, &b, &st, &err) == VEIL_OK, "%s", err.msg);
    CHECK(st.lights_used == 3, "%d lights used, expected 3", st.lights_used);
    CHECK(!same(a, b, n), "a spot aimed at the medium added nothing");
    free(b);
    b = NULL;
    s.light_count = 2;

    /* skipping empty bricks: two small particles far apart leave most of the
     * box between them empty */
    {
        veil_particle apart[2] = {{.center = {-1.0f, 0.0f, 0.0f}, .amplitude = 2.0f, .sharpness = 9.0f},
                                  {.center = {1.0f, 0.1f, 0.0f}, .amplitude = 2.0f, .sharpness = 9.0f}};
        veil_source two = {.type = VEIL_SOURCE_RBF, .particles = apart, .particle_count = 2};
        veil_scene sp = s;
        sp.medium.sources = &two;
        sp.medium.max_resolution = 64;
        sp.camera.position[0] = 2.0f; /* look along the pair */
        float *s0 = NULL, *s1 = NULL, *k1 = NULL;
        veil_render_opts plain1 = {.seed = 1, .no_skip = 1}, plain2 = {.seed = 2, .no_skip = 1}, skip1 = {.seed = 1};
        veil_render_scene(fresh, &sp, &plain1, &s0, &st, &err);
        veil_render_scene(fresh, &sp, &plain2, &s1, &st, &err);
        veil_render_scene(fresh, &sp, &skip1, &k1, &st, &err);
        double seeds = 0.0, skip = 0.0, norm = 0.0;
        for (size_t i = 0; i < n && s0 && s1 && k1; ++i) {
            if (i % 4 == 3) continue;
            seeds += (double)(s0[i] - s1[i]) * (s0[i] - s1[i]);
            skip += (double)(s0[i] - k1[i]) * (s0[i] - k1[i]);
            norm += (double)s0[i] * s0[i];
        }
        printf("skipping empty bricks: rms difference %.3g; between two jitter seeds %.3g\n", sqrt(skip / norm),
               sqrt(seeds / norm));
        CHECK(seeds > 0.0, "the jitter seed changed nothing");
        CHECK(skip > 0.0, "skipping changed nothing: no empty brick was crossed");
        CHECK(skip <= 4.0 * seeds, "skipping changed the image more than a new jitter seed (%.3g vs %.3g)",
              sqrt(skip / norm), sqrt(seeds / norm));
        free(s0);
        free(s1);
        free(k1);
    }

    /* empty medium */
    src.particle_count = 0;
    CHECK(veil_render_scene(fresh, &s, NULL, &b, &st, &err) == VEIL_OK, "%s", err.msg);
    CHECK(!st.has_volume && st.opv_computed == 0 && st.lights_used == 0, "empty medium did work");
    int bg = 1;
    for (size_t p = 0; p < 48 * 36 && b; ++p) bg &= b[4 * p] == 0.1f && b[4 * p + 1] == 0.0f && b[4 * p + 3] == 0.0f;
    CHECK(bg, "empty medium: not the background");

    free(a);
    free(b);
    veil_renderer_destroy(r);
    veil_renderer_destroy(fresh);
    veil_gl_destroy(gl);
    return check_finish();
}
