/* veil — the JSON particle array, shared by scene files' inline "rbf"
 * particles and particle files (private to io/; defined in io/particles.c). */
#ifndef VEIL_PARTICLES_JSON_H
#define VEIL_PARTICLES_JSON_H

#include "json_read.h"
#include "../scene/particle.h"

/* The array at `p` (a key of obj) of {"center","amplitude","sharpness"}
 * particles, into a newly allocated *out (the same rules for inline scene
 * particles and particle files). */
veil_result veil__parse_particle_array(const ctx* c, const cJSON* obj, const jpath* p, veil_particle** out,
                                      size_t* count);

#endif
