#include "image_set.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../io/image.h"

const char* const veil_image_set_channel_names[VEIL_IMAGE_SET_CHANNELS] = {
    "R", "G", "B", "A", "T.R", "T.G", "T.B", "P", "single.R", "single.G", "single.B", "depth",
    "multiple.volume.R", "multiple.volume.G", "multiple.volume.B",
    "multiple.screen.R", "multiple.screen.G", "multiple.screen.B", "Z"};

void veil_image_set_free(veil_image_set* s)
{
    if (!s) return;
    free(s->rgba);
    free(s->aov_t);
    free(s->aov_s);
    free(s->aov_v);
    free(s->aov_m);
    free(s->aov_q);
    free(s->aov_z);
    free(s->behind);
    veil_deep_image_free(&s->deep);
    memset(s, 0, sizeof *s);
}

void veil_image_set_plane(const veil_image_set* s, int c, float* out)
{
    const float* src;
    size_t n = (size_t)s->width * (size_t)s->height, k;
    if (c == 18) { /* Z: one float a pixel */
        for (size_t i = 0; i < n; ++i) out[i] = s->aov_z ? s->aov_z[i] : INFINITY;
        return;
    }
    if (c < 12) {
        src = c < 4 ? s->rgba : c < 8 ? s->aov_t : s->aov_s;
        k = (size_t)(c % 4);
    } else {
        src = c < 15 ? s->aov_v : s->aov_m;
        k = (size_t)((c - 12) % 3);
    }
    if (!src) {
        memset(out, 0, n * sizeof *out);
        return;
    }
    for (size_t i = 0; i < n; ++i) out[i] = src[4 * i + k];
}

veil_result veil_image_set_write_exr(const veil_image_set* s, const char* path, int aovs, veil_error* err)
{
    return veil_image_set_write_exr_meta(s, path, aovs, NULL, err);
}

veil_result veil_image_set_write_exr_meta(const veil_image_set* s, const char* path, int aovs,
                                          const veil_exr_meta* meta, veil_error* err)
{
    if (!aovs && !meta) return veil_write_exr(path, s->width, s->height, s->rgba, err);
    const int channels = aovs ? VEIL_IMAGE_SET_CHANNELS : 4; /* without the AOVs: R, G, B, A, the first four */
    size_t n = (size_t)s->width * (size_t)s->height, bytes;
    if (!veil_mul_sizes(n, (size_t)channels, sizeof(float), 1, &bytes))
        return veil_fail(err, VEIL_ERR_LIMIT, "%s: a %dx%d image set is too large", path, s->width, s->height);
    float* all = malloc(bytes);
    if (!all) return veil_fail(err, VEIL_ERR_OOM, "%s: out of memory for the image set's planes", path);
    const float* planes[VEIL_IMAGE_SET_CHANNELS];
    for (int c = 0; c < channels; ++c) {
        veil_image_set_plane(s, c, all + (size_t)c * n);
        planes[c] = all + (size_t)c * n;
    }
    veil_result r = veil_write_exr_planes_meta(path, s->width, s->height, channels, veil_image_set_channel_names,
                                               planes, meta, err);
    free(all);
    return r;
}
