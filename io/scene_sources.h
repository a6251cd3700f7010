/* veil — parsing medium.sources (private to io/). */
#ifndef VEIL_SCENE_SOURCES_H
#define VEIL_SCENE_SOURCES_H

#include "json_read.h"
#include "scene.h"

veil_result veil__parse_sources(const ctx* c, const cJSON* medium, const jpath* mp, veil_medium* m);

#endif
