#include "renderer.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/clock.h"
#include "../core/progress.h"
#include "../core/hash.h"
#include "../propagate/opv_set.h"
#include "../render/diffusion.h"
#include "../render/spread.h"
#include "../volume/ev.h"

struct veil_renderer {
    unsigned long long memory_budget; /* bytes, see veil_gl_info */
    veil_ev* ev;
    veil_opv_set* opv;
    veil_march* march;
    veil_spread* spread;
    veil_diffusion* diffusion;
    /* what the EV holds: the inject key it was made with (ev_keyed: a key
     * is held, an empty medium included), and for the report */
    uint64_t ev_key;
    int ev_keyed;
    size_t particles;
};

/* ---- lifetime ---------------------------------------------------------- */

veil_result veil_renderer_create(const veil_gl* gl, veil_renderer** out, veil_error* err)
{
    *out = NULL;
    veil_renderer* r = calloc(1, sizeof *r);
    if (!r) return veil_fail(err, VEIL_ERR_OOM, "out of memory creating the renderer");
    r->memory_budget = veil_gl_get_info(gl)->memory_budget;
    veil_result res = veil_ev_create(&r->ev, err);
    if (res == VEIL_OK) res = veil_opv_set_create(&r->opv, err);
    if (res == VEIL_OK) res = veil_march_create(&r->march, err);
    if (res == VEIL_OK) res = veil_spread_create(&r->spread, err);
    if (res == VEIL_OK) res = veil_diffusion_create(&r->diffusion, err);
    if (res != VEIL_OK) {
        veil_renderer_destroy(r);
        return res;
    }
    *out = r;
    return VEIL_OK;
}

void veil_renderer_destroy(veil_renderer* r)
{
    if (!r) return;
    veil_ev_destroy(r->ev);
    veil_opv_set_destroy(r->opv);
    veil_march_destroy(r->march);
    veil_spread_destroy(r->spread);
    veil_diffusion_destroy(r->diffusion);
    free(r);
}

/* The EV changed (or is gone): nothing made from it is valid any more. */
static void forget_volume(veil_renderer* r)
{
    veil_ev_clear(r->ev);
    veil_opv_set_clear(r->opv);
    veil_diffusion_clear(r->diffusion);
    r->ev_keyed = 0;
    r->ev_key = 0;
    r->particles = 0;
}

/* ---- planning ---------------------------------------------------------- */

veil_render_opts veil_render_opts_resolve(const veil_render_opts* opts, const veil_scene* s)
{
    veil_render_opts o = opts ? *opts : (veil_render_opts){0};
    if (!o.camera) o.camera = &s->camera;
    if (o.width <= 0) o.width = o.camera->width;
    if (o.height <= 0) o.height = o.camera->height;
    if (o.quality <= VEIL_QUALITY_UNSET || o.quality >= VEIL_QUALITY_COUNT)
        o.quality = s->quality > VEIL_QUALITY_UNSET && s->quality < VEIL_QUALITY_COUNT ? s->quality : VEIL_QUALITY_DEFAULT;
    const veil_quality_rung* q = veil_quality_rung_of(o.quality);
    if (!(o.step_voxels > 0.0f)) o.step_voxels = q->step_voxels;
    if (o.method == VEIL_OPV_DEFAULT) o.method = q->method;
    o.method = veil_opv_method_resolve(o.method);
    if (!(o.sun_across > 0.0f)) o.sun_across = q->sun_across;
    if (!(o.sun_along > 0.0f)) o.sun_along = q->sun_along;
    return o;
}

static int count_fogs(const veil_scene* s)
{
    int n = 0;
    for (size_t i = 0; i < s->medium.source_count; ++i) n += s->medium.sources[i].type == VEIL_SOURCE_EXPONENTIAL;
    return n;
}

static int light_reaches(const veil_light* l, const veil_grid* g)
{
    if (!(l->color[0] > 0.0f || l->color[1] > 0.0f || l->color[2] > 0.0f)) return 0;
    if (!g || l->type != VEIL_LIGHT_SPOT || l->outer_angle_deg >= 90.0f) return 1;
    double c[3], d2 = 0.0, r2 = 0.0;
    for (int a = 0; a < 3; ++a) {
        double half = 0.5 * g->dims[a] * (double)g->voxel;
        c[a] = g->origin[a] + half - l->position[a];
        d2 += c[a] * c[a];
        r2 += half * half;
    }
    if (d2 <= r2) return 1; /* the light is within the sphere */
    double cos_axis = (c[0] * l->direction[0] + c[1] * l->direction[1] + c[2] * l->direction[2]) / sqrt(d2);
    double angle = acos(fmax(-1.0, fmin(1.0, cos_axis)));
    double spread = l->outer_angle_deg * (VEIL_PI / 180.0) + asin(sqrt(r2 / d2));
    return angle <= spread;
}

int veil_render_lights(const veil_scene* s, const veil_grid* g, veil_light* out)
{
    int n = 0;
    if (!g && count_fogs(s) == 0) return 0; /* no medium at all */
    for (size_t l = 0; l < s->light_count && n < VEIL_MAX_LIGHTS; ++l)
        if (light_reaches(&s->lights[l], g)) out[n++] = s->lights[l];
    return n;
}

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static void why(veil_stage_report* rep, const char* fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(rep->why, sizeof rep->why, fmt, ap);
    va_end(ap);
}

/* ---- stage 1: inject --------------------------------------------------- */

static veil_result inject_scene(veil_renderer* r, const veil_scene* s, veil_render_stats* st, veil_error* err)
{
    veil_stage_report* rep = &st->stage[VEIL_STAGE_INJECT];
    uint64_t key = veil_scene_volume_key(s);
    rep->key = key;
    if (r->ev_keyed && r->ev_key == key) {
        rep->status = VEIL_STAGE_CACHED;
        why(rep, "the sources' descriptions and files are unchanged");
        st->inject_cached = 1;
        return VEIL_OK;
    }
    int had = r->ev_keyed;
    forget_volume(r);
    if (!veil_scene_volume_needed(s)) {
        rep->status = VEIL_STAGE_SKIPPED;
        why(rep, "no voxelised source%s", count_fogs(s) ? " (analytic fog only: closed form)" : "");
        r->ev_keyed = 1, r->ev_key = key; /* an empty medium, remembered as such */
        return VEIL_OK;
    }
    veil_scene_volume v;
    veil_result res = veil_scene_volume_open(s, &v, err);
    if (res != VEIL_OK) return res;
    veil_ev_report er = {0};
    res = veil_ev_build_scene(r->ev, &v, (int)s->light_count, r->memory_budget, &er, err);
    if (res == VEIL_OK) {
        r->ev_keyed = 1, r->ev_key = key;
        r->particles = er.particles;
        st->vdb_voxels = er.vdb_voxels;
        if (!v.has_volume) {
            rep->status = VEIL_STAGE_SKIPPED;
            why(rep, "the sources hold no density (no particle, no active voxel)");
        } else {
            const veil_grid* g = &v.grid;
            const veil_ev_sparse* sp = veil_ev_sparse_of(r->ev);
            char mem[200];
            if (sp)
                snprintf(mem, sizeof mem, "; %zu bricks kept of %.0f (%.0fx%.0fx%.0f), %.1f MiB on the GPU (dense: %.0f MiB)",
                         sp->slots, ceil(g->dims[0] / 8.0) * ceil(g->dims[1] / 8.0) * ceil(g->dims[2] / 8.0),
                         ceil(g->dims[0] / 8.0), ceil(g->dims[1] / 8.0), ceil(g->dims[2] / 8.0),
                         (double)er.bytes / 1048576.0, (double)g->dims[0] * g->dims[1] * g->dims[2] * 4 / 1048576.0);
            else
                snprintf(mem, sizeof mem, "; %.1f MiB on the GPU", (double)er.bytes / 1048576.0);
            rep->status = VEIL_STAGE_RAN;
            why(rep, "%s: %zu particles, %zu VDB voxels, grid %dx%dx%d, voxel %.4g m (%s%s)",
                had ? "the sources changed" : "no volume kept", er.particles, er.vdb_voxels, g->dims[0], g->dims[1],
                g->dims[2], g->voxel, v.resolution, mem);
        }
    }
    veil_scene_volume_close(&v);
    return res;
}

/* ---- stage 2: propagate ------------------------------------------------ */

/* The ladder, chosen from bench/peers.py --knobs (docs/performance.md):
 * each rung slower and more accurate than the one below it on the shared
 * smoke, none dominated on the three scenes of bench/peers.py. */
static const veil_quality_rung rungs[VEIL_QUALITY_COUNT] = {
    [VEIL_QUALITY_DRAFT] = {1.0f, VEIL_OPV_LIGHT_SPACE, 1.0f, 4.0f},
    [VEIL_QUALITY_DEFAULT] = {0.5f, VEIL_OPV_LIGHT_SPACE, 0.5f, 4.0f},
    [VEIL_QUALITY_HIGH] = {0.5f, VEIL_OPV_LIGHT_SPACE, 0.35f, 4.0f},
    [VEIL_QUALITY_MAX] = {0.25f, VEIL_OPV_LIGHT_SPACE, 0.25f, 4.0f},
};

const veil_quality_rung* veil_quality_rung_of(veil_quality q)
{
    return &rungs[q > VEIL_QUALITY_UNSET && q < VEIL_QUALITY_COUNT ? q : VEIL_QUALITY_DEFAULT];
}

veil_opv_params veil_render_opv_params(const veil_scene* s, const veil_render_opts* o, const veil_grid* g,
                                       unsigned long long budget)
{
    float st_max = 0.0f;
    for (int c = 0; c < 3; ++c) st_max = fmaxf(st_max, s->medium.sigma_a[c] + s->medium.sigma_s[c]);
    /* D changes of tol move tau by at most st_max * tol */
    veil_opv_params p = {.method = veil_opv_method_resolve(o->method),
                         .tolerance = st_max > 0.0f ? VEIL_OPV_TAU_TOLERANCE / st_max : INFINITY,
                         .sun_across = o->sun_across, .sun_along = o->sun_along};
    if (g && budget > 0) {
        /* what the device's budget leaves the suns' grids beside the EV and the rgba32f optical depths
         * veil_ev_check_budget counted (one per four lights, and one more) */
        double voxels = (double)g->dims[0] * g->dims[1] * g->dims[2];
        int n = (int)s->light_count < VEIL_MAX_LIGHTS ? (int)s->light_count : VEIL_MAX_LIGHTS;
        double used = voxels * 4.0 + voxels * 16.0 * ((n + 3) / 4 + 1);
        p.sun_bytes = (double)budget > used ? (double)budget - used : 1.0;
    }
    return p;
}

static veil_result propagate(veil_renderer* r, const veil_scene* s, const veil_light* lights, int n,
                             const veil_render_opts* o, veil_render_stats* st, veil_error* err)
{
    veil_stage_report* rep = &st->stage[VEIL_STAGE_PROPAGATE];
    const veil_grid* g = veil_ev_grid(r->ev);
    if (!g) {
        rep->status = VEIL_STAGE_SKIPPED;
        why(rep, "no volume: nothing to propagate%s", st->fogs ? " (fog's optical depth is closed form)" : "");
        return VEIL_OK;
    }
    if (n == 0) {
        rep->status = VEIL_STAGE_SKIPPED;
        why(rep, "no light reaches the medium (of %zu)", s->light_count);
        return VEIL_OK;
    }
    veil_opv_params params = veil_render_opv_params(s, o, g, r->memory_budget);
    veil_opv_report orep = {0};
    const veil_ev_sparse* sp = veil_ev_sparse_of(r->ev);
    veil_result res = veil_opv_set_update(r->opv, g, veil_ev_texture(r->ev), o->no_skip ? 0 : veil_ev_occupancy(r->ev),
                                          sp, r->ev_key, lights, n, &params, &orep, err);
    st->opv_computed = orep.computed;
    st->opv_cached = orep.cached;
    st->propagate_iterations = orep.iterations;
    veil_opv_params keyed = params;
    keyed.sun_bytes = 0.0; /* as the textures' keys: the allowance shows through the grids it makes */
    rep->key = veil_hash_bytes(r->ev_key, &keyed, sizeof keyed);
    for (int l = 0; l < n; ++l) {
        veil_opv_light ol;
        veil_opv_light_from_world(g, &lights[l], &ol);
        rep->key = veil_hash_bytes(rep->key, &ol, sizeof ol);
    }
    rep->status = orep.computed || orep.suns_computed ? VEIL_STAGE_RAN : VEIL_STAGE_CACHED;
    const char* method = sp ? "sparse: brick by brick in the light's order" : veil_opv_method_name(o->method);
    char from[64] = "";
    if (st->emission_lights) snprintf(from, sizeof from, " (+%d from the emission)", st->emission_lights);
    char suns[128] = "";
    if (orep.suns)
        snprintf(suns, sizeof suns, "; %d sun%s in light-space grids (%d computed), %.3g voxels apart across",
                 orep.suns, orep.suns > 1 ? "s" : "", orep.suns_computed, orep.sun_across);
    if (orep.computed || orep.suns_computed)
        why(rep, "%d of %zu lights%s, %s, %d passes; %d textures computed (volume or light moved), %d cached%s; "
            "%.1f MiB", n - st->emission_lights, s->light_count, from, method, orep.iterations, orep.computed,
            orep.cached, suns, orep.mib);
    else
        why(rep, "%d lights, %s: the volume, method and lights' geometry are unchanged", n, method);
    return res;
}

/* ---- the diffusion estimate (view-independent) ------------------------ */

static veil_result diffuse(veil_renderer* r, const veil_scene* s, const veil_march_desc* md,
                           veil_diffusion_field* field, veil_render_stats* st, veil_error* err)
{
    veil_stage_report* rep = &st->stage[VEIL_STAGE_VOLUMETRIC];
    const veil_multiple* m = &s->multiple;
    int escape = m->volumetric_method == VEIL_VOLUMETRIC_OCTAVE && m->octave_gate == VEIL_GATE_ESCAPE;
    if (!m->volumetric || (m->volumetric_method == VEIL_VOLUMETRIC_OCTAVE && !escape) || m->octaves < 2 * escape) {
        rep->status = VEIL_STAGE_SKIPPED;
        why(rep, "%s", m->volumetric ? "the octaves need no field (their gate is the legs through each point)"
                                     : "no volumetric estimate (multiple_scattering.volumetric)");
        return VEIL_OK;
    }
    if (md->light_count == 0) {
        rep->status = VEIL_STAGE_SKIPPED;
        why(rep, "no light reaches the medium");
        return VEIL_OK;
    }
    /* the key: the volume, the lights (geometry and colour: the source is lit), the medium's
     * coefficients and phase, the fogs and the grid settings; never the camera */
    uint64_t key = veil_hash_bytes(r->ev_key, &s->medium.sigma_a, sizeof s->medium.sigma_a);
    key = veil_hash_bytes(key, &s->medium.sigma_s, sizeof s->medium.sigma_s);
    key = veil_hash_bytes(key, &s->medium.phase, sizeof s->medium.phase);
    if (!escape) key = veil_hash_bytes(key, md->lights, (size_t)md->light_count * sizeof *md->lights);
    key = veil_hash_bytes(key, &escape, sizeof escape);
    key = veil_hash_bytes(key, &m->diffusion_cells, sizeof m->diffusion_cells);
    key = veil_hash_bytes(key, &m->diffusion_iterations, sizeof m->diffusion_iterations);
    for (size_t i = 0; i < s->medium.source_count; ++i)
        if (s->medium.sources[i].type == VEIL_SOURCE_EXPONENTIAL)
            key = veil_hash_bytes(key, &s->medium.sources[i].fog, sizeof s->medium.sources[i].fog);
    veil_diffusion_report dr;
    veil_result res = veil_diffusion_update(r->diffusion, md, key, escape ? (float)VEIL_FIELD_ESCAPE
                                                                        : (float)VEIL_FIELD_FLUENCE, field, &dr, err);
    if (res != VEIL_OK) return res;
    rep->key = key;
    if (dr.skipped && dr.sparse) {
        rep->status = VEIL_STAGE_SKIPPED;
        why(rep, "the diffusion solve needs a dense grid; over a sparse volume there is no volumetric estimate "
                 "(set multiple_scattering.volumetric_method to \"octave\")");
    } else if (dr.skipped) {
        rep->status = VEIL_STAGE_SKIPPED;
        why(rep, "no grid: no medium, or a fog box over %g m%s", VEIL_DIFFUSION_MAX_EXTENT,
            escape ? " (the octaves fall back to the legs gate)" : "");
    } else if (dr.cached) {
        rep->status = VEIL_STAGE_CACHED;
        why(rep, "the volume, lights and medium are unchanged (%dx%dx%d cells)", dr.dims[0], dr.dims[1], dr.dims[2]);
    } else {
        rep->status = VEIL_STAGE_RAN;
        if (escape && dr.sparse)
            why(rep, "the octaves' escape field, %d points a kept brick (every %.4g m): view- and light-independent, "
                "kept", VEIL_SPARSE_ESCAPE * VEIL_SPARSE_ESCAPE * VEIL_SPARSE_ESCAPE, dr.cell);
        else if (escape)
            why(rep, "the octaves' escape field, %dx%dx%d cells of %.4g m: view- and light-independent, kept",
                dr.dims[0], dr.dims[1], dr.dims[2], dr.cell);
        else
            why(rep, "%dx%dx%d cells of %.4g m, %d red-black sweeps: view-independent, kept for the next frames",
                dr.dims[0], dr.dims[1], dr.dims[2], dr.cell, dr.iterations);
    }
    return VEIL_OK;
}

/* ---- stage 4: screen-space multiple scattering ------------------------ */

/* What the spread moves (docs/multiple-scattering.md): the light from
 * behind the medium that it scatters without absorbing (veil fog's frame;
 * the scene's background is a backdrop that lights nothing, as in the
 * reference path tracer, so it is not spread), and, when the volumetric
 * estimate is off, the single scattering's light scattered on its way to
 * the camera (aov_q). With the volumetric estimate on, the medium's higher
 * orders are its: spreading aov_q too would count them twice. */
static veil_result spread(veil_renderer* r, const veil_scene* s, const veil_render_opts* o, veil_image_set* im,
                          veil_render_stats* st, veil_error* err)
{
    veil_stage_report* rep = &st->stage[VEIL_STAGE_SPREAD];
    const veil_multiple* m = &s->multiple;
    if (!m->screen_space) {
        rep->status = VEIL_STAGE_SKIPPED;
        why(rep, "off in the scene (multiple_scattering.screen_space)");
        return VEIL_OK;
    }
    const float* q = m->volumetric ? NULL : im->aov_q;
    if (!o->behind && !q) {
        rep->status = VEIL_STAGE_SKIPPED;
        why(rep, "nothing to spread: the volumetric estimate carries the medium's higher orders and the "
                 "background is a backdrop (veil fog spreads its frame)");
        return VEIL_OK;
    }
    float thick = veil_spread_max_scattering(s, im->aov_t, q, im->width, im->height);
    if (!(thick >= m->thin_threshold)) {
        rep->status = VEIL_STAGE_SKIPPED;
        why(rep, "optically thin view: max P sigma_s = %.3g < thin_threshold %g", thick, m->thin_threshold);
        return VEIL_OK;
    }
    size_t floats = (size_t)im->width * (size_t)im->height * 4;
    im->aov_m = malloc(floats * sizeof(float));
    if (!im->aov_m) return veil_fail(err, VEIL_ERR_OOM, "out of memory for the spread image");
    veil_spread_input in = {.width = im->width, .height = im->height, .L = o->behind, .background = {0, 0, 0},
                            .aov_t = im->aov_t, .aov_s = im->aov_s, .aov_q = q, .fov_y_deg = o->camera->fov_y_deg};
    veil_spread_report sr = {0};
    veil_result res = veil_spread_run(r->spread, s, &in, im->aov_m, NULL, &sr, err);
    if (res != VEIL_OK) return res;
    for (size_t i = 0; i < floats; i += 4)
        for (int c = 0; c < 3; ++c) im->rgba[i + (size_t)c] += im->aov_m[i + (size_t)c];
    rep->ms = sr.ms;
    rep->status = VEIL_STAGE_RAN;
    why(rep, "max P sigma_s = %.3g >= %g: spreads %s%s%s; %d levels on %dx%d, %s filter: depends on the camera",
        thick, m->thin_threshold, o->behind ? "the frame behind" : "", o->behind && q ? " and " : "",
        q ? "single scattering's out-scattered light" : "", sr.levels, sr.padded_width, sr.padded_height,
        m->filter == VEIL_SPREAD_2X2 ? "2x2" : m->filter == VEIL_SPREAD_6X6 ? "6x6" : "4x4");
    return VEIL_OK;
}

/* ---- stage 3: march, and the frame ------------------------------------- */

static veil_result light_and_march(veil_renderer* r, const veil_scene* s, const veil_render_opts* o,
                                   veil_image_set* images, veil_render_stats* st, veil_error* err)
{
    if (o->width < 1 || o->height < 1 || o->width > VEIL_SCENE_MAX_IMAGE || o->height > VEIL_SCENE_MAX_IMAGE)
        return veil_fail(err, VEIL_ERR_INVALID, "image size %dx%d is outside 1..%d", o->width, o->height,
                         VEIL_SCENE_MAX_IMAGE);
    if (s->light_count > VEIL_MAX_LIGHTS)
        return veil_fail(err, VEIL_ERR_LIMIT, "%zu lights; at most %d are supported", s->light_count, VEIL_MAX_LIGHTS);
    const veil_grid* g = veil_ev_grid(r->ev);
    veil_light lights[VEIL_MAX_LIGHTS];
    int n = veil_render_lights(s, g, lights);
    /* the medium's emission as lights (volume/emission_lights.h): after the scene's, while there is room */
    int emitting = 0;
    const veil_light* el = veil_ev_emission_lights(r->ev, &emitting);
    if (emitting > VEIL_MAX_LIGHTS - n) emitting = VEIL_MAX_LIGHTS - n;
    for (int i = 0; i < emitting; ++i) lights[n++] = el[i];
    st->emission_lights = emitting;
    st->fogs = count_fogs(s);
    st->lights_used = n;
    st->method = o->method;
    st->has_volume = g != NULL;
    if (g) st->grid = *g;
    st->particles = r->particles;
    st->width = o->width, st->height = o->height;
    double t0 = veil_now_ms();
    veil_progress("propagate", 0, 1);
    veil_result res = propagate(r, s, lights, n, o, st, err);
    glFinish();
    double t1 = veil_now_ms();
    st->stage[VEIL_STAGE_PROPAGATE].ms = t1 - t0;
    if (res != VEIL_OK) return res;
    GLuint opv[VEIL_MAX_OPV_TEXTURES];
    for (int t = 0; t < VEIL_MAX_OPV_TEXTURES; ++t) opv[t] = veil_opv_set_texture(r->opv, t);
    int sun_count = 0;
    veil_march_desc md = {.scene = s, .camera = o->camera, .width = o->width, .height = o->height,
                          .lights = lights, .light_count = n, .grid = g,
                          .ev = veil_ev_texture(r->ev), .occupancy = veil_ev_occupancy(r->ev),
                          .sparse = veil_ev_sparse_of(r->ev),
                          .emission = veil_ev_emission(r->ev), .opv = opv,
                          .suns = veil_opv_set_suns(r->opv, &sun_count), .sun_count = sun_count,
                          .step_voxels = o->step_voxels, .seed = o->seed, .skip_empty = !o->no_skip,
                          .max_distance = o->max_distance, .end_distance = o->behind_distance,
                          .no_background = o->behind != NULL};
    veil_diffusion_field field = {0};
    double t2 = veil_now_ms();
    veil_progress("multiple scattering", 0, 1);
    res = diffuse(r, s, &md, &field, st, err);
    glFinish();
    st->stage[VEIL_STAGE_VOLUMETRIC].ms = veil_now_ms() - t2;
    if (res != VEIL_OK) return res;
    md.diffusion = &field;
    t1 = veil_now_ms();
    veil_progress("march", 0, 1);
    res = veil_march_run(r->march, &md, images, err);
    if (res == VEIL_OK && o->behind) { /* what is behind, attenuated: T L */
        size_t pixels = (size_t)images->width * (size_t)images->height;
        for (size_t i = 0; i < pixels; ++i)
            for (int c = 0; c < 3; ++c) images->rgba[4 * i + c] += images->aov_t[4 * i + c] * o->behind[4 * i + c];
    }
    veil_stage_report* rep = &st->stage[VEIL_STAGE_RENDER];
    rep->ms = veil_now_ms() - t1;
    rep->status = VEIL_STAGE_RAN;
    const veil_multiple* ms = &s->multiple;
    why(rep, "%dx%d, %d lights, quality %s, step %g voxels%s: depends on the camera, runs every frame", o->width,
        o->height, n, veil_quality_name(o->quality), o->step_voxels,
        !ms->volumetric ? ""
        : ms->volumetric_method == VEIL_VOLUMETRIC_DIFFUSION ? ", multiple scattering from the diffusion field"
        : ms->octaves > 1 ? ", volumetric multiple scattering (octaves)" : "");
    if (res == VEIL_OK) {
        veil_progress("spread", 0, 1);
        res = spread(r, s, o, images, st, err);
    }
    return res;
}

static void finish_stats(veil_render_stats* st, veil_render_stats* out)
{
    st->inject_ms = st->stage[VEIL_STAGE_INJECT].ms;
    st->propagate_ms = st->stage[VEIL_STAGE_PROPAGATE].ms;
    st->render_ms = st->stage[VEIL_STAGE_RENDER].ms;
    if (out) *out = *st;
}

veil_result veil_render_scene_images(veil_renderer* r, const veil_scene* s, const veil_render_opts* opts,
                                     veil_image_set* images, veil_render_stats* stats, veil_error* err)
{
    veil_render_opts o = veil_render_opts_resolve(opts, s);
    veil_render_stats st;
    memset(&st, 0, sizeof st);
    veil_image_set_free(images);
    double t0 = veil_now_ms();
    veil_progress("inject", 0, 1);
    veil_result res = inject_scene(r, s, &st, err);
    glFinish();
    st.stage[VEIL_STAGE_INJECT].ms = veil_now_ms() - t0;
    if (res == VEIL_OK) res = light_and_march(r, s, &o, images, &st, err);
    finish_stats(&st, stats);
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
    veil_render_opts o = veil_render_opts_resolve(opts, s);
    veil_render_stats st;
    memset(&st, 0, sizeof st);
    *rgba = NULL;
    veil_stage_report* rep = &st.stage[VEIL_STAGE_INJECT];
    double t0 = veil_now_ms();
    uint64_t key = veil_hash_bytes(VEIL_FNV_OFFSET, g, sizeof *g);
    key = veil_hash_bytes(key, density, veil_grid_voxels(g) * sizeof(float));
    rep->key = key;
    veil_result res = VEIL_OK;
    if (r->ev_keyed && veil_ev_present(r->ev) && r->ev_key == key) {
        st.inject_cached = 1;
        rep->status = VEIL_STAGE_CACHED;
        why(rep, "the same density on the same grid");
    } else {
        forget_volume(r);
        res = veil_ev_build_density(r->ev, g, density, (int)s->light_count, r->memory_budget, err);
        if (res == VEIL_OK) r->ev_keyed = 1, r->ev_key = key;
        rep->status = VEIL_STAGE_RAN;
        why(rep, "a density given on a %dx%dx%d grid", g->dims[0], g->dims[1], g->dims[2]);
    }
    glFinish();
    rep->ms = veil_now_ms() - t0;
    veil_image_set im = {0};
    if (res == VEIL_OK) res = light_and_march(r, s, &o, &im, &st, err);
    *rgba = take_rgba(&im);
    finish_stats(&st, stats);
    return res;
}

veil_result veil_renderer_inject(veil_renderer* r, const veil_grid* g, const veil_particle* p, size_t n,
                                 float* density, veil_error* err)
{
    return veil_ev_splat_readback(r->ev, g, p, n, density, err);
}

veil_result veil_renderer_propagate(veil_renderer* r, const veil_grid* g, const float* density,
                                    const veil_opv_light* lights, int n_lights, const veil_opv_params* params,
                                    float* out, int* iterations, veil_error* err)
{
    return veil_opv_set_propagate_readback(r->opv, g, density, lights, n_lights, params, out, iterations, err);
}
