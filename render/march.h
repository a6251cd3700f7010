/* veil — the single-scattering ray march (render/shaders/march.comp): one
 * invocation per pixel, from the camera through the EV (trilinear over its
 * voxel centres' box) and the analytic fogs, lit through the optical-depth
 * volumes. Writes an image set (render/image_set.h).
 *
 * The march owns its program; the volume, the OPVs, the lights and the
 * volumetric field are the caller's (frame/ brings them up to date first). Needs the GL context
 * current at creation.
 */
#ifndef VEIL_MARCH_H
#define VEIL_MARCH_H

#include <epoxy/gl.h>
#include <stdint.h>

#include "../core/result.h"
#include "../propagate/lit_medium.h"
#include "../propagate/opv_set.h"
#include "../scene/scene.h"
#include "../volume/ev.h"
#include "../volume/volume.h"
#include "../volumetric/volumetric.h"
#include "deep.h"
#include "image_set.h"

/* Ray-march step as a fraction of the voxel edge. Half a voxel resolves the
 * trilinear medium between centres; the step error is measured, not assumed. */
#define VEIL_DEFAULT_STEP_VOXELS 0.5f

/* The march goes in bands of rows, as many rows a dispatch as keep its
 * estimated work (pixels x steps a ray x (1 + lights)) under this: a GPU
 * watchdog stops a dispatch of a few seconds, and a 16384^2 frame through
 * a dense volume is 10^11 steps. At 10^9 to 10^10 steps a second (a
 * desktop GPU) a band takes 0.03 to 0.3 s; on llvmpipe bands only add
 * progress reports. The estimate of steps a ray: the volume box's diagonal
 * over the step, plus 64 a fog and 64 more for each point or spot light in
 * a fog (its steps shrink to a quarter of the distance to a light). */
#define VEIL_MARCH_DISPATCH_WORK ((uint64_t)1 << 28)
/* On a software rasteriser (llvmpipe marches 6e7 units a second on this
 * project's 2-core machines: the demo's 3.2e8 in 5 s) a band is also the
 * time a cancel waits (issue 41: within 1 s), where one can come (a
 * progress sink): the first band 2^24 units (about 0.3 s; 0.8 s where the
 * estimate is low: a fog's steps), the next ones sized from the last's pace
 * to take VEIL_MARCH_BAND_SECONDS. Each band costs a dispatch and a finish
 * (about 20 ms there: 2^24-unit bands made the shared smoke's march 1.4
 * times slower), so bands stay as long as the latency allows, and as long
 * as a dispatch's bound without a sink (docs/performance.md, "Cancel"). */
#define VEIL_MARCH_SOFTWARE_WORK ((uint64_t)1 << 24)
#define VEIL_MARCH_BAND_SECONDS 0.3

/* A frame whose estimated work (as VEIL_MARCH_DISPATCH_WORK counts it) is at
 * least this gets a march compiled for its lights (VEIL_LIGHT_LIST: each
 * one's kind and light-space grid as constants; render/march.c). On
 * llvmpipe that program marches the demo 1.5x faster than the one that
 * reads the lights from the medium's block, and costs about 0.5 s to
 * compile once per light setup (Mesa's shader cache keeps it between runs);
 * the demo's 3.2e8 units take about 5 s the generic way, so at 2^26 = 6.7e7
 * units (about 1 s) the saving and the compile are about even. Smaller frames
 * (tests, previews, the stress test's 500 light setups) keep the generic one. */
#define VEIL_MARCH_LIGHT_LIST_WORK ((uint64_t)1 << 26)

typedef struct veil_march veil_march;

/* The phase function's g from which the default gathers the cache's later light (render/shaders/
 * cache_gather.comp) instead of reading its lobe: where the delta-Eddington forward peak f = g^2 holds at
 * least half of the scattering. The lobe's error grows with g and is 0 at g = 0, where the gather gives the
 * lobe's answer at more cost (docs/multiple-scattering.md, "The gather": measured at g <= 0.6 and 0.85). */
#define VEIL_GATHER_MIN_G 0.70710678f

typedef struct veil_march_desc {
    veil_lit_medium medium;    /* the medium, the lights that add light and their optical depths */
    const veil_camera* camera;
    int width, height;
    float step_voxels;         /* > 0 */
    uint32_t seed;             /* jitter seed */
    int skip_empty;            /* 1: jump over bricks without density (when there is no fog) */
    float max_distance;        /* > 0: no step starts at or beyond it (m); 0: no limit */
    const float* end_distance; /* NULL, or width*height distances (m, >= 0, +inf allowed) along each
                                  pixel's ray where it ends (a surface behind the medium) */
    int no_background;         /* 1: add no background (the caller composes what is behind) */
    const veil_volumetric_field* field; /* the volumetric stage's field; NULL or texture 0: none */
    int gather_rays;           /* a light cache's later light gathered towards the camera, rays a cell
                                  (render/shaders/cache_gather.comp; rounded to a square); 0: from its lobe.
                                  By default (frame/) where HG g >= VEIL_GATHER_MIN_G */
    float gather_step;         /* the gather's steps along its rays, in the cache's cells (> 0) */
    int gather_cells;          /* the gather's cells along the cache grid's longest side, at most (each then
                                  longest / gather_cells of the cache's a side); 0: VEIL_GATHER_MAX_CELLS */
    int deep_raw;              /* > 0: raw deep samples a pixel (render/deep.h), read into the image set's
                                  deep image (the march compiled with VEIL_MARCH_DEEP); 0: none */
    uint64_t band_work;        /* with a progress sink, a band's work (VEIL_MARCH_DISPATCH_WORK, or _SOFTWARE_WORK
                                  on a software rasteriser); 0: the first; without one, always the first */
    double band_seconds;       /* > 0 (with a progress sink): after the first band, each sized from the last's
                                  pace to take this long (VEIL_MARCH_BAND_SECONDS on a software rasteriser) */
    int skip_reads;            /* VEIL_MARCH_READ_* bits: images the caller does not need read back (their
                                  buffers stay NULL), and Z not made (VEIL_MARCH_READ_Z); rgba always is read */
} veil_march_desc;

/* The march's images besides rgba, for veil_march_desc.skip_reads (issue 42: a 1080p frame read back
 * 166 MB of five rgba32f images when its EXR held R, G, B, A). */
enum { VEIL_MARCH_READ_T = 1, VEIL_MARCH_READ_S = 2, VEIL_MARCH_READ_V = 4, VEIL_MARCH_READ_Q = 8, VEIL_MARCH_READ_Z = 16 };

#define VEIL_MARCH_IMAGES 5 /* rgba, T, S, V, Q */

/* What the last veil_march_run read back (--stats): images, bytes and the time of the reading (after the
 * march's GPU work finished), and whether the images were made anew (a new size) or kept. */
typedef struct veil_march_readback {
    int images, made;
    double bytes, ms;
} veil_march_readback;
veil_march_readback veil_march_last_readback(const veil_march* m);

/* The last run's images (rgba, T, S, V, Q: the image set's order, render/image_set.h), kept by m until
 * its next run of another size or its destruction: a later stage reads them on the GPU (the spread). */
void veil_march_images(const veil_march* m, unsigned int out[VEIL_MARCH_IMAGES]);

/* What the last veil_march_run gathered (render/shaders/cache_gather.comp): rays 0 when it did not. */
typedef struct veil_march_gather {
    int rays, dims[3];        /* rays a cell (a square), its cells */
    float scale;              /* the cache's cells a side of one of its cells (>= 1) */
    float step;               /* its rays' steps, in the cache's cells */
    double ms;                /* its time, apart from the march's */
} veil_march_gather;
veil_march_gather veil_march_last_gather(const veil_march* m);

veil_result veil_march_create(veil_march** out, veil_error* err);
void veil_march_destroy(veil_march* m); /* accepts NULL */

/* The march's own uniform block for d (the medium's: veil_lit_medium_fill). */
veil_result veil_march_block_fill(const veil_march_desc* d, veil_march_block* out, veil_error* err);

/* Marches every pixel and reads the image set back (*out: freed first). The march's images are kept
 * between calls of the same size (a turntable's frames make them once). */
veil_result veil_march_run(veil_march* m, const veil_march_desc* d, veil_image_set* out, veil_error* err);

/* Whether a w x h frame fits this device and this machine (issue 41: a
 * 16384^2 frame, within the documented limits, failed after the volume was
 * made with "GL_OUT_OF_MEMORY"): asked before any GPU work, of GL and of
 * the memory. The march makes VEIL_MARCH_IMAGES rgba32f textures of w x h
 * and the screen-space spread (spread: 1 when it may run) up to
 * VEIL_SPREAD_IMAGES' worth, each first asked of the driver as a proxy
 * texture (llvmpipe holds at most 1 GiB in one: 8192^2 rgba32f); the
 * textures' bytes within gpu_budget (veil_gl_info's memory_budget); the
 * image set and its EXR's planes (VEIL_IMAGE_HOST_BYTES a pixel), and on a
 * software rasteriser the textures too, within the machine's physical
 * memory. VEIL_ERR_LIMIT naming what does not fit, with the largest frame
 * of the same shape that does. Needs a current GL context. */
#define VEIL_SPREAD_IMAGES 9 /* 4 inputs, the output, 3 chains of 4/3 of a level */
#define VEIL_IMAGE_HOST_BYTES 192
veil_result veil_march_check_size(int w, int h, int spread, int hardware, unsigned long long gpu_budget,
                                  veil_error* err);

/* The rows of a band for d at w x h (a multiple of VEIL_MARCH_GROUP, or h). */
int veil_march_band_rows(const veil_march_desc* d, int w, int h);

/* Tests: the work budget of a band, over the desc's (0: the desc's again). */
void veil_march_set_dispatch_work(uint64_t work);

/* Tests: the work from which a frame's march is compiled for its lights (0: VEIL_MARCH_LIGHT_LIST_WORK
 * again; UINT64_MAX: never). */
void veil_march_set_light_list_work(uint64_t work);


#endif
