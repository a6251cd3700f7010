/* veil — the path tracer's medium and its walks (internal to reference/).
 *
 * pt_medium.c: the medium (volume + majorant blocks + fogs), free-flight
 * sampling by delta tracking and transmittance by ratio tracking.
 * pathtracer.c: the camera, the estimator per pixel, threads.
 */
#ifndef VEIL_REFERENCE_PT_INTERNAL_H
#define VEIL_REFERENCE_PT_INTERNAL_H

#include <stdint.h>

#include "pathtracer.h"
#include "../core/rng.h"

typedef struct pt_fog {
    double rho0, falloff;  /* density at the origin plane; b (m^-1) */
    double n[3], o[3];     /* fall-off direction (unit), origin */
    double lo[3], hi[3];   /* its box */
} pt_fog;

struct veil_pt_medium {
    int has_grid;          /* a volume with non-zero thickness on every axis */
    veil_grid grid;
    float* rho;            /* veil_grid_voxels floats (owned) */
    double box_lo[3], box_hi[3]; /* the box of the voxel centres */
    int nb[3];             /* majorant blocks per axis */
    float* major;          /* block maxima (owned) */
    int fog_count;
    pt_fog fog[VEIL_MAX_FOGS];
    double sigma_a[3], sigma_s[3], sigma_t[3];
    double sigma_max;      /* largest sigma_t channel (m^-1 per unit density) */
};

/* A per-pixel random stream (core/rng.h). */
typedef struct pt_rng {
    uint64_t s;
} pt_rng;

/* Uniform in [0, 1). */
static inline double pt_uniform(pt_rng* r) { return veil_rng_double53(&r->s); }

/* Counters of one thread's walks. */
typedef struct pt_counters {
    uint64_t collisions, cut_walks, majorant_misses;
} pt_counters;

typedef enum pt_event { PT_ESCAPE = 0, PT_SCATTER, PT_ABSORB, PT_CUT } pt_event;

/* Delta tracking from o along unit d: the first real collision. On
 * PT_SCATTER *t is its distance and beta (per channel) has been multiplied
 * by the event weights (1 for grey media). */
pt_event veil__pt_free_flight(const veil_pt_medium* m, const double o[3], const double d[3], pt_rng* rng,
                              double beta[3], double* t, pt_counters* c);

/* Transmittance estimate from o along unit d over length len (INFINITY: to
 * the end of the medium): ratio tracking through the volume times the
 * fogs' exact transmittance. */
void veil__pt_transmittance(const veil_pt_medium* m, const double o[3], const double d[3], double len,
                            pt_rng* rng, double T[3], pt_counters* c);

/* Exact transmittance (zero variance) along the same path: the volume's
 * optical depth integrated exactly (reference/optical_depth.h) and the
 * fogs' closed form. */
void veil__pt_transmittance_exact(const veil_pt_medium* m, const double o[3], const double d[3], double len,
                                  double T[3]);

/* Slab test of o + t d against [lo, hi] for t in [t0, t1]: 1 and the
 * clipped range when they overlap in a segment of positive length. */
int veil__pt_box_clip(const double lo[3], const double hi[3], const double o[3], const double d[3], double t0,
                      double t1, double* a, double* b);

#endif
