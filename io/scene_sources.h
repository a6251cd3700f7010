/* veil — parsing medium.sources (private to io/). */
#ifndef VEIL_SCENE_SOURCES_H
#define VEIL_SCENE_SOURCES_H

#include "json_read.h"
#include "scene.h"

veil_result veil__parse_sources(const ctx* c, const cJSON* medium, const jpath* mp, veil_medium* m);

/* A string field; *out a newly allocated copy (NULL when absent and optional). */
veil_result veil__get_string(const ctx* c, const cJSON* o, const jpath* pp, const char* key, bool required,
                             char** out);
/* `*file` resolved against the scene's folder (c->base, else the scene file's) and, unless `unchecked`,
 * checked readable (the message names the field fp). */
veil_result veil__resolve_path(const ctx* c, const jpath* fp, char** file, int unchecked);

#endif
