/* veil — the frame's plan (frame/stages.h): every setting of a frame
 * resolved once, before any stage runs and without a GPU — the quality
 * ladder, the lights that add light, the propagation's parameters, what
 * the volumetric stage is asked for — and the sparse volume's work
 * estimate. The stages' rows (frame/stages.c) read it. */
#include "stages.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../propagate/lit_medium.h"
#include "../propagate/opv_set.h"
#include "../volume/ev.h"
#include "../volume/scene_volume.h"

/* ---- the plan ---------------------------------------------------------- */

/* The ladder, chosen from bench/peers.py --knobs (docs/performance.md):
 * each rung slower and more accurate than the one below it on the shared
 * smoke, none dominated on the three scenes of bench/peers.py. The gather's
 * cells (the last field) from bench/multiple_scattering.py on the two
 * cumulus views (docs/multiple-scattering.md, "The gather's grid"): at the
 * default 24 a side cost 0.2-0.3 of the 40 a side the cache has, for
 * 4x4-block errors of 8.9-9.1 % against 7.5-9.3 %. */
static const veil_quality_rung rungs[VEIL_QUALITY_COUNT] = {
    [VEIL_QUALITY_DRAFT] = {1.0f, VEIL_OPV_LIGHT_SPACE, 1.0f, 4.0f, 1LL << 16, 24, 0, 0.0f, 0, VEIL_ENV_LIGHTS_DRAFT},
    [VEIL_QUALITY_DEFAULT] = {0.5f, VEIL_OPV_LIGHT_SPACE, 0.5f, 4.0f, 1LL << 18, 40, 16, 2.0f, 24, VEIL_ENV_LIGHTS_DEFAULT},
    [VEIL_QUALITY_HIGH] = {0.5f, VEIL_OPV_LIGHT_SPACE, 0.35f, 4.0f, 1LL << 20, 64, 16, 2.0f, 64, VEIL_ENV_LIGHTS_HIGH},
    [VEIL_QUALITY_MAX] = {0.25f, VEIL_OPV_LIGHT_SPACE, 0.25f, 4.0f, 1LL << 22, 96, 64, 2.0f, 48, VEIL_ENV_LIGHTS_HIGH},
};

const veil_quality_rung* veil_quality_rung_of(veil_quality q)
{
    return &rungs[q > VEIL_QUALITY_UNSET && q < VEIL_QUALITY_COUNT ? q : VEIL_QUALITY_DEFAULT];
}

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
    if (o.deep_samples <= 0) o.deep_samples = s->deep_samples > 0 ? s->deep_samples : VEIL_DEEP_DEFAULT_SAMPLES;
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

int veil_render_lights(const veil_scene* s, const veil_grid* g, int env_lights, int env_split, veil_light* out)
{
    int n = 0;
    if (!g && count_fogs(s) == 0) return 0; /* no medium at all */
    for (size_t l = 0; l < s->light_count && n < VEIL_MAX_LIGHTS; ++l)
        if (light_reaches(&s->lights[l], g)) out[n++] = s->lights[l];
    /* the environment as directional lights, after the scene's (scene/environment.h: the median cut) */
    const veil_env_cut* cut = veil_env_cut_for(&s->environment, env_lights);
    const int count = cut ? (env_split ? cut->bright_count : cut->count) : 0;
    const veil_light* lights = cut ? (env_split ? cut->bright : cut->lights) : NULL;
    for (int l = 0; l < count && n < VEIL_MAX_LIGHTS; ++l)
        if (light_reaches(&lights[l], g)) out[n++] = lights[l];
    return n;
}

/* The propagation parameters for s under resolved options o: the method,
 * the light-space spacing, the Jacobi tolerance on D that keeps sigma_t D
 * within VEIL_OPV_TAU_TOLERANCE, and (grid g, a device budget of `budget`
 * bytes; NULL or 0: none) the memory left for the suns' grids. */
static veil_opv_params opv_params(const veil_scene* s, const veil_render_opts* o, const veil_grid* g,
                                  unsigned long long budget)
{
    float st_max = 0.0f;
    for (int c = 0; c < 3; ++c) st_max = fmaxf(st_max, s->medium.sigma_a[c] + s->medium.sigma_s[c]);
    /* D changes of tol move tau by at most st_max * tol */
    veil_opv_params p = {.method = o->method,
                         .tolerance = st_max > 0.0f ? VEIL_OPV_TAU_TOLERANCE / st_max : INFINITY,
                         .sun_across = o->sun_across, .sun_along = o->sun_along};
    if (g && budget > 0) {
        /* what the device's budget leaves the suns' grids beside the EV and the rgba32f optical depths
         * veil_ev_check_budget counted (one per four lights, and one more) */
        double voxels = (double)g->dims[0] * g->dims[1] * g->dims[2];
        int n = (int)veil_scene_light_total(s) < VEIL_MAX_LIGHTS ? (int)veil_scene_light_total(s) : VEIL_MAX_LIGHTS;
        double used = voxels * 4.0 + voxels * 16.0 * ((n + 3) / 4 + 1);
        p.sun_bytes = (double)budget > used ? (double)budget - used : 1.0;
    }
    return p;
}

void veil_frame_plan_begin(veil_frame_plan* p, const veil_scene* s, const veil_render_opts* opts,
                           unsigned long long budget)
{
    memset(p, 0, sizeof *p);
    p->scene = s;
    p->o = veil_render_opts_resolve(opts, s);
    p->fogs = count_fogs(s);
    p->budget = budget;
    p->volume_needed = veil_scene_volume_needed(s);
}

/* What the volumetric stage is asked for: the octaves' escape field when they are gated by it, the
 * diffusion fluence when that is the method, else nothing. */
static veil_field_kind field_kind(const veil_multiple* m)
{
    if (m->volumetric && m->volumetric_method == VEIL_VOLUMETRIC_CACHE) return VEIL_FIELD_CACHE;
    int escape = m->volumetric_method == VEIL_VOLUMETRIC_OCTAVE && m->octave_gate == VEIL_GATE_ESCAPE;
    if (!m->volumetric || (m->volumetric_method == VEIL_VOLUMETRIC_OCTAVE && !escape) || m->octaves < 2 * escape)
        return VEIL_FIELD_NONE;
    return escape ? VEIL_FIELD_ESCAPE : VEIL_FIELD_FLUENCE;
}

int veil_env_split(const veil_scene* s)
{
    return s->environment.present && !s->environment.remainder_lights && field_kind(&s->multiple) == VEIL_FIELD_CACHE;
}

void veil_frame_plan_volume(veil_frame_plan* p, const veil_grid* g, int sparse, const veil_light* emission,
                            int n_emission)
{
    p->grid = g;
    p->sparse = g ? sparse : 0;
    p->env_split = veil_env_split(p->scene);
    if (p->env_split) { /* and only where the cache has a grid to hold it (a medium, fogs not too wide) */
        veil_volumetric_desc probe = {.kind = VEIL_FIELD_CACHE, .medium = {.scene = p->scene, .grid = g},
                                      .cache = {.cells = 8}};
        float lo[3], h;
        int dims[3];
        p->env_split = veil_volumetric_grid(&probe, lo, &h, dims);
    }
    p->light_count =
        veil_render_lights(p->scene, g, veil_quality_rung_of(p->o.quality)->env_lights, p->env_split, p->lights);
    const veil_multiple* m = &p->scene->multiple;
    /* the light cache carries all of the emission's light (volume/cache.h): it needs no emission lights */
    const int cache = field_kind(m) == VEIL_FIELD_CACHE;
    p->glows = 0;
    for (size_t i = 0; g && i < p->scene->medium.source_count; ++i) {
        const veil_source* src = &p->scene->medium.sources[i];
        p->glows |= (src->type == VEIL_SOURCE_VDB || src->type == VEIL_SOURCE_ARRAY) &&
                    (src->vdb.emission_grid || src->vdb.temperature_grid);
    }
    if (cache) n_emission = 0;
    /* the medium's emission as lights (volume/emission_lights.h): after the scene's, while there is room */
    if (n_emission > VEIL_MAX_LIGHTS - p->light_count) n_emission = VEIL_MAX_LIGHTS - p->light_count;
    for (int i = 0; i < n_emission; ++i) p->lights[p->light_count++] = emission[i];
    p->emission_lights = n_emission > 0 ? n_emission : 0;
    p->opv = opv_params(p->scene, &p->o, g, p->budget);
    /* the GL's 3D textures reach at least VEIL_GL_MIN_3D_TEXTURE texels an axis; a device may allow more */
    p->sun_count = g ? veil_opv_plan_suns(g, p->ev_key, p->lights, p->light_count, &p->opv,
                                          p->sparse ? 0 : VEIL_GL_MIN_3D_TEXTURE, p->index_lights, p->suns,
                                          p->sun_keys)
                     : 0;
    const veil_quality_rung* q = veil_quality_rung_of(p->o.quality);
    p->volumetric = (veil_volumetric_desc){
        .kind = field_kind(m),
        .medium = {.scene = p->scene, .lights = p->lights, .light_count = p->light_count, .grid = g,
                   .sparse = NULL},
        .diffusion_cells = m->diffusion_cells,
        .diffusion_iterations = m->diffusion_iterations,
        .cache = {.photons = m->cache_photons > 0 ? m->cache_photons : q->cache_photons,
                  .cells = m->cache_cells > 0 ? m->cache_cells : q->cache_cells,
                  .seed = m->cache_seed,
                  .emission = cache && p->glows,
                  .environment = p->env_split}};
}

veil_result veil_frame_sparse_estimate(const veil_frame_plan* p, const veil_scene_volume* v, veil_sparse_work* w,
                                       veil_error* err)
{
    memset(w, 0, sizeof *w);
    if (!v->has_volume || !v->sparse) return VEIL_OK;
    veil_sparse_census c;
    veil_result r = veil_sparse_census_of(v, &c, err);
    if (r == VEIL_OK) r = veil_sparse_census_check(&c, err);
    if (r != VEIL_OK) {
        veil_sparse_census_free(&c);
        return r;
    }
    /* the lights as the plan will hold them once the volume is made (inject's settle) */
    veil_frame_plan* q = malloc(sizeof *q);
    if (!q) {
        veil_sparse_census_free(&c);
        return veil_fail(err, VEIL_ERR_OOM, "out of memory estimating the sparse volume's work");
    }
    *q = *p;
    veil_frame_plan_volume(q, &v->grid, 1, NULL, 0);
    int lights = q->light_count;
    veil_index_light ol[VEIL_MAX_LIGHTS];
    memcpy(ol, q->index_lights, (size_t)lights * sizeof *ol);
    if (v->emission_count > 0 && v->emission_lights > 0) {
        /* the emission's lights come from the gather (if it glows at all): points at the grid's middle stand
         * for them */
        int room = VEIL_MAX_LIGHTS - lights, e = v->emission_lights < room ? v->emission_lights : room;
        for (int i = 0; i < e; ++i, ++lights) {
            memset(&ol[lights], 0, sizeof ol[lights]);
            ol[lights].type = VEIL_LIGHT_POINT;
            for (int a = 0; a < 3; ++a) {
                ol[lights].v[a] = 0.5f * (float)v->grid.dims[a] - 0.5f; /* voxel i's centre at i */
                ol[lights].c[a] = v->grid.dims[a] / 2;
            }
        }
    }
    memcpy(w->dims, v->grid.dims, sizeof w->dims);
    w->bricks = (double)c.count;
    w->lights = lights;
    for (int l = 0; l < lights; ++l) {
        w->passes += (double)veil_opv_sparse_passes(c.coords, c.count, &ol[l]);
        w->od_units += veil_sparse_od_units(&c, &ol[l]) / lights;
    }
    w->od_rays = (double)c.count * (VEIL_SPARSE_APRON * VEIL_SPARSE_APRON * VEIL_SPARSE_APRON) * lights;
    if (lights > 0 && q->volumetric.kind == VEIL_FIELD_ESCAPE) { /* volumetric_decide: the fluence is skipped */
        w->escape_rays = veil_volumetric_sparse_escape_rays((double)c.count);
        w->escape_units = veil_sparse_escape_units(&c);
    }
    free(q);
    veil_sparse_census_free(&c);
    return veil_sparse_work_check(w, err);
}
