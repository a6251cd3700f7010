/* libFuzzer target: the OpenVDB reader (io/vdb.h): the file's grids, then
 * its density grid opened, as `veil info` and `veil render` read them, and
 * its values checked as each kind of source reads them (a density, an
 * emission, a temperature: volume/vdb_volume.h, scene/limits.h): an opened
 * grid's values are finite, and a refusal has a message.
 * fuzz_nanovdb.c is this target for .nvdb files (FUZZ_VDB_FILE). */
#include "fuzz_common.h"
#include "io/vdb.h"
#include "volume/vdb_volume.h"

#include <math.h>

#ifndef FUZZ_VDB_FILE
#define FUZZ_VDB_FILE "f.vdb" /* the reader is chosen by the name's suffix */
#endif

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
    } else if (!e2.msg[0]) {
        abort();
    }
    return 0;
}
