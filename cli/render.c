/* veil render: a scene (or a turntable of it) to EXR and PNG. */
#define _POSIX_C_SOURCE 200809L
#include <unistd.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_util.h"
#include "commands.h"
#include "frame_out.h"
#include "progress.h"
#include "core/clock.h"
#include "frame/plan.h"
#include "frame/renderer.h"
#include "gpu/gl_context.h"
#include "io/image.h"
#include "io/scene.h"
#include "scene/camera.h"

typedef struct render_args {
    const char *scene, *exr, *png, *deep;
    long width, height, seed, frames, deep_samples;
    float step, sun_across, sun_along;
    veil_opv_method method;
    veil_quality quality;
    int stats, explain, aovs;
    veil_exr_format exr_format;
    int shutter_set; /* --shutter: 1 the values, -1 off, 0 the scene's */
    float shutter[2];
} render_args;

static int parse_render_args(int argc, char** argv, render_args* a)
{
    memset(a, 0, sizeof *a);
    for (int i = 2; i < argc; ++i) {
        const char* s = argv[i];
        const char* v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(s, "--stats")) { a->stats = 1; continue; }
        if (!strcmp(s, "--explain")) { a->explain = 1; continue; }
        if (!strcmp(s, "--aovs")) { a->aovs = 1; continue; }
        int xrc; /* the EXR's storage (cli/cli_util.h) */
        if ((!strcmp(s, "--exr-type") || !strcmp(s, "--exr-compression") || !strcmp(s, "--dwa-level")) &&
            veil_cli_exr_option(s, v, &a->exr_format, &xrc)) {
            if (xrc >= 0) return xrc;
            ++i;
            continue;
        }
        int takes = !strcmp(s, "-o") || !strcmp(s, "--png") || !strcmp(s, "--width") || !strcmp(s, "--height") ||
                    !strcmp(s, "--step") || !strcmp(s, "--seed") || !strcmp(s, "--method") ||
                    !strcmp(s, "--turntable") || !strcmp(s, "--quality") || !strcmp(s, "--od-spacing") ||
                    !strcmp(s, "--deep") || !strcmp(s, "--deep-samples") ||
                    !strcmp(s, "--shutter");
        if (takes && !v) return veil_cli_usage_error("%s needs a value", s);
        if (!strcmp(s, "-o")) a->exr = v;
        else if (!strcmp(s, "--png")) a->png = v;
        else if (!strcmp(s, "--deep")) a->deep = v;
        else if (!strcmp(s, "--deep-samples")) {
            if (!veil_cli_parse_int(v, 1, VEIL_DEEP_MAX_SAMPLES, &a->deep_samples))
                return veil_cli_usage_error("--deep-samples: expected samples a pixel in 1..64, got '%s'", v);
        } else if (!strcmp(s, "--width")) {
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
                return veil_cli_usage_error("--method: expected default, jacobi, jacobi-corrected, sweep, semi-lagrangian or light-space, got '%s'", v);
        } else if (!strcmp(s, "--quality")) {
            if (!veil_quality_parse(v, &a->quality))
                return veil_cli_usage_error("--quality: expected draft, default, high or max, got '%s'", v);
        } else if (!strcmp(s, "--shutter")) {
            if (!veil_cli_parse_shutter(v, &a->shutter_set, a->shutter))
                return veil_cli_usage_error("--shutter: expected OPEN,CLOSE (frames, each in -4..4, OPEN <= CLOSE) or "
                                            "off, got '%s'", v);
        } else if (!strcmp(s, "--od-spacing")) {
            char across[64];
            const char* comma = strchr(v, ',');
            size_t n = comma ? (size_t)(comma - v) : strlen(v);
            int ok = n < sizeof across;
            if (ok) {
                memcpy(across, v, n);
                across[n] = '\0';
                ok = veil_cli_parse_float(across, 0.1f, 16.0f, &a->sun_across) &&
                     veil_cli_parse_float(comma ? comma + 1 : across, 0.1f, 16.0f, &a->sun_along);
            }
            if (!ok)
                return veil_cli_usage_error("--od-spacing: expected ACROSS[,ALONG] in voxels, each in 0.1..16, got '%s'", v);
        } else if (s[0] == '-' && s[1]) return veil_cli_usage_error("unknown option '%s'", s);
        else if (!a->scene) { a->scene = s; continue; }
        else return veil_cli_usage_error("unexpected argument '%s'", s);
        ++i;
    }
    if (!a->scene) return veil_cli_usage_error("%s", "render: missing SCENE.json");
    if (!a->exr && !a->explain) return veil_cli_usage_error("%s", "render: missing -o OUT.exr");
    if (a->deep_samples && !a->deep) return veil_cli_usage_error("%s", "--deep-samples: needs --deep OUT.exr");
    return -1;
}

static int explain(const render_args* a)
{
    veil_error err = {0};
    veil_scene scene;
    veil_result r = veil_scene_load(a->scene, &scene, &err);
    if (r != VEIL_OK) return veil_cli_fail(r, &err);
    veil_cli_apply_shutter(&scene, a->shutter_set, a->shutter);
    veil_render_opts opts = {.width = (int)a->width, .height = (int)a->height, .step_voxels = a->step,
                             .seed = (uint32_t)a->seed, .method = a->method, .quality = a->quality,
                             .sun_across = a->sun_across, .sun_along = a->sun_along};
    char* text = NULL;
    r = veil_plan_explain(&scene, &opts, a->frames > 0 ? a->frames : 1, &text, &err);
    if (r != VEIL_OK && veil_cli_exit_code(r) == EXIT_INPUT) veil_cli_prefix_error(&err, a->scene);
    veil_scene_free(&scene);
    if (r != VEIL_OK) return veil_cli_fail(r, &err);
    fputs(text, stdout);
    free(text);
    return EXIT_OK;
}

int veil_cmd_render(int argc, char** argv)
{
    render_args a;
    int rc = parse_render_args(argc, argv, &a);
    if (rc >= 0) return rc;
    if (a.explain) return explain(&a);
    double t_start = veil_now_ms();
    veil_error err = {0};
    veil_scene scene;
    veil_result r = veil_scene_load(a.scene, &scene, &err);
    if (r != VEIL_OK) return veil_cli_fail(r, &err);
    veil_cli_apply_shutter(&scene, a.shutter_set, a.shutter);
    /* the run's files before any work (cli/run_files.h): the scene and what it reads, every frame's EXR and
     * PNG of --turntable N (OUT_0000.exr ...) and their staging names (issue 22: s_0001.json was
     * overwritten); then their folders, made */
    int n = 0;
    veil_run_file* files = veil_cli_scene_inputs(a.scene, &scene, 0, 3, &n);
    if (!files) {
        veil_scene_free(&scene);
        return veil_cli_fail(veil_fail(&err, VEIL_ERR_OOM, "out of memory"), &err);
    }
    char staged[48];
    snprintf(staged, sizeof staged, ".veil-staged%ld", (long)getpid()); /* veil_cli_stage's */
    veil_run_naming naming = a.frames > 0 ? VEIL_RUN_NUMBERED : VEIL_RUN_ONE;
    files[n++] = (veil_run_file){.what = "-o", .path = a.exr, .naming = naming, .writes = 1, .staged = staged};
    if (a.png)
        files[n++] = (veil_run_file){.what = "--png", .path = a.png, .naming = naming, .writes = 1, .staged = staged};
    if (a.deep)
        files[n++] = (veil_run_file){.what = "--deep", .path = a.deep, .naming = naming, .writes = 1, .staged = staged};
    const veil_frame_range turntable = {0, a.frames - 1, 1};
    veil_cli_folders made = {0};
    rc = veil_cli_check_run(files, n, a.frames > 0 ? &turntable : NULL);
    if (rc == EXIT_OK) {
        r = veil_cli_make_folders(files, n, a.frames > 0 ? &turntable : NULL, &made, &err);
        if (r != VEIL_OK) rc = veil_cli_fail(r, &err);
    }
    free(files);
    if (rc != EXIT_OK) {
        veil_scene_free(&scene);
        return rc;
    }

    veil_renderer* ren = NULL;
    /* its GL context is made once the sources are open and their work estimated: a refusal costs none */
    r = veil_renderer_create_deferred(NULL, &ren, &err);
    long frames = a.frames > 0 ? a.frames : 1;
    veil_image_set im = {0};
    veil_cli_writer* writer = NULL;
    char last[8300] = "";
    for (long f = 0; f < frames && r == VEIL_OK; ++f) {
        veil_camera cam = veil_camera_of_frame(&scene.camera, f, frames);
        veil_render_opts opts = {.width = (int)a.width, .height = (int)a.height, .step_voxels = a.step,
                                 .seed = (uint32_t)a.seed, .method = a.method, .quality = a.quality,
                                 .sun_across = a.sun_across, .sun_along = a.sun_along, .camera = &cam,
                                 .deep = a.deep != NULL, .deep_samples = (int)a.deep_samples,
                                 .flat_only = !a.aovs};
        veil_render_stats st = {0};
        char label[64] = "";
        if (frames > 1) snprintf(label, sizeof label, "frame %ld/%ld", f + 1, frames);
        veil_cli_progress_begin(label);
        r = veil_render_scene_images(ren, &scene, &opts, &im, &st, &err);
        veil_cli_progress_end();
        if (r != VEIL_OK && veil_cli_exit_code(r) == EXIT_INPUT) veil_cli_prefix_error(&err, a.scene);
        char exr[4096], png[4096], deep[4096];
        if (r == VEIL_OK) r = veil_frame_path(a.exr, f, a.frames > 0, exr, sizeof exr, &err);
        if (r == VEIL_OK && a.png) r = veil_frame_path(a.png, f, a.frames > 0, png, sizeof png, &err);
        if (r == VEIL_OK && a.deep) r = veil_frame_path(a.deep, f, a.frames > 0, deep, sizeof deep, &err);
        const veil_exr_meta meta = {.format = a.exr_format};
        if (frames > 1) { /* a turntable's frame is written on its own thread while the next renders */
            if (r == VEIL_OK)
                r = veil_cli_hand_over(&writer, a.stats, &st, &im, f, exr, a.png ? png : NULL, a.deep ? deep : NULL,
                                       a.aovs, &meta, &err);
            if (r != VEIL_OK) break;
            if (f == frames - 1) snprintf(last, sizeof last, "%s%s%s", exr, a.png ? " and " : "", a.png ? png : "");
            continue;
        }
        double t_write = veil_now_ms();
        if (r == VEIL_OK) r = veil_cli_write_frame(&im, exr, a.png ? png : NULL, a.deep ? deep : NULL, a.aovs, &meta, &err);
        if (r != VEIL_OK) break;
        if (a.stats) {
            veil_cli_print_stages(&st);
            if (a.deep) veil_cli_print_deep(&st.deep);
            printf("write      %9.2f ms\n", veil_now_ms() - t_write);
        }
        printf("wrote %s%s%s in %.2f s\n", exr, a.png ? " and " : "", a.png ? png : "", (veil_now_ms() - t_start) * 1e-3);
    }
    veil_error werr = {0};
    veil_result wr = veil_cli_writer_finish(writer, NULL, NULL, &werr); /* the last frames written */
    if (r == VEIL_OK && wr != VEIL_OK) r = wr, err = werr;
    if (r == VEIL_OK && frames > 1)
        printf("wrote frames up to %s in %.2f s\n", last, (veil_now_ms() - t_start) * 1e-3);
    veil_image_set_free(&im);
    veil_renderer_destroy(ren);
    veil_scene_free(&scene);
    veil_cli_folders_done(&made, r == VEIL_OK); /* failed: the folders it made for nothing go */
    return r == VEIL_OK ? EXIT_OK : veil_cli_fail(r, &err);
}
