#include "lit_medium.h"

#include <math.h>
#include <string.h>

static void set3(float dst[4], const float src[3], float w)
{
    dst[0] = src[0], dst[1] = src[1], dst[2] = src[2], dst[3] = w;
}

void veil_lit_medium_fill(const veil_lit_medium* d, veil_medium_block* u)
{
    memset(u, 0, sizeof *u);
    const veil_medium* m = &d->scene->medium;
    for (int c = 0; c < 3; ++c) u->sigma_t[c] = m->sigma_a[c] + m->sigma_s[c];
    set3(u->sigma_s, m->sigma_s, 0.0f);
    u->shape[2] = m->phase.type == VEIL_PHASE_HG ? m->phase.g : 0.0f;
    if (d->grid) {
        float lo[3], hi[3], inv[3];
        veil_grid_medium_box(d->grid, lo, hi);
        for (int a = 0; a < 3; ++a) inv[a] = 1.0f / ((float)d->grid->dims[a] * d->grid->voxel);
        set3(u->box_min, lo, 0.0f);
        set3(u->box_max, hi, 0.0f);
        set3(u->tex_min, d->grid->origin, 0.0f);
        set3(u->tex_inv_size, inv, 0.0f);
        float md = VEIL_MIN_LIGHT_DISTANCE_VOXELS * d->grid->voxel;
        u->shape[0] = md * md;
        u->shape[1] = d->grid->voxel;
    } else {
        float md = VEIL_MIN_LIGHT_DISTANCE_VOXELS * VEIL_FOG_MIN_STEP;
        u->shape[0] = md * md;
    }
    u->shape[3] = d->grid != NULL && d->emission ? 1.0f : 0.0f;
    int fogs = 0;
    for (size_t i = 0; i < m->source_count && fogs < VEIL_MAX_FOGS; ++i) {
        const veil_source* src = &m->sources[i];
        if (src->type != VEIL_SOURCE_EXPONENTIAL) continue;
        veil_gpu_fog* f = &u->fogs[fogs++];
        set3(f->direction, src->fog.direction, src->fog.density);
        set3(f->origin, src->fog.origin, src->fog.falloff);
        set3(f->box_min, src->fog.bounds[0], 0.0f);
        set3(f->box_max, src->fog.bounds[1], 0.0f);
    }
    int n = d->light_count < VEIL_MAX_LIGHTS ? d->light_count : VEIL_MAX_LIGHTS;
    for (int l = 0; l < n; ++l) veil_light_to_gpu(&d->lights[l], &u->lights[l]);
    u->counts[0] = n, u->counts[1] = fogs, u->counts[2] = d->grid != NULL;
    for (int k = 0; d->grid && !d->sparse && k < d->sun_count && k < VEIL_MAX_SUNS; ++k) {
        int l = d->suns[k].light;
        if (l < 0 || l >= n) continue;
        u->sun_of[l / 4][l % 4] = k + 1;
        for (int row = 0; row < 3; ++row) memcpy(u->sun_map[3 * k + row], d->suns[k].to_tex[row], sizeof u->sun_map[0]);
        const float* c = d->suns[k].space.axis[2];
        float along = sqrtf(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        u->sun_step[k][0] = along * d->grid->voxel;
        u->sun_step[k][1] = (float)d->suns[k].space.nodes[2];
        u->sun_step[k][2] = ceilf(along); /* pieces of at most a voxel, as the prefix sum's panels */
    }
}

void veil_lit_medium_bind_depths(const veil_lit_medium* d)
{
    for (int t = 0; t < VEIL_MAX_OPV_TEXTURES; ++t) glBindTextureUnit(VEIL_TEX_OPV0 + t, d && d->opv ? d->opv[t] : 0);
    if (d && d->sparse) return; /* the sparse tables hold these units */
    for (int k = 0; k < VEIL_MAX_SUNS; ++k)
        glBindTextureUnit(VEIL_TEX_SUN0 + k, d && d->grid && k < d->sun_count ? d->suns[k].texture : 0);
}
