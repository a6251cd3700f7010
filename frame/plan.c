#include "plan.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../propagate/opv_set.h"
#include "../volume/scene_volume.h"

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

/* "frames 1-9" / "frame 1" for the frames after the first. */
static void later_frames(text* t, long frames)
{
    if (frames == 2) put(t, "frame 1");
    else put(t, "frames 1-%ld", frames - 1);
}

veil_result veil_plan_explain(const veil_scene* s, const veil_render_opts* opts, long frames, char** out,
                              veil_error* err)
{
    *out = NULL;
    if (frames < 1) return veil_fail(err, VEIL_ERR_INVALID, "explain: %ld frames (at least 1)", frames);
    veil_render_opts o = veil_render_opts_resolve(opts, s);
    text t = {0};
    put(&t, "plan: %s, %ld frame%s of %dx%d%s\n", s->path ? s->path : "<scene>", frames, frames == 1 ? "" : "s",
        o.width, o.height, frames > 1 ? ", camera orbiting the look-at point (scene/camera.h)" : "");
    veil_scene_volume v;
    memset(&v, 0, sizeof v);
    veil_result r = VEIL_OK;
    uint64_t ev_key = veil_scene_volume_key(s);
    int needed = veil_scene_volume_needed(s);
    if (needed) r = veil_scene_volume_open(s, &v, err);
    if (r != VEIL_OK) {
        free(t.s);
        return r;
    }
    const veil_grid* g = v.has_volume ? &v.grid : NULL;
    int fogs = 0;
    for (size_t i = 0; i < s->medium.source_count; ++i) fogs += s->medium.sources[i].type == VEIL_SOURCE_EXPONENTIAL;

    /* inject */
    if (!g) {
        put(&t, "inject     skipped on every frame: %s%s\n",
            needed ? "the sources hold no density" : "no voxelised source",
            fogs ? " (analytic fog: closed form, never voxelised)" : "");
    } else {
        put(&t, "inject     frame 0: runs, key %016llx: %zu particles, %zu VDB voxels -> grid %dx%dx%d, voxel %.4g m\n",
            (unsigned long long)ev_key, v.particle_count, v.vdb_voxels, g->dims[0], g->dims[1], g->dims[2], g->voxel);
        put(&t, "           %s\n", v.resolution);
        if (frames > 1) {
            put(&t, "           ");
            later_frames(&t, frames);
            put(&t, ": cached (the key holds the sources' descriptions and files' identities, not the camera)\n");
        }
    }

    /* lights, then propagate */
    veil_light used[VEIL_MAX_LIGHTS];
    int n = veil_render_lights(s, g, used);
    if (g && v.emission_count > 0 && s->multiple.emission_lights > 0 && n < VEIL_MAX_LIGHTS)
        put(&t, "emission   up to %d point lights made at inject from the emission (multiple_scattering.emission_lights; "
            "their textures are not counted below)\n", s->multiple.emission_lights < VEIL_MAX_LIGHTS - n
                                                          ? s->multiple.emission_lights : VEIL_MAX_LIGHTS - n);
    int k = 0;
    for (size_t l = 0; l < s->light_count; ++l) {
        const veil_light* li = &s->lights[l];
        int is_used = k < n && !memcmp(&used[k], li, sizeof *li);
        k += is_used;
        const char* why = is_used ? "adds light"
                          : !(li->color[0] > 0.0f || li->color[1] > 0.0f || li->color[2] > 0.0f) ? "dropped: zero colour"
                          : (!g && !fogs)                                                         ? "dropped: no medium"
                                                                   : "dropped: its cone misses the volume";
        put(&t, "light %-3zu  %-11s %s\n", l, light_type_name(li->type), why);
    }
    if (!g) {
        put(&t, "propagate  skipped on every frame: no volume%s\n", fogs ? " (the fog's optical depth is closed form)" : "");
    } else if (n == 0) {
        put(&t, "propagate  skipped on every frame: no light reaches the medium\n");
    } else {
        veil_opv_params params = veil_render_opv_params(s, &o, NULL, 0); /* no device here: no memory budget */
        veil_opv_light ol[VEIL_MAX_LIGHTS];
        veil_opv_sun suns[VEIL_MAX_SUNS];
        uint64_t sun_keys[VEIL_MAX_SUNS];
        /* the GL's 3D textures reach at least VEIL_GL_MIN_3D_TEXTURE texels an axis (no GL here) */
        int n_suns = veil_opv_plan_suns(g, ev_key, used, n, &params, v.sparse ? 0 : VEIL_GL_MIN_3D_TEXTURE, ol, suns,
                                        sun_keys);
        int textures = 0;
        for (int tex = 0; 4 * tex < n; ++tex) {
            int count = n - 4 * tex < 4 ? n - 4 * tex : 4, on_grid = 0;
            for (int c = 0; c < count; ++c) on_grid += !ol[4 * tex + c].elsewhere;
            textures += on_grid > 0;
        }
        put(&t, "propagate  frame 0: runs, %d light%s (%s), %d texture%s", n, n == 1 ? "" : "s",
            v.sparse ? "sparse: brick by brick in the light's order" : veil_opv_method_name(o.method), textures,
            textures == 1 ? "" : "s");
        for (int tex = 0; 4 * tex < n; ++tex) {
            int count = n - 4 * tex < 4 ? n - 4 * tex : 4, on_grid = 0;
            for (int c = 0; c < count; ++c) on_grid += !ol[4 * tex + c].elsewhere;
            if (on_grid)
                put(&t, " key %016llx", (unsigned long long)veil_opv_texture_key(ev_key, &params, ol + 4 * tex, count));
        }
        for (int q = 0; q < n_suns; ++q) {
            const float* a = suns[q].space.axis[0];
            put(&t, "%s light %d in a light-space grid of %dx%dx%d nodes %.3g voxels apart across, key %016llx",
                q ? "," : ";", suns[q].light, suns[q].space.nodes[0], suns[q].space.nodes[1], suns[q].space.nodes[2],
                sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]), (unsigned long long)sun_keys[q]);
        }
        put(&t, "\n");
        if (frames > 1) {
            put(&t, "           ");
            later_frames(&t, frames);
            put(&t, ": cached (the keys hold the volume, the method and the lights' geometry, not the camera)\n");
        }
    }

    /* render */
    put(&t, "render     every frame: runs, %dx%d, quality %s, step %g voxels, %d light%s%s (depends on the camera)\n",
        o.width, o.height, veil_quality_name(o.quality), o.step_voxels, n, n == 1 ? "" : "s",
        fogs ? ", analytic fog in closed form" : "");
    const veil_multiple* ms = &s->multiple;
    if (ms->volumetric && ms->volumetric_method == VEIL_VOLUMETRIC_DIFFUSION)
        put(&t, "           multiple scattering: the diffusion field (stage volumetric: once, %d cells along the "
                "longest side; kept while the volume and lights are unchanged)\n", ms->diffusion_cells);
    else if (ms->volumetric && ms->octaves > 1)
        put(&t, "           multiple scattering: volumetric, %d octaves (a %g, b %g, c %g) in the march, gated by %s\n",
            ms->octaves, ms->octave_a, ms->octave_b, ms->octave_c,
            ms->octave_gate == VEIL_GATE_ESCAPE ? "the escape field (stage volumetric: once per volume, kept while "
                                                  "the volume and medium are unchanged)"
                                                : "the legs through each point");
    /* the spread (frame/renderer.c): only the light from behind, or single scattering's when the
     * volumetric estimate is off; whether the view is optically thin is known only after the march */
    if (!ms->screen_space)
        put(&t, "spread     skipped: off in the scene (multiple_scattering.screen_space)\n");
    else if (ms->volumetric && !o.behind)
        put(&t, "spread     skipped: nothing to spread (the volumetric estimate carries the medium's higher orders; "
                "the background is a backdrop)\n");
    else
        put(&t, "spread     every frame: runs unless the view is optically thin (max P sigma_s < %g), "
                "depends on the camera\n", ms->thin_threshold);
    veil_scene_volume_close(&v);
    if (t.oom) {
        free(t.s);
        return veil_fail(err, VEIL_ERR_OOM, "out of memory writing the plan");
    }
    *out = t.s;
    return VEIL_OK;
}
