#include "cli_util.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

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
    fprintf(stderr, "veil: %s\n", err->msg[0] ? err->msg : veil_result_message(r));
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

