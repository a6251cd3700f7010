/* veil — image files: HDR EXR (OpenEXRCore) and an sRGB PNG preview (libpng).
 *
 * Pixels are linear RGBA floats, row-major, top row first, 4 floats a pixel.
 * A is 1 - mean transmittance (0: nothing in front of the background).
 * Writers write to a temporary file beside the target and rename it into
 * place only when everything succeeded: a failed write leaves no file at
 * `path` (and no temporary either).
 */
#ifndef VEIL_IMAGE_H
#define VEIL_IMAGE_H

#include <stdint.h>

#include "../core/result.h"

/* EXR with channels R, G, B, A stored as 32-bit float, ZIP compression. */
veil_result veil_write_exr(const char* path, int width, int height,
                           const float* rgba, veil_error* err);

/* EXR with n named float channels (e.g. "R", "G", "B", "A", "stderr.R"),
 * each a width*height plane, top row first, ZIP compression. n is 1 to 64;
 * names must be non-empty, distinct and at most 255 characters (over 31
 * sets OpenEXR's long-names flag); VEIL_ERR_INVALID otherwise. OpenEXR
 * stores channels sorted by name. */
veil_result veil_write_exr_planes(const char* path, int width, int height, int n, const char* const* names,
                                  const float* const* planes, veil_error* err);

/* Header attributes a compositor reads, written beside the channels (all
 * optional; NULL or zero fields: none). Matrices in OpenEXR's convention:
 * row vectors, p' = p M; worldToCamera into a left-handed camera space
 * (x right, y up, z the viewing direction), worldToNDC onto the image
 * (0, 0) top left, (1, 1) bottom right, after the division by w. */
#define VEIL_EXR_META_STRINGS 8

/* How an EXR's pixels are stored, as Blender's and Nuke's EXR outputs offer
 * (all zero: 32-bit float, ZIP, the chunks compressed on every core). */
enum {
    VEIL_EXR_DEFAULT = 0, /* ZIP */
    VEIL_EXR_NONE, VEIL_EXR_RLE, VEIL_EXR_ZIPS, VEIL_EXR_ZIP, VEIL_EXR_PIZ, VEIL_EXR_PXR24, VEIL_EXR_B44,
    VEIL_EXR_B44A, VEIL_EXR_DWAA, VEIL_EXR_DWAB,
    VEIL_EXR_COMPRESSIONS
};
#define VEIL_EXR_MAX_THREADS 64
typedef struct veil_exr_format {
    int half;        /* 1: channels as 16-bit half, except those veil_exr_keeps_float names */
    int compression; /* a VEIL_EXR_* above (PXR24, B44, B44A, DWAA and DWAB are lossy) */
    float dwa_level; /* DWAA / DWAB's compression level (OpenEXR's default 45 when 0) */
    int threads;     /* threads compressing the chunks (0: veil_exr_threads()) */
} veil_exr_format;

/* The compression's name ("zip", "none", "rle", "zips", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"), and
 * back (-1: no such name). */
const char* veil_exr_compression_name(int compression);
int veil_exr_compression_parse(const char* name);
/* 1 for the channels that stay 32-bit float in a half file: distances ("Z", "ZBack", "depth") and the
 * density integral "P" (half's 11-bit significand would step a depth of 100 m by 6 cm). */
int veil_exr_keeps_float(const char* name);
/* The threads an EXR's chunks are compressed on: the machine's online cores (VEIL_EXR_THREADS in the
 * environment overrides), at most VEIL_EXR_MAX_THREADS. */
int veil_exr_threads(void);

typedef struct veil_exr_meta {
    int has_frame;
    int frame;                    /* int attribute "frame" */
    int has_camera;
    float world_to_camera[16];    /* m44f "worldToCamera", row-major */
    float world_to_ndc[16];       /* m44f "worldToNDC", row-major */
    const char* strings[VEIL_EXR_META_STRINGS][2]; /* string attributes: name, value */
    int n_strings;
    veil_exr_format format;       /* how the pixels are stored */
} veil_exr_meta;

/* veil_write_exr_planes with header attributes (meta may be NULL). */
veil_result veil_write_exr_planes_meta(const char* path, int width, int height, int n, const char* const* names,
                                       const float* const* planes, const veil_exr_meta* meta, veil_error* err);

/* Reads header attributes back: the int "frame" (*has_frame 0 when absent),
 * the two camera matrices (*has_camera 0 when either is absent) and the
 * string attribute `name` into value (n bytes; "" when absent; NULL name:
 * none). VEIL_ERR_IO naming the file when it cannot be read. */
veil_result veil_read_exr_meta(const char* path, int* has_frame, int* frame, int* has_camera, float world_to_camera[16],
                               float world_to_ndc[16], const char* name, char* value, size_t n, veil_error* err);

/* Reads one named channel (half or float, case-sensitive name) of an EXR,
 * scanline or tiled as veil_read_exr, as float into a newly malloc'd
 * width*height plane (free() it); VEIL_ERR_INVALID naming the file and
 * channel, and listing the channels it has, when it has no such channel. */
veil_result veil_read_exr_channel(const char* path, const char* name, int* width, int* height, float** plane,
                                  veil_error* err);

/* At most this many pixels are read from an EXR: 2^28, a 16384 x 16384
 * image (the largest veil renders), 4 GiB as RGBA float. An untrusted
 * header must not make veil allocate that for nothing: the image is
 * allocated only once every chunk the header implies has been found in
 * the file (the chunk table's offsets and the chunks' sizes inside it). */
#define VEIL_EXR_MAX_PIXELS ((uint64_t)1 << 28)

/* And at most this many bytes in one chunk, unpacked (OpenEXRCore
 * allocates a chunk's unpacked bytes before decoding it): 256 MiB, four
 * times a 16-line chunk of a 16384-wide image with 64 float channels. */
#define VEIL_EXR_MAX_CHUNK ((uint64_t)1 << 28)

/* Reads an EXR's R, G, B, A channels (A = 1 when absent) as float into a
 * newly malloc'd buffer *rgba (free() it). Any scanline or tiled EXR that
 * OpenEXRCore decodes with half or float channels, up to
 * VEIL_EXR_MAX_PIXELS (VEIL_ERR_LIMIT). */
veil_result veil_read_exr(const char* path, int* width, int* height,
                          float** rgba, veil_error* err);

/* veil_read_exr of an image of at most max_pixels (0: VEIL_EXR_MAX_PIXELS),
 * refused from its header alone with VEIL_ERR_LIMIT before any pixel is
 * read (an environment map, issue 41). With `what` (a short phrase:
 * "reading sky.exr"), the decoding reports its progress (core/progress.h:
 * pixels done of all) and honours a cancel between chunks, once
 * VEIL_EXR_PART_PIXELS more pixels are decoded (VEIL_ERR_CANCELLED, nothing
 * returned). */
#define VEIL_EXR_PART_PIXELS ((uint64_t)1 << 20)
veil_result veil_read_exr_within(const char* path, uint64_t max_pixels, const char* what, int* width, int* height,
                                 float** rgba, veil_error* err);

/* 8-bit sRGB PNG preview, RGB (no alpha): each pixel's linear colour times
 * 2^exposure, tone-mapped by veil_tonemap(), then sRGB-encoded. */
veil_result veil_write_png(const char* path, int width, int height,
                           const float* rgba, float exposure, veil_error* err);

/* 8-bit PNG, RGB (no alpha), from width*height*3 bytes already encoded
 * (sRGB, row-major, top row first), stored as given; the file carries an
 * sRGB chunk. For images made of colours rather than light (a heatmap). */
veil_result veil_write_png_rgb8(const char* path, int width, int height,
                                const unsigned char* rgb, veil_error* err);

/* The preview's tone curve on one linear channel value: x / (1 + x)
 * (Reinhard) applied to x >= 0; NaN and negatives map to 0. */
float veil_tonemap(float x);

/* sRGB opto-electronic transfer function (IEC 61966-2-1), input in [0,1]. */
float veil_srgb_encode(float linear);

#endif
