/* veil — RBF particle files (docs/particles.md).
 *
 * Two formats hold a list of veil_particle (centre, amplitude, sharpness):
 *   - JSON: {"format":"veil-particles","version":1,"particles":[{"center":
 *     [x,y,z],"amplitude":c,"sharpness":a}, ...]}, the per-particle rules of
 *     a scene's inline "rbf" particles;
 *   - binary: "VEILRBF1", uint32 LE count, uint32 LE reserved (0), then
 *     count x 5 float32 LE (cx, cy, cz, amplitude, sharpness); the file is
 *     exactly 16 + 20 * count bytes.
 * Both are read and written byte by byte, so files are portable. Every
 * message starts with the file name and, for a bad particle, names its index
 * and field. At most VEIL_SCENE_MAX_PARTICLES particles.
 */
#ifndef VEIL_PARTICLES_H
#define VEIL_PARTICLES_H

#include <stddef.h>
#include <stdint.h>

#include "../core/result.h"
#include "../scene/particle.h"

#define VEIL_PARTICLES_MAGIC "VEILRBF1"
#define VEIL_PARTICLES_HEADER_BYTES 16u
#define VEIL_PARTICLES_RECORD_BYTES 20u

/* Reads either format (binary when the file starts with the magic, JSON when
 * its first non-space character is '{'). *out is malloc'd (free() it; NULL
 * when count is 0). Errors: VEIL_ERR_IO (cannot open/read), VEIL_ERR_PARSE
 * (JSON syntax), VEIL_ERR_INVALID (not a particle file, truncated, padded,
 * bad value), VEIL_ERR_LIMIT (too many particles), VEIL_ERR_OOM. On failure
 * *out is NULL and *count 0. */
veil_result veil_particles_read(const char* path, veil_particle** out, size_t* count, veil_error* err);

/* Writes n particles (binary != 0: the binary format, else JSON), all or
 * nothing: a temporary beside `path`, renamed over it at the end. Particles
 * that a reader would refuse are refused (VEIL_ERR_INVALID) before anything
 * is written. */
veil_result veil_particles_write(const char* path, const veil_particle* p, size_t n, int binary,
                                 veil_error* err);

#endif
