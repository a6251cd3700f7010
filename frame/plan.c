#include "plan.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../volume/scene_volume.h"
#include "stages.h"

veil_result veil_frame_path(const char* path, long frame, int numbered, char* out, size_t n, veil_error* err)
{
    int len;
    if (!numbered) {
        len = snprintf(out, n, "%s", path);
    } else {
        const char* slash = strrchr(path, '/');
        const char* dot = strrchr(path, '.');
        if (!dot || (slash && dot < slash)) dot = path + strlen(path);
        len = snprintf(out, n, "%.*s_%04ld%s", (int)(dot - path), path, frame, dot);
    }
    if (len < 0 || (size_t)len >= n) return veil_fail(err, VEIL_ERR_LIMIT, "%s: the frame's file name is too long", path);
    return VEIL_OK;
}

/* A growing text. */
typedef struct text {
    char* s;
    size_t len, cap;
    int oom;
} text;

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static void put(text* t, const char* fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0 || t->oom) return;
    if (t->len + (size_t)n + 1 > t->cap) {
        size_t cap = (t->cap ? 2 * t->cap : 1024) + (size_t)n;
        char* s = realloc(t->s, cap);
        if (!s) {
            t->oom = 1;
            return;
        }
        t->s = s, t->cap = cap;
    }
    va_start(ap, fmt);
    vsnprintf(t->s + t->len, t->cap - t->len, fmt, ap);
    va_end(ap);
    t->len += (size_t)n;
}

static const char* light_type_name(int type)
{
    return type == VEIL_LIGHT_POINT ? "point" : type == VEIL_LIGHT_DIRECTIONAL ? "directional" : "spot";
}

/* "frame 1" / "frames 1-9" for the frames after the first. */
static void later_frames(text* t, long frames)
{
    if (frames == 2) put(t, "frame 1");
    else put(t, "frames 1-%ld", frames - 1);
}

/* The lights the plan keeps and why each other is dropped. */
static void explain_lights(text* t, const veil_frame_plan* p)
{
    const veil_scene* s = p->scene;
    if (p->emission_possible && p->light_count < VEIL_MAX_LIGHTS) {
        int room = VEIL_MAX_LIGHTS - p->light_count;
        put(t, "emission   up to %d point lights made at inject from the emission (multiple_scattering.emission_lights; "
            "their textures are not counted below)\n", s->multiple.emission_lights < room ? s->multiple.emission_lights : room);
    }
    int k = 0;
    for (size_t l = 0; l < s->light_count; ++l) {
        const veil_light* li = &s->lights[l];
        int is_used = k < p->light_count && !memcmp(&p->lights[k], li, sizeof *li);
        k += is_used;
        const char* why = is_used ? "adds light"
                          : !(li->color[0] > 0.0f || li->color[1] > 0.0f || li->color[2] > 0.0f) ? "dropped: zero colour"
                          : (!p->grid && !p->fogs)                                                 ? "dropped: no medium"
                                                                   : "dropped: its cone misses the volume";
        put(t, "light %-3zu  %-11s %s\n", l, light_type_name(li->type), why);
    }
    const veil_environment* env = &s->environment;
    if (env->present) {
        int used = 0;
        const veil_env_cut* cut = veil_env_cut_for(env, veil_quality_rung_of(p->o.quality)->env_lights);
        const int count = cut ? (p->env_split ? cut->bright_count : cut->count) : 0;
        const veil_light* lights = cut ? (p->env_split ? cut->bright : cut->lights) : NULL;
        for (int c = 0; c < count; ++c, ++k) used += k < p->light_count && !memcmp(&p->lights[k], &lights[c], sizeof *lights);
        const char* room = cut && cut->k < (env->lights > 0 ? env->lights : veil_quality_rung_of(p->o.quality)->env_lights)
                               ? ", the room the other lights leave" : "";
        const char* whose = env->lights > 0 ? "its \"lights\"" : "the quality's";
        if (p->env_split) {
            double all[3], bright[3];
            veil_env_integral(env, all);
            veil_env_part_integral(env, 1, bright);
            const double lum_all = VEIL_LUM_R * all[0] + VEIL_LUM_G * all[1] + VEIL_LUM_B * all[2];
            const double share = lum_all > 0.0 ? (VEIL_LUM_R * bright[0] + VEIL_LUM_G * bright[1] + VEIL_LUM_B * bright[2]) / lum_all : 0.0;
            put(t, "light %-3zu  environment %s: its bright part (above %g times its mean luminance: %.3g %% of its "
                   "light) as %d directional light%s of its median cut into at most %d%s (%s); the rest, %.3g %%, "
                   "by the light cache's photons%s\n",
                env->light_index, env->file ? env->file : "(a constant sky)", VEIL_ENV_CLIP, 100.0 * share, used,
                used == 1 ? "" : "s", cut ? cut->k : 0, room, whose, 100.0 * (1.0 - share),
                lum_all > 0.0 ? "" : "; black, lights nothing");
        } else {
            put(t, "light %-3zu  environment %s: %d directional light%s of its median cut into %d%s (%s)%s\n",
                env->light_index, env->file ? env->file : "(a constant sky)", used, used == 1 ? "" : "s",
                cut ? cut->k : 0, room, whose,
                count == 0 ? "; black, lights nothing" : used < count ? "; the rest: no medium" : "");
        }
        for (int c = 0; c < count; ++c) {
            const veil_light* L = &lights[c];
            put(t, "           cut %-2d direction [%.9g, %.9g, %.9g] irradiance [%.9g, %.9g, %.9g]\n", c, L->direction[0],
                L->direction[1], L->direction[2], L->color[0], L->color[1], L->color[2]);
        }
    }
}

/* Opens the volume as the files' headers describe it (no density reaches a GPU) into f's plan. */
static veil_result plan_open(veil_frame* f, const veil_scene* s, const veil_render_opts* opts, veil_scene_volume* v,
                             veil_error* err)
{
    memset(f, 0, sizeof *f);
    memset(v, 0, sizeof *v);
    veil_frame_plan* p = &f->plan;
    veil_frame_plan_begin(p, s, opts, 0); /* no device here: no memory budget */
    veil_result r = p->volume_needed ? veil_scene_volume_open(s, v, err) : VEIL_OK;
    if (r != VEIL_OK) return r;
    p->grid = v->has_volume ? &v->grid : NULL;
    p->sparse = v->sparse;
    p->particles = v->particle_count;
    p->vdb_voxels = v->vdb_voxels;
    p->resolution = p->volume_needed ? v->resolution : NULL;
    p->emission_possible = p->grid && v->emission_count > 0 && s->multiple.emission_lights > 0;
    /* a sparse volume's work as a render estimates it before the gather; a refusal is part of the plan */
    veil_error why = {0};
    r = veil_frame_sparse_estimate(p, v, &p->sparse_work, &why);
    if (r == VEIL_ERR_LIMIT) snprintf(p->sparse_refusal, sizeof p->sparse_refusal, "%s", why.msg);
    else if (r != VEIL_OK) return veil_fail(err, r, "%s", why.msg);
    return VEIL_OK;
}

/* The walk: each row's key and decision on the first frame (nothing kept)
 * and on the later ones (the first frame's results kept), as
 * frame/renderer.c makes them; `why` of size n per report; t (NULL: none)
 * gets the text of --explain. */
static void walk(veil_frame* f, veil_stage_report* first, veil_stage_report* later, char* why, size_t n, long frames,
                 text* t)
{
    veil_frame_plan* p = &f->plan;
    for (int i = 0; i < VEIL_STAGE_COUNT; ++i) {
        const veil_stage_row* row = &veil_stage_table[i];
        const char* name = veil_stage_name(row->id);
        veil_stage_report* a = &first[row->id];
        veil_stage_report* b = &later[row->id];
        a->key = b->key = row->key(p);
        a->status = row->decide(p, 0, why, n);
        snprintf(a->why, sizeof a->why, "%s", why);
        if (t && a->status == VEIL_STAGE_SKIPPED)
            put(t, "%-10s skipped on every frame: %s\n", name, why);
        else if (t && row->per_view)
            put(t, "%-10s every frame: runs, %s\n", name, why);
        else if (t)
            put(t, "%-10s frame 0: runs, %s\n", name, why);
        /* the frames after the first find the first's results kept (a stage that was skipped keeps
         * nothing: it is skipped again; one that depends on the camera runs again) */
        b->status = row->decide(p, a->status != VEIL_STAGE_SKIPPED && !row->per_view, why, n);
        snprintf(b->why, sizeof b->why, "%s", why);
        if (t && frames > 1 && a->status == VEIL_STAGE_RAN && !row->per_view) {
            put(t, "           ");
            later_frames(t, frames);
            put(t, ": %s (%s; the key holds no camera)\n", veil_stage_status_name(b->status), why);
        }
        if (row->settle) row->settle(f, a);
        if (t && row->id == VEIL_STAGE_INJECT) explain_lights(t, p);
    }
}

veil_result veil_plan_reports(const veil_scene* s, const veil_render_opts* opts, veil_stage_report* first,
                              veil_stage_report* later, veil_error* err)
{
    veil_frame f;
    veil_scene_volume v;
    veil_result r = plan_open(&f, s, opts, &v, err);
    if (r == VEIL_OK && f.plan.sparse_refusal[0]) /* the render refuses it before any stage runs */
        r = veil_fail(err, VEIL_ERR_LIMIT, "%s", f.plan.sparse_refusal);
    if (r == VEIL_OK) {
        char why[VEIL_STAGE_WHY_MAX];
        walk(&f, first, later, why, sizeof why, 2, NULL);
    }
    veil_scene_volume_close(&v);
    return r;
}

veil_result veil_plan_explain(const veil_scene* s, const veil_render_opts* opts, long frames, char** out,
                              veil_error* err)
{
    *out = NULL;
    if (frames < 1) return veil_fail(err, VEIL_ERR_INVALID, "explain: %ld frames (at least 1)", frames);
    veil_frame f;
    veil_scene_volume v;
    veil_result r = plan_open(&f, s, opts, &v, err);
    if (r != VEIL_OK) {
        veil_scene_volume_close(&v);
        return r;
    }
    text t = {0};
    put(&t, "plan: %s, %ld frame%s of %dx%d%s\n", s->path ? s->path : "<scene>", frames, frames == 1 ? "" : "s",
        f.plan.o.width, f.plan.o.height, frames > 1 ? ", camera orbiting the look-at point (scene/camera.h)" : "");
    /* the same table, the same keys and decisions as a render (frame/stages.h) */
    char why[4096];
    veil_stage_report first[VEIL_STAGE_COUNT], later[VEIL_STAGE_COUNT];
    walk(&f, first, later, why, sizeof why, frames, &t);
    veil_scene_volume_close(&v);
    if (t.oom) {
        free(t.s);
        return veil_fail(err, VEIL_ERR_OOM, "out of memory writing the plan");
    }
    *out = t.s;
    return VEIL_OK;
}
