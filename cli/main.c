/* veil — the command-line tool.
 *
 *   veil render SCENE.json -o OUT.exr [--png OUT.png] [--width W] [--height H]
 *               [--step S] [--seed N] [--method M] [--turntable N] [--stats]
 *   veil gpuinfo
 *   veil info FILE.vdb [--json]
 *   veil rbf generate -o OUT --count N --seed S --bounds x0,y0,z0,x1,y1,z1
 *               --radius r0,r1 --amplitude c0,c1 [--noise-scale L]
 *               [--noise-octaves K] [--noise-amount A] [--format json|binary]
 *   veil --help | --version
 *
 * Exit codes: 0 success, 1 bad input (scene, file), 2 usage, 3 GPU/driver.
 * Messages go to stderr; the written paths and the time to stdout.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/image.h"
#include "io/particles.h"
#include "io/scene.h"
#include "io/vdb.h"
#include "gpu/gl_context.h"
#include "gpu/gl_util.h"
#include "frame/renderer.h"
#include "cli_util.h"
#include "commands.h"


static const char* usage_text =
    "usage: veil render SCENE.json -o OUT.exr [--png OUT.png] [--width W] [--height H]\n"
    "                   [--step S] [--seed N] [--method M] [--turntable N] [--stats]\n"
    "       veil reference SCENE.json -o REF.exr --spp N [--max-order K] [--width W]\n"
    "                [--height H] [--seed N] [--threads T]\n"
    "       veil compare A.exr REF.exr [--heatmap OUT.png] [--floor F] [--json]\n"
    "       veil gpuinfo\n"
    "       veil info FILE.vdb [--json]\n"
    "       veil rbf generate -o OUT --count N --seed S --bounds x0,y0,z0,x1,y1,z1\n"
    "                --radius r0,r1 --amplitude c0,c1 [--noise-scale L] [--noise-octaves K]\n"
    "                [--noise-amount A] [--format json|binary]\n"
    "       veil --help | --version\n"
    "\n"
    "render   renders a scene (docs/scene-format.md) to an HDR EXR (R, G, B, A = 1 - mean\n"
    "         transmittance) and optionally a tone-mapped sRGB PNG preview.\n"
    "  -o OUT.exr     output EXR (required)\n"
    "  --png OUT.png  also write a preview PNG\n"
    "  --width W, --height H  override the scene camera's image size (1..16384)\n"
    "  --step S       ray-march step in voxels (default 0.5)\n"
    "  --seed N       jitter seed (default 0)\n"
    "  --method M     optical-depth propagation: semi-lagrangian (default), sweep,\n"
    "                 jacobi-corrected, jacobi (the published scheme)\n"
    "  --turntable N  N frames with the camera orbiting the look-at point about the\n"
    "                 up axis, written as OUT_0000.exr ... (volume and optical depth\n"
    "                 are computed once and reused: see --stats)\n"
    "  --stats        print the wall time of each stage in milliseconds\n"
    "reference  renders a scene with the CPU path tracer (reference/pathtracer.h), the\n"
    "         ground truth the GPU path is measured against. The EXR holds R, G, B, A and\n"
    "         the per-pixel standard error of each mean (stderr.R, stderr.G, stderr.B).\n"
    "  --spp N        samples per pixel (2..1000000, required)\n"
    "  --max-order K  scatterings counted: 1 single scattering (the GPU marcher's\n"
    "                 quantity), 0 all (default 0)\n"
    "  --seed N       (default 0); the same seed gives the same image on any thread count\n"
    "  --threads T    worker threads (default: one per core)\n"
    "compare  compares image A against reference REF (both EXR, same size): relative\n"
    "         RMSE (denominator floored at --floor, default 1% of REF's mean), max abs\n"
    "         error, fraction of pixels more than 5% off, PSNR.\n"
    "  --floor F      the denominator's floor, absolute (default 1% of REF's mean RGB)\n"
    "  --heatmap OUT.png  per-pixel relative error as a colour map, log scale:\n"
    "                 black 1e-4 (and 0), blue 1e-3, magenta 1e-2, yellow 1e-1, white 1\n"
    "  --json         print the numbers as JSON (psnr_db null for identical RGB)\n"
    "gpuinfo  prints the EGL platform and device, GL vendor, renderer, version and\n"
    "         the largest 3D texture. VEIL_DEVICE=software forces llvmpipe.\n"
    "info     lists the grids of an OpenVDB file: name, class, value type, active\n"
    "         voxels, index and world bounding boxes, voxel size and transform.\n"
    "  --json         print them as JSON instead of a table\n"
    "rbf generate  writes a seeded random particle file (docs/particles.md) for an\n"
    "         \"rbf\" source's \"file\": N particles (0..10000000), centres uniform in\n"
    "         the box, radius (1/sharpness, m) and amplitude uniform in their ranges;\n"
    "         the same seed (0..2^53-1) gives the same file on every machine.\n"
    "  --noise-amount A  0..1 (default 0): amplitude *= (1-A) + A*fbm(centre/L)\n"
    "  --noise-scale L   fBm feature size in metres (default 1)\n"
    "  --noise-octaves K fBm octaves, 1..16 (default 4)\n"
    "  --format F     json or binary (default: json when OUT ends in .json)\n"
    "\n"
    "exit codes: 0 success, 1 bad input, 2 usage, 3 GPU or driver failure\n";

static int cmd_gpuinfo(void)
{
    veil_gl* gl = NULL;
    veil_error err = {0};
    veil_result r = veil_gl_create(NULL, &gl, &err);
    if (r != VEIL_OK) {
        fprintf(stderr, "veil: no OpenGL 4.5 context: %s\n", err.msg);
        return EXIT_GPU;
    }
    const veil_gl_info* i = veil_gl_get_info(gl);
    printf("EGL platform:      %s\n", i->platform);
    printf("EGL device:        %s (%s)\n", i->device, i->hardware ? "hardware" : "software");
    printf("GL vendor:         %s\n", i->vendor);
    printf("GL renderer:       %s\n", i->renderer);
    printf("GL version:        %s\n", i->version);
    printf("max 3D texture:    %d\n", i->max_3d_texture_size);
    veil_gl_destroy(gl);
    return EXIT_OK;
}

static void print_info_grid(const veil_vdb_grid_info* g)
{
    printf("\ngrid '%s'\n", g->name);
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
    printf("  transform    %s%s\n", g->map_type, g->affine ? " (index to world, column vectors)" : " (not affine)");
    for (int r = 0; g->affine && r < 4; ++r)
        printf("               [%10.6g %10.6g %10.6g %10.6g]\n", g->index_to_world[r][0], g->index_to_world[r][1],
               g->index_to_world[r][2], g->index_to_world[r][3]);
}

static int cmd_info(int argc, char** argv)
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
    for (size_t i = 0; i < n; ++i) w = (int)strlen(grids[i].name) > w ? (int)strlen(grids[i].name) : w;
    printf("%s: %zu grid%s\n\n", path, n, n == 1 ? "" : "s");
    printf("  %-*s  %-10s  %-8s  %13s  %s\n", w, "name", "class", "type", "active voxels", "voxel size (m)");
    for (size_t i = 0; i < n; ++i) {
        const veil_vdb_grid_info* g = &grids[i];
        char vs[96];
        if (fabs(g->voxel_size[0] - g->voxel_size[1]) <= 1e-9 * g->voxel_size[0] &&
            fabs(g->voxel_size[1] - g->voxel_size[2]) <= 1e-9 * g->voxel_size[0]) /* uniform, up to rounding */
            snprintf(vs, sizeof vs, "%g", g->voxel_size[0]);
        else
            snprintf(vs, sizeof vs, "%g x %g x %g", g->voxel_size[0], g->voxel_size[1], g->voxel_size[2]);
        printf("  %-*s  %-10s  %-8s  %13llu  %s\n", w, g->name, g->grid_class, g->value_type,
               (unsigned long long)g->active_voxels, vs);
    }
    for (size_t i = 0; i < n; ++i) print_info_grid(&grids[i]);
    veil_vdb_file_info_free(grids, n);
    return EXIT_OK;
}

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

static int cmd_render(int argc, char** argv)
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

/* veil rbf generate: a seeded random particle file, optionally fBm-modulated. */
static int cmd_rbf(int argc, char** argv)
{
    if (argc < 3 || strcmp(argv[2], "generate") != 0)
        return veil_cli_usage_error("rbf: expected the subcommand 'generate', got '%s'", argc < 3 ? "" : argv[2]);
    const char* out = NULL;
    long count = -1, seed = -1, octaves = 4, format = -1; /* format: -1 by extension, 0 json, 1 binary */
    float v6[6] = {0}, bounds[6] = {0}, radius[2] = {0}, amp[2] = {0}, scale = 1.0f, amount = 0.0f;
    int have_b = 0, have_r = 0, have_a = 0;
    for (int i = 3; i < argc; ++i) {
        const char* s = argv[i];
        const char* v = i + 1 < argc ? argv[i + 1] : NULL;
        int nlist = !strcmp(s, "--bounds") ? 6 : (!strcmp(s, "--radius") || !strcmp(s, "--amplitude")) ? 2 : 0;
        int takes = nlist || !strcmp(s, "-o") || !strcmp(s, "--count") || !strcmp(s, "--seed") ||
                    !strcmp(s, "--noise-scale") || !strcmp(s, "--noise-octaves") || !strcmp(s, "--noise-amount") ||
                    !strcmp(s, "--format");
        if (!takes) {
            if (s[0] == '-' && s[1]) return veil_cli_usage_error("unknown option '%s'", s);
            return veil_cli_usage_error("unexpected argument '%s'", s);
        }
        if (!v) return veil_cli_usage_error("%s needs a value", s);
        ++i;
        if (nlist) { /* comma-separated finite numbers */
            const char* p = v;
            int k = 0;
            for (; k < nlist; ++k) {
                char* end;
                errno = 0;
                v6[k] = strtof(p, &end);
                if (errno || end == p || !isfinite(v6[k])) break;
                if (k + 1 < nlist && *end != ',') break;
                if (k + 1 == nlist && *end) break;
                p = end + 1;
            }
            int ok = k == nlist;
            if (ok && nlist == 6) {
                for (int a = 0; a < 3; ++a) ok = ok && v6[a] <= v6[a + 3];
                if (!ok)
                    return veil_cli_usage_error("--bounds: expected x0,y0,z0,x1,y1,z1 (min and max corner, m) with min <= max, got '%s'", v);
                memcpy(bounds, v6, sizeof bounds), have_b = 1;
            } else if (ok && !strcmp(s, "--radius")) {
                if (!(v6[0] > 0 && v6[0] <= v6[1] && isfinite(1.0f / v6[0])))
                    return veil_cli_usage_error("--radius: expected r0,r1 with 0 < r0 <= r1 (m), got '%s'", v);
                memcpy(radius, v6, sizeof radius), have_r = 1;
            } else if (ok) {
                if (!(v6[0] >= 0 && v6[0] <= v6[1]))
                    return veil_cli_usage_error("--amplitude: expected c0,c1 with 0 <= c0 <= c1, got '%s'", v);
                memcpy(amp, v6, sizeof amp), have_a = 1;
            } else if (nlist == 6) {
                return veil_cli_usage_error("--bounds: expected 6 comma-separated numbers x0,y0,z0,x1,y1,z1, got '%s'", v);
            } else {
                return veil_cli_usage_error(!strcmp(s, "--radius") ? "--radius: expected 2 comma-separated numbers r0,r1, got '%s'"
                                                          : "--amplitude: expected 2 comma-separated numbers c0,c1, got '%s'", v);
            }
        } else if (!strcmp(s, "-o")) out = v;
        else if (!strcmp(s, "--count")) {
            if (!veil_cli_parse_int(v, 0, VEIL_SCENE_MAX_PARTICLES, &count)) return veil_cli_usage_error("--count: expected an integer in 0..10000000, got '%s'", v);
        } else if (!strcmp(s, "--seed")) {
            if (!veil_cli_parse_int(v, 0, 9007199254740991L, &seed)) return veil_cli_usage_error("--seed: expected an integer in 0..2^53-1, got '%s'", v);
        } else if (!strcmp(s, "--noise-octaves")) {
            if (!veil_cli_parse_int(v, 1, 16, &octaves)) return veil_cli_usage_error("--noise-octaves: expected an integer in 1..16, got '%s'", v);
        } else if (!strcmp(s, "--noise-amount")) {
            if (!veil_cli_parse_float(v, 0.0f, 1.0f, &amount)) return veil_cli_usage_error("--noise-amount: expected a number in 0..1, got '%s'", v);
        } else if (!strcmp(s, "--noise-scale")) {
            if (!veil_cli_parse_float(v, 1e-30f, 3.4e38f, &scale)) return veil_cli_usage_error("--noise-scale: expected a length > 0 (m), got '%s'", v);
        } else if (!strcmp(v, "json") || !strcmp(v, "binary")) format = !strcmp(v, "binary");
        else return veil_cli_usage_error("--format: expected json or binary, got '%s'", v);
    }
    if (!out) return veil_cli_usage_error("%s", "rbf generate: missing -o OUT");
    if (count < 0) return veil_cli_usage_error("%s", "rbf generate: missing --count N");
    if (seed < 0) return veil_cli_usage_error("%s", "rbf generate: missing --seed S");
    if (!have_b) return veil_cli_usage_error("%s", "rbf generate: missing --bounds x0,y0,z0,x1,y1,z1");
    if (!have_r) return veil_cli_usage_error("%s", "rbf generate: missing --radius r0,r1");
    if (!have_a) return veil_cli_usage_error("%s", "rbf generate: missing --amplitude c0,c1");
    if (format < 0) {
        size_t n = strlen(out);
        format = !(n >= 5 && !strcmp(out + n - 5, ".json"));
    }
    veil_rbf_random_desc d = {.count = (uint32_t)count, .seed = (uint64_t)seed,
                              .bounds = {{bounds[0], bounds[1], bounds[2]}, {bounds[3], bounds[4], bounds[5]}},
                              .radius = {radius[0], radius[1]}, .amplitude = {amp[0], amp[1]}};
    veil_particle* p = count ? malloc((size_t)count * sizeof *p) : NULL;
    veil_error err = {0};
    if (count && !p) return veil_cli_fail(veil_fail(&err, VEIL_ERR_OOM, "out of memory for %ld particles", count), &err);
    veil_rbf_random_generate(&d, p);
    veil_particles_modulate(p, (size_t)count, (uint64_t)seed, scale, (int)octaves, amount);
    veil_result r = veil_particles_write(out, p, (size_t)count, (int)format, &err);
    free(p);
    if (r != VEIL_OK) return veil_cli_fail(r, &err);
    printf("wrote %s (%ld particles, %s)\n", out, count, format ? "binary" : "json");
    return EXIT_OK;
}

int main(int argc, char** argv)
{
    if (argc < 2) {
        fputs(usage_text, stderr);
        return EXIT_USAGE;
    }
    const char* cmd = argv[1];
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help")) {
        fputs(usage_text, stdout);
        return EXIT_OK;
    }
    if (!strcmp(cmd, "--version")) {
        printf("veil %s\n", VEIL_VERSION);
        return EXIT_OK;
    }
    if (!strcmp(cmd, "render")) return cmd_render(argc, argv);
    if (!strcmp(cmd, "info")) return cmd_info(argc, argv);
    if (!strcmp(cmd, "rbf")) return cmd_rbf(argc, argv);
    if (!strcmp(cmd, "reference")) return veil_cmd_reference(argc, argv);
    if (!strcmp(cmd, "compare")) return veil_cmd_compare(argc, argv);
    if (!strcmp(cmd, "gpuinfo")) {
        if (argc > 2) return veil_cli_usage_error("gpuinfo takes no arguments, got '%s'", argv[2]);
        return cmd_gpuinfo();
    }
    return veil_cli_usage_error("unknown command '%s'", cmd);
}
