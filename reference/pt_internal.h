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
    float* emission[3];    /* NULL, or per channel the emission eps on `grid` (W m^-3 sr^-1, owned) */
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
 * optical depth veil__pt_grid_depth and the fogs' closed form. */
void veil__pt_transmittance_exact(const veil_pt_medium* m, const double o[3], const double d[3], double len,
                                  double T[3]);

/* Total density at x (unitless; the extinction there is m->sigma_t times
 * it, m^-1): the volume's trilinear value plus every fog whose box holds
 * x, exactly as the walks see it. */
double veil__pt_density(const veil_pt_medium* m, const double x[3]);

/* The part of the ray o + t d, t >= 0, where a walk can collide: from the
 * first entry into the volume's box or a fog's box to the last exit (gaps
 * between boxes included). 0 when it meets none or the medium is empty. */
int veil__pt_medium_span(const veil_pt_medium* m, const double o[3], const double d[3], double* a, double* b);

/* The density (m^-1) with which veil__pt_free_flight from o along unit d,
 * started with throughput beta0, returns PT_SCATTER at distance t:
 *   q_d(t) = sum_c beta0_c sigma_s,c rho(t) T_c(t) / sum_c beta0_c
 * (pathtracer.h derives it), T exact. Also gives rho(t) and T(t); T is not
 * computed (left 0) where rho(t) is 0, as q_d is then 0. */
double veil__pt_scatter_pdf(const veil_pt_medium* m, const double o[3], const double d[3], const double beta0[3],
                            double t, double* rho, double T[3]);

/* The volume's density integrated along o + t d (d unit), t in [t0, t1]
 * (density * m): exact to rounding, as veil_ref_segment_optical_depth
 * (reference/optical_depth.h), but 3-4x faster on the demo's grid, which
 * the MIS weights, evaluated at every vertex, need: the line is cut where
 * it crosses a voxel-centre plane (the trilinear field is a cubic between
 * crossings), and each piece, inside one cell whose 8 values are read
 * once, is integrated by 2-point Gauss-Legendre (exact for cubics). */
double veil__pt_grid_depth(const veil_pt_medium* m, const double o[3], const double d[3], double t0, double t1);

/* The emitted radiance reaching o along -d: int T(0, t) eps(t) dt over the
 * grid's box, per channel, eps trilinear and T exact; per step of a quarter
 * voxel eps is taken at the midpoint and T integrated in closed form,
 * T(t_k) eps h (1 - exp(-x)) / x with x the step's optical thickness (exact
 * for a homogeneous medium). 0 without emission. */
void veil__pt_emission(const veil_pt_medium* m, const double o[3], const double d[3], double out[3]);

/* Slab test of o + t d against [lo, hi] for t in [t0, t1]: 1 and the
 * clipped range when they overlap in a segment of positive length. */
int veil__pt_box_clip(const double lo[3], const double hi[3], const double o[3], const double d[3], double t0,
                      double t1, double* a, double* b);

#endif
