/* veil — the single-scattering ray march (render/shaders/march.comp): one
 * invocation per pixel, from the camera through the EV (trilinear over its
 * voxel centres' box) and the analytic fogs, lit through the optical-depth
 * volumes. Writes an image set (render/image_set.h).
 *
 * The march owns its program; the volume, the OPVs and the lights are the
 * caller's (frame/ brings them up to date first). Needs the GL context
 * current at creation.
 */
#ifndef VEIL_MARCH_H
#define VEIL_MARCH_H

#include <epoxy/gl.h>
#include <stdint.h>

#include "../core/result.h"
#include "../propagate/opv_set.h"
#include "../scene/scene.h"
#include "../volume/ev.h"
#include "../volume/volume.h"
#include "image_set.h"

/* Ray-march step as a fraction of the voxel edge. Half a voxel resolves the
 * trilinear medium between centres; the step error is measured, not assumed. */
#define VEIL_DEFAULT_STEP_VOXELS 0.5f

/* The smallest march step through fog when there is no volume (m). */
#define VEIL_FOG_MIN_STEP 0.01f

/* Point lights closer than this fraction of a voxel count as this far (the
 * 1/r^2 singularity is integrable in the continuum but not in samples). */
#define VEIL_MIN_LIGHT_DISTANCE_VOXELS 1e-3f

/* The march goes in bands of rows, as many rows a dispatch as keep its
 * estimated work (pixels x steps a ray x (1 + lights)) under this: a GPU
 * watchdog stops a dispatch of a few seconds, and a 16384^2 frame through
 * a dense volume is 10^11 steps. At 10^9 to 10^10 steps a second (a
 * desktop GPU) a band takes 0.03 to 0.3 s; on llvmpipe bands only add
 * progress reports. The estimate of steps a ray: the volume box's diagonal
 * over the step, plus 64 a fog. */
#define VEIL_MARCH_DISPATCH_WORK ((uint64_t)1 << 28)

typedef struct veil_march veil_march;

/* A multiply scattered fluence field the march reads (render/diffusion.h). */
typedef struct veil_diffusion_field {
    GLuint texture;     /* rgba32f 3D, 0: none */
    float kind;         /* VEIL_FIELD_FLUENCE or VEIL_FIELD_ESCAPE (core/shared.glsl.h) */
    float tex_min[3];   /* texture coordinates are (x - tex_min) * tex_inv */
    float tex_inv[3];
} veil_diffusion_field;

typedef struct veil_march_desc {
    const veil_scene* scene;   /* medium coefficients, fogs, background */
    const veil_camera* camera;
    int width, height;
    const veil_light* lights;  /* the lights that add light (frame/ drops the rest) */
    int light_count;
    const veil_grid* grid;     /* NULL: no volume (fog only) */
    GLuint ev, occupancy;      /* the EV's textures when grid is set */
    const veil_ev_sparse* sparse; /* a sparse EV (ev is then its atlas, occupancy 0; the optical depths and
                                     the escape field are atlases too); NULL: dense */
    GLuint emission;           /* the EV's emission texture (0: none) */
    const GLuint* opv;         /* VEIL_MAX_OPV_TEXTURES textures (0 where unused) */
    const veil_opv_sun* suns;  /* light-space grids of suns (propagate/opv_set.h), dense volumes only */
    int sun_count;
    float step_voxels;         /* > 0 */
    uint32_t seed;             /* jitter seed */
    int skip_empty;            /* 1: jump over bricks without density (when there is no fog) */
    float max_distance;        /* > 0: no step starts at or beyond it (m); 0: no limit */
    const float* end_distance; /* NULL, or width*height distances (m, >= 0, +inf allowed) along each
                                  pixel's ray where it ends (a surface behind the medium) */
    int no_background;         /* 1: add no background (the caller composes what is behind) */
    const veil_diffusion_field* diffusion; /* NULL or texture 0: none */
} veil_march_desc;

veil_result veil_march_create(veil_march** out, veil_error* err);
void veil_march_destroy(veil_march* m); /* accepts NULL */

/* The uniform block for d (exposed so tests can check what the shader gets). */
veil_result veil_march_block_fill(const veil_march_desc* d, veil_march_block* out, veil_error* err);

/* Marches every pixel and reads the image set back (*out: freed first). */
veil_result veil_march_run(veil_march* m, const veil_march_desc* d, veil_image_set* out, veil_error* err);

/* The rows of a band for d at w x h (a multiple of VEIL_MARCH_GROUP, or h). */
int veil_march_band_rows(const veil_march_desc* d, int w, int h);

/* Tests: the work budget of a band (0: VEIL_MARCH_DISPATCH_WORK again). */
void veil_march_set_dispatch_work(uint64_t work);

/* Binds d's optical depths (OPV textures and light-space grids) for a pass
 * that reads render/shaders/medium_common.glsl; 0 unbinds them. */
void veil_march_bind_depths(const veil_march_desc* d);

#endif
