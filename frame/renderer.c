#include "renderer.h"

#include <epoxy/gl.h>
#include <stdlib.h>
#include <string.h>

#include "../core/clock.h"
#include "../core/progress.h"
#include "../propagate/opv_set.h"
#include "../render/march.h"
#include "../render/spread.h"
#include "../volume/ev.h"
#include "../volumetric/volumetric.h"

struct veil_renderer {
    unsigned long long memory_budget; /* bytes, see veil_gl_info */
    int hardware;                     /* veil_gl_info's: a software rasteriser marches in shorter bands */
    veil_frame_parts parts;           /* the stages' GPU objects and the keys of what they hold */
    int ready;                        /* 1: the GL context and the stages' objects are made */
    veil_gl* own_gl;                  /* a deferred renderer's context, made by it and destroyed with it */
    veil_gl_desc gl_desc;             /* what to make it with */
    GLuint query;                     /* a stage's GPU time (GL_TIME_ELAPSED), for --stats */
};

/* ---- lifetime ---------------------------------------------------------- */

/* The stages' GPU objects, on the current context gl. */
static veil_result make_parts(veil_renderer* r, const veil_gl* gl, veil_error* err)
{
    r->memory_budget = veil_gl_get_info(gl)->memory_budget;
    r->hardware = veil_gl_get_info(gl)->hardware;
    veil_frame_parts* p = &r->parts;
    veil_result res = veil_ev_create(&p->ev, err);
    if (res == VEIL_OK) veil_ev_set_software(p->ev, !r->hardware);
    if (res == VEIL_OK) res = veil_opv_set_create(&p->opv, err);
    if (res == VEIL_OK) res = veil_volumetric_create(&p->volumetric, err);
    if (res == VEIL_OK) res = veil_march_create(&p->march, err);
    if (res == VEIL_OK) res = veil_spread_create(&p->spread, err);
    if (res == VEIL_OK) glCreateQueries(GL_TIME_ELAPSED, 1, &r->query);
    r->ready = res == VEIL_OK;
    return res;
}

veil_result veil_renderer_create(const veil_gl* gl, veil_renderer** out, veil_error* err)
{
    *out = NULL;
    veil_renderer* r = calloc(1, sizeof *r);
    if (!r) return veil_fail(err, VEIL_ERR_OOM, "out of memory creating the renderer");
    veil_result res = make_parts(r, gl, err);
    if (res != VEIL_OK) {
        veil_renderer_destroy(r);
        return res;
    }
    *out = r;
    return VEIL_OK;
}

veil_result veil_renderer_create_deferred(const veil_gl_desc* desc, veil_renderer** out, veil_error* err)
{
    *out = calloc(1, sizeof **out);
    if (!*out) return veil_fail(err, VEIL_ERR_OOM, "out of memory creating the renderer");
    if (desc) (*out)->gl_desc = *desc;
    return VEIL_OK;
}

/* The frame's hook (veil_frame.gpu): a deferred renderer's context and objects, once. */
static veil_result make_gpu(veil_frame* f, veil_error* err)
{
    veil_renderer* r = f->gpu_user;
    if (!r->ready) {
        const double t0 = veil_now_ms();
        veil_result res = r->own_gl ? VEIL_OK : veil_gl_create(&r->gl_desc, &r->own_gl, err);
        if (res == VEIL_OK) res = make_parts(r, r->own_gl, err);
        f->gpu_ms += veil_now_ms() - t0;
        if (res != VEIL_OK) return res;
    }
    f->plan.budget = r->memory_budget;
    f->plan.hardware = r->hardware;
    if (!f->size_checked) { /* before any stage's GPU work: does the frame fit the device at all (issue 41)? */
        f->size_checked = 1;
        const veil_render_opts* o = &f->plan.o;
        return veil_march_check_size(o->width, o->height, f->plan.scene->multiple.screen_space, r->hardware,
                                     r->memory_budget, err);
    }
    return VEIL_OK;
}

void veil_renderer_destroy(veil_renderer* r)
{
    if (!r) return;
    veil_ev_destroy(r->parts.ev);
    veil_opv_set_destroy(r->parts.opv);
    veil_volumetric_destroy(r->parts.volumetric);
    veil_march_destroy(r->parts.march);
    veil_spread_destroy(r->parts.spread);
    if (r->query) glDeleteQueries(1, &r->query);
    veil_gl_destroy(r->own_gl);
    free(r);
}

/* ---- a frame: a walk over the table ------------------------------------ */

static veil_result run_frame(veil_renderer* r, veil_frame* f, veil_render_stats* st, veil_error* err)
{
    const veil_render_opts* o = &f->plan.o;
    if (o->width < 1 || o->height < 1 || o->width > VEIL_SCENE_MAX_IMAGE || o->height > VEIL_SCENE_MAX_IMAGE)
        return veil_fail(err, VEIL_ERR_INVALID, "image size %dx%d is outside 1..%d", o->width, o->height,
                         VEIL_SCENE_MAX_IMAGE);
    if (f->plan.scene->light_count > VEIL_MAX_LIGHTS)
        return veil_fail(err, VEIL_ERR_LIMIT, "%zu lights; at most %d are supported", f->plan.scene->light_count,
                         VEIL_MAX_LIGHTS);
    if (o->deep && (o->deep_samples < 1 || o->deep_samples > VEIL_DEEP_MAX_SAMPLES))
        return veil_fail(err, VEIL_ERR_INVALID, "deep samples: expected 1..%d samples a pixel, got %d",
                         VEIL_DEEP_MAX_SAMPLES, o->deep_samples);
    if (o->deep && veil_deep_bytes(o->width, o->height, o->deep_samples) > VEIL_DEEP_MAX_BYTES)
        return veil_fail(err, VEIL_ERR_LIMIT, "a deep image of %dx%d pixels at %d samples a pixel: up to %d raw "
                         "samples a pixel before the merge, %.3g GB, over the limit of %.3g GB (render/deep.h); "
                         "the file up to %.3g GB: lower the deep samples or the size", o->width, o->height,
                         o->deep_samples, veil_deep_raw_samples(o->deep_samples),
                         veil_deep_bytes(o->width, o->height, o->deep_samples) / 1e9, VEIL_DEEP_MAX_BYTES / 1e9,
                         (double)o->width * o->height * o->deep_samples * VEIL_DEEP_CHANNELS * sizeof(float) / 1e9);
    if (o->deep && o->behind) /* its samples would need the frame behind placed in depth */
        return veil_fail(err, VEIL_ERR_INVALID, "a deep image of a frame rendered in front of another (veil fog) "
                         "is not supported");
    f->parts = &r->parts;
    f->st = st;
    f->gpu = make_gpu;
    f->gpu_user = r;
    veil_result res = VEIL_OK;
    for (int i = 0; i < VEIL_STAGE_COUNT && res == VEIL_OK; ++i) {
        const veil_stage_row* row = &veil_stage_table[i];
        veil_stage_report* rep = &st->stage[row->id];
        double t0 = veil_now_ms(), gpu0 = f->gpu_ms;
        if (veil_progress_cancelled()) { /* the caller's progress callback asked to stop: between stages */
            res = veil_fail(err, VEIL_ERR_CANCELLED, "cancelled by the progress callback before the %s stage",
                            veil_stage_name(row->id));
            break;
        }
        veil_progress_set_stage(veil_stage_name(row->id));
        veil_progress(row->doing, 0, 1);
        rep->key = row->key(&f->plan);
        int kept = !row->per_view && r->parts.has[row->id] && r->parts.kept[row->id] == rep->key;
        rep->status = row->decide(&f->plan, kept, rep->why, sizeof rep->why);
        /* inject makes the GPU's side itself, once its sources are open and their work estimated */
        if (rep->status == VEIL_STAGE_RAN && row->id != VEIL_STAGE_INJECT) res = make_gpu(f, err);
        /* its GPU time apart from its wall time (--stats), on a GPU (a software rasteriser's timer queries
         * answer 0: its work is the CPU's, in the wall time); from here, where the context is made (inject
         * makes its own on a deferred renderer's first frame: that stage's GPU time is then not measured) */
        const int timed = res == VEIL_OK && rep->status == VEIL_STAGE_RAN && r->ready && r->query && r->hardware;
        rep->gpu_ms = -1.0;
        if (timed) glBeginQuery(GL_TIME_ELAPSED, r->query);
        if (res == VEIL_OK && rep->status == VEIL_STAGE_RAN) res = row->build(f, rep, err);
        if (res == VEIL_OK && row->settle) row->settle(f, rep);
        if (r->ready) glFinish();
        if (timed) {
            glEndQuery(GL_TIME_ELAPSED);
            GLuint64 ns = 0;
            glGetQueryObjectui64v(r->query, GL_QUERY_RESULT, &ns);
            rep->gpu_ms = (double)ns * 1e-6;
        }
        rep->ms = veil_now_ms() - t0 - (f->gpu_ms - gpu0);
    }
    veil_progress_set_stage(NULL);
    veil_frame_end(f);
    /* the deep image: what the flat one added after the march spread over its samples, merged to the cap */
    if (res == VEIL_OK && o->deep && f->images && f->images->deep.counts) {
        const veil_image_set* im = f->images;
        res = veil_deep_finish(&f->images->deep, im->rgba, im->aov_t, f->plan.scene->background, im->behind, o->deep_samples,
                               &st->deep, err);
    }
    st->inject_ms = st->stage[VEIL_STAGE_INJECT].ms;
    st->propagate_ms = st->stage[VEIL_STAGE_PROPAGATE].ms;
    st->render_ms = st->stage[VEIL_STAGE_RENDER].ms;
    return res;
}

veil_result veil_render_scene_images(veil_renderer* r, const veil_scene* s, const veil_render_opts* opts,
                                     veil_image_set* images, veil_render_stats* stats, veil_error* err)
{
    veil_render_stats st;
    memset(&st, 0, sizeof st);
    veil_image_set_free(images);
    veil_frame f = {.images = images};
    veil_frame_plan_begin(&f.plan, s, opts, r->memory_budget); /* 0 until a deferred renderer's GPU is made */
    veil_result res = run_frame(r, &f, &st, err);
    if (stats) *stats = st;
    return res;
}

/* Keeps the radiance buffer of an image set and frees the rest. */
static float* take_rgba(veil_image_set* im)
{
    float* rgba = im->rgba;
    im->rgba = NULL;
    veil_image_set_free(im);
    return rgba;
}

veil_result veil_render_scene(veil_renderer* r, const veil_scene* s, const veil_render_opts* opts, float** rgba,
                              veil_render_stats* stats, veil_error* err)
{
    veil_image_set im = {0};
    veil_result res = veil_render_scene_images(r, s, opts, &im, stats, err);
    *rgba = take_rgba(&im);
    return res;
}

veil_result veil_render_density(veil_renderer* r, const veil_scene* s, const veil_grid* g, const float* density,
                                const veil_render_opts* opts, float** rgba, veil_render_stats* stats,
                                veil_error* err)
{
    veil_render_stats st;
    memset(&st, 0, sizeof st);
    *rgba = NULL;
    veil_image_set im = {0};
    veil_frame f = {.images = &im};
    veil_frame_plan_begin(&f.plan, s, opts, r->memory_budget);
    f.plan.given_grid = g;
    f.plan.given_density = density;
    f.plan.volume_needed = 1;
    veil_result res = run_frame(r, &f, &st, err);
    *rgba = take_rgba(&im);
    if (stats) *stats = st;
    return res;
}

veil_result veil_renderer_inject(veil_renderer* r, const veil_grid* g, const veil_particle* p, size_t n,
                                 float* density, veil_error* err)
{
    return veil_ev_splat_readback(r->parts.ev, g, p, n, density, err);
}

veil_result veil_renderer_propagate(veil_renderer* r, const veil_grid* g, const float* density,
                                    const veil_index_light* lights, int n_lights, const veil_opv_params* params,
                                    float* out, int* iterations, veil_error* err)
{
    return veil_opv_set_propagate_readback(r->parts.opv, g, density, lights, n_lights, params, out, iterations, err);
}
