/* veil — screen-space multiple scattering: the hierarchical spread of
 * Iser & Elek, "Real-time light transport in analytically integrable
 * quasi-heterogeneous media" (CESCG 2018; ../shared/seeds/000_*), built on
 * Elek et al. 2013. docs/multiple-scattering.md derives what enters it and
 * records what it measures.
 *
 * Input, per pixel: the radiance L behind the medium (the background, or a
 * frame under `veil fog`), and the march's buffers: T and P (aov_t), the
 * depth of the scattering (aov_s alpha), and Q, single scattering's light
 * scattered out of the beam on its way to the camera, with its P (aov_q).
 * Output: the spread light L'_sc + L'_ssc per pixel (rgb) and the level it
 * was read from (a); the caller adds it to the march's radiance, which
 * already holds the attenuated background T L and the single scattering.
 *
 * Levels: K = multiple.levels (at most ceil(log2 of the larger side): a
 * coarser level would span more than the image), or from the image size
 * (0): floor(log2 of the smaller side) - 1, at most 7 (a spread of c 2^7 =
 * 110 pixels at the paper's c). The chains' level 0 is the image padded with zeros to a
 * multiple of 2^K on each side, so every level halves exactly.
 *
 * Needs the GL context current at creation and for every run.
 */
#ifndef VEIL_SPREAD_H
#define VEIL_SPREAD_H

#include "../core/result.h"
#include "../scene/scene.h"

typedef struct veil_spread veil_spread;

typedef struct veil_spread_input {
    int width, height;
    const float* L;         /* rgba per pixel (a ignored); NULL: `background` everywhere */
    float background[3];
    const float* aov_t;     /* the march's buffers (render/image_set.h), 4 floats a pixel */
    const float* aov_s;
    const float* aov_q;     /* NULL: no single scattering to spread */
    float fov_y_deg;        /* the camera's vertical field of view */
    /* the march's own images of T, S and Q (render/march.h, veil_march_images), read where they are
     * instead of being made from aov_t, aov_s and aov_q (which may then be NULL; tex_q 0 with aov_q NULL:
     * no single scattering to spread); 0: made from the buffers */
    unsigned int tex_t, tex_s, tex_q;
} veil_spread_input;

typedef struct veil_spread_report {
    int levels;             /* K used */
    int padded_width, padded_height;
    double ms;
} veil_spread_report;

veil_result veil_spread_create(veil_spread** out, veil_error* err);
void veil_spread_destroy(veil_spread* s); /* accepts NULL */

/* K for an image of w x h pixels under settings m. */
int veil_spread_levels(const veil_multiple* m, int w, int h);

/* Runs the three passes for the medium and settings of scene sc
 * (sc->multiple's screen-space fields; the medium's sigma_a, sigma_s and
 * phase) and writes width*height*4 floats to out. level0 (may be NULL)
 * gets level 0 of the L_sc chain, L_sc rgb and W in pixels, width*height*4
 * floats: what the gathering reference (reference/gather.h) spreads. */
veil_result veil_spread_run(veil_spread* s, const veil_scene* sc, const veil_spread_input* in, float* out,
                            float* level0, veil_spread_report* rep, veil_error* err);

/* The largest optical thickness of scattering in the view, max over pixels
 * of P * mean(sigma_s): below multiple.thin_threshold the spread has
 * nothing to move and the pass is skipped. */
float veil_spread_max_scattering(const veil_scene* sc, const float* aov_t, const float* aov_q, int w, int h);

#endif
