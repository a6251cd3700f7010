/* veil — a scene as plain data: camera, medium (coefficients, phase,
 * density sources), lights and background. No file format here: io/scene.h
 * reads scene files into these structs (docs/scene-format.md), and every
 * stage of the pipeline reads them.
 *
 * Units: metres, m^-1 for sigma_a/sigma_s (per unit density), W/sr for
 * point- and spot-light intensity, W/m^2 for directional irradiance,
 * degrees for the vertical field of view. A scene owns all of its memory;
 * veil_scene_free() releases it.
 */
#ifndef VEIL_SCENE_H
#define VEIL_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "../core/result.h"
#include "../core/shared.glsl.h"
#include "environment.h"
#include "light.h"
#include "particle.h"

#define VEIL_SCENE_DEFAULT_WIDTH 640
#define VEIL_SCENE_DEFAULT_HEIGHT 480
#define VEIL_SCENE_DEFAULT_FOV_Y 45.0f
#define VEIL_SCENE_DEFAULT_MAX_RES 128
#define VEIL_SCENE_MAX_IMAGE 16384   /* pixels per side */
#define VEIL_SCENE_MAX_RESOLUTION 2048 /* voxels per side; GL limit checked later */
#define VEIL_SCENE_MAX_PARTICLES 10000000u

/* Which side of the image the field of view spans (a DCC camera's sensor fit). */
typedef enum veil_sensor_fit {
    VEIL_FIT_VERTICAL = 0,   /* the height (the default: "fov_y_deg") */
    VEIL_FIT_HORIZONTAL = 1, /* the width */
    VEIL_FIT_AUTO = 2        /* the larger side (the width when they are equal), as Blender's AUTO */
} veil_sensor_fit;

typedef struct veil_camera {
    float position[3];
    float look_at[3];
    float up[3];      /* default (0,1,0) */
    float fov_y_deg;  /* field of view along the sensor_fit side, (0,180): the vertical one by default,
                         hence the name (the scene file's "fov_y_deg", or "fov_deg") */
    int width, height;
    int sensor_fit;   /* veil_sensor_fit */
    float shift[2];   /* the image window moved right (x) and up (y), in units of the fitted side's extent
                         (Blender's shift_x, shift_y); 0: centred on the view axis */
    float clip[2];    /* near and far distance along the view axis (m); the medium outside is not seen
                         (the background still is); far 0: no far plane */
    /* "shutter": [open, close], frames relative to the frame (open <= close, each within
     * VEIL_MAX_SHUTTER_FRAMES): vdb sources with a "velocity" are motion-blurred over it
     * (volume/motion_blur.h). has_shutter 0: no blur (the default) */
    int has_shutter;
    float shutter[2];
} veil_camera;

/* A shutter reaches at most this many frames from its frame: the blur
 * extrapolates the frame's velocity field as steady flow, which means
 * nothing over many frames (a film camera's shutter is open at most one
 * frame, 360 degrees). */
#define VEIL_MAX_SHUTTER_FRAMES 4.0
/* The scene's frame rate when it gives none ("fps"), frames per second:
 * velocities in units per second become displacements with it. */
#define VEIL_SCENE_DEFAULT_FPS 24.0
#define VEIL_SCENE_MAX_FPS 1000.0

/* What a vdb source's velocity grid holds per unit of time. */
typedef enum veil_velocity_unit {
    VEIL_VELOCITY_PER_SECOND = 0, /* world units per second (OpenVDB's, Houdini's "vel") */
    VEIL_VELOCITY_PER_FRAME = 1   /* world units per frame */
} veil_velocity_unit;

typedef enum veil_phase_type { VEIL_PHASE_ISOTROPIC = 0, VEIL_PHASE_HG = 1 } veil_phase_type;

typedef struct veil_phase {
    veil_phase_type type;
    float g; /* HG asymmetry in (-1, 1); 0 for isotropic */
} veil_phase;

typedef enum veil_source_type {
    VEIL_SOURCE_RBF = 0,
    VEIL_SOURCE_RBF_RANDOM = 1,
    VEIL_SOURCE_VDB = 2,
    VEIL_SOURCE_EXPONENTIAL = 3,
    VEIL_SOURCE_ARRAY = 4 /* a grid from memory (veil_scene_set_grid): a vdb source without a file */
} veil_source_type;

/* An OpenVDB float grid ({"type":"vdb", ...}), or a grid from memory
 * ({"type":"array", ...}: no file, no sequence, no level set; its grids are
 * the scene's, veil_scene_grid, found by name). */
typedef struct veil_vdb_source {
    char* file;          /* resolved against the scene's folder (owned); for a sequence, the current frame's */
    char* sequence;      /* the file's frame pattern when "file" holds one ("smoke.####.vdb"), resolved
                            (owned); NULL: one file for every frame. veil_scene_set_frame() sets `file` */
    long frame_offset;   /* "frame_offset": the file of frame f is the pattern's frame f + frame_offset */
    char* grid;          /* grid name, or NULL: "density", else the first float grid (owned) */
    float density_scale; /* multiplies the grid's values; default 1 */
    int level_set_to_fog; /* "level_set": "to_fog": convert a level set instead of refusing it */
    /* "emission": {"grid", "scale", "color"}: the medium emits radiance
     * eps = scale * value * color per metre of path (W m^-3 sr^-1, i.e.
     * W/(m^2 sr) of radiance added per m), from the named float grid of
     * the same file; NULL grid: no emission */
    char* emission_grid; /* owned */
    float emission_scale;
    float emission_color[3];
    /* "temperature": {"grid", "scale", "offset", "intensity"}: blackbody
     * emission, kelvin = scale * value + offset, eps = k rho B_rgb(kelvin)
     * (volume/blackbody.h), k the medium's sigma_a per channel (Kirchhoff:
     * what absorbs, emits) unless "intensity" (m^-1 per unit density) is
     * given; rho this source's density. NULL grid: none */
    char* temperature_grid; /* owned */
    float temperature_scale, temperature_offset;
    float temperature_intensity; /* < 0: sigma_a (the default) */
    /* "transform": the source placed in the world, column vectors, affine and invertible: world =
     * transform x (the grid's own index-to-world map), for the density, emission and temperature
     * grids alike. has_transform 0: the grids' own maps */
    int has_transform;
    double transform[4][4];
    /* "velocity": {"grid", "unit", "scale"}: the grid the density moves with, for motion
     * blur under the camera's shutter (volume/motion_blur.h); has_velocity 0: none.
     * velocity_grid NULL: the first of "vel", "v", "velocity" (a vec3 grid, or three float
     * grids NAME.x, NAME.y, NAME.z) the file holds */
    int has_velocity;
    char* velocity_grid;   /* owned */
    int velocity_unit;     /* veil_velocity_unit */
    float velocity_scale;  /* multiplies the vectors; default 1 */
} veil_vdb_source;

/* Analytic exponential (height) fog ({"type":"exponential", ...}):
 * density(x) = density * exp(-falloff * <x - origin, direction>) inside the
 * box `bounds` (the stated range that clips the otherwise unbounded fog),
 * 0 outside. Never voxelised: its optical depth is the closed form. */
typedef struct veil_exp_fog {
    float density;      /* at the origin plane (unitless density) */
    float falloff;      /* b, m^-1, >= 0 (0: homogeneous) */
    float direction[3]; /* n, unit: the density falls off along it */
    float origin[3];    /* o, m */
    float bounds[2][3]; /* min and max corner, m */
} veil_exp_fog;

typedef struct veil_source {
    veil_source_type type;
    /* VEIL_SOURCE_RBF: explicit particles (owned) */
    veil_particle* particles;
    size_t particle_count;
    char* particle_file; /* the particle file they were read from, resolved (owned); NULL: inline */
    /* VEIL_SOURCE_RBF_RANDOM */
    veil_rbf_random_desc random;
    /* VEIL_SOURCE_VDB and VEIL_SOURCE_ARRAY */
    veil_vdb_source vdb;
    /* VEIL_SOURCE_EXPONENTIAL */
    veil_exp_fog fog;
} veil_source;

/* The default extent of exponential fog around its origin when the scene
 * gives no bounds: a cube of this half-width (m). */
#define VEIL_FOG_DEFAULT_HALF_EXTENT 1000.0f
/* At most VEIL_MAX_FOGS (core/shared.glsl.h) exponential fogs. */

/* How the extinction volume holds a VDB's voxels (volume/sparse.h):
 * automatic (dense when the native grid fits the dense cap, else sparse
 * where the scene allows it), or as the user asks. */
typedef enum veil_representation {
    VEIL_REPRESENTATION_AUTO = 0,
    VEIL_REPRESENTATION_DENSE,
    VEIL_REPRESENTATION_SPARSE
} veil_representation;

typedef struct veil_medium {
    float sigma_a[3]; /* m^-1 per unit density, default 0 */
    float sigma_s[3]; /* m^-1 per unit density */
    veil_phase phase; /* default isotropic */
    int max_resolution; /* voxels along the longest side of the EV */
    /* 1: max_resolution was given (a cap the user chose). 0: the default,
     * which applies to particles only: a VDB source then keeps its own
     * voxels (volume/scene_volume.h, "native resolution"). */
    int max_resolution_set;
    veil_representation representation; /* medium.representation */
    veil_source* sources; /* owned */
    size_t source_count;
} veil_medium;

/* Lights: veil_light (scene/light.h). */

/* Multiple scattering ("multiple_scattering" in a scene file; see
 * docs/multiple-scattering.md for the derivation and the measurements that
 * chose the defaults). Two estimates, each switched on or off:
 *  - screen-space: the hierarchical spread of Iser & Elek (CESCG 2018, after
 *    Elek et al. 2013): the light scattered out of each pixel's beam (of the
 *    background, and of the single scattering on its way to the camera) is
 *    spread with Premoze's Gaussian width W(P), through MIP chains;
 *  - volumetric: by default the light cache (volumetric/cache.h): photons
 *    from every light and the emission, their fluence and flux on a grid
 *    the march scatters once more (orders >= 2); or the octave approximation
 *    (Wrenninge et al. 2013): each light's in-scattering is repeated with the
 *    optical depth scaled by a^i, the contribution by b^i and the phase
 *    function's g by c^i; or a diffusion solve. */
typedef enum veil_spread_filter { VEIL_SPREAD_2X2 = 0, VEIL_SPREAD_4X4 = 1, VEIL_SPREAD_6X6 = 2 } veil_spread_filter;
/* VEIL_INTERP_* (core/shared.glsl.h: the fetch shader reads the same values) */
typedef int veil_spread_interp;

typedef enum veil_volumetric_method {
    VEIL_VOLUMETRIC_OCTAVE = 0,    /* octaves in the march (render/shaders/march.comp) */
    VEIL_VOLUMETRIC_DIFFUSION = 1, /* a diffusion solve on a coarse grid (volumetric/volumetric.h) */
    VEIL_VOLUMETRIC_CACHE = 2      /* the light cache: photons from every source (volumetric/cache.h) */
} veil_volumetric_method;

typedef enum veil_octave_gate {
    VEIL_GATE_LEGS = 0,  /* 1 - exp(-sigma_s (D + P)): the two legs through the point (light, camera) */
    VEIL_GATE_ESCAPE = 1 /* the chance to scatter again, averaged over 14 directions (a view-independent field) */
} veil_octave_gate;

typedef struct veil_multiple {
    int screen_space;     /* 1: the screen-space spread */
    int volumetric;       /* 1: a volumetric estimate, volumetric_method */
    veil_volumetric_method volumetric_method;
    int diffusion_cells;  /* the diffusion grid's cells along its longest side, 8..256 */
    int diffusion_iterations; /* red-black SOR sweeps; 0: 3 x the longest side */
    /* the light cache (volumetric/cache.h) */
    long long cache_photons; /* photons in all; 0: the quality rung's */
    int cache_cells;         /* cells along the grid's longest side, 4..512; 0: the quality rung's */
    unsigned cache_seed;     /* the cache's random stream: the same seed gives the same cache */
    int cache_gather_rays;   /* the later light gathered towards the camera (render/march.h), rays a cell;
                                0: the quality rung's; -1: off (its lobe, as the draft rung) */
    /* screen-space */
    float c;              /* pixels: a level-k texel spreads by about c 2^(k-1) (paper: 0.86) */
    float mask_epsilon;   /* unitless: width of the leak mask, smoothstep(T, (1+eps) T, W) (paper: 2) */
    int mask;             /* 1: mask illumination leaking (paper) */
    int luminance_weighting; /* 1: the spread-space chain W is luminance-weighted (paper) */
    int density_blur;     /* 1: the level is read through the blurred density chain P (paper) */
    int levels;           /* K, the coarsest level; 0: from the image size (see render/spread.h) */
    veil_spread_filter filter;
    float weights[6];     /* the 1D filter taps (filter 2, 4 or 6 of them), normalised to sum 1 */
    veil_spread_interp interp;
    int separation;       /* 1: bright pixels get their own chain (paper: optional) */
    float sep_luminance;  /* T_y: luminance (linear RGB radiance) above which a pixel is bright */
    float sep_luminance_width; /* eps_y: same unit */
    float sep_density;    /* T_d': integrated density (density m) below which it may be separated */
    float sep_density_width;   /* eps_d': same unit */
    float k_ssc;          /* the separated chain's level as a fraction of K (paper: 0.7) */
    float thin_threshold; /* unitless: the spread is skipped where max P * sigma_s (mean) is below it */
    /* volumetric (octave) */
    int octaves;          /* N >= 1: octaves 1..N-1 are added (octave 0 is single scattering) */
    float octave_a;       /* extinction scale per octave, (0, 1] */
    float octave_b;       /* contribution scale per octave, [0, 1) */
    float octave_c;       /* phase g scale per octave, [0, 1] */
    int octave_gate;      /* VEIL_GATE_*: what scales the octaves where little medium surrounds a point */
    /* the medium's emission as up to this many point lights (volume/emission_lights.h), 0..16: what the
     * fire emits lights its smoke through every estimate; the scene's own lights come first */
    int emission_lights;
} veil_multiple;

/* The defaults: every field as documented in docs/scene-format.md. */
void veil_multiple_defaults(veil_multiple* m);
/* The default taps of each filter size (2, 4 or 6 values). */
void veil_spread_default_weights(veil_spread_filter f, float w[6]);
/* Taps of filter f: 2, 4 or 6. */
int veil_spread_taps(veil_spread_filter f);

/* The quality ladder (frame/renderer.h says what each rung sets). */
typedef enum veil_quality {
    VEIL_QUALITY_UNSET = 0, /* the scene's, else VEIL_QUALITY_DEFAULT */
    VEIL_QUALITY_DRAFT,
    VEIL_QUALITY_DEFAULT,
    VEIL_QUALITY_HIGH,
    VEIL_QUALITY_MAX,
    VEIL_QUALITY_COUNT
} veil_quality;

/* "draft", "default", "high", "max" (NULL for anything else) */
const char* veil_quality_name(veil_quality q);
/* 1 on success */
int veil_quality_parse(const char* name, veil_quality* out);

/* A grid given from memory (veil_scene_set_grid), read by the "array"
 * sources that name it. */
typedef struct veil_scene_grid {
    char* name;                 /* owned */
    float* data;                /* dims product floats (owned): x fastest, or z fastest when z_fastest */
    int dims[3];
    int z_fastest;
    double index_to_world[4][4]; /* column vectors */
    uint64_t hash;              /* of the values, dims, order and map: the stage caches' key */
} veil_scene_grid;

/* A deep image's cap, samples a pixel (render/deep.h): the default of
 * "deep": {"samples"} and --deep-samples, and their bound (the merge costs
 * O(raw^2) a pixel, raw = 4 x the cap, and a compositor slows with every
 * sample a pixel). */
#define VEIL_DEEP_DEFAULT_SAMPLES 8
#define VEIL_DEEP_MAX_SAMPLES 64

typedef struct veil_scene {
    char* path;     /* the file as given, or the name messages give a scene from memory (owned) */
    int path_is_file; /* 1: path is the file the scene was read from (veil_scene_load) */
    char* base_dir; /* its folder, for relative paths (owned) */
    veil_camera camera;
    veil_medium medium;
    veil_light* lights; /* owned */
    size_t light_count;
    float background[3]; /* linear RGB radiance seen through the medium */
    int background_set;  /* 1: "background" was given (with an environment: seen instead of it) */
    veil_environment environment; /* a light of type "environment" (at most one; not in `lights`) */
    veil_multiple multiple;
    veil_quality quality; /* "quality": UNSET when absent */
    int deep_samples;     /* "deep": {"samples"}: a deep image's cap (render/deep.h); 0 when absent */
    double fps;           /* "fps": frames per second, (0, VEIL_SCENE_MAX_FPS]; 0 read as the default */
    veil_scene_grid* grids; /* owned; grid_count of them */
    size_t grid_count;
} veil_scene;

void veil_scene_free(veil_scene* s); /* accepts NULL and zeroed scenes */

/* The lights the GPU pipeline carries: the scene's, and the environment's directional lights (its median cut). */
static inline size_t veil_scene_light_total(const veil_scene* s)
{
    return s->light_count + (size_t)veil_env_cut_max(&s->environment);
}

/* Copies a grid into s under `name`, replacing one of the same name (an
 * "array" source reads it). Checks the dimensions (each >= 1, the product
 * within VEIL_VDB_MAX_DENSE_VOXELS' 2^30) and that the map is affine with a
 * finite, invertible 3x3 part; the values are checked when read. */
veil_result veil_scene_grid_set(veil_scene* s, const char* name, const float* data, const int dims[3], int z_fastest,
                                const double index_to_world[4][4], veil_error* err);
/* An index-to-world or placement matrix m (column vectors, finite): 1 when
 * it is affine (last row 0 0 0 1) and invertible, 0 when affine but
 * singular (|det| <= 1e-12 x its longest column's cube: a voxel of no
 * volume), -1 when not affine. *det: its 3x3 part's determinant. */
int veil_affine_check(const double m[4][4], double* det);
/* The grid named `name`, or NULL. */
const veil_scene_grid* veil_scene_grid_find(const veil_scene* s, const char* name);

/* Points every sequence source of s at its file for frame `frame`
 * (pattern frame + frame_offset). VEIL_ERR_IO naming the source, the frame
 * and the file when that file cannot be read; s is left pointing at the
 * frames it could set. A scene without sequences is left as it is. */
veil_result veil_scene_set_frame(veil_scene* s, long frame, veil_error* err);
/* 1 when some source of s is a sequence. */
int veil_scene_is_sequence(const veil_scene* s);

/* A file a scene reads besides itself: a VDB source's file or a sequence's
 * frame pattern, an RBF source's particle file, or the environment light's
 * map (points into the scene). */
typedef struct veil_scene_file {
    char field[48];    /* how a message names it: "medium.sources[2].file", "lights[1].file" */
    const char* path;  /* the file; a sequence's pattern when `sequence` */
    int sequence;      /* 1: frame f reads the pattern's frame f + frame_offset */
    long frame_offset;
} veil_scene_file;
/* The files s reads, in the order of its sources, then the environment's
 * map, into out[0 .. n); returns how many there are (n = 0 counts them).
 * No file is opened. */
size_t veil_scene_files(const veil_scene* s, veil_scene_file* out, size_t n);
/* The file f names for frame `frame` (a sequence's: the pattern's frame
 * frame + frame_offset; otherwise f->path). VEIL_ERR_LIMIT when it does
 * not fit in n bytes. */
veil_result veil_scene_file_at(const veil_scene_file* f, long frame, char* out, size_t n, veil_error* err);

/* All particles of all RBF sources (explicit and generated), newly
 * allocated into *out (free() it). */
veil_result veil_scene_particles(const veil_scene* s, veil_particle** out,
                                 size_t* count, veil_error* err);

#endif
