/* veil — deep images from the march: each pixel's ray as volumetric samples
 * (io/exr_deep.h's veil_deep_image), for a compositor to hold surfaces out
 * at any depth inside the medium.
 *
 * The march compiled with VEIL_MARCH_DEEP (render/shaders/march.comp)
 * writes up to R = veil_deep_raw_samples(cap) raw samples a pixel: the
 * ray's stretches of medium, split where the opacity crosses a multiple of
 * 1/R (equal-opacity buckets), where the ray leaves the medium into empty
 * space, and at its end. A sample's colour is premultiplied (what the
 * stretch adds, divided by the transmittance in front of it), A = 1 - the
 * stretch's mean transmittance, Z and ZBack planar depths (m, along the
 * camera's view axis: the flat image's Z), Z < ZBack. The background is
 * not in the deep image: a compositor puts its own plate behind.
 *
 * veil_deep_finish then, on the CPU:
 *  - makes the samples flatten to the flat image less T x background: what
 *    the flat image adds after the march that has no depth (the screen-
 *    space spread, the clamp of a negative cache estimate, rounding) is
 *    added to a pixel's samples in proportion to each one's share of the
 *    pixel's opacity (to a transparent sample over the frame's medium depth
 *    where a pixel has none), and the most opaque sample's alpha is set so
 *    that the flattened alpha is the flat one;
 *  - merges adjacent samples, the pair holding the least of the pixel's
 *    opacity first, down to the cap. A merge is exact for the flatten
 *    (C = C1 + (1 - A1) C2, A = 1 - (1 - A1)(1 - A2), Z = Z1, ZBack = ZBack2)
 *    and loses only depth resolution, which a holdout shows: the report
 *    measures it as the holdout error against the raw samples.
 *
 * The holdout (OpenEXR's rule for volumetric samples): of a sample partly in
 * front of depth d the part x = (d - Z) / (ZBack - Z) counts, with alpha
 * 1 - (1 - A)^x and its colour scaled as its alpha (by x when A = 0). */
#ifndef VEIL_DEEP_H
#define VEIL_DEEP_H

#include <stddef.h>
#include <stdint.h>

#include "../core/result.h"
#include "../io/exr_deep.h"
#include "../scene/scene.h" /* VEIL_DEEP_DEFAULT_SAMPLES, VEIL_DEEP_MAX_SAMPLES */

/* Raw samples a pixel for a cap: 4 x the cap (each merged sample from about
 * four buckets of opacity), at most VEIL_DEEP_MAX_RAW: the march's buffer
 * holds R samples a pixel of a band of rows (VEIL_DEEP_BAND_BYTES), and
 * the merge costs O(R^2) a pixel. */
#define VEIL_DEEP_RAW_FACTOR 4
#define VEIL_DEEP_MAX_RAW 64
int veil_deep_raw_samples(int cap);

/* Memory (issue 41). The raw samples are kept until the frame is done
 * (the flat image's last additions are spread over them): up to R a pixel
 * of 24 bytes, then merged in place, and the writer holds a pointer a
 * channel a pixel (VEIL_DEEP_WRITER_BYTES). veil_deep_bytes is that peak
 * when every pixel has R samples (a medium over the whole frame: 1024 x 768
 * at 64 samples is 1.2 GB, 4096^2 at 64 is 26 GB); a frame over
 * VEIL_DEEP_MAX_BYTES is refused before any GPU work, with the numbers,
 * rather than found out of memory after the march. 8 GiB: 4K at the
 * default 8 samples a pixel (R = 32: 6.9 GB) fits, the documented limits
 * (16384^2 at 64) do not. The file holds at most the cap's samples a
 * pixel, ZIP-compressed. */
#define VEIL_DEEP_WRITER_BYTES (VEIL_DEEP_CHANNELS * 8 + 8)
#define VEIL_DEEP_MAX_BYTES ((double)((size_t)8 << 30))
double veil_deep_bytes(int width, int height, int cap);

/* The merge reports its progress (core/progress.h, "deep merge") and
 * honours a cancel (VEIL_ERR_CANCELLED) between parts of this many raw
 * samples (about 30 ms at 64 samples a pixel on this project's machines). */
#define VEIL_DEEP_PART_SAMPLES ((size_t)1 << 18)

/* The march's deep buffers hold at most this many bytes (a band's rows are
 * cut to fit, at least VEIL_MARCH_GROUP of them): 64 MiB. */
#define VEIL_DEEP_BAND_BYTES ((size_t)64 << 20)

/* Appends a band of `rows` rows (width d->width) as the march wrote them:
 * counts[rows * width] and R samples a pixel, to d (whose counts hold every
 * row; `first_row` is the band's first). */
veil_result veil_deep_append_band(veil_deep_image* d, int first_row, int rows, int R, const uint32_t* counts,
                                  const float* samples, veil_error* err);

/* What veil_deep_finish did and the holdout error of the merge. */
typedef struct veil_deep_report {
    size_t raw, kept;          /* samples before and after the merge */
    int max_raw, cap;          /* the most raw samples of a pixel; the cap */
    double residual_max;       /* the largest |flat - flatten(raw)| spread over a pixel's samples (rgb) */
    /* the holdout error of the merged samples against the raw ones, at the raw samples' depths (their Z and
     * ZBack) in every pixel with samples: alpha in front of that depth, max and mean; colour, |error| in
     * luminance over the pixel's flattened luminance, max and mean (over the points of pixels that have light) */
    double holdout_alpha_max, holdout_alpha_mean, holdout_color_max, holdout_color_mean;
    size_t holdout_points;
    double ms;                 /* the time it took */
} veil_deep_report;

/* Finishes the march's raw samples d: distributes what the flat rgba
 * (width*height*4) holds beyond flatten(d) + T x background (aov_t: the
 * transmittance rgb, 4 floats a pixel; background: the scene's, 0 when the
 * march added none; behind, when not NULL, 3 floats a pixel in its place:
 * an environment seen behind the medium, veil_image_set.behind), merges down
 * to cap (1..VEIL_DEEP_MAX_SAMPLES) and measures the merge (rep may be NULL). */
veil_result veil_deep_finish(veil_deep_image* d, const float* rgba, const float* aov_t, const float background[3],
                             const float* behind, int cap, veil_deep_report* rep, veil_error* err);

/* A pixel's n samples (VEIL_DEEP_CHANNELS floats each, front to back)
 * composited front to back in double: out = r, g, b, alpha. */
void veil_deep_flatten(const float* s, uint32_t n, double out[4]);

/* The same over what lies in front of depth d only (the holdout rule
 * above). */
void veil_deep_holdout(const float* s, uint32_t n, double d, double out[4]);

#endif
