/* veil — the diffusion estimate of multiple scattering: view-independent,
 * computed once per volume and lights (a turntable reuses it).
 *
 * On a coarse grid over the medium (cells of two EV voxels, at most
 * `cells` along the longest side; for analytic fog only, the first fog's
 * box when it is under VEIL_DIFFUSION_MAX_EXTENT), the source of
 * once-scattered light S = sigma_s rho sum_l E_l exp(-sigma_t D_l) is formed
 * from the same optical depths the march reads (render/shaders/
 * diffusion_source.comp), and the steady diffusion equation
 *   -div(D grad phi) + sigma_a rho phi = S,  D = 1 / (3 (sigma_a + sigma_s (1 - g)) rho)
 * is relaxed by red-black SOR (render/shaders/diffusion_sor.comp; phi = 0
 * beyond the grid). The march then adds sigma_s rho phi / (4 pi) as
 * in-scattering (the multiply scattered light, isotropic): orders >= 2.
 * docs/multiple-scattering.md has the derivation and the measurements.
 */
#ifndef VEIL_DIFFUSION_H
#define VEIL_DIFFUSION_H

#include <stdint.h>

#include "../core/result.h"
#include "march.h"

#define VEIL_ESCAPE_CELLS 32 /* the escape field's cells along the longest side */
#define VEIL_DIFFUSION_OMEGA 1.9f      /* SOR over-relaxation (optimal ~ 2 / (1 + sin(pi / n)), n ~ 64) */
/* A cell whose transport optical thickness (sigma_a + sigma_s (1 - g)) rho h
 * is below this is vacuum for the diffusion (which does not hold there):
 * light leaves the medium through its faces with the Marshak flux phi / 2. */
#define VEIL_DIFFUSION_VACUUM 0.001f

typedef struct veil_diffusion veil_diffusion;

typedef struct veil_diffusion_report {
    int dims[3];
    float cell;      /* m */
    int iterations;  /* red-black sweeps */
    int cached;      /* 1: the key matched what was kept */
    int skipped;     /* 1: no grid (no medium, or a fog box too large; the diffusion solve over a sparse volume) */
    int sparse;      /* 1: over a sparse volume (the escape field per kept brick, 3^3 points each) */
    uint64_t key;
} veil_diffusion_report;

veil_result veil_diffusion_create(veil_diffusion** out, veil_error* err);
void veil_diffusion_destroy(veil_diffusion* d); /* accepts NULL */
void veil_diffusion_clear(veil_diffusion* d);   /* forget the kept field */

/* Brings the field of `kind` up to date for the march described by md (its
 * scene's multiple.diffusion_cells, diffusion_iterations; the EV, OPVs and
 * lights), keyed by `key` (the caller's hash of everything it depends on);
 * fills *field (texture 0 when skipped). VEIL_FIELD_FLUENCE: the diffusion
 * solve above. VEIL_FIELD_ESCAPE: the octave estimate's gate, the chance
 * that light scattered at a point scatters again before it leaves the
 * medium (render/shaders/escape.comp; no lights involved). */
veil_result veil_diffusion_update(veil_diffusion* d, const veil_march_desc* md, uint64_t key, float kind,
                                  veil_diffusion_field* field, veil_diffusion_report* rep, veil_error* err);

/* The field's fluence read back (dims[0]*dims[1]*dims[2]*4 floats, rgb
 * phi), for tests; NULL when there is none. Caller frees. */
float* veil_diffusion_readback(const veil_diffusion* d, int dims[3]);

#endif
