/* veil — comparing two linear RGBA images (a test image against a
 * reference): the numbers `veil compare` prints and bench/accuracy records,
 * and the colour map of its error heatmap.
 *
 * Only R, G, B enter the metrics (alpha is reported separately as its max
 * abs difference). With a the image and b the reference, per channel value,
 * all sums in double:
 *  - relative RMSE: sqrt(mean over pixels and channels of
 *    ((a - b) / max(|b|, floor))^2), with `floor` a stated absolute floor on
 *    the denominator (default: VEIL_COMPARE_FLOOR_FRACTION of the mean of
 *    the reference's |RGB| values, so that near-black pixels do not dominate;
 *    VEIL_COMPARE_TINY_FLOOR where that is smaller: an all-black reference);
 *  - absolute RMSE over RGB, and the max absolute error over RGB;
 *  - the fraction of pixels whose largest channel relative error (same
 *    floor) exceeds VEIL_COMPARE_OFF_FRACTION (strictly more than 5 %);
 *  - PSNR in dB: 10 log10(peak^2 / MSE), peak the reference's largest |RGB|
 *    value (1 when that is 0, an all-black reference); +INFINITY for
 *    identical RGB (MSE 0).
 * With finite inputs every number is finite except that PSNR.
 * The library keeps no pointer to the caller's buffers.
 */
#ifndef VEIL_REFERENCE_COMPARE_H
#define VEIL_REFERENCE_COMPARE_H

#include "../core/result.h"

#define VEIL_COMPARE_FLOOR_FRACTION 0.01
#define VEIL_COMPARE_OFF_FRACTION 0.05
/* The floor when the reference is all black (mean 0): any positive tiny
 * constant keeps the ratio defined; every difference from black then reads
 * as a huge relative error, which it is. It is also the least floor: a
 * smaller one (given or default) is raised to it, so that |a - b| / floor
 * (|a - b| <= 2 FLT_MAX) and its square stay finite in double. */
#define VEIL_COMPARE_TINY_FLOOR 1e-12

/* The heatmap's scale: relative error on a log scale over four decades,
 * from VEIL_COMPARE_HEATMAP_MIN (black; below it too, 0 included) to
 * VEIL_COMPARE_HEATMAP_MAX (white; above it too). The colour stops sit one
 * per decade: black 1e-4, blue 1e-3, magenta 1e-2, yellow 1e-1, white 1. */
#define VEIL_COMPARE_HEATMAP_MIN 1e-4
#define VEIL_COMPARE_HEATMAP_MAX 1.0

typedef struct veil_compare_stats {
    int width, height;
    double floor;          /* the denominator floor used (absolute) */
    double rel_rmse;
    double rmse;           /* absolute RMSE over RGB */
    double max_abs;        /* largest |a - b| over RGB */
    double frac_off;       /* fraction of pixels > VEIL_COMPARE_OFF_FRACTION off */
    double psnr_db;        /* INFINITY when MSE is 0 */
    double alpha_max_abs;  /* largest |a - b| of alpha */
} veil_compare_stats;

/* a, b: width*height RGBA floats (b the reference), top row first.
 * floor <= 0: the default floor; NaN or infinite floor: VEIL_ERR_INVALID.
 * rel_err, when not NULL, receives width*height per-pixel relative errors
 * (largest RGB channel, same floor; FLT_MAX where larger) for a heatmap. VEIL_ERR_INVALID for a
 * non-finite value in either image (any channel, alpha included), naming
 * the first such pixel in row order as "image" or "reference", its (x, y)
 * and channel. *out is written only on success. */
veil_result veil_compare_images(const float* a, const float* b, int width, int height, double floor,
                                veil_compare_stats* out, float* rel_err, veil_error* err);

/* Means of b x b pixel blocks of an RGBA image (a partial block at the
 * right or bottom edge is dropped), into a newly malloc'd (w/b) x (h/b)
 * image; with se (3 floats a pixel, per-pixel standard errors, may be
 * NULL) also the blocks' standard errors sqrt(sum se^2) / b^2 into *se_out
 * (3 floats a block). NULL (and VEIL_ERR_*) when b < 1, b exceeds a side,
 * or out of memory. */
veil_result veil_compare_bin(const float* rgba, const float* se, int w, int h, int b, float** out, float** se_out,
                             veil_error* err);

/* Mean energy bias of a against the reference b: mean(a RGB) / mean(b RGB)
 * - 1 (0 when both are black; NaN, undefined, when only b is: callers say so rather than print a number). */
double veil_compare_bias(const float* a, const float* b, int width, int height);

/* The standard error of veil_compare_bias that the reference's noise alone gives it (se: 3 floats a
 * pixel, its standard errors): (sum a / sum b) sd(sum b) / sum b over the RGB of every pixel, with
 * sd(sum b)^2 = the sum over pixels of (se_R + se_G + se_B)^2. A pixel's three channels come from the
 * same paths: taken as wholly correlated, which never understates it. A few pixels of heavy-tailed
 * noise (a point light inside a medium) can hold most of it. NaN where the bias is undefined. */
double veil_compare_bias_se(const float* a, const float* b, const float* se, int width, int height);

/* The reference's own noise on the scale of the relative RMSE: the rms
 * over pixels and channels of se / max(|b|, floor). A measured rel_rmse
 * holds this noise in quadrature (the reference's error is independent of
 * the image's), so sqrt(max(0, rel_rmse^2 - noise^2)) is the image's own
 * error, noise-debiased. */
double veil_compare_noise(const float* b, const float* se, int width, int height, double floor);

/* The heatmap colour of a relative error: 8-bit sRGB-encoded RGB. The stops
 * are interpolated in linear light, so the luminance rises monotonically
 * with the error (black 0 < blue < magenta < yellow < white 1). NaN maps
 * to white (the worst), 0 and negatives to black. */
void veil_compare_heatmap_colour(double rel, unsigned char rgb[3]);

#endif
