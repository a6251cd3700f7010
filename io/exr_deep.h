/* veil — deep OpenEXR output: a deep scanline file of volumetric samples,
 * channels R, G, B, A, Z, ZBack (32-bit float), ZIPS compression (one
 * scanline a chunk, what compositors expect of deep files; scanline, as
 * Nuke reads no tiled deep file).
 *
 * A deep image: per pixel (row-major, top row first) a count of samples,
 * and the samples of every pixel one after another in that order, each
 * VEIL_DEEP_CHANNELS floats: premultiplied R, G, B, alpha A, and the
 * depths Z < ZBack (m) the sample spans. Samples within a pixel are front
 * to back and do not overlap. The image owns its buffers
 * (veil_deep_image_free).
 *
 * Written through OpenEXR's C++ library (Imf::DeepScanLineOutputFile), in
 * io/exr_deep.cpp behind this C header: OpenEXRCore 3.1 (Debian 12's
 * OpenEXR 3.1.5) has no deep encoder (its deep pack step returns
 * EXR_ERR_INVALID_ARGUMENT). As every writer in io/: onto a temporary file
 * beside the target, renamed over it only when everything succeeded, so a
 * failed write leaves an existing file as it was and no temporary. */
#ifndef VEIL_EXR_DEEP_H
#define VEIL_EXR_DEEP_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#include "../core/result.h"
#include "image.h"

#define VEIL_DEEP_CHANNELS 6 /* R, G, B, A, Z, ZBack */
enum { VEIL_DEEP_R, VEIL_DEEP_G, VEIL_DEEP_B, VEIL_DEEP_A, VEIL_DEEP_Z, VEIL_DEEP_ZBACK };

typedef struct veil_deep_image {
    int width, height;
    uint32_t* counts; /* width*height samples a pixel */
    size_t total;     /* their sum */
    float* samples;   /* total * VEIL_DEEP_CHANNELS floats */
} veil_deep_image;

void veil_deep_image_free(veil_deep_image* d); /* accepts NULL and zeroed images */

/* Writes d (every count's samples present, d->total their sum) to path;
 * header attributes from meta (NULL: none), as veil_write_exr_planes_meta.
 * VEIL_ERR_INVALID for a bad size or counts that do not add up to total,
 * VEIL_ERR_IO naming the file and what OpenEXR said. */
veil_result veil_write_deep_exr(const char* path, const veil_deep_image* d, const veil_exr_meta* meta,
                                veil_error* err);

/* The flat writer's way for DWAA and DWAB (io/exr.c), which OpenEXRCore 3.1 cannot encode either
 * ("DWA/A compression not yet implemented in C"): the n planes onto the open descriptor fd of the
 * writer's temporary file through the C++ library, as veil_write_exr_planes_meta would write them
 * (meta->format's half and level, its threads); VEIL_ERR_IO naming path with OpenEXR's message. */
veil_result veil__exr_write_imf(int fd, const char* path, int width, int height, int n, const char* const* names,
                                const float* const* planes, const veil_exr_meta* meta, veil_error* err);

#ifdef __cplusplus
}
#endif

#endif
