/* veil — the plan of a run over frames: which stages run on which frame and
 * why, computed from the same keys the renderer uses (frame/renderer.h),
 * without a GPU and without rendering; and the names of frame files.
 *
 * A frame's camera is veil_camera_of_frame() (scene/camera.h); no key
 * depends on the camera except the render stage's, so for a static medium
 * inject and propagate run on the first frame only.
 */
#ifndef VEIL_PLAN_H
#define VEIL_PLAN_H

#include <stddef.h>

#include "../core/result.h"
#include "../scene/scene.h"
#include "renderer.h"

/* The plan of rendering `frames` frames (>= 1) of s with opts, as text
 * (malloc'd into *text; free() it). Opens the scene's VDB files (to know
 * the volume's grid, which decides which spot lights reach it) but makes
 * no GL context. Errors are the renderer's (a missing file, ...). */
veil_result veil_plan_explain(const veil_scene* s, const veil_render_opts* opts, long frames, char** text,
                              veil_error* err);

/* The same walk as data: each stage's key, status and why (cut to
 * VEIL_STAGE_WHY_MAX) on the first frame of a run (`first`) and on the
 * frames after it (`later`), VEIL_STAGE_COUNT reports each, ms 0. What
 * frame/renderer.c reports for those frames, stage by stage, except where
 * a build learns what no description says (a view found optically thin,
 * sources that hold no density, the emission's lights). */
veil_result veil_plan_reports(const veil_scene* s, const veil_render_opts* opts, veil_stage_report* first,
                              veil_stage_report* later, veil_error* err);

/* The file of frame `frame`: `path` itself when !numbered, else its stem,
 * "_", the frame number with at least 4 digits, and its extension
 * ("out/t.exr", 7 -> "out/t_0007.exr"). VEIL_ERR_LIMIT when it does not
 * fit in n bytes. */
veil_result veil_frame_path(const char* path, long frame, int numbered, char* out, size_t n, veil_error* err);

#endif
