/* libFuzzer target: an EXR as a scene's environment map (issue 41): the map
 * read within VEIL_ENV_MAX_TEXELS (its header checked before any texel),
 * its texels checked, its integral, its median cuts for every rung, and, when
 * the scene takes it, the rest's photon table and the sampling distribution.
 * A result is a scene whose cuts' lights are finite, or an error with a
 * message. */
#include "fuzz_common.h"
#include "io/scene.h"
#include "scene/environment.h"

#include <math.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const char* path = fuzz_file(data, size, "sky.exr");
    char json[512];
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0, 0, 3], \"look_at\": [0, 0, 0], \"width\": 8, \"height\": 6},"
             " \"medium\": {\"sigma_s\": [1, 1, 1], \"sources\": []},"
             " \"lights\": [{\"type\": \"environment\", \"file\": \"%s\", \"rotation_deg\": 30}]}", path);
    veil_scene s;
    veil_error err = {0};
    if (veil_scene_parse("fuzz.json", json, strlen(json), &s, &err) != VEIL_OK) {
        if (!err.msg[0]) abort(); /* every refusal says why */
        return 0;
    }
    const veil_environment* e = &s.environment;
    for (int c = 0; c < e->cut_sets; ++c)
        for (int l = 0; l < e->cuts[c].count; ++l)
            for (int k = 0; k < 3; ++k)
                if (!isfinite(e->cuts[c].lights[l].color[k]) || !isfinite(e->cuts[c].lights[l].direction[k])) abort();
    veil_env_table t = {0};
    veil_error e2 = {0};
    if (veil_env_rest_table(e, (size_t)1 << 19, &t, &e2) != VEIL_OK && !e2.msg[0]) abort();
    veil_env_table_free(&t);
    veil_error e3 = {0};
    if (veil_env_dist_make(&s.environment, &e3) != VEIL_OK && !e3.msg[0]) abort();
    veil_scene_free(&s);
    return 0;
}
