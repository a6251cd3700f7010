/* veil — an image set: what the ray marcher writes for one frame, kept
 * apart so that a compositor gets each part as a named EXR channel.
 *
 * Every buffer is width*height pixels, row-major, top row first, 4 floats a
 * pixel (malloc'd; the set owns them; veil_image_set_free() releases):
 *   rgba   R, G, B: linear radiance reaching the camera (the light scattered
 *          toward it plus the background it sees through the medium);
 *          A = 1 - mean transmittance (0: nothing in front of the background)
 *   aov_t  the transmittance T per channel (R, G, B) and P, the density
 *          integral along the pixel's ray (density m; sigma_t * P is the
 *          optical depth)
 *   aov_s  single scattering (R, G, B: the medium's own light, background
 *          excluded) and depth, the mean distance (m) of the ray's first
 *          interaction, 0 where the ray meets no medium
 *   aov_v  volumetric multiple scattering (R, G, B: the octave or the
 *          diffusion estimate; 0 when it is off); A unused
 *   aov_m  screen-space multiple scattering (R, G, B: the spread light;
 *          0 when the pass is off or skipped); A: the MIP level read
 *   aov_z  (1 float a pixel) Z: the depth as compositors read it, along the
 *          camera's view axis (depth x the cosine of the pixel's ray to the
 *          axis), +infinity where the ray meets no medium
 *   aov_q  (not written to files) the screen-space pass's source: single
 *          scattering's light scattered, not absorbed, on its way to the
 *          camera (R, G, B), and the luminance-weighted P of it
 *   deep   (when the render asked for it) each pixel's ray as volumetric
 *          samples that flatten to rgba less T * background (render/deep.h)
 * rgba = T * background + single + volumetric + screen-space.
 */
#ifndef VEIL_IMAGE_SET_H
#define VEIL_IMAGE_SET_H

#include "../core/result.h"
#include "../io/exr_deep.h"
#include "../io/image.h"

typedef struct veil_image_set {
    int width, height;
    float* rgba;
    float* aov_t;
    float* aov_s;
    float* aov_v;
    float* aov_m;
    float* aov_q;
    float* aov_z;
    float* behind; /* 3 floats a pixel: the radiance seen behind the medium when it varies by pixel (an
                      environment light, render/march.c), else NULL (the scene's background) */
    veil_deep_image deep; /* the deep image (render/deep.h) when asked for (counts NULL: none) */
} veil_image_set;

void veil_image_set_free(veil_image_set* s); /* accepts NULL and zeroed sets */

/* The EXR channels an image set can hold, by name: "R", "G", "B", "A",
 * "T.R", "T.G", "T.B", "P", "single.R", "single.G", "single.B", "depth",
 * "multiple.volume.R", ".G", ".B", "multiple.screen.R", ".G", ".B", "Z"
 * (a zero plane when its buffer is NULL; Z: +infinity, no medium). */
#define VEIL_IMAGE_SET_CHANNELS 19
extern const char* const veil_image_set_channel_names[VEIL_IMAGE_SET_CHANNELS];

/* The plane of channel c (an index into the names above) into out
 * (width*height floats). */
void veil_image_set_plane(const veil_image_set* s, int c, float* out);

/* Writes the set to an EXR: R, G, B, A, plus the AOV channels when aovs is
 * non-zero. All or nothing, as every writer in io/. */
veil_result veil_image_set_write_exr(const veil_image_set* s, const char* path, int aovs, veil_error* err);
/* The same with header attributes (io/image.h; NULL: none). */
veil_result veil_image_set_write_exr_meta(const veil_image_set* s, const char* path, int aovs,
                                          const veil_exr_meta* meta, veil_error* err);

#endif
