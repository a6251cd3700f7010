/* The public API (include/veil.h), used as a consumer would, on the scene
 * given as argv[1] (the demo scene):
 *  - NULL in any pointer argument is VEIL_ERR_INVALID naming it, or a
 *    no-op for the destroy/close calls and the getters, never a crash;
 *  - bad descriptions (negative size, non-finite step, frame outside the
 *    turntable) are VEIL_ERR_INVALID; an unknown channel's message lists
 *    the channels;
 *  - a render's size, pixels, channels and stage reports agree; frame 0 of
 *    a turntable is the scene's camera, bit for bit; the next frame of the
 *    same context reuses the inject and propagate stages;
 *  - the EXR and PNG writers write, and fail without leaving a file.
 * Exit 77 (skipped) when no GL context can be made, except under CI=true. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "support/check.h"
#include "include/veil.h"
#include "support/temp_files.h"

static void null_arguments(void)
{
    veil_error err = {{0}};
    veil_scene* scene = (veil_scene*)&err; /* must be reset to NULL */
    CHECK(veil_scene_open(NULL, &scene, &err) == VEIL_ERR_INVALID && scene == NULL, "open(NULL path)");
    CHECK(strstr(err.msg, "path") != NULL, "message names the argument: %s", err.msg);
    CHECK(veil_scene_open("x.json", NULL, NULL) == VEIL_ERR_INVALID, "open(NULL out)");
    CHECK(veil_scene_open("/no/such/scene.json", &scene, &err) == VEIL_ERR_IO && scene == NULL, "missing file: %s",
          err.msg);
    veil_image* img = (veil_image*)&err;
    CHECK(veil_render(NULL, NULL, NULL, &img, &err) == VEIL_ERR_INVALID && img == NULL, "render(NULL ctx)");
    CHECK(veil_render(NULL, NULL, NULL, NULL, NULL) == VEIL_ERR_INVALID, "render(NULL out)");
    CHECK(veil_context_create(NULL, NULL, &err) == VEIL_ERR_INVALID, "context_create(NULL out)");
    int w = -1, h = -1;
    veil_image_size(NULL, &w, &h);
    veil_image_size(NULL, NULL, NULL);
    CHECK(w == 0 && h == 0, "size of NULL: %dx%d", w, h);
    CHECK(veil_image_rgba(NULL) == NULL, "rgba of NULL");
    float px = 0.0f;
    CHECK(veil_image_channel(NULL, "R", &px, &err) == VEIL_ERR_INVALID, "channel(NULL image)");
    CHECK(veil_image_write_exr(NULL, "x.exr", 0, &err) == VEIL_ERR_INVALID, "write_exr(NULL image)");
    CHECK(veil_image_write_png(NULL, "x.png", 0.0f, &err) == VEIL_ERR_INVALID, "write_png(NULL image)");
    CHECK(veil_image_stage_count(NULL) == 0, "stage count of NULL");
    CHECK(veil_image_stage(NULL, 0, NULL, NULL, NULL, NULL) == VEIL_ERR_INVALID, "stage(NULL image)");
    veil_context_destroy(NULL);
    veil_scene_close(NULL);
    veil_image_destroy(NULL);
    CHECK(veil_version() && strcmp(veil_version(), VEIL_VERSION) == 0, "version %s", veil_version());
    CHECK(strcmp(veil_result_name(VEIL_ERR_GPU), "VEIL_ERR_GPU") == 0, "result name");
}

/* veil_scene_from_json: a scene from text, its relative particle file
 * found through base_dir (with or without a trailing slash), and not
 * without it; errors start with the name given and name the field. Runs in
 * the test's temporary folder (g_dir). */
static void from_json(void)
{
    veil_error err = {{0}};
    char particles[256];
    path_in(particles, sizeof particles, "puffs.json");
    FILE* f = fopen(particles, "w");
    CHECK(f != NULL, "cannot write %s", particles);
    if (!f) return;
    fputs("{\"format\": \"veil-particles\", \"version\": 1, \"particles\": [\n"
          "  {\"center\": [0, 0, 0], \"amplitude\": 1, \"sharpness\": 4}]}\n", f);
    fclose(f);
    const char* json = "{\"camera\": {\"position\": [0, 0, 3], \"look_at\": [0, 0, 0]},"
                       " \"medium\": {\"sigma_a\": [0.1, 0.1, 0.1], \"sigma_s\": [1, 1, 1],"
                       " \"sources\": [{\"type\": \"rbf\", \"file\": \"puffs.json\"}]},"
                       " \"lights\": [{\"type\": \"directional\", \"direction\": [0, -1, 0], \"irradiance\": [1, 1, 1]}]}";
    veil_scene* s = (veil_scene*)&err;
    char slash[80];
    snprintf(slash, sizeof slash, "%s/", g_dir);
    CHECK(veil_scene_from_json(json, g_dir, "shot", &s, &err) == VEIL_OK && s, "base_dir %s: %s", g_dir, err.msg);
    veil_scene_close(s);
    s = NULL;
    CHECK(veil_scene_from_json(json, slash, NULL, &s, &err) == VEIL_OK && s, "base_dir %s: %s", slash, err.msg);
    veil_scene_close(s);
    s = (veil_scene*)&err;
    /* without the folder the file is looked for in the current one: not there */
    CHECK(veil_scene_from_json(json, NULL, "shot", &s, &err) == VEIL_ERR_INVALID && s == NULL &&
              strncmp(err.msg, "shot:", 5) == 0 && strstr(err.msg, "medium.sources[0].file") &&
              strstr(err.msg, "puffs.json"),
          "no base_dir: %s", err.msg);
    CHECK(veil_scene_from_json("{\"camera\": ", g_dir, NULL, &s, &err) == VEIL_ERR_PARSE && s == NULL &&
              strncmp(err.msg, "<json>", 6) == 0,
          "bad JSON: %s", err.msg);
    CHECK(veil_scene_from_json(NULL, g_dir, NULL, &s, &err) == VEIL_ERR_INVALID && s == NULL && strstr(err.msg, "json"),
          "NULL json: %s", err.msg);
    CHECK(veil_scene_from_json(json, g_dir, NULL, NULL, &err) == VEIL_ERR_INVALID, "NULL out");
    remove(particles);
}

static veil_context* context_or_skip(void)
{
    veil_context* ctx = NULL;
    veil_error err = {{0}};
    veil_result r = veil_context_create(NULL, &ctx, &err);
    if (r == VEIL_OK) return ctx;
    if (r != VEIL_ERR_GPU) {
        fprintf(stderr, "FAIL: veil_context_create: %s: %s\n", veil_result_name(r), err.msg);
        exit(1);
    }
    const char* ci = getenv("CI");
    if (ci && strcmp(ci, "true") == 0) {
        fprintf(stderr, "FAIL: no GL 4.5 context under CI: %s\n", err.msg);
        exit(1);
    }
    fprintf(stderr, "SKIPPED: no GL 4.5 context: %s\n", err.msg);
    exit(77);
}

static void bad_descriptions(veil_context* ctx, const veil_scene* scene)
{
    const veil_render_desc bad[] = {
        {.width = -1},
        {.height = 16385},
        {.step_voxels = -0.5f},
        {.step_voxels = NAN},
        {.frames = -2},
        {.frame = 1},
        {.frame = 4, .frames = 4},
        {.frame = -1, .frames = 4},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        veil_error err = {{0}};
        veil_image* img = NULL;
        CHECK(veil_render(ctx, scene, &bad[i], &img, &err) == VEIL_ERR_INVALID && img == NULL, "bad desc %zu", i);
        CHECK(strncmp(err.msg, "veil_render: ", 13) == 0, "bad desc %zu message: %s", i, err.msg);
    }
    veil_error err = {{0}};
    veil_image* img = NULL;
    CHECK(veil_render(ctx, NULL, NULL, &img, &err) == VEIL_ERR_INVALID && strstr(err.msg, "scene"), "NULL scene");
}

static int same_pixels(const veil_image* a, const veil_image* b)
{
    int wa, ha, wb, hb;
    veil_image_size(a, &wa, &ha);
    veil_image_size(b, &wb, &hb);
    return wa == wb && ha == hb && memcmp(veil_image_rgba(a), veil_image_rgba(b), (size_t)wa * ha * 4 * sizeof(float)) == 0;
}

static void render_and_read(veil_context* ctx, const veil_scene* scene)
{
    veil_error err = {{0}};
    veil_image *img = NULL, *frame0 = NULL, *frame1 = NULL;
    veil_render_desc desc = {.width = 40, .height = 30, .seed = 7};
    CHECK(veil_render(ctx, scene, &desc, &img, &err) == VEIL_OK && img, "render: %s", err.msg);
    if (!img) return;

    int w = 0, h = 0;
    veil_image_size(img, &w, &h);
    CHECK(w == 40 && h == 30, "size %dx%d", w, h);
    const float* rgba = veil_image_rgba(img);
    int finite = 1, lit = 0;
    for (int i = 0; i < w * h * 4; ++i) {
        finite &= isfinite(rgba[i]) != 0;
        lit |= rgba[i] > 0.0f;
    }
    CHECK(finite && lit, "pixels finite (%d) and not all black (%d)", finite, lit);

    float* plane = malloc((size_t)w * h * sizeof(float));
    CHECK(veil_image_channel(img, "A", plane, &err) == VEIL_OK, "channel A: %s", err.msg);
    int alpha_same = 1;
    for (int i = 0; i < w * h; ++i) alpha_same &= memcmp(&plane[i], &rgba[4 * i + 3], sizeof(float)) == 0;
    CHECK(alpha_same, "channel A is the rgba's alpha");
    CHECK(veil_image_channel(img, "depth", plane, &err) == VEIL_OK, "channel depth: %s", err.msg);
    CHECK(veil_image_channel(img, "Z", plane, &err) == VEIL_OK, "channel Z: %s", err.msg);
    CHECK(veil_image_channel(img, "z", plane, &err) == VEIL_ERR_INVALID, "channel z (names are case-sensitive)");
    CHECK(strstr(err.msg, "'z'") && strstr(err.msg, "single.R") && strstr(err.msg, "depth") && strstr(err.msg, "Z"),
          "message names the channel and lists the valid ones: %s", err.msg);
    CHECK(veil_image_channel(img, NULL, plane, &err) == VEIL_ERR_INVALID, "channel(NULL name)");
    CHECK(veil_image_channel(img, "R", NULL, &err) == VEIL_ERR_INVALID, "channel(NULL out)");
    free(plane);

    int n = veil_image_stage_count(img);
    CHECK(n == 5, "%d stages", n);
    for (int i = 0; i < n; ++i) {
        const char *name = NULL, *status = NULL, *why = NULL;
        double ms = -1.0;
        CHECK(veil_image_stage(img, i, &name, &status, &ms, &why) == VEIL_OK, "stage %d", i);
        CHECK(name && *name && status && why && *why && ms >= 0.0, "stage %d report", i);
        /* the spread (stage 4) has nothing to do in a volume render with the volumetric estimate on */
        const char* want = i == 4 ? "skipped" : "ran";
        CHECK(status && strcmp(status, want) == 0, "stage %d of a first render: %s, expected %s", i,
              status ? status : "?", want);
        CHECK(veil_image_stage(img, i, NULL, NULL, NULL, NULL) == VEIL_OK, "stage %d, no outputs", i);
    }
    const char* first = NULL;
    veil_image_stage(img, 0, &first, NULL, NULL, NULL);
    CHECK(first && strcmp(first, "inject") == 0, "stage 0 is inject: %s", first ? first : "?");
    CHECK(veil_image_stage(img, n, NULL, NULL, NULL, NULL) == VEIL_ERR_INVALID, "stage out of range");
    CHECK(veil_image_stage(img, -1, NULL, NULL, NULL, NULL) == VEIL_ERR_INVALID, "stage -1");

    /* a turntable: frame 0 is the scene's camera; later frames reuse the volumes */
    desc.frames = 4;
    CHECK(veil_render(ctx, scene, &desc, &frame0, &err) == VEIL_OK, "frame 0: %s", err.msg);
    CHECK(frame0 && same_pixels(frame0, img), "frame 0 of a turntable renders the scene's camera, bit for bit");
    desc.frame = 1;
    CHECK(veil_render(ctx, scene, &desc, &frame1, &err) == VEIL_OK, "frame 1: %s", err.msg);
    for (int i = 0; frame1 && i < 2; ++i) {
        const char *name = NULL, *status = NULL;
        veil_image_stage(frame1, i, &name, &status, NULL, NULL);
        CHECK(status && strcmp(status, "cached") == 0, "frame 1 %s: %s", name, status ? status : "?");
    }
    CHECK(frame1 && !same_pixels(frame1, img), "frame 1 sees the scene from elsewhere");

    /* writers */
    char exr[128], png[128], bad[128];
    path_in(exr, sizeof exr, "api.exr");
    path_in(png, sizeof png, "api.png");
    path_in(bad, sizeof bad, "no/such/dir/api.exr");
    CHECK(veil_image_write_exr(img, exr, 1, &err) == VEIL_OK && file_exists(exr), "write_exr: %s", err.msg);
    CHECK(veil_image_write_png(img, png, 0.0f, &err) == VEIL_OK && file_exists(png), "write_png: %s", err.msg);
    CHECK(veil_image_write_exr(img, bad, 0, &err) != VEIL_OK && !file_exists(bad), "write_exr to a missing folder");
    CHECK(veil_image_write_png(img, png, INFINITY, &err) == VEIL_ERR_INVALID, "non-finite exposure");
    CHECK(veil_image_write_exr(img, NULL, 0, &err) == VEIL_ERR_INVALID, "write_exr(NULL path)");
    /* veil 0.5: the type and compression by name; a bad name refused naming it, nothing written */
    remove(exr);
    CHECK(veil_image_write_exr_as(img, exr, 1, "double", NULL, &err) == VEIL_ERR_INVALID && strstr(err.msg, "double") &&
          !file_exists(exr), "write_exr_as, type 'double': %s", err.msg);
    CHECK(veil_image_write_exr_as(img, exr, 1, NULL, "lzma", &err) == VEIL_ERR_INVALID && strstr(err.msg, "lzma") &&
          !file_exists(exr), "write_exr_as, compression 'lzma': %s", err.msg);
    CHECK(veil_image_write_exr_as(NULL, exr, 1, NULL, NULL, &err) == VEIL_ERR_INVALID, "write_exr_as(NULL image)");
    CHECK(veil_image_write_exr_as(img, exr, 1, "half", "piz", &err) == VEIL_OK && file_exists(exr), "write_exr_as: %s",
          err.msg);
    remove(exr);
    remove(png);

    veil_image_destroy(frame1);
    veil_image_destroy(frame0);
    veil_image_destroy(img);
}

/* Several contexts on one thread (issue 22): a second context made, used
 * and destroyed leaves the first one's renders bit for bit as they were.
 * Before each call made its own context current, the first context rendered
 * through the second's (VEIL_OK, wrong pixels), and after the second was
 * destroyed (eglTerminate of the display both share) NaN. */

/* ---- grids from memory and the progress callback (veil 0.3) ------------- */

#define GX 14
#define GY 10
#define GZ 7

/* An asymmetric blob (no axis can be swapped without changing it) at index (i, j, k). */
static float blob(int i, int j, int k)
{
    double x = (i - 5.0) / 4.0, y = (j - 4.5) / 3.0, z = (k - 3.0) / 2.5;
    double r2 = x * x + y * y + z * z;
    return r2 < 1.0 ? (float)(2.0 * (1.0 - r2) * (1.0 + 0.1 * i)) : 0.0f;
}

static veil_scene* array_scene(const char* source_extra)
{
    char json[1024];
    snprintf(json, sizeof json,
             "{\"camera\": {\"position\": [0.6, 0.5, 3], \"look_at\": [0.6, 0.45, 0.3], \"width\": 40, \"height\": 30},"
             " \"medium\": {\"sigma_a\": [0.5, 0.5, 0.5], \"sigma_s\": [4, 4, 4],"
             " \"sources\": [{\"type\": \"array\", \"grid\": \"density\"%s}]},"
             " \"lights\": [{\"type\": \"directional\", \"direction\": [0.3, -1, -0.2], \"irradiance\": [2, 2, 2]}]}",
             source_extra);
    veil_scene* s = NULL;
    veil_error err = {{0}};
    CHECK(veil_scene_from_json(json, NULL, "array scene", &s, &err) == VEIL_OK && s, "array scene: %s", err.msg);
    return s;
}

/* The blob in either order, with index_to_world m (NULL: all zero, the identity). */
static veil_result set_blob(veil_scene* s, int order, const double* m, veil_error* err)
{
    static float x_fast[GX * GY * GZ], z_fast[GX * GY * GZ];
    for (int k = 0; k < GZ; ++k)
        for (int j = 0; j < GY; ++j)
            for (int i = 0; i < GX; ++i) {
                x_fast[i + GX * (j + GY * k)] = blob(i, j, k);
                z_fast[k + GZ * (j + GY * i)] = blob(i, j, k);
            }
    veil_grid_desc g = VEIL_GRID_DESC_INIT;
    g.data = order == VEIL_AXIS_ORDER_Z_FASTEST ? z_fast : x_fast;
    g.dims[0] = GX, g.dims[1] = GY, g.dims[2] = GZ;
    g.axis_order = order;
    if (m) memcpy(g.index_to_world, m, sizeof g.index_to_world);
    return veil_scene_set_grid(s, "density", &g, err);
}

static veil_image* render_small(veil_context* ctx, const veil_scene* s, const char* what)
{
    veil_render_desc d = VEIL_RENDER_DESC_INIT;
    d.seed = 3;
    veil_image* img = NULL;
    veil_error err = {{0}};
    veil_result r = veil_render(ctx, s, &d, &img, &err);
    CHECK(r == VEIL_OK && img, "%s: %s: %s", what, veil_result_name(r), err.msg);
    return img;
}

static double alpha_sum(const veil_image* img)
{
    int w = 0, h = 0;
    veil_image_size(img, &w, &h);
    const float* p = veil_image_rgba(img);
    double a = 0.0;
    for (int i = 0; p && i < w * h; ++i) a += p[4 * i + 3];
    return a;
}

static void grids_from_memory(veil_context* ctx)
{
    /* 0.1 m voxels, the blob's corner at (0.1, 0.05, 0) */
    const double m[16] = {0.1, 0, 0, 0.1, 0, 0.1, 0, 0.05, 0, 0, 0.1, 0, 0, 0, 0, 1};
    veil_error err = {{0}};
    veil_scene *a = array_scene(""), *b = array_scene("");
    const char* placed_extra = ", \"transform\": [[0.1, 0, 0, 0.1], [0, 0.1, 0, 0.05], [0, 0, 0.1, 0], [0, 0, 0, 1]]";
    veil_scene* c = array_scene(placed_extra);
    if (!a || !b || !c) return;
    CHECK(set_blob(a, VEIL_AXIS_ORDER_X_FASTEST, m, &err) == VEIL_OK, "x fastest: %s", err.msg);
    CHECK(set_blob(b, VEIL_AXIS_ORDER_Z_FASTEST, m, &err) == VEIL_OK, "z fastest: %s", err.msg);
    /* the grid's own map the identity, the source's transform the same m: world = m x I */
    CHECK(set_blob(c, VEIL_AXIS_ORDER_X_FASTEST, NULL, &err) == VEIL_OK, "identity: %s", err.msg);
    veil_image *ia = render_small(ctx, a, "x fastest"), *ib = render_small(ctx, b, "z fastest"),
               *ic = render_small(ctx, c, "placed by the source's transform");
    /* the same values at the same indices make the same tree: the same pixels, bit for bit */
    CHECK(ia && ib && same_pixels(ia, ib), "x-fastest and z-fastest orders of one grid differ");
    CHECK(ia && ic && same_pixels(ia, ic), "a grid's own map and the source's transform differ");
    CHECK(ia && alpha_sum(ia) > 1.0, "the blob is not in the picture (alpha sum %g)", ia ? alpha_sum(ia) : 0.0);
    /* the z-fastest buffer declared x-fastest is another (scrambled) field: it must not look the same */
    veil_scene* d = array_scene("");
    const double* none = NULL;
    if (d) {
        static float z_fast[GX * GY * GZ];
        for (int k = 0; k < GZ; ++k)
            for (int j = 0; j < GY; ++j)
                for (int i = 0; i < GX; ++i) z_fast[k + GZ * (j + GY * i)] = blob(i, j, k);
        veil_grid_desc g = VEIL_GRID_DESC_INIT;
        g.data = z_fast;
        g.dims[0] = GX, g.dims[1] = GY, g.dims[2] = GZ;
        memcpy(g.index_to_world, m, sizeof m);
        CHECK(veil_scene_set_grid(d, "density", &g, &err) == VEIL_OK, "scrambled: %s", err.msg);
        veil_image* id = render_small(ctx, d, "scrambled");
        CHECK(id && ia && !same_pixels(ia, id), "the axis order is ignored");
        veil_image_destroy(id);
        veil_scene_close(d);
    }
    (void)none;
    /* replacing the grid changes the render (the stage caches key on the values) */
    veil_grid_desc z = VEIL_GRID_DESC_INIT;
    float zeros[8] = {0};
    z.data = zeros, z.dims[0] = z.dims[1] = z.dims[2] = 2;
    CHECK(veil_scene_set_grid(a, "density", &z, &err) == VEIL_OK, "empty grid: %s", err.msg);
    veil_image* ie = render_small(ctx, a, "empty");
    CHECK(ie && alpha_sum(ie) == 0.0, "an empty grid still shows a medium (alpha sum %g): stale cache?",
          ie ? alpha_sum(ie) : -1.0);
    veil_image_destroy(ie);

    /* bad grids: refused by veil_scene_set_grid, or by veil_render naming the source */
    veil_grid_desc g = VEIL_GRID_DESC_INIT;
    g.data = zeros, g.dims[0] = 2, g.dims[1] = 0, g.dims[2] = 2;
    CHECK(veil_scene_set_grid(a, "density", &g, &err) == VEIL_ERR_INVALID && strstr(err.msg, "dimension 1"),
          "dims 0: %s", err.msg);
    g.dims[1] = 2, g.axis_order = 2;
    CHECK(veil_scene_set_grid(a, "density", &g, &err) == VEIL_ERR_INVALID && strstr(err.msg, "axis_order"),
          "axis order 2: %s", err.msg);
    g.axis_order = 0;
    g.index_to_world[0] = 1, g.index_to_world[5] = 1, g.index_to_world[15] = 1; /* z column zero: singular */
    CHECK(veil_scene_set_grid(a, "density", &g, &err) == VEIL_ERR_INVALID && strstr(err.msg, "singular"),
          "singular: %s", err.msg);
    g.index_to_world[10] = 1, g.index_to_world[12] = 0.5; /* last row 0.5 0 0 1 */
    CHECK(veil_scene_set_grid(a, "density", &g, &err) == VEIL_ERR_INVALID && strstr(err.msg, "last row"),
          "projective: %s", err.msg);
    g.index_to_world[12] = 0;
    g.data = NULL;
    CHECK(veil_scene_set_grid(a, "density", &g, &err) == VEIL_ERR_INVALID && strstr(err.msg, "data"), "NULL data");
    float nan_grid[8] = {0, 0, 0, NAN, 0, 0, 0, 0}; /* offset 3 of a 2x2x2 grid: x fastest (1, 1, 0), z fastest (0, 1, 1) */
    g.data = nan_grid;
    CHECK(veil_scene_set_grid(a, "density", &g, &err) == VEIL_ERR_INVALID && strstr(err.msg, "not finite") &&
              strstr(err.msg, "index [1, 1, 0] (offset 3 of 8)"),
          "NaN: %s", err.msg);
    g.axis_order = VEIL_AXIS_ORDER_Z_FASTEST;
    CHECK(veil_scene_set_grid(a, "density", &g, &err) == VEIL_ERR_INVALID && strstr(err.msg, "index [0, 1, 1]"),
          "NaN, z fastest: %s", err.msg);
    g.axis_order = VEIL_AXIS_ORDER_X_FASTEST;
    veil_image* img = NULL;
    veil_render_desc rd = VEIL_RENDER_DESC_INIT;
    veil_result r;
    veil_scene* none_given = array_scene("");
    r = none_given ? veil_render(ctx, none_given, &rd, &img, &err) : VEIL_ERR_INVALID;
    CHECK(r == VEIL_ERR_INVALID && !img && strstr(err.msg, "medium.sources[0].grid") &&
              strstr(err.msg, "no grid 'density'"),
          "no grid given: %s: %s", veil_result_name(r), err.msg);
    veil_scene_close(none_given);
    veil_image_destroy(ia);
    veil_image_destroy(ib);
    veil_image_destroy(ic);
    veil_scene_close(a);
    veil_scene_close(b);
    veil_scene_close(c);
}

/* The clip planes and the shift in the march (the rays' geometry is
 * tests/frame/test_frames.c's): a medium wholly beyond the far plane or
 * before the near one is not seen (alpha exactly 0: the march meets no
 * medium), planes around the whole medium change no pixel, and a shift
 * that moves the frame off the medium leaves only the background. The
 * medium: the blob at 0.1 m voxels, within 2.3..3.1 m of the camera along
 * its view axis. */
static void lens_in_the_march(veil_context* ctx)
{
    const double m[16] = {0.1, 0, 0, 0.1, 0, 0.1, 0, 0.05, 0, 0, 0.1, 0, 0, 0, 0, 1};
    const char* extras[] = {"", ", \"clip\": [0.5, 2.0]", ", \"clip\": [4.0, 100]", ", \"clip\": [1.0, 50]",
                            ", \"shift\": [1.5, 0]", ", \"shift\": [0.2, 0.1], \"sensor_fit\": \"auto\", \"fov_deg\": 45"};
    veil_image* img[6] = {0};
    for (int i = 0; i < 6; ++i) {
        char json[1024];
        snprintf(json, sizeof json,
                 "{\"camera\": {\"position\": [0.6, 0.5, 3], \"look_at\": [0.6, 0.45, 0.3], \"width\": 40, "
                 "\"height\": 30%s}, \"medium\": {\"sigma_a\": [0.5, 0.5, 0.5], \"sigma_s\": [4, 4, 4],"
                 " \"sources\": [{\"type\": \"array\", \"grid\": \"density\"}]},"
                 " \"lights\": [{\"type\": \"directional\", \"direction\": [0.3, -1, -0.2], \"irradiance\": [2, 2, 2]}]}",
                 extras[i]);
        veil_scene* s = NULL;
        veil_error err = {{0}};
        CHECK(veil_scene_from_json(json, NULL, "lens", &s, &err) == VEIL_OK && s, "lens %d: %s", i, err.msg);
        if (!s) continue;
        CHECK(set_blob(s, VEIL_AXIS_ORDER_X_FASTEST, m, &err) == VEIL_OK, "%s", err.msg);
        img[i] = render_small(ctx, s, extras[i]);
        veil_scene_close(s);
    }
    CHECK(img[0] && alpha_sum(img[0]) > 1.0, "no medium in view");
    CHECK(img[1] && alpha_sum(img[1]) == 0.0, "the medium beyond the far plane is seen (alpha sum %g)",
          img[1] ? alpha_sum(img[1]) : -1.0);
    CHECK(img[2] && alpha_sum(img[2]) == 0.0, "the medium before the near plane is seen (alpha sum %g)",
          img[2] ? alpha_sum(img[2]) : -1.0);
    CHECK(img[0] && img[3] && same_pixels(img[0], img[3]), "planes around the whole medium changed the image");
    CHECK(img[4] && alpha_sum(img[4]) == 0.0, "a frame shifted off the medium still sees it (alpha sum %g)",
          img[4] ? alpha_sum(img[4]) : -1.0);
    CHECK(img[5] && alpha_sum(img[5]) > 1.0 && !same_pixels(img[0], img[5]), "a small shift lost the medium or did nothing");
    for (int i = 0; i < 6; ++i) veil_image_destroy(img[i]);
}

typedef struct progress_log {
    int calls, bad, stop_at; /* stop_at: cancel at the first report of stage index stop_at (-1: never) */
    int stage;               /* the index of the stage last seen */
    double done;             /* its share last reported */
    int ended[5];            /* a stage reported done = 1 */
} progress_log;

static const char* const STAGES[5] = {"inject", "propagate", "volumetric", "render", "spread"};

static int on_progress(void* user, const char* stage, double done)
{
    progress_log* p = user;
    int s = -1;
    for (int i = 0; i < 5; ++i)
        if (stage && !strcmp(stage, STAGES[i])) s = i;
    ++p->calls;
    /* a known stage, the stages in order, the share within 0..1 and never going back within a stage */
    if (s < 0 || s < p->stage || !(done >= 0.0 && done <= 1.0) || (s == p->stage && done < p->done)) ++p->bad;
    p->stage = s, p->done = done;
    if (s >= 0 && done == 1.0) p->ended[s] = 1;
    return s >= 0 && s == p->stop_at;
}

static void progress_and_cancel(veil_context* ctx, const veil_scene* scene)
{
    veil_error err = {{0}};
    veil_image* img = NULL;
    progress_log log = {.stop_at = -1, .stage = -1};
    veil_render_desc d = VEIL_RENDER_DESC_INIT;
    d.width = 48, d.height = 36, d.seed = 5, d.progress = on_progress, d.progress_user = &log;
    CHECK(veil_render(ctx, scene, &d, &img, &err) == VEIL_OK && img, "render with progress: %s", err.msg);
    CHECK(log.calls >= 5 && log.bad == 0, "progress: %d calls, %d out of order or range", log.calls, log.bad);
    CHECK(log.ended[0] && log.ended[3] && log.ended[4], "not every stage reported its end");
    veil_image_destroy(img);
    img = NULL;
    /* cancel when the march begins: no image, its own code, and the context still renders */
    d.seed = 6; /* a new view key for the per-view stages */
    progress_log stop = {.stop_at = 3, .stage = -1};
    d.progress_user = &stop;
    veil_result r = veil_render(ctx, scene, &d, &img, &err);
    CHECK(r == VEIL_ERR_CANCELLED && img == NULL && strstr(err.msg, "cancelled"), "cancel: %s: %s",
          veil_result_name(r), err.msg);
    CHECK(stop.stage == 3, "the callback was called after it cancelled (last stage %d)", stop.stage);
    CHECK(strcmp(veil_result_name(VEIL_ERR_CANCELLED), "VEIL_ERR_CANCELLED") == 0, "the code's name");
    d.progress = NULL;
    CHECK(veil_render(ctx, scene, &d, &img, &err) == VEIL_OK && img, "after a cancel: %s", err.msg);
    if (img) { /* the stages before the cancel were kept */
        const char* status = NULL;
        veil_image_stage(img, 0, NULL, &status, NULL, NULL);
        CHECK(status && strcmp(status, "cached") == 0, "inject after a cancelled render: %s", status ? status : "?");
    }
    veil_image_destroy(img);
    /* a scene not seen before: a cancel asked for as the light cache begins stops it between its
     * dispatches of photons (2^18 each: 10^6 photons make 4), not only at the next stage */
    veil_scene* fresh = NULL;
    const char* fresh_json =
        "{\"camera\": {\"position\": [0.6, 0.5, 3], \"look_at\": [0.6, 0.45, 0.3], \"width\": 40, \"height\": 30},"
        " \"medium\": {\"sigma_s\": [4, 4, 4], \"sources\": [{\"type\": \"array\", \"grid\": \"density\"}]},"
        " \"multiple_scattering\": {\"volumetric_method\": \"cache\", \"cache_photons\": 1000000},"
        " \"lights\": [{\"type\": \"point\", \"position\": [0.6, 2, 0.3], \"intensity\": [2, 2, 2]}]}";
    CHECK(veil_scene_from_json(fresh_json, NULL, "fresh", &fresh, &err) == VEIL_OK, "fresh: %s", err.msg);
    const double m[16] = {0.1, 0, 0, 0.1, 0, 0.1, 0, 0.05, 0, 0, 0.1, 0, 0, 0, 0, 1};
    if (fresh && set_blob(fresh, VEIL_AXIS_ORDER_X_FASTEST, m, &err) == VEIL_OK) {
        progress_log mid = {.stop_at = 2, .stage = -1};
        veil_render_desc dc = VEIL_RENDER_DESC_INIT;
        dc.progress = on_progress, dc.progress_user = &mid;
        img = NULL;
        r = veil_render(ctx, fresh, &dc, &img, &err);
        CHECK(r == VEIL_ERR_CANCELLED && img == NULL && strstr(err.msg, "during the light cache"),
              "cancel in the light cache: %s: %s", veil_result_name(r), err.msg);
    }
    veil_scene_close(fresh);
}

static void two_contexts(veil_context* ctx, const veil_scene* scene)
{
    veil_error err = {{0}};
    veil_render_desc desc = {.width = 24, .height = 18, .seed = 3};
    veil_image *before = NULL, *during = NULL, *second = NULL, *after = NULL;
    CHECK(veil_render(ctx, scene, &desc, &before, &err) == VEIL_OK, "first context: %s", err.msg);
    veil_context* ctx2 = NULL;
    CHECK(veil_context_create(NULL, &ctx2, &err) == VEIL_OK && ctx2, "second context: %s", err.msg);
    if (!before || !ctx2) {
        veil_image_destroy(before);
        veil_context_destroy(ctx2);
        return;
    }
    CHECK(veil_render(ctx, scene, &desc, &during, &err) == VEIL_OK, "first context beside a second: %s", err.msg);
    CHECK(during && same_pixels(during, before), "the first context renders as before while a second lives");
    CHECK(veil_render(ctx2, scene, &desc, &second, &err) == VEIL_OK, "second context: %s", err.msg);
    CHECK(second && same_pixels(second, before), "the second context renders what the first does");
    veil_context_destroy(ctx2);
    CHECK(veil_render(ctx, scene, &desc, &after, &err) == VEIL_OK, "first context after the second: %s", err.msg);
    CHECK(after && same_pixels(after, before), "the first context renders as before once the second is gone");
    veil_image_destroy(before);
    veil_image_destroy(during);
    veil_image_destroy(second);
    veil_image_destroy(after);
}

/* A context current on this thread, used from another: refused with
 * VEIL_ERR_GPU (veil.h, "Threading"), never rendered through. */
typedef struct other_thread_call {
    veil_context* ctx;
    const veil_scene* scene;
    veil_result r;
    veil_image* img;
    veil_error err;
} other_thread_call;

static void* render_elsewhere(void* arg)
{
    other_thread_call* c = arg;
    veil_render_desc desc = {.width = 8, .height = 6};
    c->r = veil_render(c->ctx, c->scene, &desc, &c->img, &c->err);
    return NULL;
}

static void other_thread(veil_context* ctx, const veil_scene* scene)
{
    other_thread_call c = {.ctx = ctx, .scene = scene};
    pthread_t t;
    CHECK(pthread_create(&t, NULL, render_elsewhere, &c) == 0, "pthread_create");
    pthread_join(t, NULL);
    CHECK(c.r == VEIL_ERR_GPU && c.img == NULL, "a context current on another thread: %s, %s",
          veil_result_name(c.r), c.err.msg);
    veil_image_destroy(c.img);
}

int main(int argc, char** argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_api SCENE.json\n");
        return 2;
    }
    null_arguments();
    veil_context* ctx = context_or_skip();
    veil_scene* scene = NULL;
    veil_error err = {{0}};
    CHECK(veil_scene_open(argv[1], &scene, &err) == VEIL_OK && scene, "open %s: %s", argv[1], err.msg);
    if (scene && test_dir_begin("api")) {
        from_json();
        bad_descriptions(ctx, scene);
        render_and_read(ctx, scene);
        two_contexts(ctx, scene);
        grids_from_memory(ctx);
        lens_in_the_march(ctx);
        progress_and_cancel(ctx, scene);
        other_thread(ctx, scene);
        CHECK(test_dir_end(), "temporary folder left clean");
    }
    veil_scene_close(scene);
    veil_context_destroy(ctx);
    return check_finish();
}
