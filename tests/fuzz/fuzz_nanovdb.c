/* libFuzzer target: the NanoVDB reader (io/vdb.h reads a .nvdb file
 * through NanoVDB and converts its grids to OpenVDB's): the file's grids,
 * then its density grid opened, as `veil info` and `veil render` read them. */
#include "fuzz_common.h"
#include "io/vdb.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const char* path = fuzz_file(data, size, "f.nvdb");
    veil_vdb_grid_info* grids = NULL;
    size_t count = 0;
    veil_error err = {0};
    if (veil_vdb_file_info(path, &grids, &count, &err) == VEIL_OK) veil_vdb_file_info_free(grids, count);
    else if (!err.msg[0]) abort();
    veil_vdb* v = NULL;
    char chosen[64];
    veil_error e2 = {0};
    if (veil_vdb_open(path, NULL, 1, &v, chosen, sizeof chosen, &e2) == VEIL_OK) veil_vdb_close(v);
    else if (!e2.msg[0]) abort();
    return 0;
}
