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

/* A frame writer on its own thread (issue 42): a turntable renders frame N + 1 while frame N is
 * written. veil_cli_writer_put hands a frame over (the image set moved out of *im, which is left
 * empty; exr, png, deep and meta's strings copied) once the writer is free: at most one frame
 * waits while one renders, so two frames' images are held at most. Each frame is written as
 * veil_cli_write_frame writes it (staged, then renamed: a signal or an error leaves no half
 * file, and every frame finished before it in place). A write's failure is returned by the next
 * put or by finish, and no frame after it is written. With `stats`, each frame's write time is
 * printed as "write      T ms (frame F, its own thread)". */
typedef struct veil_cli_writer veil_cli_writer;
veil_result veil_cli_writer_start(int stats, veil_cli_writer** out, veil_error* err);
veil_result veil_cli_writer_put(veil_cli_writer* w, veil_image_set* im, long frame, const char* exr, const char* png,
                                const char* deep, int aovs, const veil_exr_meta* meta, veil_error* err);
/* A turntable's frame handed over, as render --turntable and turntable do it: with stats its "frame F"
 * and stage lines first (and its deep merge's when deep is not NULL), then the writer made when *w is
 * NULL (stats: it prints its write's line), then veil_cli_writer_put. */
veil_result veil_cli_hand_over(veil_cli_writer** w, int stats, const veil_render_stats* st, veil_image_set* im,
                               long frame, const char* exr, const char* png, const char* deep, int aovs,
                               const veil_exr_meta* meta, veil_error* err);
/* Waits for the frames handed over, ends the thread, frees w (NULL: nothing); the first failure, if
 * any. *write_ms (may be NULL): the writes' time in all, *waited_ms the time put waited for them. */
veil_result veil_cli_writer_finish(veil_cli_writer* w, double* write_ms, double* waited_ms, veil_error* err);

/* The --stats line of a deep image's merge (render/deep.h). */
void veil_cli_print_deep(const veil_deep_report* d);

/* One line per stage: name, wall time, what happened and why. */
void veil_cli_print_stages(const veil_render_stats* st);

#endif
