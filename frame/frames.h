/* veil — frames of a sequence: ranges ("1001-1100x2"), file-name patterns
 * ("smoke.####.exr", "smoke.%04d.exr"), shards of a range, each frame's
 * camera on an orbit and its jitter seed. Pure functions: a frame's camera,
 * seed and file name depend only on the arguments, never on which process
 * renders it or in which order (a farm's shards make the same bytes).
 */
#ifndef VEIL_FRAMES_H
#define VEIL_FRAMES_H

#include <stddef.h>
#include <stdint.h>

#include "../core/result.h"
#include "../scene/frame_pattern.h"
#include "../scene/scene.h"

/* Frames first, first + step, ... up to last (first <= last, step >= 1). */
typedef struct veil_frame_range {
    long first, last, step;
} veil_frame_range;

/* At most this many frames in a range (a day of film at 24 fps is 2 073 600). */
#define VEIL_MAX_FRAMES 10000000L
/* Frame numbers stay within +-VEIL_MAX_FRAME_NUMBER. */
#define VEIL_MAX_FRAME_NUMBER 999999999L

/* "A-B" or "A-B xS" written "A-BxS" (A, B may be negative: "-5--1"), or a
 * single frame "A". VEIL_ERR_INVALID naming what is wrong. */
veil_result veil_frame_range_parse(const char* text, veil_frame_range* out, veil_error* err);
long veil_frame_range_count(const veil_frame_range* r);
/* The i-th frame (0-based) of r. */
long veil_frame_range_at(const veil_frame_range* r, long i);

/* Shard I of N (1 <= I <= N): the frames whose index i in the range has
 * i % N == I - 1. "I/N"; VEIL_ERR_INVALID otherwise. */
veil_result veil_shard_parse(const char* text, int* index, int* count, veil_error* err);

/* File-name patterns of frames: scene/frame_pattern.h. */

/* An orbit of the camera about an axis through its look-at point. */
typedef struct veil_orbit {
    float axis[3];      /* the axis (any length > 0); all 0: the camera's up vector */
    float start_deg;    /* angle of the sequence's first frame */
    float degrees;      /* covered by the frames, frame i at start + degrees * i / count (360: a full
                           turn, no frame repeated) */
    float elevation_deg; /* the camera raised towards the axis by this much first (-89 .. 89) */
} veil_orbit;

/* The camera of frame index i (0-based) of count frames on orbit o: its
 * distance to the look-at point kept, the up vector kept (the axis when
 * given). */
veil_camera veil_orbit_camera(const veil_camera* c, const veil_orbit* o, long i, long count);

/* Frame f's jitter seed from a base seed: a mix of both, so neighbouring
 * frames do not share noise and any process gives frame f the same. */
uint32_t veil_frame_seed(uint32_t base, long frame);

#endif
