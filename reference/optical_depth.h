/* veil — CPU ground truth for optical depth through the extinction volume.
 *
 * The GPU propagation schemes (propagate/) approximate, per voxel X and
 * light S, D(X, S) = integral of density along the path from X to S. This
 * module computes the same quantity directly, in double precision, for the
 * medium exactly as volume/volume.h defines it: voxel values at the centres
 * origin + (i + 0.5) * voxel, trilinear interpolation between centres,
 * and no medium outside the box the centres span,
 * [origin + voxel/2, origin + (dims - 1/2) voxel]. The box is taken in
 * exact arithmetic from the float grid fields (promoted to double).
 *
 * Along a straight line the trilinear field is a cubic polynomial within
 * each cell and has kinks (derivative jumps) only where the line crosses a
 * voxel-centre plane. veil_ref_optical_depth() splits the path at every such
 * crossing and at the box faces and integrates each piece with 3-point
 * Gauss-Legendre, which is exact for cubics: the result is the exact
 * integral up to rounding (relative error a few times 1e-16 per piece,
 * summed with compensation). veil_ref_optical_depth_midpoint() is the plain
 * composite midpoint rule, O(h^2), kept to show that convergence.
 *
 * Units: positions in metres (world space, as the grid's origin/voxel);
 * density is the unitless voxel value; optical depths are density * m (the
 * caller multiplies by sigma_t in m^-1 to get tau). Arrays are the caller's:
 * rho holds veil_grid_voxels(g) floats, x fastest, rho[(k*ny + j)*nx + i];
 * nothing is allocated or retained, and every function is reentrant.
 */
#ifndef VEIL_REFERENCE_OPTICAL_DEPTH_H
#define VEIL_REFERENCE_OPTICAL_DEPTH_H

#include "../scene/scene.h"
#include "../volume/volume.h"

/* Density of the medium at world position x: 0 outside the closed box of the centres,
 * otherwise the trilinear interpolation at index coordinate
 * u = (x - origin) / voxel - 0.5, clamped to [0, dims - 1] per axis. */
double veil_ev_sample(const veil_grid* g, const float* rho, const double x[3]);

/* Exact (to rounding) integral of density along the segment a -> b, i.e.
 * over its part inside the box; 0 when it misses the box or a == b. */
double veil_ref_segment_optical_depth(const veil_grid* g, const float* rho, const double a[3],
                                      const double b[3]);

/* D(x, light): integral of density from x to the light.
 *  - VEIL_LIGHT_POINT, VEIL_LIGHT_SPOT: along the segment x -> position
 *    (clipped to the box; the spot cone does not matter for D);
 *  - VEIL_LIGHT_DIRECTIONAL: from x along -direction until the ray leaves
 *    the box (direction is normalised here in double; the part of the ray
 *    inside the box counts even when x is outside it).
 * The result is exact to rounding for the trilinear field, so
 * `steps_per_voxel` is ignored (kept for symmetry with the midpoint
 * version). Returns NaN for an unknown light type or a zero direction. */
double veil_ref_optical_depth(const veil_grid* g, const float* rho, const veil_light* light,
                              const double x[3], double steps_per_voxel);

/* Same path, composite midpoint rule: the in-box part of length l is cut
 * into ceil(steps_per_voxel * l / voxel) equal steps (at least one), and
 * each contributes step * density(step midpoint). Error O(h^2) in the step
 * h. Returns NaN as above, when steps_per_voxel is not > 0, or when the
 * path would take more than 2^40 steps. */
double veil_ref_optical_depth_midpoint(const veil_grid* g, const float* rho, const veil_light* light,
                                       const double x[3], double steps_per_voxel);

#endif
