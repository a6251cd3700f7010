/* veil — the OpenVDB reader: one float grid from a .vdb file, its index-to-
 * world transform, trilinear samples of it, and a summary of every grid in a
 * file (`veil info`).
 *
 * Convention (OpenVDB's, which vdb_render follows): the value of voxel
 * (i, j, k) is a sample at the integer index point (i, j, k), which lies at
 * world M * (i, j, k, 1) under the grid's affine map M; the field between
 * samples is their trilinear interpolation (openvdb::tools::BoxSampler).
 * (Blender Cycles 3.4 places the samples half a voxel off from this.) World
 * units are the file's, taken as metres. Values are unitless density; the
 * values of inactive voxels and tiles and the background are read as 0
 * (a fog volume's inactive region is empty space).
 *
 * Ownership: veil_vdb_open makes a veil_vdb that owns a copy of the grid
 * (the file is read completely and closed before it returns);
 * veil_vdb_close frees it. A veil_vdb is read-only after opening, so any
 * number of threads may sample one at once. Strings returned by the info
 * functions are malloc'd and freed by the caller (or by
 * veil_vdb_file_info_free). The implementation is C++ (io/vdb.cpp); no
 * exception leaves it: each one becomes a result code and a message that
 * names the file and says what OpenVDB said.
 */
#ifndef VEIL_VDB_H
#define VEIL_VDB_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#include "../core/result.h"

/* One loaded float grid (opaque). */
typedef struct veil_vdb veil_vdb;

/* The grid chosen when the caller names none: this one if the file has it,
 * else the file's first float grid, in the order OpenVDB lists a file's
 * grids (by name, not by position in the file). */
#define VEIL_VDB_DEFAULT_GRID "density"

/* Opens `path` and loads one float grid: `grid_name`, or when NULL the
 * default above. Writes the chosen grid's name into chosen_name (chosen_len
 * bytes, truncated; may be NULL). A level set is refused unless
 * level_set_to_fog is set, which converts it into a fog volume
 * (openvdb::tools::sdfToFogVolume: 0 outside, rising to 1 over the interior
 * narrow band, 1 inside).
 * Errors: VEIL_ERR_IO (missing, unreadable, corrupt or truncated file),
 * VEIL_ERR_INVALID (no such grid: the message lists the file's grids; not
 * a float grid: it names the value type; a level set without the flag; an
 * active value that is not a number or infinite: veil_vdb_value_range),
 * VEIL_ERR_OOM. */
veil_result veil_vdb_open(const char* path, const char* grid_name, int level_set_to_fog, veil_vdb** out,
                          char* chosen_name, size_t chosen_len, veil_error* err);
/* Accepts NULL. */
void veil_vdb_close(veil_vdb* v);

/* A grid made from memory (an "array" source): dims[0] x dims[1] x dims[2]
 * values, x fastest (data[i + nx (j + ny k)]) or, with z_fastest, z fastest
 * (data[k + nz (j + ny i)], a C array indexed [i][j][k]); the value of index
 * (i, j, k) lies at index_to_world (column vectors) times (i, j, k, 1), as a
 * file's voxel does. Values of 0 are inactive, as in a file written by
 * pyopenvdb's copyFromArray (openvdb::tools::copyFromDense, tolerance 0):
 * both give the same tree. `label` stands for the file in messages and
 * veil_vdb_path. The values are copied; NaN or infinite values are refused
 * as veil_vdb_open refuses them, and so is a singular or non-affine matrix
 * (VEIL_ERR_INVALID). */
veil_result veil_vdb_from_dense(const char* label, const char* name, const float* data, const int dims[3],
                                int z_fastest, const double index_to_world[4][4], veil_vdb** out, veil_error* err);

/* Places v in a world: its index-to-world map becomes m x (its own map)
 * (column vectors; m affine and invertible, else VEIL_ERR_INVALID). Called
 * once, right after opening, before v is shared. */
veil_result veil_vdb_place(veil_vdb* v, const double m[4][4], veil_error* err);

/* From now on, reading a file (veil_vdb_open, veil_vdb_file_info) limits
 * the process's address space for the time of the read to what it uses
 * plus 1 GiB plus 64 times the file's size (setrlimit, restored after):
 * OpenVDB allocates buffer sizes it reads from inside the trees, and a
 * corrupt file then fails with VEIL_ERR_IO instead of taking gigabytes.
 * Process-wide, so a program opts in (the CLI does); off under
 * AddressSanitizer. */
void veil_vdb_limit_reads(int on);

/* The file and grid name, for messages (owned by v). */
const char* veil_vdb_path(const veil_vdb* v);
const char* veil_vdb_grid_name(const veil_vdb* v);
/* The file's other grids, "name (value type)" comma-separated ("" when
 * none): what was not read, for reports (velocity grids and the like are
 * ignored unless a source asks for them). Owned by v. */
const char* veil_vdb_other_grids(const veil_vdb* v);

/* The active values (voxels, and active tiles counted by their voxels), as
 * veil_vdb_open read them: their range, 0 included (inactive voxels read
 * 0), and how many are below 0. veil_vdb_open refuses a grid holding a
 * value that is not a number or infinite (VEIL_ERR_INVALID, naming the
 * file, the grid, how many voxels and the first one's index), so every
 * value is finite. What a value may be beyond that depends on what it is
 * (density, emission, temperature): volume/vdb_volume.h, scene/limits.h. */
typedef struct veil_vdb_values {
    double min, max;
    uint64_t negative;
} veil_vdb_values;
void veil_vdb_value_range(const veil_vdb* v, veil_vdb_values* out);
/* Active voxels (a tile counts its voxels) whose value is below lo or above
 * hi: one pass over the values, for messages. */
uint64_t veil_vdb_count_outside(const veil_vdb* v, double lo, double hi);

/* The affine index-to-world map as a 4x4 matrix acting on column vectors:
 * world[r] = sum_c m[r][c] * (i, j, k, 1)[c]; the last row is 0 0 0 1.
 * VEIL_ERR_INVALID for a non-affine map (a frustum, or any nonlinear one). */
veil_result veil_vdb_transform(const veil_vdb* v, double index_to_world[4][4], veil_error* err);

/* The inclusive index box [lo, hi] of the active voxels and tiles, and their
 * number. An empty grid gives active 0, lo = (0,0,0), hi = (-1,-1,-1). */
veil_result veil_vdb_index_bbox(const veil_vdb* v, int lo[3], int hi[3], size_t* active_voxels);

/* The trilinear field at n world points (xyz: 3n doubles, x y z per point)
 * into out (n floats); 0 away from the active voxels. Runs in parallel (TBB)
 * with one value accessor per task. */
veil_result veil_vdb_sample_world(const veil_vdb* v, const double* xyz, size_t n, float* out, veil_error* err);

/* The values at the integer index points of the inclusive box [lo, hi] into
 * out, x fastest then y then z ((hi-lo+1) product floats, caller's).
 * VEIL_ERR_INVALID if hi < lo on an axis; VEIL_ERR_LIMIT if the count does
 * not fit in size_t. */
veil_result veil_vdb_dense(const veil_vdb* v, const int lo[3], const int hi[3], float* out);

/* Calls fn(user, ijk, value) for every active voxel of the grid whose value
 * is not 0 (an active tile's voxels one by one), leaf by leaf in the tree's
 * order, which depends only on the file. The caller bounds the work with
 * the active count of veil_vdb_index_bbox first. */
typedef void (*veil_vdb_voxel_fn)(void* user, const int ijk[3], float value);
veil_result veil_vdb_each_voxel(const veil_vdb* v, veil_vdb_voxel_fn fn, void* user, veil_error* err);

/* The grid's non-zero active values as its tree holds them, without
 * expanding a tile (what veil_vdb_each_voxel would visit, counted first):
 * fn(user, lo, hi, voxels, tile) for each leaf node with an active voxel
 * whose value is not 0 (lo, hi: the inclusive index box of those voxels,
 * voxels: how many), then each active tile whose value is not 0 (its box,
 * voxels: its volume: 8^3, 128^3 or 4096^3 in OpenVDB's default tree).
 * fn returns 0 to stop the walk (the call still returns VEIL_OK). Cost: a
 * look at each leaf's active voxels and one visit per tile, never one per
 * voxel of a tile. */
typedef int (*veil_vdb_box_fn)(void* user, const int lo[3], const int hi[3], uint64_t voxels, int tile);
veil_result veil_vdb_each_box(const veil_vdb* v, veil_vdb_box_fn fn, void* user, veil_error* err);

/* The same, summed. */
typedef struct veil_vdb_census {
    uint64_t leaves;      /* leaf nodes (8^3 voxels) with a non-zero active voxel */
    uint64_t leaf_voxels; /* their non-zero active voxels */
    uint64_t tiles;       /* active tiles of a non-zero value, at any level of the tree */
    double tile_voxels;   /* the voxels they stand for (a root may hold any number of 4096^3 tiles) */
} veil_vdb_census;
veil_result veil_vdb_census_of(const veil_vdb* v, veil_vdb_census* out, veil_error* err);

/* ---- velocity and motion blur (volume/motion_blur.h decides when) ----
 *
 * A velocity field read from a file: a vec3 grid (vec3s or vec3d; a
 * staggered one, OpenVDB's GRID_STAGGERED MAC layout, is sampled as such),
 * or three float grids NAME.x, NAME.y, NAME.z on one transform. Vectors
 * are in the file's world units per unit of time (the source's "unit");
 * inactive values and the background read as 0, as a density's do.
 * Ownership as veil_vdb: a copy of the field, read-only once placed. */
typedef struct veil_vdb_velocity veil_vdb_velocity;

/* The names tried, in this order, when a source names no velocity grid:
 * each as a vec3 grid, then as the float triple NAME.x/.y/.z. */
#define VEIL_VDB_VELOCITY_NAMES {"vel", "v", "velocity"}

/* Opens the velocity `grid_name` of `path` (NULL: the first of
 * VEIL_VDB_VELOCITY_NAMES the file holds) and writes what it read into
 * chosen ("vel", or "vel.x/.y/.z"). Errors: VEIL_ERR_IO as veil_vdb_open;
 * VEIL_ERR_INVALID naming the file and grid for a missing grid (listing
 * the file's grids), a grid that is not a vector (a float grid without
 * its .x/.y/.z partners, an integer vector...), a triple on different
 * transforms, a vector that is not finite or a non-affine map. */
veil_result veil_vdb_velocity_open(const char* path, const char* grid_name, veil_vdb_velocity** out, char* chosen,
                                   size_t chosen_len, veil_error* err);
/* Accepts NULL. */
void veil_vdb_velocity_close(veil_vdb_velocity* v);
/* Places the field as veil_vdb_place places a grid (m: column vectors,
 * affine, invertible): its points move by m, and its vectors turn and
 * stretch with m's 3x3 part (a velocity is a displacement per time). */
veil_result veil_vdb_velocity_place(veil_vdb_velocity* v, const double m[4][4], veil_error* err);
/* The largest |vector| of the field, as placed (world units per unit of
 * time): the trilinear field never exceeds it (a convex mix of corners). */
double veil_vdb_velocity_max(const veil_vdb_velocity* v);

/* The mean of a grid advected by a steady velocity field over n times:
 *
 *   g_b(x) = (1/n) sum_k g(X(x, t_k)),
 *
 * X(x, t) the point whose value reaches x after time t: the path from x
 * traced backwards through the field, dX/ds = -sign(t) scale v(X) for s
 * in [0, |t|] (semi-Lagrangian; the field is the frame's, held steady over
 * the times). The path is walked outwards from t = 0 to each side's times
 * in turn, in steps moving at most max_step_voxels of g's smallest voxel
 * edge: the first a midpoint (RK2) step, the next ones two-step
 * Adams-Bashforth (second order too, with one velocity read a step instead
 * of two); g is sampled trilinearly (BoxSampler) at each t_k, v at the
 * path's points. A constant field gives exactly g
 * shifted by -scale v t_k. Only the voxels the paths can reach are made:
 * g's active voxels and tiles dilated by reach = ceil(max|v| scale
 * max|t_k| / edge) + 1 voxels (the trilinear support). Runs in parallel
 * (TBB, one accessor per task). */
typedef struct veil_vdb_advect_desc {
    const double* times;    /* n times, in the unit the velocity's vectors are per (a frame, a second) */
    int n;                  /* 1 .. VEIL_VDB_ADVECT_MAX_TIMES */
    double scale;           /* world displacement = scale x vector x time; >= 0, finite */
    double max_step_voxels; /* > 0: the path's steps move at most this many voxels of g */
    int clamp_negative;     /* 1: g's values below 0 read as 0 first (a density, an emission) */
} veil_vdb_advect_desc;
#define VEIL_VDB_ADVECT_MAX_TIMES 1024
/* The blurred grid's active voxels at most (2^28: 1 GiB of floats, the
 * size of the dense volume's cap, VEIL_VDB_MAX_DENSE_VOXELS, over 4). */
#define VEIL_VDB_ADVECT_MAX_VOXELS ((uint64_t)1 << 28)

typedef struct veil_vdb_advect_report {
    int reach;             /* voxels the active region was dilated by */
    uint64_t voxels_in;    /* active voxels before (tiles counted by their voxels) */
    uint64_t voxels_out;   /* active voxels after (non-zero values) */
    double max_displacement_voxels; /* max|v| scale max|t_k| / edge */
    double reads;          /* the reads made: voxels of the grown region x reads a voxel (veil_vdb_advect_work) */
} veil_vdb_advect_report;

/* What veil_vdb_advect_mean(g, vel, d) would do, counted before any voxel
 * is made (issue 41: motion blur's work is refused over a budget before it
 * starts, volume/motion_blur.h). Every voxel of the grown region walks the
 * same steps (they depend on the times alone), so the reads are exact but
 * for the region's voxels, which are counted on a mask of blocks of b^3
 * voxels (b a power of two, at least 8 and at least reach / 32): each
 * leaf's and active tile's box grown by the reach, rounded out to blocks,
 * their union counted. An upper bound of the region's voxels, over it by
 * at most (1 + 2b / (box + 2 reach))^3 (1.2 for a large reach); beyond
 * 2^20 blocks of the mask the count stops (`at_least`: the region holds at
 * least `voxels`, over VEIL_VDB_ADVECT_MAX_VOXELS). Costs a walk over g's
 * leaves and a mask of at most 2^20 blocks' nodes: milliseconds. */
typedef struct veil_vdb_advect_work {
    int reach;                      /* as the report's */
    double max_displacement_voxels; /* as the report's */
    double voxels;                  /* the grown region's voxels, at most (at least, when at_least) */
    int at_least;
    double reads_per_voxel;         /* the paths' velocity reads plus the n samples of g, for each voxel */
    double reads;                   /* voxels x reads_per_voxel */
} veil_vdb_advect_work;
veil_result veil_vdb_advect_work_of(const veil_vdb* g, const veil_vdb_velocity* vel, const veil_vdb_advect_desc* d,
                                    veil_vdb_advect_work* out, veil_error* err);

/* Replaces g's values by their blurred mean (same transform, so the same
 * lattice: native, sparse and dense volumes take it as they take g); g must
 * not be shared yet (called right after opening and placing, as
 * veil_vdb_place). With max|v| scale max|t_k| = 0 g is left as it is, bit
 * for bit. Errors: VEIL_ERR_INVALID for a bad description; VEIL_ERR_LIMIT
 * when the dilated region would hold more than VEIL_VDB_ADVECT_MAX_VOXELS
 * (naming the file, the grid and the reach), counted before the region is
 * made; VEIL_ERR_OOM. Long work reports its progress (core/progress.h,
 * "motion blur": voxels done of all) between parts of about
 * VEIL_VDB_ADVECT_PART_READS reads, and a cancel asked for there ends it
 * with VEIL_ERR_CANCELLED (g left as it was). */
#define VEIL_VDB_ADVECT_PART_READS ((double)(1 << 23))
veil_result veil_vdb_advect_mean(veil_vdb* g, const veil_vdb_velocity* vel, const veil_vdb_advect_desc* d,
                                 veil_vdb_advect_report* report, veil_error* err);

/* One grid of a file, as `veil info` shows it. */
typedef struct veil_vdb_grid_info {
    char* name;            /* owned */
    char grid_class[16];   /* "fog volume", "level set", "staggered" or "unknown" */
    char value_type[32];   /* OpenVDB's name: "float", "double", "vec3s", ... */
    uint64_t active_voxels;
    int index_lo[3], index_hi[3]; /* inclusive active box; lo > hi when empty */
    double world_lo[3], world_hi[3]; /* AABB of the active box's corner samples (m); affine only */
    double voxel_size[3];  /* world length of one index step along each index axis (m) */
    int affine;            /* 1: index_to_world holds the map; 0: map_type names the nonlinear map */
    char map_type[32];     /* OpenVDB's map name, e.g. "UniformScaleTranslateMap", "NonlinearFrustumMap" */
    double index_to_world[4][4]; /* as veil_vdb_transform */
} veil_vdb_grid_info;

/* Reads the metadata and transforms of every grid in `path` (and a grid's
 * tree only when the file lacks its bounding-box statistics). */
veil_result veil_vdb_file_info(const char* path, veil_vdb_grid_info** grids, size_t* count, veil_error* err);
void veil_vdb_file_info_free(veil_vdb_grid_info* grids, size_t count);

/* The same as a JSON document (malloc'd, free() it):
 * {"file": ..., "grids": [{"name", "class", "value_type", "active_voxels",
 *  "index_bbox": [[lo],[hi]] or null, "world_bbox": [[lo],[hi]] or null,
 *  "voxel_size": [3], "map_type", "transform": the 4 rows of the
 *  index-to-world matrix of veil_vdb_transform, or null when not affine}]} */
veil_result veil_vdb_info_json(const char* path, char** json_out, veil_error* err);

#ifdef __cplusplus
}
#endif

#endif
