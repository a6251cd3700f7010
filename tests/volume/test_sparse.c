/* The sparse extinction volume (volume/sparse.h) on the files make_test_vdbs
 * writes: sparse_puffs.vdb (28 Gaussian puffs, sigma 3 voxels, over a
 * 4096^3 index box: 6.9e10 voxels, far over the dense cap) and
 * sparse_crop.vdb (three of them, a box that fits densely).
 *
 *   test_sparse DATA_DIR CASE
 *
 * structure (CPU): the automatic choice, the bricks kept, and the CPU twin
 *   of the shaders' lookup equal to the dense field bit for bit.
 * depth (GPU): the optical depth marched through the bricks equals the
 *   exact integral (a sun straight down: see the case).
 * render (GPU): the big file rendered sparse equals the crop rendered dense.
 * emission (CPU, then GPU): emissive_slab.vdb's emission (a heat grid, and
 *   the same read as temperature) sparse equals dense voxel for voxel, its
 *   lights too, and so does the render.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "core/rng.h"
#include "frame/renderer.h"
#include "gpu/gl_context.h"
#include "gpu/gl_util.h"
#include "io/scene.h"
#include "propagate/opv_set.h"
#include "volume/emission_lights.h"
#include "volume/ev.h"
#include "volume/scene_volume.h"
#include "volume/sparse.h"
#include "volume/vdb_volume.h"

static const char* g_dir;

/* The crop's puffs lie within 9 voxels of these index points (make_test_vdbs). */
static const int CROP_LO[3] = {1993 - 10, 2000 - 10, 0}, CROP_HI[3] = {2010 + 10, 2008 + 10, 12 + 10};

/* A scene of one vdb file: the camera 6 m in front of the crop (index
 * (2000, 2004, 11), voxel 0.05 m: world (100, 100.2, 0.55)) looking +z
 * with a 4 degree view, a sun straight down. */
static veil_result scene_of(const char* file, const char* representation, veil_scene* s)
{
    char json[8192];
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [100.03, 100.22, -6], \"look_at\": [100.03, 100.22, 0.55], \"fov_y_deg\": 4,"
             " \"width\": 64, \"height\": 48},"
             " \"medium\": {\"sigma_a\": [2, 2, 2], \"sigma_s\": [6, 8, 10], \"representation\": \"%s\","
             "  \"sources\": [{\"type\": \"vdb\", \"file\": \"%s/%s\"}]},"
             " \"lights\": [{\"type\": \"directional\", \"direction\": [0, -1, 0], \"irradiance\": [3, 3, 3]}],"
             " \"multiple_scattering\": {\"volumetric\": false, \"screen_space\": false}}",
             representation, g_dir, file);
    veil_error err = {0};
    veil_result r = veil_scene_parse("sparse.json", json, strlen(json), s, &err);
    if (r != VEIL_OK) fprintf(stderr, "%s\n", err.msg);
    return r;
}

static veil_result open_volume(const char* file, const char* representation, veil_scene* s, veil_scene_volume* v)
{
    memset(v, 0, sizeof *v);
    veil_result r = scene_of(file, representation, s);
    veil_error err = {0};
    if (r == VEIL_OK) r = veil_scene_volume_open(s, v, &err);
    if (r != VEIL_OK) fprintf(stderr, "%s\n", err.msg);
    return r;
}

/* The dense field's trilinear value at index point q (voxel i's centre at
 * i + 0.5), in the order the sparse twin sums its corners. */
static float dense_sample(const float* d, const int dims[3], const float q[3])
{
    int i0[3];
    float f[3];
    for (int a = 0; a < 3; ++a) {
        float p = q[a] - 0.5f;
        i0[a] = (int)floorf(p);
        f[a] = p - (float)i0[a];
    }
    float sum = 0.0f;
    for (int c = 0; c < 8; ++c) {
        float w = 1.0f;
        int idx[3];
        for (int a = 0; a < 3; ++a) {
            int up = (c >> a) & 1;
            w *= up ? f[a] : 1.0f - f[a];
            idx[a] = i0[a] + up;
        }
        float value = 0.0f;
        if (idx[0] >= 0 && idx[1] >= 0 && idx[2] >= 0 && idx[0] < dims[0] && idx[1] < dims[1] && idx[2] < dims[2])
            value = d[(size_t)idx[0] + (size_t)dims[0] * ((size_t)idx[1] + (size_t)dims[1] * (size_t)idx[2])];
        sum += w * value;
    }
    return sum;
}

/* The grid index of VDB index k on grid g (the file's lattice: index k at
 * k * 0.05 m; grid voxel j's centre at origin + (j + 0.5) voxel). */
static int grid_index(const veil_grid* g, int a, int k)
{
    return (int)lround((double)k - (double)g->origin[a] / g->voxel - 0.5);
}

static void test_structure(void)
{
    veil_scene s, sb;
    veil_scene_volume v, vb;
    veil_error err = {0};
    if (open_volume("sparse_crop.vdb", "sparse", &s, &v) != VEIL_OK) {
        CHECK(0, "opening sparse_crop.vdb as sparse");
        return;
    }
    CHECK(v.sparse == 1, "representation sparse: v.sparse = %d", v.sparse);
    veil_sparse sp;
    CHECK(veil_sparse_build(&v, 2048, &sp, &err) == VEIL_OK, "%s", err.msg);
    /* the same scene dense: the same native grid, every value copied */
    veil_scene sd;
    veil_scene_volume vd;
    float* dense = NULL;
    if (open_volume("sparse_crop.vdb", "dense", &sd, &vd) == VEIL_OK) {
        CHECK(!vd.sparse && !memcmp(&vd.grid, &v.grid, sizeof v.grid), "dense and sparse grids differ");
        CHECK(veil_scene_volume_density(&vd, &dense, &err) == VEIL_OK, "%s", err.msg);
    }
    if (dense && sp.texels) {
        /* every index point and 20000 random points of the box: the twin of the shaders' lookup
         * sums the same 8 values with the same weights (q - 0.5 - 8b is exact in float) */
        const int* d = v.grid.dims;
        long mismatches = 0, unkept_nonzero = 0;
        uint64_t rng = 7;
        for (long n = 0; n < (long)veil_grid_voxels(&v.grid) + 20000; ++n) {
            float q[3];
            if (n < (long)veil_grid_voxels(&v.grid)) {
                q[0] = (float)(n % d[0]) + 0.5f, q[1] = (float)(n / d[0] % d[1]) + 0.5f,
                q[2] = (float)(n / ((long)d[0] * d[1])) + 0.5f;
            } else {
                for (int a = 0; a < 3; ++a) q[a] = 0.5f + (float)(veil_rng_double53(&rng) * (d[a] - 1));
            }
            float want = dense_sample(dense, d, q), got = veil_sparse_sample(&sp, q);
            mismatches += got != want;
            int b[3];
            for (int a = 0; a < 3; ++a) b[a] = (int)floorf((q[a] - 0.5f) / VEIL_BRICK);
            if (!veil_sparse_slot(&sp, b)) unkept_nonzero += want != 0.0f;
        }
        CHECK(mismatches == 0, "%ld points where the sparse lookup differs from the dense field", mismatches);
        CHECK(unkept_nonzero == 0, "%ld points with density in bricks not kept", unkept_nonzero);
        size_t all = (size_t)sp.bricks[0] * (size_t)sp.bricks[1] * (size_t)sp.bricks[2];
        printf("crop: grid %dx%dx%d, %zu of %zu bricks kept, %zu non-zero voxels\n", d[0], d[1], d[2], sp.count, all,
               sp.voxels);
        CHECK(sp.count < all, "every brick kept (%zu)", sp.count);
    }
    free(dense);
    veil_sparse_free(&sp);

    /* the big file: over the dense cap, so sparse by itself, and equal to the crop there */
    if (open_volume("sparse_puffs.vdb", "auto", &sb, &vb) == VEIL_OK) {
        size_t box = veil_grid_voxels(&vb.grid);
        printf("puffs: grid %dx%dx%d (%.3g voxels), %zu active (%.2g of the box): %s\n", vb.grid.dims[0],
               vb.grid.dims[1], vb.grid.dims[2], (double)box, vb.vdb_voxels, (double)vb.vdb_voxels / (double)box,
               vb.resolution);
        CHECK(vb.sparse == 1 && vb.grid.dims[0] >= 4096 && vb.grid.dims[1] >= 4096 && vb.grid.dims[2] >= 4096,
              "the 4096^3 box is not sparse: %s", vb.resolution);
        CHECK((double)vb.vdb_voxels < 0.01 * (double)box, "%zu active voxels: not under 1 %% of the box", vb.vdb_voxels);
        CHECK(strstr(vb.resolution, "sparse: ") && strstr(vb.resolution, "dense cap"), "%s", vb.resolution);
        veil_sparse big, crop;
        CHECK(veil_sparse_build(&vb, 2048, &big, &err) == VEIL_OK, "%s", err.msg);
        CHECK(veil_sparse_build(&v, 2048, &crop, &err) == VEIL_OK, "%s", err.msg);
        long mismatches = 0, checked = 0;
        for (int k = CROP_LO[2]; k <= CROP_HI[2] && big.texels && crop.texels; ++k)
            for (int j = CROP_LO[1]; j <= CROP_HI[1]; ++j)
                for (int i = CROP_LO[0]; i <= CROP_HI[0]; ++i)
                    for (int o = 0; o < 4; ++o) { /* voxel centres and three offsets between them */
                        int vdb[3] = {i, j, k};
                        float qb[3], qc[3];
                        for (int a = 0; a < 3; ++a) {
                            float off = o == 0 ? 0.5f : o == a + 1 ? 0.75f : 0.25f;
                            qb[a] = (float)grid_index(&vb.grid, a, vdb[a]) + off;
                            qc[a] = (float)grid_index(&v.grid, a, vdb[a]) + off;
                        }
                        if (qc[0] < 0.5f || qc[1] < 0.5f || qc[2] < 0.5f) continue;
                        if (qc[0] > v.grid.dims[0] - 0.5f || qc[1] > v.grid.dims[1] - 0.5f || qc[2] > v.grid.dims[2] - 0.5f)
                            continue;
                        mismatches += veil_sparse_sample(&big, qb) != veil_sparse_sample(&crop, qc);
                        ++checked;
                    }
        CHECK(checked > 50000 && mismatches == 0, "%ld of %ld points differ between the big file and its crop",
              mismatches, checked);
        printf("puffs: %zu bricks kept, %.1f MiB (dense: %.0f MiB); crop region equal at %ld points\n", big.count,
               (double)veil_sparse_bytes(&big) / 1048576.0, (double)box * 4 / 1048576.0, checked);
        veil_sparse_free(&big);
        veil_sparse_free(&crop);
        /* the reference path tracer needs a dense copy: refused with the numbers, not attempted */
        float* none = NULL;
        veil_error e2 = {0};
        CHECK(veil_scene_volume_density(&vb, &none, &e2) == VEIL_ERR_LIMIT && strstr(e2.msg, "max_resolution"),
              "a dense copy of the 4096^3 box: %s", e2.msg);
        free(none);
        veil_scene_volume_close(&vb);
        veil_scene_free(&sb);
    } else {
        CHECK(0, "opening sparse_puffs.vdb");
    }
    veil_scene_volume_close(&vd);
    veil_scene_free(&sd);
    veil_scene_volume_close(&v);
    veil_scene_free(&s);
}

/* The optical depth over the big file for a sun straight down (and a
 * point light straight above one column of voxel centres): the path
 * from voxel centre q goes up +y along a line of voxel centres, where the
 * trilinear field is linear between centres; the march's midpoint steps
 * (half a voxel, from q to brick faces that are centre planes too) then
 * integrate it exactly, as does the trapezoid rule over the voxels' values.
 * So they agree up to float rounding:
 * - the sum: each of the n ~ 2 x 40 steps through density adds a value
 *   rounded to 2^-24 of the sum: 1e-4 D asked (n 2^-24 = 5e-6);
 * - each sample's place: its atlas coordinate is normalised and scaled
 *   back by the filter, two roundings of 2^-24 of the atlas side t: the
 *   sample moves by e = 2^-23 t texel at most, so its value by e rho_max
 *   (neighbouring voxels differ by at most the largest density, all >= 0):
 *   2 k e rho_max (h / 2) voxel over the k voxel steps in kept bricks. */
static void test_depth(void)
{
    veil_scene s;
    veil_scene_volume v;
    veil_error err = {0};
    if (open_volume("sparse_puffs.vdb", "auto", &s, &v) != VEIL_OK) {
        CHECK(0, "opening sparse_puffs.vdb");
        return;
    }
    veil_gl* gl = check_gpu_or_skip();
    veil_ev* ev = NULL;
    veil_opv_set* set = NULL;
    veil_sparse sp = {0};
    CHECK(veil_ev_create(&ev, &err) == VEIL_OK, "%s", err.msg);
    CHECK(veil_opv_set_create(&set, &err) == VEIL_OK, "%s", err.msg);
    veil_ev_report rep;
    CHECK(ev && veil_ev_build_scene(ev, &v, 1, veil_gl_get_info(gl)->memory_budget, &rep, &err) == VEIL_OK, "%s",
          err.msg);
    const veil_ev_sparse* esp = ev ? veil_ev_sparse_of(ev) : NULL;
    CHECK(esp != NULL, "the EV is not sparse");
    GLint max3d = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
    CHECK(veil_sparse_build(&v, max3d, &sp, &err) == VEIL_OK, "%s", err.msg);
    if (esp && set && sp.texels) {
        veil_opv_report orep;
        veil_opv_params params = {.method = VEIL_OPV_DEFAULT_METHOD};
        /* light 0: the scene's sun straight down; light 1: a point light 600 voxels above the crop, on
         * the column of voxel centres x = 2000, z = 9, whose paths to it are vertical too */
        veil_light lights[2] = {s.lights[0], {.type = VEIL_LIGHT_POINT, .position = {100.0f, 130.0f, 0.45f},
                                              .color = {1, 1, 1}}};
        int col_x = grid_index(&v.grid, 0, 2000), col_z = grid_index(&v.grid, 2, 9), top = grid_index(&v.grid, 1, 2600);
        CHECK(veil_opv_set_update(set, &v.grid, veil_ev_texture(ev), 0, esp, 1, lights, 2, &params, &orep, &err) ==
                  VEIL_OK, "%s", err.msg);
        int t[3];
        veil_sparse_atlas_texels(&sp, t);
        size_t n = (size_t)t[0] * (size_t)t[1] * (size_t)t[2];
        float* D = malloc(n * 4 * sizeof *D);
        CHECK(D && veil_gl_read_texture(veil_opv_set_texture(set, 0), GL_RGBA, n * 4, D, "OD", &err) == VEIL_OK, "%s",
              err.msg);
        long bad = 0, checked = 0, columns = 0;
        double worst = 0, rho_max = 0;
        for (size_t i = 0; i < n; ++i) rho_max = fmax(rho_max, sp.texels[i]);
        int side = t[0] > t[1] ? (t[0] > t[2] ? t[0] : t[2]) : (t[1] > t[2] ? t[1] : t[2]);
        double place = ldexp((double)side, -23) * rho_max; /* a sample's value moved by its place's rounding */
        for (size_t slot = 0; slot < sp.count && D; ++slot) {
            const int32_t* b = sp.coords + 4 * slot;
            /* the crop's bricks: their paths up cross the empty nodes above to the top of the box */
            int vdb_lo = grid_index(&v.grid, 0, CROP_LO[0]), vdb_hi = grid_index(&v.grid, 0, CROP_HI[0]);
            if (b[0] * VEIL_BRICK + 8 < vdb_lo || b[0] * VEIL_BRICK > vdb_hi) continue;
            int corner[3] = {(int)(slot % (size_t)sp.atlas[0]) * VEIL_SPARSE_APRON,
                             (int)(slot / (size_t)sp.atlas[0] % (size_t)sp.atlas[1]) * VEIL_SPARSE_APRON,
                             (int)(slot / ((size_t)sp.atlas[0] * (size_t)sp.atlas[1])) * VEIL_SPARSE_APRON};
            for (int z = 0; z < VEIL_SPARSE_APRON; ++z)
                for (int y = 0; y < VEIL_SPARSE_APRON; ++y)
                    for (int x = 0; x < VEIL_SPARSE_APRON; ++x) {
                        int vox[3] = {b[0] * VEIL_BRICK + x, b[1] * VEIL_BRICK + y, b[2] * VEIL_BRICK + z};
                        if (vox[0] >= v.grid.dims[0] || vox[1] >= v.grid.dims[1] || vox[2] >= v.grid.dims[2]) continue;
                        /* trapezoid over the voxels above, to the last centre of the box (the sun)
                         * or to the point light (its column) */
                        int column = vox[0] == col_x && vox[2] == col_z;
                        for (int light = 0; light < 1 + column; ++light) {
                        int end = light ? top : v.grid.dims[1] - 1;
                        double want = 0.0;
                        int kept = 0;
                        for (int yy = vox[1]; yy + 1 <= end; ++yy) {
                            int bb[3] = {vox[0] / VEIL_BRICK, yy / VEIL_BRICK, vox[2] / VEIL_BRICK};
                            int bn[3] = {vox[0] / VEIL_BRICK, (yy + 1) / VEIL_BRICK, vox[2] / VEIL_BRICK};
                            if (!veil_sparse_slot(&sp, bb) && !veil_sparse_slot(&sp, bn)) {
                                yy = (yy / VEIL_BRICK + 1) * VEIL_BRICK - 1; /* an empty brick: to its top */
                                continue;
                            }
                            ++kept;
                            float q0[3] = {vox[0] + 0.5f, yy + 0.5f, vox[2] + 0.5f}, q1[3] = {q0[0], yy + 1.5f, q0[2]};
                            want += 0.5 * ((double)veil_sparse_sample(&sp, q0) + veil_sparse_sample(&sp, q1));
                        }
                        want *= v.grid.voxel;
                        double got = D[4 * ((size_t)(corner[0] + x) +
                                            (size_t)t[0] * ((size_t)(corner[1] + y) + (size_t)t[1] * (size_t)(corner[2] + z))) +
                                       (size_t)light];
                        double e = fabs(got - want);
                        double tol = 1e-4 * want + 2.0 * kept * place * 0.5 * v.grid.voxel;
                        worst = fmax(worst, e / tol);
                        if (!(e <= tol) && bad < 10)
                            printf("voxel %d %d %d (local %d %d %d): marched %.6g, exact %.6g\n", vox[0], vox[1], vox[2], x,
                                   y, z, got, want);
                        bad += !(e <= tol);
                        ++checked;
                        columns += light;
                        }
                    }
        }
        /* the passes the frame's work estimate counts (veil_opv_sparse_passes) are the passes made: the
         * lights as the update makes them (no light-space grids over a sparse volume) */
        veil_index_light ol[VEIL_MAX_LIGHTS];
        veil_opv_sun want[VEIL_MAX_SUNS];
        uint64_t want_key[VEIL_MAX_SUNS];
        veil_opv_plan_suns(&v.grid, 1, lights, 2, &params, 0, ol, want, want_key);
        size_t passes = 0;
        for (int l = 0; l < 2; ++l) {
            size_t p = veil_opv_sparse_passes(esp->bricks, esp->slots, &ol[l]);
            passes = p > passes ? p : passes;
        }
        CHECK(passes > 1 && passes == (size_t)orep.iterations, "the estimate counts %zu passes, the update made %d",
              passes, orep.iterations);
        CHECK(checked > 10000 && columns >= 18 && bad == 0,
              "%ld of %ld optical depths off the exact integral (worst %.3g of the bound; %ld on the point light's column)",
              bad, checked, worst, columns);
        printf("optical depth: %ld texels of the crop's bricks (%ld for the point light), worst error %.3g of the bound\n",
               checked, columns, worst);
        free(D);
    }
    veil_sparse_free(&sp);
    veil_opv_set_destroy(set);
    veil_ev_destroy(ev);
    veil_gl_destroy(gl);
    veil_scene_volume_close(&v);
    veil_scene_free(&s);
}

/* The big file rendered sparse (automatically) against its crop rendered
 * dense, single scattering under the sun straight down, without skipping
 * (each ray's steps then start on the same plane: both boxes begin on the
 * crop's lowest k, which the camera faces, and end at the same distance),
 * so both march the same sample points. What differs: each sample's
 * density (the same 8 voxel values; the atlas coordinates round
 * differently from the dense texture's, by at most 2^-24 of the atlas side
 * 9 x 2048 = 1.1e-3 texel: 1.1e-3 of a voxel-to-voxel difference, which is
 * at most 0.2 of the peak for a sigma of 3 voxels: 2.2e-4 of the peak per
 * sample) and the optical depths (exact in both up to rounding: test_depth
 * and the semi-Lagrangian scheme along an axis). Over a ray through the
 * crop (~40 non-zero samples of half a voxel, sigma_t <= 12 m^-1 times
 * 0.025 m) the optical thickness moves by at most 40 x 2.2e-4 x 0.3 =
 * 2.6e-3 and so T and L by at most 0.3 %: asked, 0.3 % of the brightest
 * pixel for L and 3e-3 for alpha. The pixels at the crop box's sides (rays
 * that enter it through a side, not the front) start their steps elsewhere
 * and are left out: 2 pixels of border. */
static void test_render(void)
{
    veil_scene sc, sb;
    if (scene_of("sparse_crop.vdb", "dense", &sc) != VEIL_OK || scene_of("sparse_puffs.vdb", "auto", &sb) != VEIL_OK) {
        CHECK(0, "scenes");
        return;
    }
    veil_gl* gl = check_gpu_or_skip();
    veil_error err = {0};
    veil_renderer* r = NULL;
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    veil_image_set a = {0}, b = {0};
    veil_render_stats st = {0};
    /* the dense render's optical depth by the semi-Lagrangian pass, exact along an axis as assumed above
     * (the light-space grids' last stretch is a midpoint rule: test_sun_space measures it) */
    veil_render_opts o = {.seed = 5, .no_skip = 1, .max_distance = 7.3f, .method = VEIL_OPV_SEMI_LAGRANGIAN};
    CHECK(r && veil_render_scene_images(r, &sc, &o, &a, NULL, &err) == VEIL_OK, "%s", err.msg);
    CHECK(r && veil_render_scene_images(r, &sb, &o, &b, &st, &err) == VEIL_OK, "%s", err.msg);
    CHECK(strstr(st.stage[VEIL_STAGE_INJECT].why, "sparse: ") && strstr(st.stage[VEIL_STAGE_INJECT].why, "bricks kept"),
          "inject: %s", st.stage[VEIL_STAGE_INJECT].why);
    printf("inject: %s\n", st.stage[VEIL_STAGE_INJECT].why);
    if (a.rgba && b.rgba) {
        int w = a.width, h = a.height;
        double peak = 0, worst = 0, worst_a = 0, sum = 0;
        for (int i = 0; i < w * h * 4; ++i) peak = fmax(peak, (i & 3) == 3 ? 0 : a.rgba[i]);
        for (int y = 2; y < h - 2; ++y)
            for (int x = 2; x < w - 2; ++x)
                for (int c = 0; c < 4; ++c) {
                    size_t i = 4 * ((size_t)y * (size_t)w + (size_t)x) + (size_t)c;
                    double e = fabs((double)a.rgba[i] - b.rgba[i]);
                    if (c == 3) worst_a = fmax(worst_a, e);
                    else worst = fmax(worst, e), sum += a.rgba[i];
                }
        printf("sparse vs dense: peak %.4g, worst |dL| %.3g (%.2g of the peak), worst |dalpha| %.3g\n", peak, worst,
               worst / peak, worst_a);
        CHECK(peak > 0.01 && sum > 0, "the crop is not in view (peak %.3g)", peak);
        CHECK(worst <= 3e-3 * peak, "sparse and dense differ by %.3g (peak %.3g)", worst, peak);
        CHECK(worst_a <= 3e-3, "alpha differs by %.3g", worst_a);
    }
    veil_image_set_free(&a);
    veil_image_set_free(&b);
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
    veil_scene_free(&sc);
    veil_scene_free(&sb);
}

/* A scene of emissive_slab.vdb ("density" and "heat" 1 on a 20 x 20 x 10
 * box of 0.1 m voxels) seen from above, its heat as `kind` ("emission" or
 * "temperature"), lit by a sun straight down. */
static veil_result slab_scene(const char* kind, const char* representation, int lights, veil_scene* s)
{
    char json[8192];
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0.95, 0.95, 6], \"look_at\": [0.95, 0.95, 0], \"fov_y_deg\": 22,"
             " \"width\": 48, \"height\": 48},"
             " \"medium\": {\"sigma_a\": [0.5, 1, 2], \"sigma_s\": [2, 2, 2], \"representation\": \"%s\","
             "  \"sources\": [{\"type\": \"vdb\", \"file\": \"%s/emissive_slab.vdb\","
             "   \"%s\": {\"grid\": \"heat\", \"scale\": %s}}]},"
             " \"lights\": [{\"type\": \"directional\", \"direction\": [0, -1, 0], \"irradiance\": [1, 1, 1]}],"
             " \"multiple_scattering\": {\"volumetric\": false, \"screen_space\": false, \"emission_lights\": %d}}",
             representation, g_dir, kind, strcmp(kind, "temperature") ? "2" : "1500", lights);
    veil_error err = {0};
    veil_result r = veil_scene_parse("slab.json", json, strlen(json), s, &err);
    if (r != VEIL_OK) fprintf(stderr, "%s\n", err.msg);
    return r;
}

/* Sparse emission against dense: the same voxels' eps (the copy and the
 * formula are the same: bit for bit), the same lights (the clusters do not
 * depend on the order the voxels come in: to float rounding of the sums,
 * 1e-6), and the same image (every sample point the same: the camera faces
 * the box's top, no skipping; the sun's optical depth exact in both along
 * its axis, the emission's lights left out here since their optical depth
 * is not along an axis): 1e-4 of the brightest pixel, as test_render's
 * rounding bound with emission's one more texture read per sample. */
static void test_emission(void)
{
    static const char* const kinds[2] = {"emission", "temperature"};
    for (int k = 0; k < 2; ++k) {
        veil_scene ss, sd;
        veil_scene_volume vs, vd;
        veil_error err = {0};
        memset(&vs, 0, sizeof vs);
        memset(&vd, 0, sizeof vd);
        if (slab_scene(kinds[k], "sparse", 8, &ss) != VEIL_OK || slab_scene(kinds[k], "dense", 8, &sd) != VEIL_OK ||
            veil_scene_volume_open(&ss, &vs, &err) != VEIL_OK || veil_scene_volume_open(&sd, &vd, &err) != VEIL_OK) {
            CHECK(0, "%s: %s", kinds[k], err.msg);
            return;
        }
        CHECK(vs.sparse && !vd.sparse && !memcmp(&vs.grid, &vd.grid, sizeof vs.grid), "%s: grids", kinds[k]);
        veil_sparse sp;
        float* rgba = NULL;
        CHECK(veil_sparse_build(&vs, 2048, &sp, &err) == VEIL_OK, "%s", err.msg);
        CHECK(veil_scene_volume_emission(&vd, &rgba, &err) == VEIL_OK && rgba, "%s", err.msg);
        long differ = 0, emitting = 0;
        const int* d = vd.grid.dims;
        for (int z = 0; z < d[2] && rgba && sp.emission_texels; ++z)
            for (int y = 0; y < d[1]; ++y)
                for (int x = 0; x < d[0]; ++x) {
                    const float* want = rgba + 4 * ((size_t)x + (size_t)d[0] * ((size_t)y + (size_t)d[1] * (size_t)z));
                    int b[3] = {x / VEIL_BRICK, y / VEIL_BRICK, z / VEIL_BRICK};
                    uint32_t slot = veil_sparse_slot(&sp, b);
                    float got[3] = {0, 0, 0};
                    if (slot) {
                        int t[3];
                        veil_sparse_atlas_texels(&sp, t);
                        size_t s = slot - 1;
                        int c[3] = {(int)(s % (size_t)sp.atlas[0]) * VEIL_SPARSE_APRON + x % VEIL_BRICK,
                                    (int)(s / (size_t)sp.atlas[0] % (size_t)sp.atlas[1]) * VEIL_SPARSE_APRON + y % VEIL_BRICK,
                                    (int)(s / ((size_t)sp.atlas[0] * (size_t)sp.atlas[1])) * VEIL_SPARSE_APRON + z % VEIL_BRICK};
                        memcpy(got, sp.emission_texels + 4 * ((size_t)c[0] + (size_t)t[0] * ((size_t)c[1] + (size_t)t[1] * (size_t)c[2])),
                               sizeof got);
                    }
                    differ += got[0] != want[0] || got[1] != want[1] || got[2] != want[2];
                    emitting += want[0] > 0.0f;
                }
        CHECK(differ == 0 && emitting == 4000, "%s: %ld voxels' emission differ (%ld emitting, 4000 expected)", kinds[k],
              differ, emitting);
        CHECK(sp.emitter_count == 4000, "%s: %zu emitters", kinds[k], sp.emitter_count);
        /* the lights */
        veil_light ld[VEIL_MAX_LIGHTS], ls[VEIL_MAX_LIGHTS];
        int nd = 0, ns = 0;
        CHECK(veil_emission_lights(&vd.grid, rgba, 8, ld, &nd, &err) == VEIL_OK, "%s", err.msg);
        CHECK(veil_emission_lights_points(sp.emitters, sp.emitter_count, sp.grid.voxel, 8, ls, &ns, &err) == VEIL_OK,
              "%s", err.msg);
        CHECK(nd == 8 && ns == 8, "%s: %d and %d lights", kinds[k], nd, ns);
        for (int i = 0; i < nd && i < ns; ++i)
            for (int a = 0; a < 3; ++a) {
                CHECK(fabsf(ld[i].position[a] - ls[i].position[a]) <= 1e-6f * (1.0f + fabsf(ld[i].position[a])),
                      "%s: light %d position %g vs %g", kinds[k], i, ls[i].position[a], ld[i].position[a]);
                CHECK(fabsf(ld[i].color[a] - ls[i].color[a]) <= 1e-6f * ld[i].color[a], "%s: light %d power %g vs %g",
                      kinds[k], i, ls[i].color[a], ld[i].color[a]);
            }
        free(rgba);
        veil_sparse_free(&sp);
        veil_scene_volume_close(&vs);
        veil_scene_volume_close(&vd);
        veil_scene_free(&ss);
        veil_scene_free(&sd);
    }
    /* the render */
    veil_gl* gl = check_gpu_or_skip();
    veil_renderer* r = NULL;
    veil_error err = {0};
    CHECK(veil_renderer_create(gl, &r, &err) == VEIL_OK, "%s", err.msg);
    for (int k = 0; k < 2 && r; ++k) {
        veil_scene ss, sd;
        veil_image_set a = {0}, b = {0};
        veil_render_stats st = {0};
        veil_render_opts o = {.seed = 2, .no_skip = 1, .method = VEIL_OPV_SEMI_LAGRANGIAN}; /* as test_render */
        if (slab_scene(kinds[k], "sparse", 0, &ss) != VEIL_OK || slab_scene(kinds[k], "dense", 0, &sd) != VEIL_OK) {
            CHECK(0, "scenes");
            break;
        }
        CHECK(veil_render_scene_images(r, &sd, &o, &a, NULL, &err) == VEIL_OK, "%s", err.msg);
        CHECK(veil_render_scene_images(r, &ss, &o, &b, &st, &err) == VEIL_OK, "%s", err.msg);
        CHECK(strstr(st.stage[VEIL_STAGE_INJECT].why, "sparse: "), "%s", st.stage[VEIL_STAGE_INJECT].why);
        if (a.rgba && b.rgba) {
            double peak = 0, worst = 0;
            for (int i = 0; i < a.width * a.height * 4; ++i)
                if ((i & 3) != 3) peak = fmax(peak, a.rgba[i]), worst = fmax(worst, fabs((double)a.rgba[i] - b.rgba[i]));
            printf("%s: sparse vs dense, peak %.4g, worst %.3g (%.2g of the peak)\n", kinds[k], peak, worst, worst / peak);
            CHECK(peak > 0.1 && worst <= 1e-4 * peak, "%s: sparse and dense differ by %.3g (peak %.3g)", kinds[k], worst,
                  peak);
        }
        veil_image_set_free(&a);
        veil_image_set_free(&b);
        veil_scene_free(&ss);
        veil_scene_free(&sd);
    }
    veil_renderer_destroy(r);
    veil_gl_destroy(gl);
}

/* Whether brick b is among the census's (its coordinates sorted by sort_coords). */
static int cmp_brick(const void* a, const void* b)
{
    const int32_t *x = a, *y = b;
    for (int k = 2; k >= 0; --k)
        if (x[k] != y[k]) return x[k] < y[k] ? -1 : 1;
    return 0;
}

/* The census (volume/sparse.h) of v against the volume veil_sparse_build
 * makes of it: every brick the gather made (one whose own 8^3 voxels hold
 * a value not 0: the dilation's own are 0 there) is counted, and the
 * census counts at most the bricks its boxes cover. Returns the built count. */
static size_t census_covers(const char* what, const veil_scene_volume* v, veil_sparse_census* c)
{
    veil_error err = {0};
    veil_sparse sp;
    CHECK(veil_sparse_census_of(v, c, &err) == VEIL_OK && !c->over, "%s: census: %s", what, err.msg);
    CHECK(veil_sparse_build(v, 2048, &sp, &err) == VEIL_OK, "%s: %s", what, err.msg);
    if (!c->coords || !sp.texels) return 0;
    qsort(c->coords, c->count, 4 * sizeof *c->coords, cmp_brick);
    size_t made = 0, missing = 0;
    int t[3];
    veil_sparse_atlas_texels(&sp, t);
    for (size_t slot = 0; slot < sp.count; ++slot) {
        int corner[3] = {(int)(slot % (size_t)sp.atlas[0]) * VEIL_SPARSE_APRON,
                         (int)(slot / (size_t)sp.atlas[0] % (size_t)sp.atlas[1]) * VEIL_SPARSE_APRON,
                         (int)(slot / ((size_t)sp.atlas[0] * (size_t)sp.atlas[1])) * VEIL_SPARSE_APRON};
        int own = 0; /* density or emission in its own 8^3 voxels */
        for (int z = 0; z < VEIL_BRICK && !own; ++z)
            for (int y = 0; y < VEIL_BRICK; ++y)
                for (int x = 0; x < VEIL_BRICK; ++x) {
                    size_t at = (size_t)(corner[0] + x) +
                                (size_t)t[0] * ((size_t)(corner[1] + y) + (size_t)t[1] * (size_t)(corner[2] + z));
                    own |= sp.texels[at] != 0.0f;
                    for (int k = 0; k < 3 && sp.emission_texels; ++k) own |= sp.emission_texels[4 * at + (size_t)k] != 0.0f;
                }
        made += own;
        int32_t key[4] = {sp.coords[4 * slot], sp.coords[4 * slot + 1], sp.coords[4 * slot + 2], 0};
        missing += own && !bsearch(key, c->coords, c->count, 4 * sizeof *c->coords, cmp_brick);
    }
    CHECK(made > 0 && missing == 0, "%s: %zu of the %zu bricks the gather made are not in the census", what, missing,
          made);
    CHECK((double)c->count == c->bricks, "%s: census of %zu distinct bricks reports %.0f", what, c->count, c->bricks);
    printf("%s: census %zu bricks (%llu leaves of %llu voxels, %llu tiles of %.0f voxels); the gather made %zu, "
           "kept %zu\n", what, c->count, (unsigned long long)c->leaves, (unsigned long long)c->leaf_voxels,
           (unsigned long long)c->tiles, c->tile_voxels, made, sp.count);
    size_t kept = sp.count;
    veil_sparse_free(&sp);
    return kept;
}

/* The census before the gather (volume/sparse.h): the puffs' leaves, the
 * slab's emission grid, and (tiles_dir: make_sparse_vdbs's files) a 128^3
 * tile counted by its box, equal to what the gather makes of it, and a
 * 4096^3 one refused from its count. */
static void test_census(void)
{
    veil_scene s;
    veil_scene_volume v;
    veil_sparse_census c;
    if (open_volume("sparse_puffs.vdb", "auto", &s, &v) == VEIL_OK) {
        census_covers("puffs", &v, &c);
        CHECK(c.tiles == 0 && c.leaf_voxels == v.vdb_voxels, "puffs: %llu tiles, %llu of %zu voxels",
              (unsigned long long)c.tiles, (unsigned long long)c.leaf_voxels, v.vdb_voxels);
        veil_sparse_census_free(&c);
        veil_scene_volume_close(&v);
        veil_scene_free(&s);
    } else {
        CHECK(0, "opening sparse_puffs.vdb");
    }
    if (slab_scene("emission", "sparse", 0, &s) == VEIL_OK) {
        veil_error err = {0};
        CHECK(veil_scene_volume_open(&s, &v, &err) == VEIL_OK, "%s", err.msg);
        if (v.sparse) census_covers("emissive slab", &v, &c);
        CHECK(v.sparse && c.leaves > 0, "the slab is not sparse, or its census is empty");
        veil_sparse_census_free(&c);
        veil_scene_volume_close(&v);
        veil_scene_free(&s);
    }
    /* a 128^3 tile: counted by its box, equal to the gather's; a 4096^3 one: over the cap, never expanded */
    if (open_volume("sparse/tile_128.vdb", "sparse", &s, &v) == VEIL_OK) {
        size_t kept = census_covers("128^3 tile", &v, &c);
        int lo[3], hi[3], off[3];
        size_t active = 0;
        veil_vdb_index_bbox(v.vdbs[0], lo, hi, &active);
        double edge, origin[3], want = 1.0;
        int al;
        veil_vdb_lattice(v.vdbs[0], &edge, origin, &al);
        for (int a = 0; a < 3; ++a) { /* VDB index i at grid voxel i + off (the grid's voxel centres on the lattice) */
            off[a] = (int)lround((origin[a] - v.grid.origin[a]) / v.grid.voxel - 0.5);
            want *= (double)((hi[a] + off[a]) / VEIL_BRICK - (lo[a] + off[a]) / VEIL_BRICK + 1);
        }
        CHECK(c.tiles == 1 && c.leaves == 0 && c.tile_voxels == 128.0 * 128 * 128 && (double)c.count == want &&
                  kept == c.count,
              "128^3 tile: %llu tiles of %.0f voxels, %zu bricks counted, %.0f covered, %zu kept",
              (unsigned long long)c.tiles, c.tile_voxels, c.count, want, kept);
        veil_sparse_census_free(&c);
        veil_scene_volume_close(&v);
        veil_scene_free(&s);
    } else {
        CHECK(0, "opening sparse/tile_128.vdb");
    }
    if (open_volume("sparse/tile_4096.vdb", "auto", &s, &v) == VEIL_OK) {
        veil_error err = {0};
        CHECK(veil_sparse_census_of(&v, &c, &err) == VEIL_OK, "%s", err.msg);
        CHECK(c.over && c.bricks >= 512.0 * 512 * 512 && !c.coords && c.tiles == 1,
              "4096^3 tile: over %d, %.0f bricks, %llu tiles", c.over, c.bricks, (unsigned long long)c.tiles);
        CHECK(veil_sparse_census_check(&c, &err) == VEIL_ERR_LIMIT && strstr(err.msg, "1 active tiles") &&
                  strstr(err.msg, "VEIL_SPARSE_MAX_BRICKS"),
              "4096^3 tile refused: %s", err.msg);
        veil_sparse sp;
        veil_error e2 = {0};
        CHECK(veil_sparse_build(&v, 2048, &sp, &e2) == VEIL_ERR_LIMIT && strstr(e2.msg, "1 active tiles"),
              "4096^3 tile built: %s", e2.msg);
        veil_sparse_census_free(&c);
        veil_scene_volume_close(&v);
        veil_scene_free(&s);
    } else {
        CHECK(0, "opening sparse/tile_4096.vdb");
    }
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
    } cases[] = {{"structure", test_structure}, {"depth", test_depth}, {"render", test_render}, {"emission", test_emission},
                   {"census", test_census}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i)
        if (strcmp(argv[2], cases[i].name) == 0) {
            cases[i].fn();
            return check_finish();
        }
    fprintf(stderr, "%s: unknown case '%s'\n", argv[0], argv[2]);
    return 2;
}
