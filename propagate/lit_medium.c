#include "lit_medium.h"

#include <math.h>
#include <string.h>

#include "../gpu/gl_util.h"
#include "../scene/solid.h"

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
        const veil_sun_space* sp = &d->suns[k].space;
        u->sun_step[k][3] = (float)l;
        if (sp->perspective) {
            for (int a = 0; a < 3; ++a)
                u->sun_light[k][a] = d->grid->origin[a] + d->grid->voxel * (sp->origin[a] + 0.5f); /* index -> m */
            u->sun_light[k][3] = 1.0f;
            for (int a = 0; a < 3; ++a) u->sun_map[3 * k][a] = (float)sp->nodes[a];
            u->sun_map[3 * k][3] = sp->dz;
            u->sun_step[k][2] = (float)veil_point_space_pieces(sp);
            for (int f = 0; f < 6; ++f) {
                const veil_point_face* F = &sp->face[f];
                float* a = u->sun_face[12 * k + 2 * f];
                float* b = u->sun_face[12 * k + 2 * f + 1];
                a[0] = F->u0, a[1] = F->v0, a[2] = F->nz ? F->du : 1.0f, a[3] = F->z0;
                b[0] = (float)F->first, b[1] = (float)F->nu, b[2] = (float)F->nv, b[3] = (float)F->nz;
            }
            continue;
        }
        for (int row = 0; row < 3; ++row) memcpy(u->sun_map[3 * k + row], d->suns[k].to_tex[row], sizeof u->sun_map[0]);
        const float* c = sp->axis[2];
        float along = sqrtf(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        u->sun_step[k][0] = along * d->grid->voxel;
        u->sun_step[k][1] = (float)sp->nodes[2];
        u->sun_step[k][2] = ceilf(along); /* pieces of at most a voxel, as the prefix sum's panels */
    }
    for (int l = 0; l < n; ++l) /* the rest, in order */
        if (u->sun_of[l / 4][l % 4] == 0) u->on_opv[u->counts[3] / 4][u->counts[3] % 4] = l, ++u->counts[3];
    const veil_solid* so = d->solid;
    if (so && so->voxels && d->solid_voxels && d->solid_maps) {
        set3(u->solid_origin, so->origin, so->voxel);
        for (int a = 0; a < 3; ++a) u->solid_dims[a] = so->dims[a];
        u->solid_dims[3] = so->maps < n ? so->maps : n;
        for (int l = 0; l < u->solid_dims[3]; ++l) {
            memcpy(u->shadow[3 * l], so->rows[l][0], sizeof u->shadow[0]);
            memcpy(u->shadow[3 * l + 1], so->rows[l][1], sizeof u->shadow[0]);
            u->shadow[3 * l + 2][0] = so->bias[l][0], u->shadow[3 * l + 2][1] = so->bias[l][1];
        }
    }
}

void veil_lit_medium_bind_depths(const veil_lit_medium* d)
{
    glBindTextureUnit(VEIL_TEX_SOLID, d ? d->solid_voxels : 0);
    glBindTextureUnit(VEIL_TEX_SHADOW, d ? d->solid_maps : 0);
    for (int t = 0; t < VEIL_MAX_OPV_TEXTURES; ++t) glBindTextureUnit(VEIL_TEX_OPV0 + t, d && d->opv ? d->opv[t] : 0);
    if (d && d->sparse) return; /* the sparse tables hold these units */
    for (int k = 0; k < VEIL_MAX_SUNS; ++k)
        glBindTextureUnit(VEIL_TEX_SUN0 + k, d && d->grid && k < d->sun_count ? d->suns[k].texture : 0);
}

veil_result veil_lit_medium_solid_textures(const veil_solid* s, GLuint tex[2], veil_error* err)
{
    tex[0] = tex[1] = 0;
    if (!s->voxels) return VEIL_OK;
    veil_result r = veil_gl_texture3d(GL_R8, s->dims, "veil fog: the frame's solid", &tex[0], err);
    if (r != VEIL_OK) return r;
    glTextureParameteri(tex[0], GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(tex[0], GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1); /* rows of dims[0] bytes */
    glTextureSubImage3D(tex[0], 0, 0, 0, 0, s->dims[0], s->dims[1], s->dims[2], GL_RED, GL_UNSIGNED_BYTE, s->voxels);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &tex[1]);
    glTextureStorage3D(tex[1], 1, GL_R32F, VEIL_SOLID_MAP, VEIL_SOLID_MAP, s->maps > 0 ? s->maps : 1);
    glTextureParameteri(tex[1], GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(tex[1], GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    if (s->maps > 0)
        glTextureSubImage3D(tex[1], 0, 0, 0, 0, VEIL_SOLID_MAP, VEIL_SOLID_MAP, s->maps, GL_RED, GL_FLOAT, s->depth);
    glObjectLabel(GL_TEXTURE, tex[1], -1, "veil fog: shadow maps of the frame's solid");
    r = veil_gl_check("veil fog: the frame's solid", err);
    if (r != VEIL_OK) {
        glDeleteTextures(2, tex);
        tex[0] = tex[1] = 0;
    }
    return r;
}
