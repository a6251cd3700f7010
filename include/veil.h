/* veil — headless volumetric rendering: the public C API.
 *
 * veil renders participating media (smoke, fog, clouds given as particles,
 * OpenVDB grids or analytic fogs, lit by point, spot and directional lights)
 * on the GPU through a headless EGL/OpenGL 4.5 context: a scene file
 * (JSON, docs/scene-format.md) in, an image of linear radiance and its
 * arbitrary output variables (transmittance, density integral, single
 * scattering, depth) out, as floats or as an EXR or PNG file.
 *
 * Units: metres, m^-1 for the medium's coefficients, W/sr for point and spot
 * intensities, W/m^2 for directional irradiance; images hold linear RGBA
 * floats, row-major, top row first, 4 floats a pixel, A = 1 - mean
 * transmittance. Ray-march steps are in voxels of the extinction volume.
 *
 * Ownership: every handle is opaque, made by a veil_X_create/open/render
 * call and released by its veil_X_destroy/close (which accept NULL). veil
 * copies what it keeps and never holds on to a caller's pointer; pointers
 * it returns (pixels, names, messages) stay valid until the handle they came
 * from is released.
 *
 * Errors: every fallible call returns a veil_result (VEIL_OK is 0) and, when
 * err is not NULL, writes a sentence saying what went wrong into it. veil
 * never prints and never exits.
 *
 * Threading: a veil_context holds an OpenGL context, which veil_render and
 * veil_context_destroy make current on the calling thread, where it stays:
 * one thread may hold and use several contexts, but use each context from
 * the thread that created it (elsewhere veil_render returns VEIL_ERR_GPU).
 * Scenes and images hold no GL objects: once made they can be read from any
 * thread.
 *
 * ABI: libveil.so exports exactly the functions declared here and in
 * veil/result.h, each marked VEIL_API; everything else is hidden. The
 * VEIL_VERSION_* macros are the version of this header; veil_version() and
 * veil_version_numbers() that of the library actually loaded, so a caller
 * can check one against the other. A minor version may add functions and
 * description fields; the .so's soname names major.minor.
 *
 * Descriptions grow: each veil_X_desc opens with `size`, which the caller
 * sets to sizeof(veil_X_desc) (VEIL_X_DESC_INIT does), and a later veil.h
 * only appends fields. The library reads the fields that lie within `size`
 * and takes the default for the rest, so a program built against an older
 * veil.h keeps its meaning. size 0 (a description zeroed with `= {0}` or
 * written with designated initializers that leave size out) means the
 * first layout, veil 0.2's, every field of which is read. A size larger
 * than the library's own layout (a program built against a newer veil.h
 * running on an older library), or one that is no layout's size, is
 * refused with VEIL_ERR_INVALID and a message naming both sizes; the
 * library never reads past what the caller said it passed.
 */
#ifndef VEIL_H
#define VEIL_H

#include <stddef.h>
#include <stdint.h>

#include "veil/result.h"

/* This header's version (CMakeLists.txt reads the project's version from
 * these three lines). */
#define VEIL_VERSION_MAJOR 0
#define VEIL_VERSION_MINOR 5
#define VEIL_VERSION_PATCH 0

#ifdef __cplusplus
extern "C" {
#endif

/* The loaded library's version: "0.5.0". */
VEIL_API const char* veil_version(void);

/* The loaded library's version as numbers (each output may be NULL). */
VEIL_API void veil_version_numbers(int* major, int* minor, int* patch);

/* ---- context: a GL context and the renderer's kept stage results ------ */

typedef struct veil_context veil_context;

/* Zero means default in every field but size. */
typedef struct veil_context_desc {
    size_t size;        /* sizeof(veil_context_desc), or 0: veil 0.2's layout (see the top) */
    int force_software; /* 1: software rasteriser only; 0: hardware first (VEIL_DEVICE=software also forces it) */
    int debug;          /* 1: a GL debug context */
} veil_context_desc;

#ifdef __cplusplus
#define VEIL_CONTEXT_DESC_INIT {sizeof(veil_context_desc), 0, 0}
#else
#define VEIL_CONTEXT_DESC_INIT {.size = sizeof(veil_context_desc)}
#endif

/* Creates a headless GL 4.5 context, current on the calling thread, and a
 * renderer on it (desc may be NULL). VEIL_ERR_GPU when no such context can
 * be made. A context keeps each stage's results between renders: rendering
 * a turntable of one scene injects and propagates once. */
VEIL_API veil_result veil_context_create(const veil_context_desc* desc, veil_context** out, veil_error* err);
VEIL_API void veil_context_destroy(veil_context* ctx); /* accepts NULL */

/* ---- scene ------------------------------------------------------------- */

typedef struct veil_scene veil_scene;

/* Reads a scene file (relative paths inside resolve against its folder).
 * VEIL_ERR_IO, VEIL_ERR_PARSE or VEIL_ERR_INVALID with the file and the
 * JSON path of the offending field. */
VEIL_API veil_result veil_scene_open(const char* path, veil_scene** out, veil_error* err);

/* The same from JSON text in memory (NUL-terminated; the scene format of
 * docs/scene-format.md): relative paths inside resolve against base_dir
 * (NULL or "": the current folder), and `name` (NULL: "<json>") starts
 * every error message where a file's name would. */
VEIL_API veil_result veil_scene_from_json(const char* json, const char* base_dir, const char* name, veil_scene** out,
                                          veil_error* err);
VEIL_API void veil_scene_close(veil_scene* scene); /* accepts NULL */

/* Reading a scene with a progress callback (veil 0.4), so that a long
 * read can be cancelled: an environment map of 2^25 texels takes seconds
 * to decode and cut into lights. Zero means default in every field but
 * size. progress (veil_progress_callback: see just below) is called with
 * the stage "scene" and the share done as the files the scene names are
 * read; a non-zero return cancels: VEIL_ERR_CANCELLED, no scene. */

/* Progress (veil 0.3): called on the rendering thread as the work goes on,
 * with the stage ("inject", "propagate", "volumetric", "render" or
 * "spread") and the share of it done, 0..1. Return 0 to go on; any other
 * value cancels the render: veil_render then returns VEIL_ERR_CANCELLED as
 * soon as the work in flight ends (between stages, between bands of rows
 * of the march and parts of every long loop) and makes no image. Work
 * after the last stage (a deep image's merge) reports as that stage, done
 * 1, and can cancel too. The stages a cancelled render did finish
 * stay cached in the context. The callback may create, use and destroy
 * other contexts (veil_render makes its own current again when the
 * callback returns); veil_render of the rendering context from its callback
 * is refused (VEIL_ERR_INVALID), and veil_context_destroy of it cancels the
 * render, which returns VEIL_ERR_INVALID and releases the context. */
typedef int (*veil_progress_callback)(void* user, const char* stage, double done);

typedef struct veil_scene_desc {
    size_t size;          /* sizeof(veil_scene_desc) (see the top) */
    const char* path;     /* a scene file, as veil_scene_open; or NULL and json: */
    const char* json;     /* JSON text, as veil_scene_from_json */
    const char* base_dir; /* json: what relative paths resolve against (NULL or "": the current folder) */
    const char* name;     /* json: what messages start with (NULL: "<json>") */
    veil_progress_callback progress; /* NULL: none */
    void* progress_user;             /* passed to progress */
} veil_scene_desc;

#ifdef __cplusplus
#define VEIL_SCENE_DESC_INIT {sizeof(veil_scene_desc), nullptr, nullptr, nullptr, nullptr, nullptr, nullptr}
#else
#define VEIL_SCENE_DESC_INIT {.size = sizeof(veil_scene_desc)}
#endif

/* Reads the scene desc names (a file, or JSON text: exactly one of path
 * and json) into *out; errors as veil_scene_open and veil_scene_from_json. */
VEIL_API veil_result veil_scene_create(const veil_scene_desc* desc, veil_scene** out, veil_error* err);

/* ---- grids from memory (veil 0.3) ---------------------------------------- */

/* How a grid's values lie in memory. */
typedef enum veil_axis_order {
    VEIL_AXIS_ORDER_X_FASTEST = 0, /* value(i, j, k) = data[i + nx * (j + ny * k)] (OpenVDB's LayoutXYZ,
                                      a Fortran-ordered array a[i, j, k]) */
    VEIL_AXIS_ORDER_Z_FASTEST = 1  /* value(i, j, k) = data[k + nz * (j + ny * i)] (a C array float a[nx][ny][nz],
                                      a C-ordered numpy array indexed [i, j, k], as pyopenvdb's copyFromArray) */
} veil_axis_order;

/* A dense float grid: the value of index (i, j, k), 0 <= i < dims[0] etc.,
 * is a sample at world index_to_world * (i, j, k, 1), as a VDB file's voxel
 * (docs/scene-format.md, "vdb"): voxel centres at integer indices, the
 * field between them trilinear, values of 0 empty space. */
typedef struct veil_grid_desc {
    size_t size;               /* sizeof(veil_grid_desc), or 0: veil 0.3's layout */
    const float* data;         /* dims[0] * dims[1] * dims[2] floats, in axis_order */
    int dims[3];               /* nx, ny, nz, each >= 1, their product <= 2^30 */
    int axis_order;            /* veil_axis_order */
    double index_to_world[16]; /* row-major 4x4 acting on column vectors (i, j, k, 1), last row 0 0 0 1,
                                  invertible; all zero: the identity (1 m voxels, index (0,0,0) at the origin) */
} veil_grid_desc;

#ifdef __cplusplus
#define VEIL_GRID_DESC_INIT {sizeof(veil_grid_desc), nullptr, {0, 0, 0}, 0, {0}}
#else
#define VEIL_GRID_DESC_INIT {.size = sizeof(veil_grid_desc)}
#endif

/* Copies grid into scene under `name`, replacing a grid of that name: the
 * scene's "array" sources that name it (their "grid", or their emission or
 * temperature "grid") read it. veil keeps its own copy: the caller's
 * buffer may go once this returns. VEIL_ERR_INVALID for a bad dimension,
 * axis order or matrix, or a value that is not finite (NaN, infinite),
 * VEIL_ERR_LIMIT over 2^30 values. A source naming a
 * grid never given fails veil_render with VEIL_ERR_INVALID and the
 * source's JSON path. */
VEIL_API veil_result veil_scene_set_grid(veil_scene* scene, const char* name, const veil_grid_desc* grid,
                                         veil_error* err);

/* ---- render ------------------------------------------------------------ */

typedef struct veil_image veil_image;

/* Zero means default in every field but size. */
typedef struct veil_render_desc {
    size_t size;        /* sizeof(veil_render_desc), or 0: veil 0.2's layout (see the top) */
    int width, height;  /* pixels, 1..16384; 0: the scene camera's */
    float step_voxels;  /* ray-march step in voxels of the extinction volume; 0: 0.5 */
    uint32_t seed;      /* jitter seed: the same seed renders the same image */
    long frame, frames; /* frames > 1: frame `frame` (0..frames-1) of a turntable, one full
                           turn about the camera's up axis through its look-at point in
                           `frames` equal steps (frame 0: the scene's camera);
                           0 or 1: the scene's camera (frame must be 0) */
    veil_progress_callback progress; /* veil 0.3; NULL: none */
    void* progress_user;             /* passed to progress */
} veil_render_desc;

#ifdef __cplusplus
#define VEIL_RENDER_DESC_INIT {sizeof(veil_render_desc), 0, 0, 0.0f, 0u, 0L, 0L, nullptr, nullptr}
#else
#define VEIL_RENDER_DESC_INIT {.size = sizeof(veil_render_desc)}
#endif

/* Renders scene with ctx (desc may be NULL) into a new image (*out; free
 * it with veil_image_destroy). */
VEIL_API veil_result veil_render(veil_context* ctx, const veil_scene* scene, const veil_render_desc* desc,
                        veil_image** out, veil_error* err);

/* ---- image --------------------------------------------------------------- */

VEIL_API void veil_image_size(const veil_image* img, int* width, int* height); /* 0x0 for NULL */

/* width*height*4 floats: linear R, G, B and A, top row first; owned by img. */
VEIL_API const float* veil_image_rgba(const veil_image* img);

/* One channel as a width*height plane into out (the caller's). Names:
 * "R", "G", "B", "A", "T.R", "T.G", "T.B" (transmittance), "P" (density
 * integral), "single.R", "single.G", "single.B" (single scattering),
 * "depth" (mean distance of the first interaction, m),
 * "multiple.volume.R", ".G", ".B" (the volumetric multiple-scattering
 * estimate), "multiple.screen.R", ".G", ".B" (the screen-space spread),
 * "Z" (veil 0.3: depth along the camera's view axis, as compositors read
 * Z: depth x the cosine of the pixel's ray to the axis; +infinity where
 * the ray meets no medium);
 * R, G, B = T * background + single + multiple.volume + multiple.screen. VEIL_ERR_INVALID
 * for any other name. */
VEIL_API veil_result veil_image_channel(const veil_image* img, const char* name, float* out, veil_error* err);

/* EXR, 32-bit float, ZIP: R, G, B, A, plus every other channel above when
 * aovs is non-zero. All or nothing: a failed write leaves no file. Neither
 * writer writes over a file the render read (the scene's file, a VDB,
 * particle or environment map file, also through a link): VEIL_ERR_INVALID
 * naming both, and the file is left as it was. */
VEIL_API veil_result veil_image_write_exr(const veil_image* img, const char* path, int aovs, veil_error* err);

/* The same with the pixels stored as `type` ("float", or "half": 16-bit, except the distances Z and
 * depth and the density integral P, which stay float) and `compression` ("zip", "none", "rle", "zips",
 * "piz", and the lossy "pxr24", "b44", "b44a", "dwaa", "dwab"), as Blender's and Nuke's EXR outputs
 * offer; NULL: "float", "zip" (veil_image_write_exr's). The chunks are compressed on every core (the
 * environment's VEIL_EXR_THREADS=N: on N). VEIL_ERR_INVALID naming the argument for any other name.
 * (veil 0.5) */
VEIL_API veil_result veil_image_write_exr_as(const veil_image* img, const char* path, int aovs, const char* type,
                                             const char* compression, veil_error* err);

/* 8-bit sRGB PNG preview of the radiance times 2^exposure, tone-mapped. */
VEIL_API veil_result veil_image_write_png(const veil_image* img, const char* path, float exposure, veil_error* err);

/* The render's stage reports ("inject", "propagate", "volumetric", "render", "spread"), in order:
 * what each did ("ran", "cached", "skipped"), its wall time (ms) and why.
 * Each output may be NULL; the strings are owned by img (names: static). */
VEIL_API int veil_image_stage_count(const veil_image* img); /* 0 for NULL */
VEIL_API veil_result veil_image_stage(const veil_image* img, int i, const char** name, const char** status, double* ms,
                             const char** why);

VEIL_API void veil_image_destroy(veil_image* img); /* accepts NULL */

#ifdef __cplusplus
}
#endif

#endif
