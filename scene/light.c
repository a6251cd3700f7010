#include "light.h"

#include <math.h>
#include <string.h>

float veil_light_cos_inner(const veil_light* l) { return cosf(l->inner_angle_deg * (float)(VEIL_PI / 180.0)); }

float veil_light_cos_outer(const veil_light* l) { return cosf(l->outer_angle_deg * (float)(VEIL_PI / 180.0)); }

static void set3(float dst[4], const float src[3], float w)
{
    dst[0] = src[0], dst[1] = src[1], dst[2] = src[2], dst[3] = w;
}

void veil_light_to_gpu(const veil_light* l, veil_gpu_light* out)
{
    set3(out->position, l->position, (float)l->type);
    set3(out->direction, l->direction, l->type == VEIL_LIGHT_POINT ? l->radius * l->radius : veil_light_cos_inner(l));
    set3(out->color, l->color, veil_light_cos_outer(l));
}

void veil_light_to_index(const veil_light* l, const int dims[3], const float origin[3], float voxel,
                         veil_index_light* out)
{
    memset(out, 0, sizeof *out);
    out->type = l->type == VEIL_LIGHT_DIRECTIONAL ? VEIL_LIGHT_DIRECTIONAL : VEIL_LIGHT_POINT;
    for (int a = 0; a < 3; ++a) {
        if (out->type == VEIL_LIGHT_POINT) {
            out->v[a] = (l->position[a] - origin[a]) / voxel - 0.5f;
            /* The light's voxel, at most VEIL_INDEX_LIGHT_FAR voxels beyond the grid on each axis:
             * further out, every voxel's distance to it along that axis grows by the same amount, so
             * the ordered passes take the voxels in the same order, and sums of three such distances
             * stay far inside int (a light at 1e15 m made them overflow: undefined behaviour). */
            double c = floor((double)out->v[a] + 0.5);
            double lo = -VEIL_INDEX_LIGHT_FAR, hi = (double)dims[a] - 1.0 + VEIL_INDEX_LIGHT_FAR;
            out->c[a] = (int)(c < lo ? lo : c > hi ? hi : c);
        } else {
            out->v[a] = -l->direction[a];
        }
    }
}
