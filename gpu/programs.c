#include "programs.h"

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
