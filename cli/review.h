/* veil — turntable review outputs (cli/review.c): a contact sheet and a
 * movie made from frames' EXR files (so a last run can make them from
 * frames a farm's shards rendered). Previews use the PNG's tone curve. */
#ifndef VEIL_CLI_REVIEW_H
#define VEIL_CLI_REVIEW_H

#include <stddef.h>

#include "core/result.h"

/* At most this many frames in a sheet or a movie (its list of names, and
 * the sheet's grid: 317 columns of 10-pixel thumbnails at 4096 wide). */
#define VEIL_REVIEW_MAX_FRAMES 100000

/* A PNG of the n frames (same size) in a grid of ceil(sqrt(n)) columns,
 * each at most 320 pixels wide (the sheet at most 4096), box-filtered,
 * in order, 2 black pixels apart. */
veil_result veil_review_contact_sheet(const char* const* frames, int n, const char* out, veil_error* err);

/* A movie of the n frames at fps through the ffmpeg program (.mp4, .mov,
 * .mkv: H.264 yuv420p, odd sizes rounded down to even; .gif: a palette
 * made from the frames): PNGs in a folder beside `out`, removed after;
 * the movie is written under a staging name and renamed. VEIL_ERR_IO
 * naming the Debian package when ffmpeg is not on PATH. */
veil_result veil_review_movie(const char* const* frames, int n, double fps, const char* out, veil_error* err);

/* The names veil_review_movie makes beside `out` in this process: the
 * movie's staging file ("OUT.veil-staged<pid>.mp4") and its folder of PNG
 * frames ("OUT.veil-frames<pid>"), checked before any frame is rendered. */
void veil_review_movie_names(const char* out, char* staged, size_t ns, char* frames_dir, size_t nd);

/* The ffmpeg program on PATH: its path into out (n bytes), 1; else 0. */
int veil_review_find_ffmpeg(char* out, size_t n);

#endif
