#include "programs.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_util.h"

const char* veil_shader_source(const char* path, size_t len)
{
    if (!len) len = strlen(path);
    for (int i = 0; i < veil_shader_file_count; ++i)
        if (strlen(veil_shader_files[i].path) == len && !strncmp(veil_shader_files[i].path, path, len))
            return veil_shader_files[i].source;
    return NULL;
}

veil_result veil_gpu_program(const char* path, GLuint* out, veil_error* err)
{
    *out = 0;
    const char* src = veil_shader_source(path, 0);
    if (!src) return veil_fail(err, VEIL_ERR_INVALID, "%s: no such embedded shader (is it in CMakeLists.txt's list?)", path);
    return veil_gl_compute_program(path, src, out, err);
}

veil_result veil_gpu_program_variant(const char* path, const char* defines, const char* variant, GLuint* out,
                                     veil_error* err)
{
    *out = 0;
    const char* src = veil_shader_source(path, 0);
    if (!src) return veil_fail(err, VEIL_ERR_INVALID, "%s: no such embedded shader (is it in CMakeLists.txt's list?)", path);
    size_t nd = strlen(defines), ns = strlen(src);
    char* text = malloc(nd + ns + 1);
    if (!text) return veil_fail(err, VEIL_ERR_OOM, "out of memory for %s (%s)", path, variant);
    memcpy(text, defines, nd);
    memcpy(text + nd, src, ns + 1);
    char label[256];
    snprintf(label, sizeof label, "%s (%s)", path, variant);
    veil_result r = veil_gl_compute_program(label, text, out, err);
    free(text);
    return r;
}
