#include "cli_util.h"

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


/* 1 when a and b name the same existing file, or the same path. */
static int same_file(const char* a, const char* b)
{
    if (!strcmp(a, b)) return 1;
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

int veil_cli_check_outputs(const char* const* inputs, int n_in, const char* const* outputs, const char* const* names,
                           int n_out)
{
    for (int i = 0; i < n_out; ++i) {
        if (!outputs[i]) continue;
        char what[160];
        if (!outputs[i][0]) {
            snprintf(what, sizeof what, "%s: an empty path", names[i]);
            return veil_cli_usage_error("%s", what);
        }
        struct stat st;
        if (stat(outputs[i], &st) == 0 && S_ISDIR(st.st_mode)) {
            snprintf(what, sizeof what, "%s: '%%s' is a directory", names[i]);
            return veil_cli_usage_error(what, outputs[i]);
        }
        for (int j = 0; j < n_in; ++j)
            if (inputs[j] && same_file(outputs[i], inputs[j])) {
                snprintf(what, sizeof what, "%s: '%%s' is an input of this run (it would be overwritten)", names[i]);
                return veil_cli_usage_error(what, outputs[i]);
            }
        for (int j = 0; j < i; ++j)
            if (outputs[j] && same_file(outputs[i], outputs[j])) {
                snprintf(what, sizeof what, "%s and %s: both are '%%s'", names[j], names[i]);
                return veil_cli_usage_error(what, outputs[i]);
            }
    }
    return EXIT_OK;
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
