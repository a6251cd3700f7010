/* veil — the frame as a table of stages.
 *
 *   sources --inject--> extinction volume (volume/ev.h)
 *           --propagate--> optical depth per light (propagate/opv_set.h)
 *           --volumetric--> multiply scattered light, view-independent (volumetric/volumetric.h)
 *           --render--> the march: image set (render/march.h)
 *           --spread--> screen-space multiple scattering (render/spread.h)
 *
 * Each row of veil_stage_table is one stage (frame/stage.h): key() from
 * descriptions only, decide() without a GPU (ran / cached / skipped and
 * why, given whether a result with the key is kept), build() (the GPU
 * work, run only when decide() says "ran"; it may refine the report with
 * what it measured), and settle() (what the stage leaves to the next rows,
 * whatever it decided). frame/renderer.c renders a frame by walking the
 * table; frame/plan.c (`--explain`) walks the same table with the same
 * keys and decisions and builds nothing. Adding a stage is one row.
 *
 * Every setting is resolved once per frame into a veil_frame_plan that the
 * rows read: the options (veil_render_opts_resolve), then, once the volume
 * is known (after inject, or from the files' headers when explaining), the
 * lights that add light and the propagation's parameters
 * (veil_frame_plan_volume).
 */
#ifndef VEIL_STAGES_H
#define VEIL_STAGES_H

#include <stddef.h>
#include <stdint.h>

#include "../core/result.h"
#include "../propagate/opv.h"
#include "../propagate/opv_set.h"
#include "../render/deep.h"
#include "../render/image_set.h"
#include "../scene/scene.h"
#include "../scene/solid.h"
#include "../volume/sparse.h"
#include "../volume/volume.h"
#include "../volumetric/volumetric.h"
#include "stage.h"

/* Jacobi stops when a checked step changes no optical depth sigma_t * D by
 * more than this (unitless): well under the 8-bit resolution of a preview. */
#define VEIL_OPV_TAU_TOLERANCE 1e-4f

/* Zero means "default" in every field; veil_render_opts_resolve() says
 * what zero resolves to. */
typedef struct veil_render_opts {
    int width, height;      /* 0: the camera's */
    float step_voxels;      /* 0: the quality rung's */
    uint32_t seed;          /* jitter seed */
    veil_opv_method method; /* 0: the quality rung's */
    veil_quality quality;   /* UNSET: the scene's "quality", else VEIL_QUALITY_DEFAULT */
    float sun_across, sun_along; /* light-space grids' node spacing (voxels); 0: the rung's */
    const veil_camera* camera; /* NULL: the scene's (turntables move it) */
    int no_skip;            /* 1: march through empty bricks too (to measure what skipping saves) */
    /* > 0: rays stop at the first step boundary at or beyond this distance
     * from the camera (m); the steps before it are the same as without it,
     * so alpha (1 - mean T) is the transmittance of a prefix of the same
     * march (tests of T along rays). 0: no limit. */
    float max_distance;
    /* A frame rendered elsewhere (veil fog): width*height RGBA radiance of
     * the surfaces behind the medium (replacing the scene's background;
     * the screen-space spread blurs it) and, per pixel, their distance
     * along the camera ray (m, >= 0, +inf: nothing there), where each ray
     * ends. NULL: the scene's background at infinity. */
    const float* behind;
    const float* behind_distance;
    /* 1: the surfaces at behind_distance neither shadow the medium nor absorb its light (by default they
     * do: scene/solid.h) */
    int behind_not_solid;
    /* 1: a deep image too (the image set's deep, render/deep.h), of at most deep_samples samples a pixel
     * (0: the scene's "deep": {"samples"}, else VEIL_DEEP_DEFAULT_SAMPLES) */
    int deep;
    int deep_samples;
    /* 1: the caller keeps R, G, B, A alone (an EXR without AOVs): the march's other images are read back
     * only where a later step needs them (the screen-space spread, a frame behind, the deep image), and Z
     * is not made (issue 42) */
    int flat_only;
} veil_render_opts;

/* opts (NULL: all defaults) with every zero replaced by what it means for
 * scene s: the one place defaults are resolved. */
veil_render_opts veil_render_opts_resolve(const veil_render_opts* opts, const veil_scene* s);

/* What a rung of the quality ladder sets (each 0 left to the options). */
typedef struct veil_quality_rung {
    float step_voxels;
    veil_opv_method method;
    float sun_across, sun_along;
    long long cache_photons; /* the light cache's budget (volumetric/cache.h) */
    int cache_cells;
    int gather_rays;         /* the cache's later light gathered towards the camera: rays a cell (0: off) */
    float gather_step;       /* and its rays' steps, in the cache's cells (render/march.h) */
    int gather_cells;        /* and its cells along the grid's longest side, at most */
    int env_lights;          /* an environment light as this many directional lights (scene/environment.h) */
} veil_quality_rung;
const veil_quality_rung* veil_quality_rung_of(veil_quality q); /* UNSET: the default rung */

/* The lights of s that add light inside the box of g (NULL: fog only, no
 * box), in scene order, into out (VEIL_MAX_LIGHTS): zero colour never
 * does; a spot whose outer cone misses the box's bounding sphere does not.
 * Then an environment's median cut into env_lights: of the whole map, or
 * with env_split, of its bright part alone (the light cache carries the
 * rest: scene/environment.h). */
int veil_render_lights(const veil_scene* s, const veil_grid* g, int env_lights, int env_split, veil_light* out);
/* Whether s's environment is split (its bright part the cut's, its rest the light cache's): s has one, its
 * "remainder" is "cache" and the light cache is the volumetric method (the plan also asks for a grid). */
int veil_env_split(const veil_scene* s);

/* A frame's plan: every setting resolved once, read by every row. */
typedef struct veil_frame_plan {
    const veil_scene* scene;
    veil_render_opts o;             /* resolved (veil_render_opts_resolve) */
    int fogs;                       /* analytic fogs (closed form, never voxelised) */
    unsigned long long budget;      /* the device's memory budget (bytes); 0 when explaining */
    int hardware;                   /* the device is not a software rasteriser (veil_gl_info); 0 when explaining */
    /* the density given on a grid instead of the scene's sources (veil_render_density); NULL: the sources */
    const veil_grid* given_grid;
    const float* given_density;
    int volume_needed;              /* some source is voxelised (or a density is given) */
    /* the volume: after inject (a render) or from the files' headers (explaining) */
    const veil_grid* grid;          /* NULL: none */
    int sparse;                     /* held sparse (volume/sparse.h) */
    uint64_t ev_key;                /* inject's key */
    size_t particles, vdb_voxels;   /* explaining: what the files hold */
    const char* resolution;         /* explaining: how the grid was chosen */
    int emission_possible;          /* explaining: the volume glows and emission lights are asked for */
    /* veil_frame_plan_volume(): the lights that add light (the scene's, then the emission's) */
    veil_light lights[VEIL_MAX_LIGHTS];
    int light_count, emission_lights;
    int env_split;                  /* the environment's cut is of its bright part; the cache carries the rest */
    int glows;                      /* a voxelised source emits (the light cache traces its light) */
    veil_opv_params opv;            /* the propagation's method and parameters */
    /* the lights in the grid's index space, and the suns that get a light-space grid (as planned
     * without a device: at most VEIL_GL_MIN_3D_TEXTURE nodes an axis; propagate/opv_set.h) */
    veil_index_light index_lights[VEIL_MAX_LIGHTS];
    veil_opv_sun suns[VEIL_MAX_SUNS];
    uint64_t sun_keys[VEIL_MAX_SUNS];
    int sun_count;
    veil_volumetric_desc volumetric; /* its kind (VEIL_FIELD_NONE: no field wanted) and grid settings */
    /* explaining a sparse volume: the frame's work as estimated before the gather (volume/sparse.h), and
     * why a render refuses it ("" when it does not) */
    veil_sparse_work sparse_work;
    char sparse_refusal[VEIL_ERROR_MAX];
} veil_frame_plan;

/* The plan's first step: the options resolved for scene s. */
void veil_frame_plan_begin(veil_frame_plan* p, const veil_scene* s, const veil_render_opts* opts,
                           unsigned long long budget);

/* Its second, once the volume is known (g NULL: none): the lights that add
 * light, then up to `n_emission` of `emission` (the medium's glow as
 * lights) while there is room, and the propagation's parameters. */
void veil_frame_plan_volume(veil_frame_plan* p, const veil_grid* g, int sparse, const veil_light* emission,
                            int n_emission);

/* The work of a frame over the sparse volume v (nothing when v is not
 * sparse) under plan p, estimated before the gather: the census of its
 * bricks (refused over VEIL_SPARSE_MAX_BRICKS, a tile counted by its box,
 * never expanded), the lights as planned on v's grid (and the emission's,
 * while there is room, as points at its middle: they are made by the
 * gather), their passes as propagate/opv_set.c orders them, and the
 * escape field's rays when the octaves ask for it. VEIL_ERR_LIMIT with the
 * numbers over VEIL_SPARSE_MAX_SECONDS. Needs no GPU. */
struct veil_scene_volume;
veil_result veil_frame_sparse_estimate(const veil_frame_plan* p, const struct veil_scene_volume* v,
                                       veil_sparse_work* w, veil_error* err);

/* The GPU objects that hold the stages' results between frames (owned by
 * the renderer; the rows only use them) and the keys they hold. */
typedef struct veil_frame_parts {
    struct veil_ev* ev;
    struct veil_opv_set* opv;
    struct veil_volumetric* volumetric;
    struct veil_march* march;
    struct veil_spread* spread;
    uint64_t kept[VEIL_STAGE_COUNT]; /* the key of what each stage holds */
    int has[VEIL_STAGE_COUNT];       /* 1: it holds a result (an empty medium included) */
    int opv_textures;                /* textures the kept optical depths use */
    size_t particles;                /* the kept EV's RBF particles (for the report) */
} veil_frame_parts;

typedef struct veil_render_stats {
    veil_stage_report stage[VEIL_STAGE_COUNT];
    double inject_ms, propagate_ms, render_ms; /* = stage[...].ms */
    int width, height;    /* the image's size */
    int has_volume;       /* 0: nothing to inject (empty medium) */
    int inject_cached;    /* the EV was reused */
    veil_grid grid;       /* the EV's geometry when has_volume */
    size_t particles;
    size_t vdb_voxels;    /* active voxels of the OpenVDB grids (0 when cached) */
    int lights_used;      /* lights that reach the medium and add light (with the emission's) */
    int emission_lights;  /* of them, the medium's emission as lights (volume/emission_lights.h) */
    int fogs;             /* analytic fogs (closed form, never voxelised) */
    int opv_computed, opv_cached; /* OPV textures made / reused */
    int grids, grids_computed; /* light-space grids in use / made by this frame (propagate/sun_space.h) */
    veil_opv_method method;
    int propagate_iterations; /* Jacobi steps or sweep passes (most of any light) */
    veil_deep_report deep;    /* the deep image's merge (render/deep.h), when one was made */
} veil_render_stats;

/* One frame in flight: the plan and, in a render, where the rows work. */
typedef struct veil_frame {
    veil_frame_plan plan;
    veil_frame_parts* parts;         /* NULL when explaining */
    veil_render_stats* st;           /* a render's report (NULL when explaining) */
    veil_image_set* images;          /* the march's output */
    veil_volumetric_field field;     /* the volumetric stage's field for the march */
    /* Makes the GPU's side (a renderer whose GL context is deferred: its context and stages' objects, and
     * plan.budget) if it is not made yet; inject calls it once the sources are opened and their work
     * estimated, so that a refused volume never costs a GL context. NULL: always made. */
    veil_result (*gpu)(struct veil_frame* f, veil_error* err);
    void* gpu_user;
    double gpu_ms; /* the time gpu() spent making the GPU's side: no stage's work, so no stage's time */
    int size_checked; /* gpu() asked the device whether the frame's images fit (veil_march_check_size) */
    /* veil fog: the frame's surfaces as a solid (scene/solid.h) and its textures (voxels, shadow maps), made
     * by the first row that needs them and freed with the frame (veil_frame_end) */
    veil_solid solid;
    unsigned int solid_tex[2];
    int solid_made;
    double solid_ms;
} veil_frame;

/* Frees what a frame made for itself (the solid). */
void veil_frame_end(veil_frame* f);

/* A row of the table. decide() and key() read only the plan and never a
 * GPU; `kept` is 1 when the stage holds a result with this key. */
typedef struct veil_stage_row {
    veil_stage_id id;
    int per_view; /* 1: depends on the camera: runs every frame, holds nothing */
    const char* doing; /* what the progress line says while it works */
    uint64_t (*key)(const veil_frame_plan* p);
    veil_stage_status (*decide)(const veil_frame_plan* p, int kept, char* why, size_t n);
    veil_result (*build)(veil_frame* f, veil_stage_report* rep, veil_error* err);
    void (*settle)(veil_frame* f, const veil_stage_report* rep); /* NULL: nothing to leave */
} veil_stage_row;

/* The table, in pipeline order (row i is stage i). */
extern const veil_stage_row veil_stage_table[VEIL_STAGE_COUNT];

#endif
