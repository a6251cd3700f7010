/* veil — the optical-depth volumes of a scene's lights on the GPU, behind
 * one handle (an OPV set): ceil(n/4) rgba32f textures of the EV's grid,
 * light 4t+c in channel c of texture t (opv.h).
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

typedef struct veil_opv_set veil_opv_set;

/* What an update did, for the stage report. */
typedef struct veil_opv_report {
    int computed, cached; /* textures */
    int iterations;       /* the most Jacobi steps or sweep passes of any light */
} veil_opv_report;

veil_result veil_opv_set_create(veil_opv_set** out, veil_error* err); /* compiles the programs */
void veil_opv_set_destroy(veil_opv_set* s);                           /* accepts NULL */

/* Drops every texture (the volume changed or is gone). */
void veil_opv_set_clear(veil_opv_set* s);

/* The key texture t must have to serve these (at most 4) lights of grid g
 * for an EV of key ev_key: a hash of descriptions only. */
uint64_t veil_opv_texture_key(uint64_t ev_key, const veil_opv_params* params, const veil_opv_light* lights, int count);

/* 1 when texture t holds `key` already (the update would reuse it). */
int veil_opv_set_has(const veil_opv_set* s, int t, uint64_t key);

/* Brings the textures up to date for lights[0..n) of grid g over the EV
 * texture ev (of key ev_key). Over a sparse EV (sp: veil_ev_sparse_of;
 * NULL for dense) the textures are atlases laid out like its density's,
 * each texel's optical depth marched through its brick and the empty
 * bricks beyond, then read from the kept brick it enters, which an earlier
 * pass did (bricks taken in the light's order: propagate/shaders/
 * propagate_sparse.comp; `params` only keys it); rep->iterations: passes. */
veil_result veil_opv_set_update(veil_opv_set* s, const veil_grid* g, GLuint ev, const veil_ev_sparse* sp,
                                uint64_t ev_key, const veil_light* lights, int n, const veil_opv_params* params,
                                veil_opv_report* rep, veil_error* err);

/* Texture t (0 when none): VEIL_MAX_OPV_TEXTURES of them. */
GLuint veil_opv_set_texture(const veil_opv_set* s, int t);

/* Propagation alone, on a density given on grid g, read back into out
 * (n_lights * voxels floats, light-major): tests compare it with the C
 * twin. Leaves the set as it was. */
veil_result veil_opv_set_propagate_readback(veil_opv_set* s, const veil_grid* g, const float* density,
                                            const veil_opv_light* lights, int n_lights,
                                            const veil_opv_params* params, float* out, int* iterations,
                                            veil_error* err);

#endif
