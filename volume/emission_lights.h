/* veil — the medium's own emission as point lights, so that the light a
 * fire emits lights its smoke through every estimate a light has (single
 * scattering, the octaves, the optical-depth volumes).
 *
 * The emitting voxels (eps, W m^-3 sr^-1, on the EV's grid) are split into
 * at most `max` clusters by a k-d split: the heaviest cluster (luminance of
 * eps times voxel volume) is split along its longest side at its weighted
 * median, until there are `max` or no cluster can be split. Each cluster
 * becomes a point light at its luminance-weighted centroid with intensity
 * the sum of eps dV over it (W/sr: an isotropic emitter of that power) and
 * a radius, the weighted RMS distance of its voxels from that centroid
 * (plus half a voxel): the march floors 1/r^2 at that radius, the fluence
 * inside a ball of emitters rather than a point's singularity.
 *
 * The light emitted straight to the camera stays the march's own (the
 * emission texture); these lights carry what the medium scatters of it.
 *
 * Each voxel's eps dV and each light's intensity are held within
 * VEIL_MAX_LIGHT per channel (scene/limits.h), a light's colour kept, so
 * that the lights' derivation there holds for these too (a +inf or huge
 * voxel otherwise made an infinite light, a NaN position and runaway
 * propagation shells).
 */
#ifndef VEIL_EMISSION_LIGHTS_H
#define VEIL_EMISSION_LIGHTS_H

#include "../core/result.h"
#include "../scene/scene.h"
#include "volume.h"

/* At most VEIL_MAX_LIGHTS; fills out[0..*n). rgba: 4 floats a voxel of g
 * (veil_scene_volume_emission). */
veil_result veil_emission_lights(const veil_grid* g, const float* rgba, int max, veil_light* out, int* n,
                                 veil_error* err);

/* The same from a list of emitting voxels: 6 floats each, the voxel's
 * centre (m) and eps dV per channel (W/sr), voxels of edge `voxel` (m).
 * The clusters depend on the voxels, not on their order in the list. */
veil_result veil_emission_lights_points(const float* pts, size_t count, float voxel, int max, veil_light* out, int* n,
                                        veil_error* err);

#endif
