/* veil — what render, turntable and fog do with a rendered frame: write its
 * EXR (and PNG preview) all or nothing, and print its stages' report. */
#ifndef VEIL_CLI_FRAME_OUT_H
#define VEIL_CLI_FRAME_OUT_H

#include "core/result.h"
#include "frame/renderer.h"
#include "io/image.h"
#include "render/image_set.h"

/* im to exr (its AOVs with aovs, header attributes from meta, NULL: none)
 * and, when png is not NULL, a tone-mapped preview to png: both staged
 * beside their targets, then renamed over them (cli/cli_util.h), so an
 * existing exr stays as it was when the PNG cannot be written. */
veil_result veil_cli_write_frame(const veil_image_set* im, const char* exr, const char* png, int aovs,
                                 const veil_exr_meta* meta, veil_error* err);

/* One line per stage: name, wall time, what happened and why. */
void veil_cli_print_stages(const veil_render_stats* st);

#endif
