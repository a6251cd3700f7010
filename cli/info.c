/* veil info: the grids of an OpenVDB file, as a table or JSON. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_util.h"
#include "core/text.h"
#include "commands.h"
#include "io/vdb.h"
#include "volume/scene_volume.h"

/* A file's string for the terminal: control characters and bytes that are not UTF-8 as \xNN (core/text.h). */
typedef struct shown {
    char s[4 * 256 + 1];
} shown;

static shown show(const char* text)
{
    shown t;
    veil_text_printable(text, t.s, sizeof t.s, 0);
    return t;
}

/* The columns a printable UTF-8 string takes: its characters (bytes that do not continue one). */
static int columns(const char* s)
{
    int n = 0;
    for (; *s; ++s) n += ((unsigned char)*s & 0xC0) != 0x80;
    return n;
}

static void print_info_grid(const veil_vdb_grid_info* g)
{
    printf("\ngrid '%s'\n", show(g->name).s);
    if (g->active_voxels == 0) {
        printf("  index bbox   (empty)\n");
    } else {
        printf("  index bbox   [%d, %d, %d] .. [%d, %d, %d]  (%d x %d x %d)\n", g->index_lo[0], g->index_lo[1],
               g->index_lo[2], g->index_hi[0], g->index_hi[1], g->index_hi[2], g->index_hi[0] - g->index_lo[0] + 1,
               g->index_hi[1] - g->index_lo[1] + 1, g->index_hi[2] - g->index_lo[2] + 1);
        if (g->affine)
            printf("  world bbox   [%g, %g, %g] .. [%g, %g, %g] m\n", g->world_lo[0], g->world_lo[1], g->world_lo[2],
                   g->world_hi[0], g->world_hi[1], g->world_hi[2]);
    }
    printf("  transform    %s%s\n", show(g->map_type).s, g->affine ? " (index to world, column vectors)" : " (not affine)");
    for (int r = 0; g->affine && r < 4; ++r)
        printf("               [%10.6g %10.6g %10.6g %10.6g]\n", g->index_to_world[r][0], g->index_to_world[r][1],
               g->index_to_world[r][2], g->index_to_world[r][3]);
    /* what `veil render` does with it when the scene sets no max_resolution (volume/scene_volume.h) */
    int cubes = g->affine;
    const double s = g->index_to_world[0][0];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) cubes &= r == c ? g->index_to_world[r][c] == s && s > 0.0 : g->index_to_world[r][c] == 0.0;
    if (!g->affine)
        printf("  rendering    not renderable: its transform is not affine\n");
    else if (cubes) {
        /* the native grid: the index box and the support's ring of zeros */
        double box = 1.0;
        for (int a = 0; a < 3; ++a) box *= (double)g->index_hi[a] - g->index_lo[a] + 3;
        if (g->active_voxels > 0 && box > (double)VEIL_NATIVE_MAX_VOXELS)
            printf("  rendering    sparse: axis-aligned %g m cubes, a box of %.3g voxels (over the dense cap of 2^27): "
                   "the 8^3 bricks that hold density, values copied (without medium.max_resolution)\n", s, box);
        else
            printf("  rendering    native: axis-aligned %g m cubes, values copied (without medium.max_resolution)\n", s);
    }
    else
        printf("  rendering    resampled at its smallest voxel edge (the field at each voxel centre): its voxels are "
               "rotated or not cubes\n");
}

int veil_cmd_info(int argc, char** argv)
{
    const char* path = NULL;
    int json = 0;
    for (int i = 2; i < argc; ++i) {
        if (!strcmp(argv[i], "--json")) json = 1;
        else if (argv[i][0] == '-' && argv[i][1]) return veil_cli_usage_error("unknown option '%s'", argv[i]);
        else if (!path) path = argv[i];
        else return veil_cli_usage_error("unexpected argument '%s'", argv[i]);
    }
    if (!path) return veil_cli_usage_error("%s", "info: missing FILE.vdb");
    veil_error err = {0};
    if (json) {
        char* text = NULL;
        veil_result r = veil_vdb_info_json(path, &text, &err);
        if (r != VEIL_OK) return veil_cli_fail(r, &err);
        puts(text);
        free(text);
        return EXIT_OK;
    }
    veil_vdb_grid_info* grids = NULL;
    size_t n = 0;
    veil_result r = veil_vdb_file_info(path, &grids, &n, &err);
    if (r != VEIL_OK) return veil_cli_fail(r, &err);
    int w = 4; /* name column: the longest name */
    for (size_t i = 0; i < n; ++i) w = columns(show(grids[i].name).s) > w ? columns(show(grids[i].name).s) : w;
    printf("%s: %zu grid%s\n\n", show(path).s, n, n == 1 ? "" : "s");
    printf("  %-*s  %-10s  %-8s  %13s  %s\n", w, "name", "class", "type", "active voxels", "voxel size (m)");
    for (size_t i = 0; i < n; ++i) {
        const veil_vdb_grid_info* g = &grids[i];
        char vs[96];
        if (fabs(g->voxel_size[0] - g->voxel_size[1]) <= 1e-9 * g->voxel_size[0] &&
            fabs(g->voxel_size[1] - g->voxel_size[2]) <= 1e-9 * g->voxel_size[0]) /* uniform, up to rounding */
            snprintf(vs, sizeof vs, "%g", g->voxel_size[0]);
        else
            snprintf(vs, sizeof vs, "%g x %g x %g", g->voxel_size[0], g->voxel_size[1], g->voxel_size[2]);
        const shown name = show(g->name);
        printf("  %s%*s  %-10s  %-8s  %13llu  %s\n", name.s, w - columns(name.s), "", show(g->grid_class).s,
               show(g->value_type).s, (unsigned long long)g->active_voxels, vs);
    }
    for (size_t i = 0; i < n; ++i) print_info_grid(&grids[i]);
    veil_vdb_file_info_free(grids, n);
    return EXIT_OK;
}

