/* veil — scene files (JSON), parsed into the plain structs of scene/scene.h.
 *
 * The format is documented in docs/scene-format.md. veil_scene_load() reads
 * a file; every error message starts with the file name, then the JSON path
 * of the offending field (e.g. `lights[1].intensity`) and what was
 * expected. Unknown keys are errors. Relative paths inside the scene
 * resolve against the scene file's folder (scene->base_dir).
 */
#ifndef VEIL_IO_SCENE_H
#define VEIL_IO_SCENE_H

#include <stddef.h>

#include "../core/result.h"
#include "../scene/scene.h"

/* Parses `path`. On failure *out is left zeroed and err says why:
 * VEIL_ERR_IO (missing/unreadable file), VEIL_ERR_PARSE (JSON syntax, with
 * line and column), VEIL_ERR_INVALID (wrong type, unknown key, missing
 * field, value out of range). */
veil_result veil_scene_load(const char* path, veil_scene* out, veil_error* err);

/* Same, from a string in memory; `name` is used in messages and base_dir. */
veil_result veil_scene_parse(const char* name, const char* json, size_t len,
                             veil_scene* out, veil_error* err);

/* Same, relative paths resolved against `base_dir` (NULL or "": name's
 * folder, as veil_scene_parse), which becomes out->base_dir. */
veil_result veil_scene_parse_in(const char* name, const char* json, size_t len, const char* base_dir,
                                veil_scene* out, veil_error* err);

#endif
