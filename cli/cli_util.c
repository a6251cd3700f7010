#include "cli_util.h"
#include "io/image.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/text.h"
#include "io/tempfile.h"

int veil_cli_usage_error(const char* fmt, const char* arg)
{
    fputs("veil: ", stderr);
    fprintf(stderr, fmt, arg);
    fputs("\n(run 'veil --help' for usage)\n", stderr);
    return EXIT_USAGE;
}

int veil_cli_exit_code(veil_result r)
{
    return (r == VEIL_ERR_GPU || r == VEIL_ERR_SHADER) ? EXIT_GPU : EXIT_INPUT;
}

int veil_cli_fail(veil_result r, const veil_error* err)
{
    /* a message may quote a file's bytes (a grid's name): control characters are escaped, lines kept */
    char shown[4 * VEIL_ERROR_MAX];
    veil_text_printable(err->msg[0] ? err->msg : veil_result_message(r), shown, sizeof shown, 1);
    fprintf(stderr, "veil: %s\n", shown);
    return veil_cli_exit_code(r);
}

/* "what went wrong" -> "scene.json: what went wrong", for errors that the
 * scene's content caused but that were found while rendering it. */
void veil_cli_prefix_error(veil_error* err, const char* file)
{
    char tmp[VEIL_ERROR_MAX];
    snprintf(tmp, sizeof tmp, "%.500s: %.1500s", file, err->msg);
    memcpy(err->msg, tmp, sizeof tmp);
}

/* Parses a whole decimal integer in [lo, hi]. */
int veil_cli_parse_int(const char* s, long lo, long hi, long* out)
{
    char* end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi) return 0;
    *out = v;
    return 1;
}

int veil_cli_parse_float(const char* s, float lo, float hi, float* out)
{
    char* end;
    errno = 0;
    float v = strtof(s, &end);
    if (errno || end == s || *end || !(v >= lo && v <= hi)) return 0;
    *out = v;
    return 1;
}

int veil_cli_parse_shutter(const char* s, int* set, float sh[2])
{
    if (!strcmp(s, "off")) {
        *set = -1;
        return 1;
    }
    const char* comma = strchr(s, ',');
    char open[64];
    if (!comma || (size_t)(comma - s) >= sizeof open) return 0;
    memcpy(open, s, (size_t)(comma - s));
    open[comma - s] = '\0';
    const float lim = (float)VEIL_MAX_SHUTTER_FRAMES;
    if (!veil_cli_parse_float(open, -lim, lim, &sh[0]) || !veil_cli_parse_float(comma + 1, -lim, lim, &sh[1]) ||
        !(sh[1] >= sh[0]))
        return 0;
    *set = 1;
    return 1;
}

void veil_cli_apply_shutter(veil_scene* scene, int set, const float sh[2])
{
    if (set < 0) scene->camera.has_shutter = 0;
    if (set > 0) {
        scene->camera.has_shutter = 1;
        scene->camera.shutter[0] = sh[0], scene->camera.shutter[1] = sh[1];
    }
}

veil_result veil_cli_check_output_folder(const char* path, veil_error* err)
{
    char dir[4096];
    const char* slash = strrchr(path, '/');
    if (!slash) return VEIL_OK;
    size_t n = slash == path ? 1 : (size_t)(slash - path);
    if (n >= sizeof dir) return veil_fail(err, VEIL_ERR_IO, "%s: path too long", path);
    memcpy(dir, path, n);
    dir[n] = '\0';
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return veil_fail(err, VEIL_ERR_IO, "%s: the folder '%s' does not exist", path, dir);
    return VEIL_OK;
}


int veil_cli_check_run(const veil_run_file* files, int n, const veil_frame_range* range)
{
    veil_error err = {0};
    veil_run_clash* clash = malloc(sizeof *clash);
    if (!clash) return veil_cli_fail(veil_fail(&err, VEIL_ERR_OOM, "out of memory"), &err);
    veil_result r = veil_run_files_check(files, n, range, 1, clash, &err);
    int rc = EXIT_OK;
    if (r != VEIL_OK) {
        rc = veil_cli_fail(r, &err);
    } else if (clash->problem != VEIL_RUN_FINE) {
        char text[VEIL_ERROR_MAX];
        veil_run_clash_text(files, clash, text, sizeof text);
        rc = veil_cli_usage_error("%s", text);
    }
    free(clash);
    return rc;
}

int veil_cli_check_outputs(const char* const* inputs, int n_in, const char* const* outputs, const char* const* names,
                           int n_out)
{
    veil_run_file files[16];
    int n = 0;
    for (int i = 0; i < n_in && n < 16; ++i)
        if (inputs[i]) files[n++] = (veil_run_file){.what = "the input", .path = inputs[i]};
    for (int i = 0; i < n_out && n < 16; ++i)
        if (outputs[i]) files[n++] = (veil_run_file){.what = names[i], .path = outputs[i], .writes = 1};
    return veil_cli_check_run(files, n, NULL);
}

veil_run_file* veil_cli_scene_inputs(const char* path, const veil_scene* s, int per_frame, int extra, int* n)
{
    enum { PATH = 4096 };
    size_t k = veil_scene_files(s, NULL, 0);
    size_t entries = 1 + k + (size_t)extra;
    /* the entries, then each file (its field name inside) and (frame 1's) path */
    char* block = calloc(1, entries * sizeof(veil_run_file) + k * (sizeof(veil_scene_file) + PATH));
    if (!block) return NULL;
    veil_run_file* files = (veil_run_file*)block;
    veil_scene_file* sf = (veil_scene_file*)(block + entries * sizeof(veil_run_file));
    char* paths = (char*)(sf + k);
    veil_scene_files(s, sf, k);
    int m = 0;
    files[m++] = (veil_run_file){.what = "the scene", .path = path};
    for (size_t i = 0; i < k; ++i) {
        veil_run_file f = {.what = sf[i].field, .path = sf[i].path};
        veil_error err = {0};
        if (sf[i].sequence && per_frame) f.naming = VEIL_RUN_PATTERN, f.offset = sf[i].frame_offset;
        else if (sf[i].sequence && veil_scene_file_at(&sf[i], 1, paths + i * PATH, PATH, &err) == VEIL_OK)
            f.path = paths + i * PATH;
        else if (sf[i].sequence)
            continue; /* a name too long to read: nothing to overwrite either */
        files[m++] = f;
    }
    *n = m;
    return files;
}

/* Appends a copy of dir to the list; 0 when out of memory. */
static int note_made(veil_cli_folders* m, const char* dir)
{
    if (m->n == m->cap) {
        size_t cap = m->cap ? 2 * m->cap : 8;
        char** grown = realloc(m->made, cap * sizeof *grown);
        if (!grown) return 0;
        m->made = grown, m->cap = cap;
    }
    size_t len = strlen(dir) + 1;
    if (!(m->made[m->n] = malloc(len))) return 0;
    memcpy(m->made[m->n++], dir, len);
    return 1;
}

/* dir and its missing ancestors, as mkdir -p; the ones made noted. */
static veil_result make_path(const char* what, const char* file, const char* dir, veil_cli_folders* m,
                             veil_error* err)
{
    char part[4096];
    size_t len = strlen(dir);
    if (len >= sizeof part) return veil_fail(err, VEIL_ERR_LIMIT, "%s: '%s': the name is too long", what, file);
    for (size_t k = 1; k <= len; ++k) {
        if (k < len && dir[k] != '/') continue;
        if (dir[k - 1] == '/') continue; /* "a//b", the root */
        memcpy(part, dir, k);
        part[k] = '\0';
        struct stat st;
        if (mkdir(part, 0777) == 0) {
            if (!note_made(m, part)) return veil_fail(err, VEIL_ERR_OOM, "out of memory");
        } else if (errno != EEXIST || stat(part, &st) != 0 || !S_ISDIR(st.st_mode)) {
            int e = errno == EEXIST ? ENOTDIR : errno;
            return veil_fail(err, VEIL_ERR_IO, "%s: '%s': cannot make the folder '%s': %s", what, file, part,
                             strerror(e));
        }
    }
    if (access(dir, W_OK | X_OK) != 0)
        return veil_fail(err, VEIL_ERR_IO, "%s: '%s': cannot write into the folder '%s': %s", what, file, dir,
                         strerror(errno));
    return VEIL_OK;
}

veil_result veil_cli_make_folders(const veil_run_file* files, int n, const veil_frame_range* range,
                                  veil_cli_folders* made, veil_error* err)
{
    veil_result r = VEIL_OK;
    long count = range ? veil_frame_range_count(range) : 0;
    veil_temp_hold_signals(); /* made and registered as one step */
    for (int g = 0; g < n && r == VEIL_OK; ++g) {
        if (!files[g].writes) continue;
        char last[4096] = "";
        long frames = files[g].naming == VEIL_RUN_ONE ? 1 : count;
        for (long i = 0; i < frames && r == VEIL_OK; ++i) {
            char path[4096], dir[4096];
            r = veil_run_file_path(&files[g], files[g].naming == VEIL_RUN_ONE ? 0 : veil_frame_range_at(range, i),
                                   path, sizeof path, err);
            const char* slash = r == VEIL_OK ? strrchr(path, '/') : NULL;
            if (!slash) continue; /* the current folder, or an error */
            size_t len = slash == path ? 1 : (size_t)(slash - path);
            memcpy(dir, path, len);
            dir[len] = '\0';
            if (!strcmp(dir, last)) continue; /* a pattern's frames share their folder */
            r = make_path(files[g].what, path, dir, made, err);
            strcpy(last, dir);
        }
    }
    veil_temp_register_made_folders(made->made, made->n);
    veil_temp_release_signals();
    if (r != VEIL_OK) veil_cli_folders_done(made, 0);
    return r;
}

void veil_cli_folders_done(veil_cli_folders* made, int ok)
{
    veil_temp_forget_made_folders();
    for (size_t i = made->n; i > 0; --i) {
        if (!ok) rmdir(made->made[i - 1]); /* only an empty one goes */
        free(made->made[i - 1]);
    }
    free(made->made);
    memset(made, 0, sizeof *made);
}

const char* veil_cli_stage(veil_cli_outputs* o, const char* target, veil_error* err)
{
    if (o->count == 4) {
        veil_fail(err, VEIL_ERR_INVALID, "at most 4 outputs");
        return NULL;
    }
    struct stat st;
    if (stat(target, &st) == 0 && !S_ISREG(st.st_mode)) {
        /* renaming over it would replace it (a FIFO, a device): as the writers refuse it */
        veil_fail(err, VEIL_ERR_IO, "%s: exists and is not a regular file", target);
        return NULL;
    }
    int i = o->count;
    int n = snprintf(o->staged[i], sizeof o->staged[i], "%s.veil-staged%ld", target, (long)getpid());
    if (n < 0 || (size_t)n >= sizeof o->staged[i]) {
        veil_fail(err, VEIL_ERR_IO, "%s: path too long", target);
        return NULL;
    }
    o->target[i] = target;
    o->count++;
    veil_temp_register(o->staged[i]); /* a signal removes it (io/tempfile.h) */
    return o->staged[i];
}

veil_result veil_cli_commit(veil_cli_outputs* o, int ok, veil_error* err)
{
    veil_result r = VEIL_OK;
    for (int i = 0; i < o->count; ++i) {
        if (ok && r == VEIL_OK && rename(o->staged[i], o->target[i]) != 0)
            r = veil_fail(err, VEIL_ERR_IO, "%s: cannot rename the finished file over it: %s", o->target[i],
                          strerror(errno));
        else if (!ok || r != VEIL_OK)
            unlink(o->staged[i]);
        veil_temp_forget(o->staged[i]);
    }
    o->count = 0;
    return r;
}

int veil_cli_exr_option(const char* s, const char* v, veil_exr_format* f, int* rc)
{
    *rc = -1;
    if (strcmp(s, "--exr-type") && strcmp(s, "--exr-compression") && strcmp(s, "--dwa-level")) return 0;
    if (!v) {
        *rc = veil_cli_usage_error("%s needs a value", s);
        return 1;
    }
    if (!strcmp(s, "--exr-type")) {
        if (!strcmp(v, "half") || !strcmp(v, "float")) f->half = !strcmp(v, "half");
        else *rc = veil_cli_usage_error("--exr-type: expected half or float, got '%s'", v);
    } else if (!strcmp(s, "--exr-compression")) {
        int c = veil_exr_compression_parse(v);
        if (c > 0) f->compression = c;
        else *rc = veil_cli_usage_error("--exr-compression: expected none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa "
                                        "or dwab, got '%s'", v);
    } else if (!veil_cli_parse_float(v, 1e-3f, 1000.0f, &f->dwa_level)) {
        *rc = veil_cli_usage_error("--dwa-level: expected a compression level in 0.001..1000 (OpenEXR's default 45), "
                                   "got '%s'", v);
    }
    return 1;
}
