/* libFuzzer target: veil_scene_from_json with "array" sources (issue 41):
 * the input is a scene; every grid an array source names (its "grid", its
 * emission's and temperature's) is set to an 8^3 puff, and a scene of array
 * and analytic sources only is opened as the render opens its volume (CPU
 * only): the grid's placement composed with the source's transform, the
 * values' checks, the resampling. Every refusal has a message. */
#include "fuzz_common.h"
#include "include/veil.h"
#include "io/scene.h"
#include "volume/scene_volume.h"

static void set_puff(veil_scene* s, const char* name)
{
    if (!name) return;
    static float puff[8 * 8 * 8];
    for (int i = 0; i < 512; ++i) puff[i] = (float)((i * 13) % 7) / 7.0f;
    veil_grid_desc g = VEIL_GRID_DESC_INIT;
    g.data = puff, g.dims[0] = g.dims[1] = g.dims[2] = 8;
    g.index_to_world[0] = g.index_to_world[5] = g.index_to_world[10] = 0.125, g.index_to_world[15] = 1.0;
    veil_error err = {{0}};
    if (veil_scene_set_grid(s, name, &g, &err) != VEIL_OK && !err.msg[0]) abort();
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    char* json = malloc(size + 1);
    if (!json) return 0;
    memcpy(json, data, size);
    json[size] = '\0';
    veil_scene* s = NULL;
    veil_error err = {{0}};
    veil_result r = veil_scene_from_json(json, NULL, "fuzz", &s, &err);
    free(json);
    if (r != VEIL_OK) {
        if (!err.msg[0]) abort();
        return 0;
    }
    int cheap = 1; /* array and analytic sources only: no particle generator, no file */
    for (size_t i = 0; i < s->medium.source_count; ++i) {
        const veil_source* src = &s->medium.sources[i];
        if (src->type == VEIL_SOURCE_ARRAY) {
            set_puff(s, src->vdb.grid);
            set_puff(s, src->vdb.emission_grid);
            set_puff(s, src->vdb.temperature_grid);
        } else if (src->type != VEIL_SOURCE_EXPONENTIAL) {
            cheap = 0;
        }
    }
    if (cheap && s->medium.max_resolution <= 64) {
        veil_scene_volume v;
        veil_error e2 = {{0}};
        if (veil_scene_volume_open(s, &v, &e2) == VEIL_OK) veil_scene_volume_close(&v);
        else if (!e2.msg[0]) abort();
    }
    veil_scene_close(s);
    return 0;
}
