/* veil tests — what the VDB tests share (tests/io/test_vdb.c,
 * tests/volume/test_vdb_import.c): the data folder the files were written to
 * (make_test_vdbs), a file in it, opening one that must open, and a grid
 * around a VDB's support. */
#ifndef VEIL_TEST_VDB_UTIL_H
#define VEIL_TEST_VDB_UTIL_H

#include <math.h>
#include <stdio.h>

#include "check.h"
#include "io/vdb.h"
#include "volume/vdb_volume.h"

static const char* g_dir;

static inline const char* file(const char* name)
{
    static char buf[4][4096];
    static int slot;
    char* p = buf[slot++ & 3];
    snprintf(p, sizeof buf[0], "%s/%s", g_dir, name);
    return p;
}

static inline veil_vdb* open_ok(const char* name, const char* grid, int to_fog, char* chosen, size_t chosen_len)
{
    veil_vdb* v = NULL;
    veil_error err = {0};
    veil_result r = veil_vdb_open(file(name), grid, to_fog, &v, chosen, chosen_len, &err);
    CHECK(r == VEIL_OK && v, "%s: %s: %s", name, veil_result_name(r), err.msg);
    return v;
}

/* A grid of voxel h around v's support, its origin shifted by `shift` voxels. */
static inline veil_grid grid_around(const veil_vdb* v, float h, float shift)
{
    float lo[3], hi[3];
    veil_error err = {0};
    CHECK(veil_vdb_world_support(v, lo, hi, &err) == VEIL_OK, "support: %s", err.msg);
    veil_grid g = {.voxel = h};
    for (int a = 0; a < 3; ++a) {
        g.origin[a] = lo[a] - (1.0f + shift) * h;
        g.dims[a] = (int)ceilf((hi[a] - g.origin[a]) / h) + 1;
    }
    return g;
}

#endif
