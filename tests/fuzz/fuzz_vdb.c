/* libFuzzer target: the OpenVDB reader (io/vdb.h): the file's grids, then
 * its density grid opened, as `veil info` and `veil render` read them; its
 * values checked as each kind of source reads them (a density, an emission,
 * a temperature: volume/vdb_volume.h, scene/limits.h): an opened grid's
 * values are finite, and a refusal has a message; its leaves and tiles
 * counted (veil_vdb_census_of), and, in a scene that asks for it sparse, the
 * census of its bricks and the frame's work as a render estimates them
 * before the gather (frame/stages.h; CPU only, no GL).
 * fuzz_nanovdb.c is this target for .nvdb files (FUZZ_VDB_FILE). */
#include "fuzz_common.h"
#include "frame/stages.h"
#include "io/scene.h"
#include "io/vdb.h"
#include "volume/scene_volume.h"
#include "volume/vdb_volume.h"

#include <math.h>

#ifndef FUZZ_VDB_FILE
#define FUZZ_VDB_FILE "f.vdb" /* the reader is chosen by the name's suffix */
#endif

/* The file as a sparse medium: the census and the work estimate, refused or
 * not; any failure must say why. */
static void sparse_estimate(const char* path)
{
    char json[512];
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0, 0, -5], \"look_at\": [0, 0, 0], \"width\": 8, \"height\": 6},"
             " \"medium\": {\"sigma_s\": [1, 1, 1], \"representation\": \"sparse\","
             "  \"sources\": [{\"type\": \"vdb\", \"file\": \"%s\", \"level_set\": \"to_fog\"}]},"
             " \"lights\": [{\"type\": \"directional\", \"direction\": [-1, -2, -3], \"irradiance\": [1, 1, 1]},"
             "  {\"type\": \"point\", \"position\": [0, 1, 0], \"intensity\": [1, 1, 1]}]}",
             path);
    veil_scene s;
    veil_error err = {0};
    if (veil_scene_parse("fuzz.json", json, strlen(json), &s, &err) != VEIL_OK) abort(); /* the scene is ours */
    veil_scene_volume v;
    veil_error e2 = {0};
    if (veil_scene_volume_open(&s, &v, &e2) == VEIL_OK) {
        veil_frame_plan p;
        veil_frame_plan_begin(&p, &s, NULL, 0);
        veil_sparse_work w;
        veil_error e3 = {0};
        if (veil_frame_sparse_estimate(&p, &v, &w, &e3) != VEIL_OK && !e3.msg[0]) abort();
        veil_scene_volume_close(&v);
    } else if (!e2.msg[0]) {
        abort();
    }
    veil_scene_free(&s);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const char* path = fuzz_file(data, size, FUZZ_VDB_FILE);
    veil_vdb_grid_info* grids = NULL;
    size_t count = 0;
    veil_error err = {0};
    if (veil_vdb_file_info(path, &grids, &count, &err) == VEIL_OK) veil_vdb_file_info_free(grids, count);
    else if (!err.msg[0]) abort();
    veil_vdb* v = NULL;
    char chosen[64];
    veil_error e2 = {0};
    if (veil_vdb_open(path, NULL, 1, &v, chosen, sizeof chosen, &e2) == VEIL_OK) {
        veil_vdb_census c;
        veil_error e4 = {0};
        if (veil_vdb_census_of(v, &c, &e4) != VEIL_OK && !e4.msg[0]) abort();
        veil_vdb_values x;
        veil_vdb_value_range(v, &x);
        if (!isfinite(x.min) || !isfinite(x.max) || x.min > 0.0 || x.max < 0.0) abort();
        static const veil_values_kind kinds[] = {VEIL_VALUES_DENSITY, VEIL_VALUES_EMISSION, VEIL_VALUES_TEMPERATURE};
        for (int k = 0; k < 3; ++k) {
            veil_error e3 = {0};
            if (veil_vdb_check_values(v, kinds[k], 1.0, 0.0, &e3) != VEIL_OK && !e3.msg[0]) abort();
        }
        if (x.negative > 0 && veil_vdb_count_outside(v, 0.0, HUGE_VAL) != x.negative) abort();
        veil_vdb_close(v);
        sparse_estimate(path);
    } else if (!e2.msg[0]) {
        abort();
    }
    return 0;
}
