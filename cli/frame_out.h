/* veil — what render, turntable and fog do with a rendered frame: write its
 * EXR (and PNG preview) all or nothing, and print its stages' report. */
#ifndef VEIL_CLI_FRAME_OUT_H
#define VEIL_CLI_FRAME_OUT_H

#include "core/result.h"
#include "frame/renderer.h"
#include "io/image.h"
#include "render/image_set.h"

/* im to exr (its AOVs with aovs, header attributes from meta, NULL: none),
 * when png is not NULL a tone-mapped preview to png, and when deep is not
 * NULL im's deep image to deep (io/exr_deep.h, the same attributes): all
 * staged beside their targets, then renamed over them (cli/cli_util.h), so
 * an existing exr stays as it was when the PNG or the deep file cannot be
 * written. */
veil_result veil_cli_write_frame(const veil_image_set* im, const char* exr, const char* png, const char* deep,
                                 int aovs, const veil_exr_meta* meta, veil_error* err);

/* The --stats line of a deep image's merge (render/deep.h). */
void veil_cli_print_deep(const veil_deep_report* d);

/* One line per stage: name, wall time, what happened and why. */
void veil_cli_print_stages(const veil_render_stats* st);

#endif
