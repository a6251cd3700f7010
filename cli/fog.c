/* veil fog FRAME.exr --scene fog.json -o OUT.exr [--png OUT.png]
 *                  [--depth-channel NAME] [--depth-is z|distance] [--no-occluders] [--aovs] [--stats]
 *
 * Adds the scene's medium to a frame rendered elsewhere with the scene's
 * camera (the paper's own use case: Iser & Elek 2018): the surfaces in
 * FRAME are attenuated by the medium in front of them, the medium's single
 * scattering (and the volumetric estimate) is added in front of them, and
 * the light they send through the medium is spread (screen-space multiple
 * scattering: glow and blur). The medium, lights and settings come from the
 * scene; its background is replaced by the frame. The frame's surfaces are
 * also solid for the medium's light (scene/solid.h): they shadow it from the
 * lights and absorb the light cache's photons; --no-occluders turns that off.
 *
 * FRAME: R, G, B (linear radiance; A is ignored) and a depth channel, the
 * first of Z, depth.Z, depth, distance that it holds (or --depth-channel).
 * By default depth is Z, the distance along the camera's view axis (what
 * Blender, Arnold and most renderers write as Z): each ray's distance is
 * Z / cos(angle off the axis). --depth-is distance reads it as the
 * distance along the ray. +inf (sky, nothing hit) is allowed.
 * Errors (exit 1, nothing written): FRAME missing or not an EXR, no depth
 * channel (or one that is neither half nor float), a size other than the
 * scene camera's, a NaN or negative depth, a non-finite colour or one over
 * 1e38. Negative colour values are read as 0, with a note.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli_util.h"
#include "commands.h"
#include "frame_out.h"
#include "progress.h"
#include "frame/renderer.h"
#include "gpu/gl_context.h"
#include "io/image.h"
#include "io/scene.h"
#include "scene/camera.h"

typedef struct fog_args {
    const char *frame, *scene, *exr, *png, *depth_channel;
    int depth_is_distance, aovs, stats, no_occluders;
    veil_exr_format exr_format;
} fog_args;

static int parse_fog_args(int argc, char** argv, fog_args* a)
{
    memset(a, 0, sizeof *a);
    for (int i = 2; i < argc; ++i) {
        const char* s = argv[i];
        const char* v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(s, "--aovs")) { a->aovs = 1; continue; }
        if (!strcmp(s, "--stats")) { a->stats = 1; continue; }
        if (!strcmp(s, "--no-occluders")) { a->no_occluders = 1; continue; }
        int xrc; /* the EXR's storage (cli/cli_util.h) */
        if ((!strcmp(s, "--exr-type") || !strcmp(s, "--exr-compression") || !strcmp(s, "--dwa-level")) &&
            veil_cli_exr_option(s, v, &a->exr_format, &xrc)) {
            if (xrc >= 0) return xrc;
            ++i;
            continue;
        }
        int takes = !strcmp(s, "-o") || !strcmp(s, "--png") || !strcmp(s, "--scene") ||
                    !strcmp(s, "--depth-channel") || !strcmp(s, "--depth-is");
        if (takes && !v) return veil_cli_usage_error("%s needs a value", s);
        if (!strcmp(s, "-o")) a->exr = v;
        else if (!strcmp(s, "--png")) a->png = v;
        else if (!strcmp(s, "--scene")) a->scene = v;
        else if (!strcmp(s, "--depth-channel")) a->depth_channel = v;
        else if (!strcmp(s, "--depth-is")) {
            if (!strcmp(v, "z")) a->depth_is_distance = 0;
            else if (!strcmp(v, "distance")) a->depth_is_distance = 1;
            else return veil_cli_usage_error("--depth-is: expected z or distance, got '%s'", v);
        } else if (s[0] == '-' && s[1]) return veil_cli_usage_error("unknown option '%s'", s);
        else if (!a->frame) { a->frame = s; continue; }
        else return veil_cli_usage_error("unexpected argument '%s'", s);
        ++i;
    }
    if (!a->frame) return veil_cli_usage_error("%s", "fog: missing FRAME.exr");
    if (!a->scene) return veil_cli_usage_error("%s", "fog: missing --scene SCENE.json");
    if (!a->exr) return veil_cli_usage_error("%s", "fog: missing -o OUT.exr");
    return -1;
}

/* The frame's radiance the fog may attenuate: the output is T L + the fog's
 * own radiance, T <= 1 and the fog's < 2.6e37 (scene/limits.h), so L <=
 * 1e38 keeps every output value under FLT_MAX = 3.4e38. Negative values
 * (no light is negative; a sharpening filter's ringing makes them) are
 * read as 0, with a note: fog over them would stay negative. */
#define FOG_MAX_RADIANCE 1e38

/* The frame's depth plane: the named channel, or the first usual one. */
static veil_result read_depth(const fog_args* a, int w, int h, float** depth, const char** used, veil_error* err)
{
    static const char* const usual[] = {"Z", "depth.Z", "depth", "distance", NULL};
    const char* one[] = {a->depth_channel, NULL};
    const char* const* names = a->depth_channel ? one : usual;
    for (int i = 0; names[i]; ++i) {
        int dw = 0, dh = 0;
        veil_error e = {0};
        veil_result r = veil_read_exr_channel(a->frame, names[i], &dw, &dh, depth, &e);
        if (r == VEIL_ERR_INVALID) continue; /* no such channel: the next name */
        if (r != VEIL_OK) {
            /* there, but unreadable (a uint channel, say): that, not "no depth channel" */
            veil_fail(err, r, "%s (the depth channel)", e.msg);
            return r;
        }
        if (dw != w || dh != h) {
            free(*depth);
            *depth = NULL;
            return veil_fail(err, VEIL_ERR_INVALID, "%s: channel %s is %dx%d, the colour %dx%d", a->frame, names[i],
                             dw, dh, w, h);
        }
        *used = names[i];
        return VEIL_OK;
    }
    if (a->depth_channel)
        return veil_fail(err, VEIL_ERR_INVALID, "%s: no channel '%s' (--depth-channel)", a->frame, a->depth_channel);
    return veil_fail(err, VEIL_ERR_INVALID, "%s: no depth channel: expected one of Z, depth.Z, depth, distance "
                     "(or name it with --depth-channel)", a->frame);
}

/* Depth -> distance along each pixel's ray; refuses NaN and negative depth. */
static veil_result to_distance(const fog_args* a, const veil_camera* cam, int w, int h, const char* channel,
                               float* depth, veil_error* err)
{
    veil_camera_basis b;
    veil_result r = veil_camera_make_basis(cam, w, h, &b, err);
    if (r != VEIL_OK) return r;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* d = &depth[(size_t)y * (size_t)w + (size_t)x];
            char got[32];
            if (isnan(*d) || *d < 0.0f)
                return veil_fail(err, VEIL_ERR_INVALID, "%s: channel %s at pixel (%d, %d) is %s: expected a depth "
                                 ">= 0 (m; inf where nothing was hit)", a->frame, channel, x, y,
                                 veil_number_text(*d, got, sizeof got));
            if (a->depth_is_distance) continue;
            float dir[3];
            veil_camera_ray(&b, w, h, x, y, dir);
            float cos_axis = dir[0] * b.fwd[0] + dir[1] * b.fwd[1] + dir[2] * b.fwd[2];
            *d = *d / cos_axis; /* cos_axis >= cos(diagonal half-angle) > 0; inf stays inf */
        }
    return VEIL_OK;
}

int veil_cmd_fog(int argc, char** argv)
{
    fog_args a;
    int rc = parse_fog_args(argc, argv, &a);
    if (rc >= 0) return rc;
    veil_error err = {0};
    veil_scene scene = {0};
    float *frame = NULL, *depth = NULL;
    int w = 0, h = 0;
    const char* channel = NULL;
    veil_result r = veil_scene_load(a.scene, &scene, &err);
    if (r != VEIL_OK) return veil_cli_fail(r, &err);
    /* -o and --png against the frame, the scene and what it reads (cli/run_files.h), then their folders */
    int n = 0;
    veil_run_file* files = veil_cli_scene_inputs(a.scene, &scene, 0, 3, &n);
    if (!files) {
        veil_scene_free(&scene);
        return veil_cli_fail(veil_fail(&err, VEIL_ERR_OOM, "out of memory"), &err);
    }
    char staged[48];
    snprintf(staged, sizeof staged, ".veil-staged%ld", (long)getpid()); /* veil_cli_stage's */
    files[n++] = (veil_run_file){.what = "the frame", .path = a.frame};
    files[n++] = (veil_run_file){.what = "-o", .path = a.exr, .writes = 1, .staged = staged};
    if (a.png) files[n++] = (veil_run_file){.what = "--png", .path = a.png, .writes = 1, .staged = staged};
    veil_cli_folders made = {0};
    rc = veil_cli_check_run(files, n, NULL);
    if (rc == EXIT_OK) {
        r = veil_cli_make_folders(files, n, NULL, &made, &err);
        if (r != VEIL_OK) rc = veil_cli_fail(r, &err);
    }
    free(files);
    if (rc != EXIT_OK) {
        veil_scene_free(&scene);
        return rc;
    }
    if (r == VEIL_OK) r = veil_read_exr(a.frame, &w, &h, &frame, &err);
    if (r == VEIL_OK && (w != scene.camera.width || h != scene.camera.height))
        r = veil_fail(&err, VEIL_ERR_INVALID, "%s is %dx%d but the scene %s's camera is %dx%d (camera.width, "
                      "camera.height): the frame must be rendered with the scene's camera", a.frame, w, h, a.scene,
                      scene.camera.width, scene.camera.height);
    size_t negative = 0, first_negative = 0;
    for (size_t i = 0; r == VEIL_OK && i < (size_t)w * (size_t)h * 4; ++i) {
        if (i % 4 == 3) continue;
        if (!isfinite(frame[i]) || frame[i] > FOG_MAX_RADIANCE) {
            char got[32];
            r = veil_fail(&err, VEIL_ERR_INVALID, "%s: pixel (%zu, %zu) channel %c is %s: expected finite radiance "
                          "<= %g", a.frame, (i / 4) % (size_t)w, (i / 4) / (size_t)w, "RGB"[i % 4],
                          veil_number_text(frame[i], got, sizeof got), FOG_MAX_RADIANCE);
        } else if (frame[i] < 0.0f) {
            if (negative++ == 0) first_negative = i;
            frame[i] = 0.0f;
        }
    }
    if (r == VEIL_OK && negative)
        fprintf(stderr, "veil: note: %s: %zu value%s of negative radiance (a filter's ringing?), the first at pixel "
                "(%zu, %zu) channel %c, read as 0\n", a.frame, negative, negative == 1 ? "" : "s",
                (first_negative / 4) % (size_t)w, (first_negative / 4) / (size_t)w, "RGB"[first_negative % 4]);
    if (r == VEIL_OK) r = read_depth(&a, w, h, &depth, &channel, &err);
    if (r == VEIL_OK) r = to_distance(&a, &scene.camera, w, h, channel, depth, &err);
    veil_renderer* ren = NULL;
    veil_image_set im = {0};
    veil_render_stats st = {0};
    if (r == VEIL_OK) r = veil_renderer_create_deferred(NULL, &ren, &err);
    if (r == VEIL_OK) {
        veil_render_opts opts = {.behind = frame, .behind_distance = depth, .behind_not_solid = a.no_occluders,
                                 .flat_only = !a.aovs};
        veil_cli_progress_begin(NULL);
        r = veil_render_scene_images(ren, &scene, &opts, &im, &st, &err);
        veil_cli_progress_end();
        if (r != VEIL_OK && veil_cli_exit_code(r) == EXIT_INPUT) veil_cli_prefix_error(&err, a.scene);
    }
    if (r == VEIL_OK) r = veil_cli_write_frame(&im, a.exr, a.png, NULL, a.aovs, &(veil_exr_meta){.format = a.exr_format},
                                                  &err); /* all or nothing */
    if (r == VEIL_OK && a.stats) veil_cli_print_stages(&st);
    if (r == VEIL_OK) printf("wrote %s%s%s (depth from channel %s, as %s)\n", a.exr, a.png ? " and " : "",
                             a.png ? a.png : "", channel, a.depth_is_distance ? "distance along the ray" : "Z");
    veil_image_set_free(&im);
    veil_renderer_destroy(ren);
    veil_scene_free(&scene);
    free(frame);
    free(depth);
    veil_cli_folders_done(&made, r == VEIL_OK);
    return r == VEIL_OK ? EXIT_OK : veil_cli_fail(r, &err);
}
