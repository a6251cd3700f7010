/* libFuzzer target: the scene parser (io/scene.h) on arbitrary bytes. A
 * result is either a scene or an error with a message; nothing else. */
#include "fuzz_common.h"
#include "io/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    veil_scene s;
    veil_error err = {0};
    veil_result r = veil_scene_parse("fuzz.json", (const char*)data, size, &s, &err);
    if (r == VEIL_OK) veil_scene_free(&s);
    else if (!err.msg[0]) abort(); /* every refusal says why */
    return 0;
}
