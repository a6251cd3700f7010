#include "march.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>
#include <string.h>

#include "../core/clock.h"
#include "../core/progress.h"
#include "../gpu/gl_util.h"
#include "../gpu/programs.h"
#include "../scene/camera.h"

/* The march's programs: march.comp with defines for what llvmpipe would otherwise pay for in every
 * sample, since it runs both sides of each branch it cannot fold, texture reads included:
 * VEIL_SPARSE (a sparse volume), VEIL_MARCH_EMISSION (the volume glows), VEIL_SOLID (a frame's surfaces
 * shadow the lights: scene/solid.h), VEIL_MARCH_FIELD (the field u_phi holds: a VEIL_FIELD_*),
 * VEIL_MARCH_GATHER (the cache's later light gathered), and for a large frame VEIL_LIGHT_LIST (the
 * lights, each one's kind and light-space grid: VEIL_MARCH_LIGHT_LIST_WORK). A loop over the lights
 * that read each one's kind and grid from the medium's block paid for a sun's grid lookup and its
 * stretch of density in every light's every sample: 1.35x the demo's march (docs/performance.md).
 * Programs are made when first needed and the last MARCH_PROGRAMS kept, keyed by their defines (a
 * turntable's frames share one). */
enum { MARCH_PROGRAMS = 12 };

typedef struct {
    GLuint program;
    char defines[VEIL_MAX_LIGHTS * 24 + 224];
} march_program;

struct veil_march {
    march_program programs[MARCH_PROGRAMS];
    int next; /* the slot a new program takes (the oldest) */
    GLuint ubo, medium_ubo;
    GLuint gather[4]; /* render/shaders/cache_gather.comp, at 2 sparse + solid; made when first needed */
    veil_march_gather last_gather;
    GLuint images[VEIL_MARCH_IMAGES]; /* the march's images, kept for the next frame of the same size */
    int images_w, images_h;
    veil_march_readback last_readback;
};

veil_march_gather veil_march_last_gather(const veil_march* m) { return m->last_gather; }
veil_march_readback veil_march_last_readback(const veil_march* m) { return m->last_readback; }

void veil_march_images(const veil_march* m, unsigned int out[VEIL_MARCH_IMAGES])
{
    for (int i = 0; i < VEIL_MARCH_IMAGES; ++i) out[i] = m->images[i];
}

static veil_result gather_variant(veil_march* m, int v, veil_error* err)
{
    if (m->gather[v]) return VEIL_OK;
    static const char* const defines[4] = {"", "#define VEIL_SOLID 1\n", "#define VEIL_SPARSE 1\n",
                                           "#define VEIL_SPARSE 1\n#define VEIL_SOLID 1\n"};
    static const char* const names[4] = {"dense", "solid", "sparse", "sparse, solid"};
    return veil_gpu_program_variant("render/shaders/cache_gather.comp", defines[v], names[v], &m->gather[v], err);
}

/* Appends to a fixed buffer (march_program's is sized for the longest list). */
static void append(char* dst, size_t cap, const char* fmt, int a, int b, int c)
{
    size_t n = strlen(dst);
    if (n < cap) snprintf(dst + n, cap - n, fmt, a, b, c);
}

/* The march's program for this frame: the medium's block mu, the march's u, the lights compiled in
 * or not. */
static veil_result program_for(veil_march* m, const veil_lit_medium* lm, const veil_medium_block* mu,
                               const veil_march_block* u, int light_list, int deep_raw, GLuint* out, veil_error* err)
{
    march_program want;
    memset(&want, 0, sizeof want);
    const size_t cap = sizeof want.defines;
    char name[96] = "";
    if (lm->grid && lm->sparse) append(want.defines, cap, "#define VEIL_SPARSE 1\n", 0, 0, 0), strcat(name, "sparse, ");
    if (lm->grid && lm->emission)
        append(want.defines, cap, "#define VEIL_MARCH_EMISSION 1\n", 0, 0, 0), strcat(name, "emission, ");
    if (mu->solid_origin[3] > 0.0f) append(want.defines, cap, "#define VEIL_SOLID 1\n", 0, 0, 0), strcat(name, "solid, ");
    if (deep_raw > 0) /* the deep samples (render/deep.h): R a pixel */
        append(want.defines, cap, "#define VEIL_MARCH_DEEP %d\n", deep_raw, 0, 0), strcat(name, "deep, ");
    if (light_list) { /* and the field with them (march.comp says why not apart) */
        const int field = (int)u->diffusion[3];
        append(want.defines, cap, "#define VEIL_MARCH_FIELD %d\n#define VEIL_MARCH_GATHER %d\n", field, u->march[1] > 0.0f, 0);
        if (field == VEIL_FIELD_CACHE && u->octave[3] > 1.0f) /* a cache of the first scattering alone: octaves too */
            append(want.defines, cap, "#define VEIL_MARCH_OCTAVES 1\n", 0, 0, 0), strcat(name, "octaves, ");
        snprintf(name + strlen(name), sizeof name - strlen(name), "field %d%s, ", field, u->march[1] > 0.0f ? ", gathered" : "");
        append(want.defines, cap, "#define VEIL_LIGHT_LIST", 0, 0, 0);
        for (int l = 0; l < mu->counts[0] && l < VEIL_MAX_LIGHTS; ++l)
            append(want.defines, cap, " VEIL_LIGHT(%d, %d, %d)", l, (int)mu->lights[l].position[3],
                   mu->sun_of[l / 4][l % 4] - 1);
        append(want.defines, cap, "\n", 0, 0, 0);
        snprintf(name + strlen(name), sizeof name - strlen(name), "%d lights compiled in", mu->counts[0]);
    }
    for (int i = 0; i < MARCH_PROGRAMS; ++i)
        if (m->programs[i].program && strcmp(m->programs[i].defines, want.defines) == 0) {
            *out = m->programs[i].program;
            return VEIL_OK;
        }
    veil_result r = veil_gpu_program_variant("render/shaders/march.comp", want.defines, name, &want.program, err);
    if (r != VEIL_OK) return r;
    march_program* slot = &m->programs[m->next];
    m->next = (m->next + 1) % MARCH_PROGRAMS;
    glDeleteProgram(slot->program);
    *slot = want;
    *out = want.program;
    return VEIL_OK;
}

veil_result veil_march_create(veil_march** out, veil_error* err)
{
    *out = NULL;
    veil_march* m = calloc(1, sizeof *m);
    if (!m) return veil_fail(err, VEIL_ERR_OOM, "out of memory creating the ray marcher");
    veil_result r = veil_gl_buffer(NULL, sizeof(veil_march_block), GL_DYNAMIC_STORAGE_BIT, "veil march block", &m->ubo, err);
    if (r == VEIL_OK)
        r = veil_gl_buffer(NULL, sizeof(veil_medium_block), GL_DYNAMIC_STORAGE_BIT, "veil march medium block",
                           &m->medium_ubo, err);
    if (r != VEIL_OK) {
        veil_march_destroy(m);
        return r;
    }
    *out = m;
    return VEIL_OK;
}

void veil_march_destroy(veil_march* m)
{
    if (!m) return;
    for (int i = 0; i < MARCH_PROGRAMS; ++i) glDeleteProgram(m->programs[i].program);
    for (int v = 0; v < 4; ++v) glDeleteProgram(m->gather[v]);
    glDeleteTextures(VEIL_MARCH_IMAGES, m->images);
    glDeleteBuffers(1, &m->ubo);
    glDeleteBuffers(1, &m->medium_ubo);
    free(m);
}

static void set3(float dst[4], const float src[3], float w)
{
    dst[0] = src[0], dst[1] = src[1], dst[2] = src[2], dst[3] = w;
}

static int sees_environment(const veil_scene* s) { return s->environment.present && !s->background_set; }

veil_result veil_march_block_fill(const veil_march_desc* d, veil_march_block* u, veil_error* err)
{
    veil_camera_basis cam;
    veil_result r = veil_camera_make_basis(d->camera, d->width, d->height, &cam, err);
    if (r != VEIL_OK) return r;
    memset(u, 0, sizeof *u);
    const veil_lit_medium* lm = &d->medium;
    set3(u->cam_pos, cam.pos, 0.0f);
    set3(u->cam_fwd, cam.center, 0.0f);
    set3(u->cam_right, cam.right, cam.clip[0]);
    set3(u->cam_up, cam.up, isfinite(cam.clip[1]) ? cam.clip[1] : FLT_MAX);
    /* an environment is seen behind the medium (added after the march, environment_behind), unless the scene
     * gives a background of its own */
    if (!d->no_background && !sees_environment(lm->scene)) set3(u->background, lm->scene->background, 0.0f);
    u->march[0] = lm->grid ? d->step_voxels * lm->grid->voxel : VEIL_FOG_MIN_STEP;
    u->limits[0] = d->max_distance > 0.0f ? d->max_distance : 3.0e38f;
    int fogs = 0;
    for (size_t i = 0; i < lm->scene->medium.source_count; ++i)
        fogs += lm->scene->medium.sources[i].type == VEIL_SOURCE_EXPONENTIAL;
    u->size[0] = d->width, u->size[1] = d->height;
    /* empty bricks hold no density but may glow: no skipping with emission (a sparse volume's bricks
     * not kept hold neither) */
    u->flags[1] = lm->grid != NULL && fogs == 0 && d->skip_empty && (!lm->emission || lm->sparse);
    u->flags[2] = d->seed;
    u->flags[3] = d->end_distance != NULL;
    const veil_multiple* ms = &lm->scene->multiple;
    if (d->field && d->field->texture) {
        set3(u->diffusion, d->field->tex_min, (float)d->field->kind);
        set3(u->diffusion_inv, d->field->tex_inv, (float)d->field->depth);
        if (d->field->kind == VEIL_FIELD_CACHE && d->gather_rays > 0 && d->field->depth > 0) {
            /* the gather's grid (gather_cells, else VEIL_GATHER_MAX_CELLS): cubes of s of the cache's cells */
            GLint n[3] = {0, 0, d->field->depth};
            glGetTextureLevelParameteriv(d->field->texture, 0, GL_TEXTURE_WIDTH, &n[0]);
            glGetTextureLevelParameteriv(d->field->texture, 0, GL_TEXTURE_HEIGHT, &n[1]);
            const int longest = n[0] > n[1] ? (n[0] > n[2] ? n[0] : n[2]) : (n[1] > n[2] ? n[1] : n[2]);
            u->march[1] = (float)d->gather_rays;
            u->march[2] = d->gather_step > 0.0f ? d->gather_step : 1.0f;
            /* a grid of G cells along the longest side, each s = longest / G of the cache's cells a side (s >= 1),
             * and ceil(n / s) = ceil(n G / longest) cells along a side of n (the shaders read these counts) */
            const int G = d->gather_cells > 0 ? d->gather_cells : VEIL_GATHER_MAX_CELLS;
            const int gc = longest > G ? G : longest;
            u->march[3] = (float)longest / (float)gc;
            for (int a = 0; a < 3; ++a) u->limits[1 + a] = (float)((n[a] * gc + longest - 1) / longest);
        }
    }
    /* the octaves: asked for, or in place of a light cache that could not be made (a fog box too wide for
     * its grid, a medium too thick for photons): gated by the legs then (no escape field) */
    const int no_cache = ms->volumetric_method == VEIL_VOLUMETRIC_CACHE &&
                         !(d->field && d->field->texture && d->field->kind == VEIL_FIELD_CACHE && !d->field->first_only);
    if (ms->volumetric && (ms->volumetric_method == VEIL_VOLUMETRIC_OCTAVE || no_cache) && ms->octaves > 1) {
        u->octave[0] = ms->octave_a, u->octave[1] = ms->octave_b, u->octave[2] = ms->octave_c;
        u->octave[3] = (float)ms->octaves;
    }
    return VEIL_OK;
}

static veil_result image(int w, int h, const char* label, GLuint* tex, veil_error* err)
{
    glCreateTextures(GL_TEXTURE_2D, 1, tex);
    glTextureStorage2D(*tex, 1, GL_RGBA32F, w, h);
    glObjectLabel(GL_TEXTURE, *tex, -1, label);
    return veil_gl_check(label, err);
}

/* ---- the frame's size (veil_march_check_size) ---------------------------------------------------- */

typedef struct size_need {
    int driver;          /* 1: the driver holds an rgba32f texture of w x h (a proxy texture) */
    double gpu, host;    /* bytes */
} size_need;

static size_need need_of(int w, int h, int spread)
{
    size_need n;
    glTexImage2D(GL_PROXY_TEXTURE_2D, 0, GL_RGBA32F, w, h, 0, GL_RGBA, GL_FLOAT, NULL);
    GLint got = 0;
    glGetTexLevelParameteriv(GL_PROXY_TEXTURE_2D, 0, GL_TEXTURE_WIDTH, &got);
    n.driver = got == w;
    const double px = (double)w * (double)h;
    n.gpu = px * 16.0 * (spread ? VEIL_SPREAD_IMAGES : VEIL_MARCH_IMAGES); /* the spread's after the march's */
    n.host = px * VEIL_IMAGE_HOST_BYTES;
    return n;
}

static double physical_memory(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    return pages > 0 && page > 0 ? (double)pages * (double)page : 1e30;
}

static void clear_gl_errors(void)
{
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) {
    }
}

static int fits(size_need n, int hardware, double gpu_budget, double host)
{
    return n.driver && n.gpu <= gpu_budget && n.host + (hardware ? 0.0 : n.gpu) <= host;
}

veil_result veil_march_check_size(int w, int h, int spread, int hardware, unsigned long long gpu_budget,
                                  veil_error* err)
{
    const double host = physical_memory(), budget = gpu_budget ? (double)gpu_budget : 1e30;
    const size_need n = need_of(w, h, spread);
    clear_gl_errors(); /* a proxy that is refused sets no error; one over GL_MAX_TEXTURE_SIZE may */
    if (fits(n, hardware, budget, host)) return VEIL_OK;
    /* the largest frame of this shape that fits: scale s in (0, 1), bisected on the proxy and the bytes */
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < 20; ++i) {
        const double s = 0.5 * (lo + hi);
        const int sw = (int)(w * s), sh = (int)(h * s);
        if (sw >= 1 && sh >= 1 && fits(need_of(sw, sh, spread), hardware, budget, host)) lo = s;
        else hi = s;
    }
    clear_gl_errors();
    const int bw = (int)(w * lo), bh = (int)(h * lo);
    char why[512];
    if (!n.driver)
        snprintf(why, sizeof why, "the GL driver (%s) holds no rgba32f texture of %dx%d (%.3g GB; a proxy texture "
                 "says so)", (const char*)glGetString(GL_RENDERER), w, h, (double)w * h * 16.0 / 1e9);
    else if (n.gpu > budget)
        snprintf(why, sizeof why, "its %d rgba32f textures take %.3g GB, over the %.3g GB veil allows itself on this "
                 "device (veil_gl_info's memory budget)", spread ? VEIL_SPREAD_IMAGES : VEIL_MARCH_IMAGES, n.gpu / 1e9,
                 budget / 1e9);
    else
        snprintf(why, sizeof why, "its buffers take %.3g GB of memory%s, over the machine's %.3g GB", n.host / 1e9,
                 hardware ? "" : " (the textures' included: a software rasteriser's live there)",
                 host / 1e9);
    if (bw >= 1 && bh >= 1)
        return veil_fail(err, VEIL_ERR_LIMIT, "a %dx%d image: %s; the largest image of this shape this device "
                         "renders is %dx%d", w, h, why, bw, bh);
    return veil_fail(err, VEIL_ERR_LIMIT, "a %dx%d image: %s", w, h, why);
}

static uint64_t g_band_work = 0, g_light_list_work = VEIL_MARCH_LIGHT_LIST_WORK; /* g_band_work 0: the desc's */

void veil_march_set_dispatch_work(uint64_t work) { g_band_work = work; }

void veil_march_set_light_list_work(uint64_t work) { g_light_list_work = work ? work : VEIL_MARCH_LIGHT_LIST_WORK; }

/* The work of one row of w pixels: w x steps a ray x (1 + lights) (VEIL_MARCH_DISPATCH_WORK). */
static double row_work(const veil_march_desc* d, int w)
{
    double steps = 1.0;
    const veil_lit_medium* lm = &d->medium;
    if (lm->grid) {
        float lo[3], hi[3];
        veil_grid_medium_box(lm->grid, lo, hi);
        const double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
        steps += sqrt(dx * dx + dy * dy + dz * dz) / ((double)d->step_voxels * lm->grid->voxel);
    }
    for (size_t i = 0; i < lm->scene->medium.source_count; ++i) {
        const veil_source* src = &lm->scene->medium.sources[i];
        if (src->type != VEIL_SOURCE_EXPONENTIAL) continue;
        steps += 64.0; /* steps growing by VEIL_FOG_STEP_FRACTION of the distance */
        /* and near each point or spot light inside it, steps of a quarter of the distance to it */
        for (int l = 0; l < lm->light_count; ++l) {
            const veil_light* li = &lm->lights[l];
            int inside = li->type != VEIL_LIGHT_DIRECTIONAL;
            for (int a = 0; a < 3 && inside; ++a)
                inside = li->position[a] >= src->fog.bounds[0][a] && li->position[a] <= src->fog.bounds[1][a];
            if (inside) steps += 64.0;
        }
    }
    return (double)w * steps * (1.0 + lm->light_count);
}

int veil_march_band_rows(const veil_march_desc* d, int w, int h)
{
    const double per_row = row_work(d, w);
    const uint64_t work = g_band_work ? g_band_work : d->band_work ? d->band_work : VEIL_MARCH_DISPATCH_WORK;
    double rows = floor((double)work / per_row / VEIL_MARCH_GROUP) * VEIL_MARCH_GROUP;
    if (rows < VEIL_MARCH_GROUP) rows = VEIL_MARCH_GROUP;
    return rows >= h ? h : (int)rows;
}

/* The image set's Z (render/image_set.h): the depth AOV, a distance along each pixel's ray, as a depth
 * along the view axis (distance x the cosine of the pixel's ray to the axis: the camera's own rays,
 * lens shift included), +infinity where the ray meets no medium (depth 0). */
static veil_result planar_depth(const veil_march_desc* d, veil_image_set* out, veil_error* err)
{
    veil_camera_basis b;
    veil_result r = veil_camera_make_basis(d->camera, d->width, d->height, &b, err);
    if (r != VEIL_OK) return r;
    size_t n = (size_t)d->width * (size_t)d->height;
    out->aov_z = malloc(n * sizeof *out->aov_z);
    if (!out->aov_z) return veil_fail(err, VEIL_ERR_OOM, "out of memory for a %dx%d depth plane", d->width, d->height);
    for (int py = 0; py < d->height; ++py)
        for (int px = 0; px < d->width; ++px) {
            float dir[3];
            veil_camera_ray(&b, d->width, d->height, px, py, dir);
            double c = (double)dir[0] * b.fwd[0] + (double)dir[1] * b.fwd[1] + (double)dir[2] * b.fwd[2];
            size_t i = (size_t)py * (size_t)d->width + (size_t)px;
            float dist = out->aov_s[4 * i + 3];
            out->aov_z[i] = dist > 0.0f ? (float)(dist * c) : INFINITY;
        }
    return VEIL_OK;
}

/* The environment seen through the medium: T times its radiance along each pixel's ray (the march added no
 * background). On the CPU, after the read-back: the map is piecewise constant and looked up once a pixel. */
static veil_result environment_behind(const veil_march_desc* d, veil_image_set* out, veil_error* err)
{
    veil_camera_basis b;
    veil_result r = veil_camera_make_basis(d->camera, d->width, d->height, &b, err);
    if (r != VEIL_OK) return r;
    const veil_environment* env = &d->medium.scene->environment;
    out->behind = malloc((size_t)d->width * (size_t)d->height * 3 * sizeof *out->behind);
    if (!out->behind) return veil_fail(err, VEIL_ERR_OOM, "out of memory for a %dx%d environment plane", d->width, d->height);
    for (int py = 0; py < d->height; ++py)
        for (int px = 0; px < d->width; ++px) {
            float dir[3];
            veil_camera_ray(&b, d->width, d->height, px, py, dir);
            double n = sqrt((double)dir[0] * dir[0] + (double)dir[1] * dir[1] + (double)dir[2] * dir[2]), e[3];
            double dd[3] = {dir[0] / n, dir[1] / n, dir[2] / n};
            veil_env_radiance(env, dd, e);
            size_t i = (size_t)py * (size_t)d->width + (size_t)px;
            for (int k = 0; k < 3; ++k) {
                out->behind[3 * i + k] = (float)e[k];
                out->rgba[4 * i + k] += out->aov_t[4 * i + k] * out->behind[3 * i + k];
            }
        }
    return VEIL_OK;
}

veil_result veil_march_run(veil_march* m, const veil_march_desc* d, veil_image_set* out, veil_error* err)
{
    veil_image_set_free(out);
    veil_march_block u;
    veil_result r = veil_march_block_fill(d, &u, err);
    if (r != VEIL_OK) return r;
    veil_medium_block mu;
    const veil_lit_medium* lm = &d->medium;
    veil_lit_medium_fill(lm, &mu);
    int w = d->width, h = d->height;
    size_t floats;
    if (!veil_mul_sizes((size_t)w, (size_t)h, 4, 1, &floats)) return veil_fail(err, VEIL_ERR_LIMIT, "image too large");
    enum { N = VEIL_MARCH_IMAGES };
    static const char* const labels[N] = {"veil image", "veil image T, P", "veil image single, depth",
                                          "veil image volumetric", "veil image out-scattered single"};
    static const GLuint units[N] = {VEIL_IMAGE_OUT, VEIL_IMAGE_AOV_T, VEIL_IMAGE_AOV_S, VEIL_IMAGE_AOV_V,
                                    VEIL_IMAGE_AOV_Q};
    /* the images, made once per size: every pixel of each is written by every march */
    memset(&m->last_readback, 0, sizeof m->last_readback);
    if (m->images_w != w || m->images_h != h || !m->images[0]) {
        glDeleteTextures(N, m->images);
        memset(m->images, 0, sizeof m->images);
        m->images_w = m->images_h = 0;
        for (int i = 0; i < N && r == VEIL_OK; ++i) r = image(w, h, labels[i], &m->images[i], err);
        if (r != VEIL_OK) {
            glDeleteTextures(N, m->images);
            memset(m->images, 0, sizeof m->images);
        } else {
            m->images_w = w, m->images_h = h, m->last_readback.made = 1;
        }
    }
    const GLuint* tex = m->images;
    /* what is read back: rgba always; the others unless the caller said it needs them not (T for the
     * environment behind this function adds, S for Z) */
    const int env = !d->no_background && sees_environment(lm->scene);
    int read[N] = {1, !(d->skip_reads & VEIL_MARCH_READ_T) || env, !(d->skip_reads & VEIL_MARCH_READ_S),
                   !(d->skip_reads & VEIL_MARCH_READ_V), !(d->skip_reads & VEIL_MARCH_READ_Q)};
    GLuint limit = 0;
    if (r == VEIL_OK && d->end_distance) {
        glCreateTextures(GL_TEXTURE_2D, 1, &limit);
        glTextureStorage2D(limit, 1, GL_R32F, w, h);
        glTextureSubImage2D(limit, 0, 0, 0, w, h, GL_RED, GL_FLOAT, d->end_distance);
        glObjectLabel(GL_TEXTURE, limit, -1, "veil ray ends");
        r = veil_gl_check("veil ray ends", err);
    }
    float** dst[N] = {&out->rgba, &out->aov_t, &out->aov_s, &out->aov_v, &out->aov_q};
    for (int i = 0; i < N && r == VEIL_OK; ++i) {
        if (!read[i]) continue;
        *dst[i] = malloc(floats * sizeof(float));
        if (!*dst[i]) r = veil_fail(err, VEIL_ERR_OOM, "out of memory for a %dx%d image", w, h);
    }
    if (r == VEIL_OK) {
        out->width = w, out->height = h;
        glNamedBufferSubData(m->ubo, 0, sizeof u, &u);
        glNamedBufferSubData(m->medium_ubo, 0, sizeof mu, &mu);
    }
    GLuint program = 0;
    const int light_list = row_work(d, w) * h >= (double)g_light_list_work;
    if (r == VEIL_OK) r = program_for(m, lm, &mu, &u, light_list, d->deep_raw, &program, err);
    /* deep: a band's buffers (counts, R samples a pixel) within VEIL_DEEP_BAND_BYTES, read after each band */
    /* bands: without a progress sink no cancel can come and a dispatch's own bound serves; with one, the
     * desc's (a software rasteriser's shorter bands), sized anew after each to take band_seconds */
    const int report = veil_progress_wanted(), adapt = report && d->band_seconds > 0.0 && !g_band_work;
    veil_march_desc bands = *d;
    if (!report) bands.band_work = VEIL_MARCH_DISPATCH_WORK;
    int band = veil_march_band_rows(&bands, w, h), band_cap = h;
    GLuint deep_buf[2] = {0, 0};
    uint32_t* deep_counts = NULL;
    float* deep_samples = NULL;
    size_t deep_row_floats = (size_t)w * (size_t)(d->deep_raw > 0 ? d->deep_raw : 0) * VEIL_DEEP_CHANNELS;
    if (r == VEIL_OK && d->deep_raw > 0) {
        const size_t row_bytes = (size_t)w * (sizeof(uint32_t) + (size_t)d->deep_raw * VEIL_DEEP_CHANNELS * sizeof(float));
        size_t rows = VEIL_DEEP_BAND_BYTES / row_bytes / VEIL_MARCH_GROUP * VEIL_MARCH_GROUP;
        if (rows < VEIL_MARCH_GROUP) rows = VEIL_MARCH_GROUP;
        if ((size_t)band > rows) band = (int)rows;
        if ((size_t)band_cap > rows) band_cap = (int)rows;
        out->deep.width = w, out->deep.height = h;
        deep_counts = malloc((size_t)band_cap * (size_t)w * sizeof *deep_counts);
        deep_samples = malloc((size_t)band_cap * deep_row_floats * sizeof *deep_samples);
        if (!deep_counts || !deep_samples) r = veil_fail(err, VEIL_ERR_OOM, "out of memory for a band of deep samples");
        if (r == VEIL_OK)
            r = veil_gl_buffer(NULL, (size_t)band_cap * (size_t)w * sizeof(uint32_t), GL_DYNAMIC_STORAGE_BIT,
                               "veil deep counts", &deep_buf[0], err);
        if (r == VEIL_OK)
            r = veil_gl_buffer(NULL, (size_t)band_cap * deep_row_floats * sizeof(float), GL_DYNAMIC_STORAGE_BIT,
                               "veil deep samples", &deep_buf[1], err);
    }
    if (r == VEIL_OK) {
        glUseProgram(program);
        veil_ev_sparse_bind(lm->grid ? lm->sparse : NULL);
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_MARCH, m->ubo);
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_MEDIUM, m->medium_ubo);
        glBindTextureUnit(VEIL_TEX_EV, lm->grid ? lm->ev : 0);
        glBindTextureUnit(VEIL_TEX_OCC, lm->grid ? lm->occupancy : 0);
        veil_lit_medium_bind_depths(lm);
        glBindTextureUnit(VEIL_TEX_LIMIT, limit);
        glBindTextureUnit(VEIL_TEX_DIFFUSION, d->field ? d->field->texture : 0);
        glBindTextureUnit(VEIL_TEX_EMISSION, lm->grid ? lm->emission : 0);
        memset(&m->last_gather, 0, sizeof m->last_gather);
        if (u.march[1] > 0.0f) { /* the cache's later light gathered towards this camera (slab 4) */
            const double t0 = veil_now_ms();
            const int gv = (lm->grid && lm->sparse ? 2 : 0) + (mu.solid_origin[3] > 0.0f ? 1 : 0);
            r = gather_variant(m, gv, err);
            if (r == VEIL_OK) {
                glUseProgram(m->gather[gv]);
                glBindImageTexture(VEIL_IMAGE_CACHE, d->field->texture, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
                const float sc = u.march[3];
                const int gd[3] = {(int)u.limits[1], (int)u.limits[2], (int)u.limits[3]};
                glDispatchCompute(veil_groups(gd[0], VEIL_GATHER_GROUP), veil_groups(gd[1], VEIL_GATHER_GROUP),
                                  veil_groups(gd[2], VEIL_GATHER_GROUP));
                glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
                glFinish(); /* its time apart from the march's (--stats) */
                veil_march_gather* g = &m->last_gather;
                g->rays = (int)u.march[1], g->scale = sc, g->step = u.march[2], g->ms = veil_now_ms() - t0;
                memcpy(g->dims, gd, sizeof gd);
                glBindImageTexture(VEIL_IMAGE_CACHE, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
                glUseProgram(program);
            }
        }
        for (int i = 0; i < N; ++i) glBindImageTexture(units[i], tex[i], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        if (deep_buf[0]) {
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_DEEP_COUNT, deep_buf[0]);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_DEEP_SAMPLES, deep_buf[1]);
        }
        if (report) veil_progress("march, rows", 0, h);
        for (int y = 0, rows = 0; y < h && r == VEIL_OK; y += rows) { /* (r: the gather's program was made) */
            if (y > 0) { /* the band's first row: size.z of the march's block (uploaded with 0) */
                u.size[2] = y;
                glNamedBufferSubData(m->ubo, offsetof(veil_march_block, size), sizeof u.size, u.size);
            }
            rows = h - y < band ? h - y : band;
            const double t0 = adapt ? veil_now_ms() : 0.0;
            glDispatchCompute(veil_groups(w, VEIL_MARCH_GROUP), veil_groups(rows, VEIL_MARCH_GROUP), 1);
            if (deep_buf[0]) { /* this band's samples, before the next band overwrites them */
                glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
                glGetNamedBufferSubData(deep_buf[0], 0, (GLsizeiptr)((size_t)rows * w * sizeof(uint32_t)), deep_counts);
                glGetNamedBufferSubData(deep_buf[1], 0, (GLsizeiptr)((size_t)rows * deep_row_floats * sizeof(float)),
                                        deep_samples);
                r = veil_gl_check("reading back the deep samples", err);
                if (r == VEIL_OK) r = veil_deep_append_band(&out->deep, y, rows, d->deep_raw, deep_counts, deep_samples, err);
            }
            if (report) { /* what is reported is done */
                glFinish();
                if (adapt) { /* the next band's rows to take band_seconds at this one's pace (doubling at most) */
                    const double ms = veil_now_ms() - t0, want = rows * (1e3 * d->band_seconds) / (ms > 1.0 ? ms : 1.0);
                    const double most = fmin(2.0 * rows, (double)band_cap);
                    band = (int)(fmax(VEIL_MARCH_GROUP, fmin(want, most)) / VEIL_MARCH_GROUP) * VEIL_MARCH_GROUP;
                    if (band < VEIL_MARCH_GROUP) band = VEIL_MARCH_GROUP;
                }
                veil_progress("march, rows", y + rows, h);
                if (veil_progress_cancelled() && y + rows < h)
                    r = veil_fail(err, VEIL_ERR_CANCELLED, "cancelled by the progress callback during the march "
                                  "(%d of %d rows done)", y + rows, h);
            } else {
                glFlush();
            }
        }
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
        for (int i = 0; i < N; ++i) glBindImageTexture(units[i], 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        if (deep_buf[0]) {
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_DEEP_COUNT, 0);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VEIL_BIND_DEEP_SAMPLES, 0);
        }
        for (int t = 0; t <= VEIL_TEX_EMISSION; ++t) glBindTextureUnit((GLuint)t, 0);
        if (!(lm->grid && lm->sparse)) veil_lit_medium_bind_depths(NULL);
        veil_ev_sparse_bind(NULL);
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_MARCH, 0);
        glBindBufferBase(GL_UNIFORM_BUFFER, VEIL_UBO_MEDIUM, 0);
        glUseProgram(0);
        if (r == VEIL_OK) r = veil_gl_check("ray march (render/shaders/march.comp)", err);
        if (r == VEIL_OK) glFinish(); /* the march's work done: what follows is the reading */
        const double t_read = veil_now_ms();
        for (int i = 0; i < N && r == VEIL_OK; ++i) {
            if (!read[i]) continue;
            r = veil_gl_read_texture(tex[i], GL_RGBA, floats, *dst[i], "reading back the image", err);
            m->last_readback.images += 1, m->last_readback.bytes += (double)floats * sizeof(float);
        }
        m->last_readback.ms = veil_now_ms() - t_read;
        if (r == VEIL_OK && out->aov_s && !(d->skip_reads & VEIL_MARCH_READ_Z)) r = planar_depth(d, out, err);
        if (r == VEIL_OK && env) r = environment_behind(d, out, err);
    }
    glDeleteTextures(1, &limit);
    glDeleteBuffers(2, deep_buf);
    free(deep_counts);
    free(deep_samples);
    if (r != VEIL_OK) veil_image_set_free(out);
    return r;
}
