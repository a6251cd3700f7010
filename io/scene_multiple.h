/* veil — reading a scene's "multiple_scattering" object (private to io/). */
#ifndef VEIL_IO_SCENE_MULTIPLE_H
#define VEIL_IO_SCENE_MULTIPLE_H

#include "../scene/scene.h"
#include "json_read.h"

/* Defaults first, then the fields the object gives (absent: defaults). */
veil_result veil__parse_multiple(const ctx* c, const cJSON* root, veil_multiple* m);

#endif
