/* veil — motion blur from velocity: a vdb source's density (and its
 * emission and temperature) averaged over the camera's shutter, moved by
 * the source's velocity grid (Eulerian motion blur, as Cycles and Arnold
 * blur volumes).
 *
 * Method: a blurred grid, made once per frame when the source is opened,
 *
 *   rho_b(x) = (1/N) sum_k rho(X(x, t_k)),
 *
 * X(x, t) the point whose density the flow carries to x in time t (the
 * path from x traced backwards through the velocity, which is held steady
 * over the shutter: io/vdb.h, veil_vdb_advect_mean). It replaces the grid
 * the rest of the pipeline reads, on the same lattice, so dense, sparse and
 * native volumes, the optical depth, the light cache, the march and the
 * reference path tracer all see one blurred medium, and its shadows agree
 * with what the camera sees. Not in the march's lookup (a time per ray, as
 * a path tracer has it): the march is deterministic, a time per ray would
 * add noise the frame has no samples to average away, and the light's
 * optical depth and the cache, built once for all rays, have no ray time;
 * here the GPU stages are untouched, a scene without a shutter pays
 * nothing, and the cost is paid once per frame on the CPU (docs/performance.md).
 *
 * What it is not: the mean of N renders (exp(-tau) of the mean optical
 * depth, not the mean of exp(-tau_k): an edge blurs a little denser than a
 * camera would show it, within Jensen's gap, Var_k(tau_k)/2 per pixel:
 * tests/render/test_motion_blur.c measures it); and the velocity is the
 * frame's, so a curved path over the shutter is followed only as far as
 * the field at the frame describes it.
 *
 * Times: the N midpoints of N equal parts of [open, close] (frames
 * relative to the frame), N = ceil(D) clamped to [VEIL_BLUR_MIN_SAMPLES,
 * VEIL_BLUR_MAX_SAMPLES], D the largest displacement over the shutter in
 * voxels of the density grid (max |v| x scale x (close - open) / fps for
 * "unit": "second", without / fps for "frame"): consecutive samples are at
 * most one voxel apart, as far as the cap allows (capped: D / N voxels,
 * and --stats says so). The paths are walked in steps of at most one voxel
 * (second order: a midpoint step, then Adams-Bashforth), the velocity read
 * along the path, not only at x.
 */
#ifndef VEIL_MOTION_BLUR_H
#define VEIL_MOTION_BLUR_H

#include <stddef.h>

#include "../core/result.h"
#include "../io/vdb.h"
#include "../scene/scene.h"

/* At least 2 samples (the shutter's two halves); at most 64 (a grid's blur
 * costs N trilinear samples a voxel of its grown region: 64 makes a
 * 128^3 smoke take a few seconds on two cores: docs/performance.md). */
#define VEIL_BLUR_MIN_SAMPLES 2
#define VEIL_BLUR_MAX_SAMPLES 64
/* The path's steps move at most this many voxels (the velocity is read
 * once a voxel along the way). */
#define VEIL_BLUR_STEP_VOXELS 1.0

/* The budget (issue 41). A blur's work is known before it starts
 * (io/vdb.h, veil_vdb_advect_work_of): the region's voxels, each walking
 * the same paths, so many reads (trilinear samples of the velocity along
 * them, and of the grid at each time) a voxel. It grows as D^4 (the region
 * as D^3, its paths as D): a velocity in cm/s read as m/s (100 times too
 * fast) turns a second into days. A read costs VEIL_BLUR_READ_SECONDS of
 * CPU time (measured on this project's 2-core machines, with its path's
 * arithmetic: docs/performance.md, "Motion blur's budget"); a frame's blurs
 * (every source's density, emission and temperature) may take
 * VEIL_BLUR_MAX_SECONDS of it, the sparse estimate's budget
 * (volume/sparse.h): over it a blur is refused before it starts, naming
 * the grid, the displacement, the voxels, the reads and the seconds. */
#define VEIL_BLUR_READ_SECONDS 5.5e-8
#define VEIL_BLUR_MAX_SECONDS 40.0

/* N for a displacement of d voxels over the shutter (see above). */
int veil_motion_blur_samples(double d);
/* The n midpoint times of [open, close] into t (frames). */
void veil_motion_blur_times(const float shutter[2], int n, double* t);

/* One source's blur: its velocity and the times, shared by its grids. */
typedef struct veil_motion_blur {
    veil_vdb_velocity* velocity; /* owned; NULL: the source is not blurred */
    char velocity_name[96];      /* the grid read ("vel", "vel.x/.y/.z") */
    int samples;                 /* N */
    double times[VEIL_BLUR_MAX_SAMPLES]; /* frames */
    double per_frame;            /* world displacement per unit of the grid's vectors per frame */
    double displacement;         /* D: voxels of the density over the shutter, at most */
} veil_motion_blur;

/* When the scene's camera has a shutter and source i (src) a "velocity",
 * opens the velocity from src's file (placed by src's transform) and
 * chooses N from `density`, the source's density grid as opened; else
 * leaves mb->velocity NULL. Errors name the source and the field
 * (`medium.sources[0].velocity.grid: smoke.vdb: no velocity grid ...`). */
veil_result veil_motion_blur_open(const veil_scene* s, const veil_source* src, size_t i, const veil_vdb* density,
                                  veil_motion_blur* mb, veil_error* err);
/* Replaces g (the source's density, emission or temperature grid, not yet
 * shared) by its blur; clamp_negative as veil_vdb_advect_desc. A no-op when
 * mb->velocity is NULL. *seconds: the CPU time the frame's blurs before
 * this one were estimated to take, raised by this one's; VEIL_ERR_LIMIT
 * when the sum would pass VEIL_BLUR_MAX_SECONDS (nothing done). Progress
 * and cancel: io/vdb.h. */
veil_result veil_motion_blur_apply(const veil_motion_blur* mb, veil_vdb* g, int clamp_negative, double* seconds,
                                   veil_vdb_advect_report* report, veil_error* err);
void veil_motion_blur_close(veil_motion_blur* mb); /* accepts a zeroed one */

#endif
