/* veil — parsing medium.sources (private to io/). */
#ifndef VEIL_SCENE_SOURCES_H
#define VEIL_SCENE_SOURCES_H

#include "json_read.h"
#include "scene.h"

veil_result veil__parse_sources(const ctx* c, const cJSON* medium, const jpath* mp, veil_medium* m);

/* The array at `p` (a key of obj) of {"center","amplitude","sharpness"}
 * particles, into a newly allocated *out (the same rules for inline scene
 * particles and particle files). */
veil_result veil__parse_particle_array(const ctx* c, const cJSON* obj, const jpath* p, veil_particle** out,
                                      size_t* count);

#endif
