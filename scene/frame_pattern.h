/* veil — file names that hold a frame number: the frames a turntable
 * writes ("smoke.####.exr") and the files of an animated source
 * ("cache/smoke.%04d.vdb"), as film tools write them. */
#ifndef VEIL_FRAME_PATTERN_H
#define VEIL_FRAME_PATTERN_H

#include <stddef.h>

#include "../core/result.h"

/* A file-name pattern holds the frame number once: a run of '#' (its
 * length the least number of digits, "####" -> 0042) or a printf
 * conversion "%d" / "%0Nd" (N <= 9). Returns 1 when `pattern` has one, 0
 * when it has none, -1 when it has two or a malformed '%' conversion
 * ("%%" is a literal '%'). */
int veil_frame_pattern_kind(const char* pattern);
/* The file of `frame` (negative frames get a '-' before the padded
 * digits). VEIL_ERR_INVALID when the pattern holds no single number,
 * VEIL_ERR_LIMIT when the name does not fit in n bytes. */
veil_result veil_frame_pattern_path(const char* pattern, long frame, char* out, size_t n, veil_error* err);

#endif
