/* veil turntable: many frames of one scene, the camera on an orbit, frame
 * numbers and ranges as film tools use them, shards for a render farm. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli_util.h"
#include "commands.h"
#include "frame_out.h"
#include "progress.h"
#include "review.h"
#include "core/clock.h"
#include "core/hash.h"
#include "frame/frames.h"
#include "frame/plan.h"
#include "frame/renderer.h"
#include "gpu/gl_context.h"
#include "io/image.h"
#include "io/scene.h"
#include "scene/camera.h"

typedef struct tt_args {
    const char *scene, *exr, *png, *movie, *sheet, *deep;
    long deep_samples;
    float fps;
    long width, height, seed, frames;
    veil_frame_range range;
    int have_range, shard, shards, skip_existing, skip_missing, stats, explain, aovs;
    float step, sun_across, sun_along;
    veil_opv_method method;
    veil_quality quality;
    veil_orbit orbit;
    int shutter_set; /* --shutter: 1 the values, -1 off, 0 the scene's */
    float shutter[2];
    veil_exr_format exr_format;
} tt_args;

static int parse_vec3(const char* v, float out[3])
{
    char extra;
    return sscanf(v, "%f,%f,%f%c", &out[0], &out[1], &out[2], &extra) == 3 && isfinite(out[0]) && isfinite(out[1]) &&
           isfinite(out[2]);
}

static int parse_args(int argc, char** argv, tt_args* a)
{
    memset(a, 0, sizeof *a);
    a->orbit.degrees = 360.0f;
    a->fps = 24.0f;
    a->shard = a->shards = 1;
    for (int i = 2; i < argc; ++i) {
        const char* s = argv[i];
        const char* v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(s, "--stats")) { a->stats = 1; continue; }
        if (!strcmp(s, "--explain")) { a->explain = 1; continue; }
        if (!strcmp(s, "--aovs")) { a->aovs = 1; continue; }
        if (!strcmp(s, "--skip-existing")) { a->skip_existing = 1; continue; }
        if (!strcmp(s, "--skip-missing")) { a->skip_missing = 1; continue; }
        if (!strcmp(s, "--quiet")) { veil_cli_progress_mode(-1); continue; }
        if (!strcmp(s, "--progress")) { veil_cli_progress_mode(1); continue; }
        int xrc; /* the EXR's storage (cli/cli_util.h) */
        if ((!strcmp(s, "--exr-type") || !strcmp(s, "--exr-compression") || !strcmp(s, "--dwa-level")) &&
            veil_cli_exr_option(s, v, &a->exr_format, &xrc)) {
            if (xrc >= 0) return xrc;
            ++i;
            continue;
        }
        if (s[0] != '-' || !s[1]) {
            if (a->scene) return veil_cli_usage_error("unexpected argument '%s'", s);
            a->scene = s;
            continue;
        }
        if (!v) return veil_cli_usage_error("%s needs a value (or is unknown)", s);
        veil_error err = {0};
        if (!strcmp(s, "-o")) a->exr = v;
        else if (!strcmp(s, "--png")) a->png = v;
        else if (!strcmp(s, "--deep")) a->deep = v;
        else if (!strcmp(s, "--deep-samples")) {
            if (!veil_cli_parse_int(v, 1, VEIL_DEEP_MAX_SAMPLES, &a->deep_samples))
                return veil_cli_usage_error("--deep-samples: expected samples a pixel in 1..64, got '%s'", v);
        }
        else if (!strcmp(s, "--movie")) a->movie = v;
        else if (!strcmp(s, "--contact-sheet")) a->sheet = v;
        else if (!strcmp(s, "--fps")) {
            if (!veil_cli_parse_float(v, 0.1f, 1000.0f, &a->fps)) return veil_cli_usage_error("--fps: expected frames a second in 0.1..1000, got '%s'", v);
        }
        else if (!strcmp(s, "--frames")) {
            if (!veil_cli_parse_int(v, 1, VEIL_MAX_FRAMES, &a->frames))
                return veil_cli_usage_error("--frames: expected a number of frames in 1..10000000, got '%s'", v);
        } else if (!strcmp(s, "--range")) {
            if (veil_frame_range_parse(v, &a->range, &err) != VEIL_OK) return veil_cli_usage_error("--range: %s", err.msg);
            a->have_range = 1;
        } else if (!strcmp(s, "--shard")) {
            if (veil_shard_parse(v, &a->shard, &a->shards, &err) != VEIL_OK) return veil_cli_usage_error("--shard: %s", err.msg);
        } else if (!strcmp(s, "--axis")) {
            if (!parse_vec3(v, a->orbit.axis) ||
                !(fabsf(a->orbit.axis[0]) + fabsf(a->orbit.axis[1]) + fabsf(a->orbit.axis[2]) > 0.0f))
                return veil_cli_usage_error("--axis: expected a non-zero X,Y,Z, got '%s'", v);
        } else if (!strcmp(s, "--start")) {
            if (!veil_cli_parse_float(v, -36000.0f, 36000.0f, &a->orbit.start_deg))
                return veil_cli_usage_error("--start: expected degrees in -36000..36000, got '%s'", v);
        } else if (!strcmp(s, "--degrees")) {
            if (!veil_cli_parse_float(v, -36000.0f, 36000.0f, &a->orbit.degrees))
                return veil_cli_usage_error("--degrees: expected degrees in -36000..36000, got '%s'", v);
        } else if (!strcmp(s, "--elevation")) {
            if (!veil_cli_parse_float(v, -89.0f, 89.0f, &a->orbit.elevation_deg))
                return veil_cli_usage_error("--elevation: expected degrees in -89..89, got '%s'", v);
        } else if (!strcmp(s, "--width")) {
            if (!veil_cli_parse_int(v, 1, VEIL_SCENE_MAX_IMAGE, &a->width)) return veil_cli_usage_error("--width: expected an integer in 1..16384, got '%s'", v);
        } else if (!strcmp(s, "--height")) {
            if (!veil_cli_parse_int(v, 1, VEIL_SCENE_MAX_IMAGE, &a->height)) return veil_cli_usage_error("--height: expected an integer in 1..16384, got '%s'", v);
        } else if (!strcmp(s, "--step")) {
            if (!veil_cli_parse_float(v, 0.01f, 16.0f, &a->step)) return veil_cli_usage_error("--step: expected a number of voxels in 0.01..16, got '%s'", v);
        } else if (!strcmp(s, "--seed")) {
            if (!veil_cli_parse_int(v, 0, 4294967295L, &a->seed)) return veil_cli_usage_error("--seed: expected an integer in 0..4294967295, got '%s'", v);
        } else if (!strcmp(s, "--method")) {
            if (!veil_opv_method_parse(v, &a->method))
                return veil_cli_usage_error("--method: expected default, jacobi, jacobi-corrected, sweep, semi-lagrangian or light-space, got '%s'", v);
        } else if (!strcmp(s, "--shutter")) {
            if (!veil_cli_parse_shutter(v, &a->shutter_set, a->shutter))
                return veil_cli_usage_error("--shutter: expected OPEN,CLOSE (frames, each in -4..4, OPEN <= CLOSE) or "
                                            "off, got '%s'", v);
        } else if (!strcmp(s, "--quality")) {
            if (!veil_quality_parse(v, &a->quality))
                return veil_cli_usage_error("--quality: expected draft, default, high or max, got '%s'", v);
        } else {
            return veil_cli_usage_error("unknown option '%s'", s);
        }
        ++i;
    }
    if (!a->scene) return veil_cli_usage_error("%s", "turntable: missing SCENE.json");
    if (!a->exr && !a->explain) return veil_cli_usage_error("%s", "turntable: missing -o OUT.####.exr");
    if (a->frames && a->have_range) return veil_cli_usage_error("%s", "turntable: --frames and --range: give one");
    if (!a->have_range) a->range = (veil_frame_range){1, a->frames ? a->frames : 1, 1};
    if (a->exr && veil_frame_pattern_kind(a->exr) != 1)
        return veil_cli_usage_error("-o: '%s' needs the frame number once, as #### or %%04d", a->exr);
    if (a->movie) { /* what veil_review_movie makes, known before any frame is rendered */
        const char* dot = strrchr(a->movie, '.');
        if (!dot || (strcmp(dot, ".mp4") && strcmp(dot, ".mov") && strcmp(dot, ".mkv") && strcmp(dot, ".gif")))
            return veil_cli_usage_error("--movie: '%s': expected a .mp4, .mov, .mkv or .gif file", a->movie);
    }
    if (a->png && veil_frame_pattern_kind(a->png) != 1)
        return veil_cli_usage_error("--png: '%s' needs the frame number once, as #### or %%04d", a->png);
    if (a->deep && veil_frame_pattern_kind(a->deep) != 1)
        return veil_cli_usage_error("--deep: '%s' needs the frame number once, as #### or %%04d", a->deep);
    if (a->deep_samples && !a->deep) return veil_cli_usage_error("%s", "--deep-samples: needs --deep OUT.####.exr");
    return -1;
}

static veil_render_opts opts_of(const tt_args* a, long frame, const veil_camera* cam)
{
    return (veil_render_opts){.width = (int)a->width, .height = (int)a->height, .step_voxels = a->step,
                              .seed = veil_frame_seed((uint32_t)a->seed, frame), .method = a->method,
                              .quality = a->quality, .sun_across = a->sun_across, .sun_along = a->sun_along,
                              .camera = cam, .deep = a->deep != NULL, .deep_samples = (int)a->deep_samples,
                              .flat_only = !a->aovs};
}

/* FNV-1a of the scene file's bytes (0 when it cannot be read: it was, a moment ago). */
static uint64_t file_hash(const char* path)
{
    FILE* f = fopen(path, "rb");
    if (!f) return 0;
    uint64_t h = VEIL_FNV_OFFSET;
    unsigned char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0) h = veil_hash_bytes(h, buf, n);
    fclose(f);
    return h;
}

static int exists(const char* path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* A regular file that begins with `magic` (n bytes): a frame --skip-existing may count as done. A file of
 * another kind under the frame's name (a PNG written there by a clash of names, issue 22) is not. */
static int exists_as(const char* path, const unsigned char* magic, size_t n)
{
    unsigned char head[8];
    FILE* f = exists(path) ? fopen(path, "rb") : NULL;
    if (!f) return 0;
    int ok = n <= sizeof head && fread(head, 1, n, f) == n && !memcmp(head, magic, n);
    fclose(f);
    return ok;
}

static const unsigned char EXR_MAGIC[4] = {0x76, 0x2f, 0x31, 0x01};                       /* OpenEXR's */
static const unsigned char PNG_MAGIC[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a}; /* PNG's signature */

/* The files of the run, checked before any frame (cli/run_files.h): the scene and every file it reads over
 * the range, each frame's EXR and PNG and their staging names, the contact sheet, the movie and its
 * scratch names; then the review outputs' limits and ffmpeg; then the outputs' folders, made. */
static int prepare_files(const tt_args* a, const veil_scene* scene, long count, veil_cli_folders* made)
{
    if ((a->movie || a->sheet) && count > VEIL_REVIEW_MAX_FRAMES) {
        char what[160];
        snprintf(what, sizeof what, "%s: the range has %ld frames; a movie or a contact sheet takes at most %d",
                 a->movie ? "--movie" : "--contact-sheet", count, VEIL_REVIEW_MAX_FRAMES);
        return veil_cli_usage_error("%s", what);
    }
    int n = 0;
    veil_run_file* files = veil_cli_scene_inputs(a->scene, scene, 1, 7, &n);
    veil_error err = {0};
    if (!files) return veil_cli_fail(veil_fail(&err, VEIL_ERR_OOM, "out of memory"), &err);
    char staged[48], movie_staged[4200], movie_frames[4200];
    snprintf(staged, sizeof staged, ".veil-staged%ld", (long)getpid()); /* veil_cli_stage's */
    files[n++] = (veil_run_file){.what = "-o", .path = a->exr, .naming = VEIL_RUN_PATTERN, .writes = 1,
                                 .staged = staged};
    if (a->png)
        files[n++] = (veil_run_file){.what = "--png", .path = a->png, .naming = VEIL_RUN_PATTERN, .writes = 1,
                                     .staged = staged};
    if (a->deep)
        files[n++] = (veil_run_file){.what = "--deep", .path = a->deep, .naming = VEIL_RUN_PATTERN, .writes = 1,
                                     .staged = staged};
    if (a->sheet) files[n++] = (veil_run_file){.what = "--contact-sheet", .path = a->sheet, .writes = 1};
    if (a->movie) {
        veil_review_movie_names(a->movie, movie_staged, sizeof movie_staged, movie_frames, sizeof movie_frames);
        files[n++] = (veil_run_file){.what = "--movie", .path = a->movie, .writes = 1};
        files[n++] = (veil_run_file){.what = "--movie's staging file", .path = movie_staged, .writes = 1};
        files[n++] = (veil_run_file){.what = "--movie's folder of frames", .path = movie_frames, .writes = 1,
                                     .scratch = 1};
    }
    /* every frame of the range, whichever shard renders it: the shards are one run */
    int rc = veil_cli_check_run(files, n, &a->range);
    char ffmpeg[4096];
    if (rc == EXIT_OK && a->movie && !veil_review_find_ffmpeg(ffmpeg, sizeof ffmpeg))
        rc = veil_cli_fail(veil_fail(&err, VEIL_ERR_IO, "%s: a movie needs the ffmpeg program (Debian package ffmpeg), "
                                     "and there is none on PATH; nothing was rendered", a->movie), &err);
    /* the folders of this shard's frames and of the review outputs */
    veil_frame_range mine = {a->range.first + (a->shard - 1) * a->range.step, a->range.last,
                             a->range.step * a->shards};
    veil_result r = VEIL_OK;
    if (rc == EXIT_OK) r = veil_cli_make_folders(files, n, mine.first <= mine.last ? &mine : NULL, made, &err);
    if (r != VEIL_OK) rc = veil_cli_fail(r, &err);
    free(files);
    return rc;
}

/* The contact sheet and the movie, from every frame of the range (rendered by this run or others). */
static veil_result review(const tt_args* a, long count, veil_error* err)
{
    if (count > VEIL_REVIEW_MAX_FRAMES) /* refused before any frame (prepare_files): kept for the sizes below */
        return veil_fail(err, VEIL_ERR_LIMIT, "a movie or sheet of %ld frames: at most %d", count, VEIL_REVIEW_MAX_FRAMES);
    char** names = calloc((size_t)count, sizeof *names);
    if (!names) return veil_fail(err, VEIL_ERR_OOM, "out of memory");
    veil_result r = VEIL_OK;
    long missing = 0, first_missing = 0;
    for (long i = 0; i < count && r == VEIL_OK; ++i) {
        char path[4096];
        long frame = veil_frame_range_at(&a->range, i);
        r = veil_frame_pattern_path(a->exr, frame, path, sizeof path, err);
        if (r == VEIL_OK && !exists(path) && !missing++) first_missing = frame;
        if (r == VEIL_OK && !(names[i] = malloc(strlen(path) + 1))) r = veil_fail(err, VEIL_ERR_OOM, "out of memory");
        if (r == VEIL_OK) strcpy(names[i], path);
    }
    if (r == VEIL_OK && missing)
        r = veil_fail(err, VEIL_ERR_IO, "%s: %ld of the range's %ld frames are not written yet (frame %ld first); the "
                      "movie and the contact sheet need them all (render the other shards first, then rerun with "
                      "--skip-existing)", a->exr, missing, count, first_missing);
    double t0 = veil_now_ms();
    if (r == VEIL_OK && a->sheet) r = veil_review_contact_sheet((const char* const*)names, (int)count, a->sheet, err);
    if (r == VEIL_OK && a->sheet) printf("wrote the contact sheet %s in %.2f s\n", a->sheet, (veil_now_ms() - t0) * 1e-3);
    t0 = veil_now_ms();
    if (r == VEIL_OK && a->movie) r = veil_review_movie((const char* const*)names, (int)count, a->fps, a->movie, err);
    if (r == VEIL_OK && a->movie) {
        struct stat st;
        printf("wrote the movie %s (%lld bytes, %ld frames at %g fps) in %.2f s\n", a->movie,
               stat(a->movie, &st) == 0 ? (long long)st.st_size : -1LL, count, a->fps, (veil_now_ms() - t0) * 1e-3);
    }
    for (long i = 0; i < count; ++i) free(names[i]);
    free(names);
    return r;
}

int veil_cmd_turntable(int argc, char** argv)
{
    tt_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) return rc;
    veil_error err = {0};
    veil_scene scene;
    veil_result r = veil_scene_load(a.scene, &scene, &err);
    if (r != VEIL_OK) return veil_cli_fail(r, &err);
    veil_cli_apply_shutter(&scene, a.shutter_set, a.shutter);
    long count = veil_frame_range_count(&a.range);
    if (a.explain) {
        veil_render_opts opts = opts_of(&a, a.range.first, NULL);
        char* text = NULL;
        long mine = (count - (a.shard - 1) + a.shards - 1) / a.shards; /* this shard's frames */
        const int sequence = veil_scene_is_sequence(&scene);
        /* a sequence's first frame stands for each of its frames: every one has its own files */
        r = veil_plan_explain(&scene, &opts, sequence || mine < 1 ? 1 : mine, &text, &err);
        if (r == VEIL_OK) {
            printf("frames %ld-%ld step %ld: %ld frames, shard %d/%d renders %ld of them\n", a.range.first, a.range.last,
                   a.range.step, count, a.shard, a.shards, mine);
            if (sequence)
                printf("sequence: a source's file changes with the frame, so every frame runs inject, propagate and "
                       "render, as the first frame's plan below\n");
            fputs(text, stdout);
        }
        for (long i = a.shard - 1; sequence && r == VEIL_OK && i < count; i += a.shards) {
            long frame = veil_frame_range_at(&a.range, i);
            veil_error ferr = {0};
            if (veil_scene_set_frame(&scene, frame, &ferr) == VEIL_OK)
                printf("frame %ld: runs every stage\n", frame);
            else
                printf("frame %ld: %s (%s)\n", frame, ferr.msg, a.skip_missing ? "skipped: --skip-missing" : "an error");
        }
        free(text);
        veil_scene_free(&scene);
        if (r != VEIL_OK && veil_cli_exit_code(r) == EXIT_INPUT) veil_cli_prefix_error(&err, a.scene);
        return r == VEIL_OK ? EXIT_OK : veil_cli_fail(r, &err);
    }
    veil_cli_folders made = {0};
    rc = prepare_files(&a, &scene, count, &made);
    if (rc != EXIT_OK) {
        veil_scene_free(&scene);
        return rc;
    }
    double t_start = veil_now_ms();
    const uint64_t scene_hash = file_hash(a.scene);
    veil_renderer* ren = NULL;
    veil_image_set im = {0};
    long done = 0, skipped = 0, missing = 0;
    double stage_total[VEIL_STAGE_COUNT] = {0}, write_total = 0.0, t_render = 0.0;
    veil_cli_writer* writer = NULL;
    int stage_runs[VEIL_STAGE_COUNT] = {0};
    for (long i = a.shard - 1; i < count && r == VEIL_OK; i += a.shards) {
        long frame = veil_frame_range_at(&a.range, i);
        char exr[4096], png[4096], deep[4096];
        r = veil_frame_pattern_path(a.exr, frame, exr, sizeof exr, &err);
        if (r == VEIL_OK && a.png) r = veil_frame_pattern_path(a.png, frame, png, sizeof png, &err);
        if (r == VEIL_OK && a.deep) r = veil_frame_pattern_path(a.deep, frame, deep, sizeof deep, &err);
        if (r != VEIL_OK) break;
        /* complete: frames are renamed into place, so an EXR, a PNG and a deep EXR there are whole */
        if (a.skip_existing && exists_as(exr, EXR_MAGIC, 4) && (!a.png || exists_as(png, PNG_MAGIC, 8)) &&
            (!a.deep || exists_as(deep, EXR_MAGIC, 4))) {
            ++skipped;
            continue;
        }
        r = veil_scene_set_frame(&scene, frame, &err); /* an animated source's file of this frame */
        if (r == VEIL_ERR_IO && a.skip_missing) {
            fprintf(stderr, "veil: %s: %s (skipped)\n", a.scene, err.msg);
            r = VEIL_OK;
            ++missing;
            continue;
        }
        if (r != VEIL_OK) {
            veil_cli_prefix_error(&err, a.scene);
            break;
        }
        if (!ren) { /* made on the first frame to render: a rerun with every frame done needs no GPU, and its
                     * GL context once that frame's sources are open and their work estimated */
            r = veil_renderer_create_deferred(NULL, &ren, &err);
            if (r != VEIL_OK) break;
            t_render = veil_now_ms();
        }
        veil_camera cam = veil_orbit_camera(&scene.camera, &a.orbit, i, count);
        veil_render_opts opts = opts_of(&a, frame, &cam);
        veil_render_stats st = {0};
        char label[96], eta[40] = "";
        long mine = (count - (a.shard - 1) + a.shards - 1) / a.shards, left = mine - done - skipped - missing;
        if (done > 0) /* the frames rendered so far, at their mean pace */
            snprintf(eta, sizeof eta, ", about %.0f s left", (veil_now_ms() - t_render) * 1e-3 / (double)done * (double)left);
        snprintf(label, sizeof label, "frame %ld (%ld of %ld%s)", frame, done + skipped + missing + 1, mine, eta);
        veil_cli_progress_begin(label);
        r = veil_render_scene_images(ren, &scene, &opts, &im, &st, &err);
        veil_cli_progress_end();
        if (r != VEIL_OK && veil_cli_exit_code(r) == EXIT_INPUT) veil_cli_prefix_error(&err, a.scene);
        /* the header a compositor reads: the frame, the camera, what made the image */
        veil_render_opts used = veil_render_opts_resolve(&opts, &scene);
        veil_exr_meta meta = {.has_frame = 1, .frame = (int)frame, .format = a.exr_format};
        veil_camera_basis basis;
        if (r == VEIL_OK && veil_camera_make_basis(&cam, used.width, used.height, &basis, NULL) == VEIL_OK) {
            veil_camera_exr_matrices(&basis, meta.world_to_camera, meta.world_to_ndc);
            meta.has_camera = 1;
        }
        char hash[32], settings[256], software[64];
        snprintf(hash, sizeof hash, "%016llx", (unsigned long long)scene_hash);
        snprintf(settings, sizeof settings, "quality %s, step %g voxels, method %s, od-spacing %g,%g, seed %u, %dx%d",
                 veil_quality_name(used.quality), used.step_voxels, veil_opv_method_name(used.method), used.sun_across,
                 used.sun_along, used.seed, used.width, used.height);
        snprintf(software, sizeof software, "veil %s", VEIL_VERSION);
        const char* strings[4][2] = {{"software", software}, {"veil:scene", a.scene}, {"veil:sceneHash", hash},
                                     {"veil:settings", settings}};
        memcpy(meta.strings, strings, sizeof strings);
        meta.n_strings = 4;
        /* the frame's files all or nothing, renamed into place, on the writer's thread while the next frame
         * renders (cli/frame_out.h) */
        if (r == VEIL_OK)
            r = veil_cli_hand_over(&writer, a.stats, &st, &im, frame, exr, a.png ? png : NULL, a.deep ? deep : NULL,
                                   a.aovs, &meta, &err);
        if (r != VEIL_OK) break;
        ++done;
        for (int k = 0; k < VEIL_STAGE_COUNT; ++k) {
            stage_total[k] += st.stage[k].ms;
            stage_runs[k] += st.stage[k].status == VEIL_STAGE_RAN;
        }
    }
    double waited = 0.0;
    veil_error werr = {0};
    veil_result wr = veil_cli_writer_finish(writer, &write_total, &waited, &werr); /* the last frame written */
    if (r == VEIL_OK && wr != VEIL_OK) r = wr, err = werr;
    if (r == VEIL_OK && a.stats && done > 1) { /* the whole run: what ran how often, and its time */
        printf("total over %ld frames\n", done);
        for (int k = 0; k < VEIL_STAGE_COUNT; ++k)
            printf("%-10s %9.2f ms  (ran on %d of %ld frames)\n", veil_stage_name((veil_stage_id)k), stage_total[k],
                   stage_runs[k], done);
        printf("write      %9.2f ms  (on its own thread beside the renders; they waited %.2f ms for it)\n",
               write_total, waited);
    }
    if (r == VEIL_OK && (a.movie || a.sheet)) r = review(&a, count, &err);
    if (r == VEIL_OK) {
        char step[32] = "";
        if (a.range.step > 1) snprintf(step, sizeof step, "x%ld", a.range.step);
        char miss[64] = "";
        if (missing) snprintf(miss, sizeof miss, ", %ld without their source files", missing);
        printf("turntable: %ld frames rendered, %ld already there%s, shard %d/%d of frames %ld-%ld%s, in %.2f s\n",
               done, skipped, miss, a.shard, a.shards, a.range.first, a.range.last, step,
               (veil_now_ms() - t_start) * 1e-3);
    }
    veil_image_set_free(&im);
    veil_renderer_destroy(ren);
    veil_scene_free(&scene);
    veil_cli_folders_done(&made, r == VEIL_OK); /* failed: the folders it made for nothing go */
    return r == VEIL_OK ? EXIT_OK : veil_cli_fail(r, &err);
}
