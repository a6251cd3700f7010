/* libFuzzer target: the array grid descriptor (veil_scene_set_grid,
 * include/veil.h; issue 41): the input's first bytes are its dimensions,
 * axis order and index-to-world matrix, the rest its values (repeated to
 * fill the dimensions, at most 2^16 of them). Set on a scene whose "array"
 * source reads it: a refusal has a message; a grid set is opened as the
 * render opens it (the scene's volume, CPU only), and its values read
 * back within the grid's bounds. */
#include "fuzz_common.h"
#include "include/veil.h"
#include "io/scene.h"
#include "volume/scene_volume.h"

#include <math.h>

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    enum { HEAD = 3 * 2 + 1 + 16 * 8, MAX_VALUES = 1 << 16 };
    if (size < HEAD) return 0;
    veil_grid_desc g = VEIL_GRID_DESC_INIT;
    size_t at = 0;
    for (int a = 0; a < 3; ++a, at += 2) g.dims[a] = (int)(((uint16_t)data[at] | (uint16_t)data[at + 1] << 8) % 64) - 1;
    g.axis_order = data[at++] % 3; /* 2: refused */
    for (int i = 0; i < 16; ++i, at += 8) memcpy(&g.index_to_world[i], data + at, 8);
    size_t n = 1;
    for (int a = 0; a < 3; ++a) n *= g.dims[a] > 0 ? (size_t)g.dims[a] : 1;
    if (n > MAX_VALUES) return 0;
    static float values[MAX_VALUES];
    const size_t have = (size - HEAD) / 4;
    for (size_t i = 0; i < n; ++i) {
        if (have) memcpy(&values[i], data + HEAD + 4 * (i % have), 4);
        else values[i] = 1.0f;
    }
    g.data = values;
    static const char* const json =
        "{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0], \"width\": 8, \"height\": 6},"
        " \"medium\": {\"sigma_s\": [1, 1, 1], \"max_resolution\": 32, \"sources\": [{\"type\": \"array\", "
        "\"grid\": \"density\"}]}, \"lights\": [{\"type\": \"directional\", \"direction\": [0, -1, 0], "
        "\"irradiance\": [1, 1, 1]}]}";
    veil_scene* s = NULL;
    veil_error err = {{0}};
    if (veil_scene_from_json(json, NULL, "fuzz", &s, &err) != VEIL_OK) abort(); /* ours */
    veil_result r = veil_scene_set_grid(s, "density", &g, &err);
    if (r != VEIL_OK) {
        if (!err.msg[0]) abort();
    } else {
        veil_scene_volume v;
        veil_error e2 = {{0}};
        if (veil_scene_volume_open(s, &v, &e2) == VEIL_OK) veil_scene_volume_close(&v);
        else if (!e2.msg[0]) abort();
    }
    veil_scene_close(s);
    return 0;
}
