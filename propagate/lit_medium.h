/* veil — the medium and its lights as every pass after propagation reads
 * them: the march (render/) and the volumetric stage (volumetric/). No
 * camera here: what a pass needs of the view is its own block.
 *
 * A veil_lit_medium names what the earlier stages made — the EV's textures
 * (volume/ev.h), the lights that add light (frame/ drops the rest) and
 * their optical depths (opv_set.h) — and the scene's medium coefficients,
 * phase and fogs. veil_lit_medium_fill() turns it into the std140
 * veil_medium_block (core/shared.glsl.h) that propagate/shaders/
 * lit_medium.glsl reads at VEIL_UBO_MEDIUM. Nothing is owned: the textures
 * are the stages', the pointers the caller's.
 */
#ifndef VEIL_LIT_MEDIUM_H
#define VEIL_LIT_MEDIUM_H

#include <epoxy/gl.h>

#include "../core/shared.glsl.h"
#include "../scene/light.h"
#include "../scene/scene.h"
#include "../volume/ev.h"
#include "../volume/volume.h"
#include "opv_set.h"

/* The smallest march step through fog when there is no volume (m). */
#define VEIL_FOG_MIN_STEP 0.01f

/* Point lights closer than this fraction of a voxel count as this far (the
 * 1/r^2 singularity is integrable in the continuum but not in samples). */
#define VEIL_MIN_LIGHT_DISTANCE_VOXELS 1e-3f

typedef struct veil_lit_medium {
    const veil_scene* scene;      /* medium coefficients, phase, fogs, background, multiple scattering */
    const veil_light* lights;     /* the lights that add light (frame/ drops the rest) */
    int light_count;
    const veil_grid* grid;        /* NULL: no volume (fog only) */
    GLuint ev, occupancy;         /* the EV's textures when grid is set */
    const veil_ev_sparse* sparse; /* a sparse EV (ev is then its atlas, occupancy 0; the optical depths and
                                     the escape field are atlases too); NULL: dense */
    GLuint emission;              /* the EV's emission texture (0: none) */
    const GLuint* opv;            /* VEIL_MAX_OPV_TEXTURES textures (0 where unused) */
    const veil_opv_sun* suns;     /* light-space grids of suns, dense volumes only */
    int sun_count;
    /* the surfaces of a frame under `veil fog` (scene/solid.h: its grid and shadow maps, one a light in
     * `lights`' order) and their textures; NULL, 0: none */
    const struct veil_solid* solid;
    GLuint solid_voxels, solid_maps;
} veil_lit_medium;

/* The uniform block for m (exposed so tests can check what the shaders
 * get); each light converted by veil_light_to_gpu (scene/light.h). */
void veil_lit_medium_fill(const veil_lit_medium* m, veil_medium_block* out);

/* The textures a pass reads a frame's solid from (scene/solid.h): tex[0] its
 * voxels (r8, 1 where solid), tex[1] its shadow maps (r32f, a layer a light);
 * both 0 and VEIL_OK when s holds no solid. The caller deletes them. */
veil_result veil_lit_medium_solid_textures(const struct veil_solid* s, GLuint tex[2], veil_error* err);

/* Binds m's optical depths (OPV textures and, over a dense volume, the
 * light-space grids) for a pass that reads lit_medium.glsl; NULL unbinds
 * them all (call it so only where no sparse table holds the sun units). */
void veil_lit_medium_bind_depths(const veil_lit_medium* m);

#endif
