/* veil — scene files (JSON), parsed into plain structs.
 *
 * The format is documented in docs/scene-format.md. Units: metres, m^-1 for
 * sigma_a/sigma_s (per unit density), W/sr for point- and spot-light intensity, W/m^2
 * for directional irradiance, degrees for the vertical field of view.
 *
 * veil_scene_load() reads a file; every error message starts with the file
 * name, then the JSON path of the offending field (e.g. `lights[1].intensity`)
 * and what was expected. Unknown keys are errors. Relative paths inside the
 * scene resolve against the scene file's folder (scene->base_dir).
 * The scene owns all of its memory; veil_scene_free() releases it.
 */
#ifndef VEIL_SCENE_H
#define VEIL_SCENE_H

#include <stddef.h>

#include "../core/result.h"
#include "../core/shared.glsl.h"
#include "../volume/rbf.h"

#define VEIL_SCENE_DEFAULT_WIDTH 640
#define VEIL_SCENE_DEFAULT_HEIGHT 480
#define VEIL_SCENE_DEFAULT_FOV_Y 45.0f
#define VEIL_SCENE_DEFAULT_MAX_RES 128
#define VEIL_SCENE_MAX_IMAGE 16384   /* pixels per side */
#define VEIL_SCENE_MAX_RESOLUTION 2048 /* voxels per side; GL limit checked later */
#define VEIL_SCENE_MAX_PARTICLES 10000000u

typedef struct veil_camera {
    float position[3];
    float look_at[3];
    float up[3];      /* default (0,1,0) */
    float fov_y_deg;  /* vertical field of view, (0,180) */
    int width, height;
} veil_camera;

typedef enum veil_phase_type { VEIL_PHASE_ISOTROPIC = 0, VEIL_PHASE_HG = 1 } veil_phase_type;

typedef struct veil_phase {
    veil_phase_type type;
    float g; /* HG asymmetry in (-1, 1); 0 for isotropic */
} veil_phase;

typedef enum veil_source_type { VEIL_SOURCE_RBF = 0, VEIL_SOURCE_RBF_RANDOM = 1 } veil_source_type;

typedef struct veil_source {
    veil_source_type type;
    /* VEIL_SOURCE_RBF: explicit particles (owned) */
    veil_particle* particles;
    size_t particle_count;
    /* VEIL_SOURCE_RBF_RANDOM */
    veil_rbf_random_desc random;
} veil_source;

typedef struct veil_medium {
    float sigma_a[3]; /* m^-1 per unit density, default 0 */
    float sigma_s[3]; /* m^-1 per unit density */
    veil_phase phase; /* default isotropic */
    int max_resolution; /* voxels along the longest side of the EV */
    veil_source* sources; /* owned */
    size_t source_count;
} veil_medium;

/* VEIL_LIGHT_POINT, VEIL_LIGHT_DIRECTIONAL or VEIL_LIGHT_SPOT (core/shared.glsl.h)
 * (the shaders use the same values); at most VEIL_MAX_LIGHTS lights. */
typedef int veil_light_type;

typedef struct veil_light {
    veil_light_type type;
    float position[3];  /* point, spot: m */
    float direction[3]; /* directional, spot: unit vector in which light travels (spot: its axis) */
    float color[3];     /* point, spot: intensity W/sr on the axis; directional: irradiance W/m^2 */
    /* spot: full intensity within inner_angle_deg of the axis, none beyond
     * outer_angle_deg, veil_spot_falloff() between; 0 <= inner < outer <= 180 */
    float inner_angle_deg, outer_angle_deg;
} veil_light;

typedef struct veil_scene {
    char* path;     /* the file as given (owned) */
    char* base_dir; /* its folder, for relative paths (owned) */
    veil_camera camera;
    veil_medium medium;
    veil_light* lights; /* owned */
    size_t light_count;
    float background[3]; /* linear RGB radiance seen through the medium */
} veil_scene;

/* Parses `path`. On failure *out is left zeroed and err says why:
 * VEIL_ERR_IO (missing/unreadable file), VEIL_ERR_PARSE (JSON syntax, with
 * line and column), VEIL_ERR_INVALID (wrong type, unknown key, missing
 * field, value out of range). */
veil_result veil_scene_load(const char* path, veil_scene* out, veil_error* err);

/* Same, from a string in memory; `name` is used in messages and base_dir. */
veil_result veil_scene_parse(const char* name, const char* json, size_t len,
                             veil_scene* out, veil_error* err);

void veil_scene_free(veil_scene* s); /* accepts NULL and zeroed scenes */

/* All particles of all RBF sources (explicit and generated), newly
 * allocated into *out (free() it). */
veil_result veil_scene_particles(const veil_scene* s, veil_particle** out,
                                 size_t* count, veil_error* err);

#endif
