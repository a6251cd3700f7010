/* veil tests — OpenVDB trees checked before OpenVDB reads them
 * (io/vdb_header.cpp): every grid type under every compression reads, and
 * a tree whose claims are absurd is refused by the check, with its
 * message, not by OpenVDB after allocating what it claimed.
 *
 *   test_vdb_trees DATA_DIR CASE     CASE: types, corrupt
 * The files are make_test_vdbs's (tree_files() there). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <string.h>

#include "support/check.h"
#include "support/vdb_util.h"
#include "io/vdb.h"

/* The typed grids' active voxels (make_test_vdbs.cpp, typed_grid): 37 x 15
 * x 10 scattered voxels and a 512-voxel tile; 24 x 3 x 2 and the tile in
 * the narrow (uncompressed) file. */
#define WIDE_ACTIVE (37u * 15u * 10u + 512u)
#define NARROW_ACTIVE (24u * 3u * 2u + 512u)

static void test_types(void)
{
    static const char* const files[] = {"types_blosc.vdb", "types_zip.vdb", "types_raw.vdb", "types_half.vdb"};
    static const struct {
        const char *grid, *type;
    } grids[] = {{"float", "float"}, {"double", "double"}, {"int32", "int32"}, {"int64", "int64"},
                 {"vec3s", "vec3s"}, {"vec3d", "vec3d"},   {"vec3i", "vec3i"}, {"bool", "bool"},
                 {"instance", "float"}};
    for (size_t f = 0; f < sizeof files / sizeof files[0]; ++f) {
        const uint64_t want = strcmp(files[f], "types_raw.vdb") == 0 ? NARROW_ACTIVE : WIDE_ACTIVE;
        /* written without statistics: the file's info reads every tree */
        veil_vdb_grid_info* gi = NULL;
        size_t n = 0;
        veil_error err = {0};
        veil_result r = veil_vdb_file_info(file(files[f]), &gi, &n, &err);
        CHECK(r == VEIL_OK && n == 10, "%s: %s, %zu grids: %s", files[f], veil_result_name(r), n, err.msg);
        for (size_t g = 0; r == VEIL_OK && g < sizeof grids / sizeof grids[0]; ++g) {
            const veil_vdb_grid_info* hit = NULL;
            for (size_t k = 0; k < n; ++k)
                if (strcmp(gi[k].name, grids[g].grid) == 0) hit = &gi[k];
            CHECK(hit && strcmp(hit->value_type, grids[g].type) == 0 && hit->active_voxels == want,
                  "%s: grid %s: type %s, %llu active voxels (expected %s, %llu)", files[f], grids[g].grid,
                  hit ? hit->value_type : "(missing)", hit ? (unsigned long long)hit->active_voxels : 0ull,
                  grids[g].type, (unsigned long long)want);
        }
        if (r == VEIL_OK) veil_vdb_file_info_free(gi, n);
        /* the float grids open: the grid, its instance, the level set as fog */
        static const char* const opens[] = {"float", "instance", "level_set"};
        for (int k = 0; k < 3; ++k) {
            veil_vdb* v = open_ok(files[f], opens[k], 1, NULL, 0);
            if (!v) continue;
            int lo[3], hi[3];
            size_t active = 0;
            CHECK(veil_vdb_index_bbox(v, lo, hi, &active) == VEIL_OK && active > 0, "%s %s: no active voxel",
                  files[f], opens[k]);
            if (k < 2) CHECK(active == want, "%s %s: %zu active, expected %llu", files[f], opens[k], active,
                             (unsigned long long)want);
            veil_vdb_close(v);
        }
        printf("%s: 9 grids of 8 types read, %llu active voxels each; float, instance and level set open\n",
               files[f], (unsigned long long)want);
    }
}

/* Each corrupt file is refused by the tree check, whose message names the
 * claim, with VEIL_ERR_IO: before the check, chunk_big.vdb made OpenVDB
 * allocate 10 GB (under AddressSanitizer: abort), chunk_raw.vdb had OpenVDB
 * read up to 4 096 bytes into a 16-byte heap buffer, chunk_header.vdb went to blosc
 * with a 1 GiB claim and root_count.vdb allocated a 256 KB node per
 * claimed child until the stream failed. */
static void refused(const char* name, const char* has)
{
    veil_vdb* v = NULL;
    veil_error err = {0};
    veil_result r = veil_vdb_open(file(name), NULL, 0, &v, NULL, 0, &err);
    CHECK(r == VEIL_ERR_IO && !v, "%s: %s, expected VEIL_ERR_IO: %s", name, veil_result_name(r), err.msg);
    CHECK(strstr(err.msg, name) && strstr(err.msg, has), "%s: the message lacks the file or '%s': %s", name, has,
          err.msg);
    printf("%s: %s: %s\n", name, veil_result_name(r), err.msg);
    if (v) veil_vdb_close(v);
}

static void test_corrupt(void)
{
    refused("chunk_big.vdb", "a compressed chunk (10000000000) does not fit");
    refused("chunk_raw.vdb", "a chunk of -4096 bytes where the node's values take 16");
    refused("chunk_header.vdb", "says it holds 1073741824 bytes");
    refused("root_count.vdb", "a root's tile and child counts (2147483648) does not fit");
    /* OpenVDB reads such a file's grids whole as they come, before any of
     * the checks above could look at them (the fuzzer found a 7 KB one that
     * took 2 GB under AddressSanitizer): refused */
    refused("no_offsets.vdb", "without grid offsets");
    /* OpenVDB reads a tree as half floats as the grid's metadata says, not
     * its type: where they differ, the walk could not follow it */
    refused("half_mismatch.vdb", "but its metadata is_saved_as_half_float is false");
    /* NanoVDB allocated the described size before reading (1 TiB here) and
     * followed a grid's child offsets as given (here 1 TiB past the buffer) */
    refused("nano_size.nvdb", "a grid's bytes");
    refused("nano_child.nvdb", "a child node outside the grid");
}

int main(int argc, char** argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: %s DATA_DIR CASE\n", argv[0]);
        return 2;
    }
    g_dir = argv[1];
    if (strcmp(argv[2], "types") == 0) test_types();
    else if (strcmp(argv[2], "corrupt") == 0) test_corrupt();
    else {
        fprintf(stderr, "%s: unknown case '%s'\n", argv[0], argv[2]);
        return 2;
    }
    return check_finish();
}
