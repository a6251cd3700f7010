/* veil — the program registry: every shader file of the source tree,
 * embedded into the library at build time (cmake/embed.cmake, from the one
 * list in CMakeLists.txt), looked up by its path.
 *
 * A stage asks for its program by path ("render/shaders/march.comp"); a
 * line `//@include PATH` inside a shader pulls in another embedded file by
 * its path (a header shared by C and GLSL such as
 * propagate/opv_schemes.glsl.h). core/shared.glsl.h is prepended to every
 * shader. Needs a current veil_gl context.
 */
#ifndef VEIL_PROGRAMS_H
#define VEIL_PROGRAMS_H

#include <epoxy/gl.h>

#include "../core/result.h"

typedef struct veil_shader_file {
    const char* path;   /* relative to the source root */
    const char* source; /* NUL-terminated text */
} veil_shader_file;

/* The registry (generated). */
extern const veil_shader_file veil_shader_files[];
extern const int veil_shader_file_count;

/* The embedded text of `path` (the first `len` bytes of it when len > 0,
 * else all of it), or NULL when no such file was embedded. */
const char* veil_shader_source(const char* path, size_t len);

/* Compiles and links the embedded compute shader `path`. Errors name the
 * file (VEIL_ERR_SHADER with the driver's log; VEIL_ERR_INVALID when the
 * path is not in the registry). */
veil_result veil_gpu_program(const char* path, GLuint* out, veil_error* err);

/* The same with `defines` (e.g. "#define VEIL_SPARSE 1\n") put before the
 * file's text: a variant of one shader (the march with emission, or over a
 * sparse volume). The label is "PATH (variant)". */
veil_result veil_gpu_program_variant(const char* path, const char* defines, const char* variant, GLuint* out,
                                     veil_error* err);

#endif
