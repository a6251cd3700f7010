/* libFuzzer target: the NanoVDB reader (io/vdb.h reads a .nvdb file
 * through NanoVDB and converts its grids to OpenVDB's): the same target as
 * fuzz_vdb.c, the input written as a .nvdb file. */
#define FUZZ_VDB_FILE "f.nvdb"
#include "fuzz_vdb.c"
