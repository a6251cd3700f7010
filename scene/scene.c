/* veil — releasing a scene, and the particles its sources describe. */
#include "scene.h"

#include <stdlib.h>
#include <string.h>

void veil_scene_free(veil_scene* s)
{
    if (!s) return;
    for (size_t i = 0; i < s->medium.source_count; ++i) {
        free(s->medium.sources[i].particles);
        free(s->medium.sources[i].vdb.file);
        free(s->medium.sources[i].vdb.grid);
    }
    free(s->medium.sources);
    free(s->lights);
    free(s->path);
    free(s->base_dir);
    memset(s, 0, sizeof *s);
}

static size_t source_particles(const veil_source* src)
{
    if (src->type == VEIL_SOURCE_RBF) return src->particle_count;
    return src->type == VEIL_SOURCE_RBF_RANDOM ? src->random.count : 0;
}

veil_result veil_scene_particles(const veil_scene* s, veil_particle** out,
                                 size_t* count, veil_error* err)
{
    if (!s || !out || !count) return veil_fail(err, VEIL_ERR_INVALID, "veil_scene_particles: NULL argument");
    *out = NULL, *count = 0;
    const char* name = s->path ? s->path : "<scene>";
    size_t total = 0, bytes, k = 0;
    for (size_t i = 0; i < s->medium.source_count; ++i) {
        size_t n = source_particles(&s->medium.sources[i]);
        if (n > VEIL_SCENE_MAX_PARTICLES - total)
            return veil_fail(err, VEIL_ERR_LIMIT, "%s: medium.sources[%zu]: the sources hold more than %u "
                             "particles in total", name, i, VEIL_SCENE_MAX_PARTICLES);
        total += n;
    }
    /* at least one element, so that *out is never NULL on success */
    if (!veil_mul_sizes(total ? total : 1, sizeof(veil_particle), 1, 1, &bytes))
        return veil_fail(err, VEIL_ERR_LIMIT, "%s: %zu particles do not fit in memory", name, total);
    veil_particle* p = malloc(bytes);
    if (!p)
        return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory allocating %zu particles (%zu bytes)",
                         name, total, bytes);
    for (size_t i = 0; i < s->medium.source_count; ++i) {
        const veil_source* src = &s->medium.sources[i];
        size_t n = source_particles(src);
        if (n && src->type == VEIL_SOURCE_RBF) memcpy(p + k, src->particles, n * sizeof *p);
        else if (n && src->type == VEIL_SOURCE_RBF_RANDOM) veil_rbf_random_generate(&src->random, p + k);
        k += n;
    }
    *out = p, *count = total;
    return VEIL_OK;
}
