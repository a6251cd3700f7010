/* veil render: a scene (or a turntable of it) to EXR and PNG. */
#define _POSIX_C_SOURCE 200809L
#include <unistd.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_util.h"
#include "commands.h"
#include "core/clock.h"
#include "frame/renderer.h"
#include "gpu/gl_context.h"
#include "io/image.h"
#include "io/scene.h"
#include "scene/camera.h"

typedef struct render_args {
    const char *scene, *exr, *png;
    long width, height, seed, frames;
    float step;
    veil_opv_method method;
    int stats;
} render_args;

static int parse_render_args(int argc, char** argv, render_args* a)
{
    memset(a, 0, sizeof *a);
    for (int i = 2; i < argc; ++i) {
        const char* s = argv[i];
        const char* v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(s, "--stats")) { a->stats = 1; continue; }
        int takes = !strcmp(s, "-o") || !strcmp(s, "--png") || !strcmp(s, "--width") || !strcmp(s, "--height") ||
                    !strcmp(s, "--step") || !strcmp(s, "--seed") || !strcmp(s, "--method") ||
                    !strcmp(s, "--turntable");
        if (takes && !v) return veil_cli_usage_error("%s needs a value", s);
        if (!strcmp(s, "-o")) a->exr = v;
        else if (!strcmp(s, "--png")) a->png = v;
        else if (!strcmp(s, "--width")) {
            if (!veil_cli_parse_int(v, 1, VEIL_SCENE_MAX_IMAGE, &a->width)) return veil_cli_usage_error("--width: expected an integer in 1..16384, got '%s'", v);
        } else if (!strcmp(s, "--height")) {
            if (!veil_cli_parse_int(v, 1, VEIL_SCENE_MAX_IMAGE, &a->height)) return veil_cli_usage_error("--height: expected an integer in 1..16384, got '%s'", v);
        } else if (!strcmp(s, "--step")) {
            if (!veil_cli_parse_float(v, 0.01f, 16.0f, &a->step)) return veil_cli_usage_error("--step: expected a number of voxels in 0.01..16, got '%s'", v);
        } else if (!strcmp(s, "--seed")) {
            if (!veil_cli_parse_int(v, 0, 4294967295L, &a->seed)) return veil_cli_usage_error("--seed: expected an integer in 0..4294967295, got '%s'", v);
        } else if (!strcmp(s, "--turntable")) {
            if (!veil_cli_parse_int(v, 1, 100000, &a->frames)) return veil_cli_usage_error("--turntable: expected a number of frames in 1..100000, got '%s'", v);
        } else if (!strcmp(s, "--method")) {
            if (!veil_opv_method_parse(v, &a->method))
                return veil_cli_usage_error("--method: expected default, jacobi, jacobi-corrected, sweep or semi-lagrangian, got '%s'", v);
        } else if (s[0] == '-' && s[1]) return veil_cli_usage_error("unknown option '%s'", s);
        else if (!a->scene) { a->scene = s; continue; }
        else return veil_cli_usage_error("unexpected argument '%s'", s);
        ++i;
    }
    if (!a->scene) return veil_cli_usage_error("%s", "render: missing SCENE.json");
    if (!a->exr) return veil_cli_usage_error("%s", "render: missing -o OUT.exr");
    return -1;
}

/* The folder an output goes into must exist: found before rendering, not
 * after seconds of work. */
/* "out/t.exr", frame 7 -> "out/t_0007.exr" (a turntable's frame files). */
static void frame_path(const char* path, long frame, int numbered, char* out, size_t n)
{
    if (!numbered) {
        snprintf(out, n, "%s", path);
        return;
    }
    const char* slash = strrchr(path, '/');
    const char* dot = strrchr(path, '.');
    if (!dot || (slash && dot < slash)) dot = path + strlen(path);
    snprintf(out, n, "%.*s_%04ld%s", (int)(dot - path), path, frame, dot);
}

/* The scene camera turned by `angle` radians about the up axis through look_at. */
static veil_camera orbit(const veil_camera* c, double angle)
{
    veil_camera o = *c;
    double u[3], v[3], len = 0.0;
    for (int a = 0; a < 3; ++a) {
        u[a] = c->up[a];
        len += u[a] * u[a];
        v[a] = (double)c->position[a] - c->look_at[a];
    }
    len = sqrt(len);
    for (int a = 0; a < 3; ++a) u[a] /= len;
    double cs = cos(angle), sn = sin(angle), uv = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    double x[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    for (int a = 0; a < 3; ++a)
        o.position[a] = (float)(c->look_at[a] + v[a] * cs + x[a] * sn + u[a] * uv * (1.0 - cs));
    return o;
}

static void print_stats(const veil_render_stats* st, size_t lights, int w, int h, double write_ms)
{
    printf("inject     %9.2f ms", st->inject_ms);
    if (st->inject_cached)
        printf("  (cached)\n");
    else if (st->has_volume)
        printf("  (%zu particles, %zu VDB voxels, grid %dx%dx%d, voxel %.4g m)\n", st->particles, st->vdb_voxels,
               st->grid.dims[0], st->grid.dims[1], st->grid.dims[2], st->grid.voxel);
    else
        printf("  (no voxelised source: no volume%s)\n", st->fogs ? "; analytic fog only" : "");
    printf("propagate  %9.2f ms", st->propagate_ms);
    if (st->lights_used == 0)
        printf("  (no light reaches the medium: skipped)\n");
    else if (st->opv_computed == 0)
        printf("  (cached: %d lights, %s)\n", st->lights_used, veil_opv_method_name(st->method));
    else
        printf("  (%d of %zu lights, %s, %d passes; %d textures computed, %d cached)\n", st->lights_used, lights,
               veil_opv_method_name(st->method), st->propagate_iterations, st->opv_computed, st->opv_cached);
    printf("render     %9.2f ms  (%dx%d)\n", st->render_ms, w, h);
    printf("write      %9.2f ms\n", write_ms);
}

int veil_cmd_render(int argc, char** argv)
{
    render_args a;
    int rc = parse_render_args(argc, argv, &a);
    if (rc >= 0) return rc;
    double t_start = veil_now_ms();
    veil_error err = {0};
    veil_scene scene;
    veil_result r = veil_cli_check_output_folder(a.exr, &err);
    if (r == VEIL_OK && a.png) r = veil_cli_check_output_folder(a.png, &err);
    if (r != VEIL_OK) return veil_cli_fail(r, &err);
    r = veil_scene_load(a.scene, &scene, &err);
    if (r != VEIL_OK) return veil_cli_fail(r, &err);

    veil_gl* gl = NULL;
    veil_renderer* ren = NULL;
    r = veil_gl_create(NULL, &gl, &err);
    if (r == VEIL_OK) r = veil_renderer_create(gl, &ren, &err);
    int w = a.width ? (int)a.width : scene.camera.width, h = a.height ? (int)a.height : scene.camera.height;
    long frames = a.frames > 0 ? a.frames : 1;
    for (long f = 0; f < frames && r == VEIL_OK; ++f) {
        veil_camera cam = orbit(&scene.camera, 2.0 * VEIL_PI * (double)f / (double)frames);
        veil_render_opts opts = {.width = (int)a.width, .height = (int)a.height, .step_voxels = a.step,
                                 .seed = (uint32_t)a.seed, .method = a.method, .camera = &cam};
        veil_render_stats st = {0};
        float* rgba = NULL;
        r = veil_render_scene(ren, &scene, &opts, &rgba, &st, &err);
        if (r != VEIL_OK && veil_cli_exit_code(r) == EXIT_INPUT) veil_cli_prefix_error(&err, a.scene);
        char exr[4096], png[4096];
        frame_path(a.exr, f, a.frames > 0, exr, sizeof exr);
        if (a.png) frame_path(a.png, f, a.frames > 0, png, sizeof png);
        double t_write = veil_now_ms();
        if (r == VEIL_OK) r = veil_write_exr(exr, w, h, rgba, &err);
        if (r == VEIL_OK && a.png) {
            r = veil_write_png(png, w, h, rgba, 0.0f, &err);
            if (r != VEIL_OK) unlink(exr); /* all or nothing, per frame */
        }
        free(rgba);
        if (r != VEIL_OK) break;
        if (a.stats) {
            if (frames > 1) printf("frame %ld\n", f);
            print_stats(&st, scene.light_count, w, h, veil_now_ms() - t_write);
        }
        if (frames == 1 || f == frames - 1)
            printf("wrote %s%s%s%s in %.2f s\n", frames > 1 ? "frames up to " : "", exr, a.png ? " and " : "",
                   a.png ? png : "", (veil_now_ms() - t_start) * 1e-3);
    }
    veil_renderer_destroy(ren);
    veil_gl_destroy(gl);
    veil_scene_free(&scene);
    return r == VEIL_OK ? EXIT_OK : veil_cli_fail(r, &err);
}

