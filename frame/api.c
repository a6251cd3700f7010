/* veil — the public API (include/veil.h) over the renderer, the scene
 * reader and the image writers. Every pointer argument is checked here, so
 * that a caller's NULL is a VEIL_ERR_INVALID naming the argument, never a
 * crash; the internal functions below assume valid arguments. */
#define _POSIX_C_SOURCE 200809L /* stat's dev_t and ino_t */
#include "../include/veil.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "../core/progress.h"
#include "../core/result.h"
#include "../gpu/gl_context.h"
#include "../io/image.h"
#include "../io/scene.h"
#include "../render/image_set.h"
#include "../scene/camera.h"
#include "../scene/scene.h"
#include "desc_size.h"
#include "renderer.h"
#include "stage.h"

struct veil_context {
    veil_gl* gl;
    veil_renderer* renderer;
    /* Re-entry from the render's own progress callback (issue 41): a
     * veil_render of this context while it renders is refused, and a
     * veil_context_destroy is deferred to the end of the render, which it
     * cancels. */
    int rendering;
    int destroy_pending;
};

/* A file the render read (the scene's file, its VDB, particle and
 * environment files): an image is never written over one (issue 41). */
typedef struct api_input {
    char field[48]; /* "the scene", "lights[0].file", ... */
    char* path;     /* owned, for messages */
    dev_t dev;
    ino_t ino;
} api_input;

struct veil_image {
    veil_image_set set;
    veil_render_stats stats;
    api_input* inputs; /* owned */
    size_t input_count;
};

#define VEIL__NULL_ARG(fn, arg) veil_fail(err, VEIL_ERR_INVALID, "%s: %s is NULL", fn, arg)

const char* veil_version(void)
{
    return VEIL_VERSION;
}

void veil_version_numbers(int* major, int* minor, int* patch)
{
    if (major) *major = VEIL_VERSION_MAJOR;
    if (minor) *minor = VEIL_VERSION_MINOR;
    if (patch) *patch = VEIL_VERSION_PATCH;
}

/* ---- the released layouts of each description ---------------------------
 * Frozen copies, one per release that changed the struct, oldest first; a
 * later veil.h only appends fields (include/veil.h, "Descriptions grow").
 * When a field is added: freeze the new layout here (larger than the one
 * before), append it to the list and point the _NEWEST name at it. */

#define VEIL__COUNT(a) ((int)(sizeof(a) / sizeof((a)[0])))

typedef struct context_desc_0_2 {
    size_t size;
    int force_software, debug;
} context_desc_0_2;
#define CONTEXT_DESC_NEWEST context_desc_0_2
static const veil__desc_layout context_desc_releases[] = {VEIL__DESC_LAYOUT(context_desc_0_2, debug)};
static const veil__desc_layouts context_desc_layouts = {"veil_context_create", "veil_context_desc",
                                                        context_desc_releases, VEIL__COUNT(context_desc_releases)};
_Static_assert(sizeof(veil_context_desc) == sizeof(CONTEXT_DESC_NEWEST),
               "veil_context_desc changed: freeze its new layout above");

typedef struct render_desc_0_2 {
    size_t size;
    int width, height;
    float step_voxels;
    uint32_t seed;
    long frame, frames;
} render_desc_0_2;
typedef struct render_desc_0_3 {
    size_t size;
    int width, height;
    float step_voxels;
    uint32_t seed;
    long frame, frames;
    veil_progress_callback progress;
    void* progress_user;
} render_desc_0_3;
#define RENDER_DESC_NEWEST render_desc_0_3
static const veil__desc_layout render_desc_releases[] = {VEIL__DESC_LAYOUT(render_desc_0_2, frames),
                                                         VEIL__DESC_LAYOUT(render_desc_0_3, progress_user)};
static const veil__desc_layouts render_desc_layouts = {"veil_render", "veil_render_desc", render_desc_releases,
                                                       VEIL__COUNT(render_desc_releases)};
_Static_assert(sizeof(veil_render_desc) == sizeof(RENDER_DESC_NEWEST),
               "veil_render_desc changed: freeze its new layout above");

typedef struct grid_desc_0_3 {
    size_t size;
    const float* data;
    int dims[3];
    int axis_order;
    double index_to_world[16];
} grid_desc_0_3;
#define GRID_DESC_NEWEST grid_desc_0_3
static const veil__desc_layout grid_desc_releases[] = {VEIL__DESC_LAYOUT(grid_desc_0_3, index_to_world)};
static const veil__desc_layouts grid_desc_layouts = {"veil_scene_set_grid", "veil_grid_desc", grid_desc_releases,
                                                     VEIL__COUNT(grid_desc_releases)};
_Static_assert(sizeof(veil_grid_desc) == sizeof(GRID_DESC_NEWEST), "veil_grid_desc changed: freeze its new layout above");

typedef struct scene_desc_0_4 {
    size_t size;
    const char *path, *json, *base_dir, *name;
    veil_progress_callback progress;
    void* progress_user;
} scene_desc_0_4;
#define SCENE_DESC_NEWEST scene_desc_0_4
static const veil__desc_layout scene_desc_releases[] = {VEIL__DESC_LAYOUT(scene_desc_0_4, progress_user)};
static const veil__desc_layouts scene_desc_layouts = {"veil_scene_create", "veil_scene_desc", scene_desc_releases,
                                                      VEIL__COUNT(scene_desc_releases)};
_Static_assert(sizeof(veil_scene_desc) == sizeof(SCENE_DESC_NEWEST),
               "veil_scene_desc changed: freeze its new layout above");

/* ---- context ------------------------------------------------------------- */

veil_result veil_context_create(const veil_context_desc* desc, veil_context** out, veil_error* err)
{
    if (!out) return VEIL__NULL_ARG("veil_context_create", "out");
    *out = NULL;
    veil_context_desc d;
    veil_result r = veil__desc_read(&context_desc_layouts, desc, &d, err);
    if (r != VEIL_OK) return r;
    veil_context* ctx = calloc(1, sizeof *ctx);
    if (!ctx) return veil_fail(err, VEIL_ERR_OOM, "veil_context_create: out of memory");
    veil_gl_desc gd = {.force_software = d.force_software != 0, .debug = d.debug != 0};
    r = veil_gl_create(&gd, &ctx->gl, err);
    if (r == VEIL_OK) r = veil_renderer_create(ctx->gl, &ctx->renderer, err);
    if (r != VEIL_OK) {
        veil_context_destroy(ctx);
        return r;
    }
    *out = ctx;
    return VEIL_OK;
}

void veil_context_destroy(veil_context* ctx)
{
    if (!ctx) return;
    if (ctx->rendering) { /* from its render's progress callback: released when veil_render returns */
        ctx->destroy_pending = 1;
        return;
    }
    /* its GL objects go while its context is current (another veil_context may have been since); a context
     * current on another thread cannot be made current here: its objects go with it, unfreed (misuse) */
    if (!ctx->gl || veil_gl_make_current(ctx->gl, NULL) == VEIL_OK) veil_renderer_destroy(ctx->renderer);
    veil_gl_destroy(ctx->gl);
    free(ctx);
}

/* ---- scene --------------------------------------------------------------- */

/* The caller's progress callback while a scene is read (veil_scene_create): every report is the stage
 * "scene", its share done kept from going back (reading a map, then cutting it: each 0..1 of itself). */
typedef struct scene_progress {
    veil_progress_callback fn;
    void* user;
    double done;
} scene_progress;

static void scene_progress_sink(void* user, const char* what, double done, double total)
{
    scene_progress* p = user;
    /* reading the files: the first quarter; cutting the environment map into lights: the rest */
    const double share = total > 0.0 ? fmin(fmax(done / total, 0.0), 1.0) : 0.0;
    const double at = strncmp(what, "cutting", 7) == 0 ? 0.25 + 0.75 * share : 0.25 * share;
    p->done = fmax(p->done, at);
    veil_progress_state saved = veil_progress_save(), none = {0};
    veil_progress_restore(&none); /* the callback may read scenes or render: to sinks of their own */
    const int stop = p->fn(p->user, "scene", p->done);
    veil_progress_restore(&saved);
    if (stop) veil_progress_cancel();
}

static veil_result scene_read(const char* fn, const char* path, const char* json, const char* base_dir,
                              const char* name, veil_progress_callback progress, void* progress_user,
                              veil_scene** out, veil_error* err)
{
    veil_scene* s = calloc(1, sizeof *s);
    if (!s) return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory", fn);
    scene_progress prog = {progress, progress_user, 0.0};
    void* old_user = NULL;
    veil_progress_fn old = progress ? veil_progress_sink(scene_progress_sink, &prog, &old_user) : NULL;
    veil_result r = path ? veil_scene_load(path, s, err)
                         : veil_scene_parse_in(name ? name : "<json>", json, json ? strlen(json) : 0, base_dir, s, err);
    if (progress) veil_progress_sink(old, old_user, NULL);
    if (r != VEIL_OK) {
        veil_scene_close(s);
        return r;
    }
    *out = s;
    return VEIL_OK;
}

veil_result veil_scene_open(const char* path, veil_scene** out, veil_error* err)
{
    if (!out) return VEIL__NULL_ARG("veil_scene_open", "out");
    *out = NULL;
    if (!path) return VEIL__NULL_ARG("veil_scene_open", "path");
    return scene_read("veil_scene_open", path, NULL, NULL, NULL, NULL, NULL, out, err);
}

veil_result veil_scene_from_json(const char* json, const char* base_dir, const char* name, veil_scene** out,
                                 veil_error* err)
{
    if (!out) return VEIL__NULL_ARG("veil_scene_from_json", "out");
    *out = NULL;
    if (!json) return VEIL__NULL_ARG("veil_scene_from_json", "json");
    return scene_read("veil_scene_from_json", NULL, json, base_dir, name, NULL, NULL, out, err);
}

veil_result veil_scene_create(const veil_scene_desc* desc, veil_scene** out, veil_error* err)
{
    if (!out) return VEIL__NULL_ARG("veil_scene_create", "out");
    *out = NULL;
    if (!desc) return VEIL__NULL_ARG("veil_scene_create", "desc");
    veil_scene_desc d;
    veil_result r = veil__desc_read(&scene_desc_layouts, desc, &d, err);
    if (r != VEIL_OK) return r;
    if (!d.path == !d.json)
        return veil_fail(err, VEIL_ERR_INVALID, "veil_scene_create: give exactly one of desc->path and desc->json "
                         "(%s)", d.path ? "both given" : "neither given");
    return scene_read("veil_scene_create", d.path, d.json, d.base_dir, d.name, d.progress, d.progress_user, out, err);
}

veil_result veil_scene_set_grid(veil_scene* scene, const char* name, const veil_grid_desc* grid, veil_error* err)
{
    if (!scene) return VEIL__NULL_ARG("veil_scene_set_grid", "scene");
    if (!name) return VEIL__NULL_ARG("veil_scene_set_grid", "name");
    if (!grid) return VEIL__NULL_ARG("veil_scene_set_grid", "grid");
    veil_grid_desc d;
    veil_result r = veil__desc_read(&grid_desc_layouts, grid, &d, err);
    if (r != VEIL_OK) return r;
    if (!d.data) return VEIL__NULL_ARG("veil_scene_set_grid", "grid->data");
    if (d.axis_order != VEIL_AXIS_ORDER_X_FASTEST && d.axis_order != VEIL_AXIS_ORDER_Z_FASTEST)
        return veil_fail(err, VEIL_ERR_INVALID, "veil_scene_set_grid: grid '%.200s': axis_order %d is neither "
                         "VEIL_AXIS_ORDER_X_FASTEST (0) nor VEIL_AXIS_ORDER_Z_FASTEST (1)", name, d.axis_order);
    double m[4][4];
    int zero = 1;
    for (int i = 0; i < 16; ++i) zero &= d.index_to_world[i] == 0.0;
    for (int i = 0; i < 16; ++i) m[i / 4][i % 4] = zero ? (i % 5 == 0 ? 1.0 : 0.0) : d.index_to_world[i];
    veil_error inner = {{0}};
    r = veil_scene_grid_set(scene, name, d.data, d.dims, d.axis_order == VEIL_AXIS_ORDER_Z_FASTEST, m, &inner);
    if (r != VEIL_OK) return veil_fail(err, r, "veil_scene_set_grid: %.1900s", inner.msg);
    return VEIL_OK;
}

void veil_scene_close(veil_scene* scene)
{
    if (!scene) return;
    veil_scene_free(scene);
    free(scene);
}

/* ---- render -------------------------------------------------------------- */

/* Notes the files scene reads, as they are now (device and inode), in
 * img: a file that does not exist (a scene from memory's name) is none. */
static veil_result note_inputs(veil_image* img, const veil_scene* scene, veil_error* err)
{
    size_t k = veil_scene_files(scene, NULL, 0);
    veil_scene_file* sf = calloc(k + 1, sizeof *sf);
    img->inputs = calloc(k + 1, sizeof *img->inputs);
    if (!sf || !img->inputs) {
        free(sf);
        return veil_fail(err, VEIL_ERR_OOM, "veil_render: out of memory");
    }
    veil_scene_files(scene, sf, k);
    if (scene->path_is_file) sf[k++] = (veil_scene_file){.field = "the scene", .path = scene->path};
    veil_result r = VEIL_OK;
    for (size_t i = 0; i < k && r == VEIL_OK; ++i) {
        char path[4096];
        struct stat st;
        veil_error inner = {{0}};
        /* a sequence: veil_render reads frame 1's file (veil_scene_set_frame is the CLI's) */
        if (veil_scene_file_at(&sf[i], 1, path, sizeof path, &inner) != VEIL_OK || stat(path, &st) != 0) continue;
        api_input* in = &img->inputs[img->input_count];
        memcpy(in->field, sf[i].field, sizeof in->field);
        in->dev = st.st_dev, in->ino = st.st_ino;
        if (!(in->path = malloc(strlen(path) + 1))) r = veil_fail(err, VEIL_ERR_OOM, "veil_render: out of memory");
        else strcpy(in->path, path), img->input_count++;
    }
    free(sf);
    return r;
}

/* VEIL_ERR_INVALID when path is (or links to) a file the render read. */
static veil_result check_not_input(const veil_image* img, const char* fn, const char* path, veil_error* err)
{
    struct stat st;
    if (stat(path, &st) != 0) return VEIL_OK; /* not there: nothing of the render's can be lost */
    for (size_t i = 0; i < img->input_count; ++i)
        if (img->inputs[i].dev == st.st_dev && img->inputs[i].ino == st.st_ino)
            return veil_fail(err, VEIL_ERR_INVALID, "%s: '%.900s' is %s '%.900s', which the render read: it would "
                             "be overwritten", fn, path, img->inputs[i].field, img->inputs[i].path);
    return VEIL_OK;
}


static veil_result check_render_desc(const veil_render_desc* d, veil_error* err)
{
    if (d->width < 0 || d->height < 0 || d->width > VEIL_SCENE_MAX_IMAGE || d->height > VEIL_SCENE_MAX_IMAGE)
        return veil_fail(err, VEIL_ERR_INVALID, "veil_render: image size %dx%d is outside 1..%d (0: the scene's)",
                         d->width, d->height, VEIL_SCENE_MAX_IMAGE);
    if (!(d->step_voxels >= 0.0f) || !isfinite(d->step_voxels))
        return veil_fail(err, VEIL_ERR_INVALID, "veil_render: step_voxels %g is not a finite value >= 0 (0: default)",
                         (double)d->step_voxels);
    if (d->frames < 0)
        return veil_fail(err, VEIL_ERR_INVALID, "veil_render: frames %ld is negative", d->frames);
    long n = d->frames > 1 ? d->frames : 1;
    if (d->frame < 0 || d->frame >= n)
        return veil_fail(err, VEIL_ERR_INVALID, "veil_render: frame %ld is outside 0..%ld (frames %ld)", d->frame,
                         n - 1, d->frames);
    return VEIL_OK;
}

/* The caller's progress callback behind the pipeline's progress sink
 * (core/progress.h): the internal reports ("march, rows", 120 of 480) become
 * the stage's share done; a stage's end is reported as 1 when the next
 * begins (and the last when the render returns). */
typedef struct api_progress {
    veil_progress_callback fn;
    void* user;
    const char* stage; /* the stage last reported */
    veil_context* ctx; /* the rendering context, made current again after each call */
} api_progress;

static void api_progress_tell(api_progress* p, const char* stage, double done)
{
    /* the callback may render with another context on this thread, make one or destroy one: the thread's
     * progress state and current GL context are this render's again when it returns (issue 41) */
    veil_progress_state saved = veil_progress_save(), none = {0};
    veil_progress_restore(&none); /* a render inside the callback reports to its own sink, or to none */
    int stop = p->fn(p->user, stage, done);
    veil_progress_restore(&saved);
    if (veil_gl_make_current(p->ctx->gl, NULL) != VEIL_OK) stop = 1; /* the next GL call would fail: stop */
    if (stop || p->ctx->destroy_pending) veil_progress_cancel();
}

static void api_progress_sink(void* user, const char* what, double done, double total)
{
    (void)what;
    api_progress* p = user;
    const char* stage = veil_progress_stage();
    if (!stage) { /* after the stages (a deep image merged): the last stage, done, so that it can still cancel */
        if (p->stage) api_progress_tell(p, p->stage, 1.0);
        return;
    }
    if (p->stage && p->stage != stage) api_progress_tell(p, p->stage, 1.0);
    p->stage = stage;
    double share = total > 0.0 ? done / total : 0.0;
    api_progress_tell(p, stage, share < 0.0 ? 0.0 : share > 1.0 ? 1.0 : share);
}

veil_result veil_render(veil_context* ctx, const veil_scene* scene, const veil_render_desc* desc, veil_image** out,
                        veil_error* err)
{
    if (!out) return VEIL__NULL_ARG("veil_render", "out");
    *out = NULL;
    if (!ctx) return VEIL__NULL_ARG("veil_render", "ctx");
    if (!scene) return VEIL__NULL_ARG("veil_render", "scene");
    if (ctx->rendering)
        return veil_fail(err, VEIL_ERR_INVALID, "veil_render: the context is rendering already (this call came from "
                         "its render's progress callback): render with another veil_context, or after veil_render "
                         "returns");
    veil_render_desc d;
    veil_result r = veil__desc_read(&render_desc_layouts, desc, &d, err);
    if (r == VEIL_OK) r = check_render_desc(&d, err);
    /* one thread may hold several contexts: each call makes its own current (issue 22) */
    if (r == VEIL_OK) r = veil_gl_make_current(ctx->gl, err);
    if (r != VEIL_OK) return r;

    veil_image* img = calloc(1, sizeof *img);
    if (!img) return veil_fail(err, VEIL_ERR_OOM, "veil_render: out of memory");
    veil_camera cam = veil_camera_of_frame(&scene->camera, d.frame, d.frames);
    veil_render_opts opts = {.width = d.width, .height = d.height, .step_voxels = d.step_voxels,
                             .seed = d.seed, .camera = &cam};
    api_progress prog = {d.progress, d.progress_user, NULL, ctx};
    void* old_user = NULL;
    veil_progress_fn old = d.progress ? veil_progress_sink(api_progress_sink, &prog, &old_user) : NULL;
    ctx->rendering = 1;
    r = veil_render_scene_images(ctx->renderer, scene, &opts, &img->set, &img->stats, err);
    if (d.progress) {
        if (r == VEIL_OK && prog.stage) api_progress_tell(&prog, prog.stage, 1.0);
        if (r == VEIL_OK && veil_progress_cancelled()) /* asked for by the last report: nothing is returned */
            r = veil_fail(err, VEIL_ERR_CANCELLED, "cancelled by the progress callback as the render ended");
        veil_progress_sink(old, old_user, NULL);
    }
    ctx->rendering = 0;
    if (ctx->destroy_pending) { /* destroyed by its progress callback: the render stopped, and the context goes */
        r = veil_fail(err, VEIL_ERR_INVALID, "veil_render: the progress callback destroyed the rendering context: the "
                      "render was cancelled and the context is released now (destroy a context after its "
                      "veil_render returns)");
        veil_context_destroy(ctx);
    }
    if (r == VEIL_OK) r = note_inputs(img, scene, err);
    if (r != VEIL_OK) {
        veil_image_destroy(img);
        return r;
    }
    *out = img;
    return VEIL_OK;
}

/* ---- image --------------------------------------------------------------- */

void veil_image_size(const veil_image* img, int* width, int* height)
{
    if (width) *width = img ? img->set.width : 0;
    if (height) *height = img ? img->set.height : 0;
}

const float* veil_image_rgba(const veil_image* img)
{
    return img ? img->set.rgba : NULL;
}

veil_result veil_image_channel(const veil_image* img, const char* name, float* out, veil_error* err)
{
    if (!img) return VEIL__NULL_ARG("veil_image_channel", "img");
    if (!name) return VEIL__NULL_ARG("veil_image_channel", "name");
    if (!out) return VEIL__NULL_ARG("veil_image_channel", "out");
    for (int c = 0; c < VEIL_IMAGE_SET_CHANNELS; ++c) {
        if (!strcmp(name, veil_image_set_channel_names[c])) {
            veil_image_set_plane(&img->set, c, out);
            return VEIL_OK;
        }
    }
    char list[256] = "";
    size_t len = 0;
    for (int c = 0; c < VEIL_IMAGE_SET_CHANNELS && len < sizeof list; ++c) {
        int n = snprintf(list + len, sizeof list - len, "%s%s", c ? ", " : "", veil_image_set_channel_names[c]);
        if (n < 0) break;
        len += (size_t)n;
    }
    return veil_fail(err, VEIL_ERR_INVALID, "veil_image_channel: no channel '%.64s'; the channels are %s", name, list);
}

veil_result veil_image_write_exr(const veil_image* img, const char* path, int aovs, veil_error* err)
{
    if (!img) return VEIL__NULL_ARG("veil_image_write_exr", "img");
    if (!path) return VEIL__NULL_ARG("veil_image_write_exr", "path");
    veil_result r = check_not_input(img, "veil_image_write_exr", path, err);
    if (r != VEIL_OK) return r;
    return veil_image_set_write_exr(&img->set, path, aovs, err);
}

veil_result veil_image_write_exr_as(const veil_image* img, const char* path, int aovs, const char* type,
                                    const char* compression, veil_error* err)
{
    if (!img) return VEIL__NULL_ARG("veil_image_write_exr_as", "img");
    if (!path) return VEIL__NULL_ARG("veil_image_write_exr_as", "path");
    veil_exr_meta meta = {0};
    if (type && strcmp(type, "float") && strcmp(type, "half"))
        return veil_fail(err, VEIL_ERR_INVALID, "veil_image_write_exr_as: type '%.32s': expected \"float\" or \"half\"",
                         type);
    meta.format.half = type && !strcmp(type, "half");
    if (compression) {
        meta.format.compression = veil_exr_compression_parse(compression);
        if (meta.format.compression <= 0)
            return veil_fail(err, VEIL_ERR_INVALID, "veil_image_write_exr_as: compression '%.32s': expected zip, none, "
                             "rle, zips, piz, pxr24, b44, b44a, dwaa or dwab", compression);
    }
    veil_result r = check_not_input(img, "veil_image_write_exr_as", path, err);
    if (r != VEIL_OK) return r;
    return veil_image_set_write_exr_meta(&img->set, path, aovs, &meta, err);
}

veil_result veil_image_write_png(const veil_image* img, const char* path, float exposure, veil_error* err)
{
    if (!img) return VEIL__NULL_ARG("veil_image_write_png", "img");
    if (!path) return VEIL__NULL_ARG("veil_image_write_png", "path");
    if (!isfinite(exposure))
        return veil_fail(err, VEIL_ERR_INVALID, "veil_image_write_png: exposure %g is not finite", (double)exposure);
    veil_result r = check_not_input(img, "veil_image_write_png", path, err);
    if (r != VEIL_OK) return r;
    return veil_write_png(path, img->set.width, img->set.height, img->set.rgba, exposure, err);
}

int veil_image_stage_count(const veil_image* img)
{
    return img ? VEIL_STAGE_COUNT : 0;
}

veil_result veil_image_stage(const veil_image* img, int i, const char** name, const char** status, double* ms,
                             const char** why)
{
    if (!img || i < 0 || i >= VEIL_STAGE_COUNT) return VEIL_ERR_INVALID;
    const veil_stage_report* rep = &img->stats.stage[i];
    if (name) *name = veil_stage_name((veil_stage_id)i);
    if (status) *status = veil_stage_status_name(rep->status);
    if (ms) *ms = rep->ms;
    if (why) *why = rep->why;
    return VEIL_OK;
}

void veil_image_destroy(veil_image* img)
{
    if (!img) return;
    veil_image_set_free(&img->set);
    for (size_t i = 0; i < img->input_count; ++i) free(img->inputs[i].path);
    free(img->inputs);
    free(img);
}
