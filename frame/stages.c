#include "stages.h"

#include <epoxy/gl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/clock.h"
#include "../core/hash.h"
#include "../gpu/gl_context.h"
#include "../propagate/lit_medium.h"
#include "../propagate/opv_set.h"
#include "../render/march.h"
#include "../render/spread.h"
#include "../scene/camera.h"
#include "../volume/ev.h"
#include "../volume/scene_volume.h"

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static void say(char* why, size_t n, const char* fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, n, fmt, ap);
    va_end(ap);
}

/* The medium as the passes after propagation read it, with the textures the stages hold (the
 * optical-depth textures are the caller's to add: their array must outlive the use). */
static veil_lit_medium lit_medium(const veil_frame* f)
{
    const veil_frame_plan* p = &f->plan;
    veil_lit_medium m = {.scene = p->scene, .lights = p->lights, .light_count = p->light_count, .grid = p->grid};
    if (!f->parts) return m;
    m.ev = veil_ev_texture(f->parts->ev);
    m.occupancy = veil_ev_occupancy(f->parts->ev);
    m.sparse = veil_ev_sparse_of(f->parts->ev);
    m.emission = veil_ev_emission(f->parts->ev);
    m.suns = veil_opv_set_suns(f->parts->opv, &m.sun_count);
    if (f->solid.voxels) m.solid = &f->solid, m.solid_voxels = f->solid_tex[0], m.solid_maps = f->solid_tex[1];
    return m;
}

/* veil fog's surfaces as a solid, once a frame, over the medium's boxes (the EV's and the fogs'): the
 * rows that light the medium (volumetric, render) call it before they read lit_medium(). */
static veil_result frame_solid(veil_frame* f, veil_error* err)
{
    const veil_frame_plan* p = &f->plan;
    if (f->solid_made || !p->o.behind_distance || p->o.behind_not_solid) return VEIL_OK;
    f->solid_made = 1;
    const double t0 = veil_now_ms();
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    if (p->grid) veil_grid_medium_box(p->grid, lo, hi);
    const veil_medium* m = &p->scene->medium;
    for (size_t i = 0; i < m->source_count; ++i)
        if (m->sources[i].type == VEIL_SOURCE_EXPONENTIAL)
            for (int a = 0; a < 3; ++a) {
                lo[a] = fminf(lo[a], m->sources[i].fog.bounds[0][a]);
                hi[a] = fmaxf(hi[a], m->sources[i].fog.bounds[1][a]);
            }
    if (!(lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2])) return VEIL_OK;
    veil_result r = veil_solid_build(p->o.camera, p->o.width, p->o.height, p->o.behind_distance, lo, hi, p->lights,
                                     p->light_count, &f->solid, err);
    if (r != VEIL_OK || !f->solid.voxels) return r;
    r = veil_lit_medium_solid_textures(&f->solid, f->solid_tex, err);
    f->solid_ms = veil_now_ms() - t0;
    return r;
}

void veil_frame_end(veil_frame* f)
{
    if (f->solid_tex[0] || f->solid_tex[1]) glDeleteTextures(2, f->solid_tex);
    f->solid_tex[0] = f->solid_tex[1] = 0;
    veil_solid_free(&f->solid);
    f->solid_made = 0;
}

/* The EV changed (or is gone): nothing made from it is valid any more. */
static void forget_volume(veil_frame_parts* parts)
{
    if (parts->ev) { /* (a deferred renderer's GPU side may not be made yet: nothing is held then) */
        veil_ev_clear(parts->ev);
        veil_opv_set_clear(parts->opv);
        veil_volumetric_clear(parts->volumetric);
    }
    for (int i = VEIL_STAGE_INJECT; i <= VEIL_STAGE_VOLUMETRIC; ++i) parts->has[i] = 0, parts->kept[i] = 0;
    parts->particles = 0;
    parts->opv_textures = 0;
}

/* ---- inject: sources -> extinction volume ----------------------------- */

static uint64_t inject_key(const veil_frame_plan* p)
{
    if (p->given_grid) {
        uint64_t key = veil_hash_bytes(VEIL_FNV_OFFSET, p->given_grid, sizeof *p->given_grid);
        return veil_hash_bytes(key, p->given_density, veil_grid_voxels(p->given_grid) * sizeof(float));
    }
    return veil_scene_volume_key(p->scene);
}

static veil_stage_status inject_decide(const veil_frame_plan* p, int kept, char* w, size_t n)
{
    if (!p->volume_needed) { /* nothing to make, so nothing kept either: skipped on every frame */
        say(w, n, "no voxelised source%s", p->fogs ? " (analytic fog only: closed form)" : "");
        return VEIL_STAGE_SKIPPED;
    }
    if (kept) {
        say(w, n, "%s", p->given_grid ? "the same density on the same grid"
                                      : "the sources' descriptions and files are unchanged");
        return VEIL_STAGE_CACHED;
    }
    if (p->given_grid) {
        const int* d = p->given_grid->dims;
        say(w, n, "a density given on a %dx%dx%d grid", d[0], d[1], d[2]);
        return VEIL_STAGE_RAN;
    }
    if (p->resolution && !p->grid) { /* explaining: the files hold nothing */
        say(w, n, "the sources hold no density (no particle, no active voxel)");
        return VEIL_STAGE_SKIPPED;
    }
    if (p->grid && p->resolution && p->sparse) { /* explaining a sparse volume: and its work, estimated */
        const veil_sparse_work* k = &p->sparse_work;
        char work[VEIL_ERROR_MAX + 64];
        if (p->sparse_refusal[0])
            snprintf(work, sizeof work, "a render refuses it: %s", p->sparse_refusal);
        else
            snprintf(work, sizeof work, "work ~%.3g s of a CPU driver's time (at most %g): %.0f bricks, %.0f passes for %d "
                     "light%s, %.3g texel rays of %.0f steps, %.3g escape rays of %.0f steps", k->seconds,
                     VEIL_SPARSE_MAX_SECONDS, k->bricks, k->passes, k->lights, k->lights == 1 ? "" : "s", k->od_rays,
                     k->od_units, k->escape_rays, k->escape_units);
        say(w, n, "key %016llx: %zu particles, %zu VDB voxels -> grid %dx%dx%d, voxel %.4g m\n           %s\n           %s",
            (unsigned long long)inject_key(p), p->particles, p->vdb_voxels, p->grid->dims[0], p->grid->dims[1],
            p->grid->dims[2], p->grid->voxel, p->resolution, work);
    } else if (p->grid && p->resolution) /* explaining: what the files hold */
        say(w, n, "key %016llx: %zu particles, %zu VDB voxels -> grid %dx%dx%d, voxel %.4g m\n           %s",
            (unsigned long long)inject_key(p), p->particles, p->vdb_voxels, p->grid->dims[0], p->grid->dims[1],
            p->grid->dims[2], p->grid->voxel, p->resolution);
    else
        say(w, n, "the sources changed");
    return VEIL_STAGE_RAN;
}

static veil_result inject_build(veil_frame* f, veil_stage_report* rep, veil_error* err)
{
    veil_frame_parts* r = f->parts;
    const veil_frame_plan* p = &f->plan;
    const int had = r->has[VEIL_STAGE_INJECT];
    veil_result res = VEIL_OK;
    if (p->given_grid) {
        if (f->gpu) res = f->gpu(f, err);
        forget_volume(r);
        if (res != VEIL_OK) return res;
        res = veil_ev_build_density(r->ev, p->given_grid, p->given_density, (int)veil_scene_light_total(p->scene),
                                    p->budget, err);
        if (res == VEIL_OK) r->has[VEIL_STAGE_INJECT] = 1, r->kept[VEIL_STAGE_INJECT] = rep->key;
        return res;
    }
    veil_scene_volume v;
    res = veil_scene_volume_open(p->scene, &v, err);
    /* a sparse volume's work, before the gather (and the GPU's work) starts */
    veil_sparse_work work;
    if (res == VEIL_OK) res = veil_frame_sparse_estimate(p, &v, &work, err);
    /* only now the GPU, when it waited: a refused volume never made a GL context (issue 22: 57 MB) */
    if (res == VEIL_OK && f->gpu) res = f->gpu(f, err);
    forget_volume(r); /* whatever happens next, the volume held is not this one */
    if (res != VEIL_OK) {
        veil_scene_volume_close(&v); /* (a failed open left it empty: closing it is a no-op) */
        return res;
    }
    veil_ev_report er = {0};
    if (res == VEIL_OK) res = veil_ev_build_scene(r->ev, &v, (int)veil_scene_light_total(p->scene), p->budget, &er, err);
    if (res == VEIL_OK) {
        r->has[VEIL_STAGE_INJECT] = 1, r->kept[VEIL_STAGE_INJECT] = rep->key;
        r->particles = er.particles;
        f->st->vdb_voxels = er.vdb_voxels;
        if (!v.has_volume) {
            rep->status = VEIL_STAGE_SKIPPED;
            say(rep->why, sizeof rep->why, "the sources hold no density (no particle, no active voxel)");
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
            say(rep->why, sizeof rep->why, "%s: %zu particles, %zu VDB voxels, grid %dx%dx%d, voxel %.4g m (%s%s)",
                had ? "the sources changed" : "no volume kept", er.particles, er.vdb_voxels, g->dims[0], g->dims[1],
                g->dims[2], g->voxel, v.resolution, mem);
        }
    }
    veil_scene_volume_close(&v);
    return res;
}

static void inject_settle(veil_frame* f, const veil_stage_report* rep)
{
    veil_frame_plan* p = &f->plan;
    p->ev_key = rep->key; /* what the volume's results are keyed by */
    if (!f->parts) { /* explaining: the grid is the files' */
        veil_frame_plan_volume(p, p->grid, p->sparse, NULL, 0);
        return;
    }
    veil_frame_parts* r = f->parts;
    if (rep->status == VEIL_STAGE_SKIPPED && !(r->has[VEIL_STAGE_INJECT] && r->kept[VEIL_STAGE_INJECT] == rep->key)) {
        forget_volume(r); /* decided: no voxelised source, an empty medium remembered as such */
        r->has[VEIL_STAGE_INJECT] = 1, r->kept[VEIL_STAGE_INJECT] = rep->key;
    }
    /* (no EV before a deferred renderer's GPU side is made: a skipped inject made none) */
    const veil_grid* g = r->ev ? veil_ev_grid(r->ev) : NULL;
    int emitting = 0;
    const veil_light* el = r->ev ? veil_ev_emission_lights(r->ev, &emitting) : NULL;
    veil_frame_plan_volume(p, g, r->ev && veil_ev_sparse_of(r->ev) != NULL, el, emitting);
    veil_render_stats* st = f->st;
    st->inject_cached = rep->status == VEIL_STAGE_CACHED;
    st->emission_lights = p->emission_lights;
    st->fogs = p->fogs;
    st->lights_used = p->light_count;
    st->method = p->o.method;
    st->has_volume = g != NULL;
    if (g) st->grid = *g;
    st->particles = r->particles;
    st->width = p->o.width, st->height = p->o.height;
}

/* ---- propagate: optical depth per light ------------------------------- */

static uint64_t propagate_key(const veil_frame_plan* p)
{
    if (!p->grid || p->light_count == 0) return 0;
    veil_opv_params keyed = p->opv;
    keyed.sun_bytes = 0.0; /* as the textures' keys: the allowance shows through the grids it makes */
    uint64_t key = veil_hash_bytes(p->ev_key, &keyed, sizeof keyed);
    return veil_hash_bytes(key, p->index_lights, (size_t)p->light_count * sizeof *p->index_lights);
}

static const char* propagate_method(const veil_frame_plan* p)
{
    return p->sparse ? "sparse: brick by brick in the light's order" : veil_opv_method_name(p->o.method);
}

static veil_stage_status propagate_decide(const veil_frame_plan* p, int kept, char* w, size_t n)
{
    if (!p->grid) {
        say(w, n, "no volume: nothing to propagate%s", p->fogs ? " (the fog's optical depth is closed form)" : "");
        return VEIL_STAGE_SKIPPED;
    }
    if (p->light_count == 0) {
        say(w, n, "no light reaches the medium (of %zu)", p->scene->light_count);
        return VEIL_STAGE_SKIPPED;
    }
    if (kept) {
        say(w, n, "%d lights, %s: the volume, method and lights' geometry are unchanged", p->light_count,
            propagate_method(p));
        return VEIL_STAGE_CACHED;
    }
    /* the textures and light-space grids it will make */
    const veil_index_light* ol = p->index_lights;
    const veil_opv_sun* suns = p->suns;
    const uint64_t* sun_keys = p->sun_keys;
    const int n_suns = p->sun_count;
    int textures = 0;
    for (int tex = 0; 4 * tex < p->light_count; ++tex) {
        int count = p->light_count - 4 * tex < 4 ? p->light_count - 4 * tex : 4, on_grid = 0;
        for (int c = 0; c < count; ++c) on_grid += !ol[4 * tex + c].elsewhere;
        textures += on_grid > 0;
    }
    size_t len = 0;
    len += (size_t)snprintf(w, n, "%d light%s (%s), %d texture%s", p->light_count, p->light_count == 1 ? "" : "s",
                            propagate_method(p), textures, textures == 1 ? "" : "s");
    for (int tex = 0; 4 * tex < p->light_count && len < n; ++tex) {
        int count = p->light_count - 4 * tex < 4 ? p->light_count - 4 * tex : 4, on_grid = 0;
        for (int c = 0; c < count; ++c) on_grid += !ol[4 * tex + c].elsewhere;
        if (on_grid)
            len += (size_t)snprintf(w + len, n - len, " key %016llx",
                                    (unsigned long long)veil_opv_texture_key(p->ev_key, &p->opv, ol + 4 * tex, count));
    }
    for (int q = 0; q < n_suns && len < n; ++q) {
        int faces = 0;
        for (int f = 0; f < 6; ++f) faces += suns[q].space.face[f].nz > 0;
        char shape[32] = "";
        if (suns[q].space.perspective) snprintf(shape, sizeof shape, " (%d faces around it)", faces);
        len += (size_t)snprintf(w + len, n - len, "%s light %d in a light-space grid of %dx%dx%d nodes%s %.3g voxels "
                                "apart across, key %016llx", q ? "," : ";", suns[q].light, suns[q].space.nodes[0],
                                suns[q].space.nodes[1], suns[q].space.nodes[2], shape, (double)suns[q].space.across,
                                (unsigned long long)sun_keys[q]);
    }
    return VEIL_STAGE_RAN;
}

static veil_result propagate_build(veil_frame* f, veil_stage_report* rep, veil_error* err)
{
    veil_frame_parts* r = f->parts;
    const veil_frame_plan* p = &f->plan;
    veil_render_stats* st = f->st;
    veil_opv_report orep = {0};
    const veil_ev_sparse* sp = veil_ev_sparse_of(r->ev);
    veil_result res = veil_opv_set_update(r->opv, p->grid, veil_ev_texture(r->ev),
                                          p->o.no_skip ? 0 : veil_ev_occupancy(r->ev), sp, p->ev_key, p->lights,
                                          p->light_count, &p->opv, &orep, err);
    if (res != VEIL_OK) return res;
    r->has[VEIL_STAGE_PROPAGATE] = 1, r->kept[VEIL_STAGE_PROPAGATE] = rep->key;
    r->opv_textures = orep.computed + orep.cached;
    st->opv_computed = orep.computed;
    st->opv_cached = orep.cached;
    st->grids = orep.suns;
    st->grids_computed = orep.suns_computed;
    st->propagate_iterations = orep.iterations;
    rep->status = orep.computed || orep.suns_computed ? VEIL_STAGE_RAN : VEIL_STAGE_CACHED;
    char from[64] = "";
    if (p->emission_lights) snprintf(from, sizeof from, " (+%d from the emission)", p->emission_lights);
    char suns[128] = "";
    if (orep.suns)
        snprintf(suns, sizeof suns, "; %d light%s in light-space grids (%d computed), %.3g voxels apart across",
                 orep.suns, orep.suns > 1 ? "s" : "", orep.suns_computed, orep.sun_across);
    if (rep->status == VEIL_STAGE_RAN)
        say(rep->why, sizeof rep->why, "%d of %zu lights%s, %s, %d passes; %d textures computed (volume or light moved), %d cached%s; "
            "%.1f MiB", p->light_count - p->emission_lights, p->scene->light_count, from, propagate_method(p),
            orep.iterations, orep.computed, orep.cached, suns, orep.mib);
    else
        say(rep->why, sizeof rep->why, "%d lights, %s: the volume, method and lights' geometry are unchanged", p->light_count,
            propagate_method(p));
    return VEIL_OK;
}

static void propagate_settle(veil_frame* f, const veil_stage_report* rep)
{
    if (f->parts && rep->status == VEIL_STAGE_CACHED && f->st->opv_computed == 0 && f->st->opv_cached == 0) {
        f->st->opv_cached = f->parts->opv_textures; /* decided: every texture and grid is the kept one */
        f->st->grids = f->plan.sun_count;
    }
}

/* ---- volumetric: multiply scattered light, view-independent ----------- */

/* Sources of the volumetric field: the lights, and for the light cache the medium's emission and the
 * environment's rest. */
static int volumetric_sources(const veil_frame_plan* p)
{
    const int cache = p->volumetric.kind == VEIL_FIELD_CACHE;
    return p->light_count + (cache && p->volumetric.cache.emission) + (cache && p->volumetric.cache.environment);
}

static uint64_t volumetric_key(const veil_frame_plan* p)
{
    if (p->volumetric.kind == VEIL_FIELD_NONE || volumetric_sources(p) == 0) return 0;
    /* under veil fog the frame's surfaces absorb the cache's photons: its depth is part of the key */
    uint64_t key = veil_volumetric_key(p->ev_key, &p->volumetric);
    return p->o.behind_not_solid ? key : veil_solid_key(key, p->o.width, p->o.height, p->o.behind_distance);
}

static veil_stage_status volumetric_decide(const veil_frame_plan* p, int kept, char* w, size_t n)
{
    const veil_multiple* m = &p->scene->multiple;
    const veil_volumetric_desc* d = &p->volumetric;
    const int escape = d->kind == VEIL_FIELD_ESCAPE;
    if (d->kind == VEIL_FIELD_NONE) {
        say(w, n, "%s", m->volumetric ? "the octaves need no field (their gate is the legs through each point)"
                                      : "no volumetric estimate (multiple_scattering.volumetric)");
        return VEIL_STAGE_SKIPPED;
    }
    const int cache = d->kind == VEIL_FIELD_CACHE;
    if (volumetric_sources(p) == 0) {
        say(w, n, "no light reaches the medium%s", cache ? " and it does not glow" : "");
        return VEIL_STAGE_SKIPPED;
    }
    if (p->sparse && !escape && !cache) {
        say(w, n, "the diffusion solve needs a dense grid; over a sparse volume there is no volumetric estimate "
                  "(set multiple_scattering.volumetric_method to \"octave\")");
        return VEIL_STAGE_SKIPPED;
    }
    veil_volumetric_desc dd = *d;
    dd.medium.sparse = NULL;
    float lo[3], cell;
    int dims[3];
    if (!(p->sparse && !cache ? p->grid != NULL : veil_volumetric_grid(&dd, lo, &cell, dims) != 0)) {
        say(w, n, "no grid: no medium, or a fog box over %g m%s", VEIL_DIFFUSION_MAX_EXTENT,
            escape ? " (the octaves fall back to the legs gate)"
                   : cache ? " (the march's octaves, gated by the legs, stand in for the light cache)" : "");
        return VEIL_STAGE_SKIPPED;
    }
    if (kept) {
        say(w, n, "the volume, lights and medium are unchanged");
        return VEIL_STAGE_CACHED;
    }
    const unsigned long long key = (unsigned long long)volumetric_key(p);
    if (escape && p->sparse)
        say(w, n, "key %016llx: the octaves' escape field, %d points a kept brick (every %.4g m): view- and "
            "light-independent, kept", key, VEIL_SPARSE_ESCAPE * VEIL_SPARSE_ESCAPE * VEIL_SPARSE_ESCAPE,
            (double)VEIL_BRICK / (VEIL_SPARSE_ESCAPE - 1) * p->grid->voxel);
    else if (cache)
        say(w, n, "key %016llx: the light cache, %lld photons from %d source%s%s, %dx%dx%d cells of %.4g m: "
            "view-independent, kept for the next frames", key, d->cache.photons, volumetric_sources(p),
            volumetric_sources(p) == 1 ? "" : "s",
            d->cache.emission && d->cache.environment ? " (the emission and the environment's rest two of them)"
            : d->cache.emission                       ? " (the emission one of them)"
            : d->cache.environment                    ? " (the environment's rest one of them)" : "",
            dims[0], dims[1], dims[2], cell);
    else if (escape)
        say(w, n, "key %016llx: the octaves' escape field, %dx%dx%d cells of %.4g m: view- and light-independent, "
            "kept", key, dims[0], dims[1], dims[2], cell);
    else
        say(w, n, "key %016llx: the diffusion fluence, %dx%dx%d cells of %.4g m, %d red-black sweeps: "
            "view-independent, kept for the next frames", key, dims[0], dims[1], dims[2], cell,
            veil_volumetric_sweeps(&dd, dims));
    return VEIL_STAGE_RAN;
}

static veil_result volumetric_build(veil_frame* f, veil_stage_report* rep, veil_error* err)
{
    veil_result sr = frame_solid(f, err);
    if (sr != VEIL_OK) return sr;
    veil_volumetric_desc d = f->plan.volumetric;
    d.medium = lit_medium(f);
    GLuint opv[VEIL_MAX_OPV_TEXTURES];
    for (int t = 0; t < VEIL_MAX_OPV_TEXTURES; ++t) opv[t] = veil_opv_set_texture(f->parts->opv, t);
    d.medium.opv = opv;
    veil_volumetric_report vr;
    veil_result res = veil_volumetric_update(f->parts->volumetric, &d, rep->key, &f->field, &vr, err);
    if (res != VEIL_OK) return res;
    f->parts->has[VEIL_STAGE_VOLUMETRIC] = 1, f->parts->kept[VEIL_STAGE_VOLUMETRIC] = rep->key;
    if (vr.skipped && vr.cache.too_thick) {
        rep->status = VEIL_STAGE_SKIPPED;
        say(rep->why, sizeof rep->why, "no light cache: the medium is too thick for photons (about %.3g steps a "
            "photon: %d photons would take over %d x the budget's %lld steps); the march's octaves, gated by the "
            "legs, stand in for it",
            vr.cache.steps, VEIL_CACHE_MIN_PHOTONS, VEIL_CACHE_STEPS_PER_PHOTON, d.cache.photons);
    } else if (!vr.skipped && vr.cache.too_thick) {
        say(rep->why, sizeof rep->why, "the light cache holds the environment's rest alone, %lld photons each to its "
            "first scattering, %dx%dx%d cells of %.4g m: the medium is too thick for more (about %.3g steps a photon); "
            "the march's octaves, gated by the legs, stand in for the higher orders", vr.cache.photons,
            vr.cache.dims[0], vr.cache.dims[1], vr.cache.dims[2], (double)vr.cache.cell, vr.cache.steps);
    } else if (vr.skipped) { /* decide() found a grid; the module did not: say so rather than hide it */
        rep->status = VEIL_STAGE_SKIPPED;
        say(rep->why, sizeof rep->why, "no grid was made for the field");
    } else if (d.kind == VEIL_FIELD_CACHE) {
        const veil_cache_report* c = &vr.cache;
        const int env = c->env_rest[0] > 0.0 || c->env_rest[1] > 0.0 || c->env_rest[2] > 0.0;
        say(rep->why, sizeof rep->why, "the light cache: %lld photons from %d source%s%s, %dx%dx%d cells of %.4g m, "
            "noise %.2g %% a cell (fluence-weighted RMS), %.1f MiB while built, %.1f MiB kept%s",
            c->photons, c->sources, c->sources == 1 ? "" : "s",
            env ? (c->sources == 1 ? " (the environment's rest)" : " (the environment's rest one of them)") : "",
            c->dims[0], c->dims[1], c->dims[2], (double)c->cell,
            100.0 * c->noise, c->bytes / 1048576.0,
            (double)c->dims[0] * c->dims[1] * c->dims[2] * 64.0 / 1048576.0, /* the texture: four rgba32f grids */
            c->cut || c->clamped ? "" : "");
        double e_in = VEIL_LUM_R * c->energy[VEIL_CACHE_ENERGY_IN][0] + VEIL_LUM_G * c->energy[VEIL_CACHE_ENERGY_IN][1] +
                      VEIL_LUM_B * c->energy[VEIL_CACHE_ENERGY_IN][2];
        if (e_in > 0.0) { /* the energy account: what scattered leaves or is absorbed (cut photons aside) */
            double out = 0.0, ab = 0.0;
            for (int k = 0; k < 3; ++k) {
                double l = k == 0 ? VEIL_LUM_R : (k == 1 ? VEIL_LUM_G : VEIL_LUM_B);
                out += l * c->energy[VEIL_CACHE_ENERGY_OUT][k];
                ab += l * c->energy[VEIL_CACHE_ENERGY_ABSORBED][k];
            }
            size_t len = strlen(rep->why);
            snprintf(rep->why + len, sizeof rep->why - len, "; of the light that scattered%s, %.1f %% left the grid, "
                     "%.1f %% was absorbed", env ? " or came into the grid as the environment's rest" : "", 100.0 * out / e_in,
                     100.0 * ab / e_in);
        }
        if (c->asked > c->photons) {
            size_t len = strlen(rep->why);
            snprintf(rep->why + len, sizeof rep->why - len, "; %lld photons asked for, fewer in a medium this thick "
                     "(about %.0f steps a photon)", c->asked, c->steps);
        }
        if (c->misses) {
            size_t len = strlen(rep->why);
            snprintf(rep->why + len, sizeof rep->why - len, "; %u densities above their cell's majorant (a bug)",
                     c->misses);
        }
        if (c->cut || c->clamped) {
            size_t len = strlen(rep->why);
            snprintf(rep->why + len, sizeof rep->why - len, "; %u photons cut at %d steps, %u scores clamped",
                     c->cut, c->cap, c->clamped);
        }
    }
    return VEIL_OK;
}

static void volumetric_settle(veil_frame* f, const veil_stage_report* rep)
{
    memset(&f->field, 0, sizeof f->field);
    if (f->parts && rep->status != VEIL_STAGE_SKIPPED) f->field = *veil_volumetric_field_of(f->parts->volumetric);
}

/* ---- render: the march ------------------------------------------------ */

static uint64_t per_view_key(const veil_frame_plan* p)
{
    (void)p;
    return 0; /* depends on the camera: nothing is kept */
}

static veil_stage_status render_decide(const veil_frame_plan* p, int kept, char* w, size_t n)
{
    (void)kept;
    const veil_multiple* ms = &p->scene->multiple;
    char multiple[200] = "";
    if (ms->volumetric && ms->volumetric_method == VEIL_VOLUMETRIC_CACHE)
        snprintf(multiple, sizeof multiple, ", orders >= 2 from the light cache%s (stage volumetric; where it is "
                 "not made, the octaves)", p->env_split ? ", every order of the environment's rest" : "");
    else if (ms->volumetric && ms->volumetric_method == VEIL_VOLUMETRIC_DIFFUSION)
        snprintf(multiple, sizeof multiple, ", multiple scattering from the diffusion field (stage volumetric)");
    else if (ms->volumetric && ms->octaves > 1)
        snprintf(multiple, sizeof multiple, ", volumetric multiple scattering: %d octaves (a %g, b %g, c %g) gated by %s",
                 ms->octaves, ms->octave_a, ms->octave_b, ms->octave_c,
                 ms->octave_gate == VEIL_GATE_ESCAPE ? "the escape field (stage volumetric)"
                                                     : "the legs through each point");
    say(w, n, "%dx%d, quality %s, step %g voxels, %d light%s%s%s: depends on the camera", p->o.width, p->o.height,
        veil_quality_name(p->o.quality), p->o.step_voxels, p->light_count, p->light_count == 1 ? "" : "s",
        p->fogs ? ", analytic fog in closed form" : "", multiple);
    return VEIL_STAGE_RAN;
}

static veil_result render_build(veil_frame* f, veil_stage_report* rep, veil_error* err)
{
    const veil_frame_plan* p = &f->plan;
    const veil_render_opts* o = &p->o;
    veil_result sr = frame_solid(f, err);
    if (sr != VEIL_OK) return sr;
    GLuint opv[VEIL_MAX_OPV_TEXTURES];
    for (int t = 0; t < VEIL_MAX_OPV_TEXTURES; ++t) opv[t] = veil_opv_set_texture(f->parts->opv, t);
    veil_march_desc md = {.medium = lit_medium(f), .camera = o->camera, .width = o->width, .height = o->height,
                          .step_voxels = o->step_voxels, .seed = o->seed, .skip_empty = !o->no_skip,
                          .max_distance = o->max_distance, .end_distance = o->behind_distance,
                          .no_background = o->behind != NULL, .field = &f->field,
                          .deep_raw = o->deep ? veil_deep_raw_samples(o->deep_samples) : 0,
                          .band_work = p->hardware ? VEIL_MARCH_DISPATCH_WORK : VEIL_MARCH_SOFTWARE_WORK,
                          .band_seconds = p->hardware ? 0.0 : VEIL_MARCH_BAND_SECONDS};
    md.medium.opv = opv;
    if (o->flat_only) { /* only what the steps after the march read (spread_build, the behind, the deep image) */
        const veil_multiple* ms = &p->scene->multiple;
        const int spread = ms->screen_space && (o->behind || !ms->volumetric);
        /* (the spread reads S where the march left it; T and Q's P for its decision, on the CPU) */
        md.skip_reads = VEIL_MARCH_READ_V | VEIL_MARCH_READ_Z | VEIL_MARCH_READ_S |
                        (spread && !ms->volumetric ? 0 : VEIL_MARCH_READ_Q) |
                        (spread || o->behind || o->deep ? 0 : VEIL_MARCH_READ_T);
    }
    /* the cache's later light gathered towards the camera: as the scene says, else the rung's where the
     * phase function's forward peak holds at least half its scattering (render/march.h) */
    const veil_quality_rung* q = veil_quality_rung_of(o->quality);
    const int gather = p->scene->multiple.cache_gather_rays;
    const veil_phase* ph = &p->scene->medium.phase;
    const int peaked = ph->type == VEIL_PHASE_HG && ph->g >= VEIL_GATHER_MIN_G;
    md.gather_rays = gather < 0 ? 0 : gather > 0 ? gather : peaked ? q->gather_rays : 0;
    md.gather_step = q->gather_step > 0.0f ? q->gather_step : 1.0f;
    md.gather_cells = q->gather_cells;
    if (f->solid.voxels) { /* what the lights and the cache saw of the frame's surfaces */
        size_t len = strlen(rep->why);
        snprintf(rep->why + len, sizeof rep->why - len, "; the frame's surfaces as a solid (scene/solid.h): "
                 "%dx%dx%d voxels of %.3g m, %zu solid, %d shadow map%s, made in %.0f ms", f->solid.dims[0],
                 f->solid.dims[1], f->solid.dims[2], (double)f->solid.voxel, f->solid.solid_count, f->solid.maps,
                 f->solid.maps == 1 ? "" : "s", f->solid_ms);
    }
    veil_result res = veil_march_run(f->parts->march, &md, f->images, err);
    const veil_march_readback rb = veil_march_last_readback(f->parts->march);
    if (res == VEIL_OK) {
        size_t len = strlen(rep->why);
        snprintf(rep->why + len, sizeof rep->why - len, "; %d image%s read back (%.0f MB) in %.0f ms%s", rb.images,
                 rb.images == 1 ? "" : "s", rb.bytes / 1e6, rb.ms, rb.made ? ", the images made for this size" : "");
    }
    const veil_march_gather g = veil_march_last_gather(f->parts->march);
    if (res == VEIL_OK && g.rays > 0) {
        size_t len = strlen(rep->why);
        snprintf(rep->why + len, sizeof rep->why - len, "; the cache's later light gathered towards the camera "
                 "(render/march.h): %d rays a cell, %dx%dx%d cells, steps of %.3g cells, %.0f ms", g.rays, g.dims[0],
                 g.dims[1], g.dims[2], (double)g.step, g.ms);
    }
    if (res == VEIL_OK && o->behind) { /* what is behind, attenuated: T L */
        veil_image_set* im = f->images;
        size_t pixels = (size_t)im->width * (size_t)im->height;
        for (size_t i = 0; i < pixels; ++i)
            for (int c = 0; c < 3; ++c) im->rgba[4 * i + c] += im->aov_t[4 * i + c] * o->behind[4 * i + c];
    }
    return res;
}

/* ---- spread: screen-space multiple scattering -------------------------- */

/* What the spread moves (docs/multiple-scattering.md): the light from
 * behind the medium that it scatters without absorbing (veil fog's frame;
 * the scene's background is a backdrop that lights nothing, as in the
 * reference path tracer, so it is not spread), and, when the volumetric
 * estimate is off, the single scattering's light scattered on its way to
 * the camera (aov_q). With the volumetric estimate on, the medium's higher
 * orders are its: spreading aov_q too would count them twice. */
static veil_stage_status spread_decide(const veil_frame_plan* p, int kept, char* w, size_t n)
{
    (void)kept;
    const veil_multiple* m = &p->scene->multiple;
    if (!m->screen_space) {
        say(w, n, "off in the scene (multiple_scattering.screen_space)");
        return VEIL_STAGE_SKIPPED;
    }
    if (!p->o.behind && m->volumetric) {
        say(w, n, "nothing to spread: the volumetric estimate carries the medium's higher orders and the "
                  "background is a backdrop (veil fog spreads its frame)");
        return VEIL_STAGE_SKIPPED;
    }
    say(w, n, "unless the view is optically thin (max P sigma_s < %g): depends on the camera", m->thin_threshold);
    return VEIL_STAGE_RAN;
}

/* The vertical field of view of a width x height image (the camera's fov spans the side its sensor fit names):
 * the spread's pixel footprint. */
static float vertical_fov_deg(const veil_camera* c, int width, int height)
{
    double tx, ty;
    veil_camera_tan_half(c, width, height, &tx, &ty);
    return (float)(atan(ty) * 360.0 / VEIL_PI);
}

static veil_result spread_build(veil_frame* f, veil_stage_report* rep, veil_error* err)
{
    const veil_frame_plan* p = &f->plan;
    const veil_scene* s = p->scene;
    const veil_render_opts* o = &p->o;
    const veil_multiple* m = &s->multiple;
    veil_image_set* im = f->images;
    const float* q = m->volumetric ? NULL : im->aov_q;
    float thick = veil_spread_max_scattering(s, im->aov_t, q, im->width, im->height);
    if (!(thick >= m->thin_threshold)) {
        rep->status = VEIL_STAGE_SKIPPED;
        say(rep->why, sizeof rep->why, "optically thin view: max P sigma_s = %.3g < thin_threshold %g", thick, m->thin_threshold);
        return VEIL_OK;
    }
    size_t floats = (size_t)im->width * (size_t)im->height * 4;
    im->aov_m = malloc(floats * sizeof(float));
    if (!im->aov_m) return veil_fail(err, VEIL_ERR_OOM, "out of memory for the spread image");
    /* T, S and Q read where the march left them (its images: no upload of the buffers read back) */
    unsigned int march_images[VEIL_MARCH_IMAGES];
    veil_march_images(f->parts->march, march_images);
    veil_spread_input in = {.width = im->width, .height = im->height, .L = o->behind, .background = {0, 0, 0},
                            .aov_t = im->aov_t, .aov_s = im->aov_s, .aov_q = q,
                            .fov_y_deg = vertical_fov_deg(o->camera, im->width, im->height),
                            .tex_t = march_images[1], .tex_s = march_images[2], .tex_q = q ? march_images[4] : 0};
    veil_spread_report sr = {0};
    veil_result res = veil_spread_run(f->parts->spread, s, &in, im->aov_m, NULL, &sr, err);
    if (res != VEIL_OK) return res;
    for (size_t i = 0; i < floats; i += 4)
        for (int c = 0; c < 3; ++c) im->rgba[i + (size_t)c] += im->aov_m[i + (size_t)c];
    say(rep->why, sizeof rep->why, "max P sigma_s = %.3g >= %g: spreads %s%s%s; %d levels on %dx%d, %s filter: depends on the camera",
        thick, m->thin_threshold, o->behind ? "the frame behind" : "", o->behind && q ? " and " : "",
        q ? "single scattering's out-scattered light" : "", sr.levels, sr.padded_width, sr.padded_height,
        m->filter == VEIL_SPREAD_2X2 ? "2x2" : m->filter == VEIL_SPREAD_6X6 ? "6x6" : "4x4");
    return VEIL_OK;
}

/* ---- the table --------------------------------------------------------- */

const veil_stage_row veil_stage_table[VEIL_STAGE_COUNT] = {
    {VEIL_STAGE_INJECT, 0, "inject", inject_key, inject_decide, inject_build, inject_settle},
    {VEIL_STAGE_PROPAGATE, 0, "propagate", propagate_key, propagate_decide, propagate_build, propagate_settle},
    {VEIL_STAGE_VOLUMETRIC, 0, "multiple scattering", volumetric_key, volumetric_decide, volumetric_build,
     volumetric_settle},
    {VEIL_STAGE_RENDER, 1, "march", per_view_key, render_decide, render_build, NULL},
    {VEIL_STAGE_SPREAD, 1, "spread", per_view_key, spread_decide, spread_build, NULL},
};
