/* Importing VDBs as production makes them (issue 11), on the files that
 * make_test_vdbs writes:
 *
 *   test_vdb_import DATA_DIR CASE
 *
 * CASE: native (a VDB keeps its own voxels), nanovdb (.nvdb and half-float
 * files read exactly), filters (the resampling filter by direction).
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "io/scene.h"
#include "reference/optical_depth.h"
#include "support/vdb_util.h"
#include "volume/scene_volume.h"

/* Native resolution (volume/scene_volume.h): without medium.max_resolution
 * a VDB keeps its own voxels. offset_scaled.vdb (axis-aligned, voxel
 * 0.25 m, index 0..15) must come out on its own lattice with every value
 * copied bit for bit (each EV voxel centre on an index point; the support's
 * ring of zeros around it); with max_resolution 8 it is resampled to 8
 * voxels along its longest side and says so; the rotated grid keeps its
 * voxel edge (0.05 m) but is resampled, and says why. */
static veil_result open_scene(const char* file, const char* extra, veil_scene* s, veil_scene_volume* v)
{
    char path[4200], json[8800];
    snprintf(path, sizeof path, "%s/%s", g_dir, file);
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0, 0, 9], \"look_at\": [0, 0, 0]},"
             " \"medium\": {\"sigma_s\": [1, 1, 1]%s, \"sources\": [{\"type\": \"vdb\", \"file\": \"%s\"}]}}",
             extra, path);
    veil_error err = {0};
    veil_result r = veil_scene_parse("native.json", json, strlen(json), s, &err);
    if (r == VEIL_OK) r = veil_scene_volume_open(s, v, &err);
    if (r != VEIL_OK) fprintf(stderr, "%s\n", err.msg);
    return r;
}

static void test_native(void)
{
    veil_scene s;
    veil_scene_volume v;
    veil_error err = {0};
    memset(&v, 0, sizeof v);
    if (open_scene("offset_scaled.vdb", "", &s, &v) != VEIL_OK) {
        CHECK(0, "open offset_scaled.vdb");
        return;
    }
    if (v.has_volume) {
        printf("offset_scaled: %s\n", v.resolution);
        CHECK(v.grid.voxel == 0.25f && strncmp(v.resolution, "native", 6) == 0, "native: voxel %g, '%s'",
              v.grid.voxel, v.resolution);
        /* index i sits at world 1 + i/4 (x), -2 + j/4, 3 + k/4: the first voxel centre's index */
        int first[3];
        const double t[3] = {1.0, -2.0, 3.0};
        for (int a = 0; a < 3; ++a) first[a] = (int)lround((v.grid.origin[a] + 0.5 * v.grid.voxel - t[a]) / 0.25);
        CHECK(first[0] == -1 && first[1] == -1 && first[2] == -1 && v.grid.dims[0] == 18, "the lattice: first index "
              "(%d, %d, %d), %d voxels a side (expected -1 and 18: the support's ring)", first[0], first[1], first[2],
              v.grid.dims[0]);
        float* d = NULL;
        CHECK(veil_scene_volume_density(&v, &d, &err) == VEIL_OK, "%s", err.msg);
        int lo[3] = {first[0], first[1], first[2]};
        int hi[3] = {first[0] + v.grid.dims[0] - 1, first[1] + v.grid.dims[1] - 1, first[2] + v.grid.dims[2] - 1};
        size_t n = veil_grid_voxels(&v.grid);
        float* want = malloc(n * sizeof *want);
        CHECK(want && veil_vdb_dense(v.vdbs[0], lo, hi, want) == VEIL_OK, "dense read");
        size_t differ = 0;
        for (size_t i = 0; d && want && i < n; ++i) differ += memcmp(&d[i], &want[i], sizeof(float)) != 0;
        CHECK(differ == 0, "%zu of %zu voxels are not the VDB's values bit for bit", differ, n);
        free(d);
        free(want);
    }
    veil_scene_volume_close(&v);
    veil_scene_free(&s);

    if (open_scene("offset_scaled.vdb", ", \"max_resolution\": 8", &s, &v) != VEIL_OK) {
        CHECK(0, "open with a cap");
        return;
    }
    int longest = v.grid.dims[0] > v.grid.dims[1] ? v.grid.dims[0] : v.grid.dims[1];
    longest = longest > v.grid.dims[2] ? longest : v.grid.dims[2];
    CHECK(longest == 8 && strstr(v.resolution, "resampled") && strstr(v.resolution, "max_resolution"),
          "a cap the user chose: %d voxels, '%s'", longest, v.resolution);
    veil_scene_volume_close(&v);
    veil_scene_free(&s);

    /* two sources of different voxel sizes: the finest (fog_sphere's 0.05 m) on its lattice */
    {
        char a[4200], b[4200], json[9000];
        snprintf(a, sizeof a, "%s/offset_scaled.vdb", g_dir);
        snprintf(b, sizeof b, "%s/fog_sphere.vdb", g_dir);
        snprintf(json, sizeof json,
                 "{\"camera\": {\"position\": [0, 0, 9], \"look_at\": [0, 0, 0]},"
                 " \"medium\": {\"sigma_s\": [1, 1, 1], \"sources\": [{\"type\": \"vdb\", \"file\": \"%s\"},"
                 " {\"type\": \"vdb\", \"file\": \"%s\"}]}}", a, b);
        CHECK(veil_scene_parse("two.json", json, strlen(json), &s, &err) == VEIL_OK, "%s", err.msg);
        memset(&v, 0, sizeof v);
        CHECK(veil_scene_volume_open(&s, &v, &err) == VEIL_OK, "%s", err.msg);
        printf("two sources: %s, grid %dx%dx%d\n", v.resolution, v.grid.dims[0], v.grid.dims[1], v.grid.dims[2]);
        CHECK(fabsf(v.grid.voxel - 0.05f) < 1e-6f && strncmp(v.resolution, "native", 6) == 0,
              "two sources: the finest voxel (0.05 m) natively: %g, '%s'", v.grid.voxel, v.resolution);
        veil_scene_volume_close(&v);
        veil_scene_free(&s);
    }

    if (open_scene("rotated.vdb", "", &s, &v) != VEIL_OK) {
        CHECK(0, "open rotated.vdb");
        return;
    }
    printf("rotated: %s, grid %dx%dx%d\n", v.resolution, v.grid.dims[0], v.grid.dims[1], v.grid.dims[2]);
    CHECK(fabsf(v.grid.voxel - 0.05f) < 1e-6f && strstr(v.resolution, "rotated"), "rotated: voxel %g, '%s'",
          v.grid.voxel, v.resolution);
    veil_scene_volume_close(&v);
    veil_scene_free(&s);
}

/* A NanoVDB file is read like an OpenVDB file (and a half-float OpenVDB
 * file exactly, where its values are exact in half): offset_scaled.nvdb holds
 * the same grid as offset_scaled.vdb (make_test_vdbs writes both), so the
 * reader must give the same name, index box, active count, transform and
 * values, bit for bit (a float NanoVDB grid stores the floats as they are). */
static void test_nanovdb(void)
{
    char a[4200], b[4200], hpath[4200];
    snprintf(a, sizeof a, "%s/offset_scaled.vdb", g_dir);
    snprintf(b, sizeof b, "%s/offset_scaled.nvdb", g_dir);
    snprintf(hpath, sizeof hpath, "%s/offset_scaled_half.vdb", g_dir);
    veil_vdb *va = NULL, *vb = NULL;
    veil_error err = {0};
    char name[64] = "";
    CHECK(veil_vdb_open(a, NULL, 0, &va, NULL, 0, &err) == VEIL_OK, "%s", err.msg);
    CHECK(veil_vdb_open(b, NULL, 0, &vb, name, sizeof name, &err) == VEIL_OK, "%s", err.msg);
    if (!va || !vb) {
        veil_vdb_close(va);
        veil_vdb_close(vb);
        return;
    }
    CHECK(strcmp(name, "density") == 0, "the .nvdb grid's name: '%s'", name);
    int alo[3], ahi[3], blo[3], bhi[3];
    size_t an = 0, bn = 0;
    veil_vdb_index_bbox(va, alo, ahi, &an);
    veil_vdb_index_bbox(vb, blo, bhi, &bn);
    CHECK(an == bn && memcmp(alo, blo, sizeof alo) == 0 && memcmp(ahi, bhi, sizeof ahi) == 0,
          "index box and count: %zu vs %zu", an, bn);
    double ma[4][4], mb[4][4];
    CHECK(veil_vdb_transform(va, ma, &err) == VEIL_OK && veil_vdb_transform(vb, mb, &err) == VEIL_OK, "%s", err.msg);
    CHECK(memcmp(ma, mb, sizeof ma) == 0, "transform differs");
    float da[16 * 16 * 16], db[16 * 16 * 16];
    CHECK(veil_vdb_dense(va, alo, ahi, da) == VEIL_OK && veil_vdb_dense(vb, alo, ahi, db) == VEIL_OK, "dense reads");
    CHECK(memcmp(da, db, sizeof da) == 0, "values differ");
    /* a half-float file of the same (half-exact) values: read exactly */
    veil_vdb* vh = NULL;
    CHECK(veil_vdb_open(hpath, NULL, 0, &vh, NULL, 0, &err) == VEIL_OK, "%s", err.msg);
    if (vh) {
        float dh[16 * 16 * 16];
        CHECK(veil_vdb_dense(vh, alo, ahi, dh) == VEIL_OK && memcmp(da, dh, sizeof da) == 0,
              "the half-float file's values differ from the float file's");
        veil_vdb_close(vh);
    }
    veil_vdb_grid_info* info = NULL;
    size_t count = 0;
    CHECK(veil_vdb_file_info(b, &info, &count, &err) == VEIL_OK && count == 1 && info &&
              strcmp(info[0].name, "density") == 0 && info[0].active_voxels == 4096 &&
              strcmp(info[0].grid_class, "fog volume") == 0,
          "file info of the .nvdb: %s", err.msg);
    veil_vdb_file_info_free(info, count);
    veil_vdb_close(va);
    veil_vdb_close(vb);
    /* a corrupt .nvdb: an I/O error naming it */
    char c[4200];
    snprintf(c, sizeof c, "%s/garbage.nvdb", g_dir);
    FILE* f = fopen(c, "wb");
    if (f) {
        fputs("not a NanoVDB file at all\n", f);
        fclose(f);
    }
    veil_vdb* vc = NULL;
    veil_result r = veil_vdb_open(c, NULL, 0, &vc, NULL, 0, &err);
    CHECK(r == VEIL_ERR_IO && strstr(err.msg, "garbage.nvdb") && strstr(err.msg, "NanoVDB"), "corrupt .nvdb: %s: %s",
          veil_result_name(r), err.msg);
    veil_vdb_close(vc);
    remove(c);
}

/* The resampling filter by direction (volume/vdb_volume.h), measured: the
 * rotated Gaussian blob (sigma 5 voxels) resampled at its own voxel size
 * (1x) and at half of it (0.5x, enlarging) with what veil does there (the
 * field at each centre, k = 1) and with a box filter of 2^3 samples (what
 * it did before); each result's trilinear field against the VDB's own at
 * 4000 random points in the blob: the relative RMS error. The field is the
 * trilinear interpolation of samples 1 voxel apart; sampling it at the
 * target's centres and interpolating again errs by the curvature over a
 * voxel (~ h^2 f'' / 8), the box filter adds its own blur (variance h^2 /
 * 12 per axis on top), so the point samples must come out closer. Printed,
 * with the 2x (reducing) box filter for scale. */
static void test_filters(void)
{
    veil_vdb* v = open_ok("rotated.vdb", NULL, 0, NULL, 0);
    if (!v) return;
    veil_error err = {0};
    const double ratios[] = {1.0, 0.5};
    for (int ri = 0; ri < 2; ++ri) {
        veil_grid g = grid_around(v, (float)(0.05 * ratios[ri]), 0.21f);
        size_t n = veil_grid_voxels(&g);
        float* point = calloc(n, sizeof *point);
        float* box = calloc(n, sizeof *box);
        double* xyz = malloc(n * 8 * 3 * sizeof *xyz);
        float* s = malloc(n * 8 * sizeof *s);
        if (!point || !box || !xyz || !s) {
            CHECK(0, "out of memory");
            free(point), free(box), free(xyz), free(s);
            break;
        }
        veil_vdb_resample_plan plan;
        CHECK(veil_vdb_plan_resample(v, &g, &plan, &err) == VEIL_OK && plan.k == 1, "%gx: k %d", ratios[ri], plan.k);
        CHECK(veil_vdb_to_grid(v, 1.0f, &g, point, &err) == VEIL_OK, "%s", err.msg);
        /* the box filter by hand: 2^3 sub-cube centres per voxel */
        size_t q = 0;
        for (int k = 0; k < g.dims[2]; ++k)
            for (int j = 0; j < g.dims[1]; ++j)
                for (int i = 0; i < g.dims[0]; ++i)
                    for (int c = 0; c < 8; ++c, ++q) {
                        const int idx[3] = {i, j, k};
                        for (int a = 0; a < 3; ++a)
                            xyz[3 * q + a] = g.origin[a] + (idx[a] + 0.25 + 0.5 * ((c >> a) & 1)) * (double)g.voxel;
                    }
        CHECK(veil_vdb_sample_world(v, xyz, n * 8, s, &err) == VEIL_OK, "%s", err.msg);
        for (size_t i = 0; i < n; ++i) {
            double m = 0.0;
            for (int c = 0; c < 8; ++c) m += s[8 * i + (size_t)c];
            box[i] = (float)(m / 8.0);
        }
        /* both against the VDB's field at random points near the blob's middle */
        const int N = 4000;
        double* pts = malloc((size_t)N * 3 * sizeof *pts);
        float* truth = malloc((size_t)N * sizeof *truth);
        uint32_t seed = 777u;
        float lo[3], hi[3];
        veil_grid_medium_box(&g, lo, hi);
        for (int p = 0; pts && p < N; ++p)
            for (int a = 0; a < 3; ++a) {
                seed = seed * 1664525u + 1013904223u;
                double u = (seed >> 8) / 16777216.0, mid = 0.5 * (lo[a] + hi[a]), half = 0.3 * (hi[a] - lo[a]);
                pts[3 * p + a] = mid + (2.0 * u - 1.0) * half;
            }
        CHECK(pts && truth && veil_vdb_sample_world(v, pts, (size_t)N, truth, &err) == VEIL_OK, "%s", err.msg);
        double e_point = 0.0, e_box = 0.0, sum = 0.0;
        for (int p = 0; pts && truth && p < N; ++p) {
            double a = veil_ev_sample(&g, point, pts + 3 * p), b = veil_ev_sample(&g, box, pts + 3 * p);
            e_point += (a - truth[p]) * (a - truth[p]);
            e_box += (b - truth[p]) * (b - truth[p]);
            sum += (double)truth[p] * truth[p];
        }
        e_point = sqrt(e_point / sum), e_box = sqrt(e_box / sum);
        printf("rotated.vdb %.1fx: the field at the centres %.4f, box filter 2^3 %.4f (relative RMS vs the VDB)\n",
               ratios[ri], e_point, e_box);
        CHECK(e_point < e_box, "%.1fx: point samples %.4f not closer than the box filter %.4f", ratios[ri], e_point,
              e_box);
        free(point), free(box), free(xyz), free(s), free(pts), free(truth);
    }
    veil_vdb_close(v);
}

int main(int argc, char** argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: %s DATA_DIR CASE\n", argv[0]);
        return 2;
    }
    g_dir = argv[1];
    static const struct {
        const char* name;
        void (*fn)(void);
    } cases[] = {{"native", test_native}, {"nanovdb", test_nanovdb}, {"filters", test_filters}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i)
        if (strcmp(argv[2], cases[i].name) == 0) {
            cases[i].fn();
            return check_finish();
        }
    fprintf(stderr, "%s: unknown case '%s'\n", argv[0], argv[2]);
    return 2;
}
