/* veil — the optical-depth volumes of a scene's lights on the GPU, behind
 * one handle (an OPV set): ceil(n/4) rgba32f textures of the EV's grid,
 * light 4t+c in channel c of texture t (opv.h), and, with
 * VEIL_OPV_LIGHT_SPACE over a dense EV, one r32f light-space grid for each
 * of the first VEIL_MAX_SUNS suns (sun_space.h), whose channel then stays
 * empty (a texture all of whose lights are suns so kept is not made).
 *
 * Each texture remembers the key it was made with; an update recomputes a
 * texture only when its key changed, so a light that moved re-propagates
 * its own texture and nothing else. The key is the caller's (frame/ forms
 * it from descriptions: the EV's key, the method, the lights' geometry,
 * never their colour). Needs the GL context current at creation.
 */
#ifndef VEIL_OPV_SET_H
#define VEIL_OPV_SET_H

#include <epoxy/gl.h>
#include <stdint.h>

#include "../core/result.h"
#include "../volume/ev.h"
#include "opv.h"
#include "sun_space.h"

/* The widest spacing (voxels) a light-space grid is widened to before its
 * sun goes back to the EV's grid. */
#define VEIL_SUN_WIDEST 8.0f

typedef struct veil_opv_set veil_opv_set;

/* What an update did, for the stage report. */
typedef struct veil_opv_report {
    int computed, cached; /* textures */
    int iterations;       /* the most Jacobi steps or sweep passes of any light */
    int suns, suns_computed; /* light-space grids in use, and made by this update */
    float sun_across;     /* the widest node spacing across the light of any (voxels) */
    double mib;           /* GPU memory of the textures in use */
} veil_opv_report;

/* A sun whose optical depth is in a light-space grid, as the march reads it. */
typedef struct veil_opv_sun {
    GLuint texture;      /* r32f, D in density * m */
    int light;           /* its index in the update's lights */
    float to_tex[3][4];  /* world -> texture coordinates (veil_sun_space_to_texture) */
    veil_sun_space space;
} veil_opv_sun;

veil_result veil_opv_set_create(veil_opv_set** out, veil_error* err); /* compiles the programs */
void veil_opv_set_destroy(veil_opv_set* s);                           /* accepts NULL */

/* Drops every texture (the volume changed or is gone). */
void veil_opv_set_clear(veil_opv_set* s);

/* The key texture t must have to serve these (at most 4) lights of grid g
 * for an EV of key ev_key: a hash of descriptions only. */
uint64_t veil_opv_texture_key(uint64_t ev_key, const veil_opv_params* params, const veil_index_light* lights, int count);

/* 1 when texture t holds `key` already (the update would reuse it). */
int veil_opv_set_has(const veil_opv_set* s, int t, uint64_t key);

/* Brings the textures up to date for lights[0..n) of grid g over the EV
 * texture ev (of key ev_key) and its occupancy bricks occ (0: none, no
 * skipping). Over a sparse EV (sp: veil_ev_sparse_of;
 * NULL for dense) the textures are atlases laid out like its density's,
 * each texel's optical depth marched through its brick and the empty
 * bricks beyond, then read from the kept brick it enters, which an earlier
 * pass did (bricks taken in the light's order: propagate/shaders/
 * propagate_sparse.comp; `params` only keys it); rep->iterations: passes. */
veil_result veil_opv_set_update(veil_opv_set* s, const veil_grid* g, GLuint ev, GLuint occ,
                                const veil_ev_sparse* sp, uint64_t ev_key, const veil_light* lights, int n, const veil_opv_params* params,
                                veil_opv_report* rep, veil_error* err);

/* Texture t (0 when none): VEIL_MAX_OPV_TEXTURES of them. */
GLuint veil_opv_set_texture(const veil_opv_set* s, int t);

/* Which of lights[0..n) get light-space grids under params (none unless
 * VEIL_OPV_LIGHT_SPACE): the first VEIL_MAX_SUNS suns whose grid fits
 * max_axis nodes an axis (the GL's 3D texture limit; 0: none fits) and the
 * node budget, the spacing across widened until it does. Fills ol[0..n)
 * (veil_light_to_index, with `elsewhere` set for those), want[] and
 * their keys; returns how many. Needs no GL: veil_plan_explain calls it. */
int veil_opv_plan_suns(const veil_grid* g, uint64_t ev_key, const veil_light* lights, int n,
                       const veil_opv_params* params, int max_axis, veil_index_light* ol, veil_opv_sun* want,
                       uint64_t* want_key);

/* The passes veil_opv_set_update makes for light l over a sparse volume
 * whose kept bricks are `bricks` (n of them, 4 ints each: x, y, z, 0): its
 * distinct levels in the order of the passes (each brick's path to the
 * light leaves it towards bricks of earlier passes only). Needs no GL: the
 * frame's work estimate counts them before the volume is made. */
size_t veil_opv_sparse_passes(const int32_t* bricks, size_t n, const veil_index_light* l);

/* The light-space grids of the last update (*count of them). */
const veil_opv_sun* veil_opv_set_suns(const veil_opv_set* s, int* count);

/* The light-space grid of one sun on a density given on grid g, read back
 * into out (veil_sun_space_nodes floats): tests compare it with
 * veil_sun_space_cpu. occupancy 1: skip empty bricks as the renderer does. */
veil_result veil_opv_set_sun_readback(veil_opv_set* s, const veil_grid* g, const float* density,
                                      const veil_sun_space* space, int occupancy, float* out, veil_error* err);

/* Propagation alone, on a density given on grid g, read back into out
 * (n_lights * voxels floats, light-major): tests compare it with the C
 * twin. Leaves the set as it was. */
veil_result veil_opv_set_propagate_readback(veil_opv_set* s, const veil_grid* g, const float* density,
                                            const veil_index_light* lights, int n_lights,
                                            const veil_opv_params* params, float* out, int* iterations,
                                            veil_error* err);

#endif
